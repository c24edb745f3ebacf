"""The CPU transparency modes of many semi-transparent isosurfaces (libMini note §4: 2-pass, 3-pass, 4-pass and the
exact per-pixel sorted reference, ``volviz.iso.composite``) shown in a PyVista plotter, composited with the opaque
scene through the depth buffer exactly as volviz's PT volumes are (``volviz.render.pt_prop``):

1. the plotter's scene is rendered with every volviz overlay off (the translucent isosurface actors are hidden by
   the caller while a CPU mode is on; opaque isosurfaces stay VTK actors), and VTK's z-buffer is read back as
   eye-space depth;
2. the translucent surfaces of all isosurface components are rasterised ONCE into per-pixel fragment lists;
   fragments at or behind the opaque depth of their pixel are dropped (the opaque scene, opaque isosurfaces
   included, is the mode's "opaque background" pass);
3. the mode composites the remaining fragments over a transparent background; the premultiplied image is drawn as
   a full-window overlay with (SRC_ALPHA, ONE_MINUS_SRC_ALPHA), i.e. C = C_iso + (1 − α_iso)·C_scene. For 3/4-pass
   α_iso = 1 − Π(1 − α_i), so this equals the mode's Π(1 − α_i)·B + Σ e_i with B the scene color; where the sum
   of emissions exceeds α_iso (straight alpha cannot carry that) the pixel is composited on the CPU over the
   read-back scene color and drawn opaque (see ``finish``);
4. with a regular (VTK) volume shown, ``compute`` renders it once more from the eye to the nearest translucent
   surface, in an offscreen window of a thread of its own (``begin`` only copies the camera, lights and volume
   properties), and the image becomes (1 − a_f)·I + α·V_f (``volviz.render.iso_volume_split``): the volume in front
   of the surfaces lies over them, the rest under them (issue #28), exact where a ray meets one translucent layer.

The 8-bit overlay costs at most about 1/255 per channel against the float image (measured in the tests).
``begin`` / ``compute`` / ``finish`` split the work as every ``image_overlay.OverlayView`` does: ``compute`` is pure
NumPy/Numba and runs in a background worker (a preview magnified to the window there too, ``_shown_rgba8``); the app
recomputes after every camera change. Surfaces of components with
LOD on are drawn at the level their screen size asks for, geomorphed (``volviz.iso.lod``); the statistics report the
triangles drawn.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal, Optional, Sequence

import numpy as np

from volviz.iso.composite import MODES, Fragments, composite, fragments, triangles_drawn
from volviz.iso.extract import IsoMesh
from volviz.iso.lod import lod_mesh, select_level
from volviz.render.image_overlay import Buffers, OverlayRequest, OverlayView, overlay_rgba8
from volviz.render.iso_volume_split import FrontVolume, in_volume
from volviz.model.camera import Camera

if TYPE_CHECKING:   # type-only imports for the signatures
    from volviz.iso.lod import LodChain
    from volviz.jobs import ProgressCallback

__all__ = ["IsoModeView", "IsoOverlay", "IsoStats", "cut_at_depth"]


def cut_at_depth(frags: Fragments, depth: np.ndarray) -> Fragments:
    """The fragments strictly in front of the opaque depth of their pixel (``depth`` (H, W), +inf = nothing)."""
    counts = np.diff(frags.ptr)
    pix = np.repeat(np.arange(len(counts)), counts)
    keep = frags.depth < np.asarray(depth, dtype=np.float64).reshape(-1)[pix]
    ptr = np.zeros_like(frags.ptr)
    np.cumsum(np.bincount(pix[keep], minlength=len(counts)), out=ptr[1:])
    return Fragments(frags.size, ptr, frags.depth[keep], frags.rgba[keep], frags.opaque[keep], frags.back[keep],
                     frags.n_triangles, frags.n_opaque_triangles, frags.seconds)


@dataclass
class IsoStats:
    """``IsoOverlay.compute``'s statistics (``image_overlay.OverlayStats``): seconds (``raster_s`` the fragment
    lists, ``total_s`` with the compositing), fragments, triangles rasterised (``n_visible``), drawn by the mode and in
    the full-resolution meshes, and saturated pixels (composited over the scene colour)."""

    raster_s: float
    total_s: float
    fragments: int
    n_visible: int
    triangles_drawn: int
    full_triangles: int
    saturated_px: int
    sort_s: float = 0.0
    project_s: float = 0.0
    extra: dict[str, Any] = field(default_factory=dict)


def _shown_rgba8(img: np.ndarray, request: OverlayRequest) -> tuple[np.ndarray, int]:
    """Any thread: the overlay image ``img`` (premultiplied) as VTK shows it (``overlay_rgba8``; a preview magnified
    to the window) and the number of saturated pixels. Straight-alpha blending cannot show a color above its alpha,
    which the order-independent sums of 3/4-pass produce; those pixels are composited over the scene color read back
    in ``begin`` and drawn opaque (exact for the opaque scene; a PT volume's overlay under such a pixel is not seen
    through)."""
    over = np.any(img[..., :3] > img[..., 3:4] + 0.5 / 255.0, axis=-1)
    shown = img
    if over.any():
        shown = img.copy()
        scene = request["rgb"][over].astype(np.float64) / 255.0
        shown[over, :3] = np.minimum(img[over, :3] + (1.0 - img[over, 3:4]) * scene, 1.0)
        shown[over, 3] = 1.0
    return overlay_rgba8(shown, request), int(over.sum())


class IsoModeView:
    """The ``mode`` of an isosurface view (one of ``volviz.iso.composite.MODES``, checked when set); a subclass
    applies a new mode in ``_mode_changed``."""

    _mode = "3pass"

    @property
    def mode(self) -> str:
        return self._mode

    @mode.setter
    def mode(self, mode: str) -> None:
        if mode not in MODES:
            raise ValueError(f"unknown transparency mode {mode!r}; choose from {MODES}")
        self._mode = mode
        self._mode_changed(mode)

    def _mode_changed(self, mode: str) -> None:
        """Called after every change of ``mode``."""


class IsoOverlay(OverlayView[IsoStats], IsoModeView):
    """The isosurfaces of a scene drawn by one of the CPU transparency modes as a depth-composited overlay. With a
    regular volume shown, ``split_volume`` (default) puts the volume in front of the surfaces over them and the rest
    under them (``volviz.render.iso_volume_split``; ``front_volume`` draws that volume on a thread of its own); False
    draws the overlay over the whole scene (the order before issue #28, kept for ``volviz bench iso_modes_volume``)."""

    split_volume = True

    kind: Literal["iso"] = "iso"
    backend = "cpu"
    job = ("iso-overlay", "isosurfaces")  # the app's key for its updates, and what its worker makes

    def __init__(self, plotter: Any, meshes: Sequence[IsoMesh] = (), mode: str = "3pass",
                 shading: str = "spectrum") -> None:
        super().__init__(plotter)
        self.front_volume = FrontVolume()
        self.meshes = list(meshes)
        self.lod: list[Any] = [None] * len(self.meshes)  # per mesh: (LodChain, triangles per pixel²) or None
        self.mode = mode
        self.shading = shading

    def set_surfaces(self, meshes: Sequence[IsoMesh], lod: Sequence[Optional[tuple[LodChain, float]]],
                     shading: str) -> None:
        """Draw ``meshes`` with their LOD chains (``lod``: per mesh (LodChain, triangles per pixel²) or None) and
        ``shading`` from the next image on."""
        self.meshes, self.lod, self.shading = list(meshes), list(lod), shading

    def _far(self, cam: Camera) -> float:
        pts = [m.points for m in self.meshes if len(m.points)]
        if not pts:
            return float(cam.clipping_range[1])
        p = np.concatenate(pts)
        return float(((p - cam.position) @ cam.frame()[2]).max())

    def begin(self, scale: int = 1, drawn: Optional[Buffers] = None) -> OverlayRequest:
        """GUI thread: ``OverlayView.begin`` (the scene drawn and read back, or ``drawn``), and with a regular volume
        shown what ``compute`` needs to draw the volume in front of the translucent surfaces off this thread
        (``FrontVolume.snapshot``)."""
        translucent = [m for m in self.meshes if m.style.opacity < 1.0] if self.split_volume else []
        front = self.front_volume.snapshot(self.plotter, translucent) if translucent else None
        request = super().begin(scale, drawn)
        cam = request["camera"]
        near = min(cam.clipping_range[0], 1e-3 * cam.clipping_range[1])  # VTK's range ignores the hidden actors
        request["camera"] = Camera(cam.position, cam.focal_point, cam.view_up, cam.view_angle, cam.parallel,
                                   cam.parallel_scale, (near, cam.clipping_range[1]))
        request.update(meshes=list(self.meshes), lod=list(self.lod), mode=self.mode, shading=self.shading,
                       front_scene=front)
        return request

    def _front_image(self, request: OverlayRequest) -> np.ndarray | None:
        """Any thread: the volume in front of the surfaces for ``request`` (``FrontVolume.render``, at the window's
        size; for a preview each preview pixel's first window pixel, as its scene color), or None."""
        scene = request.get("front_scene")
        if scene is None:
            return None
        front = self.front_volume.render(scene)
        if front is not None and request["preview"]:
            (w, h), (big_h, big_w) = request["size"], front.shape[:2]
            front = front[(np.arange(h) * big_h) // h][:, (np.arange(w) * big_w) // w]
        return front

    def compute(self, request: OverlayRequest, progress: Optional[ProgressCallback] = None
                ) -> tuple[np.ndarray, IsoStats, np.ndarray]:
        """Any thread: rasterise all surfaces once, cut at the opaque depth, composite in the request's mode (the
        volume in front of the surfaces over it, ``in_volume``); then the
        image as VTK will show it (``_shown_rgba8``: saturated pixels over the scene color, straight-alpha RGBA8, a
        preview magnified to the window), made here so that ``finish`` on the GUI thread only hands it over (the
        magnification stalled the GUI thread per preview, issue #28; docs/bench/docstring-figures.md)."""
        if progress is not None:
            progress(0.0, f"isosurfaces: {request['mode']}")
        t0 = time.perf_counter()
        cam, size = request["camera"], request["size"]
        lod = request.get("lod") or [None] * len(request["meshes"])
        meshes = [m if lv is None else lod_mesh(lv[0], select_level(lv[0], cam, size, lv[1]))
                  for m, lv in zip(request["meshes"], lod)]
        fr = cut_at_depth(fragments(meshes, cam, size, request["shading"]), request["depth"])
        t1 = time.perf_counter()
        img = in_volume(composite(fr, request["mode"]), self._front_image(request))
        t2 = time.perf_counter()
        rgba8, saturated = _shown_rgba8(img, request)
        st = IsoStats(sort_s=0.0, project_s=0.0, raster_s=t1 - t0, total_s=t2 - t0, fragments=len(fr.depth),
                      n_visible=fr.n_triangles, triangles_drawn=triangles_drawn(fr, request["mode"]),
                      full_triangles=sum(m.n_triangles for m in request["meshes"]), saturated_px=saturated,
                      extra={})
        return img, st, rgba8

    def remove(self) -> None:
        """Detach the overlay and end the thread that draws the volume in front of the surfaces."""
        super().remove()
        self.front_volume.close()

    def finish(self, request: OverlayRequest, img: np.ndarray, st: IsoStats, rgba8: np.ndarray | None = None
               ) -> np.ndarray:
        """GUI thread: show ``rgba8`` as ``compute`` made it (made here from ``img`` when not given) and record the
        statistics; returns the premultiplied image."""
        saturated = getattr(st, "saturated_px", 0)
        if rgba8 is None:
            rgba8, saturated = _shown_rgba8(img, request)
        super().finish(request, img, st, rgba8)
        self.stats.update(method=f"iso {request['mode']}", composite_s=st.total_s - st.raster_s,
                          triangles=st.n_visible, triangles_drawn=st.triangles_drawn, saturated_px=saturated,
                          full_triangles=st.full_triangles)
        return img
