"""Screenshot and movie export in the background (issue #5: "export screenshot (PNG, any size, offscreen re-render)
and movie along a camera path or through time, with progress"; background work stays off the UI thread).

One mechanism for both: a screenshot is an export of one frame. The scene is prepared on a worker and its props
added to an offscreen plotter on the GUI thread. Each frame then takes these steps:
1. The GUI thread sets the frame's camera and display time. A worker re-extracts the time series' isosurfaces and
   blends its volumes, and the GUI thread shows them.
2. A worker computes the view-dependent CPU images (natural scene, LOD blocks, PT volumes, iso overlay) in the two
   stages of ``SceneController.begin_views``. The GUI thread hands them to VTK.
3. The GUI thread makes the final VTK render. A worker encodes and writes the frame.
Between steps the event loop runs. Cancel (the status bar's button) stops at the running step. A newer export
supersedes an older one. A partial movie is removed (``MovieWriter.abort``).
"""
from __future__ import annotations

import logging
import threading
from typing import Any, Callable, Optional

from PySide6.QtCore import QTimer

log = logging.getLogger("volviz.app")

STAGE_MS = 30  # pause between GUI-thread stages (other events run in between)

Frame = tuple[Optional[Any], Optional[float]]  # (camera or None: keep, display time or None: keep)


