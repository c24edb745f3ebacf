"""volviz's own images (premultiplied float RGBA from a CPU renderer) drawn over a PyVista plotter's scene and
composited with its opaque geometry through the depth buffer (Guthe §4.5: a volume behind an opaque surface is
hidden, in front of it it blends). ``ImageOverlay`` draws an image; ``OverlayView`` re-makes one in a GUI / worker /
GUI split. Used by the projected-tetrahedra volumes (``pt_prop``), the isosurface overlay (``iso_overlay``) and the
LOD block ray caster (``lod_volume``).

    overlay = ImageOverlay(plotter)
    z, rgb = overlay.opaque_buffers((w, h))     # the scene rendered with every volviz overlay off, read back
    depth = zbuffer_to_depth(z, clipping_range, parallel)
    ...render the image with the ray limit ``depth``...
    overlay.show(unpremultiply_rgba8(img))      # straight-alpha RGBA8, row 0 at the top

How it draws: a full-window ``vtkImageActor`` in a renderer on a higher layer of the render window, seen by a
parallel camera, with VTK's (SRC_ALPHA, ONE_MINUS_SRC_ALPHA) blending, which is the premultiplied "over"
C = C_img + (1 - a_img) C_scene. The 8-bit round trip costs at most about 1/255 per channel. The image actor spans
its first to last point, so the centres of the image's border pixels would lie on the quad's edge, where rasterisation
drops the top row and the right column: the image is uploaded with a one-pixel border (its edge repeated) at origin
(-1, -1), so every pixel of the image is inside the quad (tested).

Eye-space depth from VTK's z-buffer: ``d = n f / (f - z (f - n))`` for perspective and ``d = n + z (f - n)`` for
parallel projection, with (n, f) the camera's clipping range; ``z = 1`` (no geometry) is unlimited. 24-bit depth at
the typical clipping ratio f/n = 1000 resolves about 1e-4 of the view distance.

Multisampling (PyVista's default, 4 samples) is switched off while any overlay is in the plotter and back on when the
last one is removed: with MSAA a silhouette pixel of opaque geometry has a blended color (object and what is behind
it) but VTK's depth read-back gives one depth, so the image was cut there by that one depth for the whole pixel: a
one-pixel edge around opaque objects (docs/bench/docstring-figures.md).
Compositing per sample would need every sample's depth, which ``GetZbufferData`` does not give.

A plotter drawn by a software rasteriser has no multisampling at all (``single_sample_on_software``): there 4x MSAA
made every frame several times as costly (docs/bench/multisampling.md), and each still frame of a large scene held
the window that much longer. Hardware drivers keep the plotter's setting; ``volviz render`` and the app follow the same
rule, so their pictures still agree.
"""
from __future__ import annotations

import time
import weakref
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Generic, Optional, Protocol, TypeVar, Union

import numpy as np

from volviz.model.camera import Camera
from volviz.render.backend import plotter_gl_info

if TYPE_CHECKING:   # type-only: VTK's classes, reached through the facade at run time; the progress callback
    import pyvista as pv

    from volviz.jobs import ProgressCallback
    from volviz.render.vtk_facade import vtkRenderer, vtkRenderWindow

__all__ = ["ImageOverlay", "OverlayRequest", "OverlayStats", "OverlayView", "StatsT", "WindowPlotter", "block_min",
           "overlay_rgba8", "read_buffers", "read_premultiplied", "single_sample_on_software", "unpremultiply_rgba8",
           "zbuffer_to_depth"]

#: every overlay renderer of a plotter (the renderers are VTK objects: a plotter's list lives as long as it does)
_SIBLINGS: "weakref.WeakKeyDictionary[Any, list[Any]]" = weakref.WeakKeyDictionary()


def zbuffer_to_depth(z: np.ndarray, clipping_range: tuple[float, float], parallel: bool) -> np.ndarray:
    """OpenGL window depth z in [0, 1] -> eye-space depth along the direction of projection; z >= 1 -> +inf."""
    n, f = (float(v) for v in clipping_range)
    z = np.asarray(z, dtype=np.float64)
    if parallel:
        d = n + z * (f - n)
    else:
        with np.errstate(divide="ignore"):
            d = n * f / (f - z * (f - n))
    return np.where((z >= 1.0) | ~np.isfinite(z), np.inf, d)


