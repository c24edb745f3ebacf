"""The view scheduler of the main window (a mixin of ``MainWindow``): the background refreshes of the views that depend
on the camera, the transfer function, the viewport's size or the display time.

Each kind of view keeps one job in flight and the newest request next (``volviz.jobs.OneInFlight``), so that every
finished render is shown while requests keep coming: the natural scene (``refresh_nature``), PT volumes and the
isosurfaces' CPU overlay (``refresh_pt``, ``refresh_iso_overlay``), all through one path over the view calls of
``volviz.render.views`` (``_refresh_view``: ``begin`` on this thread, ``compute`` on a worker, ``finish`` here), the
blocks of volumes at a level of detail in two budgets (``refresh_lod``), and the blended volumes and re-extracted
isosurfaces of time series (``refresh_time_volumes``, ``refresh_time_isosurfaces``). While the camera moves the
images are previews (``MOVING_SCALE``), the full-size images follow its end (``_camera_moved``). A new scene's first
views end its loading (``_show_first_views``). After a PT render the error is measured against the exact reference
and the error budget applied (``volviz.render.error_budget``).

It expects of the window: ``controller`` (a ``SceneController`` or None), ``plotter``, ``jobs`` (a ``JobBridge``),
``session``, ``render()``, ``show_error(title, text)``, ``status_label``, ``render_settings`` and
``_settings_changed(values)`` (the budget's switch of table), ``timeline``, ``nonfinite``, ``collector``,
``_set_busy(busy)``, ``_load_serial`` and ``_loading_views``. ``_init_view_scheduler()`` makes its state and
``_connect_view_scheduler()`` its timers and the viewport's interaction observers (both called by the window's
``__init__``)."""
from __future__ import annotations

import time
from typing import Any, Callable, Optional

from PySide6.QtCore import QTimer

from volviz.jobs import JobOutcome, OneInFlight
from volviz.render.controller import no_render
from volviz.render.error_budget import MOST_ACCURATE_TABLE, error_budget_choice

MOVING_SCALE = 2         # previews while the camera moves or a TF point is dragged: 1/2 x 1/2 of the window
RESIZE_MS = 200          # overlays re-render once the viewport stopped resizing for 200 ms
FLY_SETTLE_MS = 300      # fly mode: full-size images once no key moved the camera for 300 ms


