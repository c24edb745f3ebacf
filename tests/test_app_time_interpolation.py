"""The scene's 4D interpolation switch (the Timeline dock's Interpolate) is kept by the session: a session saved with
it off opens with it off (the scene shows the nearest step, the dock's box unticked), the switch writes every time
series' ``interpolate`` setting, and a saved session keeps it. Real widgets under Xvfb."""
from __future__ import annotations

import json
from pathlib import Path

from test_app_background import write_pvm_series
from test_app_workflows import wait_loaded


def _session(tmp_path: Path, interpolate: bool) -> Path:
    write_pvm_series(tmp_path, 3, 12)
    path = tmp_path / "series.json"
    path.write_text(json.dumps({
        "format": "volviz-session", "version": 1,
        "datasets": [{"id": "series", "path": str(tmp_path / "blob.pvm-t%02d")}],
        "components": [{"id": "series", "type": "volume", "dataset": "series",
                        "settings": {"interpolate": interpolate}},
                       {"id": "iso", "type": "isosurface", "dataset": "series",
                        "settings": {"styles": [{"value": 120.0, "opacity": 0.5}]}}]}))
    return path


def test_the_interpolation_switch_is_kept_by_the_session(qtbot, make_window, tmp_path: Path) -> None:
    window = make_window()
    window.open_path(_session(tmp_path, interpolate=False))
    wait_loaded(qtbot, window)
    assert window.error_dialog is None
    assert window.controller.interpolate_time is False
    assert not window.timeline.interpolate.isChecked()

    window.timeline.interpolate.setChecked(True)                 # as the user ticks it
    qtbot.waitUntil(lambda: window.controller.interpolate_time, timeout=20000)
    settings = {c.id: c.settings.get("interpolate") for c in window.session.components}
    assert settings == {"series": True, "iso": True}
    window.timeline.interpolate.setChecked(False)
    qtbot.waitUntil(lambda: not window.controller.interpolate_time, timeout=20000)

    saved = tmp_path / "saved.json"
    assert window.save_session(saved)
    doc = json.loads(saved.read_text())
    assert {c["id"]: c["settings"].get("interpolate") for c in doc["components"]} == {"series": False, "iso": False}
    window.open_path(saved)
    wait_loaded(qtbot, window)
    assert window.controller.interpolate_time is False and not window.timeline.interpolate.isChecked()
