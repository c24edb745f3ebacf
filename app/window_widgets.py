"""The main window's widgets (a mixin of ``MainWindow``): the docks (transfer function, scene tree, render settings,
timeline, statistics, clipping) with their signals connected to the window's handlers (``volviz_app.scene_edits``; the
timeline's are connected by ``volviz_app.view_scheduler``), the menus and their actions (File, Edit with undo and redo
over the TF, clipping and scene stacks, View, Camera, Help), and the status bar with its progress bar and Cancel button:
``_set_busy`` shows them while a scene loads, its first views are computed or an export runs, and ``cancel_current_job``
stops the export first, else the loading, else the first views.

It makes the docks (``tf_editor``, ``scene_tree``,
``render_settings``, ``timeline``, ``statistics``, ``clipping`` and their ``*_dock``), ``layout_keeper``, the undo
group, ``array_choice``, ``export_dialogs``, ``decorations``, ``python_console`` (stopped by ``closeEvent``), ``help``,
``file_drop``, the actions, ``status_label``, ``progress_bar`` and ``cancel_button``. It expects of the window:
``settings``, ``plotter``, ``jobs``, ``scene_loading``, ``view_scheduler`` (its ``loading_views``), ``export_runs``, the
handlers its docks and actions call (``open_path``, ``set_fly_mode``, ``reset_camera``, ``set_clip``...),
``session_files`` (the File menu's open and save entries, ``recent_menu``), and ``camera_bookmarks``, which adds the
Camera menu's entries. ``_build_docks()`` and ``_build_status_bar()`` are called by the window's ``__init__`` before its
parts are made, ``_build_menus()`` after."""
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


