"""``volviz-app --screenshot PNG [TARGET]``: open the demo scene (or TARGET), wait for its first complete image, save
the window as PNG and quit -- the check that an installed or packaged app starts and renders (``packaging/``)."""
from __future__ import annotations

import time
from pathlib import Path
from typing import Any

TIMEOUT_S = 180.0


def pump_events(app: Any, until: Any, seconds: float) -> bool:
    """Process Qt events until ``until()`` is true (True) or ``seconds`` have passed (False)."""
    start = time.perf_counter()
    while not until():
        if time.perf_counter() - start > seconds:
            return False
        app.processEvents()
        time.sleep(0.005)
    return True


def show_target(app: Any, window: Any, target: str | None) -> bool:
    """Show ``window`` with ``target`` (None: the demo) and wait for its first complete image, an error or the
    layout dialog of headerless data; False when none came within ``TIMEOUT_S``."""
    window.resize(1024, 700)
    window.show()
    pump_events(app, lambda: window.isVisible(), 10.0)
    if target:
        window.open_path(target)
    else:
        window.open_demo()
    return pump_events(app, lambda: window.error_dialog is not None or window.raw_dialog is not None or (
        window.controller is not None and not window.progress_bar.isVisible()), TIMEOUT_S)


def screenshot(app: Any, window: Any, target: str | None, out: Path) -> int:
    """Show ``target`` (None: the demo) in ``window``, save its grab to ``out``; 0 when it showed, 1 otherwise."""
    shown = show_target(app, window, target)
    pump_events(app, lambda: False, 0.5)
    window.plotter.render()
    (window.raw_dialog or window).grab().save(str(out))    # headerless data: the dialog asking its layout
    window.dirty = False
    failed = window.error_dialog is not None or not shown
    if failed:
        print(f"volviz-app: the scene was not shown within {TIMEOUT_S:.0f} s" if not shown else
              "volviz-app: opening the scene gave an error (see the screenshot)")
    window.close()
    return 1 if failed else 0
