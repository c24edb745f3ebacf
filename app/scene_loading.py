"""Loading a scene in the main window: ``open_path``, the one code path behind File > Open, Open Recent,
drag-and-drop and the command line, the demo scenes, and ``show_session``, which shows a session: its datasets are
read and the scene prepared in the background (``SceneController.prepare``) with progress and cancel in the status
bar, its CPU ray-cast volumes set up off the GUI thread (``set_up_volumes``), then installed on the GUI thread
(``_install``: props added, the window told, one render) in short stages, and
its first views computed in the background (``volviz_app.view_scheduler``). A newer open supersedes an older one;
the shown scene stays until the new one is ready, and stays on when it fails.

Held by the window as ``window.scene_loading``; its collaborators are the shown scene (``shown_scene``: it replaces
the session, file, datasets and controller), the window (the parent of its dialogs, whose dock state a session
restores), the plotter, the window's ``jobs``, the settings (remembered data folders), the recent files, the
stand-in frame, the status label, and the window's side of a new scene as callbacks: ``set_busy(busy)``,
``show_error(title, text)``, ``supersede()`` (a newer scene comes: the shown scene's background work stops),
``installed(controller, title, dirty, new_data)`` (the window's docks, menus and view state take the scene),
``first_render()`` and ``first_views(controller, serial, title)`` (which end the loading)."""
from __future__ import annotations

import logging
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Optional

from PySide6.QtCore import QByteArray, QSettings, Qt, QTimer
from PySide6.QtWidgets import QLabel, QMainWindow

from volviz.jobs import Job, JobOutcome
from volviz.session import Session
from .errors import open_error
from .recent import RecentFiles
from .shown_scene import ShownScene
from .stand_in import StandInFrame
from .volume_setup_job import set_up_volumes

if TYPE_CHECKING:
    from volviz.render.controller import SceneController
    from volviz.render.scene_builder import PreparedScene
    from volviz.render.volume_setup import VolumeSetup
    from .viewport_types import Viewport
    from .workers import JobBridge

log = logging.getLogger("volviz_app.window")  # the logger these methods had in window.py

STAGE_MS = 30            # pause between GUI-thread stages of showing a new scene (other events run in between)


