"""A component's on/off settings are one titled check box each (issue #28, found driving the app as a new user): the
scene dock's form showed "[ ] Log color scale  [ ]", a box that only marks the field as set in the session, carrying
the title, and an untitled box beside it that holds the value. A click on the words "Log color scale" stored
``log_scale: false``, marked the session edited and left the picture as it was; the untitled box took a click only
on its 13-pixel square."""
from __future__ import annotations

import json

import numpy as np
from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QCheckBox, QStyle

from flows import assert_matches_render, open_settled, screen, wait_settled


def _box_titled(window, title: str) -> QCheckBox:
    """The check box of the scene dock's settings form whose text is ``title``: what the user reads and clicks."""
    form = window.scene_tree.form
    boxes = [box for box in form.findChildren(QCheckBox) if box.text() == title]
    assert len(boxes) == 1, [box.text() for box in form.findChildren(QCheckBox)]
    return boxes[0]


def _on_the_words(box: QCheckBox) -> QPoint:
    """The middle of the box's text (right of its square), where a reader clicks."""
    style = box.style()
    text_left = (style.pixelMetric(QStyle.PixelMetric.PM_IndicatorWidth, None, box)
                 + style.pixelMetric(QStyle.PixelMetric.PM_CheckBoxLabelSpacing, None, box))
    words = box.fontMetrics().horizontalAdvance(box.text())
    assert text_left + words <= box.width(), (text_left, words, box.width())
    return QPoint(text_left + words // 2, box.height() // 2)


def test_a_click_on_the_words_log_color_scale_turns_it_on(qtbot, make_window, tmp_path) -> None:
    """HeadMRVolume.mhd: a click on the middle of the words "Log color scale" in the scene dock puts the volume in log
    color scale (the session saves ``log_scale: true``, the picture changes, and matches ``volviz render`` of the
    saved session); a second click turns it off again: the first picture exactly. The form has one box per on/off
    setting (Log color scale, Shading), none untitled."""
    window = open_settled(qtbot, make_window, "volumes/HeadMRVolume.mhd")
    linear = screen(window)
    window.scene_dock.raise_()
    qtbot.waitUntil(lambda: window.scene_tree.form is not None and "log_scale" in window.scene_tree.form.rows)
    boxes = window.scene_tree.form.findChildren(QCheckBox)
    assert sorted(box.text() for box in boxes) == ["Log color scale", "Shading"]   # before: two more, untitled
    box = _box_titled(window, "Log color scale")
    qtbot.waitUntil(box.isVisible)
    qtbot.mouseClick(box, Qt.MouseButton.LeftButton, pos=_on_the_words(box))
    component = window.session.components[0].id
    qtbot.waitUntil(lambda: window.controller.component(component).settings.get("log_scale") is True,
                    timeout=20000)   # before the fix: log_scale stayed False
    wait_settled(qtbot, window)
    logged = screen(window)
    assert float(np.sqrt(np.mean((logged - linear) ** 2))) > 2.0    # the log scale changed the picture
    assert_matches_render(window, tmp_path, "log", max_rmse=1.0, max_off=0.002)
    assert json.loads((tmp_path / "log.json").read_text())["components"][0]["settings"]["log_scale"] is True

    box = _box_titled(window, "Log color scale")        # the form is made again for the new settings
    qtbot.waitUntil(box.isVisible)
    assert box.isChecked()
    qtbot.mouseClick(box, Qt.MouseButton.LeftButton, pos=_on_the_words(box))
    qtbot.waitUntil(lambda: window.controller.component(component).settings.get("log_scale") is False,
                    timeout=20000)
    wait_settled(qtbot, window)
    assert np.array_equal(screen(window), linear)
