"""Background work: an executor with progress callbacks, cancellation and superseding of stale requests.

Long work in volviz (loading, decompression, sorting, table builds, extraction) takes an optional
``progress(fraction, message)`` callable. Run through a ``JobRunner``, that callable reports progress and raises
``Cancelled`` once the job's token is cancelled, so cancellation needs no extra plumbing in the numerics. A job
submitted with a ``key`` supersedes the running job of the same key: the old one is cancelled and its result is never
delivered (sorting for the newest camera, not every camera; docs/design.md "Background work"). ``OneInFlight`` is the
other policy: one job of a kind at a time, the newest waiting request next, so that every finished result is shown
while requests keep coming (the app's view refreshes).

This module is Qt-free; the app bridges ``on_progress`` and ``on_done`` to Qt signals.

A job makes no VTK (PyVista) object and hands none over: it returns arrays (model datasets, meshes) and the GUI
thread makes the VTK objects when it shows them (``finish``, ``install``, ``show_volumes``). A worker that makes or
drops a VTK object from Python holds the GIL while VTK's garbage collector may be waiting for a collection on the
GUI thread, and that collection, inside a render (which releases the GIL), may be freeing a PyVista object whose
clean-up needs the GIL: each waits for the other and the window freezes for good (issue #28: orbiting a terrain;
playing a surface series while orbiting). ``tests/test_jobs_vtk_threads.py`` holds the view updates,
scene preparation, first-look transfer functions and time blends to it. Not yet: isosurface extraction and cuts
(VTK's contour, clip and probe filters in ``volviz.iso``) and frame export still run VTK filters on workers.
"""
from __future__ import annotations

import itertools
import logging
import os
import threading
import traceback
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

log = logging.getLogger(__name__)

ProgressCallback = Callable[[float, str], None]


class Cancelled(Exception):
    """Raised inside a job when its token was cancelled."""


class CancelToken:
    """A flag shared between the requester and the job."""

    def __init__(self) -> None:
        self._event = threading.Event()

    def cancel(self) -> None:
        self._event.set()

    @property
    def cancelled(self) -> bool:
        return self._event.is_set()

    def raise_if_cancelled(self) -> None:
        if self._event.is_set():
            raise Cancelled()


def report(progress: Optional[ProgressCallback], fraction: float, message: str = "") -> None:
    """Call ``progress`` if given; library code uses this so that a missing callback costs nothing."""
    if progress is not None:
        progress(fraction, message)


@dataclass
class JobOutcome:
    """What a finished job delivers to ``on_done``: a result, an error (with traceback text), or a cancellation."""

    job_id: int
    name: str
    result: Any = None
    error: Optional[BaseException] = None
    traceback: str = ""
    cancelled: bool = False

    @property
    def ok(self) -> bool:
        return self.error is None and not self.cancelled


@dataclass
class Job:
    job_id: int
    name: str
    key: Optional[str]
    token: CancelToken
    future: Future = field(repr=False)

    def cancel(self) -> None:
        """Ask the job to stop; a job not yet started finishes at once as cancelled."""
        self.token.cancel()

    def done(self) -> bool:
        return self.future.done()

    def outcome(self, timeout: Optional[float] = None) -> JobOutcome:
        return self.future.result(timeout)


def _leave_a_core_free() -> None:
    """Parallel Numba kernels started from this worker thread use all cores but one (a per-thread setting), so the
    UI thread and the display server are never starved while background work runs."""
    try:
        # Numba (heavy): only in a worker thread, where kernels run
        import numba
    except ImportError:  # pragma: no cover - numba is a dependency
        return
    # numba.config sets its settings at import time; its stubs do not declare them
    numba.set_num_threads(max(1, numba.config.NUMBA_NUM_THREADS - 1))  # type: ignore[attr-defined]


#: how much lower than the requester's the scheduling priority of a job thread is (Linux nice increment)
BACKGROUND_NICE = 10
_thread_state = threading.local()


def _yield_the_cpu() -> None:
    """Run this worker thread at a lower scheduling priority (nice + ``BACKGROUND_NICE``; Linux schedules threads
    one by one), once per thread; threads it starts (Numba's pool) inherit it. On two busy cores the UI thread then
    wins the CPU from background work, where at equal priority the event loop's gaps during a table build were long
    under load (docs/bench/docstring-figures.md). Without per-thread priorities (not Linux) nothing changes."""
    if getattr(_thread_state, "niced", False):
        return
    _thread_state.niced = True
    try:
        tid = threading.get_native_id()
        os.setpriority(os.PRIO_PROCESS, tid, min(19, os.getpriority(os.PRIO_PROCESS, tid) + BACKGROUND_NICE))
    except (AttributeError, OSError):  # pragma: no cover - platforms without per-thread priorities
        pass


