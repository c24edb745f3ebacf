"""The window's busy state is a part given its collaborators (issue #31, the window composed, not mixed in):
``volviz_app.busy_status.BusyStatus`` drives a real progress bar, Cancel button and status label beside a plain
``QMainWindow``, with the real job bridge running real background jobs, and is told by callbacks whether an export
runs, which scene is loading and whether first views are computed, without a ``MainWindow``."""
from __future__ import annotations

import threading
from typing import Any, Optional

import pytest

pytest.importorskip("PySide6")

from PySide6.QtWidgets import QLabel, QMainWindow, QProgressBar, QPushButton  # noqa: E402

from volviz.jobs import Job, JobOutcome  # noqa: E402
from volviz_app.busy_status import BusyStatus  # noqa: E402
from volviz_app.workers import JobBridge  # noqa: E402


def test_progress_busy_and_cancel_follow_what_the_parts_say(qtbot) -> None:
    window = QMainWindow()
    qtbot.addWidget(window)
    status, bar, cancel, jobs = QLabel("Ready"), QProgressBar(), QPushButton("Cancel"), JobBridge(window)
    bar.setRange(0, 1000)
    for widget in (status, bar, cancel):
        window.statusBar().addWidget(widget)
    window.show()
    bar.setVisible(False)   # as the window's status bar starts: shown while busy
    cancel.setVisible(False)
    state: dict[str, Any] = {"exporting": False, "loading": None, "first_views": False, "export_cancels": 0}
    busy = BusyStatus(status, bar, cancel, jobs, exporting=lambda: state["exporting"],
                      cancel_export=lambda: state.__setitem__("export_cancels", state["export_cancels"] + 1),
                      loading=lambda: state["loading"], first_views=lambda: state["first_views"])
    release = threading.Event()
    outcomes: list[JobOutcome] = []

    def work(progress: Optional[Any] = None) -> str:   # a background job that reports half-way, then waits
        progress(0.5, "Reading half")
        while not release.wait(0.01):
            progress(0.5, "Reading half")
        return "read"

    try:
        busy.set_busy(True)
        assert bar.isVisible() and cancel.isVisible() and bar.value() == 0
        job: Job = jobs.submit(work, name="load", on_done=outcomes.append)
        qtbot.waitUntil(lambda: bar.value() == 500 and status.text() == "Reading half", timeout=10000)

        state["exporting"] = True    # an export runs: its Cancel first, and it keeps the bar shown
        cancel.click()
        assert state["export_cancels"] == 1 and not job.token.cancelled
        busy.set_busy(False)
        assert bar.isVisible()

        state.update(exporting=False, loading=job)   # then the scene loading
        assert busy.busy_elsewhere()
        cancel.click()
        assert job.token.cancelled and state["export_cancels"] == 1
        qtbot.waitUntil(lambda: len(outcomes) == 1, timeout=10000)
        assert outcomes[0].cancelled
        busy.set_busy(False)
        assert not bar.isVisible() and not cancel.isVisible()

        state.update(loading=None, first_views=True)   # then a new scene's first views: every running job stops
        assert busy.busy_elsewhere()
        views = jobs.submit(work, name="first views", on_done=outcomes.append)
        qtbot.waitUntil(lambda: jobs.runner.active == 1, timeout=10000)
        busy.cancel_current_job()
        qtbot.waitUntil(lambda: len(outcomes) == 2, timeout=10000)
        assert views.token.cancelled and outcomes[1].cancelled
        state["first_views"] = False
        assert not busy.busy_elsewhere()
        status.setText("Showing demo")
        jobs.progress.emit(0, 0.25, "an error estimate")   # the bar is hidden: the status line keeps its text
        assert bar.value() == 250 and status.text() == "Showing demo"
    finally:
        release.set()
        jobs.shutdown()