class WindowWidgets(WindowBase):
    """Docks, menus and the status bar of the window (see the module's docstring)."""

    def _fill_docks(self, controller: SceneController) -> None:
        """The docks show a newly installed scene: its components, render settings, decorations, clipping, and its
        time steps at the session's display time (no re-blend, no re-extraction: the scene already shows it)."""
        session = controller.session
        self.scene_tree.populate(session.components, [ref.id for ref in session.datasets], self.array_choice.names,
                                 controller.dataset_traits, controller.drawn_as)
        self.render_settings.load(session.render)
        self.decorations.sync()
        self.clipping.load(session.clip, controller.installed_bounds)
        display_time = controller.time  # the session's display time, which set_steps would reset to the first step
        self.timeline.blockSignals(True)
        try:
            self.timeline.interpolate.setChecked(controller.interpolate_time)   # the session's switch
            self.timeline.set_steps(controller.time_steps())
            if controller.time_series():
                self.timeline.set_time(display_time)
        finally:
            self.timeline.blockSignals(False)

    def _dock(self, title: str, name: str, widget: QWidget, scroll: bool = True) -> QDockWidget:
        dock = QDockWidget(title, self)
        dock.setObjectName(name)
        dock.setWidget(scrolled(widget) if scroll else widget)
        return dock

    def _build_docks(self) -> None:
        self.tf_editor = TransferFunctionEditor()
        self.scene_tree = SceneTree()
        self.render_settings = RenderSettingsDock()
        self.timeline = Timeline()
        self.statistics = Statistics()
        self.clipping = ClippingDock()
        self.tf_dock = self._dock("Transfer function", "tfDock", self.tf_editor)
        self.scene_dock = self._dock("Scene", "sceneDock", self.scene_tree)
        self.settings_dock = self._dock("Render settings", "settingsDock", self.render_settings)
        self.timeline_dock = self._dock("Timeline", "timelineDock", self.timeline, scroll=False)
        self.stats_dock = self._dock("Statistics", "statsDock", self.statistics)
        self.clip_dock = self._dock("Clipping", "clipDock", self.clipping)
        self.slice_tool, self.iso_tool = SliceTool(self), IsoTool(self)
        self.slices_dock = self._dock("Slices", "slicesDock", self.slice_tool.dock)
        self.iso_dock = self._dock("Isosurfaces", "isoDock", self.iso_tool.dock)
        self.docks = [self.tf_dock, self.scene_dock, self.settings_dock, self.timeline_dock, self.stats_dock,
                      self.clip_dock, self.slices_dock, self.iso_dock]
        self.layout_keeper = WindowLayout(self, self.settings, [self.tf_dock, self.scene_dock, self.settings_dock,
                                                                self.clip_dock, self.stats_dock, self.slices_dock,
                                                                self.iso_dock], [self.timeline_dock])
        self.layout_keeper.arrange()

        self.tf_editor.changed.connect(self._tf_changed)
        self.tf_editor.committed.connect(self._tf_committed)
        self.scene_tree.componentSelected.connect(self._select_component)
        self.scene_tree.populated.connect(self.slice_tool.scene_shown)
        self.scene_tree.populated.connect(self.iso_tool.scene_shown)
        self.scene_tree.visibilityChanged.connect(self._set_visibility)
        self.scene_tree.opacityChanged.connect(self._set_opacity)
        self.scene_tree.settingsEdited.connect(lambda comp_id, before, after: edit_settings(
            self, self.scene_undo_stack, comp_id, before, after))
        self.render_settings.changed.connect(self._settings_changed)
        self.clipping.changed.connect(self.set_clip)

    def _build_menus(self) -> None:
        file_menu = self.menuBar().addMenu("&File")
        files = self.session_files
        self.action_open_data = self._action(file_menu, "Open &Data…", QKeySequence.StandardKey.Open,
                                             files.ask_open_data)
        self.action_open_folder = self._action(file_menu, "Open &Folder…", "Ctrl+Alt+O", files.ask_open_folder)
        self.action_open_session = self._action(file_menu, "Open &Session…", "Ctrl+Shift+O", files.ask_open_session)
        file_menu.addMenu(self.recent_menu)
        self.file_choices = FileChoices(self, file_menu)
        self.reload_data = ReloadData(self, file_menu)
        self.action_save_session = self._action(file_menu, "&Save Session", QKeySequence.StandardKey.Save,
                                                files.save)
        self.action_save_session_as = self._action(file_menu, "Save Session &As…", QKeySequence.StandardKey.SaveAs,
                                                   files.ask_save_as)
        file_menu.addSeparator()
        self.action_export_screenshot = self._action(file_menu, "&Export Screenshot…", "Ctrl+E",
                                                     lambda: self.export_dialogs.ask_screenshot())
        self.action_export_movie = self._action(file_menu, "Export &Movie…", "Ctrl+Shift+E",
                                                lambda: self.export_dialogs.ask_movie())
        self.export_dialogs: ExportDialogs = ExportDialogs(self)
        file_menu.addSeparator()
        self._action(file_menu, "&Quit", QKeySequence.StandardKey.Quit, self.close)

        edit_menu = self.menuBar().addMenu("&Edit")
        # Edit > Undo / Redo act on the stack edited last (transfer function, clipping, or the scene: arrays shown)
        self.undo_group = QUndoGroup(self)
        self.scene_undo_stack = QUndoStack(self)
        self.array_choice = ArrayChoice(self, self.scene_tree.array, self.scene_undo_stack)
        for stack in (self.tf_editor.undo_stack, self.clipping.undo_stack, self.scene_undo_stack):
            self.undo_group.addStack(stack)
            stack.indexChanged.connect(lambda _index, s=stack: self._activate_undo_stack(s))
        self.undo_group.setActiveStack(self.tf_editor.undo_stack)
        undo = self.undo_group.createUndoAction(self, "&Undo")
        undo.setShortcut(QKeySequence.StandardKey.Undo)
        redo = self.undo_group.createRedoAction(self, "&Redo")
        redo.setShortcut(QKeySequence.StandardKey.Redo)
        edit_menu.addAction(undo)
        edit_menu.addAction(redo)
        self.action_undo, self.action_redo = undo, redo

        view_menu = self.menuBar().addMenu("&View")
        for dock in self.docks:
            view_menu.addAction(dock.toggleViewAction())
        view_menu.addSeparator()
        self._action(view_menu, "Reset &Layout", "", self.layout_keeper.reset)
        view_menu.addSeparator()
        self.decorations = DecorationToggles(self, view_menu)
        self.scalar_bar_editor = ScalarBarEditor(self, view_menu)
        self.log_scale_status = LogScaleStatus(self)
        self.python_console = PythonConsole(self, view_menu)
        view_menu.addSeparator()
        self.action_fly = self._action(view_menu, "&Fly Mode", "F", self.set_fly_mode)
        self.action_fly.setCheckable(True)
        self._action(view_menu, "&Reset Camera", "R", self.reset_camera)

        self.camera_bookmarks.add_to_menu(self.menuBar().addMenu("&Camera"))
        self.help = HelpMenu(self, self.menuBar().addMenu("&Help"), self.plotter.ren_win)
        self.file_drop = FileDrop([self, self.plotter.interactor], files.open_path_asking)

    def closeEvent(self, event: Any) -> None:
        """Reached once the window's own ``closeEvent`` accepted the close: the console's kernel stops with it."""
        self.python_console.shutdown()
        super().closeEvent(event)

    def _activate_undo_stack(self, stack: Any) -> None:
        import shiboken6

        if shiboken6.isValid(stack) and shiboken6.isValid(self.undo_group):  # not while the window is torn down
            self.undo_group.setActiveStack(stack)

    def _action(self, menu: Any, text: str, shortcut: Any, slot: Any) -> QAction:
        return menu_action(self, menu, text, shortcut, slot)

    def _build_status_bar(self) -> None:
        bar = self.statusBar()
        self.status_label = QLabel("Ready")
        self.progress_bar = QProgressBar()
        self.progress_bar.setMaximumWidth(220)
        self.progress_bar.setRange(0, 1000)
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.clicked.connect(self.cancel_current_job)
        bar.addWidget(self.status_label, 1)
        self.probe = ProbeTool(self)   # the value under the cursor, left of the progress bar
        bar.addPermanentWidget(self.progress_bar)
        bar.addPermanentWidget(self.cancel_button)
        self.progress_bar.setVisible(False)   # shown while busy (``_set_busy``)
        self.cancel_button.setVisible(False)

    def _on_progress(self, job_id: int, fraction: float, message: str) -> None:
        bar = self.progress_bar
        # QProgressBar.setValue repaints at once (synchronously); under load that paint and its flush to the X
        # server held the event loop for most of 80-140 ms gaps. With updates off it only schedules a paint.
        bar.setUpdatesEnabled(False)
        bar.setValue(int(round(fraction * 1000)))
        bar.setUpdatesEnabled(True)
        if message and bar.isVisible():  # background work after loading (error estimates) keeps "Showing ..."
            self.status_label.setText(message)

    def _set_busy(self, busy: bool) -> None:
        was = self.progress_bar.isVisible()
        busy = busy or self.export_runs.running  # a running export keeps its progress bar and cancel button
        self.progress_bar.setVisible(busy)
        self.cancel_button.setVisible(busy)
        if busy and not was:
            self.progress_bar.setValue(0)

    def _busy_elsewhere(self) -> bool:
        """A job other than an export still shows progress (a scene loading, its first views)."""
        return self.scene_loading.loading() or self.view_scheduler.loading_views

    def cancel_current_job(self) -> None:
        if self.export_runs.running:  # an export runs alongside whatever else: the button stops it first
            self.export_runs.cancel()
        elif self.scene_loading.loading() and self.scene_loading.current_job is not None:
            self.scene_loading.current_job.cancel()
        elif self.view_scheduler.loading_views:  # the scene is shown; stop computing its first views
            self.jobs.runner.cancel_all()
