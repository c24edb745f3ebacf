"""Bridge from volviz.jobs (Qt-free) to Qt signals, so results reach widgets on the GUI thread."""
from __future__ import annotations

import time
from typing import Any, Callable, Optional

from PySide6.QtCore import QObject, Qt, Signal

from volviz.jobs import Job, JobOutcome, JobRunner


PROGRESS_INTERVAL = 0.08


class JobBridge(QObject):
    """Runs jobs on a JobRunner; emits ``progress(job_id, fraction, message)`` and ``finished(outcome)`` queued.

    A job superseded by a newer one of its key gets no ``on_done`` (``JobRunner.submit``); its handler is dropped when
    the job ends (``retired``, queued after ``finished``), so ``busy`` does not wait for it forever and the handler's
    closure (a scene's controller, its datasets) is freed: moving a slice's slider ten steps left ten handlers behind,
    and ``busy`` was True from then on."""

    progress = Signal(int, float, str)
    finished = Signal(object)
    retired = Signal(int)

    def __init__(self, parent: Optional[QObject] = None, max_workers: int = 1):
        # One worker: background jobs run Numba kernels one at a time. Two at once (a volume render beside an error
        # estimate that was still compiling) aborted the process once in CI even with the OpenMP threading layer.
        super().__init__(parent)
        self.runner = JobRunner(max_workers=max_workers)
        self._handlers: dict[int, Callable[[JobOutcome], None]] = {}
        self.finished.connect(self._dispatch)
        # queued even when emitted on this thread (a job done before its callback was added): after ``finished``
        self.retired.connect(self._retire, Qt.ConnectionType.QueuedConnection)

    def submit(self, fn: Callable[..., Any], *args: Any, name: str, key: Optional[str] = None,
               on_done: Optional[Callable[[JobOutcome], None]] = None, **kwargs: Any) -> Job:
        last = [0.0]

        def progress(job_id: int, fraction: float, message: str) -> None:
            now = time.monotonic()
            if now - last[0] >= PROGRESS_INTERVAL or fraction >= 1.0:  # at most ~12 UI updates a second
                last[0] = now
                self.progress.emit(job_id, fraction, message)

        job = self.runner.submit(fn, *args, name=name, key=key, on_progress=progress, on_done=self.finished.emit,
                                 **kwargs)
        if on_done is not None:
            self._handlers[job.job_id] = on_done
            # after run() returned: its on_done (if any) was emitted first, so ``finished`` is dispatched first
            job_id = job.job_id

            def ended(_future: Any) -> None:
                self.retired.emit(job_id)

            job.future.add_done_callback(ended)
        return job

    def cancel(self, key: str) -> None:
        """Cancel the newest job submitted with ``key`` (``JobRunner.cancel``)."""
        self.runner.cancel(key)

    def busy(self) -> bool:
        """Whether a job whose result the window waits for is still running or queued."""
        return bool(self._handlers)

    def _dispatch(self, outcome: JobOutcome) -> None:
        handler = self._handlers.pop(outcome.job_id, None)
        if handler is not None:
            handler(outcome)

    def _retire(self, job_id: int) -> None:
        """The job has ended: a handler still here belongs to a superseded job, which is never dispatched."""
        self._handlers.pop(job_id, None)

    def shutdown(self) -> None:
        self.runner.shutdown(wait=False)
