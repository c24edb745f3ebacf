"""A still frame drawn in horizontal strips, one VTK render each (issue #28: no event-loop stall over 100 ms).

VTK renders on the GUI thread; on a software OpenGL a still frame of a regular volume holds it well over 100 ms at
the window's size, most of it per pixel (measured in docs/bench/flow-gaps.md). Strip k of n draws the renderer into
pixel rows [r_k, r_k+1) of its viewport with the same camera's sub-frustum of those rows (the camera's window centre
moved, its vertical view angle or parallel scale narrowed by the strip's share of the height), without swapping: the
render framebuffer keeps the strips drawn before. The renderer's 2D props (scalar bar, titles), placed in viewport
coordinates, and the renderers over it (the orientation axes) are left out of the strips and drawn in a last pass
over the whole viewport that erases nothing, then the frame is swapped. The camera, viewport, visibilities and
swapping are put back after each pass, so no other code sees them changed; a render by anyone else between two
passes draws a whole frame over the strips (the caller notices it: ``volviz_app.still_strips``).
"""
from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Any, Callable, Optional, Sequence, TypeVar

if TYPE_CHECKING:   # type-only imports for the signatures
    from volviz.render.vtk_facade import vtkRenderer, vtkRenderWindow

T = TypeVar("T")

MAX_STRIPS = 16
SPLIT_OVER_S = 0.08      # a still frame that took longer is drawn in strips next time (the app's rule)
STRIP_BUDGET_S = 0.05    # the mean time of a strip; the volume fills the middle strips: twice as many as that needs
PASS_BUDGET_S = 0.03     # each later strip's rows drawn in this time at the last strip's rate (denser ones follow)
FIRST_FRAME_S = 0.4      # what a new scene's first still frame is taken to cost before it is measured (16 strips)
PAYS_UNDER_S = 0.08      # strips pay where a frame's thinnest strip took less: else each pass holds the loop as long
STOP_AFTER_S = 0.05      # a strip still ray casting this long after its pass began is stopped (``StripFrame``)
STOP_OVER_ROWS = 8       # a strip of more rows can be stopped: a thinner one is drawn to its end


#: the strips of a frame: (first row, row past the last, seconds its pass took)
StripCosts = Sequence[tuple[int, int, float]]


def planned_rows(profile: StripCosts, lo: int, budget_s: float, most: int) -> int:
    """How many rows from ``lo`` up a strip gets so that it takes ``budget_s`` at the rates of ``profile`` (the strips
    of an earlier frame of the same height: each row costs its strip's seconds over its rows), at least 1, at most
    ``most``: a denser part of the picture gets thinner strips before it is drawn, not after."""
    rows, spent = 0, 0.0
    for a, b, seconds in profile:
        if b <= lo:
            continue
        per_row = max(seconds, 1e-9) / max(1, b - a)
        start = max(a, lo + rows)
        fit = int((budget_s - spent) / per_row + 1e-9)   # (rows that fit exactly count)
        if fit < b - start:
            rows += max(0, fit)
            break
        rows += b - start
        spent += (b - start) * per_row
        if rows >= most:
            break
    return max(1, min(most, rows))


def last_strip_share(costs: StripCosts, height: Optional[int] = None) -> float:
    """The share of a frame drawn in strips (``StripFrame.costs``) that its last strip took, in (0, 1]. VTK's ray
    casters size the next frame's rays from the time their last render took over the time it is allotted
    (``vtkFixedPointVolumeRayCastMapper::ComputeRequiredImageSampleDistance``): after a frame in strips that render
    was the last strip's, so the next interactive frame, allotted its time scaled by this share, gets the rays
    of the frame's whole cost (unscaled, the first frame of a drag after it cast rays for every pixel). ``height``:
    the frame's rows, for a frame cut short (a playback or a drag began before its last strip): its whole cost is
    taken as what its strips took, times its rows over theirs."""
    spent = sum(seconds for _, _, seconds in costs)
    rows = sum(hi - lo for lo, hi, _ in costs)
    if not costs or spent <= 0.0 or rows <= 0:
        return 1.0
    total = spent * max(1.0, (height if height is not None else rows) / rows)
    return min(1.0, max(costs[-1][2], 1e-6) / total)


