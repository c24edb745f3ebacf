"""The offscreen PyVista windows the benchmarks draw in: one color and depth sample per pixel (as the CPU renderers
and the exact references), their render window and their image as floats."""
from __future__ import annotations

import time
from typing import Any, Optional, Sequence

import numpy as np


def bench_plotter(size: Sequence[int], background: Optional[Sequence[float] | str] = None) -> Any:
    """An offscreen plotter of ``size`` (width, height) without multisampling, on ``background`` if given."""
    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    import pyvista as pv

    pl = pv.Plotter(off_screen=True, window_size=[int(size[0]), int(size[1])])
    render_window(pl).SetMultiSamples(0)
    if background is not None:
        pl.set_background(background)  # type: ignore[arg-type]  # pyvista types its functools.wraps wrapper wrongly
    return pl


def finish(window: Any) -> None:
    """Wait until the GPU has completed the frame (``vtkOpenGLRenderWindow.WaitForCompletion``, a glFinish), so that
    a timed ``Render()`` ends with the GPU's completion and not with the command submission (issue #29)."""
    window.WaitForCompletion()


def timed_renders(window: Any, reps: int) -> list[float]:
    """The seconds of ``reps`` draws of a render window, each to the GPU's completion (``finish``)."""
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        window.Render()
        finish(window)
        times.append(time.perf_counter() - t0)
    return times


def render_window(pl: Any) -> Any:
    """A plotter's render window (there is one until the plotter is closed)."""
    window = pl.ren_win
    assert window is not None, "the plotter was closed"
    return window


def screenshot_rgb(pl: Any) -> np.ndarray:
    """The plotter's last frame, RGB in [0, 1] (a screenshot alone does not render: render first)."""
    img = pl.screenshot(return_img=True)
    assert img is not None
    return np.asarray(img, dtype=np.float64)[..., :3] / 255.0
