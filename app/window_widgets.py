"""The main window's widgets, built into the window by functions (issue #31: no mixin): the docks (transfer
function, scene tree, render settings, timeline, statistics, clipping, slices, isosurfaces) with their signals
connected to the window's handlers (``volviz_app.scene_edits``; the timeline's are connected by
``volviz_app.time_views``), the menus and their actions (File, Edit with undo and redo over the TF, clipping and scene
stacks, View, Camera, Help), and the status bar's label and the value under the cursor (its progress bar and Cancel
button are ``volviz_app.busy_status``'s). ``fill_docks`` shows a newly installed scene in the docks.

``build_docks`` makes the docks (``tf_editor``, ``scene_tree``, ``render_settings``, ``timeline``, ``statistics``,
``clipping`` and their ``*_dock``), ``layout_keeper``, ``slice_tool`` and ``iso_tool``; ``build_status_bar`` the
``status_label`` and ``probe``; ``build_menus`` the undo group, ``array_choice``, ``export_dialogs``, ``decorations``,
``python_console`` (stopped by the window's ``closeEvent``), ``help``, ``file_drop`` and the actions. They are given
the window, typed by ``window_base.WindowBase`` (what they set and what they connect to); ``build_docks`` and
``build_status_bar`` are called by the window's ``__init__`` before its parts are made, ``build_menus`` after (it uses
``settings``, ``plotter``, ``session_files``, ``recent_menu``, ``camera_bookmarks`` and the window's handlers)."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from PySide6.QtGui import QAction, QKeySequence, QUndoGroup, QUndoStack
from PySide6.QtWidgets import QDockWidget, QLabel, QProgressBar, QPushButton, QWidget

from .actions import menu_action
from .array_choice import ArrayChoice
from .console import PythonConsole
from .file_choices import FileChoices
from .reload_data import ReloadData
from .component_settings import edit_settings
from .decoration_toggles import DecorationToggles
from .docks.clipping import ClippingDock
from .docks.render_settings import RenderSettingsDock
from .docks.scene_tree import SceneTree
from .docks.statistics import Statistics
from .docks.tf_editor import TransferFunctionEditor
from .docks.timeline import Timeline
from .drop import FileDrop
from .export_dialogs import ExportDialogs
from .help import HelpMenu
from .iso_tool import IsoTool
from .log_scale_status import LogScaleStatus
from .slice_tool import SliceTool
from .layout import WindowLayout, scrolled
from .probe import ProbeTool
from .scalar_bar_editor import ScalarBarEditor
from .window_base import WindowBase

if TYPE_CHECKING:
    from volviz.render.controller import SceneController


def fill_docks(window: WindowBase, controller: SceneController) -> None:
    """The docks show a newly installed scene: its components, render settings, decorations, clipping, and its
    time steps at the session's display time (no re-blend, no re-extraction: the scene already shows it)."""
    session = controller.session
    window.scene_tree.populate(session.components, [ref.id for ref in session.datasets], window.array_choice.names,
                               controller.dataset_traits, controller.drawn_as)
    window.render_settings.load(session.render)
    window.decorations.sync()
    window.clipping.load(session.clip, controller.installed_bounds)
    display_time = controller.time  # the session's display time, which set_steps would reset to the first step
    window.timeline.blockSignals(True)
    try:
        window.timeline.interpolate.setChecked(controller.interpolate_time)   # the session's switch
        window.timeline.set_steps(controller.time_steps())
        if controller.time_series():
            window.timeline.set_time(display_time)
    finally:
        window.timeline.blockSignals(False)


def _dock(window: WindowBase, title: str, name: str, widget: QWidget, scroll: bool = True) -> QDockWidget:
    dock = QDockWidget(title, window)
    dock.setObjectName(name)
    dock.setWidget(scrolled(widget) if scroll else widget)
    return dock


def build_docks(window: WindowBase) -> None:
    window.tf_editor = TransferFunctionEditor()
    window.scene_tree = SceneTree()
    window.render_settings = RenderSettingsDock()
    window.timeline = Timeline()
    window.statistics = Statistics()
    window.clipping = ClippingDock()
    window.tf_dock = _dock(window, "Transfer function", "tfDock", window.tf_editor)
    window.scene_dock = _dock(window, "Scene", "sceneDock", window.scene_tree)
    window.settings_dock = _dock(window, "Render settings", "settingsDock", window.render_settings)
    window.timeline_dock = _dock(window, "Timeline", "timelineDock", window.timeline, scroll=False)
    window.stats_dock = _dock(window, "Statistics", "statsDock", window.statistics)
    window.clip_dock = _dock(window, "Clipping", "clipDock", window.clipping)
    window.slice_tool, window.iso_tool = SliceTool(window), IsoTool(window)
    window.slices_dock = _dock(window, "Slices", "slicesDock", window.slice_tool.dock)
    window.iso_dock = _dock(window, "Isosurfaces", "isoDock", window.iso_tool.dock)
    window.docks = [window.tf_dock, window.scene_dock, window.settings_dock, window.timeline_dock, window.stats_dock,
                    window.clip_dock, window.slices_dock, window.iso_dock]
    side = [window.tf_dock, window.scene_dock, window.settings_dock, window.clip_dock, window.stats_dock,
            window.slices_dock, window.iso_dock]
    window.layout_keeper = WindowLayout(window, window.settings, side, [window.timeline_dock])
    window.layout_keeper.arrange()

    window.tf_editor.changed.connect(window._tf_changed)
    window.tf_editor.committed.connect(window._tf_committed)
    window.scene_tree.componentSelected.connect(window._select_component)
    window.scene_tree.populated.connect(window.slice_tool.scene_shown)
    window.scene_tree.populated.connect(window.iso_tool.scene_shown)
    window.scene_tree.visibilityChanged.connect(window._set_visibility)
    window.scene_tree.opacityChanged.connect(window._set_opacity)
    window.scene_tree.settingsEdited.connect(lambda comp_id, before, after: edit_settings(
        window, window.scene_undo_stack, comp_id, before, after))
    window.render_settings.changed.connect(window._settings_changed)
    window.clipping.changed.connect(window.set_clip)


