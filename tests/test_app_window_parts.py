"""The window's parts are objects given their collaborators (issue #31, the window composed, not mixed in): a part
works beside any object that holds the shown scene (``volviz_app.shown_scene.ShownScene``) and a plain
``QMainWindow``, without a ``MainWindow``, so it reads and writes nothing of the window but what it was given."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional

import pytest

pytest.importorskip("PySide6")

from PySide6.QtCore import QSettings  # noqa: E402
from PySide6.QtWidgets import QLabel, QMainWindow, QMenu  # noqa: E402

from volviz.session import Session, load  # noqa: E402
from volviz_app.recent import RecentFiles  # noqa: E402
from volviz_app.session_files import SessionFiles  # noqa: E402


@dataclass
class Shown:
    """A shown scene with no controller yet (``ShownScene``)."""

    session: Session = field(default_factory=Session)
    session_path: Optional[Path] = None
    datasets: dict[str, Any] = field(default_factory=dict)
    controller: Any = None
    title: str = "demo scene"
    dirty: bool = False


def test_session_files_saves_the_shown_scene_without_a_main_window(qtbot, tmp_path: Path) -> None:
    window = QMainWindow()
    qtbot.addWidget(window)
    settings = QSettings(str(tmp_path / "settings.ini"), QSettings.Format.IniFormat)
    recent = RecentFiles(settings, QMenu(window), lambda path: None)
    status, shown, errors = QLabel(), Shown(), []
    files = SessionFiles(shown, window, tmp_path / "recovery", recent, status, lambda path: None,
                         lambda paths: None, lambda *args, **kwargs: None, lambda title, text: errors.append(text))
    shown.session.render.size = (640, 480)

    files.set_dirty()
    assert shown.dirty and window.windowTitle() == "volviz — demo scene *"
    assert not files.autosave()            # nothing to recover without a scene drawn
    assert not (tmp_path / "recovery").exists()

    target = tmp_path / "views" / "a.json"
    target.parent.mkdir()
    assert files.save_session(target) and not errors
    assert shown.session_path == target and not shown.dirty
    assert window.windowTitle() == "volviz — a.json" and status.text() == "Saved a.json"
    assert recent.files() == [str(target.resolve())]
    saved = load(target)
    assert tuple(saved.render.size) == (640, 480)
    assert saved.layout["window_state"] == window.saveState().toBase64().toStdString()
    assert shown.session.layout["window_state"] == saved.layout["window_state"]   # the saved session is the shown one

    files.stop()
    assert not files.autosave_timer.isActive() and not files.edit_autosave_timer.isActive()
