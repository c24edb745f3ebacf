"""The preview hold's camera swap draws what its log says (``volviz.render.preview_hold``, issue #28): a held frame
with the preview image's camera, the next frame after the hold with the live one. VTK's OpenGL camera re-uses its
matrices until the camera's time stamp passes theirs, and ``DeepCopy`` keeps the time stamp: the first held frame
after a mouse move computed the matrices for the swapped-in camera, and every frame after the hold (the screen, the
opaque depth the next CPU PT image was cut by) stayed at that preview's camera while the camera said otherwise."""
from __future__ import annotations

import numpy as np
import pytest

pv = pytest.importorskip("pyvista")

from volviz.render.image_overlay import read_buffers  # noqa: E402
from volviz.render.preview_hold import PreviewCameraHold  # noqa: E402
from volviz.render.vtk_facade import vtk  # noqa: E402

SIZE = (200, 150)
FOCUS = (0.16, 0.09, 0.005)
LIVE = ((1.0, -0.5, 0.5), (-0.65, -0.34, 0.68))     # notch_disp.vtu's box after the flow's orbit, roughly
PREVIEW = ((0.84, 0.77, 0.69), (0.0, 0.0, 1.0))      # and before it


def _frame(plotter: pv.Plotter) -> np.ndarray:
    """One render of the window as the app's repaint does it (no PyVista call that marks the renderer modified),
    its colour read back."""
    plotter.ren_win.Render()
    return read_buffers(plotter.ren_win, *SIZE)[1].astype(np.float64)


def _aim(plotter: pv.Plotter, pose: tuple[tuple[float, ...], tuple[float, ...]]) -> vtk.vtkCamera:
    """The plotter's camera put at ``pose`` (position, view up), its clipping range reset; returns a copy."""
    camera = plotter.renderer.GetActiveCamera()
    camera.SetPosition(pose[0])
    camera.SetFocalPoint(FOCUS)
    camera.SetViewUp(pose[1])
    plotter.renderer.ResetCameraClippingRange()
    copy = vtk.vtkCamera()
    copy.DeepCopy(camera)
    return copy


def test_a_held_frame_draws_the_preview_camera_and_the_next_one_the_live_camera() -> None:
    pl = pv.Plotter(off_screen=True, window_size=list(SIZE))
    pl.set_background("black")
    pl.add_mesh(pv.Box((0.0, 0.4, 0.0, 0.1, 0.0, 0.01)).outline(), color="white")
    preview = _aim(pl, PREVIEW)
    at_preview = _frame(pl)
    _aim(pl, LIVE)
    at_live = _frame(pl)
    assert np.abs(at_live - at_preview).max() == 255      # the two poses draw the box apart
    hold = PreviewCameraHold(pl)
    hold.holding, hold.image_camera = True, preview       # a drag, with a preview of an older camera shown
    pl.renderer.GetActiveCamera().Modified()              # the drag's last mouse move
    held_at_preview = np.array_equal(_frame(pl), at_preview)
    assert held_at_preview, "the held frame did not draw the preview's camera"
    hold.holding = False                                  # the full-size image of the live camera is shown
    after_at_live = np.array_equal(_frame(pl), at_live)
    assert after_at_live, "the frame after the hold drew the preview's camera"
    live = pl.renderer.GetActiveCamera()
    assert np.allclose(live.GetPosition(), LIVE[0])       # the live camera is put back
    hold.remove()
    pl.close()


def test_a_held_frame_draws_the_orientation_axes_at_the_preview_camera() -> None:
    """The orientation axes (their own renderer, whose camera follows the plotter's at each render's start) are
    drawn at the camera the held frame draws the scene with: before, they followed the live camera while the box
    was drawn at the preview's (up to ~10 frames out of step in a CPU PT drag)."""
    pl = pv.Plotter(off_screen=True, window_size=list(SIZE))
    pl.set_background("black")
    pl.add_mesh(pv.Box((0.0, 0.4, 0.0, 0.1, 0.0, 0.01)).outline(), color="white")
    pl.add_axes(interactive=False, line_width=1)
    preview = _aim(pl, PREVIEW)
    at_preview = _frame(pl)
    _aim(pl, LIVE)
    at_live = _frame(pl)
    x0, y0, x1, y1 = pl.renderer.axes_widget.GetViewport()
    corner = (slice(int(SIZE[1] * (1 - y1)), int(SIZE[1] * (1 - y0))), slice(int(SIZE[0] * x0), int(SIZE[0] * x1)))
    assert np.abs(at_live[corner] - at_preview[corner]).max() > 100   # the two poses draw the axes apart
    hold = PreviewCameraHold(pl)
    hold.holding, hold.image_camera = True, preview
    pl.renderer.GetActiveCamera().Modified()
    held = _frame(pl)
    assert np.array_equal(held[corner], at_preview[corner]), "the held frame drew the axes at the live camera"
    assert np.array_equal(held, at_preview)
    hold.holding = False
    assert np.array_equal(_frame(pl), at_live), "the frame after the hold drew the axes at the preview's camera"
    hold.remove()
    pl.close()
