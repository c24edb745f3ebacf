"""The app survives PySide6 6.12.0's lost references to None (``volviz_app.none_refs``)."""
from __future__ import annotations

import os
import subprocess
import sys

CALLS = 300_000   # void Qt calls: each takes one reference from None where the bug is (~125,000 at start-up)

SCRIPT = f"""
import sys
{{guard}}
from PySide6.QtWidgets import QApplication, QLabel
app = QApplication([])
label = QLabel()
for _ in range({CALLS}):
    label.setText("x")
print("alive")
"""


def _run(guard: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen"}
    return subprocess.run([sys.executable, "-c", SCRIPT.format(guard=guard)], capture_output=True, text=True,
                          timeout=300, env=env)


def test_many_void_qt_calls_do_not_abort_the_app() -> None:
    proc = _run("import volviz_app")
    assert proc.returncode == 0 and proc.stdout.strip() == "alive", proc.stderr[-500:]


def test_the_guard_is_what_keeps_it_alive_where_the_bug_is() -> None:
    from volviz_app.none_refs import affected

    proc = _run("")
    if affected():
        assert proc.returncode != 0 and "none_dealloc" in proc.stderr
    else:   # a fixed PySide6 or an immortal None: alive without the guard too
        assert proc.returncode == 0
