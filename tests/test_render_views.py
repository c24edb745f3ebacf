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
