"""Regenerate the README's screenshots of the main window (run under Xvfb):

    xvfb-run -a -s "-screen 0 1600x1000x24" .venv/bin/python -m volviz_app.screenshots docs/screenshots

With ``--layout`` only the window's default layout at a laptop's 1366x740 and at 1280x860 is shot.

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


def _iso_session(data_path: Path) -> Path:
    """A session showing three semi-transparent isosurfaces of ``data_path`` (in a temporary folder)."""
    import json
    import tempfile

    styles = [{"value": 0.6, "color": [0.2, 0.45, 1.0], "opacity": 0.3},
              {"value": 1.4, "color": [0.3, 0.9, 0.4], "opacity": 0.35},
              {"value": 2.8, "color": [1.0, 0.3, 0.15], "opacity": 0.6}]
    doc = {"format": "volviz-session", "version": 1, "datasets": [{"id": "d", "path": str(data_path)}],
           "components": [{"id": "isosurfaces", "type": "isosurface", "dataset": "d", "settings": {"styles": styles}}]}
    path = Path(tempfile.mkdtemp()) / "isosurfaces.json"
    path.write_text(json.dumps(doc))
    return path


LAYOUT_SIZES = ((1366, 740), (1280, 860))  # a 1366x768 laptop screen less its panel; the default window


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    layout_only = "--layout" in args  # only the window at LAYOUT_SIZES (the default layout on the demo scene)
    args = [a for a in args if a != "--layout"]
    out = Path(args[0] if args else "docs/screenshots")
    out.mkdir(parents=True, exist_ok=True)
    data = Path(os.environ.get("VOLVIZ_DATA", Path(__file__).resolve().parent.parent.parent / "shared" / "data"))

    from PySide6.QtWidgets import QApplication

    from .window import MainWindow

    app = QApplication.instance() or QApplication([])
    window = MainWindow()
    window.resize(1400, 860)
    window.show()
    window.layout_keeper.arrange()  # the default arrangement, whatever a previous launch left

    def shot(name: str) -> None:
        for _ in range(5):
            app.processEvents()
            time.sleep(0.05)
        window.grab().save(str(out / f"{name}.png"))
        print(f"wrote {out / name}.png")

    window.open_demo()
    _wait(app, window)
    for width, height in LAYOUT_SIZES:
        window.resize(width, height)
        shot(f"window-{width}x{height}")
    if layout_only:
        window.close()
        return 0
    window.resize(1400, 860)
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
    window.open_path(_iso_session(data / "bluntfin" / "bluntfinxyz.bin"))
    _wait(app, window)
    window.clipping.add_plane()
    window.clipping.set_plane(0, (0.0, 0.0, -1.0), -3.0)  # keep z <= 3
    window.render_settings.iso_mode.setCurrentText("4pass")
    _wait(app, window)
    window.clip_dock.raise_()
    window.clipping.show_widget.setChecked(True)
    for _ in range(100):  # the background overlay render
        app.processEvents()
        time.sleep(0.02)
    shot("clipping-isosurfaces-4pass")
    window.dirty = False
    window.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
