"""File > Export Screenshot and File > Export Movie: the dialogs, and the checks made before anything renders.

A screenshot is made at exactly the size asked (issue #28: 512x384 set gave 512x365): the screenshot dialog
(``ScreenshotDialog``) starts at the render settings' export size, takes any size up to ``MAX_IMAGE_SIDE`` a side
whatever the window's shape, or the window's size times a scale factor, and a transparent background (alpha 0 where
nothing is drawn). Its format follows the file's extension (PNG, JPEG, TIFF), and any other extension, a size this
machine cannot render, or transparency in a JPEG is refused with a message before rendering
(``volviz.render.export``). A movie is an orbit of the current view (no recorded path needed), a recorded camera
path, or a run through the time series, at the size and frame rate its dialog (``MovieDialog``) sets."""
from __future__ import annotations

import os
from typing import Any, Optional

from PySide6.QtWidgets import (QCheckBox, QComboBox, QDialog, QDialogButtonBox, QDoubleSpinBox, QFormLayout,
                               QHBoxLayout, QLabel, QSpinBox, QWidget)

from volviz.argtypes import MAX_IMAGE_SIDE

IMAGE_FILTER = ("Images (*.png *.jpg *.jpeg *.tif *.tiff);;PNG image (*.png);;JPEG image (*.jpg *.jpeg);;"
                "TIFF image (*.tif *.tiff)")
MOVIE_FILTER = "MP4 video (*.mp4);;QuickTime movie (*.mov);;Folder of PNG frames (*)"
ORBIT = "Orbit around the current view"
THROUGH_TIME = "Through time"
MOVIE_FPS = 24.0


def size_boxes(size: tuple[int, int], least: int = 1, step: int = 1) -> tuple[QSpinBox, QSpinBox, QHBoxLayout]:
    """Width and height boxes (``least`` .. ``MAX_IMAGE_SIDE`` pixels) at ``size``, and the row that shows them."""
    boxes = QSpinBox(), QSpinBox()
    row = QHBoxLayout()
    for box, value in zip(boxes, size):
        box.setRange(least, MAX_IMAGE_SIDE)
        box.setSingleStep(step)
        box.setSuffix(" px")
        box.setValue(int(value))
    row.addWidget(boxes[0])
    row.addWidget(QLabel("x"))
    row.addWidget(boxes[1])
    return boxes[0], boxes[1], row


def ok_cancel(dialog: QDialog) -> QDialogButtonBox:
    buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel)
    buttons.accepted.connect(dialog.accept)
    buttons.rejected.connect(dialog.reject)
    return buttons


def scaled_size(viewport: tuple[int, int], scale: float) -> tuple[int, int]:
    """The viewport's size times ``scale``, each side 1 .. ``MAX_IMAGE_SIDE``."""
    w, h = (min(max(int(round(int(side) * scale)), 1), MAX_IMAGE_SIDE) for side in viewport[:2])
    return w, h


class ScreenshotDialog(QDialog):
    """The screenshot's size (``width`` and ``height``, or ``of_window`` times ``scale``) and ``transparent``
    background; ``chosen()`` reads them."""

    def __init__(self, parent: QWidget, size: tuple[int, int], viewport: tuple[int, int]) -> None:
        super().__init__(parent)
        self.setWindowTitle("Export screenshot")
        self.viewport = (int(viewport[0]), int(viewport[1]))
        self.width_box, self.height_box, size_row = size_boxes(size)
        self.of_window = QCheckBox(f"The window's size ({self.viewport[0]}x{self.viewport[1]}) times")
        self.scale = QDoubleSpinBox()
        self.scale.setRange(0.25, 8.0)
        self.scale.setSingleStep(0.5)
        self.scale.setValue(2.0)
        self.scale.setSuffix("x")
        self.transparent = QCheckBox("Transparent background (PNG, TIFF)")
        window_row = QHBoxLayout()
        window_row.addWidget(self.of_window)
        window_row.addWidget(self.scale)
        buttons = ok_cancel(self)
        self.ok_button = buttons.button(QDialogButtonBox.StandardButton.Ok)
        form = QFormLayout(self)
        form.addRow("Size:", size_row)
        form.addRow("", window_row)
        form.addRow("", QLabel(f"Any size up to {MAX_IMAGE_SIDE} pixels a side, whatever the window's shape."))
        form.addRow("", self.transparent)
        form.addRow(buttons)
        self.of_window.toggled.connect(self._follow_window)
        self.scale.valueChanged.connect(lambda _: self._follow_window(self.of_window.isChecked()))

    def _follow_window(self, on: bool) -> None:
        """With ``of_window`` the size boxes show the window's size times the scale, and are not edited."""
        self.width_box.setEnabled(not on)
        self.height_box.setEnabled(not on)
        if on:
            w, h = scaled_size(self.viewport, self.scale.value())
            self.width_box.setValue(w)
            self.height_box.setValue(h)

    def chosen(self) -> tuple[tuple[int, int], bool]:
        """(the size in pixels, transparent background)."""
        return (self.width_box.value(), self.height_box.value()), self.transparent.isChecked()


