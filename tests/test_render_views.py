"""The registry of volviz's views (``volviz.render.views``): every view kind and backend names a class that offers
the view calls with its own backend, an unknown pair is a clear error, and a LOD volume updated through the view
calls shows what ``update`` shows."""
from __future__ import annotations

import inspect

import numpy as np
import pytest

from volviz.render.views import VIEWS, View, view_class


@pytest.mark.parametrize("kind, backend", sorted(VIEWS))
def test_each_registered_view_offers_the_view_calls(kind, backend):
    cls = view_class(kind, backend)
    assert cls.backend == backend
    for name in ("begin", "compute", "finish", "remove"):
        assert callable(getattr(cls, name, None)), f"{cls.__name__} has no {name}"
    begin = inspect.signature(cls.begin).parameters
    assert "scale" in begin and begin["scale"].default == 1, f"{cls.__name__}.begin(scale=1)"


def test_an_unknown_kind_or_backend_names_what_exists():
    with pytest.raises(ValueError, match=r"no 'gpu' view for 'lod'; views: pt/gpu, pt/cpu, .*lod/cpu"):
        view_class("lod", "gpu")


def test_a_lod_volume_through_the_view_calls_shows_what_update_shows(tmp_path):
    import pyvista as pv

    from conftest import blob_vvz
    from volviz.optics import TransferFunction
    from volviz.regular.lod import LodTree
    from volviz.render.lod_volume import LodVolume

    tree = LodTree(blob_vvz(tmp_path / "blob.vvz", 40), cache_bytes=16 << 20)
    tf = TransferFunction([20.0, 100.0, 255.0], [[1.0, 0.6, 0.2], [0.3, 0.6, 1.0], [1.0, 1.0, 1.0]],
                          [0.0, 0.08, 0.2])
    images = []
    for through_views in (False, True):
        pl = pv.Plotter(off_screen=True, window_size=[96, 80])
        try:
            volume = LodVolume(pl, tree, tf, budget=64)
            pl.camera_position = [(100.0, -70.0, 60.0), (20.0, 20.0, 20.0), (0, 0, 1)]
            pl.camera_set = True
            assert isinstance(volume, View)
            if through_views:
                request = volume.begin()
                stats = volume.finish(request, *volume.compute(request))
                assert volume.begin(scale=2)["budget"] == 8
            else:
                stats = volume.update()
            images.append(np.asarray(volume.image).copy())
            assert stats["blocks"] > 0 and images[-1][..., 3].max() > 0
            volume.remove()
        finally:
            pl.close()
    np.testing.assert_array_equal(images[0], images[1])


@pytest.mark.parametrize("kind", sorted(__import__("volviz.render.views", fromlist=["x"]).COMPONENT_VIEWS))
def test_each_component_view_offers_the_component_calls(kind):
    from volviz.render.views import component_view_classes

    for cls in component_view_classes(kind):
        assert cls.kind == kind and isinstance(cls.camera_dependent, bool)
        for name in ("set_tf", "set_clip", "update", "bounds", "remove"):
            assert callable(getattr(cls, name, None)), f"{cls.__name__} has no {name}"
        assert "opacity" in inspect.signature(cls.set_tf).parameters, f"{cls.__name__}.set_tf(tf, opacity)"
        assert isinstance(getattr(cls, "visible", None), property) or "visible" in cls.__annotations__


