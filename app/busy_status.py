"""The main window's busy state: the status bar's progress bar and Cancel button, shown while a scene loads, its first
views are computed or an export runs; the background jobs' progress shown on them; Cancel stops the export first,
else the loading, else the first views.

Held by the window as ``window.busy`` (issue #31: a part with its own state, not a mixin); ``set_busy(busy)`` and
``busy_elsewhere()`` are what the scene loading, the view scheduler and the export runs are given. Its collaborators
are the status label, the progress bar, the Cancel button (connected here), the window's ``jobs`` (their progress,
connected here; the first views' jobs cancelled), and as callbacks what the window's other parts say:
``exporting()`` and ``cancel_export()`` (``volviz_app.export_runs``), ``loading()`` (the scene being read and
prepared, None when none: ``volviz_app.scene_loading``) and ``first_views()`` (a new scene's first views are being
computed: ``volviz_app.view_scheduler``)."""
from __future__ import annotations

from typing import TYPE_CHECKING, Callable, Optional

from PySide6.QtWidgets import QLabel, QProgressBar, QPushButton

if TYPE_CHECKING:
    from volviz.jobs import Job
    from .workers import JobBridge


class BusyStatus:
    """The progress bar and Cancel button of the window (see the module's docstring)."""

    def __init__(self, status: QLabel, progress_bar: QProgressBar, cancel_button: QPushButton, jobs: JobBridge, *,
                 exporting: Callable[[], bool], cancel_export: Callable[[], None],
                 loading: Callable[[], Optional[Job]], first_views: Callable[[], bool]) -> None:
        self.status, self.progress_bar, self.cancel_button, self.jobs = status, progress_bar, cancel_button, jobs
        self.exporting, self.cancel_export, self.loading, self.first_views = exporting, cancel_export, loading, \
            first_views
        jobs.progress.connect(self.on_progress)
        cancel_button.clicked.connect(self.cancel_current_job)

    def on_progress(self, job_id: int, fraction: float, message: str) -> None:
        bar = self.progress_bar
        # QProgressBar.setValue repaints at once (synchronously); under load that paint and its flush to the X
        # server held the event loop for most of 80-140 ms gaps. With updates off it only schedules a paint.
        bar.setUpdatesEnabled(False)
        bar.setValue(int(round(fraction * 1000)))
        bar.setUpdatesEnabled(True)
        if message and bar.isVisible():  # background work after loading (error estimates) keeps "Showing ..."
            self.status.setText(message)

    def set_busy(self, busy: bool) -> None:
        was = self.progress_bar.isVisible()
        busy = busy or self.exporting()  # a running export keeps its progress bar and cancel button
        self.progress_bar.setVisible(busy)
        self.cancel_button.setVisible(busy)
        if busy and not was:
            self.progress_bar.setValue(0)

    def busy_elsewhere(self) -> bool:
        """A job other than an export still shows progress (a scene loading, its first views)."""
        return self.loading() is not None or self.first_views()

    def cancel_current_job(self) -> None:
        job = self.loading()
        if self.exporting():  # an export runs alongside whatever else: the button stops it first
            self.cancel_export()
        elif job is not None:
            job.cancel()
        elif self.first_views():  # the scene is shown; stop computing its first views
            self.jobs.runner.cancel_all()