def build_menus(window: WindowBase) -> None:
    file_menu = window.menuBar().addMenu("&File")
    files = window.session_files
    window.action_open_data = _action(window, file_menu, "Open &Data…", QKeySequence.StandardKey.Open,
                                      files.ask_open_data)
    window.action_open_folder = _action(window, file_menu, "Open &Folder…", "Ctrl+Alt+O", files.ask_open_folder)
    window.action_open_session = _action(window, file_menu, "Open &Session…", "Ctrl+Shift+O", files.ask_open_session)
    file_menu.addMenu(window.recent_menu)
    window.file_choices = FileChoices(window, file_menu)
    window.reload_data = ReloadData(window, file_menu)
    window.action_save_session = _action(window, file_menu, "&Save Session", QKeySequence.StandardKey.Save,
                                         files.save)
    window.action_save_session_as = _action(window, file_menu, "Save Session &As…", QKeySequence.StandardKey.SaveAs,
                                            files.ask_save_as)
    file_menu.addSeparator()
    window.action_export_screenshot = _action(window, file_menu, "&Export Screenshot…", "Ctrl+E",
                                              lambda: window.export_dialogs.ask_screenshot())
    window.action_export_movie = _action(window, file_menu, "Export &Movie…", "Ctrl+Shift+E",
                                         lambda: window.export_dialogs.ask_movie())
    window.export_dialogs = ExportDialogs(window)
    file_menu.addSeparator()
    _action(window, file_menu, "&Quit", QKeySequence.StandardKey.Quit, window.close)

    edit_menu = window.menuBar().addMenu("&Edit")
    # Edit > Undo / Redo act on the stack edited last (transfer function, clipping, or the scene: arrays shown)
    window.undo_group = QUndoGroup(window)
    window.scene_undo_stack = QUndoStack(window)
    window.array_choice = ArrayChoice(window, window.scene_tree.array, window.scene_undo_stack)
    for stack in (window.tf_editor.undo_stack, window.clipping.undo_stack, window.scene_undo_stack):
        window.undo_group.addStack(stack)
        stack.indexChanged.connect(lambda _index, s=stack: _activate_undo_stack(window, s))
    window.undo_group.setActiveStack(window.tf_editor.undo_stack)
    undo = window.undo_group.createUndoAction(window, "&Undo")
    undo.setShortcut(QKeySequence.StandardKey.Undo)
    redo = window.undo_group.createRedoAction(window, "&Redo")
    redo.setShortcuts(redo_keys())
    edit_menu.addAction(undo)
    edit_menu.addAction(redo)
    window.action_undo, window.action_redo = undo, redo

    view_menu = window.menuBar().addMenu("&View")
    for dock in window.docks:
        view_menu.addAction(dock.toggleViewAction())
    view_menu.addSeparator()
    _action(window, view_menu, "Reset &Layout", "", window.layout_keeper.reset)
    view_menu.addSeparator()
    window.decorations = DecorationToggles(window, view_menu)
    window.scalar_bar_editor = ScalarBarEditor(window, view_menu)
    window.log_scale_status = LogScaleStatus(window)
    window.python_console = PythonConsole(window, view_menu)
    view_menu.addSeparator()
    window.action_fly = _action(window, view_menu, "&Fly Mode", "F", window.set_fly_mode)
    window.action_fly.setCheckable(True)
    _action(window, view_menu, "&Reset Camera", "R", window.reset_camera)

    window.camera_bookmarks.add_to_menu(window.menuBar().addMenu("&Camera"))
    window.help = HelpMenu(window, window.menuBar().addMenu("&Help"), lambda: window.plotter.ren_win)
    window.file_drop = FileDrop([window, window.plotter.interactor], files.open_path_asking)


def redo_keys() -> list[QKeySequence]:
    """The platform's redo keys, and Ctrl+Y where they lack it: on X11 Qt's standard redo is only Ctrl+Shift+Z, and
    Ctrl+Y, the redo key on Windows, did nothing (issue #28)."""
    keys = QKeySequence.keyBindings(QKeySequence.StandardKey.Redo)
    ctrl_y = QKeySequence("Ctrl+Y")
    return keys if ctrl_y in keys else [*keys, ctrl_y]


def _activate_undo_stack(window: WindowBase, stack: Any) -> None:
    import shiboken6

    if shiboken6.isValid(stack) and shiboken6.isValid(window.undo_group):  # not while the window is torn down
        window.undo_group.setActiveStack(stack)


def _action(window: WindowBase, menu: Any, text: str, shortcut: Any, slot: Any) -> QAction:
    return menu_action(window, menu, text, shortcut, slot)


def build_status_bar(window: WindowBase) -> None:
    bar = window.statusBar()
    window.status_label = QLabel("Ready")
    window.progress_bar = QProgressBar()
    window.progress_bar.setMaximumWidth(220)
    window.progress_bar.setRange(0, 1000)
    window.cancel_button = QPushButton("Cancel")
    bar.addWidget(window.status_label, 1)
    window.probe = ProbeTool(window)   # the value under the cursor, left of the progress bar
    bar.addPermanentWidget(window.progress_bar)
    bar.addPermanentWidget(window.cancel_button)
    window.progress_bar.setVisible(False)   # shown while busy (``busy_status``)
    window.cancel_button.setVisible(False)