def _block_starts(shape: tuple[int, ...], size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """The first row and column of the (H, W) pixels under each pixel of a ``size`` (w, h) image of the same view."""
    w, h = (int(v) for v in size)
    return (np.arange(h) * shape[0]) // h, (np.arange(w) * shape[1]) // w


def block_min(depth: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """A (H, W) depth image reduced to ``size`` (w, h) pixels covering the same view: each is the minimum of the
    pixels it covers, so a smaller image is cut at the nearest opaque surface under each of its pixels."""
    rows, cols = _block_starts(depth.shape, size)
    return np.minimum.reduceat(np.minimum.reduceat(depth, rows, axis=0), cols, axis=1)


def overlay_rgba8(image: np.ndarray, request: Optional[OverlayRequest] = None) -> np.ndarray:
    """Premultiplied float RGBA as ``ImageOverlay.show`` takes it: straight-alpha RGBA8 (``unpremultiply_rgba8``);
    a preview of ``request`` (``OverlayView.begin`` with ``scale`` > 1) magnified to the window first
    (``preview_upsample``). Made on a worker where possible (``PTVolume.compute``)."""
    if request is not None and request.get("preview") and ("window_depth" in request or "_read_back" in request):
        from volviz.render.preview_upsample import upsample_preview  # Numba: loaded by a moving camera's preview

        image = upsample_preview(image, request["depth"], request["window_depth"])
    return unpremultiply_rgba8(image)


def unpremultiply_rgba8(image: np.ndarray) -> np.ndarray:
    """Premultiplied float RGBA (H, W, 4) -> straight-alpha uint8 RGBA (H, W, 4) for (SRC_ALPHA, 1 - SRC_ALPHA)."""
    a = np.clip(image[..., 3:4], 0.0, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(a > 0, image[..., :3] / a, 0.0)
    out = np.empty(image.shape[:2] + (4,), np.uint8)
    out[..., :3] = np.rint(np.clip(c, 0.0, 1.0) * 255.0)
    out[..., 3] = np.rint(a[..., 0] * 255.0)
    return out


#: a render window's (z (H, W) float64, rgb (H, W, 3) uint8), row 0 at the top (``read_buffers``)
Buffers = tuple[np.ndarray, np.ndarray]


def image_renderers(plotter: object) -> list[vtkRenderer]:
    """The renderers of ``plotter``'s image overlays (``ImageOverlay``), which its read-back leaves out."""
    return list(_SIBLINGS.get(plotter, []))


def read_buffers(ren_win: vtkRenderWindow, w: int, h: int) -> Buffers:
    """(z (H, W) float64, rgb (H, W, 3) uint8) of the render window, row 0 at the top. ``rgb`` is a view of the RGBA
    rows copied whole: gathering 3 of 4 bytes per pixel into a new array was most of the read-back's time on the
    GUI thread."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk, vtk_to_numpy

    z = vtk.vtkFloatArray()
    ren_win.GetZbufferData(0, 0, w - 1, h - 1, z)
    rgb = vtk.vtkUnsignedCharArray()
    ren_win.GetRGBACharPixelData(0, 0, w - 1, h - 1, 0, rgb)
    zz = vtk_to_numpy(z).reshape(h, w)[::-1].astype(np.float64)
    cc = np.ascontiguousarray(vtk_to_numpy(rgb).reshape(h, w, 4)[::-1])[:, :, :3]
    return zz, cc


def read_premultiplied(ren_win: vtkRenderWindow, w: int, h: int) -> np.ndarray:
    """The render window's colour and alpha as float RGBA (H, W, 4) in 8-bit steps, row 0 at the top: the
    premultiplied image of what it drew over a transparent black background (the offscreen windows of
    ``volviz.render.gl_thread``)."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk, vtk_to_numpy

    rgba = vtk.vtkUnsignedCharArray()
    ren_win.GetRGBACharPixelData(0, 0, w - 1, h - 1, 0, rgba)
    return vtk_to_numpy(rgba).reshape(h, w, 4)[::-1].astype(np.float64) / 255.0


def window_size(window: Union[vtkRenderer, vtkRenderWindow]) -> tuple[int, int]:
    """The (width, height) in pixels of a vtkRenderer or vtkRenderWindow."""
    width, height = window.GetSize()
    return int(width), int(height)


class WindowPlotter(Protocol):
    """A plotter with an open render window, what the multisampling holds read (PyVista types ``ren_win`` Optional,
    None once the plotter is closed; these are called while it is open)."""

    @property
    def ren_win(self) -> vtkRenderWindow: ...


@dataclass
class _SingleSample:
    """A plotter's multisampling while overlays hold it off: the setting to restore and the ids of the holders (ids,
    not the holders: they refer to the plotter, which would then never leave ``_single_sample``)."""

    restore: int
    holders: list[int] = field(default_factory=list)


_single_sample: weakref.WeakKeyDictionary[Any, _SingleSample] = weakref.WeakKeyDictionary()   # by plotter


def hold_single_sample(plotter: WindowPlotter, holder: object) -> None:
    """Multisampling off while ``holder`` is in the plotter (one color and depth per pixel: the overlays read the
    depth back, the GL PT pass draws into a single-sample float target; module docstring)."""
    held = _single_sample.get(plotter)
    if held is None:
        held = _single_sample[plotter] = _SingleSample(int(plotter.ren_win.GetMultiSamples()))
        plotter.ren_win.SetMultiSamples(0)
    held.holders.append(id(holder))


def single_sample_on_software(plotter: pv.BasePlotter) -> None:
    """No multisampling in ``plotter`` when a software rasteriser draws it, and none to restore when the last
    overlay leaves (module docstring); a hardware driver keeps the plotter's setting."""
    if plotter_gl_info(plotter).software:
        window = plotter.ren_win
        assert window is not None   # open: its driver was just asked (PyVista types it None once closed)
        window.SetMultiSamples(0)
        held = _single_sample.get(plotter)
        if held is not None:
            held.restore = 0


def release_single_sample(plotter: WindowPlotter, holder: object) -> None:
    """``holder`` is gone: the last one restores the plotter's multisampling."""
    held = _single_sample.get(plotter)
    if held is None:
        return
    if id(holder) in held.holders:
        held.holders.remove(id(holder))
    if not held.holders:
        plotter.ren_win.SetMultiSamples(_single_sample.pop(plotter).restore)


class ImageOverlay:
    """One full-window image over a plotter's scene (see the module docstring). Starts hidden."""

    def __init__(self, plotter: Any) -> None:
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk

        self.plotter = plotter
        ren_win = plotter.ren_win
        layer = max(1, ren_win.GetNumberOfLayers())
        ren_win.SetNumberOfLayers(layer + 1)
        self.renderer = vtk.vtkRenderer()
        hold_single_sample(plotter, self.renderer)
        self.renderer.SetLayer(layer)
        self.renderer.InteractiveOff()
        # one translucent image: VTK's order-independent transparency (on by default) would draw it through float
        # targets of the window's size and a full-window resolve, the most of the image's cost on a software OpenGL
        self.renderer.SetUseOIT(False)
        self.renderer.SetViewport(plotter.renderer.GetViewport())
        self.data = vtk.vtkImageData()
        self.actor = vtk.vtkImageActor()
        self.actor.GetMapper().SetInputData(self.data)
        self.actor.InterpolateOff()
        self.actor.ForceTranslucentOn()
        self.renderer.AddActor(self.actor)
        self.renderer.GetActiveCamera().ParallelProjectionOn()
        ren_win.AddRenderer(self.renderer)
        self.renderer.DrawOff()
        self.siblings: list[Any] = _SIBLINGS.setdefault(plotter, [])
        self.siblings.append(self.renderer)

    def opaque_buffers(self, size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
        """Render the plotter's scene with every volviz overlay off and read back (z, rgb) (row 0 at the top)."""
        ren_win = self.plotter.ren_win
        shown = [o.GetDraw() for o in self.siblings]
        for o in self.siblings:
            o.DrawOff()
        ren_win.Render()
        out = read_buffers(ren_win, int(size[0]), int(size[1]))
        for o, on in zip(self.siblings, shown):
            o.SetDraw(on)
        return out

    def show(self, rgba8: np.ndarray, visible: bool = True, render: bool = True) -> None:
        """Upload straight-alpha RGBA8 (H, W, 4), row 0 at the top, and redraw the window unless ``render`` is False
        or the plotter's rendering is suppressed. The image fills the window whatever its size (pixel blocks where
        it is smaller: a preview is magnified by ``overlay_rgba8`` before)."""
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import numpy_to_vtk

        h, w = rgba8.shape[:2]
        padded = np.pad(np.asarray(rgba8, np.uint8)[::-1], ((1, 1), (1, 1), (0, 0)), mode="edge")  # VTK: bottom up
        self.data.SetOrigin(-1.0, -1.0, 0.0)
        self.data.SetDimensions(w + 2, h + 2, 1)
        arr = numpy_to_vtk(np.ascontiguousarray(padded.reshape(-1, 4)), deep=True)
        arr.SetName("rgba")
        self.data.GetPointData().SetScalars(arr)
        self.data.Modified()
        oc = self.renderer.GetActiveCamera()
        oc.SetFocalPoint((w - 1) / 2.0, (h - 1) / 2.0, 0.0)
        oc.SetPosition((w - 1) / 2.0, (h - 1) / 2.0, 1.0)
        oc.SetViewUp(0.0, 1.0, 0.0)
        oc.SetParallelScale(h / 2.0)
        oc.SetClippingRange(0.5, 1.5)
        self.renderer.SetDraw(bool(visible))
        if render and not getattr(self.plotter, "suppress_rendering", False):
            self.plotter.ren_win.Render()

    @property
    def visible(self) -> bool:
        return bool(self.renderer.GetDraw())

    @visible.setter
    def visible(self, on: bool) -> None:
        if bool(on) == self.visible:
            return
        self.renderer.SetDraw(bool(on))
        if not getattr(self.plotter, "suppress_rendering", False):
            self.plotter.ren_win.Render()      # PyVista's screenshot() does not notice a foreign renderer's change

    def remove(self) -> None:
        """Detach from the render window; the last overlay of a plotter restores its multisampling."""
        self.plotter.ren_win.RemoveRenderer(self.renderer)
        if self.renderer in self.siblings:
            self.siblings.remove(self.renderer)
        release_single_sample(self.plotter, self.renderer)


class OverlayRequest(dict[str, Any]):
    """A request of ``OverlayView.begin``: its ``depth`` (the depth limit of each image pixel), ``rgb`` (the opaque
    scene's colour under it) and, for a preview, ``window_depth`` are made from the GUI thread's raw read-back on
    their first use, on whichever thread asks first: the job's worker, so that the conversion and the preview's
    block minimum (a stall of the GUI thread under load, issue #28; docs/bench/docstring-figures.md) stay off the GUI
    thread."""

    def __missing__(self, key: str) -> Any:
        if key not in ("depth", "rgb", "window_depth") or "_read_back" not in self:
            raise KeyError(key)
        z, rgb, clipping_range, parallel = self.pop("_read_back")
        depth = zbuffer_to_depth(z, clipping_range, parallel)
        if self["preview"]:
            size = self["size"]
            self["window_depth"] = depth
            rows, cols = _block_starts(rgb.shape, size)
            depth, rgb = block_min(depth, size), rgb[rows][:, cols]
        self["depth"], self["rgb"] = depth, rgb
        return self[key]


class OverlayStats(Protocol):
    """What an overlay's ``compute`` reports and ``OverlayView.finish`` reads: the seconds it took (``total_s``);
    ``sort_s``, ``project_s``, ``raster_s``, ``fragments`` and ``n_visible`` are read where the renderer has them
    (``volviz.unstructured.render.UnstructuredRenderStats``, ``volviz.render.iso_overlay.IsoStats``)."""

    @property
    def total_s(self) -> float: ...


#: the statistics type of an ``OverlayView``'s ``compute``
StatsT = TypeVar("StatsT", bound=OverlayStats)


class OverlayView(Generic[StatsT]):
    """An image of ours (a CPU renderer's premultiplied RGBA) kept over a plotter's scene and re-made in three parts,
    so that the app can run the middle one in its job runner:

    - ``begin`` (GUI thread): render the opaque scene with every overlay off, read its depth, fix the camera (the far
      plane extended to ``_far``, since VTK's clipping range covers only VTK's own props); returns a request;
    - ``compute(request)`` (any thread, no VTK): the image and its statistics; subclasses implement it;
    - ``finish(request, img, st)`` (GUI thread): show it and record the statistics.

    ``update`` does all three. Subclasses: ``pt_prop.PTVolume`` and ``iso_overlay.IsoOverlay``, each of its own
    statistics type (``StatsT``)."""

    def __init__(self, plotter: Any) -> None:
        self.plotter = plotter
        self.stats: dict[str, Any] = {}
        self.image: np.ndarray | None = None          # last premultiplied image (H, W, 4)
        self.depth: np.ndarray | None = None          # last per-pixel depth limit (H, W)
        self.scene_rgb: np.ndarray | None = None      # last opaque scene color (H, W, 3) uint8
        self.camera: Any = None
        self._overlay = ImageOverlay(plotter)

    def _far(self, camera: Any) -> float:
        """The largest view depth of what this view draws (the far plane it needs)."""
        return float(camera.clipping_range[1])

    def update(self) -> np.ndarray:
        """Re-make the image for the plotter's current camera and opaque scene; returns the premultiplied image."""
        request = self.begin()
        return self.finish(request, *self.compute(request))

    def begin(self, scale: int = 1, drawn: Optional[Buffers] = None) -> OverlayRequest:
        """GUI-thread part 1: the opaque scene's depth and color, the camera and the image size: the window's, or
        for a preview (``scale`` > 1, e.g. while the camera moves) the window's divided by ``scale``, with the depth
        limit of each preview pixel the nearest opaque depth under it (``block_min``), the scene color at its
        first pixel and the window's own depth (``window_depth``, for ``upsample_preview``); only the read-back is
        done here, the rest where the request is first used (``OverlayRequest``). ``drawn``: the opaque scene's
        (z, rgb) read back already, for the current camera and the window's size (a still frame drawn in strips, read
        before their last pass drew the overlays: ``volviz.render.strips.StripFrame``); else it is drawn and read
        here (``ImageOverlay.opaque_buffers``)."""
        t_start = time.perf_counter()
        w, h = (int(v) for v in self.plotter.ren_win.GetSize())
        z, rgb = drawn if drawn is not None else self._overlay.opaque_buffers((w, h))
        live = Camera.from_pyvista(self.plotter.renderer.GetActiveCamera())
        near, far = live.clipping_range
        cam = Camera(live.position, live.focal_point, live.view_up, live.view_angle, live.parallel,
                     live.parallel_scale, (near, max(far, 1.01 * self._far(live))))
        size = (w, h) if scale <= 1 else (max(1, w // int(scale)), max(1, h // int(scale)))
        return OverlayRequest(camera=cam, size=size, preview=scale > 1, t_start=t_start, t_read=time.perf_counter(),
                              _read_back=(z, rgb, live.clipping_range, live.parallel))

    def compute(self, request: OverlayRequest, progress: Optional[ProgressCallback] = None
                ) -> tuple[np.ndarray, StatsT, np.ndarray]:
        """Any-thread part: (premultiplied image, statistics with ``total_s``, straight-alpha RGBA8)."""
        raise NotImplementedError

    def finish(self, request: OverlayRequest, img: np.ndarray, st: StatsT, rgba8: np.ndarray | None = None
               ) -> np.ndarray:
        """GUI-thread part 2: show a computed image and record the statistics. ``rgba8``: the image (straight alpha,
        row 0 at the top) as ``compute`` converted it (else converted here). The window redraws unless the
        plotter's rendering is suppressed (the caller then draws once itself)."""
        t_show = time.perf_counter()
        w, h = request["size"]
        self._overlay.show(overlay_rgba8(img, request) if rgba8 is None else rgba8)
        t_end = time.perf_counter()
        depth = request["depth"]
        self.image, self.depth, self.scene_rgb, self.camera = img, depth, request["rgb"], request["camera"]
        readback = request["t_read"] - request["t_start"]
        self.stats = {"readback_s": readback, "volume_s": st.total_s, "upload_s": t_end - t_show,
                      "total_s": readback + st.total_s + (t_end - t_show), "size": (w, h),
                      "occluded_px": int(np.isfinite(depth).sum())}
        for key in ("sort_s", "project_s", "raster_s", "fragments", "n_visible"):
            self.stats[key] = getattr(st, key, 0)
        return img

    @property
    def visible(self) -> bool:
        return self._overlay.visible

    @visible.setter
    def visible(self, on: bool) -> None:
        self._overlay.visible = on

    def remove(self) -> None:
        """Detach the overlay from the plotter's render window."""
        self._overlay.remove()
