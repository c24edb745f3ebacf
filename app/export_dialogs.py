"""File > Export Screenshot and File > Export Movie: the dialogs, and the checks made before anything renders.

A screenshot has the viewport's aspect ratio by default (the render settings' export width, the height that keeps the
viewport's shape); its format follows the file's extension (PNG, JPEG, TIFF), and any other extension is refused with
a message before rendering (``volviz.render.export.check_output``). A movie is an orbit of the current view (no
recorded path needed), a recorded camera path, or a run through the time series."""
from __future__ import annotations

import os
from typing import Any, Optional

from PySide6.QtWidgets import QInputDialog

IMAGE_FILTER = ("Images (*.png *.jpg *.jpeg *.tif *.tiff);;PNG image (*.png);;JPEG image (*.jpg *.jpeg);;"
                "TIFF image (*.tif *.tiff)")
MOVIE_FILTER = "MP4 video (*.mp4);;QuickTime movie (*.mov);;Folder of PNG frames (*)"
ORBIT = "Orbit around the current view"
THROUGH_TIME = "Through time"


def aspect_size(viewport: tuple[int, int], width: int) -> tuple[int, int]:
    """An image ``width`` pixels wide with the viewport's aspect ratio (at least 1 pixel high)."""
    vw, vh = max(int(viewport[0]), 1), max(int(viewport[1]), 1)
    return int(width), max(int(round(width * vh / vw)), 1)


class ExportDialogs:
    """The export menu entries of ``window`` (``ask_file``, ``export_screenshot``, ``export_movie``, ``show_error``).
    The open choice of movie is kept as ``movie_dialog``."""

    def __init__(self, window: Any) -> None:
        self.window = window
        self.movie_dialog: Optional[QInputDialog] = None

    def refused(self, path: str | os.PathLike, movie: bool = False) -> bool:
        """Check what ``path`` would receive; a refusal is shown as a message (True: refused)."""
        from volviz.io.atomic import OutputPathError
        from volviz.render.export import ExportError, check_output

        try:
            check_output(path, movie=movie)
        except (ExportError, OutputPathError) as exc:
            self.window.show_error("Cannot export", f"{exc}\n\nChoose another name or folder.")
            return True
        return False

    def screenshot_size(self) -> tuple[int, int]:
        """The render settings' export width at the viewport's aspect ratio."""
        viewport = self.window.plotter.interactor
        return aspect_size((viewport.width(), viewport.height()), self.window.session.render.size[0])

    def screenshot(self, path: str | os.PathLike) -> bool:
        """Export the current view to ``path`` at ``screenshot_size`` (False: the name was refused)."""
        if self.refused(path):
            return False
        self.window.export_screenshot(path, self.screenshot_size())
        return True

    def ask_screenshot(self) -> None:
        self.window.ask_file("Export screenshot", IMAGE_FILTER, self.screenshot, save=True, default_name="volviz.png")

    def movie_choices(self) -> list[str]:
        controller = self.window.controller
        through_time = bool(controller is not None and controller.time_series())
        return [ORBIT] + list(self.window.session.camera_paths) + ([THROUGH_TIME] if through_time else [])

    def movie(self, path: str | os.PathLike, choice: str) -> bool:
        """Export the movie ``choice`` (``movie_choices``) to ``path`` (False: the name was refused)."""
        if self.refused(path, movie=True):
            return False
        orbit, through_time = choice == ORBIT, choice == THROUGH_TIME
        self.window.export_movie(path, None if orbit or through_time else choice, through_time, orbit=orbit)
        return True

    def ask_movie(self) -> QInputDialog:
        """Which movie (non-blocking), then where to write it."""
        dialog = QInputDialog(self.window)
        dialog.setWindowTitle("Export movie")
        dialog.setLabelText("Movie:")
        dialog.setComboBoxItems(self.movie_choices())
        dialog.setComboBoxEditable(False)
        dialog.textValueSelected.connect(lambda choice: self.window.ask_file(
            "Export movie", MOVIE_FILTER, lambda path: self.movie(path, choice), save=True,
            default_name="volviz.mp4"))
        dialog.open()
        self.movie_dialog = dialog
        return dialog
