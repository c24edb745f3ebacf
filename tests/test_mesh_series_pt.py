"""A time series of meshes is drawn as a PT volume (``scene_builder.uses_pt``; issue #28: VTK's projected tetrahedra
drew it in the scene's window, on the GUI thread at every frame): each display time gives the view its mesh, made on
any thread with its cut by the clipping (``SceneController.blend_volume``: a ``MeshFrame``) and shown by
``show_volumes``, and the image is the one a scene built at that display time draws."""
from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv

from volviz.model.clip import ClipPlane, ClipSettings
from volviz.model.datasets import TetMesh, TimeSeries
from volviz.render.controller import MeshFrame, SceneController
from volviz.render.pt_prop import PTVolume
from volviz.session import CameraState, Component, DatasetRef, Session
from volviz.unstructured.synthetic import box_tets

SIZE = (64, 48)
PLAIN = {"scalar_bar": False, "axes": False, "outline": False, "backend": "cpu"}


def _series() -> TimeSeries:
    """The unit cube's tetrahedra with a field that drifts along x from step to step."""
    mesh = box_tets(4)
    x = mesh.points[:, 0]
    return TimeSeries([0.0, 1.0, 2.0], [TetMesh(mesh.points, mesh.tets, 0.5 * x + 0.25 * k, "s") for k in range(3)])


def _scene(series: TimeSeries, t: float | None = None) -> tuple[pv.Plotter, SceneController]:
    s = Session(datasets=[DatasetRef("m", "/unused")], components=[Component("vol", "volume", dataset="m")],
                camera=CameraState((0.5, -2.5, 1.2), (0.5, 0.5, 0.5), (0.0, 0.0, 1.0)))
    s.render.options.update(PLAIN)
    if t is not None:
        s.render.options["time"] = t
    p = pv.Plotter(off_screen=True, window_size=list(SIZE))
    c = SceneController(p, s, {"m": series})
    c.build()
    return p, c


def test_each_display_time_draws_the_image_of_a_scene_built_at_that_time() -> None:
    series = _series()
    p, c = _scene(series)
    p2, c2 = _scene(series, 2.0)
    try:
        view = c.pt_volume("vol")
        assert isinstance(view, PTVolume) and c.time_volumes() == ["vol"]
        assert not p.renderer.GetVolumes().GetNumberOfItems()           # nothing drawn by VTK's mappers
        first = view.image.copy()
        frame = c.blend_volume("vol", 2.0)
        assert isinstance(frame, MeshFrame) and frame.shown is frame.whole
        np.testing.assert_array_equal(frame.whole.scalars, series.frame(2).scalars)
        c.set_time(2.0)
        assert view.whole_mesh is not series.frame(0) and np.abs(view.image - first).max() > 0.1
        np.testing.assert_array_equal(view.image, c2.pt_volume("vol").image)
        c.set_time(0.5)                                                  # between two steps: their blend
        np.testing.assert_allclose(view.whole_mesh.scalars, 0.5 * series.frame(0).points[:, 0] + 0.125, atol=1e-6)
    finally:
        c.clear()
        c2.clear()
        p.close()
        p2.close()


def test_a_new_display_time_keeps_the_clipping() -> None:
    p, c = _scene(_series())
    try:
        c.set_clip(ClipSettings(planes=(ClipPlane((0.5, 0.0, 0.0), (1.0, 0.0, 0.0)),)))
        c.set_time(1.0)
        view = c.pt_volume("vol")
        assert view.whole_mesh.points[:, 0].min() == pytest.approx(0.0)
        assert view.mesh.points[:, 0].min() == pytest.approx(0.5) and view.mesh is not view.whole_mesh
        np.testing.assert_allclose(view.whole_mesh.scalars, 0.5 * view.whole_mesh.points[:, 0] + 0.25)
        np.testing.assert_allclose(view.mesh.scalars, 0.5 * view.mesh.points[:, 0] + 0.25)   # the cut of t = 1
        left = view.image[:, : SIZE[0] // 4, 3]
        assert left.max() == 0.0 and view.image[..., 3].max() > 0.2      # the half x < 0.5 is gone
    finally:
        c.clear()
        p.close()


def test_a_display_time_cut_by_an_older_clipping_is_not_shown() -> None:
    """A blend made on a worker before the clipping changed (``blend_volume`` cuts its mesh by the clipping of its
    start): ``show_volumes`` gives the view the new whole mesh, keeps the mesh it shows and names the view to be cut
    again; its cut then shows the new step cut by the new clipping. Before, the old clipping's cut was shown until
    the next step."""
    p, c = _scene(_series())
    try:
        view = c.pt_volume("vol")
        frame = c.blend_volume("vol", 1.0)                             # no clipping yet
        shown = view.mesh
        c.set_clip(ClipSettings(planes=(ClipPlane((0.5, 0.0, 0.0), (1.0, 0.0, 0.0)),)), update=False)
        c.show_cut("vol", c.cut("vol"))                                 # the clipping's cut of the step shown
        shown = view.mesh
        assert c.show_volumes({"vol": frame}) == ["vol"]
        assert view.whole_mesh is frame.whole and view.mesh is shown    # not the uncut frame
        c.show_cut("vol", c.cut("vol"))
        assert view.mesh.points[:, 0].min() == pytest.approx(0.5)
        np.testing.assert_allclose(view.mesh.scalars, 0.5 * view.mesh.points[:, 0] + 0.25)   # the cut of t = 1
        assert c.show_volumes({"vol": c.blend_volume("vol", 2.0)}) == []   # a blend of the clipping shown
    finally:
        c.clear()
        p.close()