@pytest.mark.parametrize("backend, gpu_thread", [("cpu", "auto"), ("gpu", "off"), ("gpu", "on")])
def test_every_kind_of_component_answers_the_same_calls_through_the_controller(tmp_path, backend, gpu_thread):
    """A volume VTK draws, a PT volume, a volume at a level of detail and isosurfaces in one scene: the controller
    gives each the same calls (TF, opacity, visibility, clipping, bounds) and each does its own thing with them. The
    GPU pass in the scene's window (``gpu_thread`` "off") and in a thread of its own ("on": an image, as the CPU's,
    of a cut mesh under clipping)."""
    import pyvista as pv

    from conftest import blob_vvz
    from volviz.model.clip import ClipPlane, ClipSettings
    from volviz.regular.lod import LodTree
    from volviz.render.controller import SceneController
    from volviz.render.views import ComponentView
    from volviz.session import CameraState, Component, DatasetRef, Session

    from volviz.model import RegularVolume

    g = np.linspace(-1.0, 1.0, 20)
    x, y, z = np.meshgrid(g, g, g, indexing="ij")
    datasets = {"ball": RegularVolume((x * x + y * y + z * z).astype(np.float32), origin=(30.0, 0.0, 0.0)),
                "blob": LodTree(blob_vvz(tmp_path / "blob.vvz", 24), cache_bytes=8 << 20)}
    session = Session(datasets=[DatasetRef("ball", "/unused"), DatasetRef("blob", "/unused")],
                      components=[Component("vol", "volume", "ball"),
                                  Component("iso", "isosurface", "ball",
                                            settings={"styles": [{"value": 0.5, "color": [1, 0.5, 0.2],
                                                                  "opacity": 0.5}]}),
                                  Component("demo", "demo", settings={"cells_per_edge": 6}),
                                  Component("blob", "volume", "blob", settings={"budget": 16})],
                      camera=CameraState((15.0, -80.0, 20.0), (15.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    session.render.options.update(backend=backend, gpu_thread=gpu_thread, scalar_bar=False, axes=False, outline=False)
    image_view = backend == "cpu" or gpu_thread == "on"       # the PT volume is an image made off the window
    pl = pv.Plotter(off_screen=True, window_size=[96, 72])
    try:
        c = SceneController(pl, session, datasets)
        c.build()
        kinds = {comp_id: view.kind for comp_id, view in c.views.items()}
        assert kinds == {"vol": "vtk", "iso": "isosurfaces", "demo": "pt", "blob": "lod"}
        assert all(isinstance(view, ComponentView) for view in c.views.values())
        assert c.views["demo"].backend == ("cpu" if image_view else "gpu") and c.views["demo"].drawn_by == backend
        assert set(c.camera_views()) == {"lod:blob", ("pt:demo" if image_view else "pt-order:demo")}
        whole = c.bounds()

        # transfer functions: each view draws the new one (VTK's property, the PT table, the LOD volume's TF)
        for comp_id in ("vol", "demo", "blob"):
            tf = c.transfer_function(comp_id).scaled_extinction(2.0)
            c.set_transfer_function(comp_id, tf)
        assert c.views["demo"].tf.extinction[-1] == pytest.approx(c.transfer_function("demo").extinction[-1])
        assert c.views["blob"].tf is not None and c.views["blob"].tf.extinction[-1] == pytest.approx(
            c.transfer_function("blob").extinction[-1])

        # opacity: a volume's extinction is scaled, the isosurfaces are cut again with the new opacity
        shown = c.views["iso"].parts
        c.set_opacity("iso", 0.5)
        assert c.views["iso"].parts is not shown
        assert c.views["iso"].parts.shown[0].style.opacity == pytest.approx(0.25)
        c.set_opacity("demo", 0.5)
        assert c.views["demo"].tf.extinction[-1] == pytest.approx(0.5 * c.transfer_function("demo").extinction[-1])

        # visibility
        for comp_id in ("vol", "iso", "demo", "blob"):
            c.set_visible(comp_id, False)
            assert not c.views[comp_id].visible
            c.set_visible(comp_id, True)
            assert c.views[comp_id].visible
        assert c.camera_views() and c.lod_volumes()

        # clipping: VTK's props, the GPU PT pass and the LOD volume clip at once; the CPU PT mesh and the isosurfaces
        # are cut (here, now); the scene's bounds stay the uncut extents
        half = ClipSettings([ClipPlane((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))])  # keeps x >= 0
        cut = c.set_clip(half)
        assert sorted(cut) == (["demo", "iso"] if image_view else ["iso"])
        assert c.views["vol"].prop.GetMapper().GetNumberOfClippingPlanes() == 1
        assert c.views["blob"].volume.GetMapper().GetNumberOfClippingPlanes() == 1
        assert c.views["iso"].parts.clip == half
        if image_view:
            assert c.views["demo"].mesh.n_cells < c.views["demo"].whole_mesh.n_cells
            c.update_views()
            assert c.views["demo"].stats["method"] == ("pt" if backend == "cpu" else "pt-gl")
            assert c.views["demo"].image[..., 3].max() > 0.1
        assert c.bounds() == pytest.approx(whole)
        c.clear()
    finally:
        pl.close()
