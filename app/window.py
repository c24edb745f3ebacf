"""The main window: a PyVista viewport with docks, menus and a status bar. No numerics here: everything is a call
into volviz. ``MainWindow`` holds its parts as objects with their own state, given their collaborators (the shown
scene, typed by ``shown_scene.ShownScene``, widgets, callbacks) when they are made:

- ``camera_bookmarks``: camera bookmarks and camera-path recording (``camera_bookmarks.CameraBookmarks``);
- ``export_runs``: screenshot and movie export in the background (``export_runs.ExportRuns``);
- ``session_files``: open/save dialogs, saving, dirty tracking, autosave, crash recovery, the unsaved-changes
  question on closing (``session_files.SessionFiles``; ``recent``: File > Open Recent);
- ``scene_loading``: ``open_path`` and showing a session, prepared in the background, then installed
  (``scene_loading.SceneLoading``; the window's side of a new scene is ``_scene_installed``);
- ``scene_edits``: what the docks' edits do to the shown scene (TF, visibility, opacity, settings, clipping, render
  settings; ``scene_edits.SceneEdits``);
- ``view_scheduler``: the background refreshes of the views (one job in flight per view), the error estimate and
  budget (``view_scheduler.ViewScheduler``);
- ``time_views``: the timeline's display time shown, volumes blended and isosurfaces re-extracted in the background
  (``time_views.TimeViews``);
- ``busy``: the status bar's progress bar and Cancel button (``busy_status.BusyStatus``);

and gets its docks, menus and actions and its status bar from ``window_widgets``' builder functions (no mixin).

This module sets the window's shared state (``session``, ``controller``, ``jobs``, ``plotter``..., typed in
``window_base.WindowBase``), and holds its construction (a part made later is given to an earlier one as a callback
that reads it when called), ``render_scene``, fly mode, ``show_error``, closing, and
one-line forwarders to its parts for what other modules and the tests call on the window."""
from __future__ import annotations

import logging
import os
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Optional

import numpy as np
from PySide6.QtCore import QPoint, QSettings, Qt
from PySide6.QtGui import QImage, QPainter, QPixmap, QShowEvent
from PySide6.QtWidgets import QFileDialog, QMainWindow, QMenu, QMessageBox, QWidget

from volviz.model.json_types import json_float
from volviz.render.backend import plotter_gl_info
from volviz.render.controller import SceneController, iso_summary
from volviz.render.volume_setup import release_shared
from volviz.session import Session
from .busy_status import BusyStatus
from .camera_bookmarks import CameraBookmarks
from .clip_widget import ClipPlaneWidget
from .export_runs import ExportRuns
from .gc_guard import GuiThreadCollector
from .interaction_renders import SingleRenderDuringInteraction
from .navigation import FlyMode
from .stand_in import StandInFrame
from .startup_imports import import_gui_thread_modules
from .still_strips import StillStrips
from .nonfinite_status import NonFiniteStatus
from .part_attribute import PartAttribute
from .recent import RecentFiles
from .scene_edits import SceneEdits
from .scene_loading import SceneLoading
from .session_files import SessionFiles, default_recovery_dir
from .time_views import TimeViews
from .view_scheduler import ViewScheduler
from .viewport_types import make_plotter
from .window_base import WindowBase
from .window_widgets import build_docks, build_menus, build_status_bar, fill_docks
from .workers import JobBridge

if TYPE_CHECKING:
    from volviz.model.clip import ClipSettings

log = logging.getLogger(__name__)