class SceneLoading:
    """Opening files and showing sessions (see the module's docstring)."""

    def __init__(self, scene: ShownScene, window: QMainWindow, plotter: Viewport, jobs: JobBridge,
                 settings: QSettings, recent: RecentFiles, stand_in: StandInFrame, status: QLabel, *,
                 set_busy: Callable[[bool], None], show_error: Callable[[str, str], None],
                 supersede: Callable[[], None], installed: Callable[[SceneController, str, bool, bool], None],
                 first_render: Callable[[], None],
                 first_views: Callable[[SceneController, int, str], None]) -> None:
        self.scene, self.window, self.plotter, self.jobs = scene, window, plotter, jobs
        self.settings, self.recent, self.stand_in, self.status = settings, recent, stand_in, status
        self.set_busy, self.show_error, self.supersede, self.installed = set_busy, show_error, supersede, installed
        self.first_render, self.first_views = first_render, first_views
        self.serial = 0                          # the newest open/rebuild; an older one's late callbacks do nothing
        self.current_job: Optional[Job] = None   # the newest scene's reading and preparing, until it is installed
        self.raw_dialog: Optional[Any] = None    # the layout dialog of the last headerless data opened
        self.missing_dialog: Optional[Any] = None  # the dialog locating a session's missing data files
        self.volume_setup: Optional[VolumeSetup] = None   # the process's, since the first CPU ray-cast volume

    def loading(self) -> bool:
        """A scene is being read and prepared (the Cancel button stops it)."""
        return self.current_job is not None and not self.current_job.done()

    def open_demo(self) -> None:
        from volviz.scene.demo import demo_session

        self.show_session(demo_session(), None, "demo scene")

    def open_demo_volume(self) -> None:
        """The tetrahedral demo volume (an analytic field on a tetrahedralised cube), drawn by volviz's PT."""
        from volviz.scene.demo import demo_volume_session

        self.show_session(demo_volume_session(), None, "demo volume")

    def open_paths(self, paths: list[str]) -> None:
        """Open what the Open dialog chose: a PLOT3D grid and its solution file together, else the first file."""
        from volviz.io.plot3d_pairs import grid_and_solution

        pair = grid_and_solution(paths)
        if pair is not None:
            self.open_path(pair[0], q=pair[1])
        elif paths:
            self.open_path(paths[0])

    def open_path(self, path: str | os.PathLike, q: Optional[str | os.PathLike] = None) -> None:
        """Open a session file or a data file (the path behind every Open action and the command line); ``q``: the
        solution file of a PLOT3D grid."""
        from volviz.render.export import is_session_file
        from volviz.scene.opening import data_session
        from volviz.session import load

        p = Path(path)
        try:
            if not p.exists():
                raise FileNotFoundError(p)
            if q is None and self._ask_raw_layout(p):
                return
            session, session_path = (load(p), p) if is_session_file(p) else (data_session(p, q), None)
        except Exception as exc:  # the file's fault or ours: a message in the user's terms, the scene stays
            self.show_error(f"Cannot open {p.name}", open_error(p, exc))
            return
        if session_path is not None and self._ask_missing_data(session, session_path, path=p):
            return
        # File > Open Recent lists it once it has opened
        self.show_session(session, session_path, p.name, path=p, on_shown=lambda: self.recent.add(p))

    def _ask_missing_data(self, session: Session, session_path: Path, path: Path) -> bool:
        """A session whose data files are not where it says: those in the remembered folders are used; for the
        others the dialog that names them and locates them (kept as ``missing_dialog``), which shows the session
        once all are found. True when the dialog was shown (the shown scene stays meanwhile)."""
        from .missing_data import MissingDataDialog, still_missing

        missing = still_missing(session, session_path, self.settings)
        if not missing:
            return False

        def complete(found: Session) -> None:
            self.show_session(found, session_path, path.name, path=path, on_shown=lambda: self.recent.add(path))

        self.missing_dialog = MissingDataDialog(session, session_path, missing, self.settings, complete, self.window)
        self.missing_dialog.open()
        return True

    def _ask_raw_layout(self, path: Path) -> bool:
        """For headerless data (``volviz.io.raw_layout.headerless_data``), the dialog that asks its layout (kept as
        ``raw_dialog``; Open opens the header it writes). True when the dialog was shown."""
        from volviz.io.raw_layout import headerless_data

        from .raw_import import RawImportDialog

        files = headerless_data(path)
        if not files:
            return False
        self.raw_dialog = RawImportDialog(files, self.open_path, self.window)
        self.raw_dialog.setWindowModality(Qt.WindowModality.WindowModal)
        self.raw_dialog.open()
        return True

    def show_session(self, session: Session, session_path: Optional[Path], title: str,
                      dirty: bool = False, datasets: Optional[dict[str, Any]] = None, path: Optional[Path] = None,
                      on_shown: Optional[Callable[[], None]] = None) -> None:
        """Show ``session``: its datasets are read (unless ``datasets`` are given) and the scene prepared in the
        background (``SceneController.prepare``: reading, extraction, tetrahedralisation, natural scene), with
        progress and cancel in the status bar; then the props are added on this thread (``install``) and the
        view-dependent parts computed in the background. A newer open supersedes an older one; the current scene
        stays until the new one is ready, and stays on when the new one fails (a message names ``path``, the file
        opened, and what is wrong with it). ``on_shown()`` runs once the new scene is installed."""
        from volviz.render.controller import SceneController
        from volviz.scene.datasets import load_datasets

        self.serial += 1
        serial = self.serial
        self.supersede()  # the shown scene's background work (error estimates...) would delay this one
        self.status.setText(f"Loading {title}…")
        self.set_busy(True)
        controller = SceneController(self.plotter, session, {}, on_screen=True)

        def load(progress: Any = None) -> Any:
            def part(lo: float, hi: float) -> Any:
                return lambda fraction, message="": progress(lo + (hi - lo) * fraction, message)

            controller.datasets = load_datasets(session, session_path, part(0.0, 0.6), loaded=datasets)
            return controller.prepare(part(0.6, 1.0))

        def done(outcome: JobOutcome) -> None:
            if serial != self.serial:
                return
            if outcome.cancelled:
                self.set_busy(False)
                self.status.setText(f"Loading {title} cancelled")
                return
            if outcome.error is not None:
                self.set_busy(False)
                self.status.setText(f"Could not load {title}")
                self.show_error(f"Cannot open {title}", open_error(path, outcome.error, title))
                return

            def install(cancelled: bool) -> None:
                if serial != self.serial:
                    return
                if cancelled:
                    self.set_busy(False)
                    self.status.setText(f"Loading {title} cancelled")
                    return
                if self._install(controller, outcome.result, session_path, title, dirty, serial, path,
                                 same_data=datasets is not None) and on_shown:
                    on_shown()

            self.current_job = self.set_up_volumes(controller, outcome.result, title, install)

        self.current_job = self.jobs.submit(load, name=f"load {title}", key="load", on_done=done)

    def set_up_volumes(self, controller: SceneController, prepared: PreparedScene, title: str,
                       then: Callable[[bool], None]) -> Optional[Job]:
        """GUI thread: ``then(cancelled)`` once ``prepared``'s CPU ray-cast volumes are set up off the GUI thread
        (``volume_setup_job.set_up_volumes``); ``volume_setup`` is the process's set-up from the first one on."""
        job = set_up_volumes(self.jobs, controller, prepared, title, then)
        if job is not None:
            from volviz.render.volume_setup import shared_setup   # (made and primed at start-up: startup_imports)

            self.volume_setup = shared_setup()
        return job

    def _install(self, controller: SceneController, prepared: Any, session_path: Optional[Path], title: str,
                 dirty: bool, serial: int, path: Optional[Path] = None, same_data: bool = False) -> bool:
        """GUI thread: replace the shown scene by a prepared one (no numerics here: props added, the window's docks
        filled, one render), then compute its view-dependent parts in the background; loading ends when they are
        shown. A scene that cannot be installed is taken out again and the previous one rebuilt (False).
        ``same_data``: the same data rebuilt; its last frame stays over the viewport until the first views are shown
        (``StandInFrame``)."""
        shown = self.scene
        session = controller.session
        previous = shown.controller
        camera = previous.camera() if previous is not None else None  # install places the new scene's camera
        if same_data and previous is not None:
            self.stand_in.grab()
        else:
            self.stand_in.drop()
        if previous is not None:
            previous.clear()
        self.plotter.clear()
        self.current_job = None
        try:
            controller.install(prepared, views=False)
        except Exception as exc:  # a scene that cannot be shown must not take the window down, nor the old scene
            log.exception("building the scene for %s failed", title)
            self.stand_in.drop()
            controller.clear()
            shown.controller = None
            self.set_busy(False)
            self.status.setText(f"Could not show {title}")
            self.show_error(f"Cannot open {title}", open_error(path, exc, title))
            if previous is not None:  # the window's state still describes it: show it again, same camera
                shown.session.camera = camera
                self.show_session(shown.session, shown.session_path, getattr(shown, "title", ""), shown.dirty,
                                  datasets=shown.datasets)
            return False
        if controller.camera_views():   # views made in the background: the last frame stays over them till then
            self.stand_in.show()
        else:                            # VTK draws the whole scene at once
            self.stand_in.drop()
        shown.session, shown.session_path, shown.datasets = session, session_path, controller.datasets
        shown.controller = controller
        if "window_state" in session.layout:
            self.window.restoreState(QByteArray.fromBase64(session.layout["window_state"].encode("ascii")))
        self.installed(controller, title, dirty, not same_data)

        def first_render() -> None:
            if self.scene.controller is controller:
                self.first_render()

        # the first render and the first views' GUI-thread parts (a PT volume's depth read-back renders too) in
        # later turns of the event loop, with room for other events between them: in one turn they held it 160-330
        # ms for a big PT scene under load
        QTimer.singleShot(STAGE_MS, first_render)
        QTimer.singleShot(2 * STAGE_MS, lambda: self.first_views(controller, serial, title))
        return True