class JobRunner:
    """Runs callables on worker threads. Numba kernels (nogil) and NumPy release the GIL, so the UI stays live."""

    def __init__(self, max_workers: int = 2):
        self._pool = ThreadPoolExecutor(max_workers=max_workers, thread_name_prefix="volviz-job")
        self._ids = itertools.count(1)
        self._lock = threading.Lock()
        self._latest: dict[str, Job] = {}
        self._running: dict[int, Job] = {}

    def submit(self, fn: Callable[..., Any], *args: Any, name: str = "", key: Optional[str] = None,
               on_progress: Optional[Callable[[int, float, str], None]] = None,
               on_done: Optional[Callable[[JobOutcome], None]] = None, **kwargs: Any) -> Job:
        """Run ``fn(*args, progress=..., **kwargs)`` in the background.

        ``fn`` must accept a ``progress`` keyword. ``on_progress(job_id, fraction, message)`` and ``on_done(outcome)``
        are called on the worker thread; ``on_done`` is not called for a job superseded by a newer one of its key.
        """
        token = CancelToken()
        job_id = next(self._ids)
        label = name or getattr(fn, "__name__", "job")

        def progress(fraction: float, message: str = "") -> None:
            token.raise_if_cancelled()
            if on_progress is not None:
                on_progress(job_id, min(max(float(fraction), 0.0), 1.0), message)

        def run() -> JobOutcome:
            _leave_a_core_free()
            _yield_the_cpu()
            outcome = JobOutcome(job_id, label)
            try:
                token.raise_if_cancelled()
                outcome.result = fn(*args, progress=progress, **kwargs)
                if token.cancelled:
                    outcome.cancelled, outcome.result = True, None
            except Cancelled:
                outcome.cancelled = True
            except BaseException as exc:  # delivered to the caller, never a silently dead thread
                outcome.error = exc
                outcome.traceback = traceback.format_exc()
                log.error("job %s (%s) failed:\n%s", job_id, label, outcome.traceback)
            finally:
                with self._lock:
                    self._running.pop(job_id, None)
                    superseded = key is not None and self._latest.get(key) is not None \
                        and self._latest[key].job_id != job_id
                    if key is not None and not superseded:
                        self._latest.pop(key, None)
            if on_done is not None and not superseded:
                try:
                    on_done(outcome)
                except Exception:  # a broken callback must not kill the worker
                    log.exception("on_done callback of job %s (%s) failed", job_id, label)
            return outcome

        with self._lock:
            if key is not None and key in self._latest:
                self._latest[key].cancel()
            future = self._pool.submit(run)
            job = Job(job_id, label, key, token, future)
            self._running[job_id] = job
            if key is not None:
                self._latest[key] = job
        return job

    def cancel(self, key: str) -> None:
        """Cancel the newest job of ``key``, if one is queued or running (it stops at its next progress call; its
        ``on_done`` gets a cancelled outcome)."""
        with self._lock:
            job = self._latest.get(key)
        if job is not None:
            job.cancel()

    def cancel_all(self) -> None:
        with self._lock:
            jobs = list(self._running.values())
        for job in jobs:
            job.cancel()

    @property
    def active(self) -> int:
        with self._lock:
            return len(self._running)

    def shutdown(self, wait: bool = True) -> None:
        self.cancel_all()
        self._pool.shutdown(wait=wait, cancel_futures=True)


class OneInFlight:
    """At most one background job of a kind: a request made while one runs waits, and only the newest waiting one
    starts when it is done. (Cancelling the running job for every newer request, as a job key does, starves it while
    requests keep coming: at 30 playback ticks a second no result would ever be shown.)

    Not thread-safe: requests and completions are made on one thread (the app's GUI thread)."""

    def __init__(self) -> None:
        self.running = False
        self._pending: Optional[Callable[[Callable[[], None]], None]] = None
        self._waiting: list[Callable[[], None]] = []   # ``settled`` callbacks of requests not started yet
        self._current: list[Callable[[], None]] = []   # ... of the running job (it answers the requests before it)

    def request(self, start: Callable[[Callable[[], None]], None],
                settled: Optional[Callable[[], None]] = None) -> None:
        """``start(next_request)`` submits the job; its completion handler must call ``next_request()`` last.
        ``settled()`` is called once a job started at or after this request is over (a newer request answers an
        older one that never started)."""
        self._pending = start
        if settled is not None:
            self._waiting.append(settled)
        if not self.running:
            self._next()

    def _next(self) -> None:
        over, self._current = self._current, []
        start, self._pending = self._pending, None
        if start is not None:
            self._current, self._waiting = self._waiting, []
        self.running = start is not None
        for settled in over:
            settled()
        if start is not None:
            start(self._next)
