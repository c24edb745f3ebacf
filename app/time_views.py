"""The display time of the main window's scene: the timeline's time, interpolation switch and playback shown in the
scene. The volumes of time series are blended and their isosurfaces re-extracted for the display time in the
background (issue #8: playback never waits; one job in flight per kind, the newest display time next:
``volviz.jobs.OneInFlight``), then given to VTK on the GUI thread and drawn once; during playback VTK draws at its
interactive rate (``view_scheduler.interactive_rate``).

Held by the window as ``window.time_views`` (issue #31: a part with its own state, not a mixin). Its collaborators
are the shown scene (``shown_scene.ShownScene``), the plotter, the window's ``jobs`` and the timeline (whose signals
it connects), and as callbacks ``show_error(title, text)``, ``schedule_render()``, ``refresh_iso_overlay()``,
``refresh_views(comp_ids, estimate=False)`` (the view scheduler's: the isosurfaces' CPU overlay follows new
isosurfaces, a PT volume's image its new mesh) and ``cut_again(controller, comp_ids)`` (the clipping's cut of a PT
volume's new mesh, made in the background, when the clipping changed while its blend was made). The window calls
``scene_installed()`` for a new scene."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable, Optional

from volviz.jobs import JobOutcome, OneInFlight
from volviz.render.controller import MeshFrame
from .shown_scene import ShownScene
from .view_scheduler import interactive_rate

if TYPE_CHECKING:
    from volviz.render.controller import SceneController
    from .docks.timeline import Timeline
    from .viewport_types import Viewport
    from .workers import JobBridge


class TimeViews:
    """The scene at the timeline's display time (see the module's docstring)."""

    def __init__(self, scene: ShownScene, plotter: Viewport, jobs: JobBridge, timeline: Timeline, *,
                 show_error: Callable[[str, str], None], schedule_render: Callable[[], None],
                 refresh_iso_overlay: Callable[[], None], refresh_views: Callable[..., int],
                 cut_again: Callable[[SceneController, list[str]], None]) -> None:
        self.scene, self.plotter, self.jobs, self.timeline = scene, plotter, jobs, timeline
        self.show_error, self.schedule_render = show_error, schedule_render
        self.refresh_iso_overlay = refresh_iso_overlay
        self.refresh_views = refresh_views
        self.cut_again = cut_again
        self._iso_jobs = OneInFlight()     # isosurface extraction for the display time
        self._volume_jobs = OneInFlight()  # blended volumes of time series for the display time
        self.volume_time_shown: Optional[tuple[float, bool]] = None  # (time, interpolated) of the shown volumes
        self.iso_time_shown: Optional[tuple[float, bool]] = None     # (time, interpolated) of the shown isosurfaces
        timeline.timeChanged.connect(self.time_changed)
        timeline.interpolationToggled.connect(self.interpolation_toggled)
        timeline.play_button.toggled.connect(self.playing_changed)

    @property
    def controller(self) -> Optional[SceneController]:
        """The shown scene's, read when needed: the window replaces it when it shows another scene."""
        return self.scene.controller

    def scene_installed(self) -> None:
        """A new scene is shown (at its session's display time): no blend or extraction of it shown yet."""
        self.volume_time_shown = self.iso_time_shown = None

    def time_changed(self, t: float) -> None:
        if self.controller is not None and self.controller.time_series():
            self._show_time(t, None)

    def playing_changed(self, playing: bool) -> None:
        """During playback VTK draws at its interactive rate, as while the mouse moves the camera (its ray casters
        then cast fewer rays); at the pause the still rate, and one full-quality frame."""
        if self.plotter.ren_win is None:  # the window has closed
            return
        interactive_rate(self.plotter, playing)
        if not playing:
            self.schedule_render()

    def interpolation_toggled(self, on: bool) -> None:
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
            stale = controller.show_volumes(result)
            self.volume_time_shown = key
            if stale:                                    # cut by an older clipping: cut again, shown when made
                self.cut_again(controller, stale)
            meshes = [comp_id for comp_id, frame in result.items() if isinstance(frame, MeshFrame)
                      and comp_id not in stale]
            if meshes:                                   # a PT volume's image of its new mesh
                self.refresh_views(meshes, estimate=False)

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