def strips_for(seconds: float) -> int:
    """How many strips a still frame that takes ``seconds`` whole is drawn in (1: whole)."""
    if seconds <= SPLIT_OVER_S:
        return 1
    return min(MAX_STRIPS, max(2, math.ceil(2.0 * seconds / STRIP_BUDGET_S)))


def strip_window_center(center_y: float, lo: float, hi: float) -> float:
    """The camera's vertical window centre that shows rows [``lo``, ``hi``) (fractions of the viewport's height,
    from the bottom) of the frame a camera with ``center_y`` shows: VTK's frustum spans (c - 1) h .. (c + 1) h in
    height; the strip's spans (c - 1 + 2 lo) h .. (c - 1 + 2 hi) h, which is (c' - 1) f h .. (c' + 1) f h with
    f = hi - lo."""
    return (center_y - 1.0 + 2.0 * lo) / (hi - lo) + 1.0


def _renderers(ren_win: vtkRenderWindow) -> list[Any]:
    found = ren_win.GetRenderers()
    found.InitTraversal()
    return [found.GetNextItem() for _ in range(found.GetNumberOfItems())]


def can_strip(ren_win: vtkRenderWindow, renderer: vtkRenderer) -> bool:
    """Whether ``renderer`` is the only renderer of ``ren_win`` drawn in its layer or below (renderers in layers
    above, such as the orientation axes', are overlays drawn in the last pass): another one would draw over the
    strips or between them; and whether it shows volumes, all ray cast (``ray_cast_volumes``)."""
    return (not any(r is not renderer and r.GetDraw() and r.GetLayer() <= renderer.GetLayer()
                    for r in _renderers(ren_win)) and ray_cast_volumes(renderer))


def ray_cast_volumes(renderer: vtkRenderer) -> bool:
    """Whether ``renderer`` shows volumes and every one is drawn by a ray caster of image data (``vtkVolumeMapper``:
    its cost follows the pixels, so a strip costs its share). VTK's projected tetrahedra sort and project every cell
    at each render: each strip would cost the whole frame. Geometry alone is drawn whole too: each strip draws all
    of it, and each strip's own projection rounds a 1-pixel line's pixels its own way, so a line can move a pixel
    between a frame in strips and a whole one; a CPU image over the scene cut by the depth read back from one of
    them (``image_overlay``) then shows the volume over the line, and a hole beside it, in the other."""
    mappers = _shown_volume_mappers(renderer)
    return bool(mappers) and all(mapper.IsA("vtkVolumeMapper") for mapper in mappers)


def _shown_volume_mappers(renderer: vtkRenderer) -> list[Any]:
    """The mappers of ``renderer``'s visible volumes."""
    volumes = renderer.GetVolumes()
    volumes.InitTraversal()
    shown = []
    for _ in range(volumes.GetNumberOfItems()):
        volume = volumes.GetNextVolume()
        mapper = volume.GetMapper() if volume is not None and volume.GetVisibility() else None
        if mapper is not None:
            shown.append(mapper)
    return shown