class MainWindow(WindowBase, QMainWindow):
    """volviz main window. ``open_path`` is the single code path behind File > Open and the command line."""

    def __init__(self, parent: Optional[QWidget] = None, settings: Optional[QSettings] = None,
                 recovery_dir: Optional[Path] = None):
        super().__init__(parent)
        self.setWindowTitle("volviz")
        import_gui_thread_modules()
        self.collector = GuiThreadCollector(self)  # cycles are freed on this thread, never in a worker
        self.settings = settings or QSettings("volviz", "volviz")
        self.plotter = make_plotter(self)
        self.setCentralWidget(self.plotter.interactor)
        self.jobs = JobBridge(self)
        self.session = Session()
        # the empty viewport (before a scene, or when the first open failed) in a scene's colour, not pyvista's white
        self.plotter.set_background(self.session.render.background)  # type: ignore[arg-type]  # pyvista's wrapper
        self.session_path = None
        self.datasets = {}
        self.controller = None
        self.error_dialog = None
        self.dirty = False
        self.last_stats = {}

        build_docks(self)
        build_status_bar(self)
        busy = self.busy = BusyStatus(
            self.status_label, self.progress_bar, self.cancel_button, self.jobs,
            exporting=lambda: self.export_runs.running, cancel_export=lambda: self.export_runs.cancel(),
            loading=lambda: self.scene_loading.current_job if self.scene_loading.loading() else None,
            first_views=lambda: self.view_scheduler.loading_views)
        self.nonfinite = NonFiniteStatus(self)  # the status bar's note on non-finite values
        self.stand_in = StandInFrame(self.plotter)   # the last frame over the viewport while its scene is rebuilt
        views = self.view_scheduler = ViewScheduler(
            self, self, self.plotter, self.jobs, self.status_label, self.render_settings, self.stand_in, self.collector,
            render_scene=self.render_scene, show_statistics=self.show_statistics, show_error=self.show_error,
            set_busy=busy.set_busy, settings_changed=self._settings_changed,
            load_serial=lambda: self.scene_loading.serial, report_nonfinite=self.nonfinite.report)
        self.time_views = TimeViews(self, self.plotter, self.jobs, self.timeline, show_error=self.show_error,
                                    schedule_render=views.schedule_render,
                                    refresh_iso_overlay=views.refresh_iso_overlay,
                                    refresh_views=views.refresh_views,
                                    cut_again=lambda c, ids: self.scene_edits.cut_in_background(c, c.clip, ids))
        self.camera_bookmarks = CameraBookmarks(self, self, self.status_label, self.set_dirty, views.camera_moved)
        self.export_runs = ExportRuns(self, self.jobs, self.plotter, self.status_label, busy.set_busy,
                                      busy.busy_elsewhere, self.show_error)
        self.recent_menu = QMenu("Open &Recent", self)   # File > Open Recent
        self.recent = RecentFiles(self.settings, self.recent_menu, self.open_path_asking)
        loading = self.scene_loading = SceneLoading(
            self, self, self.plotter, self.jobs, self.settings, self.recent, self.stand_in, self.status_label,
            set_busy=busy.set_busy, show_error=self.show_error, supersede=views.supersede,
            installed=self._scene_installed, first_render=self.render_scene, first_views=views.show_first_views)
        self.session_files = SessionFiles(self, self, Path(recovery_dir) if recovery_dir else default_recovery_dir(),
                                          self.recent, self.status_label, loading.open_path, loading.open_paths,
                                          loading.show_session, self.show_error)   # its autosave timer runs from now
        build_menus(self)
        self.scene_edits = SceneEdits(self, self, views, self.jobs, self.status_label, self.tf_editor, self.scene_tree,
                                      self.array_choice, render_scene=self.render_scene, set_dirty=self.set_dirty,
                                      show_error=self.show_error, show_session=loading.show_session,
                                      enforce_error_budget=views.enforce_error_budget)   # its TF preview timer
        self.resize(*self.layout_keeper.default_size())
        self.layout_keeper.restore()
        self.fly = FlyMode(self.plotter, on_camera_moved=views.fly_moved)
        self.single_render = SingleRenderDuringInteraction(self.plotter)  # one render per move of a drag
        self.still_strips: StillStrips | None = None   # the native viewport's slow still frames, drawn in strips
        if hasattr(self.plotter, "strip_stills"):
            self.still_strips = StillStrips(self.plotter, lambda: self.controller is not None
                                            and self.controller.drawn_in_strips(), drawn=self.show_statistics)
            self.plotter.strip_stills(self.still_strips)
            views.read_back = self.still_strips.after_still_frame
        self.clip_widget = ClipPlaneWidget(self.plotter, self.clipping)
        views.watch_viewport(self.fly)  # interaction observers, fly-mode settle and resize timers
        self.collector.freeze_long_lived()

    def showEvent(self, ev: QShowEvent) -> None:
        """Shown: the first time, after the docks took their sizes (``layout``), the native viewport draws its first
        frame before the window is mapped (``NativeViewport.draw_before_mapped``)."""
        super().showEvent(ev)
        if hasattr(self.plotter, "draw_before_mapped"):
            self.plotter.draw_before_mapped()

    # ------------------------------------------------------------------------------------------------ a new scene
    def _scene_installed(self, controller: SceneController, title: str, dirty: bool, new_data: bool) -> None:
        """``scene_loading`` installed ``controller``'s scene as the shown one: the window follows its state, the
        docks and the bookmark menu show it, the views' state starts afresh. ``new_data``: another file or scene,
        whose settings edits are not undone on the new one."""
        controller.changes.subscribe(self.scene_edits.scene_changed)   # the window follows the scene from now on
        fill_docks(self, controller)
        self.view_scheduler.scene_installed()
        self.time_views.scene_installed()
        self.scene_edits.scene_installed()
        if self.still_strips is not None:
            self.still_strips.new_scene()
        self.camera_bookmarks.refresh_menu()
        self.title = title
        self.set_dirty(dirty)
        if new_data:
            self.scene_undo_stack.clear()

    # ------------------------------------------------------------------------------------------------ rendering
    def grab(self, *args: Any) -> QPixmap:
        """``QWidget.grab``; of the whole window with the native viewport (``make_plotter``), its frame drawn over the
        viewport's rectangle: Qt's grab paints widgets through their paint engines, which a native GLX window lacks
        (its region of the grab was garbage: docs/bench/flight.md). ``--screenshot``, screenshots and the
        first-open figure grab the window."""
        pixmap = super().grab(*args)
        if args or not hasattr(self.plotter, "reduce_paints") or self.plotter.ren_win is None:
            return pixmap
        frame = np.ascontiguousarray(np.asarray(self.plotter.screenshot(None, return_img=True))[..., :3])
        image = QImage(frame.data, frame.shape[1], frame.shape[0], 3 * frame.shape[1], QImage.Format.Format_RGB888)
        image.setDevicePixelRatio(pixmap.devicePixelRatio())
        painter = QPainter(pixmap)
        painter.drawImage(self.plotter.interactor.mapTo(self, QPoint(0, 0)), image)
        painter.end()
        return pixmap

    def render_scene(self) -> None:
        """Draw the scene: now, or in strips from the next paint on when a whole still frame would hold the event
        loop too long (``volviz_app.still_strips``)."""
        if self.still_strips is not None and self.still_strips.wanted():
            self.plotter.interactor.update()   # (the statistics once its strips are drawn)
            return
        start = time.perf_counter()
        self.plotter.render()
        self.show_statistics(time.perf_counter() - start)

    def show_statistics(self, elapsed: Optional[float] = None) -> None:
        """The statistics dock for the last frame (``elapsed``: its render's seconds; default the last render's)."""
        if elapsed is None:
            elapsed = self.last_stats.get("render_seconds", 0.0) if getattr(self, "last_stats", None) else 0.0
        stats: dict[str, Any] = {"frame_seconds": elapsed, "render_seconds": elapsed,
                                 "method": self.session.render.method,
                                 "cells": sum(getattr(d, "n_cells", 0) for d in self.datasets.values()),
                                 "gl": plotter_gl_info(self.plotter).renderer}
        pt = self.controller.pt_stats() if self.controller is not None else {}
        if pt and self.controller is not None:  # volviz's own renderer: the split of its last frame
            last = list(pt.values())
            stats.update(frame_seconds=sum(json_float(s.get("total_s", 0.0)) for s in last) + elapsed,
                         sort_seconds=sum(json_float(s.get("sort_s", 0.0)) for s in last),
                         project_seconds=sum(json_float(s.get("project_s", 0.0)) for s in last),
                         raster_seconds=sum(json_float(s.get("raster_s", 0.0)) for s in last),
                         method=", ".join(sorted({str(s.get("method")) for s in last})),
                         error=self.view_scheduler.error_estimate, backends=self.controller.pt_backends())
        iso = self.controller.iso_stats() if self.controller is not None else {}
        if iso:
            stats["iso"] = iso_summary(iso)
        self.last_stats = stats
        self.statistics.show_stats(stats)

    # ------------------------------------------------------------------------------------------------ navigation
    def set_fly_mode(self, enabled: bool) -> None:
        from volviz.render.collision import OpaqueObstacles, fly_bounds, fly_clearance

        nature = self.controller.nature if self.controller is not None else None
        terrain = getattr(getattr(nature, "scene", None), "terrain", None)
        # the scene's size: a terrain's extent (the sky dome around it is 6 times wider, and its size made the flight
        # cross the whole terrain in a second), else the bounds of what is drawn
        bounds = terrain.bounds() if terrain is not None else self.plotter.bounds
        size = max(bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4], 1e-9)
        self.fly.set_enabled(enabled, size)
        # collision-free flight: the eye stays a clearance (the render option fly_clearance, a share of the scene
        # size, 1 % by default) above the terrain and short of opaque geometry
        self.fly.set_ground(terrain.height_at if terrain is not None else None,
                            clearance=fly_clearance(self.session.render.options) * size,
                            obstacle=OpaqueObstacles(self.plotter.renderer))
        self.fly.set_bounds(fly_bounds(bounds, self.plotter.camera.position, terrain))
        self.action_fly.setChecked(enabled)
        self.status_label.setText("Fly mode: W/A/S/D or arrows move, Q/E sink/rise, drag to look, +/- speed"
                                  if enabled else "Orbit mode")
        if enabled:
            self.plotter.interactor.setFocus()

    def reset_camera(self) -> None:
        if self.controller is not None:
            self.controller.set_camera(None, update=False)
            self.view_scheduler.camera_moved()

    # ------------------------------------------------------------------------------------------------ forwarders
    # what tests and other modules call or read on the window, kept while they move to its parts
    export_result = PartAttribute("export_runs", "result")
    export_threads = PartAttribute("export_runs", "threads")
    recovery_file = PartAttribute("session_files")
    recovery_dialog = PartAttribute("session_files")
    file_dialog = PartAttribute("session_files")
    unsaved_dialog = PartAttribute("session_files")
    autosave_timer = PartAttribute("session_files")
    raw_dialog = PartAttribute("scene_loading")
    missing_dialog = PartAttribute("scene_loading")
    _load_serial = PartAttribute("scene_loading", "serial")
    components_shown = PartAttribute("scene_edits")
    histograms_computed = PartAttribute("scene_edits")
    histogram_threads = PartAttribute("scene_edits")
    nature_rebuilds = PartAttribute("scene_edits")
    _view_jobs = PartAttribute("view_scheduler", "view_jobs")
    view_updates = PartAttribute("view_scheduler")
    view_shown = PartAttribute("view_scheduler")
    volume_time_shown = PartAttribute("time_views")
    iso_time_shown = PartAttribute("time_views")

    def schedule_render(self) -> None:
        self.view_scheduler.schedule_render()

    def _camera_moving(self) -> None:
        self.view_scheduler.camera_moving()

    def _camera_moved(self) -> None:
        self.view_scheduler.camera_moved()

    def _set_busy(self, busy: bool) -> None:
        self.busy.set_busy(busy)

    def cancel_current_job(self) -> None:
        self.busy.cancel_current_job()

    def add_bookmark(self, name: str) -> None:
        self.camera_bookmarks.add_bookmark(name)

    def set_recording(self, recording: bool) -> Optional[str]:
        return self.camera_bookmarks.set_recording(recording)

    def export_screenshot(self, path: str | os.PathLike, size: Optional[tuple[int, int]] = None,
                          transparent: bool = False) -> None:
        self.export_runs.export_screenshot(path, size, transparent)

    def export_movie(self, path: str | os.PathLike, path_name: Optional[str], through_time: bool,
                     fps: float = 24.0, size: Optional[tuple[int, int]] = None, orbit: bool = False) -> None:
        self.export_runs.export_movie(path, path_name, through_time, fps, size, orbit)

    def open_path(self, path: str | os.PathLike, q: Optional[str | os.PathLike] = None) -> None:
        self.scene_loading.open_path(path, q)

    def open_paths(self, paths: list[str]) -> None:
        self.scene_loading.open_paths(paths)

    def open_demo(self) -> None:
        self.scene_loading.open_demo()

    def open_demo_volume(self) -> None:
        self.scene_loading.open_demo_volume()

    def _show_session(self, session: Session, session_path: Optional[Path], title: str, dirty: bool = False,
                      datasets: Optional[dict[str, Any]] = None, path: Optional[Path] = None,
                      on_shown: Optional[Callable[[], None]] = None) -> None:
        self.scene_loading.show_session(session, session_path, title, dirty, datasets, path, on_shown)

    def set_dirty(self, dirty: bool = True) -> None:
        self.session_files.set_dirty(dirty)

    def save_session(self, path: str | os.PathLike) -> bool:
        return self.session_files.save_session(path)

    def autosave(self) -> bool:
        return self.session_files.autosave()

    def offer_recovery(self) -> bool:
        return self.session_files.offer_recovery()

    def recent_files(self) -> list[str]:
        return self.session_files.recent_files()

    def ask_file(self, title: str, name_filter: str, on_chosen: Any, save: bool = False,
                 default_name: str = "", multiple: bool = False, folder: bool = False) -> QFileDialog:
        return self.session_files.ask_file(title, name_filter, on_chosen, save, default_name, multiple, folder)

    def open_path_asking(self, path: str | os.PathLike) -> None:
        self.session_files.open_path_asking(path)

    def _ask_open_data(self) -> None:
        self.session_files.ask_open_data()

    # the docks' signals (connected in ``window_widgets``), the budget's switch of table (``view_scheduler``), the
    # settings path (``component_settings``, ``array_choice``) and the tests' waits
    def _select_component(self, comp_id: str) -> None:
        self.scene_edits.select_component(comp_id)

    def _tf_changed(self, tf: Any) -> None:
        self.scene_edits.tf_changed(tf)

    def _tf_committed(self, tf: Any) -> None:
        self.scene_edits.tf_committed(tf)

    def _set_visibility(self, comp_id: str, visible: bool) -> None:
        self.scene_edits.set_visibility(comp_id, visible)

    def _set_opacity(self, comp_id: str, opacity: float) -> None:
        self.scene_edits.set_opacity(comp_id, opacity)

    def _settings_changed(self, values: dict[str, Any]) -> None:
        self.scene_edits.settings_changed(values)

    def set_clip(self, clip: ClipSettings | dict[str, Any]) -> None:
        self.scene_edits.set_clip(clip)

    def clipping_shown(self) -> bool:
        return self.scene_edits.clipping_shown()

    def apply_component_settings(self, comp_id: str, settings: dict[str, Any]) -> bool:
        return self.scene_edits.apply_component_settings(comp_id, settings)

    # ------------------------------------------------------------------------------------------------ errors
    def show_error(self, title: str, text: str) -> None:
        """A non-blocking error dialog (the app keeps running); also logged."""
        log.error("%s: %s", title, text)
        if self.controller is None:
            self.plotter.render()  # a window with no scene yet shows its empty viewport, not an undrawn white one
        dialog = QMessageBox(QMessageBox.Icon.Critical, title, text, QMessageBox.StandardButton.Ok, self)
        dialog.setWindowModality(Qt.WindowModality.WindowModal)
        dialog.open()
        self.error_dialog = dialog

    # ------------------------------------------------------------------------------------------------ closing
    def closeEvent(self, event: Any) -> None:
        if not self.session_files.confirm_close():
            event.ignore()
            return
        self.session_files.clear_recovery()
        self.layout_keeper.save()
        self.session_files.stop()
        self.scene_edits.stop()
        self.camera_bookmarks.stop()
        self.timeline.set_playing(False)
        if self.controller is not None:  # before the plotter closes: the GPU PT pass frees its GL resources
            self.controller.clear()
        self.controller = None  # late timer callbacks find no scene to update
        self.export_runs.abandon()  # no partial movie left behind, no callbacks into a closed window
        self.jobs.shutdown()
        self.plotter.close()
        release_shared()   # the volume set-up's window (``startup_imports``) closes with the last app window
        self.collector.unfreeze()  # what was long-lived while the window was open can be collected again
        self.python_console.shutdown()   # the console's kernel stops with the window
        super().closeEvent(event)
