"""An offscreen VTK render window owned by one thread of its own, so that a render the app needs besides the window's
(the volume in front of the isosurfaces, ``volviz.render.iso_volume_split``) runs off the GUI thread (issue #28).

An OpenGL context is current in one thread at a time, and VTK makes its window's context current in whatever thread
calls it: every call that touches the window or its props' graphics resources (render, read-back, adding or
removing props, the window's end) runs on the one thread (``call``), which waits between calls. ``threads`` records
the threads the calls ran on (one; tests check that it is not the GUI thread), ``calls`` counts them.
"""
from __future__ import annotations

import threading
import weakref
from concurrent.futures import ThreadPoolExecutor
from typing import TYPE_CHECKING, Any, Callable, TypeVar

if TYPE_CHECKING:   # type-only imports for the signatures
    from volviz.render.vtk_facade import vtkRenderer, vtkRenderWindow

__all__ = ["GLThread"]

T = TypeVar("T")


def _end(pool: ThreadPoolExecutor, state: dict[str, Any], threads: set[int]) -> None:
    """Close the window on its thread (its props' graphics resources with it), then let the thread end. Run there
    directly when the object is collected on that thread (its last call's work item held the last reference)."""
    def close() -> None:
        window = state.pop("window", None)
        state.clear()                   # the props (kept by the caller's state) go while the context is current
        if window is not None:
            window.Finalize()
    if threading.get_ident() in threads:
        close()
    else:
        try:
            pool.submit(close).result()
        except RuntimeError:            # the interpreter is shutting its pools down: nothing to release
            pass
    pool.shutdown(wait=False)


class GLThread:
    """One thread and its offscreen render window with one renderer (module docstring). ``state`` is a dict that the
    caller's functions keep their VTK objects in, so that they are released on this thread by ``close``."""

    def __init__(self, name: str = "volviz-gl") -> None:
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix=name)
        self.state: dict[str, Any] = {}
        self.threads: set[int] = set()
        self.calls = 0
        self._end = weakref.finalize(self, _end, self._pool, self.state, self.threads)

    def call(self, fn: Callable[..., T], *args: object) -> T:
        """``fn(renderer, *args)`` on the thread, the window made first; returns its result (its error raised)."""
        return self._pool.submit(self._run, fn, *args).result()

    def _run(self, fn: Callable[..., T], *args: object) -> T:
        self.threads.add(threading.get_ident())
        self.calls += 1
        if "window" not in self.state:
            self.state["window"], self.state["renderer"] = _window()
        return fn(self.state["renderer"], *args)

    def close(self) -> None:
        """Release the window and its props on the thread and end it (also when the object is collected)."""
        self._end()


def _window() -> tuple[vtkRenderWindow, vtkRenderer]:
    """An offscreen, single-sampled render window with alpha planes and one renderer."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(True)
    window.SetMultiSamples(0)
    window.SetAlphaBitPlanes(True)
    renderer = vtk.vtkRenderer()
    window.AddRenderer(renderer)
    return window, renderer
