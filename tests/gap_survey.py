"""An opt-in pytest plugin that surveys the GUI thread's event-loop gaps in every flow a test drives (issue #28: "no
event-loop stall over 100 ms in any flow"). Not loaded by default; the survey is a measurement, not a test:

    GAP_SURVEY=gaps.jsonl PYTHONPATH=tests VOLVIZ_DATA=../shared/data \
        python -m pytest -p gap_survey tests/test_flow_*.py

A 10 ms timer ticks on the GUI thread while the test waits in ``qtbot.wait`` / ``waitUntil`` (the app's own event
loop). A gap between two ticks of one wait is how long the app held its loop; gaps that span the test's own code
between waits (its checks, ``volviz render`` subprocesses) are not counted. An input event the test delivers itself
(``QApplication.sendEvent``, qtbot's mouse and key functions) is handled at once, outside the loop: each such
delivery counts as a gap of its own length, and so does each window call a test makes in place of a user's event
(``USER_CALLS``: File > Open's ``open_path``, an action's ``trigger``, ...; until survey 16 these were not counted:
opening a DEM read it there for 128 ms). ``blocked`` is a gap less the time the
machine took (``loop_latency``: the GUI thread's and the renderer's run-queue waits, steal). For each test one JSON
line: the gaps over 100 ms blocked, each with the GUI thread's most sampled stacks in it (app, volviz and test
frames; a sampling thread needs the GIL, so a stack in C++ code that holds it is seen only at its edges).
docs/bench/flow-gaps.md has a survey and what it found.
"""
from __future__ import annotations

import faulthandler
import json
import os
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path
from typing import Any, Iterator

import pytest

from loop_latency import LIMIT_S, _RendererThreads, _run_queue_wait_s, _steal_s

_waiting = {"depth": 0, "serial": 0}   # nesting of the qtbot waits now; the outermost waits begun so far


def _counted(wait: Any) -> Any:
    def counted(self: Any, *args: Any, **kwargs: Any) -> Any:
        if _waiting["depth"] == 0:
            _waiting["serial"] += 1
        _waiting["depth"] += 1
        try:
            return wait(self, *args, **kwargs)
        finally:
            _waiting["depth"] -= 1
    return counted


_deliveries: list[tuple[float, float, dict[str, float]]] = []   # (start, end, machine time lost) of input events


_delivering = {"depth": 0}   # nesting of the timed calls (an action's trigger delivers events): the outermost counts


def _timed(deliver: Any) -> Any:
    def timed(*args: Any, **kwargs: Any) -> Any:
        start, wait, steal = time.perf_counter(), _run_queue_wait_s(), _steal_s()
        _delivering["depth"] += 1
        try:
            return deliver(*args, **kwargs)
        finally:
            _delivering["depth"] -= 1
            if _delivering["depth"] == 0:
                _deliveries.append((start, time.perf_counter(),
                                    {"lost": (_run_queue_wait_s() - wait) + (_steal_s() - steal)}))
    return timed


#: the window's calls a test makes in place of a user's event (File > Open, a menu action, an edit in a dock, the
#: timeline, an export), each a stall of its own length as an input event's delivery is
USER_CALLS = {"volviz_app.window:MainWindow": ("open_path", "open_demo", "open_demo_volume", "save_session"),
              "PySide6.QtGui:QAction": ("trigger",),
              "volviz_app.docks.tf_editor:TransferFunctionEditor": ("edit", "apply_preset"),
              "volviz_app.docks.timeline:Timeline": ("set_time",),
              "volviz_app.export_dialogs:ExportDialogs": ("screenshot",)}


def pytest_configure(config: Any) -> None:
    from PySide6.QtWidgets import QApplication
    from pytestqt.qtbot import QtBot

    QtBot.wait = _counted(QtBot.wait)             # type: ignore[method-assign]
    QtBot.waitUntil = _counted(QtBot.waitUntil)   # type: ignore[method-assign]
    QApplication.sendEvent = staticmethod(_timed(QApplication.sendEvent))   # type: ignore[method-assign]
    for name in ("mousePress", "mouseRelease", "mouseClick", "mouseDClick", "mouseMove", "keyPress", "keyRelease",
                 "keyClick", "keyClicks", "keySequence"):
        found = QtBot.__dict__.get(name)
        if isinstance(found, staticmethod):   # (pytest-qt's input functions are static methods)
            setattr(QtBot, name, staticmethod(_timed(found.__func__)))
        elif found is not None:
            setattr(QtBot, name, _timed(found))
    import importlib

    for spec, names in USER_CALLS.items():
        module, _, name = spec.partition(":")
        cls = getattr(importlib.import_module(module), name)
        for method in names:
            setattr(cls, method, _timed(getattr(cls, method)))


