"""The typed view of the main window that ``window_widgets``' builder functions have (issue #31: they build the docks,
menus and status bar into the window; no mixin is left).

``MainWindow`` derives from ``WindowBase``, which declares, once and with their types:

- the window's shared state: what more than one part of the window reads or writes (``session``, ``controller``,
  ``jobs``, ``plotter``, the docks, ``status_label``...), whichever of ``MainWindow.__init__`` or a builder sets it;
- the signatures of the window's methods a builder connects widgets to (``set_fly_mode``, the handlers the docks and
  actions are connected to...).

The methods are declared under ``TYPE_CHECKING`` only: at run time ``WindowBase`` holds nothing but annotations, so
the real definitions (in ``MainWindow`` or ``QMainWindow``'s) are what the window runs. mypy checks every real
definition against its declaration here as an override. For the type checker ``WindowBase`` is a ``QMainWindow`` (the
builders pass the window as the parent of widgets, call ``menuBar()``, ``statusBar()``...); at run time it is a plain
class, so that ``MainWindow`` keeps a single Qt base."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Optional

if TYPE_CHECKING:
    from PySide6.QtCore import QSettings
    from PySide6.QtGui import QAction, QUndoGroup, QUndoStack
    from PySide6.QtWidgets import QDockWidget, QLabel, QMainWindow, QMenu, QMessageBox, QProgressBar, QPushButton

    from volviz.model.clip import ClipSettings
    from volviz.render.controller import SceneController
    from volviz.session import Session
    from .array_choice import ArrayChoice
    from .busy_status import BusyStatus
    from .console import PythonConsole
    from .drop import FileDrop
    from .export_dialogs import ExportDialogs
    from .help import HelpMenu
    from .iso_tool import IsoTool
    from .log_scale_status import LogScaleStatus
    from .probe import ProbeTool
    from .scalar_bar_editor import ScalarBarEditor
    from .slice_tool import SliceTool
    from .time_views import TimeViews
    from .camera_bookmarks import CameraBookmarks
    from .export_runs import ExportRuns
    from .scene_edits import SceneEdits
    from .scene_loading import SceneLoading
    from .session_files import SessionFiles
    from .view_scheduler import ViewScheduler
    from .stand_in import StandInFrame
    from .decoration_toggles import DecorationToggles
    from .docks.clipping import ClippingDock
    from .docks.render_settings import RenderSettingsDock
    from .docks.scene_tree import SceneTree
    from .docks.statistics import Statistics
    from .docks.tf_editor import TransferFunctionEditor
    from .file_choices import FileChoices
    from .reload_data import ReloadData
    from .docks.timeline import Timeline
    from .gc_guard import GuiThreadCollector
    from .layout import WindowLayout
    from .navigation import FlyMode
    from .nonfinite_status import NonFiniteStatus
    from .recent import RecentFiles
    from .viewport_types import Viewport
    from .workers import JobBridge

    _QtWindow = QMainWindow
else:
    _QtWindow = object


class WindowBase(_QtWindow):
    """The main window's shared state and the methods its parts call on each other (see the module's docstring)."""

    # -- set by MainWindow.__init__
    settings: QSettings
    collector: GuiThreadCollector
    plotter: Viewport
    jobs: JobBridge
    nonfinite: NonFiniteStatus
    file_choices: FileChoices
    reload_data: ReloadData
    error_dialog: Optional[QMessageBox]
    last_stats: dict[str, Any]
    # -- the shown scene (set by MainWindow.__init__, replaced by scene_loading and session_files: ``ShownScene``)
    session: Session
    session_path: Optional[Path]
    datasets: dict[str, Any]
    controller: Optional[SceneController]
    title: str                         # what the window title names when there is no session file
    dirty: bool
    # -- widgets (window_widgets' builders)
    tf_editor: TransferFunctionEditor
    scene_tree: SceneTree
    render_settings: RenderSettingsDock
    timeline: Timeline
    statistics: Statistics
    clipping: ClippingDock
    layout_keeper: WindowLayout
    scene_undo_stack: QUndoStack
    array_choice: ArrayChoice
    decorations: DecorationToggles
    recent: RecentFiles
    stand_in: StandInFrame
    camera_bookmarks: CameraBookmarks  # (window.py)
    export_runs: ExportRuns            # (window.py)
    session_files: SessionFiles        # (window.py)
    scene_loading: SceneLoading        # (window.py)
    scene_edits: SceneEdits            # (window.py)
    view_scheduler: ViewScheduler      # (window.py)
    time_views: TimeViews              # (window.py)
    busy: BusyStatus                   # (window.py)
    recent_menu: QMenu                 # (window.py)
    action_fly: QAction
    fly: FlyMode                       # (window.py)
    status_label: QLabel
    progress_bar: QProgressBar
    cancel_button: QPushButton
    probe: ProbeTool
    tf_dock: QDockWidget
    scene_dock: QDockWidget
    settings_dock: QDockWidget
    timeline_dock: QDockWidget
    stats_dock: QDockWidget
    clip_dock: QDockWidget
    slices_dock: QDockWidget
    iso_dock: QDockWidget
    docks: list[QDockWidget]
    slice_tool: SliceTool
    iso_tool: IsoTool
    undo_group: QUndoGroup
    action_undo: QAction
    action_redo: QAction
    action_open_data: QAction
    action_open_folder: QAction
    action_open_session: QAction
    action_save_session: QAction
    action_save_session_as: QAction
    action_export_screenshot: QAction
    action_export_movie: QAction
    export_dialogs: ExportDialogs
    scalar_bar_editor: ScalarBarEditor
    log_scale_status: LogScaleStatus
    python_console: PythonConsole
    help: HelpMenu
    file_drop: FileDrop

    if TYPE_CHECKING:
        # -- MainWindow
        def render_scene(self) -> None: ...
        def show_statistics(self, elapsed: Optional[float] = None) -> None: ...
        def show_error(self, title: str, text: str) -> None: ...
        def set_fly_mode(self, enabled: bool) -> None: ...
        def reset_camera(self) -> None: ...

        # -- forwarded by MainWindow to scene_loading
        @property
        def _load_serial(self) -> int: ...
        def _show_session(self, session: Session, session_path: Optional[Path], title: str,
                          dirty: bool = False, datasets: Optional[dict[str, Any]] = None, path: Optional[Path] = None,
                          on_shown: Optional[Callable[[], None]] = None) -> None: ...

        # -- forwarded by MainWindow to session_files
        def set_dirty(self, dirty: bool = True) -> None: ...

        # -- forwarded by MainWindow to scene_edits (the docks' signals, the error budget's switch of table)
        def set_clip(self, clip: ClipSettings | dict[str, Any]) -> None: ...
        def _select_component(self, comp_id: str) -> None: ...
        def _set_visibility(self, comp_id: str, visible: bool) -> None: ...
        def _set_opacity(self, comp_id: str, opacity: float) -> None: ...
        def _settings_changed(self, values: dict[str, Any]) -> None: ...
        def _tf_changed(self, tf: Any) -> None: ...
        def _tf_committed(self, tf: Any) -> None: ...