class ViewScheduler:
    """The window's background view refreshes (see the module's docstring)."""

    def _init_view_scheduler(self) -> None:
        self._overlay_jobs: dict[str, OneInFlight] = {}  # per overlay (a PT volume, the iso overlay): its renders
        self.overlay_updates: dict[str, int] = {}  # per overlay: the renders shown so far
        self._moving_scheduled = False     # a refresh for the camera the mouse is moving is queued
        self._iso_jobs = OneInFlight()     # isosurface extraction for the display time
        self._nature_jobs = OneInFlight()  # the natural scene's view-dependent parts for the camera
        self._volume_jobs = OneInFlight()  # blended volumes of time series for the display time
        self.volume_time_shown: Optional[tuple[float, bool]] = None  # (time, interpolated) of the shown volumes
        self.nature_updates = 0            # background updates of the natural scene shown so far
        self._lod_jobs: dict[str, OneInFlight] = {}  # block selection of volumes at a level of detail
        self.lod_shown: dict[str, int] = {}  # the block budget of the selection each LOD volume shows
        self.iso_time_shown: Optional[tuple[float, bool]] = None  # (time, interpolated) of the shown isosurfaces

    def _connect_view_scheduler(self) -> None:
        """The viewport's interaction observers, the fly-mode settle timer and the resize timer."""
        # fly mode has no end-of-interaction event: the camera has stopped once no key moved it for a while
        self.fly_settle_timer = QTimer(self, singleShot=True, interval=FLY_SETTLE_MS)
        self.fly_settle_timer.timeout.connect(self._camera_moved)
        self.plotter.iren.add_observer("StartInteractionEvent", lambda *args: setattr(self.collector, "interacting",
                                                                                      True))
        self.plotter.iren.add_observer("InteractionEvent", lambda *args: self._schedule_camera_moving())
        self.plotter.iren.add_observer("EndInteractionEvent", lambda *args: (
            setattr(self.collector, "interacting", False), QTimer.singleShot(0, self._camera_moved)))
        # a resized viewport makes the overlay images (PT volumes, CPU-mode isosurfaces) the wrong size: redo them
        self.resize_timer = QTimer(self, singleShot=True, interval=RESIZE_MS)
        self.resize_timer.timeout.connect(self._viewport_resized)
        self.plotter.iren.add_observer("ConfigureEvent", lambda *args: self.resize_timer.start())

    def _show_first_views(self, controller: Any, serial: int, title: str) -> None:
        """Compute the new scene's view-dependent parts in the background (natural scene, LOD blocks, PT volumes,
        the isosurfaces' CPU mode); the loading ends when all are shown (or failed, or were cancelled)."""
        waiting = [1]

        def settled() -> None:
            waiting[0] -= 1
            if waiting[0] == 0 and serial == self._load_serial and self.controller is controller:
                self._loading_views = False
                self._set_busy(False)
                self.status_label.setText(f"Showing {title}")
                self.nonfinite.report(title)  # NaN / Inf counts, once, when they arrive

        self._loading_views = True
        if controller.nature is not None:
            waiting[0] += 1
            self.refresh_nature(settled=settled)
        lods = list(controller.lod_volumes())
        waiting[0] += len(lods)
        self.refresh_lod(lods, settled=settled)
        for comp_id in controller.pt_stats():
            waiting[0] += 1
            self.refresh_pt(comp_id, settled=settled)
        if controller.iso_overlay is not None:
            waiting[0] += 1
            self.refresh_iso_overlay(settled=settled)
        settled()

    def estimate_error(self, comp_id: str, request: Optional[dict[str, Any]] = None) -> None:
        """Measure the PT volume's error against the exact reference for the current view, in the background; the
        statistics dock shows it when done (a newer request supersedes an older one)."""
        volume = self.controller.pt_volume(comp_id) if self.controller is not None else None
        if volume is None:
            return
        request = request or volume.begin()
        controller = self.controller

        def done(outcome: JobOutcome) -> None:
            if outcome.ok and self.controller is controller:
                e = outcome.result
                self.error_estimate = (f"RMSE {e['rmse']:.2f}, max {e['max']:.1f} of 255 vs exact "
                                       f"({e['size'][0]}x{e['size'][1]})")
                self.last_error_rmse = e["rmse"]
                self.render()
                self._enforce_error_budget(e["rmse"])

        self.jobs.submit(volume.error_estimate, request, name="error estimate", key=f"error:{comp_id}",
                         on_done=done)

    MOST_ACCURATE_TABLE = MOST_ACCURATE_TABLE

    def _enforce_error_budget(self, rmse: float) -> None:
        """Measured error above the budget: switch to the most accurate table once, or say that it cannot be met
        (``volviz.render.error_budget``)."""
        choice = error_budget_choice(rmse, self.session.render.options)
        if choice.message is not None:
            self.status_label.setText(choice.message)
        if choice.table is None:
            return
        values = self.render_settings.settings()
        values["options"].update(choice.table)
        self.render_settings.load_values(values)
        self._settings_changed(values)

    def schedule_render(self) -> None:
        """Draw once control returns to the event loop: a repaint of the viewport, which renders (Qt merges the
        repaints asked for in one pass). One render per frame instead of two: ``render`` renders, then the widget's
        paint renders again (pyvistaqt), each 10-70 ms on llvmpipe."""
        self.plotter.interactor.update()

    def _schedule_camera_moving(self) -> None:
        """A VTK interaction moved the camera (a mouse drag): refresh what follows it once control returns to the
        event loop (one queued refresh however many motion events arrive before)."""
        if not self._moving_scheduled:
            self._moving_scheduled = True
            QTimer.singleShot(0, self._camera_moving)

    def _camera_moving(self) -> None:
        """While the mouse moves the camera, the images of our own renderers follow it: the natural scene's fog and
        clouds (with the terrain's C-LOD mesh), PT volumes and the isosurface overlay are re-made in the background,
        one render of each in flight and the newest camera next (``OneInFlight``), so each shows every render it
        finishes. VTK draws its own props at once. The images are previews at 1 / ``MOVING_SCALE`` of the window's
        size in each direction (a quarter of the pixels, magnified smoothly); the full-size images, the error
        estimate and the LOD re-selection follow at the end of the interaction (``_camera_moved``)."""
        self._moving_scheduled = False
        if self.controller is None:
            return
        self.refresh_nature(scale=MOVING_SCALE)
        for comp_id in self.controller.pt_stats():
            self.refresh_pt(comp_id, estimate=False, scale=MOVING_SCALE)
        self.refresh_iso_overlay(scale=MOVING_SCALE)

    def _fly_moved(self) -> None:
        """A fly-mode step moved the camera: previews follow it as during a mouse drag (``_camera_moving``), and
        the full-size images once the keys have stopped for ``FLY_SETTLE_MS``."""
        self._camera_moving()
        self.fly_settle_timer.start()

    def _camera_moved(self) -> None:
        """After the camera moved: refresh what depends on it (terrain LOD, fog and cloud images, PT volumes), then
        draw and re-measure the error estimate for the new view."""
        if self.controller is None:
            return
        self.refresh_nature()
        self.refresh_lod()
        self.last_view_stats = self.controller.update_views(pt=False, nature=False, lod=False)
        self.render()
        for comp_id in self.controller.pt_stats():
            self.refresh_pt(comp_id)
        self.refresh_iso_overlay()

    def _viewport_resized(self) -> None:
        if self.controller is None:
            return
        self.refresh_nature()  # its overlay image has the viewport's size
        self.refresh_lod()     # the block selection depends on the viewport's size
        size = tuple(int(v) for v in self.plotter.ren_win.GetSize())
        for comp_id, stats in self.controller.pt_stats().items():
            if stats and tuple(stats.get("size", size)) != size:
                self.refresh_pt(comp_id)
        overlay = self.controller.iso_overlay
        if overlay is not None and tuple(overlay.stats.get("size", size)) != size:
            self.refresh_iso_overlay()

    def refresh_nature(self, settled: Optional[Callable[[], None]] = None, scale: int = 1) -> None:
        """Re-compute the natural scene's view-dependent parts (C-LOD terrain, fog and cloud images; issue #5) for
        the newest camera in the background (``_refresh_view``), then draw once the event loop is free."""
        controller = self.controller
        view = controller.nature if controller is not None else None
        if view is None:
            if settled is not None:
                settled()
            return

        def shown(request: Any, stats: Any) -> None:
            self.last_view_stats = stats
            self.nature_updates += 1
            self.schedule_render()

        self._refresh_view(view, self._nature_jobs, "natural scene", lambda: controller.nature, shown, settled, scale)

    def refresh_lod(self, comp_ids: Optional[list[str]] = None,
                    settled: Optional[Callable[[], None]] = None) -> None:
        """Re-select the blocks of volumes at a level of detail for the current camera and TF in the background:
        first a coarse selection (an eighth of the block budget) that shows quickly, then the full budget (the
        refinement once the camera stopped); selection and decoding on a worker, the drawing on this thread."""
        controller = self.controller
        if controller is None:
            return
        for comp_id, volume in controller.lod_volumes().items():
            if comp_ids is not None and comp_id not in comp_ids:
                continue
            jobs = self._lod_jobs.setdefault(comp_id, OneInFlight())
            budgets = list(dict.fromkeys((max(1, volume.budget // 8), volume.budget)))
            for budget in budgets:  # ``settled()`` once per volume, when its full budget is shown
                jobs.request(self._lod_step(controller, comp_id, volume, budget),
                             settled if budget == budgets[-1] else None)

    def _lod_step(self, controller: Any, comp_id: str, volume: Any, budget: int) -> Callable[..., None]:
        def start(next_request: Callable[[], None]) -> None:
            if self.controller is not controller or controller.props.get(comp_id) is not volume:
                next_request()
                return
            camera = volume.camera()

            def select(progress: Any = None) -> tuple[Any, list[Any], float, float]:
                t0 = time.perf_counter()
                selection = volume.select(camera, budget)
                t1 = time.perf_counter()
                return selection, volume.decode(selection), t1 - t0, time.perf_counter() - t1

            def done(outcome: JobOutcome) -> None:
                if outcome.ok and self.controller is controller and controller.props.get(comp_id) is volume:
                    volume.show(*outcome.result)
                    self.lod_shown[comp_id] = budget
                    self.schedule_render()
                elif outcome.error is not None:
                    self.show_error("Cannot select the volume's level of detail", str(outcome.error))
                next_request()

            self.jobs.submit(select, name="level of detail", on_done=done)

        return start

    def refresh_pt(self, comp_id: str, settled: Optional[Callable[[], None]] = None, estimate: bool = True,
                   scale: int = 1) -> None:
        """Re-render a PT volume for the current camera and TF: the depth read-back on this thread, the sort, table
        and rasterisation in the background (``_refresh_overlay``), then the image and, with ``estimate``, a fresh
        error estimate. ``scale`` > 1: a preview that many times smaller in each direction. ``settled()`` is called
        when a render for this request is over. On the GPU backend only the visibility order is made in the
        background; until it is done, VTK's renders draw with the newest order there is."""
        controller = self.controller
        volume = controller.pt_volume(comp_id) if controller is not None else None
        gl = controller.gl_pt_volume(comp_id) if controller is not None else None
        if volume is not None:
            after = (lambda request: self.estimate_error(comp_id, request)) if estimate else None
            self._refresh_overlay(volume, f"pt:{comp_id}", "volume", lambda: controller.pt_volume(comp_id), after,
                                  settled, scale)
        elif gl is not None:  # the GPU draws with the newest order; the order for this camera is made on a worker
            gl.reuse_order = True
            self._refresh_overlay(gl, f"pt-order:{comp_id}", "visibility order",
                                  lambda: controller.gl_pt_volume(comp_id), None, settled, scale)
        elif settled is not None:
            settled()

    def refresh_iso_overlay(self, settled: Optional[Callable[[], None]] = None, scale: int = 1) -> None:
        """Re-render the isosurfaces' CPU transparency mode (when one is on) in the background, like a PT volume."""
        controller = self.controller
        overlay = controller.iso_overlay if controller is not None else None
        if overlay is not None:
            self._refresh_overlay(overlay, "iso-overlay", "isosurfaces", lambda: controller.iso_overlay,
                                  settled=settled, scale=scale)
        elif settled is not None:
            settled()

    def _refresh_overlay(self, handle: Any, key: str, what: str, current: Any, after: Any = None,
                         settled: Optional[Callable[[], None]] = None, scale: int = 1) -> None:
        """Re-make an overlay view's image (a PT volume, the isosurfaces' CPU overlay; or a GPU PT volume's
        visibility order) for the current camera (``_refresh_view``), one in flight per ``key``; a preview is
        drawn by the next paint, a full-size image at once, then ``after(request)``."""

        def shown(request: Any, result: Any) -> None:
            self.overlay_updates[key] = self.overlay_updates.get(key, 0) + 1
            if request.get("preview"):  # while the camera moves: drawn by the next paint, in its own turn
                self.plotter.update()   # of the event loop, not in the one that also handles the mouse
            else:
                self.render()
            if after is not None:
                after(request)

        self._refresh_view(handle, self._overlay_jobs.setdefault(key, OneInFlight()), what, current, shown, settled,
                           scale)

    def _refresh_view(self, view: Any, jobs: OneInFlight, what: str, current: Callable[[], Any],
                      shown: Callable[[Any, Any], None], settled: Optional[Callable[[], None]] = None,
                      scale: int = 1) -> None:
        """Update a view (``volviz.render.views.View``) for the current camera in the background: ``begin`` on this
        thread when the job starts (the camera and opaque depth of then, not of the request), ``compute`` on a
        worker, ``finish`` here, then ``shown(request, finish's result)``. One job in flight per ``jobs``, the newest
        request next (``OneInFlight``): while the camera or a TF keeps changing, every finished update is shown. (A
        newer request cancelling the older job would throw away work a kernel cannot stop: nothing would be shown
        until the requests stopped.) A view that ``current()`` no longer returns is left alone."""
        controller = self.controller

        def start(next_request: Callable[[], None]) -> None:
            if self.controller is not controller or current() is not view:
                next_request()
                return
            request = view.begin(scale=scale)

            def done(outcome: JobOutcome) -> None:
                if outcome.ok and self.controller is controller and current() is view:
                    with no_render(self.plotter):  # the caller's ``shown`` draws once
                        result = view.finish(request, *outcome.result)
                    shown(request, result)
                elif outcome.error is not None:
                    self.show_error(f"Cannot update the {what}", str(outcome.error))
                next_request()

            self.jobs.submit(view.compute, request, name=what, on_done=done)

        jobs.request(start, settled)

    def _time_changed(self, t: float) -> None:
        if self.controller is not None and self.controller.time_series():
            self._show_time(t, None)

    def _playing_changed(self, playing: bool) -> None:
        """During playback VTK draws at its interactive rate, as while the mouse moves the camera (its ray casters
        then cast fewer rays); at the pause the still rate, and one full-quality frame."""
        iren = self.plotter.iren.interactor if hasattr(self.plotter.iren, "interactor") else self.plotter.iren
        rate = iren.GetDesiredUpdateRate() if playing else iren.GetStillUpdateRate()
        self.plotter.ren_win.SetDesiredUpdateRate(rate)
        if not playing:
            self.schedule_render()

    def _interpolation_toggled(self, on: bool) -> None:
        if self.controller is not None:
            self._show_time(self.timeline.time, on)

    def _show_time(self, t: float, interpolate: Optional[bool]) -> None:
        controller = self.controller
        controller.set_time(t, interpolate=interpolate, update=False, isosurfaces=False, volumes=False)
        self.refresh_time_volumes()
        self.refresh_time_isosurfaces()

    def refresh_time_volumes(self) -> None:
        """Blend the volumes of time series for the display time in the background (one blend in flight, the
        newest display time next: ``OneInFlight``), then give them to VTK on this thread and draw once."""

        def shown(controller: Any, result: dict[str, Any], key: tuple[float, bool]) -> None:
            controller.show_volumes(result)
            self.volume_time_shown = key

        self._time_job(self._volume_jobs, "time blend", "Cannot show the volume at this time",
                       lambda c: c.time_volumes(), lambda c: c.blend_volume, shown)

    def _time_job(self, jobs: OneInFlight, name: str, error: str, comp_ids: Callable[[Any], list[str]],
                  compute: Callable[[Any], Callable[..., Any]], shown: Callable[[Any, Any, tuple], None]) -> None:
        """For the display time: ``compute(controller)(comp_id, t, interpolate, progress=...)`` for every component
        of ``comp_ids(controller)`` on a worker (``OneInFlight``: playback never waits), then
        ``shown(controller, results, (t, interpolate))`` on this thread and one repaint."""
        controller = self.controller
        if controller is None or not comp_ids(controller):
            return
        t, interpolate = controller.time, controller.interpolate_time

        def start(next_request: Callable[[], None]) -> None:
            ids = comp_ids(controller) if self.controller is controller else []
            if not ids:
                next_request()
                return
            fn = compute(controller)

            def run(progress: Any = None) -> dict[str, Any]:
                return {comp_id: fn(comp_id, t, interpolate, progress=progress) for comp_id in ids}

            def done(outcome: JobOutcome) -> None:
                if outcome.ok and self.controller is controller:
                    shown(controller, outcome.result, (t, interpolate))
                    self.schedule_render()
                elif outcome.error is not None:
                    self.show_error(error, str(outcome.error))
                next_request()

            self.jobs.submit(run, name=name, on_done=done)

        jobs.request(start)

    def refresh_time_isosurfaces(self) -> None:
        """Re-extract the isosurfaces of time series for the display time in the background (issue #8: playback
        never waits for the extraction; ``OneInFlight``), with their clipping and LOD chains, then replace their
        actors on this thread."""

        def shown(controller: Any, result: dict[str, Any], key: tuple[float, bool]) -> None:
            controller.show_isosurfaces(result)
            self.iso_time_shown = key
            self.refresh_iso_overlay()

        self._time_job(self._iso_jobs, "isosurfaces", "Cannot extract the isosurfaces",
                       lambda c: c.time_isosurfaces(), lambda c: c.isosurface_parts, shown)