def _stack(dump: str, thread: int, depth: int = 14) -> str:
    """The app's, volviz's and the tests' frames of ``thread``'s stack in a ``faulthandler`` dump of every thread
    (innermost first), after its innermost frame. ``faulthandler`` reads the stacks without taking a reference to a
    frame: a sampling thread that held one could be the last holder of a frame the GUI thread had left, and free its
    locals (VTK objects among them) off the GUI thread, which froze a render (test_flow_play_orbit, 2 runs of 2)."""
    block = dump.split(f"Thread 0x{thread:016x}", 1)[-1].split("\n\n", 1)[0] if f"0x{thread:016x}" in dump else ""
    out: list[str] = []
    for line in block.splitlines()[1:]:
        if len(out) >= depth or not line.strip().startswith("File "):
            continue
        name, _, rest = line.strip()[6:].partition('", line ')
        number, _, function = rest.partition(" in ")
        if not out or any(part in name for part in ("/app/", "/volviz/", "/tests/")) and "gap_survey" not in name:
            out.append(f"{Path(name).name}:{function}:{number}")
    return " < ".join(out)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_call(item: Any) -> Iterator[None]:
    from PySide6.QtCore import QTimer
    from PySide6.QtWidgets import QApplication

    if QApplication.instance() is None:
        yield
        return
    renderers, start = _RendererThreads(), time.perf_counter()
    gaps: list[tuple[float, float, float, str]] = []      # (start s, gap s, blocked s, "loop" or "input")
    samples: list[tuple[float, str]] = []
    main, running = threading.main_thread().ident, [True]

    def sample() -> None:
        with tempfile.TemporaryFile("w+") as dump:
            while running[0]:
                time.sleep(0.005)
                dump.seek(0)
                dump.truncate()
                faulthandler.dump_traceback(dump, all_threads=True)
                dump.seek(0)
                samples.append((time.perf_counter(), _stack(dump.read(), main or 0)))

    threading.Thread(target=sample, daemon=True).start()
    last = {"t": start, "wait": _run_queue_wait_s(), "steal": _steal_s(), "serial": _waiting["serial"],
            "in": _waiting["depth"] > 0}
    last_renderers = renderers.waits()

    def tick() -> None:
        nonlocal last_renderers
        now, wait, steal, waits = time.perf_counter(), _run_queue_wait_s(), _steal_s(), renderers.waits()
        if _waiting["depth"] > 0 and last["in"] and last["serial"] == _waiting["serial"]:
            gap = now - last["t"]
            renderer = max((w - last_renderers.get(tid, w) for tid, w in waits.items()), default=0.0)
            lost = min(gap, (wait - last["wait"]) + renderer + (steal - last["steal"]))
            gaps.append((last["t"] - start, gap, gap - lost, "loop"))
        last.update(t=now, wait=wait, steal=steal, serial=_waiting["serial"], **{"in": _waiting["depth"] > 0})
        last_renderers = waits

    timer = QTimer()
    timer.setInterval(10)
    timer.timeout.connect(tick)
    timer.start()
    _deliveries.clear()
    try:
        yield
    finally:
        timer.stop()
        running[0] = False
        gaps += [(a - start, b - a, max(0.0, b - a - lost["lost"]), "input") for a, b, lost in _deliveries]
        over = sorted(g for g in gaps if g[2] >= LIMIT_S)
        found = []
        for at, gap, blocked, kind in over:
            seen = Counter(stack for t, stack in samples if start + at <= t <= start + at + gap)
            found.append({"at_s": round(at, 2), "kind": kind, "gap_ms": round(gap * 1e3),
                          "blocked_ms": round(blocked * 1e3), "stacks": seen.most_common(4)})
        with open(os.environ.get("GAP_SURVEY", "gap_survey.jsonl"), "a") as out:
            out.write(json.dumps({"test": item.nodeid, "ticks": len(gaps),
                                  "max_blocked_ms": round(1e3 * max((g[2] for g in gaps), default=0.0)),
                                  "over_100ms": found}) + "\n")
