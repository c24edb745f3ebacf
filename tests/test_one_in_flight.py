"""``volviz.jobs.OneInFlight``: one job of a kind at a time, the newest waiting request next, and each request's
``settled`` callback once a job started at or after it is over (the app's view refreshes: ``app/view_scheduler.py``)."""
from __future__ import annotations

from typing import Callable

from volviz.jobs import OneInFlight


class Jobs:
    """Records what started and keeps each started job's ``next_request`` to finish it later."""

    def __init__(self) -> None:
        self.log: list[str] = []
        self.finish: dict[str, Callable[[], None]] = {}

    def start(self, name: str) -> Callable[[Callable[[], None]], None]:
        def start(next_request: Callable[[], None]) -> None:
            self.log.append(f"start {name}")
            self.finish[name] = next_request
        return start

    def settled(self, name: str) -> Callable[[], None]:
        return lambda: self.log.append(f"settled {name}")


def test_an_idle_kind_starts_at_once_and_settles_when_the_job_is_over() -> None:
    jobs, flight = Jobs(), OneInFlight()
    flight.request(jobs.start("a"), jobs.settled("a"))
    assert jobs.log == ["start a"] and flight.running
    jobs.finish["a"]()
    assert jobs.log == ["start a", "settled a"] and not flight.running


def test_only_the_newest_waiting_request_starts_and_it_answers_the_older_ones() -> None:
    jobs, flight = Jobs(), OneInFlight()
    flight.request(jobs.start("a"), jobs.settled("a"))
    flight.request(jobs.start("b"), jobs.settled("b"))
    flight.request(jobs.start("c"), jobs.settled("c"))
    assert jobs.log == ["start a"]                       # one in flight: b and c wait
    jobs.finish["a"]()
    assert jobs.log == ["start a", "settled a", "start c"]  # b never starts; a settles before c starts
    assert flight.running
    jobs.finish["c"]()
    assert jobs.log == ["start a", "settled a", "start c", "settled b", "settled c"]
    assert not flight.running and set(jobs.finish) == {"a", "c"}


def test_a_request_without_settled_and_one_made_while_idle_again() -> None:
    jobs, flight = Jobs(), OneInFlight()
    flight.request(jobs.start("a"))
    jobs.finish["a"]()
    assert jobs.log == ["start a"] and not flight.running
    flight.request(jobs.start("b"), jobs.settled("b"))
    assert jobs.log == ["start a", "start b"]
    jobs.finish["b"]()
    assert jobs.log == ["start a", "start b", "settled b"]


def test_a_job_that_gives_up_at_once_settles_and_frees_the_kind() -> None:
    """A start that finds nothing to do (the scene changed) calls ``next_request()`` at once."""
    log: list[str] = []
    flight = OneInFlight()
    flight.request(lambda next_request: (log.append("start"), next_request()), lambda: log.append("settled"))
    assert log == ["start", "settled"] and not flight.running
    flight.request(lambda next_request: log.append("again"))
    assert log == ["start", "settled", "again"] and flight.running
