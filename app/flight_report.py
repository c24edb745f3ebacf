"""``volviz-app --flight-report MD [TARGET]``: fly through a natural scene (default: the shipped Yukon session) with W
held for ``--flight-seconds``, as a keyboard's auto-repeat sends it (30 presses a second), in the real window at
1366x768, and write what the user got: frames drawn per second, camera steps, and the event loop's longest gaps
(a 10 ms timer on the GUI thread; a gap is how long the window could not answer), the size the flight's frames were
drawn at (``volviz_app.reduced_frames``), and what the stop costs: the time from the release to the full-resolution
frame and the longest gap in it. Issue #28 asks for the frame rate of a 30-second flight on this machine; the report
says the command and the load it ran under."""
from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any

from PySide6.QtCore import QEvent, Qt, QTimer
from PySide6.QtGui import QKeyEvent
from PySide6.QtWidgets import QApplication

from .smoke import TIMEOUT_S, pump_events

YUKON = Path(__file__).resolve().parents[1] / "resources" / "sessions" / "yukon.json"
REPEAT_S = 1.0 / 30.0        # X's default auto-repeat rate
SIZE = (1366, 768)


def _cpu_wait_s() -> float:
    """Seconds the calling thread has waited runnable for a CPU (``/proc/thread-self/schedstat``; 0 elsewhere)."""
    try:
        return int(Path("/proc/thread-self/schedstat").read_text().split()[1]) * 1e-9
    except (OSError, IndexError, ValueError):
        return 0.0


class _Gaps:
    """The gaps between the ticks of a 10 ms timer on the GUI thread, and each gap less the time the GUI thread
    waited for a CPU in it (``blocked``: what the app itself held the loop for; a shared machine takes the rest)."""

    def __init__(self) -> None:
        self.gaps: list[float] = []
        self.blocked: list[float] = []
        self._last, self._wait = time.perf_counter(), _cpu_wait_s()
        self.timer = QTimer(interval=10)
        self.timer.timeout.connect(self._tick)
        self.timer.start()

    def _tick(self) -> None:
        now, wait = time.perf_counter(), _cpu_wait_s()
        self.gaps.append(now - self._last)
        self.blocked.append(max(0.0, now - self._last - (wait - self._wait)))
        self._last, self._wait = now, wait


def _key(widget: Any, kind: QEvent.Type, repeat: bool) -> None:
    QApplication.sendEvent(widget, QKeyEvent(kind, Qt.Key.Key_W, Qt.KeyboardModifier.NoModifier, "w", repeat))


def fly(app: Any, window: Any, target: str | None, seconds: float) -> dict[str, Any]:
    """Open ``target``, wait for its full image, hold W for ``seconds`` in fly mode; the flight's figures."""
    window.resize(*SIZE)
    window.show()
    window.open_path(target or YUKON)
    loaded = pump_events(app, lambda: window.controller is not None and not window.progress_bar.isVisible()
                         and not window.jobs.busy(), TIMEOUT_S)
    if not loaded or window.controller.nature is None:
        raise RuntimeError(f"{target or YUKON}: no natural scene was shown within {TIMEOUT_S:.0f} s")
    pump_events(app, lambda: False, 1.0)
    window.action_fly.trigger()
    pump_events(app, lambda: not window.jobs.busy(), TIMEOUT_S)   # the coarse terrain fly mode makes at once
    ren_win, canvas, reduced = window.plotter.ren_win, window.plotter.interactor, window.fly.frames
    viewport = tuple(int(v) for v in ren_win.GetSize())
    frames = [0]
    observer = ren_win.AddObserver("EndEvent", lambda *a: frames.__setitem__(0, frames[0] + 1))
    gaps = _Gaps()
    began = time.perf_counter()
    _key(canvas, QEvent.Type.KeyPress, False)
    while time.perf_counter() - began < seconds:
        pump_events(app, lambda: False, REPEAT_S)
        _key(canvas, QEvent.Type.KeyPress, True)
    _key(canvas, QEvent.Type.KeyRelease, False)
    flown = time.perf_counter() - began
    gaps.timer.stop()
    ren_win.RemoveObserver(observer)
    drawn_reduced, drawn_at = reduced.renders, reduced.last_size
    stop = _stop(app, window, flown + began)
    worst = sorted(gaps.gaps)
    return {"seconds": flown, "frames": frames[0], "fps": frames[0] / flown, "steps": window.fly.steps,
            "gap_max_ms": 1e3 * worst[-1], "gap_p99_ms": 1e3 * worst[int(0.99 * (len(worst) - 1))],
            "gaps_over_100ms": sum(g > 0.1 for g in worst), "blocked_max_ms": 1e3 * max(gaps.blocked),
            "blocked_over_100ms": sum(b > 0.1 for b in gaps.blocked), "load": os.getloadavg()[0],
            "size": f"{SIZE[0]}x{SIZE[1]}", "target": str(target or "resources/sessions/yukon.json"),
            "viewport": f"{viewport[0]}x{viewport[1]}", "viewport_class": type(window.plotter).__name__,
            "reduced_frames": drawn_reduced,
            "reduced_size": f"{drawn_at[0]}x{drawn_at[1]}", **stop}


