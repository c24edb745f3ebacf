"""The background job runner: results, errors, progress, cancellation, superseding."""
from __future__ import annotations

import threading
import time

import pytest

from volviz.jobs import Cancelled, JobRunner


def slow_count(n: int, progress, stop_at: int | None = None) -> int:
    for i in range(n):
        progress(i / n, f"step {i}")
        time.sleep(0.01)
    return n


def test_result_error_and_progress() -> None:
    runner = JobRunner(max_workers=1)
    seen: list[float] = []
    job = runner.submit(slow_count, 5, on_progress=lambda jid, f, m: seen.append(f))
    outcome = job.outcome(timeout=10)
    assert outcome.ok and outcome.result == 5
    assert seen == [0.0, 0.2, 0.4, 0.6, 0.8]

    def fails(progress) -> None:
        raise ValueError("bad value in file x")

    delivered = []
    outcome = runner.submit(fails, on_done=delivered.append).outcome(timeout=10)
    assert isinstance(outcome.error, ValueError) and "bad value" in outcome.traceback
    assert delivered == [outcome]
    runner.shutdown()


def test_cancel_stops_a_running_job() -> None:
    runner = JobRunner(max_workers=1)
    started = threading.Event()

    def forever(progress) -> None:
        started.set()
        while True:
            progress(0.5, "working")
            time.sleep(0.005)

    job = runner.submit(forever)
    assert started.wait(5)
    job.cancel()
    outcome = job.outcome(timeout=5)
    assert outcome.cancelled and outcome.result is None and outcome.error is None
    assert runner.active == 0
    runner.shutdown()


def test_newer_request_supersedes_stale_one() -> None:
    runner = JobRunner(max_workers=2)
    delivered = []
    first = runner.submit(slow_count, 200, key="sort", on_done=delivered.append)
    second = runner.submit(slow_count, 3, key="sort", on_done=delivered.append)
    assert second.outcome(timeout=10).result == 3
    assert first.outcome(timeout=10).cancelled
    assert [o.job_id for o in delivered] == [second.job_id]
    runner.shutdown()


def test_cancel_by_key_stops_that_job_only() -> None:
    """The app cancels a pending error estimate (key ``error:<id>``) when the camera moves: it stops, its on_done
    hears so, and the job queued behind it on the one worker runs."""
    runner = JobRunner(max_workers=1)
    delivered = []
    estimate = runner.submit(slow_count, 500, key="error:a", on_done=delivered.append)
    preview = runner.submit(slow_count, 3, key="pt:a", on_done=delivered.append)
    runner.cancel("error:a")
    runner.cancel("nothing of that key")
    assert preview.outcome(timeout=2).result == 3      # 500 steps of 10 ms would have held it back 5 s
    assert estimate.outcome(timeout=2).cancelled
    assert [o.job_id for o in delivered] == [estimate.job_id, preview.job_id]
    runner.shutdown()


def test_cancelled_is_an_exception_type() -> None:
    with pytest.raises(Cancelled):
        raise Cancelled()
