"""Paints of the native viewport that nobody asked for (the window system's exposes) are drawn once, a moment later, in
a turn of the event loop of their own (``NativeViewport._coalesce_expose``; issue #28: no event-loop stall over 100
ms). Showing the window exposed the viewport twice in one turn, with the docks: two whole renders there, and two
more after. The first frame is drawn inside the show, before the window is mapped (``draw_before_mapped``)."""
from __future__ import annotations

import gc

import numpy as np
import pytest
from PySide6.QtCore import QRect, QSettings
from PySide6.QtGui import QPaintEvent, QRegion
from PySide6.QtWidgets import QApplication


@pytest.fixture
def unshown_window(qtbot, tmp_path):
    from volviz_app.window import MainWindow

    settings = QSettings(str(tmp_path / "settings.ini"), QSettings.Format.IniFormat)
    window = MainWindow(settings=settings, recovery_dir=tmp_path / "recovery")
    if not hasattr(window.plotter, "reduce_paints"):
        pytest.fail("the app did not make its native viewport (VOLVIZ_VIEWPORT?)")
    yield window
    window.dirty = False
    window.close()
    gc.collect()


def _count_renders(window) -> list[int]:
    renders: list[int] = []
    window.plotter.ren_win.AddObserver("StartEvent", lambda *args: renders.append(1))
    return renders


def test_a_window_shown_renders_its_viewport_at_most_twice(qtbot, unshown_window) -> None:
    window = unshown_window
    renders = _count_renders(window)
    window.resize(1280, 740)
    window.show()
    assert len(renders) == 1   # inside the show (``draw_before_mapped``)
    del renders[:]
    qtbot.waitExposed(window)
    qtbot.wait(600)
    # the first exposes of the viewport and its resizes, one render; the window system exposes it once more after it
    # (here: 2 renders, before 4)
    assert 1 <= len(renders) <= 2


def test_the_viewports_first_frame_is_drawn_in_the_show_at_the_size_it_keeps(qtbot, unshown_window) -> None:
    """A new render window's first frame at its size (framebuffers at that size, a software rasteriser's shaders)
    and the first magnifying blit are drawn while the window is shown, before it is mapped, at the size the docks
    leave the viewport: the exposes after it draw at that size too, so none makes framebuffers again (before, the
    docks took their sizes a turn after the show, and the first paint drew at a new size)."""
    window = unshown_window
    sizes: list[tuple[int, int]] = []
    window.plotter.ren_win.AddObserver("StartEvent", lambda rw, _e: sizes.append(tuple(rw.GetSize())))
    window.resize(1280, 740)
    window.show()
    in_show = list(sizes)
    assert window.plotter._magnified
    qtbot.waitExposed(window)
    qtbot.wait(600)
    canvas = window.plotter.interactor
    final = (canvas.width(), canvas.height())
    assert in_show == [final]
    assert len(sizes) > 1 and set(sizes) == {final}


def _expose(canvas) -> None:
    """Three paints as the window system's exposes deliver them."""
    for _ in range(3):
        QApplication.sendEvent(canvas, QPaintEvent(QRegion(QRect(0, 0, canvas.width(), canvas.height()))))


def test_paints_nobody_asked_for_redraw_the_last_frame_a_moment_later(qtbot, unshown_window) -> None:
    """Exposes are drawn once, a moment later, from the last frame (VTK's display framebuffer blitted and swapped):
    a combo box's list closed over the Blunt Fin drawn by VTK's projected tetrahedra re-rendered it, 327 ms of a held
    event loop. A frame not swapped whole (a reduced frame, a strip) is rendered again instead."""
    window = unshown_window
    window.resize(900, 600)
    window.show()
    qtbot.waitExposed(window)
    qtbot.wait(600)
    canvas = window.plotter.interactor
    window.plotter.set_background("#336699")
    canvas.repaint()                                   # a paint asked for renders
    shown = np.asarray(window.plotter.screenshot(None, return_img=True))
    renders = _count_renders(window)
    redrawn = canvas.exposes_redrawn
    _expose(canvas)
    assert renders == [] and canvas.exposes_redrawn == redrawn
    qtbot.wait(300)
    assert renders == [] and canvas.exposes_redrawn == redrawn + 1
    np.testing.assert_array_equal(np.asarray(window.plotter.screenshot(None, return_img=True)), shown)
    window.plotter.ren_win.SetSwapBuffers(0)           # a strip's pass: drawn, not swapped
    window.plotter.ren_win.Render()
    window.plotter.ren_win.SetSwapBuffers(1)
    del renders[:]
    _expose(canvas)
    qtbot.wait(300)
    assert len(renders) == 1 and canvas.exposes_redrawn == redrawn + 1
    canvas.update()      # a paint asked for renders
    qtbot.wait(300)
    assert len(renders) == 2
