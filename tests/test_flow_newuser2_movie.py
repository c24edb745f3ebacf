"""File > Export Movie through time lasts as long as the timeline plays the series (issue #28, found driving the app
as a new user): the movie took one second per unit of the data's time, whatever the unit, so the monthly sea-surface
temperatures of tos_O1_2001-2002.nc (24 steps, t in days from 15 to 705) made a movie of 16,561 frames, hours of
rendering with no way to shorten it in the dialog."""
from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QComboBox

from flows import open_settled, pick_combo_item, wait_settled
from test_flow_export import assert_within_bound, choose_file, read_png, save_as, volviz_render


def test_a_movie_through_time_plays_the_steps_at_the_timelines_speed(qtbot, make_window, tmp_path) -> None:
    """tos_O1_2001-2002.nc, the timeline's speed typed as 23 steps per second, File > Export Movie, "Through time",
    a folder of PNG frames: the dialog says 1 s, the movie has 25 frames (one second at 24 fps, both ends), and its
    first frame matches ``volviz render`` of the saved session (the first month) within the export flows' bound."""
    window = open_settled(qtbot, make_window, "ecosystem/tos_O1_2001-2002.nc")
    assert len(window.timeline.steps) == 24
    speed = window.timeline.speed
    speed.setFocus()
    qtbot.keyClick(speed, Qt.Key.Key_A, Qt.KeyboardModifier.ControlModifier)
    qtbot.keyClicks(speed, "23")
    qtbot.keyClick(speed, Qt.Key.Key_Return)
    assert speed.value() == 23.0
    saved = tmp_path / "tos.json"
    save_as(qtbot, window, saved)
    window.action_export_movie.trigger()
    dialog = window.export_dialogs.movie_dialog
    qtbot.waitUntil(lambda: dialog is not None and dialog.isVisible())
    assert dialog.labelText() == "Movie (through time: 1 s at the timeline's speed):"
    pick_combo_item(qtbot, dialog.findChild(QComboBox), "Through time")
    dialog.accept()
    frames = tmp_path / "frames"
    choose_file(qtbot, window, "Export movie", frames)
    qtbot.waitUntil(lambda: " of " in window.status_label.text() or window.export_result is not None, timeout=60000)
    assert window.export_result is not None or " of 25:" in window.status_label.text(), window.status_label.text()
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=300000)   # before the fix: frame 1 of 16561
    assert window.export_result, window.status_label.text()
    assert len(list(frames.glob("frame_*.png"))) == 25
    wait_settled(qtbot, window)
    size = tuple(window.session.render.size)
    assert_within_bound(read_png(frames / "frame_00000.png"), volviz_render(saved, tmp_path / "reference.png", size))