class FrameExport:
    """One running export. ``window`` provides ``jobs`` (a ``JobBridge``); ``frames_of(controller)`` lists the
    frames once the scene is installed; ``open_sink()`` (on a worker) returns an object with ``append(image)``,
    ``close()`` and ``abort()``; ``on_end(ok, message)`` runs once at the end. ``transparent``: the frames keep
    alpha, without the background (``volviz.render.export.snapshot``)."""

    def __init__(self, window: Any, plotter: Any, controller: Any, size: tuple[int, int], name: str,
                 frames_of: Callable[[Any], list[Frame]], open_sink: Callable[[], Any],
                 on_end: Callable[[bool, str], None], t: Optional[float] = None, transparent: bool = False) -> None:
        self.window, self.plotter, self.controller = window, plotter, controller
        self.size, self.name = (int(size[0]), int(size[1])), name
        self.transparent = bool(transparent)
        self.frames_of, self.open_sink, self.on_end = frames_of, open_sink, on_end
        self.frames: list[Frame] = []
        self.sink: Any = None
        self.threads: set[int] = set()      # the threads its background steps ran on
        self.cancelled = False
        self.over = False
        self._job: Any = None
        self._scene_drawn = False   # the window's first render with the scene (``_frame``)
        self._step(lambda progress=None: controller.prepare(progress, t), then=self._installed,
                   message="preparing the scene")
        # the offscreen window's GL context is made by a first (empty) render, in its own turn of the event loop
        QTimer.singleShot(STAGE_MS, lambda: not self.over and not controller.props and self._snapshot((8, 8)))

    # -- control ----------------------------------------------------------------------------------------------------
    def cancel(self) -> None:
        """Stop at the running step; the export ends as cancelled."""
        self.cancelled = True
        if self._job is not None and not self._job.done():
            self._job.cancel()

    def abandon(self, wait_s: float = 10.0) -> None:
        """The window closes: stop now, without callbacks. The running step is cancelled and given ``wait_s`` to
        return (it may be writing to the movie), then the partial movie is removed and the offscreen plotter closed."""
        if self.over:
            return
        self.over = self.cancelled = True
        job = self._job
        if job is not None and not job.done():
            job.cancel()
            try:
                job.outcome(timeout=wait_s)
            except Exception:  # cancelled, failed or still running: the file is removed below either way
                pass
        self._release(abort=True)

    def _release(self, abort: bool) -> None:
        """Close the offscreen scene and let go of the output; ``abort``: remove what was written of it."""
        from volviz.render.export import close_scene

        close_scene(self.plotter, self.controller)
        sink, self.sink = self.sink, None
        if sink is not None and abort:
            try:
                sink.abort()  # no partial movie left behind
            except Exception:
                log.exception("could not remove the partial export of %s", self.name)

    def _end(self, ok: bool, message: str, error: Optional[BaseException] = None) -> None:
        if self.over:
            return
        self.over = True
        self._release(abort=not ok)
        if error is not None:
            log.error("export of %s failed: %s", self.name, error)
        self.on_end(ok, message if error is None else f"{message}: {error}")

    def _step(self, fn: Callable[..., Any], then: Callable[[Any], None], message: str, frame: int = 0) -> None:
        """Run ``fn(progress=...)`` on a worker, then ``then(result)`` here, unless cancelled or failed meanwhile."""
        n = max(len(self.frames), 1)

        def run(progress: Any = None) -> Any:
            self.threads.add(threading.get_ident())

            def scaled(fraction: float, text: str = "") -> None:
                if progress is not None:
                    prefix = f"{self.name}: frame {frame + 1} of {n}" if len(self.frames) > 1 else self.name
                    progress((frame + fraction) / n, f"{prefix}: {text or message}")

            scaled(0.0)
            return fn(progress=scaled)

        def done(outcome: Any) -> None:
            if outcome.error is not None and not (self.over or self.cancelled or outcome.cancelled):
                self._end(False, f"Could not export {self.name}", outcome.error)
            else:
                self._continue(lambda: then(outcome.result), outcome.cancelled)

        # no job key: with one, a newer export's job would drop this one's completion (its plotter never closed)
        self._job = self.window.jobs.submit(run, name=f"export {self.name}", on_done=done)

    def _later(self, fn: Callable[[], None]) -> None:
        """``fn`` in a later turn of the event loop, unless the export ended meanwhile."""
        QTimer.singleShot(STAGE_MS, lambda: self._continue(fn))

    def _continue(self, fn: Callable[[], None], cancelled: bool = False) -> None:
        """GUI thread: the next step ``fn``, unless the export is over or cancelled; a failure (the VTK side) ends it
        with a message, and the app keeps working."""
        if self.over:
            return
        if cancelled or self.cancelled:
            self._end(False, f"Export of {self.name} cancelled")
            return
        try:
            fn()
        except Exception as exc:
            log.exception("export of %s failed", self.name)
            self._end(False, f"Could not export {self.name}", exc)

    # -- the frames -------------------------------------------------------------------------------------------------
    def _installed(self, prepared: Any) -> None:
        self.controller.install(prepared, views=False)
        self.frames = list(self.frames_of(self.controller))
        if not self.frames:
            raise ValueError("there are no frames to export")
        self._step(self._open_sink, then=lambda _: self._frame(0), message="opening the output")

    def _open_sink(self, progress: Any = None) -> None:
        """Worker: open the output and keep it at once, so that an export cancelled meanwhile still removes it."""
        self.sink = self.open_sink()

    def _frame(self, i: int) -> None:
        from volviz.render.export import size_window

        if i == 0 and not self._scene_drawn:
            # the offscreen window's first render with the scene (shaders, textures) at a tiny size in its own turn
            # of the event loop, before the views begin at the frame's size (together they held it over 100 ms)
            self._scene_drawn = True
            self._snapshot((8, 8))
            self._later(lambda: self._frame(i))
            return
        camera, t = self.frames[i]
        c = self.controller
        size_window(self.plotter, self.size)  # the views begin at the frame's size (the GL warm-up render is 8x8)
        if camera is not None:
            c.set_camera(camera, update=False)
        if t is not None and t != c.time:
            c.set_time(t, update=False, isosurfaces=False, volumes=False)
            isosurfaces, volumes = c.time_isosurfaces(), c.time_volumes()
            if isosurfaces or volumes:
                def parts(progress: Any = None) -> tuple[dict[str, Any], dict[str, Any]]:
                    return ({k: c.isosurface_parts(k, t) for k in isosurfaces},
                            {k: c.blend_volume(k, t) for k in volumes})

                def show(result: tuple[dict[str, Any], dict[str, Any]]) -> None:
                    c.show_isosurfaces(result[0])
                    c.show_volumes(result[1])
                    self._views(i, 0)

                self._step(parts, then=show, message=f"the data at t = {t:.4g}", frame=i)
                return
        self._views(i, 0)

    def _views(self, i: int, stage: int) -> None:
        if stage == 2:
            self._later(lambda: self._render(i))
            return
        requests = self.controller.begin_views(stage)
        if not requests:
            self._views(i, stage + 1)
            return

        def shown(results: Any) -> None:
            self.controller.finish_views(requests, results)
            self._views(i, stage + 1)

        self._step(lambda progress=None: self.controller.compute_views(requests, progress=progress), then=shown,
                   message="rendering the views", frame=i)

    def _render(self, i: int) -> None:
        image = self._snapshot(self.size, self.transparent)
        sink = self.sink

        def written(_: Any) -> None:
            if i + 1 < len(self.frames):
                self._later(lambda: self._frame(i + 1))
                return
            self._step(lambda progress=None: sink.close(), then=self._closed, message="finishing", frame=i)

        self._step(lambda progress=None: sink.append(image), then=written, message="writing", frame=i)

    def _closed(self, _: Any) -> None:
        self.sink = None
        frames = f"{len(self.frames)} frames, " if len(self.frames) > 1 else ""
        self._end(True, f"Exported {self.name} ({frames}{self.size[0]}x{self.size[1]})")

    def _snapshot(self, size: tuple[int, int], transparent: bool = False) -> Any:
        from volviz.render.export import snapshot

        return snapshot(self.plotter, size, transparent)