class StripFrame:
    """One still frame of ``ren_win`` drawn in strips of ``renderer``, bottom first, then a last pass for its 2D props
    and the renderers over it when there are any. ``strips``: how many strips at first; with ``budget_s`` each strip
    after the first gets the rows the last one drew in that time (a denser part of the picture gets thinner strips;
    none higher than the first), else all have the same height; with the ``profile`` of an earlier frame of the
    same height too, each strip is planned from its rates (``planned_rows``). ``step()`` draws the next pass;
    ``done`` once the frame is swapped; ``costs`` has its strips' rows and seconds. ``after_base`` is called when
    the whole frame but the renderers ``images`` is drawn: what is then in the render window is the scene without
    those images (``ImageOverlay.opaque_buffers``' read-back; the last pass is then two: all but the images, and
    the images). With ``stop_after_s``, a strip of over ``STOP_OVER_ROWS`` rows whose volumes are still ray cast that
    long after its pass began is stopped (VTK's abort of a render, checked by the CPU ray caster every few rows; the
    GPU ray caster does not check it): its rows are drawn again by strips a quarter as high, planned from their own
    rates, so that a band denser than its plan (the profile is of the frame before, at another camera or of another
    picture) does not hold the pass for the whole band; ``stopped`` has the rows and seconds of each."""

    def __init__(self, ren_win: vtkRenderWindow, renderer: vtkRenderer, strips: int,
                 budget_s: Optional[float] = None, profile: Optional[StripCosts] = None,
                 after_base: Optional[Callable[[], None]] = None, images: Sequence[vtkRenderer] = (),
                 stop_after_s: Optional[float] = None) -> None:
        self.ren_win, self.renderer, self.budget_s, self.stop_after_s = ren_win, renderer, budget_s, stop_after_s
        self.stopped: list[tuple[int, int, float]] = []   # the strips stopped: their rows and seconds
        self.after_base = after_base   # called once all but the ``images`` renderers over it are drawn
        self.images = list(images)
        self.height = max(1, int(renderer.GetSize()[1]))
        self.rows_per_strip = self.most_rows = math.ceil(self.height / max(1, min(MAX_STRIPS, int(strips))))
        self.profile = list(profile) if profile and budget_s is not None and profile[-1][1] == self.height else None
        self.costs: list[tuple[int, int, float]] = []
        self.overlays = [r for r in _renderers(ren_win)
                         if r is not renderer and r.GetDraw() and r.GetLayer() > renderer.GetLayer()]
        self.last_pass_2d = bool(self._shown_2d() or self.overlays)
        self.drawn: list[tuple[int, int]] = []     # the rows [lo, hi) of each strip drawn so far
        self.done = False
        self.view = self._view()

    def read_after_base(self, read: Callable[[], None], images: Sequence[vtkRenderer] = ()) -> None:
        """``after_base`` and ``images`` from now on (a read-back asked for while the frame is drawn): ``read()`` now
        when the strips have drawn the whole frame already, which has no last pass (no 2D props, no renderers over
        it)."""
        self.after_base, self.images = read, list(images)
        if self.drawn and self.drawn[-1][1] >= self.height and not self.done and not self.last_pass_2d:
            read()

    def _view(self) -> tuple[Any, ...]:
        """What the strips' picture depends on that others may change between passes: the camera's pose and lens,
        and the window's size (not the clipping range, which VTK may reset at any render)."""
        cam = self.renderer.GetActiveCamera()
        return (cam.GetPosition(), cam.GetFocalPoint(), cam.GetViewUp(), cam.GetViewAngle(), cam.GetWindowCenter(),
                cam.GetParallelProjection(), cam.GetParallelScale(), tuple(self.ren_win.GetSize()),
                tuple(self.renderer.GetSize()))

    def stale(self) -> bool:
        """Whether the camera or the window changed since the frame began: its strips would not fit together."""
        return self._view() != self.view

    def _shown_2d(self) -> list[Any]:
        props = self.renderer.GetActors2D()
        props.InitTraversal()
        shown = []
        for _ in range(props.GetNumberOfItems()):
            prop = props.GetNextActor2D()
            if prop is not None and prop.GetVisibility():
                shown.append(prop)
        return shown

    def step(self) -> bool:
        """Draw the next pass; True once the frame is complete and swapped."""
        if self.done:
            return True
        lo = self.drawn[-1][1] if self.drawn else 0
        if lo >= self.height:
            self._props_2d()
            self.done = True
            return True
        rows = self.rows_per_strip
        if self.profile is not None and self.budget_s is not None:
            rows = planned_rows(self.profile, lo, self.budget_s, self.most_rows)
        hi = min(self.height, lo + rows)
        swap = hi >= self.height and not self.last_pass_2d
        stop = self.stop_after_s if not swap and hi - lo > STOP_OVER_ROWS else None
        start = time.perf_counter()
        if self._strip(lo, hi, swap, stop):
            # denser than planned: these rows again, thinner, from this frame's own rates from now on
            self.stopped.append((lo, hi, time.perf_counter() - start))
            self.profile = None
            self.rows_per_strip = max(1, (hi - lo) // 4)
            return False
        if hi >= self.height and self.after_base is not None and not self.last_pass_2d:
            self.after_base()
        elapsed = time.perf_counter() - start
        if self.budget_s is not None:
            per_row = max(elapsed, 1e-6) / (hi - lo)
            self.rows_per_strip = max(1, min(self.most_rows, int(self.budget_s / per_row)))
        self.costs.append((lo, hi, elapsed))
        self.drawn.append((lo, hi))
        self.done = swap
        return self.done

    def _render(self, swap: bool, stop_after_s: Optional[float] = None) -> bool:
        """One pass; a pass that does not swap waits for the GPU (``WaitForCompletion``), so that its drawing is done
        in its own turn, not left to the next pass. With ``stop_after_s``, the volumes' ray casting is stopped when
        it still runs that long after the pass began; True when it was."""
        swapping = self.ren_win.GetSwapBuffers()
        self.ren_win.SetSwapBuffers(1 if swap else 0)
        watched = self._stop_after(stop_after_s) if stop_after_s is not None else []
        try:
            self.ren_win.Render()
            stopped = bool(watched) and bool(self.ren_win.GetAbortRender())
            if not swap:
                self.ren_win.WaitForCompletion()
        finally:
            for mapper, tag in watched:
                mapper.RemoveObserver(tag)
            self.ren_win.SetSwapBuffers(swapping)
        return stopped

    def _stop_after(self, seconds: float) -> list[tuple[Any, int]]:
        """Observers of the renderer's volume mappers' ray casting progress (``VolumeMapperRenderProgressEvent``,
        sent by the CPU ray caster every few rows) that abort the render once ``seconds`` passed: VTK's ray casters
        check the window's abort flag as they go; the mappers with their observers' tags."""
        ren_win, deadline = self.ren_win, time.perf_counter() + seconds

        def check(*args: Any) -> None:
            if time.perf_counter() > deadline:
                ren_win.SetAbortRender(1)

        return [(mapper, mapper.AddObserver("VolumeMapperRenderProgressEvent", check))
                for mapper in _shown_volume_mappers(self.renderer) if mapper.IsA("vtkVolumeMapper")]

    def _strip(self, lo: int, hi: int, swap: bool, stop_after_s: Optional[float] = None) -> bool:
        ren, cam = self.renderer, self.renderer.GetActiveCamera()
        viewport = ren.GetViewport()
        angle, center, scale = cam.GetViewAngle(), cam.GetWindowCenter(), cam.GetParallelScale()
        hidden = self._shown_2d()
        a, b = lo / self.height, hi / self.height
        try:
            for prop in hidden:
                prop.SetVisibility(0)
            ren.SetViewport(viewport[0], viewport[1] + a * (viewport[3] - viewport[1]),
                            viewport[2], viewport[1] + b * (viewport[3] - viewport[1]))
            if cam.GetParallelProjection():
                cam.SetParallelScale(scale * (b - a))
            elif not cam.GetUseHorizontalViewAngle():   # (a horizontal angle narrows with the strip's aspect)
                cam.SetViewAngle(math.degrees(2.0 * math.atan((b - a) * math.tan(math.radians(angle) / 2.0))))
            cam.SetWindowCenter(center[0], strip_window_center(center[1], a, b))
            return self._drawing(self.overlays, False, lambda: self._render(swap, stop_after_s))
        finally:
            ren.SetViewport(*viewport)
            cam.SetViewAngle(angle)
            cam.SetParallelScale(scale)
            cam.SetWindowCenter(*center)
            for prop in hidden:
                prop.SetVisibility(1)

    def _props_2d(self) -> None:
        ren = self.renderer
        props = ren.GetViewProps()
        props.InitTraversal()
        hidden = []
        for _ in range(props.GetNumberOfItems()):
            prop = props.GetNextProp()
            if prop is not None and prop.GetVisibility() and not prop.IsA("vtkActor2D"):
                hidden.append(prop)
        images = [r for r in self.overlays if r in self.images] if self.after_base is not None else []
        erase = ren.GetErase()
        try:
            for prop in hidden:
                prop.SetVisibility(0)
            ren.SetErase(0)
            if self.after_base is not None:
                # all but the images, read back, then the images alone in the pass that swaps
                others = [r for r in self.overlays if r not in images]
                self._drawing(images, False, lambda: self._render(swap=not images))
                self.after_base()
                if not images:
                    return
                hidden += self._shown_2d()
                for prop in hidden:
                    prop.SetVisibility(0)
                self._drawing(others, False, lambda: self._render(swap=True))
                return
            self._render(swap=True)
        finally:
            ren.SetErase(erase)
            for prop in hidden:
                prop.SetVisibility(1)

    @staticmethod
    def _drawing(renderers: Sequence[Any], on: bool, draw: Callable[[], T]) -> T:
        """``draw()`` with ``renderers`` drawing (``on``) or not, as they were after; what it returned."""
        was = [r.GetDraw() for r in renderers]
        for r in renderers:
            r.SetDraw(int(on))
        try:
            return draw()
        finally:
            for r, drew in zip(renderers, was):
                r.SetDraw(drew)