class MovieDialog(QDialog):
    """Which movie (one of ``choices``), its size (the render settings' export size at first, even sides for the
    video encoder) and frames per second; ``chosen()`` reads them. The movie's length is the orbit's turn, the
    camera path's duration or the timeline's playback, so the frame rate sets how many frames are rendered."""

    def __init__(self, parent: QWidget, choices: list[str], label: str, size: tuple[int, int]) -> None:
        super().__init__(parent)
        self.setWindowTitle("Export movie")
        self.label = QLabel(label)
        self.combo = QComboBox()
        self.combo.addItems(choices)
        self.width_box, self.height_box, size_row = size_boxes((size[0] + size[0] % 2, size[1] + size[1] % 2),
                                                               least=16, step=2)
        self.fps = QDoubleSpinBox()
        self.fps.setRange(1.0, 120.0)
        self.fps.setDecimals(1)
        self.fps.setValue(MOVIE_FPS)
        self.fps.setSuffix(" frames/s")
        form = QFormLayout(self)
        form.addRow(self.label)
        form.addRow(self.combo)
        form.addRow("Size:", size_row)
        form.addRow("Frame rate:", self.fps)
        form.addRow(ok_cancel(self))

    def labelText(self) -> str:   # noqa: N802 - as QInputDialog's, which this dialog replaced
        return self.label.text()

    def comboBoxItems(self) -> list[str]:   # noqa: N802
        return [self.combo.itemText(i) for i in range(self.combo.count())]

    def setTextValue(self, text: str) -> None:   # noqa: N802
        self.combo.setCurrentText(text)

    def chosen(self) -> tuple[str, tuple[int, int], float]:
        """(the movie, its size in pixels, frames per second)."""
        return self.combo.currentText(), (self.width_box.value(), self.height_box.value()), self.fps.value()


class ExportDialogs:
    """The export menu entries of ``window`` (``ask_file``, ``export_screenshot``, ``export_movie``, ``show_error``).
    The open choice of movie is kept as ``movie_dialog``."""

    def __init__(self, window: Any) -> None:
        self.window = window
        self.movie_dialog: Optional[MovieDialog] = None
        self.screenshot_dialog: Optional[ScreenshotDialog] = None

    def refused(self, path: str | os.PathLike, movie: bool = False, size: Optional[tuple[int, int]] = None,
                transparent: bool = False) -> bool:
        """Check what ``path`` would receive (an image of ``size``, with alpha when ``transparent``); a refusal is
        shown as a message (True: refused)."""
        from volviz.io.atomic import OutputPathError
        from volviz.render.export import ExportError, check_image_size, check_output, check_transparency

        try:
            check_output(path, movie=movie)
            if size is not None:
                check_image_size(size)
            if transparent:
                check_transparency(path)
        except (ExportError, OutputPathError) as exc:
            self.window.show_error("Cannot export", f"{exc}\n\nChoose another name, format or size.")
            return True
        return False

    def screenshot_size(self) -> tuple[int, int]:
        """The render settings' export size, exactly."""
        width, height = self.window.session.render.size
        return int(width), int(height)

    def screenshot(self, path: str | os.PathLike, size: Optional[tuple[int, int]] = None,
                   transparent: bool = False) -> bool:
        """Export the current view to ``path`` at exactly ``size`` (default ``screenshot_size``), without the
        background when ``transparent`` (False: refused, with a message)."""
        size = size or self.screenshot_size()
        if self.refused(path, size=size, transparent=transparent):
            return False
        self.window.export_screenshot(path, size, transparent)
        return True

    def ask_screenshot(self) -> ScreenshotDialog:
        """The size and background (non-blocking ``ScreenshotDialog``), then where to write the image."""
        viewport = self.window.plotter.window_size
        dialog = ScreenshotDialog(self.window, self.screenshot_size(), (viewport[0], viewport[1]))

        def chosen() -> None:
            size, transparent = dialog.chosen()
            self.window.ask_file("Export screenshot", IMAGE_FILTER,
                                 lambda path: self.screenshot(path, size, transparent), save=True,
                                 default_name="volviz.png")

        dialog.accepted.connect(chosen)
        dialog.open()
        self.screenshot_dialog = dialog
        return dialog

    def movie_choices(self) -> list[str]:
        controller = self.window.controller
        through_time = bool(controller is not None and controller.time_series())
        return [ORBIT] + list(self.window.session.camera_paths) + ([THROUGH_TIME] if through_time else [])

    def movie(self, path: str | os.PathLike, choice: str, size: Optional[tuple[int, int]] = None,
              fps: float = MOVIE_FPS) -> bool:
        """Export the movie ``choice`` (``movie_choices``) to ``path`` at ``size`` (default: the render settings'
        export size) and ``fps`` (False: the name or size was refused)."""
        if self.refused(path, movie=True, size=size):
            return False
        orbit, through_time = choice == ORBIT, choice == THROUGH_TIME
        self.window.export_runs.export_movie(path, None if orbit or through_time else choice, through_time, fps=fps,
                                             size=size, orbit=orbit,
                                             duration=self.playback_seconds() if through_time else None)
        return True

    def playback_seconds(self) -> float:
        """How long the timeline plays the series once at its speed (time steps per second): the length of a movie
        through time. It was one second per unit of the data's time, whatever the unit: the monthly sea-surface
        temperatures (t in days, 15 .. 705) made 16,561 frames for 24 steps, hours of rendering (issue #28)."""
        timeline = self.window.timeline
        return max(len(timeline.steps) - 1, 1) / float(timeline.speed.value())

    def ask_movie(self) -> MovieDialog:
        """Which movie, its size and frame rate (non-blocking ``MovieDialog``), then where to write it."""
        choices = self.movie_choices()
        label = (f"Movie ({THROUGH_TIME.lower()}: {self.playback_seconds():.3g} s at the timeline's speed):"
                 if THROUGH_TIME in choices else "Movie:")
        dialog = MovieDialog(self.window, choices, label, self.screenshot_size())

        def chosen() -> None:
            choice, size, fps = dialog.chosen()
            self.window.ask_file("Export movie", MOVIE_FILTER, lambda path: self.movie(path, choice, size, fps),
                                 save=True, default_name="volviz.mp4")

        dialog.accepted.connect(chosen)
        dialog.open()
        self.movie_dialog = dialog
        return dialog
