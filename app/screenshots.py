"""Regenerate the README's screenshots of the main window (run under Xvfb):

    xvfb-run -a -s "-screen 0 1600x1000x24" .venv/bin/python -m volviz_app.screenshots docs/screenshots

Each shot shows the real window on real data with one dock in front; the data comes from ../shared/data or
$VOLVIZ_DATA, the natural scene is the built-in demo.
"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path


def _wait(app, window, seconds: float = 120.0) -> None:
    start = time.time()
    while (window.controller is None or window.progress_bar.isVisible()) and time.time() - start < seconds:
        app.processEvents()
        time.sleep(0.02)
    for _ in range(10):
        app.processEvents()
        time.sleep(0.02)


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    out = Path(args[0] if args else "docs/screenshots")
    out.mkdir(parents=True, exist_ok=True)
    data = Path(os.environ.get("VOLVIZ_DATA", Path(__file__).resolve().parent.parent.parent / "shared" / "data"))

    from PySide6.QtWidgets import QApplication

    from volviz_app.window import MainWindow

    app = QApplication.instance() or QApplication([])
    window = MainWindow()
    window.resize(1400, 860)
    window.show()

    def shot(name: str) -> None:
        for _ in range(5):
            app.processEvents()
            time.sleep(0.05)
        window.grab().save(str(out / f"{name}.png"))
        print(f"wrote {out / name}.png")

    window.open_demo()
    _wait(app, window)
    window.scene_dock.raise_()
    shot("scene-tree-natural-scene")
    window.open_path(data / "volumes" / "neghip.slc")
    _wait(app, window)
    window.tf_editor.log_box.setChecked(True)
    window.tf_dock.raise_()
    shot("transfer-function-editor")
    window.settings_dock.raise_()
    window.stats_dock.raise_()
    shot("render-settings-and-statistics")
    window.open_path(data / "storm" / "Storm.pvm-t01")
    _wait(app, window)
    window.timeline.set_time(14.5)
    window.timeline_dock.raise_()
    shot("timeline-storm-series")
    window.dirty = False
    window.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
