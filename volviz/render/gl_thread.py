"""An offscreen VTK render window owned by one thread of its own, so that a render the app needs besides the window's
(the volume in front of the isosurfaces, ``volviz.render.iso_volume_split``) runs off the GUI thread (issue #28).

An OpenGL context is current in one thread at a time, and VTK makes its window's context current in whatever thread
calls it: every call that touches the window or its props' graphics resources (render, read-back, adding or
removing props, the window's end) runs on the one thread (``call``), which waits between calls. ``threads`` records
the threads the calls ran on (one; tests check that it is not the GUI thread), ``calls`` counts them.
"""
from __future__ import annotations

import queue
import threading
import weakref
from concurrent.futures import Future
from typing import TYPE_CHECKING, Any, Callable, TypeVar

if TYPE_CHECKING:   # type-only imports for the signatures
    from volviz.render.vtk_facade import vtkRenderer, vtkRenderWindow

__all__ = ["GLThread", "GLThreadClosed"]

T = TypeVar("T")
_STOP = None   # the item that ends the thread


def _serve(jobs: queue.SimpleQueue) -> None:
    """The thread's loop: run each (function, arguments, future) put on ``jobs`` until ``_STOP``."""
    while True:
        item = jobs.get()
        if item is _STOP:
            return
        fn, args, future = item
        if future.set_running_or_notify_cancel():
            try:
                future.set_result(fn(*args))
            except BaseException as exc:   # noqa: BLE001  (handed to the caller, which raises it)
                future.set_exception(exc)
        del item, fn, args, future     # no reference to a caller (its GLThread) while waiting for the next job


def _end(jobs: queue.SimpleQueue, state: dict[str, Any], threads: set[int], wait: bool = True) -> None:
    """Close the window on its thread (its props' graphics resources with it), then let the thread end. Run there
    directly when the object is collected on that thread (its last call's work item held the last reference).

    This runs as a finalizer too, wherever the collector runs, so it takes no lock another thread's code could hold:
    a ``SimpleQueue``'s ``put`` is reentrant, and waiting on a future needs only that future's. (With a
    ``ThreadPoolExecutor`` it submitted the close: a collection inside another executor's ``submit``, which holds
    the module's global shutdown lock, deadlocked the process.)"""
    def close() -> None:
        window = state.pop("window", None)
        state.clear()                   # the props (kept by the caller's state) go while the context is current
        if window is not None:
            window.Finalize()
    if threading.get_ident() in threads:
        close()
        jobs.put(_STOP)
        return
    done: Future = Future()
    jobs.put((close, (), done))
    jobs.put(_STOP)
    if threads and wait:                # (a thread that never ran a call has no window to close)
        done.result()


class GLThreadClosed(RuntimeError):
    """A call submitted to a ``GLThread`` after its ``close``: no thread serves it."""


class GLThread:
    """One thread and its offscreen render window with one renderer (module docstring). ``state`` is a dict that the
    caller's functions keep their VTK objects in, so that they are released on this thread by ``close``."""

    def __init__(self, name: str = "volviz-gl") -> None:
        self._jobs: queue.SimpleQueue = queue.SimpleQueue()
        # a daemon thread: the interpreter joins other threads before it runs the finalizers that stop them
        threading.Thread(target=_serve, args=(self._jobs,), name=name, daemon=True).start()
        self.state: dict[str, Any] = {}
        self.threads: set[int] = set()
        self.calls = 0
        self.name = name
        self._closed = False
        self._lock = threading.Lock()   # (taken by ``submit`` and ``close`` only, never by the finalizer)
        self._end = weakref.finalize(self, _end, self._jobs, self.state, self.threads)

    def call(self, fn: Callable[..., T], *args: object) -> T:
        """``fn(renderer, *args)`` on the thread, the window made first; returns its result (its error raised)."""
        return self.submit(fn, *args).result()

    def submit(self, fn: Callable[..., T], *args: object) -> Future:
        """``fn(renderer, *args)`` queued for the thread (``call`` without waiting): its future; after ``close`` a
        future that raises ``GLThreadClosed`` (queued after the thread's end, it would never be served)."""
        future: Future = Future()
        with self._lock:
            if self._closed:
                future.set_exception(GLThreadClosed(f"{self.name}: the thread is closed"))
            else:
                self._jobs.put((self._run, (fn, *args), future))
        return future

    def _run(self, fn: Callable[..., T], *args: object) -> T:
        self.threads.add(threading.get_ident())
        self.calls += 1
        if "window" not in self.state:
            self.state["window"], self.state["renderer"] = _window()
        return fn(self.state["renderer"], *args)

    def close(self, wait: bool = True) -> None:
        """Release the window and its props on the thread and end it (also when the object is collected). With
        ``wait`` False the close is queued after the call in progress, without waiting for either: a view removed
        on the GUI thread while its image is drawn here (issue #28)."""
        with self._lock:
            self._closed = True
        if wait:
            self._end()
        elif self._end.detach() is not None:
            _end(self._jobs, self.state, self.threads, wait=False)


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