def _stop(app: Any, window: Any, released: float) -> dict[str, float]:
    """After the release: seconds until the full-resolution frame was drawn (the reduced frames over and the
    views' full-size updates shown), that frame's render and the longest event-loop gap meanwhile, in ms."""
    ren_win, canvas, reduced = window.plotter.ren_win, window.plotter.interactor, window.fly.frames
    gaps = _Gaps()
    started, full = [0.0], [0.0, 0.0]   # a render's start; the full-resolution frame's end and render time

    def ended(*args: Any) -> None:
        if not reduced.active and getattr(canvas, "_in_paint", False) and not full[0]:
            full[0], full[1] = time.perf_counter(), time.perf_counter() - started[0]

    observers = [ren_win.AddObserver("StartEvent", lambda *a: started.__setitem__(0, time.perf_counter())),
                 ren_win.AddObserver("EndEvent", ended)]
    pump_events(app, lambda: bool(full[0]), TIMEOUT_S)
    pump_events(app, lambda: False, 0.05)     # the gap that frame's paint made
    gaps.timer.stop()
    for tag in observers:
        ren_win.RemoveObserver(tag)
    return {"stop_s": (full[0] or time.perf_counter()) - released, "stop_render_ms": 1e3 * full[1],
            "stop_gap_max_ms": 1e3 * max(gaps.gaps, default=0.0)}


def markdown(result: dict[str, Any], command: str) -> str:
    r = result
    return "\n".join([
        "# A flight through the natural scene in the app", "",
        f"Command: `{command}` (window {r['size']}, load average at the end {r['load']:.1f}).", "",
        f"W held for {r['seconds']:.1f} s over {r['target']}, 30 key repeats a second: {r['steps']} camera steps, "
        f"{r['frames']} frames drawn, **{r['fps']:.1f} frames per second**.", "",
        f"Event-loop gaps (10 ms timer on the GUI thread): longest {r['gap_max_ms']:.0f} ms, 99th percentile "
        f"{r['gap_p99_ms']:.0f} ms, {r['gaps_over_100ms']} over 100 ms. These are wall-clock gaps: time the machine "
        "gave to other processes is in them. Less the time the GUI thread waited for a CPU in each: longest "
        f"{r['blocked_max_ms']:.0f} ms, {r['blocked_over_100ms']} over 100 ms (the renderer's threads' waits stay in).",
        "",
        f"Frames drawn while flying at {r['reduced_size']} ({r['reduced_frames']} of them), magnified to the "
        f"{r['viewport']} viewport ({r['viewport_class']}). After the release: the full-resolution frame "
        f"{r['stop_s']:.2f} s later (the views' full-size updates made in the background), its render "
        f"{r['stop_render_ms']:.0f} ms; longest event-loop gap from the release to it {r['stop_gap_max_ms']:.0f} ms.",
        ""])


def flight_report(app: Any, window: Any, target: str | None, out: Path, seconds: float) -> int:
    """Fly, write the report to ``out``, print it; 0 when the flight ran."""
    from volviz.io.atomic import atomic_write_text

    result = fly(app, window, target, seconds)
    window.dirty = False
    command = f"volviz-app --flight-report {out} --flight-seconds {seconds:g}" + (f" {target}" if target else "")
    text = markdown(result, command)
    atomic_write_text(out, text)
    print(text)
    window.close()
    return 0
