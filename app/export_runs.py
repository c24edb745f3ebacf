"""Export of the main window: ``export_screenshot`` and ``export_movie`` re-render the scene offscreen in the
background (``volviz_app.frame_export``) from a copy of the shown session, with progress and cancel in the status
bar; a newer export supersedes an older one. ``result`` is None while one runs, then True (written) or False. The
menu entries and their dialogs are ``volviz_app.export_dialogs``.

Held by the window as ``window.export_runs``; its collaborators are the shown scene (``shown_scene``), the window's
``jobs`` (a ``JobBridge``, where the export's steps run), the plotter (the viewport's size), the status label, and
the window's busy state: ``set_busy(busy)`` shows or hides the progress bar and Cancel button, ``busy_elsewhere()``
says whether a job other than an export still shows them. The window's Cancel button and ``closeEvent`` stop a
running export (``cancel``, ``abandon``)."""
from __future__ import annotations

import copy
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Optional

from PySide6.QtWidgets import QLabel

from volviz.session import Session
from .errors import hide_temporary_names
from .shown_scene import ShownScene

if TYPE_CHECKING:
    from .frame_export import FrameExport
    from .viewport_types import Viewport
    from .workers import JobBridge


class ExportRuns:
    """Screenshot and movie export (see the module's docstring)."""

    def __init__(self, scene: ShownScene, jobs: JobBridge, plotter: Viewport, status: QLabel,
                 set_busy: Callable[[bool], None], busy_elsewhere: Callable[[], bool],
                 show_error: Callable[[str, str], None]) -> None:
        self.scene, self.jobs, self.plotter, self.status = scene, jobs, plotter, status
        self.set_busy, self.busy_elsewhere, self.show_error = set_busy, busy_elsewhere, show_error
        self.run: Optional[FrameExport] = None     # the running screenshot or movie export
        self.result: Optional[bool] = None         # of the last export: None while it runs
        self.threads: set[int] = set()             # the threads its background steps ran on

    @property
    def running(self) -> bool:
        return self.run is not None

    def cancel(self) -> None:
        """The Cancel button: the running export ends (its result False), its partial output removed."""
        if self.run is not None:
            self.run.cancel()

    def abandon(self) -> None:
        """The window closes: no partial movie left behind, no callbacks into a closed window."""
        if self.run is not None:
            self.run.abandon()
            self.run = None

    def export_screenshot(self, path: str | os.PathLike, size: Optional[tuple[int, int]] = None,
                          transparent: bool = False) -> None:
        """Re-render the current view offscreen at exactly ``size`` (default: the viewport's) and write an image (PNG,
        JPEG or TIFF by the extension; ``transparent``: alpha 0 where nothing is drawn), in the background with
        progress and cancel in the status bar (``volviz_app.frame_export``; a newer export supersedes an older one).
        ``result`` is None while it runs, then True (written) or False."""
        from volviz.render.export import ImageFile

        size = size or (self.plotter.interactor.width(), self.plotter.interactor.height())
        self._export(Path(path).name, size, lambda controller: [(None, None)], lambda: ImageFile(path), transparent)

    def export_movie(self, path: str | os.PathLike, path_name: Optional[str], through_time: bool,
                     fps: float = 24.0, size: Optional[tuple[int, int]] = None, orbit: bool = False,
                     duration: Optional[float] = None) -> None:
        """Render a movie offscreen along the camera path ``path_name`` (or, with ``orbit``, one turn around the
        current view) and/or through time (over ``duration`` seconds; None: one second per unit of data time), in
        the background like a screenshot (``result``): MP4 through imageio-ffmpeg for ``.mp4``, else a PNG sequence
        in the folder ``path``."""
        from volviz.render.export import MovieWriter, movie_frames

        self._export(Path(path).name, size or self.scene.session.render.size,
                     lambda controller: movie_frames(controller, path_name, fps, through_time, duration, orbit=orbit),
                     lambda: MovieWriter(Path(path), fps))

    def _export(self, name: str, size: tuple[int, int], frames_of: Callable[[Any], list[Any]],
                open_sink: Callable[[], Any], transparent: bool = False) -> None:
        from volviz.render.export import offscreen_scene
        from .frame_export import FrameExport

        if self.run is not None:
            self.run.cancel()  # superseded: it ends quietly, the newer export owns the status bar
        self.result = None
        live, shown = self.scene.controller, self.scene.session
        session = Session(datasets=shown.datasets, components=copy.deepcopy(shown.components),
                          transfer_functions=dict(shown.transfer_functions),  # immutable models: shared
                          camera=live.camera() if live else None, render=shown.render,
                          clip=shown.clip, camera_paths=copy.deepcopy(shown.camera_paths))
        plotter, controller = offscreen_scene(session, self.scene.datasets, size)
        t = None
        if live is not None and live.time_series():
            t, controller.interpolate_time = live.time, live.interpolate_time
        self.status.setText(f"Exporting {name}…")
        self.set_busy(True)
        run: Any = None

        def end(ok: bool, message: str) -> None:
            self.threads |= run.threads
            cancelled = run.cancelled
            if run is not self.run:  # superseded
                return
            self.run = None
            self.result = ok
            if not self.busy_elsewhere():
                self.set_busy(False)
            self.status.setText(message)
            if not ok and not cancelled:
                self.show_error("Cannot export", hide_temporary_names(message))

        self.threads = set()
        # FrameExport runs its steps through ``self.jobs``
        run = FrameExport(self, plotter, controller, size, name, frames_of, open_sink, end, t, transparent)
        self.run = run
