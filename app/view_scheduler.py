"""The view scheduler of the main window: the background refreshes of the views that depend on the camera, the
session's edits (``views_follow``: a transfer function, visibility, opacity, clipping, the isosurfaces' mode, however
the edit was made) or the viewport's size.

Every view that re-makes something for a camera (``SceneController.camera_views``: the natural scene, volumes at a
level of detail, PT volumes on either backend, the isosurfaces' CPU overlay) is refreshed through one path over the
view calls of ``volviz.render.views`` (``refresh_views``: ``begin`` on this thread, ``compute`` on a worker,
``finish`` here), one job in flight per view and the newest request next (``volviz.jobs.OneInFlight``), so that every
finished update is shown while requests keep coming. While the camera moves the images are previews
(``MOVING_SCALE``), the full-size images follow its end (``camera_moved``); a view that asks for it
(``coarse_first``: the LOD volumes' block selection) first shows a coarse update. A new scene's first views end its
loading (``show_first_views``). After a CPU PT render the error is measured against the exact reference and the
error budget applied (``volviz.render.error_budget``). (The display time's blends and isosurfaces:
``volviz_app.time_views``.)

Held by the window as ``window.view_scheduler`` (issue #31: a part with its own state, not a mixin). Its collaborators
are the shown scene (``shown_scene.ShownScene``: the controller and session of the moment), the parent of its
timers, the plotter, the window's ``jobs``, the status label, the render settings dock (the budget's switch of
table), the stand-in frame (dropped when a new scene's first views are shown) and the window's ``collector``
(interacting while the mouse moves the camera), and as callbacks ``render_scene()``, ``show_statistics()``,
``show_error(title, text)``, ``set_busy(busy)``, ``settings_changed(values)`` (``volviz_app.scene_edits``: the
budget's table applied), ``load_serial()`` (the newest open, ``volviz_app.scene_loading``) and
``report_nonfinite(title)``. ``watch_viewport(fly)`` adds the viewport's interaction observers and the fly-mode
settle timer once the window's fly mode exists."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable, Optional

from PySide6.QtCore import QObject, QTimer
from PySide6.QtWidgets import QLabel

from volviz.jobs import JobOutcome, OneInFlight
from volviz.render.controller import SceneController, no_render
from volviz.render.error_budget import error_budget_choice
from volviz.render.image_overlay import Buffers, OverlayView
from .shown_scene import ShownScene

if TYPE_CHECKING:
    from volviz.model.events import SceneChange
    from .docks.render_settings import RenderSettingsDock
    from .gc_guard import GuiThreadCollector
    from .navigation import FlyMode
    from .stand_in import StandInFrame
    from .viewport_types import Viewport
    from .workers import JobBridge

MOVING_SCALE = 2         # previews while the camera moves or a TF point is dragged: 1/2 x 1/2 of the window
FLY_SCALE = 4            # previews while flying: 1/4 x 1/4 (a flight near the ground fills the window with fog)
RESIZE_MS = 200          # overlays re-render once the viewport stopped resizing for 200 ms
FLY_SETTLE_MS = 300      # fly mode: full-size images once no key moved the camera for 300 ms


def interactive_rate(plotter: Viewport, on: bool) -> None:
    """VTK's interactive update rate for the window (``on``; what its interactor styles set during a mouse drag) or its
    still rate: during playback and flight, as during a drag, its ray casters cast fewer rays and the GPU PT pass fills
    a reduced target (``GLPTVolume.set_interactive``)."""
    ren_win = plotter.ren_win
    if ren_win is None:   # the window has closed
        return
    iren = plotter.iren.interactor if hasattr(plotter.iren, "interactor") else plotter.iren
    ren_win.SetDesiredUpdateRate(iren.GetDesiredUpdateRate() if on else iren.GetStillUpdateRate())


def _shown(request: Any, result: Any) -> dict[str, Any]:
    """What to keep of a shown update: its request's numbers and flags (a LOD volume's block ``budget``,
    ``preview``) and the statistics its ``finish`` returned, not its images, depths or meshes."""
    kept = {k: v for k, v in (request.items() if isinstance(request, dict) else ())
            if isinstance(v, (bool, int, float, str))}
    if isinstance(result, dict):
        kept.update(result)
    return kept


class ViewScheduler:
    """The window's background view refreshes (see the module's docstring)."""

    def __init__(self, scene: ShownScene, parent: QObject, plotter: Viewport, jobs: JobBridge, status: QLabel,
                 render_settings: RenderSettingsDock, stand_in: StandInFrame,
                 collector: GuiThreadCollector, *, render_scene: Callable[[], None],
                 show_statistics: Callable[[], None], show_error: Callable[[str, str], None],
                 set_busy: Callable[[bool], None], settings_changed: Callable[[dict[str, Any]], None],
                 load_serial: Callable[[], int], report_nonfinite: Callable[[str], None]) -> None:
        self.scene, self.parent, self.plotter, self.jobs, self.status = scene, parent, plotter, jobs, status
        self.render_settings, self.stand_in = render_settings, stand_in
        self.collector = collector
        self.render_scene, self.show_statistics, self.show_error = render_scene, show_statistics, show_error
        self.set_busy, self.settings_changed, self.load_serial = set_busy, settings_changed, load_serial
        self.report_nonfinite = report_nonfinite
        self.fly: Optional[FlyMode] = None   # the window's fly mode (``watch_viewport``)
        self.view_jobs: dict[str, OneInFlight] = {}  # per camera view (by its key): its updates
        self.view_updates: dict[str, int] = {}  # per camera view: the updates shown so far
        self.view_shown: dict[str, dict[str, Any]] = {}  # per camera view: the last shown update (``_shown``)
        self._moving_scheduled = False     # a refresh for the camera the mouse is moving is queued
        self.error_estimate: Optional[str] = None   # the last CPU PT error estimate, as the statistics dock shows it
        self.last_error_rmse: Optional[float] = None   # and its RMSE, which the error budget is checked against
        self.loading_views = False         # the newest scene is installed, its first views are computed
        # the opaque scene read back from the next still frame drawn in strips (``StillStrips.after_still_frame``):
        # False when still frames are not drawn so now
        self.read_back: Optional[Callable[[Callable[[Optional[Buffers]], None]], bool]] = None

    @property
    def controller(self) -> Optional[SceneController]:
        """The shown scene's, read when needed: the window replaces it when it shows another scene."""
        return self.scene.controller

    def supersede(self) -> None:
        """A newer scene is being shown: the shown scene's background work (error estimates...) would delay it."""
        self.jobs.runner.cancel_all()
        self.loading_views = False

    def scene_installed(self) -> None:
        """A new scene is shown: nothing of it has been measured yet."""
        self.error_estimate = None
        self.last_error_rmse = None

    def watch_viewport(self, fly: FlyMode) -> None:
        """The viewport's interaction observers, the fly-mode (``fly``) settle timer and the resize timer."""
        self.fly = fly
        # fly mode has no end-of-interaction event: the camera has stopped once no key moved it for a while
        self.fly_settle_timer = QTimer(self.parent, singleShot=True, interval=FLY_SETTLE_MS)
        self.fly_settle_timer.timeout.connect(self.fly_stopped)
        self.plotter.iren.add_observer("StartInteractionEvent", lambda *args: setattr(self.collector, "interacting",
                                                                                      True))
        self.plotter.iren.add_observer("InteractionEvent", lambda *args: self._schedule_camera_moving())

        def interaction_ended(*args: Any) -> None:
            self.collector.interacting = False
            QTimer.singleShot(0, self.camera_moved)

        self.plotter.iren.add_observer("EndInteractionEvent", interaction_ended)
        # a resized viewport makes the overlay images (PT volumes, CPU-mode isosurfaces) the wrong size: redo them
        self.resize_timer = QTimer(self.parent, singleShot=True, interval=RESIZE_MS)
        self.resize_timer.timeout.connect(self._viewport_resized)
        self.plotter.iren.add_observer("ConfigureEvent", lambda *args: self.resize_timer.start())

    def show_first_views(self, controller: SceneController, serial: int, title: str) -> None:
        """Compute the new scene's camera views in the background (natural scene, LOD blocks, PT volumes, the
        isosurfaces' CPU mode); the loading ends when all are shown (or failed, or were cancelled)."""

        def settled() -> None:
            if serial == self.load_serial() and self.controller is controller:
                self.stand_in.drop()   # the new scene's views are all shown: the old frame goes
                self.loading_views = False
                self.set_busy(False)
                self.status.setText(f"Showing {title}")
                self.report_nonfinite(title)  # NaN / Inf counts, once, when they arrive

        self.loading_views = True
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
                self.enforce_error_budget(e["rmse"])

        self.jobs.submit(volume.error_estimate, request, name="error estimate", key=f"error:{comp_id}",
                         on_done=done)

    def enforce_error_budget(self, rmse: float) -> None:
        """Measured error above the budget: switch to the most accurate table once, or say that it cannot be met
        (``volviz.render.error_budget``)."""
        render = self.scene.session.render
        choice = error_budget_choice(rmse, render.options, render.method)
        if choice.message is not None:
            self.status.setText(choice.message)
        if choice.table is None:
            return
        values = self.render_settings.settings()
        values["options"].update(choice.table)
        self.render_settings.load_values(values)
        self.settings_changed(values)

    def schedule_render(self) -> None:
        """Draw once control returns to the event loop: a repaint of the viewport, which renders (Qt merges the
        repaints asked for in one pass). One render per frame instead of two: ``render_scene`` renders, then the
        widget's paint renders again (pyvistaqt), each a full render (docs/bench/docstring-figures.md)."""
        self.plotter.interactor.update()

    def _schedule_camera_moving(self) -> None:
        """A VTK interaction moved the camera (a mouse drag): refresh what follows it once control returns to the
        event loop (one queued refresh however many motion events arrive before)."""
        if not self._moving_scheduled:
            self._moving_scheduled = True
            QTimer.singleShot(0, self.camera_moving)

    def camera_moving(self) -> None:
        """While the mouse moves the camera, the camera views follow it (``refresh_views`` with ``moving``): re-made
        in the background, one update of each in flight and the newest camera next (``OneInFlight``), so each shows
        every update it finishes. VTK draws its own props at once. Images are previews at 1 / ``MOVING_SCALE`` of the
        window's size in each direction (a quarter of the pixels, magnified smoothly); the full-size images, the
        error estimate and the LOD re-selection follow at the end of the interaction (``camera_moved``)."""
        self._moving_scheduled = False
        if self.controller is not None:
            self.refresh_views(scale=MOVING_SCALE, estimate=False, moving=True)

    def fly_moved(self) -> None:
        """A fly-mode step moved the camera: previews follow it as during a mouse drag (``camera_moving``, at
        ``FLY_SCALE``), and the full-size images once the keys have stopped for ``FLY_SETTLE_MS``."""
        self._moving_scheduled = False
        if not self.fly_settle_timer.isActive():   # the flight starts: frames at the interactive rate until it stops
            interactive_rate(self.plotter, True)
        if self.controller is not None:
            self.refresh_views(scale=FLY_SCALE, estimate=False, moving=True)
        self.fly_settle_timer.start()

    def fly_stopped(self) -> None:
        """No fly-mode key moved the camera for ``FLY_SETTLE_MS``: the still rate again, and the full-size views;
        unless a movement key is still held (``FlyMode.held``: a long frame delayed its auto-repeat; a full-size
        frame then, with a synchronous render at the still rate, stalled the flight further). The flight's reduced
        frames (``FlyMode.frames``) go on until the views' full-size updates are shown, then the full-resolution
        frame: no synchronous full-size render of the flight's previews before them."""
        fly = self.fly
        if fly is None:   # not reached: the settle timer is made with the fly mode (``watch_viewport``)
            return
        if fly.held:
            self.fly_settle_timer.start()
            return
        interactive_rate(self.plotter, False)
        self.refresh_views(settled=fly.frames.ending())

    def camera_moved(self) -> None:
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
        through ``volviz_app.scene_edits.SceneEdits.scene_changed``). A transfer function: re-made in the background,
        while a point is dragged as a preview (``MOVING_SCALE``), a finished edit at full size with a fresh error
        estimate (VTK's own mappers draw it at once). Visibility, opacity, clipping: drawn, and the views refreshed
        except those waiting for a cut made on the CPU (``controller.pending``, refreshed once their cut is shown) and
        those of a component without a view yet (a natural-scene component or one being prepared: refreshed once
        installed). The isosurfaces' mode, and a transfer function (the overlay splits a regular volume at the surfaces,
        ``volviz.render.iso_volume_split``): the CPU overlay re-rendered."""
        controller = self.controller
        comp = change.component
        if controller is None or (change.what == "visible" and comp not in controller.views):
            return
        if change.what == "transfer_function":   # the isosurfaces' CPU overlay holds the volume in front of them
            if not self.refresh_views([comp, "iso-overlay"] if comp else None, estimate=not change.preview,
                                      scale=MOVING_SCALE if change.preview else 1):
                self.render_edit(change.preview)
            return
        self.render_scene()
        if change.what == "iso_mode":
            self.refresh_iso_overlay()
        elif comp is None:   # clipping: every camera view but the natural scene's
            self.refresh_views([key for key, view in controller.camera_views().items()
                                if view.kind != "nature" and key.split(":", 1)[-1] not in controller.pending])
        elif comp not in controller.pending:
            self.refresh_views([comp, "iso-overlay"])

    def render_edit(self, preview: bool) -> None:
        """Draw an edit now: a ``preview`` (a TF point being dragged) at VTK's interactive rate, as a camera drag's
        frames (its ray casters cast fewer rays: a still frame of a regular volume holds the event loop well over
        100 ms on a software OpenGL, docs/bench/flow-gaps.md), the finished edit at the rate the window had."""
        ren_win = self.plotter.ren_win
        if not preview or ren_win is None:
            self.render_scene()
            return
        rate = ren_win.GetDesiredUpdateRate()
        interactive_rate(self.plotter, True)
        try:
            self.render_scene()
        finally:
            ren_win.SetDesiredUpdateRate(rate)

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
        jobs = self.view_jobs.setdefault(key, OneInFlight())
        what = view.job[1]
        comp_id = key.split(":", 1)[-1]

        def still_shown() -> bool:
            return self.controller is controller and controller.camera_views().get(key) is view

        def step(scale: int) -> Callable[[Callable[[], None]], None]:
            def start(next_request: Callable[[], None]) -> None:
                if not still_shown():
                    next_request()
                    return
                # an image over the scene reads the scene back: from the next still frame drawn in strips when there
                # is one (``read_back``), else drawn whole here (``ImageOverlay.opaque_buffers``)
                if scale == 1 and isinstance(view, OverlayView) and self.read_back is not None:
                    if self.read_back(lambda drawn: begin(next_request, drawn)):
                        return
                begin(next_request, None)

            def begin(next_request: Callable[[], None], drawn: Optional[Buffers]) -> None:
                if not still_shown():
                    next_request()
                    return
                request = view.begin(scale=scale) if drawn is None else view.begin(scale=scale, drawn=drawn)

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
