"""The view scheduler of the main window (a mixin of ``MainWindow``): the background refreshes of the views that depend
on the camera, the session's edits (``views_follow``: a transfer function, visibility, opacity, clipping, the
isosurfaces' mode, however the edit was made), the viewport's size or the display time.

Every view that re-makes something for a camera (``SceneController.camera_views``: the natural scene, volumes at a
level of detail, PT volumes on either backend, the isosurfaces' CPU overlay) is refreshed through one path over the
view calls of ``volviz.render.views`` (``refresh_views``: ``begin`` on this thread, ``compute`` on a worker,
``finish`` here), one job in flight per view and the newest request next (``volviz.jobs.OneInFlight``), so that every
finished update is shown while requests keep coming. While the camera moves the images are previews
(``MOVING_SCALE``), the full-size images follow its end (``_camera_moved``); a view that asks for it
(``coarse_first``: the LOD volumes' block selection) first shows a coarse update. A new scene's first views end its
loading (``_show_first_views``). After a CPU PT render the error is measured against the exact reference and the
error budget applied (``volviz.render.error_budget``). The blended volumes and re-extracted isosurfaces of time
series follow the display time (``refresh_time_volumes``, ``refresh_time_isosurfaces``).

It expects of the window: ``controller`` (a ``SceneController`` or None), ``plotter``, ``jobs`` (a ``JobBridge``),
``session``, ``render_scene()``, ``show_statistics()``, ``show_error(title, text)``, ``status_label``,
``render_settings`` and ``_settings_changed(values)`` (the budget's switch of table), ``timeline``, ``nonfinite``,
``collector``, ``_set_busy(busy)``, ``_load_serial`` and ``_loading_views``. ``_init_view_scheduler()`` makes its
state and ``_connect_view_scheduler()`` its timers and the viewport's interaction observers (both called by the
window's ``__init__``)."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable, Optional

from PySide6.QtCore import QTimer

from volviz.jobs import JobOutcome, OneInFlight
from volviz.render.controller import SceneController, no_render
from volviz.render.error_budget import MOST_ACCURATE_TABLE, error_budget_choice
from .window_base import WindowBase

if TYPE_CHECKING:
    from volviz.model.events import SceneChange

MOVING_SCALE = 2         # previews while the camera moves or a TF point is dragged: 1/2 x 1/2 of the window
FLY_SCALE = 4            # previews while flying: 1/4 x 1/4 (a flight near the ground fills the window with fog)
RESIZE_MS = 200          # overlays re-render once the viewport stopped resizing for 200 ms
FLY_SETTLE_MS = 300      # fly mode: full-size images once no key moved the camera for 300 ms


def _shown(request: Any, result: Any) -> dict[str, Any]:
    """What to keep of a shown update: its request's numbers and flags (a LOD volume's block ``budget``,
    ``preview``) and the statistics its ``finish`` returned, not its images, depths or meshes."""
    kept = {k: v for k, v in (request.items() if isinstance(request, dict) else ())
            if isinstance(v, (bool, int, float, str))}
    if isinstance(result, dict):
        kept.update(result)
    return kept


class ViewScheduler(WindowBase):
    """The window's background view refreshes (see the module's docstring)."""

    def _init_view_scheduler(self) -> None:
        self._view_jobs: dict[str, OneInFlight] = {}  # per camera view (by its key): its updates
        self.view_updates: dict[str, int] = {}  # per camera view: the updates shown so far
        self.view_shown: dict[str, dict[str, Any]] = {}  # per camera view: the last shown update (``_shown``)
        self._moving_scheduled = False     # a refresh for the camera the mouse is moving is queued
        self._iso_jobs = OneInFlight()     # isosurface extraction for the display time
        self._volume_jobs = OneInFlight()  # blended volumes of time series for the display time
        self.volume_time_shown = None      # (time, interpolated) of the shown volumes
        self.iso_time_shown = None         # (time, interpolated) of the shown isosurfaces
        self.error_estimate = None         # the last CPU PT error estimate, as the statistics dock shows it
        self.last_error_rmse = None        # and its RMSE, which the error budget is checked against

    def _connect_view_scheduler(self) -> None:
        """The viewport's interaction observers, the fly-mode settle timer and the resize timer."""
        # fly mode has no end-of-interaction event: the camera has stopped once no key moved it for a while
        self.fly_settle_timer = QTimer(self, singleShot=True, interval=FLY_SETTLE_MS)
        self.fly_settle_timer.timeout.connect(self._fly_stopped)
        self.plotter.iren.add_observer("StartInteractionEvent", lambda *args: setattr(self.collector, "interacting",
                                                                                      True))
        self.plotter.iren.add_observer("InteractionEvent", lambda *args: self._schedule_camera_moving())

        def interaction_ended(*args: Any) -> None:
            self.collector.interacting = False
            QTimer.singleShot(0, self._camera_moved)

        self.plotter.iren.add_observer("EndInteractionEvent", interaction_ended)
        # a resized viewport makes the overlay images (PT volumes, CPU-mode isosurfaces) the wrong size: redo them
        self.resize_timer = QTimer(self, singleShot=True, interval=RESIZE_MS)
        self.resize_timer.timeout.connect(self._viewport_resized)
        self.plotter.iren.add_observer("ConfigureEvent", lambda *args: self.resize_timer.start())

    def _show_first_views(self, controller: SceneController, serial: int, title: str) -> None:
        """Compute the new scene's camera views in the background (natural scene, LOD blocks, PT volumes, the
        isosurfaces' CPU mode); the loading ends when all are shown (or failed, or were cancelled)."""

        def settled() -> None:
            if serial == self._load_serial and self.controller is controller:
                self.stand_in.drop()   # the new scene's views are all shown: the old frame goes
                self._loading_views = False
                self._set_busy(False)
                self.status_label.setText(f"Showing {title}")
                self.nonfinite.report(title)  # NaN / Inf counts, once, when they arrive

        self._loading_views = True
        self.refresh_views(settled=settled)

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
                self.render_scene()
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
        repaints asked for in one pass). One render per frame instead of two: ``render_scene`` renders, then the
        widget's paint renders again (pyvistaqt), each 10-70 ms on llvmpipe."""
        self.plotter.interactor.update()

    def _schedule_camera_moving(self) -> None:
        """A VTK interaction moved the camera (a mouse drag): refresh what follows it once control returns to the
        event loop (one queued refresh however many motion events arrive before)."""
        if not self._moving_scheduled:
            self._moving_scheduled = True
            QTimer.singleShot(0, self._camera_moving)

    def _camera_moving(self) -> None:
        """While the mouse moves the camera, the camera views follow it (``refresh_views`` with ``moving``): re-made
        in the background, one update of each in flight and the newest camera next (``OneInFlight``), so each shows
        every update it finishes. VTK draws its own props at once. Images are previews at 1 / ``MOVING_SCALE`` of the
        window's size in each direction (a quarter of the pixels, magnified smoothly); the full-size images, the
        error estimate and the LOD re-selection follow at the end of the interaction (``_camera_moved``)."""
        self._moving_scheduled = False
        if self.controller is not None:
            self.refresh_views(scale=MOVING_SCALE, estimate=False, moving=True)

    def _fly_moved(self) -> None:
        """A fly-mode step moved the camera: previews follow it as during a mouse drag (``_camera_moving``, at
        ``FLY_SCALE``), and the full-size images once the keys have stopped for ``FLY_SETTLE_MS``."""
        self._moving_scheduled = False
        if not self.fly_settle_timer.isActive():   # the flight starts: frames at the interactive rate until it stops
            self._interactive_rate(True)
        if self.controller is not None:
            self.refresh_views(scale=FLY_SCALE, estimate=False, moving=True)
        self.fly_settle_timer.start()

    def _fly_stopped(self) -> None:
        """No fly-mode key moved the camera for ``FLY_SETTLE_MS``: the still rate again, and the full-size views;
        unless a movement key is still held (``FlyMode.held``: a long frame delayed its auto-repeat; a full-size
        frame then, with a synchronous render at the still rate, stalled the flight further). The flight's reduced
        frames (``FlyMode.frames``) go on until the views' full-size updates are shown, then the full-resolution
        frame: no synchronous full-size render of the flight's previews before them."""
        if self.fly.held:
            self.fly_settle_timer.start()
            return
        self._interactive_rate(False)
        self.refresh_views(settled=self.fly.frames.ending())

    def _camera_moved(self) -> None:
        """After the camera moved: draw, and refresh every camera view for the new camera (full size, with the error
        estimate)."""
        if self.controller is None:
            return
        self.render_scene()
        self.refresh_views()

    def _viewport_resized(self) -> None:
        """The images of the camera views have the viewport's size, and the block selection depends on it: refresh
        the views whose last update was made for another size."""
        if self.controller is None or self.plotter.ren_win is None:  # no scene, or the window has closed
            return
        size = tuple(int(v) for v in self.plotter.ren_win.GetSize())
        stale = [key for key, view in self.controller.camera_views().items()
                 if tuple(getattr(view, "stats", {}).get("size", ())) != size]
        if stale:
            self.refresh_views(stale)

    def views_follow(self, change: SceneChange) -> None:
        """The camera views follow an edit of the session once the controller's views hold it (the window hears it
        through its one subscription, ``_scene_changed``). A transfer function: re-made in the background, while a
        point is dragged as a preview (``MOVING_SCALE``), a finished edit at full size with a fresh error estimate
        (VTK's own mappers draw it at once). Visibility, opacity, clipping: drawn, and the views refreshed except
        those waiting for a cut made on the CPU (``controller.pending``, refreshed once their cut is shown) and those
        of a component without a view yet (a natural-scene component or one being prepared: refreshed once
        installed). The isosurfaces' mode, and a transfer function (the overlay splits a regular volume at the surfaces,
        ``volviz.render.iso_volume_split``): the CPU overlay re-rendered."""
        controller = self.controller
        comp = change.component
        if controller is None or (change.what == "visible" and comp not in controller.views):
            return
        if change.what == "transfer_function":   # the isosurfaces' CPU overlay holds the volume in front of them
            if not self.refresh_views([comp, "iso-overlay"] if comp else None, estimate=not change.preview,
                                      scale=MOVING_SCALE if change.preview else 1):
                self.render_scene()
            return
        self.render_scene()
        if change.what == "iso_mode":
            self.refresh_iso_overlay()
        elif comp is None:   # clipping: every camera view but the natural scene's
            self.refresh_views([key for key, view in controller.camera_views().items()
                                if view.kind != "nature" and key.split(":", 1)[-1] not in controller.pending])
        elif comp not in controller.pending:
            self.refresh_views([comp, "iso-overlay"])

    def refresh_nature(self, settled: Optional[Callable[[], None]] = None, scale: int = 1) -> None:
        """Re-compute the natural scene's view-dependent parts (C-LOD terrain, fog and clouds) for the newest camera
        in the background (``refresh_views``)."""
        self.refresh_views(["nature"], settled=settled, scale=scale)

    def refresh_iso_overlay(self, settled: Optional[Callable[[], None]] = None, scale: int = 1) -> None:
        """Re-render the isosurfaces' CPU transparency mode (when one is on) in the background (``refresh_views``)."""
        self.refresh_views(["iso-overlay"], settled=settled, scale=scale)

    def refresh_views(self, keys: Optional[list[str]] = None, settled: Optional[Callable[[], None]] = None,
                      scale: int = 1, estimate: bool = True, moving: bool = False) -> int:
        """Update the camera views (``SceneController.camera_views``; only those whose key or component id is in
        ``keys`` when given) for the current camera in the background (``_refresh_view``). ``scale`` > 1: previews
        that many times smaller in each direction; ``moving``: the camera is moving (a view whose VTK props need
        nothing new for a moving camera, ``while_moving = False``, is left alone); ``estimate``: measure a CPU PT
        image's error afterwards. ``settled()`` is called once every chosen view's update is over. Returns the number
        of views chosen."""
        controller = self.controller
        views = controller.camera_views() if controller is not None else {}
        chosen = [(key, view) for key, view in views.items()
                  if (keys is None or key in keys or key.split(":", 1)[-1] in keys)
                  and not (moving and not getattr(view, "while_moving", True))]
        waiting = [len(chosen) + 1]

        def one_settled() -> None:
            waiting[0] -= 1
            if waiting[0] == 0 and settled is not None:
                settled()

        for key, view in chosen:
            if moving:   # an error estimate of an earlier camera would hold the one worker back from the previews
                self.jobs.cancel(f"error:{key.split(':', 1)[-1]}")
            self._refresh_view(key, view, one_settled, scale, estimate)
        one_settled()
        return len(chosen)

    def _refresh_view(self, key: str, view: Any, settled: Callable[[], None], scale: int, estimate: bool) -> None:
        """Update a view (``volviz.render.views.View``) for the current camera in the background: ``begin`` on this
        thread when the job starts (the camera and opaque depth of then, not of the request), ``compute`` on a
        worker, ``finish`` here; it is drawn by the next paint, in its own turn of the event loop (not in the one
        that also handles the mouse), and a full-size update's statistics go to the statistics dock. One job in
        flight per view, the newest request next (``OneInFlight``): while the camera or a TF keeps changing, every
        finished update is shown. (A newer request cancelling the older job would throw away work a kernel cannot
        stop: nothing would be shown until the requests stopped.) A view that the controller no longer shows under
        ``key`` is left alone. A view with ``coarse_first`` shows a coarse update (``begin(scale=2)``) before a
        full-size one."""
        controller = self.controller
        if controller is None:
            return
        jobs = self._view_jobs.setdefault(key, OneInFlight())
        what = view.job[1]
        comp_id = key.split(":", 1)[-1]

        def still_shown() -> bool:
            return self.controller is controller and controller.camera_views().get(key) is view

        def step(scale: int) -> Callable[[Callable[[], None]], None]:
            def start(next_request: Callable[[], None]) -> None:
                if not still_shown():
                    next_request()
                    return
                request = view.begin(scale=scale)

                def done(outcome: JobOutcome) -> None:
                    if outcome.ok and still_shown():
                        with no_render(self.plotter):  # drawn once, below
                            result = view.finish(request, *outcome.result)
                        self.view_updates[key] = self.view_updates.get(key, 0) + 1
                        self.view_shown[key] = _shown(request, result)
                        preview = bool(request.get("preview")) if isinstance(request, dict) else False
                        self.schedule_render()
                        if not preview:
                            self.show_statistics()
                        if estimate and not preview and hasattr(view, "error_estimate"):
                            self.estimate_error(comp_id, request)
                    elif outcome.error is not None:
                        self.show_error(f"Cannot update the {what}", str(outcome.error))
                    next_request()

                self.jobs.submit(view.compute, request, name=what, on_done=done)

            return start

        if scale == 1 and getattr(view, "coarse_first", False):
            jobs.request(step(2))
        jobs.request(step(scale), settled)

    def _time_changed(self, t: float) -> None:
        if self.controller is not None and self.controller.time_series():
            self._show_time(t, None)

    def _playing_changed(self, playing: bool) -> None:
        """During playback VTK draws at its interactive rate, as while the mouse moves the camera (its ray casters
        then cast fewer rays); at the pause the still rate, and one full-quality frame."""
        if self.plotter.ren_win is None:  # the window has closed
            return
        self._interactive_rate(playing)
        if not playing:
            self.schedule_render()

    def _interactive_rate(self, on: bool) -> None:
        """VTK's interactive update rate for the window (``on``; what its interactor styles set during a mouse drag)
        or its still rate: during playback and flight, as during a drag, its ray casters cast fewer rays and the GPU
        PT pass fills a reduced target (``GLPTVolume.set_interactive``)."""
        ren_win = self.plotter.ren_win
        if ren_win is None:   # the window has closed
            return
        iren = self.plotter.iren.interactor if hasattr(self.plotter.iren, "interactor") else self.plotter.iren
        ren_win.SetDesiredUpdateRate(iren.GetDesiredUpdateRate() if on else iren.GetStillUpdateRate())

    def _interpolation_toggled(self, on: bool) -> None:
        if self.controller is not None:
            self._show_time(self.timeline.time, on)

    def _show_time(self, t: float, interpolate: Optional[bool]) -> None:
        controller = self.controller
        if controller is None:
            return
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
