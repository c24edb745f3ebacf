"""The main window: a PyVista viewport with docks (transfer function, scene tree, render settings, timeline,
statistics), menus, status bar with progress and cancel, sessions with autosave and crash recovery. No numerics here:
everything is a call into volviz."""
from __future__ import annotations

import logging
import threading
import time
from pathlib import Path
from typing import Any, Optional

from PySide6.QtCore import QSettings, Qt, QTimer
from PySide6.QtGui import QAction, QKeySequence, QUndoGroup, QUndoStack
from PySide6.QtWidgets import (QDockWidget, QLabel, QMainWindow, QMessageBox,
                               QProgressBar, QPushButton, QWidget)

from volviz.jobs import JobOutcome
from volviz.render.backend import plotter_gl_info
from volviz.render.controller import iso_summary
from volviz.session import CameraKey, Session, SessionError
from volviz_app.array_choice import ArrayChoice
from volviz_app.camera_bookmarks import CameraBookmarks
from volviz_app.component_settings import edit_settings
from volviz_app.clip_widget import ClipPlaneWidget
from volviz_app.decoration_toggles import DecorationToggles
from volviz_app.docks.clipping import ClippingDock
from volviz_app.docks.render_settings import RENDERER_DEFAULTS, RenderSettingsDock
from volviz_app.gc_guard import GuiThreadCollector
from volviz_app.help import HelpMenu
from volviz_app.export_dialogs import ExportDialogs
from volviz_app.export_runs import ExportRuns
from volviz_app.layout import WindowLayout, scrolled
from volviz_app.recent import RecentFiles
from volviz_app.scene_loading import SceneLoading
from volviz_app.session_files import SessionFiles, default_recovery_dir
from volviz_app.docks.scene_tree import SceneTree
from volviz_app.docks.statistics import Statistics
from volviz_app.docks.tf_editor import TransferFunctionEditor
from volviz_app.docks.timeline import Timeline
from volviz_app.drop import FileDrop
from volviz_app.interaction_renders import SingleRenderDuringInteraction
from volviz_app.navigation import FlyMode
from volviz_app.view_scheduler import MOVING_SCALE, ViewScheduler
from volviz_app.nonfinite_status import NonFiniteStatus
from volviz_app.workers import JobBridge

log = logging.getLogger(__name__)

PREVIEW_MS = 40          # live transfer-function preview: at most one re-render per 40 ms while dragging
RECORD_MS = 250          # camera-path recording samples the camera four times a second


def _histogram_range(hist: Any) -> Optional[tuple[float, float]]:
    """The data range a (counts, edges) histogram spans (None without one)."""
    return None if hist is None else (float(hist[1][0]), float(hist[1][-1]))


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


