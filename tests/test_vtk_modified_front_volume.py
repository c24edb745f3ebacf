"""The volume in front of the translucent surfaces (``volviz.render.iso_volume_split.FrontVolume``) follows what the
scene's volume is changed to in place (issue #28, VTK objects changed without a new time stamp). Its window lives
from one overlay image to the next and is handed copies each time (``snapshot``: camera, lights, volume property,
clipping planes); VTK re-uses what it built for an object until the object's time stamp passes that build (the
camera's ``DeepCopy`` kept its stamp, and the CPU ray caster re-used its last image: fixed with ``Modified`` in
``_draw``, tested in tests/test_iso_split_off_gui_thread.py). Here the scene's transfer function and a clipping plane
are changed in place, as the app's edits do, and the long-lived window's next image is held to the image of a new
``FrontVolume`` drawing the same snapshot (max difference 0), and to differ from the image before the change."""
from __future__ import annotations

import numpy as np
import pytest

from iso_volume_scene import close_plotters, scene  # noqa: F401 (a fixture)
from volviz.render.iso_volume_split import FrontVolume, shown_regular_volumes
from volviz.render.vtk_facade import vtk


def _fresh(plotter, meshes) -> np.ndarray:
    """The volume in front drawn by a new FrontVolume (a window that drew nothing before)."""
    front = FrontVolume()
    try:
        return front.render(front.snapshot(plotter, meshes))
    finally:
        front.close()


def _follows(front: FrontVolume, plotter, meshes, before: np.ndarray) -> float:
    """The long-lived window's image of the scene now equals a new window's, and differs from ``before``; returns
    the largest change from ``before``."""
    after = front.render(front.snapshot(plotter, meshes))
    fresh = _fresh(plotter, meshes)
    assert np.abs(after - fresh).max() == 0.0, "the long-lived window drew something else than a new one"
    change = float(np.abs(after - before).max())
    assert change > 0.05, "the change of the scene did not change the volume in front"
    return change


@pytest.mark.parametrize("backend", ["cpu", "gpu"])
def test_volume_in_front_follows_a_transfer_function_and_a_clipping_plane_changed_in_place(backend) -> None:
    c, p = scene(backend, iso_mode="3pass")
    meshes = [m for m in c.iso_overlay.meshes if m.style.opacity < 1.0]
    assert meshes
    (volume,) = shown_regular_volumes(p.renderer)
    front = FrontVolume()
    try:
        before = front.render(front.snapshot(p, meshes))
        assert np.abs(before - _fresh(p, meshes)).max() == 0.0
        ctf = volume.GetProperty().GetRGBTransferFunction(0)      # the scene's colours, changed in place
        lo, hi = ctf.GetRange()
        ctf.RemoveAllPoints()
        ctf.AddRGBPoint(lo, 1.0, 0.0, 0.0)
        ctf.AddRGBPoint(hi, 1.0, 1.0, 0.0)
        print(backend, "transfer function: largest change", _follows(front, p, meshes, before))
        plane = vtk.vtkPlane()                                    # a clipping plane of the scene, then moved
        plane.SetOrigin(15.5, 15.5, 15.5)
        plane.SetNormal(1.0, 0.0, 0.0)
        volume.GetMapper().AddClippingPlane(plane)
        clipped = front.render(front.snapshot(p, meshes))
        assert np.abs(clipped - _fresh(p, meshes)).max() == 0.0
        plane.SetOrigin(22.0, 15.5, 15.5)
        print(backend, "clipping plane moved: largest change", _follows(front, p, meshes, clipped))
    finally:
        front.close()
