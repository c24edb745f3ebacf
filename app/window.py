"""The main window: a PyVista viewport with docks (transfer function, scene tree, render settings, timeline,
statistics), menus, status bar with progress and cancel, sessions with autosave and crash recovery. No numerics here:
everything is a call into volviz."""
from __future__ import annotations

import logging
import time
from pathlib import Path
from typing import Any, Optional

from PySide6.QtCore import QSettings, Qt, QTimer
from PySide6.QtGui import QAction, QKeySequence, QUndoGroup, QUndoStack
from PySide6.QtWidgets import (QDockWidget, QLabel, QMainWindow, QMessageBox,
                               QProgressBar, QPushButton, QWidget)

from volviz.render.backend import plotter_gl_info
from volviz.render.controller import iso_summary
from volviz.session import CameraKey, Session
from volviz_app.array_choice import ArrayChoice
from volviz_app.camera_bookmarks import CameraBookmarks
from volviz_app.component_settings import edit_settings
from volviz_app.clip_widget import ClipPlaneWidget
from volviz_app.decoration_toggles import DecorationToggles
from volviz_app.docks.clipping import ClippingDock
from volviz_app.docks.render_settings import RenderSettingsDock
from volviz_app.gc_guard import GuiThreadCollector
from volviz_app.help import HelpMenu
from volviz_app.export_dialogs import ExportDialogs
from volviz_app.export_runs import ExportRuns
from volviz_app.layout import WindowLayout, scrolled
from volviz_app.recent import RecentFiles
from volviz_app.scene_edits import SceneEdits
from volviz_app.scene_loading import SceneLoading
from volviz_app.session_files import SessionFiles, default_recovery_dir
from volviz_app.docks.scene_tree import SceneTree
from volviz_app.docks.statistics import Statistics
from volviz_app.docks.tf_editor import TransferFunctionEditor
from volviz_app.docks.timeline import Timeline
from volviz_app.drop import FileDrop
from volviz_app.interaction_renders import SingleRenderDuringInteraction
from volviz_app.navigation import FlyMode
from volviz_app.view_scheduler import ViewScheduler
from volviz_app.nonfinite_status import NonFiniteStatus
from volviz_app.workers import JobBridge

log = logging.getLogger(__name__)

RECORD_MS = 250          # camera-path recording samples the camera four times a second


def _import_gui_thread_modules() -> None:
    """Import at start-up what the GUI thread later imports inside functions: a first ``import vtk`` (the natural
    scene's overlay) took 0.2-0.5 s of a blocked event loop in the middle of loading a scene."""
    import vtk  # noqa: F401

    import volviz.nature.nature_scene  # noqa: F401
    import volviz.render.controller  # noqa: F401
    import volviz.render.pt_prop  # noqa: F401
    import volviz.render.scene_builder  # noqa: F401
    import pyvista

    # pyvista asks once per process whether this system can plot (it runs ``xset -q``) when the first offscreen plotter
    # of an export is made: ~60 ms of a blocked event loop at the start of the first export, here at start-up instead
    pyvista.system_supports_plotting()