class MainWindow(SceneLoading, SessionFiles, ViewScheduler, ExportRuns, CameraBookmarks, QMainWindow):
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
        self.components_shown = 0          # components hidden at load, prepared in the background and added
        self._histogram_job: Any = None
        self.histograms_computed = 0       # TF-editor histograms computed in the background and shown
        self.histogram_threads: set[int] = set()       # the threads they were computed on
        self._init_exports()               # the running export and the last one's result
        self._load_serial = 0              # the newest open/rebuild; an older one's late callbacks do nothing
        self._loading_views = False        # the newest scene is installed, its first views are computed
        self._init_view_scheduler()        # its OneInFlight jobs and what they have shown
        self._pending_tf: Optional[tuple[str, Any, bool]] = None  # (component, TF, a finished edit)
        self._recording: Optional[list[CameraKey]] = None
        self.nature_rebuilds = 0           # natural scenes rebuilt in the background (visibility toggles)
        self.isosurface_clip_shown: Optional[dict[str, Any]] = None  # the clipping the shown isosurfaces are cut by
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

        self.preview_timer = QTimer(self, singleShot=True, interval=PREVIEW_MS)
        self.preview_timer.timeout.connect(self._apply_pending_tf)
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

    # ------------------------------------------------------------------------------------------------ docks
    def _select_component(self, comp_id: str) -> None:
        if self.controller is None:
            return
        self.array_choice.show_component(comp_id)
        tf = self.controller.transfer_function(comp_id)
        self.tf_editor.setEnabled(tf is not None)
        if tf is None:
            return
        if comp_id in self.controller.lod_volumes():  # too large to decode whole: the range from node statistics
            from volviz.render.lod_volume import lod_scalar_range

            self.tf_editor.set_transfer_function(tf, data_range=lod_scalar_range(self.controller.dataset_of(comp_id)))
            return
        known = self.controller.histograms.get(comp_id)
        self.tf_editor.blockSignals(True)  # the scene already shows this TF: no preview re-render
        try:
            self.tf_editor.set_transfer_function(tf, data_range=_histogram_range(known), histogram=known)
        finally:
            self.tf_editor.blockSignals(False)
        if known is None:
            self._compute_histogram(comp_id)
        elif self._histogram_job is not None:
            self._histogram_job.cancel()  # an older selection's histogram is no longer wanted

    def _compute_histogram(self, comp_id: str) -> None:
        """The data histogram of a component that has none yet (hidden at load), for the TF editor: its dataset is
        read and the histogram computed on a worker (``volviz.model.stats.histogram``) while the editor shows a
        placeholder; a newer selection supersedes it. ``histograms_computed`` counts the ones shown."""
        from volviz.model.stats import histogram
        from volviz.render.scene_builder import load_datasets

        controller, session_path = self.controller, self.session_path
        self.tf_editor.set_histogram_pending()

        def compute(progress: Any = None) -> Any:
            load_datasets(controller.session, session_path, loaded=controller.datasets, also=(comp_id,))  # hidden
            self.histogram_threads.add(threading.get_ident())
            return histogram(controller.dataset_of(comp_id))

        def done(outcome: JobOutcome) -> None:
            if outcome.ok and self.controller is controller:
                controller.histograms[comp_id] = outcome.result
                if self.scene_tree.current_component() == comp_id:
                    self.tf_editor.set_histogram(outcome.result, _histogram_range(outcome.result))
                    self.histograms_computed += 1
            elif outcome.error is not None:
                self.tf_editor.set_histogram(None, None)
                self.show_error(f"Cannot compute the histogram of {comp_id}", str(outcome.error))

        self._histogram_job = self.jobs.submit(compute, name=f"histogram {comp_id}", key="histogram", on_done=done)

    def _tf_changed(self, tf: Any) -> None:
        comp_id = self.scene_tree.current_component()
        if comp_id is None or self.controller is None:
            return
        # a finished edit renders at full size; a drag under way (the editor's TF not yet committed) as a preview
        self._pending_tf = (comp_id, tf, tf is self.tf_editor.committed_transfer_function)
        if not self.preview_timer.isActive():
            self.preview_timer.start()

    def _apply_pending_tf(self) -> None:
        if self._pending_tf is None or self.controller is None:
            return
        comp_id, tf, finished = self._pending_tf
        self._pending_tf = None
        volume = self.controller.pt_volume(comp_id)
        if volume is None:  # VTK mapper: the new color/opacity functions draw at once
            lod = comp_id in self.controller.lod_volumes()
            self.controller.set_transfer_function(comp_id, tf, update=not lod)
            self.render()
            if lod:  # the block selection depends on the TF (transparent blocks): re-select in the background
                self.refresh_lod([comp_id])
            return
        # volviz PT volume: table build and rasterisation run in the background; the newest edit renders next, while
        # dragging as a preview (``MOVING_SCALE``), a finished edit at full size with a fresh error estimate
        self.controller.set_transfer_function(comp_id, tf, update=False)
        self.refresh_pt(comp_id, estimate=finished, scale=1 if finished else MOVING_SCALE)

    def set_clip(self, clip: dict[str, Any]) -> None:
        """New scene-wide clipping (from the clipping dock): every prop is cut; isosurfaces and PT volumes are cut
        in the background (a 535k-triangle isosurface: 0.2 s of clipping and LOD chains), then re-rendered; volumes
        at a level of detail are ray cast again with the planes in the background."""
        if self.controller is None:
            return
        controller = self.controller
        try:
            pt_ids = controller.set_clip(clip, update_pt=False, cut_pt=False, isosurfaces=False)
        except ValueError as exc:
            self.show_error("Invalid clipping", str(exc))
            return
        self.set_dirty()
        self.render()
        self.refresh_iso_overlay()
        self.refresh_lod()      # ray cast again with the new planes, in the background
        settings = controller.clip
        self._recut_isosurfaces(controller, settings)
        for comp_id in pt_ids:  # the exact cut of a tetrahedral mesh runs in the background, then the re-render

            def done(outcome: JobOutcome, comp_id: str = comp_id) -> None:
                if outcome.ok and self.controller is controller and controller.clip == settings:
                    controller.set_pt_mesh(comp_id, outcome.result)
                    self.render()
                    self.refresh_pt(comp_id)
                elif outcome.error is not None:
                    self.show_error("Cannot clip the volume", str(outcome.error))

            self.jobs.submit(controller.cut_pt_mesh, comp_id, settings, name="clip volume", key=f"clip:{comp_id}",
                             on_done=done)

    def _recut_isosurfaces(self, controller: Any, settings: Any) -> None:
        """Cut the isosurfaces' extracted surfaces by new clipping (or for a new opacity) on a worker, with their LOD
        chains (a newer request supersedes), then swap their actors here; ``isosurfaces_cut()`` tells when the
        clipping is shown."""
        from volviz.render.scene_builder import isosurface_parts

        meshes = controller.isosurface_meshes()
        if not meshes:
            self.isosurface_clip_shown = settings.to_dict()
            return
        comps = {comp_id: controller.component(comp_id) for comp_id in meshes}

        def cut(progress: Any = None) -> dict[str, Any]:
            return {comp_id: isosurface_parts(comps[comp_id], meshes=m, clip=settings)
                    for comp_id, m in meshes.items()}

        def done(outcome: JobOutcome) -> None:
            if outcome.ok and self.controller is controller and controller.clip == settings:
                controller.show_isosurfaces(outcome.result)
                self.isosurface_clip_shown = settings.to_dict()
                self.render()
                self.refresh_iso_overlay()
            elif outcome.error is not None:
                self.show_error("Cannot clip the isosurfaces", str(outcome.error))

        self.jobs.submit(cut, name="clip isosurfaces", key="clip:isosurfaces", on_done=done)

    def isosurfaces_cut(self) -> bool:
        """Whether the isosurfaces on screen are cut by the current clipping (it is re-cut in the background)."""
        return self.controller is None or self.isosurface_clip_shown == self.controller.clip.to_dict()

    def _tf_committed(self, tf: Any) -> None:
        self._tf_changed(tf)
        self.set_dirty()

    def _set_visibility(self, comp_id: str, visible: bool) -> None:
        from volviz.render.scene_builder import NATURE_TYPES

        if self.controller is None:
            return
        controller = self.controller
        nature = controller.component(comp_id).type in NATURE_TYPES
        build = visible and controller.needs_build(comp_id)
        controller.set_visible(comp_id, visible, nature=False, build=False)
        self.set_dirty()
        if nature:
            self.rebuild_nature(comp_id, visible)
            return
        if build:
            self.show_component(comp_id)
            return
        self.render()
        self.refresh_iso_overlay()

    def show_component(self, comp_id: str) -> None:
        """A component hidden at load was shown: prepare it in the background (extraction, tetrahedralisation, VTK
        volume input, histogram; a newer request for it supersedes), add its prop on this thread, then compute its
        view-dependent parts in the background. ``components_shown`` counts the ones installed."""
        from volviz.render.scene_builder import load_datasets

        controller, session_path = self.controller, self.session_path
        self.status_label.setText(f"Preparing {comp_id}…")

        def prepare(progress: Any = None) -> Any:
            load_datasets(controller.session, session_path, loaded=controller.datasets)  # a component shown anew
            return controller.prepare_component(comp_id, progress)

        def done(outcome: JobOutcome) -> None:
            if self.controller is not controller:
                return
            if outcome.ok:
                if not controller.component(comp_id).visible or not controller.needs_build(comp_id):
                    return  # hidden again meanwhile (or already shown)
                controller.install_component(comp_id, outcome.result, views=False)
                self.components_shown += 1
                self.status_label.setText(f"Showing {comp_id}")
                self.schedule_render()
                self.refresh_pt(comp_id)
                self.refresh_lod([comp_id])
                self.refresh_iso_overlay()
            elif outcome.error is not None:
                self._revert_visibility(comp_id, True)
                self.show_error(f"Cannot show {comp_id}", str(outcome.error))

        self.jobs.submit(prepare, name=f"show {comp_id}", key=f"show:{comp_id}", on_done=done)

    def _revert_visibility(self, comp_id: str, visible: bool) -> None:
        """Showing (``visible``) or hiding a component failed: it keeps its previous state, and so does its box."""
        self.controller.component(comp_id).visible = not visible
        tree = self.scene_tree.tree
        tree.blockSignals(True)
        try:
            self.scene_tree.item(comp_id).setCheckState(
                0, Qt.CheckState.Unchecked if visible else Qt.CheckState.Checked)
        finally:
            tree.blockSignals(False)

    def rebuild_nature(self, comp_id: str, visible: bool) -> None:
        """A terrain / fog / clouds / sky component was shown or hidden: rebuild the natural scene in the background
        (maps, fog prisms, cloud volumes; a newer toggle supersedes an older one), put it in on this thread, then
        compute its first view in the background; the old one stays on screen meanwhile. A scene that cannot be
        built (fog without terrain) leaves the component as it was, with a message."""
        from volviz.render.scene_builder import load_datasets

        controller, session_path = self.controller, self.session_path

        def prepare(progress: Any = None) -> Any:
            load_datasets(controller.session, session_path, loaded=controller.datasets)  # a component shown anew
            return controller.prepare_nature(progress)

        def done(outcome: JobOutcome) -> None:
            if self.controller is not controller:
                return
            if outcome.ok:
                controller.install_nature(outcome.result, views=False)
                self.nature_rebuilds += 1
                if controller.nature is None:
                    self.schedule_render()
                self.refresh_nature()
            elif outcome.error is not None:
                self._revert_visibility(comp_id, visible)
                self.show_error(f"Cannot {'show' if visible else 'hide'} {comp_id}", str(outcome.error))

        self.jobs.submit(prepare, name="natural scene", key="nature-build", on_done=done)

    def _set_opacity(self, comp_id: str, opacity: float) -> None:
        if self.controller is None:
            return
        controller = self.controller
        iso = controller.component(comp_id).type == "isosurface"
        controller.set_opacity(comp_id, opacity, isosurfaces=not iso)
        self.set_dirty()
        if iso:  # the surfaces are re-made (opacity, clipping, LOD chains) in the background
            self._recut_isosurfaces(controller, controller.clip)
            return
        self.render()
        self.refresh_iso_overlay()

    def apply_component_settings(self, comp_id: str, settings: dict[str, Any]) -> bool:
        """New settings for a component (the scene tree's form, an undo step): validated through the session schema,
        then the scene is rebuilt with the same camera and marked dirty; a bad value gives a message naming the field
        and changes nothing. Undoable edits go through ``volviz_app.component_settings.edit_settings``."""
        from volviz.session import session_from_dict, session_to_dict

        if self.controller is None:
            return False
        try:
            doc = session_to_dict(self.session)
            for comp in doc["components"]:
                if comp["id"] == comp_id:
                    comp["settings"] = settings
            candidate = session_from_dict(doc, "scene tree")
        except (ValueError, SessionError) as exc:
            self.show_error("Invalid settings", f"{comp_id}: {exc}")
            return False
        candidate.camera = self.controller.camera()
        candidate.layout.pop("window_state", None)  # the docks stay where they are
        # prepared in the background; the current scene stays until the new one is ready (or shown on an error)
        self._show_session(candidate, self.session_path, getattr(self, "title", ""), True, datasets=self.datasets)
        return True

    def _settings_changed(self, values: dict[str, Any]) -> None:
        current = {**RENDERER_DEFAULTS, **self.session.render.options}  # a missing option is its default
        rebuild = (values["method"] != self.session.render.method
                   or any(values["options"].get(k) != current[k] for k in RENDERER_DEFAULTS))
        budget_changed = values["options"].get("error_budget") != self.session.render.options.get("error_budget")
        iso_mode = values["options"].get("iso_mode", "vtk")
        iso_changed = iso_mode != self.session.render.options.get("iso_mode", "vtk")
        self.session.render.method = values["method"]
        self.session.render.size = values["size"]
        self.session.render.options.update(values["options"])
        self.set_dirty()
        if iso_changed and not rebuild and self.controller is not None:
            self.controller.set_iso_mode(iso_mode, update=False)
            self.render()
            self.refresh_iso_overlay()
        if budget_changed and not rebuild and getattr(self, "last_error_rmse", None) is not None:
            self._enforce_error_budget(self.last_error_rmse)
            return
        if rebuild and self.controller is not None:  # another renderer: rebuild the scene with the same camera
            self.session.camera = self.controller.camera()
            self.session.layout.pop("window_state", None)
            self._show_session(self.session, self.session_path, getattr(self, "title", ""), True,
                               datasets=self.datasets)

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
