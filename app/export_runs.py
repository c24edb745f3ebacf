"""Export of the main window (a mixin of ``MainWindow``): ``export_screenshot`` and ``export_movie`` re-render the
scene offscreen in the background (``volviz_app.frame_export``) from a copy of the shown session, with progress and
cancel in the status bar; a newer export supersedes an older one. ``export_result`` is None while one runs, then
True (written) or False. The menu entries and their dialogs are ``volviz_app.export_dialogs``.

It expects of the window: ``controller``, ``session``, ``datasets``, ``plotter``, ``status_label``,
``_set_busy(busy)``, ``_busy_elsewhere()`` and ``show_error``; ``_init_exports()`` makes its state (called by the
window's ``__init__``); the window's ``cancel_current_job`` and ``closeEvent`` stop a running export
(``_export_run``)."""
from __future__ import annotations

import copy
import os
from pathlib import Path
from typing import Any, Callable, Optional

from volviz.session import Session
from .errors import hide_temporary_names
from .window_base import WindowBase


class ExportRuns(WindowBase):
    """Screenshot and movie export (see the module's docstring)."""

    def _init_exports(self) -> None:
        self._export_run: Any = None       # the running screenshot or movie export (``frame_export``)
        self.export_result: Optional[bool] = None  # of the last export: None while it runs
        self.export_threads: set[int] = set()      # the threads its background steps ran on

    def export_screenshot(self, path: str | os.PathLike, size: Optional[tuple[int, int]] = None,
                          transparent: bool = False) -> None:
        """Re-render the current view offscreen at exactly ``size`` (default: the viewport's) and write an image (PNG,
        JPEG or TIFF by the extension; ``transparent``: alpha 0 where nothing is drawn), in the background with
        progress and cancel in the status bar (``volviz_app.frame_export``; a newer export supersedes an older one).
        ``export_result`` is None while it runs, then True (written) or False."""
        from volviz.render.export import ImageFile

        size = size or (self.plotter.interactor.width(), self.plotter.interactor.height())
        self._export(Path(path).name, size, lambda controller: [(None, None)], lambda: ImageFile(path), transparent)

    def export_movie(self, path: str | os.PathLike, path_name: Optional[str], through_time: bool,
                     fps: float = 24.0, size: Optional[tuple[int, int]] = None, orbit: bool = False) -> None:
        """Render a movie offscreen along the camera path ``path_name`` (or, with ``orbit``, one turn around the
        current view) and/or through time, in the background like a screenshot (``export_result``): MP4 through
        imageio-ffmpeg for ``.mp4``, else a PNG sequence in the folder ``path``."""
        from volviz.render.export import MovieWriter, movie_frames

        self._export(Path(path).name, size or self.session.render.size,
                     lambda controller: movie_frames(controller, path_name, fps, through_time, orbit=orbit),
                     lambda: MovieWriter(Path(path), fps))

    def _export(self, name: str, size: tuple[int, int], frames_of: Callable[[Any], list[Any]],
                open_sink: Callable[[], Any], transparent: bool = False) -> None:
        from volviz.render.export import offscreen_scene
        from .frame_export import FrameExport

        if self._export_run is not None:
            self._export_run.cancel()  # superseded: it ends quietly, the newer export owns the status bar
        self.export_result = None
        live = self.controller
        session = Session(datasets=self.session.datasets, components=copy.deepcopy(self.session.components),
                          transfer_functions=copy.deepcopy(self.session.transfer_functions),
                          camera=live.camera() if live else None, render=self.session.render,
                          clip=self.session.clip, camera_paths=copy.deepcopy(self.session.camera_paths))
        plotter, controller = offscreen_scene(session, self.datasets, size)
        t = None
        if live is not None and live.time_series():
            t, controller.interpolate_time = live.time, live.interpolate_time
        self.status_label.setText(f"Exporting {name}…")
        self._set_busy(True)
        run: Any = None

        def end(ok: bool, message: str) -> None:
            self.export_threads |= run.threads
            if run is not self._export_run:  # superseded
                return
            self._export_run = None
            self.export_result = ok
            if not self._busy_elsewhere():
                self._set_busy(False)
            self.status_label.setText(message)
            if not ok and not run.cancelled:
                self.show_error("Cannot export", hide_temporary_names(message))

        self.export_threads = set()
        run = FrameExport(self, plotter, controller, size, name, frames_of, open_sink, end, t, transparent)
        self._export_run = run