class MainWindow(SceneLoading, SessionFiles, ViewScheduler, SceneEdits, ExportRuns, CameraBookmarks, QMainWindow):
    """volviz main window. ``open_path`` is the single code path behind File > Open and the command line."""

    def __init__(self, parent: Optional[QWidget] = None, settings: Optional[QSettings] = None,
                 recovery_dir: Optional[Path] = None):
        super().__init__(parent)
        from pyvistaqt import QtInteractor

        self.setWindowTitle("volviz")
        _import_gui_thread_modules()
        self.collector = GuiThreadCollector(self)  # cycles are freed on this thread, never in a worker
        self.settings = settings or QSettings("volviz", "volviz")
        self.recovery_dir = Path(recovery_dir) if recovery_dir else default_recovery_dir()
        self.plotter = QtInteractor(self, auto_update=False)  # we render when something changed, never on a timer
        self.setCentralWidget(self.plotter.interactor)
        self.jobs = JobBridge(self)
        self.jobs.progress.connect(self._on_progress)
        self.session: Session = Session()
        self.session_path: Optional[Path] = None
        self.datasets: dict[str, Any] = {}
        self.controller: Optional[Any] = None
        self.error_dialog: Optional[QMessageBox] = None
        self.recovery_dialog: Optional[QMessageBox] = None
        self.dirty = False
        self.last_stats: dict[str, Any] = {}
        self._current_job = None
        self._init_scene_edits()           # histograms, the pending TF preview, what the edits have shown
        self._init_exports()               # the running export and the last one's result
        self._load_serial = 0              # the newest open/rebuild; an older one's late callbacks do nothing
        self._loading_views = False        # the newest scene is installed, its first views are computed
        self._init_view_scheduler()        # its OneInFlight jobs and what they have shown
        self._recording: Optional[list[CameraKey]] = None
        self._record_start = 0.0

        self._build_docks()
        self._build_menus()
        self._build_status_bar()
        self.resize(*self.layout_keeper.default_size())
        self.layout_keeper.restore()
        self.fly = FlyMode(self.plotter, on_camera_moved=self._fly_moved)
        self.single_render = SingleRenderDuringInteraction(self.plotter)  # one render per move of a drag
        self.clip_widget = ClipPlaneWidget(self.plotter, self.clipping)
        self._connect_view_scheduler()  # interaction observers, fly-mode settle and resize timers

        self._connect_scene_edits()  # the TF preview timer
        self._connect_session_files()  # the autosave timer
        self.record_timer = QTimer(self, interval=RECORD_MS)
        self.record_timer.timeout.connect(self._record_sample)
        self.nonfinite = NonFiniteStatus(self)  # the status bar's note on non-finite values
        self.collector.freeze_long_lived()

    # ------------------------------------------------------------------------------------------------ construction
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
        self.docks = [self.tf_dock, self.scene_dock, self.settings_dock, self.timeline_dock, self.stats_dock,
                      self.clip_dock]
        self.layout_keeper = WindowLayout(self, self.settings, [self.tf_dock, self.scene_dock, self.settings_dock,
                                                                self.clip_dock, self.stats_dock], [self.timeline_dock])
        self.layout_keeper.arrange()

        self.tf_editor.changed.connect(self._tf_changed)
        self.tf_editor.committed.connect(self._tf_committed)
        self.scene_tree.componentSelected.connect(self._select_component)
        self.scene_tree.visibilityChanged.connect(self._set_visibility)
        self.scene_tree.opacityChanged.connect(self._set_opacity)
        self.scene_tree.settingsEdited.connect(lambda comp_id, before, after: edit_settings(
            self, self.scene_undo_stack, comp_id, before, after))
        self.render_settings.changed.connect(self._settings_changed)
        self.timeline.timeChanged.connect(self._time_changed)
        self.timeline.interpolationToggled.connect(self._interpolation_toggled)
        self.timeline.play_button.toggled.connect(self._playing_changed)
        self.clipping.changed.connect(self.set_clip)

    def _build_menus(self) -> None:
        file_menu = self.menuBar().addMenu("&File")
        self.action_open_data = self._action(file_menu, "Open &Data…", QKeySequence.StandardKey.Open,
                                             self._ask_open_data)
        self.action_open_session = self._action(file_menu, "Open &Session…", "Ctrl+Shift+O", self._ask_open_session)
        self.recent_menu = file_menu.addMenu("Open &Recent")
        self.action_save_session = self._action(file_menu, "&Save Session", QKeySequence.StandardKey.Save,
                                                self._save_session)
        self.action_save_session_as = self._action(file_menu, "Save Session &As…", QKeySequence.StandardKey.SaveAs,
                                                   self._ask_save_session_as)
        file_menu.addSeparator()
        self.action_export_screenshot = self._action(file_menu, "&Export Screenshot…", "Ctrl+E",
                                                     lambda: self.export_dialogs.ask_screenshot())
        self.action_export_movie = self._action(file_menu, "Export &Movie…", "Ctrl+Shift+E",
                                                lambda: self.export_dialogs.ask_movie())
        self.export_dialogs = ExportDialogs(self)
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
        view_menu.addSeparator()
        self.action_fly = self._action(view_menu, "&Fly Mode", "F", self.set_fly_mode)
        self.action_fly.setCheckable(True)
        self._action(view_menu, "&Reset Camera", "R", self.reset_camera)

        camera_menu = self.menuBar().addMenu("&Camera")
        self._action(camera_menu, "Add &Bookmark…", "Ctrl+B", self._ask_bookmark)
        self.bookmark_menu = camera_menu.addMenu("Go to Bookmark")
        camera_menu.addSeparator()
        self.action_record = self._action(camera_menu, "&Record Camera Path", "Ctrl+R", self.set_recording)
        self.action_record.setCheckable(True)
        self.help = HelpMenu(self, self.menuBar().addMenu("&Help"), self.plotter.ren_win)
        self.recent = RecentFiles(self.settings, self.recent_menu, self.open_path)
        self.file_drop = FileDrop([self, self.plotter.interactor], self.open_path)

    def _activate_undo_stack(self, stack: Any) -> None:
        import shiboken6

        if shiboken6.isValid(stack) and shiboken6.isValid(self.undo_group):  # not while the window is torn down
            self.undo_group.setActiveStack(stack)

    def _action(self, menu: Any, text: str, shortcut: Any, slot: Any) -> QAction:
        action = QAction(text, self)
        action.setShortcut(QKeySequence(shortcut))
        action.triggered.connect(slot)
        menu.addAction(action)
        return action

    def _build_status_bar(self) -> None:
        bar = self.statusBar()
        self.status_label = QLabel("Ready")
        self.progress_bar = QProgressBar()
        self.progress_bar.setMaximumWidth(220)
        self.progress_bar.setRange(0, 1000)
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.clicked.connect(self.cancel_current_job)
        bar.addWidget(self.status_label, 1)
        bar.addPermanentWidget(self.progress_bar)
        bar.addPermanentWidget(self.cancel_button)
        self._set_busy(False)

    # ------------------------------------------------------------------------------------------------ rendering
    def render(self) -> None:
        start = time.perf_counter()
        self.plotter.render()
        elapsed = time.perf_counter() - start
        stats: dict[str, Any] = {"frame_seconds": elapsed, "method": self.session.render.method,
                                 "cells": sum(getattr(d, "n_cells", 0) for d in self.datasets.values()),
                                 "gl": plotter_gl_info(self.plotter).renderer}
        pt = self.controller.pt_stats() if self.controller is not None else {}
        if pt:  # volviz's own renderer: the split of its last frame
            last = list(pt.values())
            stats.update(frame_seconds=sum(s.get("total_s", 0.0) for s in last) + elapsed,
                         sort_seconds=sum(s.get("sort_s", 0.0) for s in last),
                         project_seconds=sum(s.get("project_s", 0.0) for s in last),
                         raster_seconds=sum(s.get("raster_s", 0.0) for s in last),
                         method=", ".join(sorted({str(s.get("method")) for s in last})),
                         error=getattr(self, "error_estimate", None), backends=self.controller.pt_backends())
        iso = self.controller.iso_stats() if self.controller is not None else {}
        if iso:
            stats["iso"] = iso_summary(iso)
        self.last_stats = stats
        self.statistics.show_stats(stats)

    # ------------------------------------------------------------------------------------------------ navigation
    def set_fly_mode(self, enabled: bool) -> None:
        bounds = self.plotter.bounds
        size = max(bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4], 1e-9)
        self.fly.set_enabled(enabled, size)
        nature = self.controller.nature if self.controller is not None else None
        terrain = getattr(getattr(nature, "scene", None), "terrain", None)
        # collision-free flight: the eye stays a clearance (the render option fly_clearance, a share of the scene
        # size, 1 % by default) above the terrain and short of opaque geometry
        from volviz.render.collision import OpaqueObstacles, fly_clearance

        self.fly.set_ground(terrain.height_at if terrain is not None else None,
                            clearance=fly_clearance(self.session.render.options) * size,
                            obstacle=OpaqueObstacles(self.plotter.renderer))
        self.action_fly.setChecked(enabled)
        self.status_label.setText("Fly mode: W/A/S/D or arrows move, Q/E sink/rise, drag to look, +/- speed"
                                  if enabled else "Orbit mode")
        if enabled:
            self.plotter.interactor.setFocus()

    def reset_camera(self) -> None:
        if self.controller is not None:
            self.controller.set_camera(None, update=False)
            self._camera_moved()

    # -- autosave and recovery ------------------------------------------------------------------------------------
    # ------------------------------------------------------------------------------------------------ dialogs
    def show_error(self, title: str, text: str) -> None:
        """A non-blocking error dialog (the app keeps running); also logged."""
        log.error("%s: %s", title, text)
        if self.controller is None:
            self.plotter.render()  # a window with no scene yet shows its empty viewport, not an undrawn white one
        dialog = QMessageBox(QMessageBox.Icon.Critical, title, text, QMessageBox.StandardButton.Ok, self)
        dialog.setWindowModality(Qt.WindowModality.WindowModal)
        dialog.open()
        self.error_dialog = dialog

    # ------------------------------------------------------------------------------------------------ progress
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
        busy = busy or self._export_run is not None  # a running export keeps its progress bar and cancel button
        self.progress_bar.setVisible(busy)
        self.cancel_button.setVisible(busy)
        if busy and not was:
            self.progress_bar.setValue(0)

    def _busy_elsewhere(self) -> bool:
        """A job other than an export still shows progress (a scene loading, its first views)."""
        return (self._current_job is not None and not self._current_job.done()) or self._loading_views

    def cancel_current_job(self) -> None:
        if self._export_run is not None:  # an export runs alongside whatever else: the button stops it first
            self._export_run.cancel()
        elif self._current_job is not None and not self._current_job.done():
            self._current_job.cancel()
        elif self._loading_views:  # the scene is shown; stop computing its first views
            self.jobs.runner.cancel_all()

    # ------------------------------------------------------------------------------------------------ closing
    def closeEvent(self, event: Any) -> None:
        if not self._confirm_close():
            event.ignore()
            return
        self.clear_recovery()
        self.layout_keeper.save()
        self.autosave_timer.stop()
        self.preview_timer.stop()
        self.record_timer.stop()
        self.timeline.set_playing(False)
        if self.controller is not None:  # before the plotter closes: the GPU PT pass frees its GL resources
            self.controller.clear()
        self.controller = None  # late timer callbacks find no scene to update
        if self._export_run is not None:  # no partial movie left behind, no callbacks into a closed window
            self._export_run.abandon()
            self._export_run = None
        self.jobs.shutdown()
        self.plotter.close()
        self.collector.unfreeze()  # what was long-lived while the window was open can be collected again
        super().closeEvent(event)
