"""Put volviz's own projected-tetrahedra volumes into any PyVista plotter, composited with the opaque geometry
through the depth buffer (Roettger §8.4 / Guthe §4.6 for the volume; the depth test as in Guthe §4.5: a volume
behind an opaque surface is hidden, in front of it it blends).

    handle = add_pt_volume(plotter, mesh, tf)          # TetMesh or anything volviz.unstructured.tetrahedralize takes
    ...move the camera...
    handle.update()                                    # re-render the volume for the current camera and geometry
    handle.stats                                       # seconds (readback / sort / project / raster / upload) + counts

How a frame is made (``update``):

1. the plotter's own scene is rendered with the volume overlay switched off;
2. VTK's z-buffer (``GetZbufferData``) is read and converted to eye-space depth along the direction of projection:
   ``d = n f / (f - z (f - n))`` for perspective and ``d = n + z (f - n)`` for parallel projection, with (n, f) the
   camera's clipping range; pixels with ``z = 1`` (no geometry) are unlimited. 24-bit depth at the typical clipping
   ratio f/n = 1000 resolves about 1e-4 of the view distance;
3. the volume is rendered by ``volviz.unstructured.render(..., depth=d)``: every ray segment is clipped at the opaque
   depth of its pixel, so the volume stops exactly at the surface (not at the cell containing it);
   with the method "vtk" VTK's projected tetrahedra draw it instead, over that depth, in a window of a thread of its
   own (``volviz.render.vtk_pt_image``), and with "pt-gl" volviz's GPU PT pass does there;
4. the premultiplied result is drawn over the scene by ``volviz.render.image_overlay.ImageOverlay`` (straight-alpha
   RGBA8 in an overlay renderer on a higher layer: the premultiplied "over" C = C_vol + (1 - a_vol) C_scene; the
   8-bit round trip costs at most about 1/255 per channel, measured in the tests).

Later renders of the plotter (screenshots, interaction) keep showing the last volume image over the live scene; call
``update()`` after the camera or the opaque geometry changed. Several PT volumes in one plotter are each clipped by
the opaque depth and blended in the order they were added (their own depths are not interleaved: overlapping
volumes should be merged into one mesh). Multisampling is off while a volume is in the plotter (see
``image_overlay``: with MSAA, silhouettes of opaque objects left a one-pixel edge).
"""
from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any, Optional, TypedDict

import numpy as np

from volviz.model.camera import Camera
from volviz.model.datasets import TetMesh
from volviz.model.extent import point_extent
from volviz.optics.metrics import max_abs, rmse
from volviz.render.image_overlay import (Buffers, OverlayRequest, OverlayView, overlay_rgba8, unpremultiply_rgba8,
                                         window_size, zbuffer_to_depth)
from volviz.render.gl_thread import GLThreadClosed
from volviz.render.preview_hold import PreviewCameraHold, holds_previews
from volviz.render.pt_view import PTView
from volviz.render.vtk_pt_image import THREAD_METHODS, ThreadPTImages
from volviz.unstructured.prefetch import SortPrefetcher
from volviz.unstructured.render import UnstructuredRenderStats, render
from volviz.unstructured.tetrahedralize import tetrahedralize

if TYPE_CHECKING:   # type-only imports for the signatures
    import pyvista as pv
    from typing_extensions import Unpack

    from volviz.jobs import ProgressCallback
    from volviz.model.clip import ClipSettings
    from volviz.optics.transfer_function import TransferFunction

__all__ = ["METHODS", "ErrorEstimate", "PTVolume", "add_pt_volume", "unpremultiply_rgba8", "zbuffer_to_depth"]


#: what draws a PT volume's image: volviz's pre-integrated PT, the exact float64 reference, VTK's projected
#: tetrahedra or volviz's GPU PT pass (both ``volviz.render.vtk_pt_image``, drawn in a window of a thread of its own)
METHODS = ("pt", "reference", "vtk", "pt-gl")
#: the keywords of a "pt-gl" image's GPU pass (``volviz.render.gl_pt.GLPTVolume``) among the render options
_GL_OPTIONS = ("sort", "nonconvex", "lookup", "n_s", "n_l", "degree", "iso", "iso_shading", "classification")


class ErrorEstimate(TypedDict):
    """``PTVolume.error_estimate``: RMSE and max abs in 8-bit units against the exact reference, and the image size
    (w, h) they were measured at."""

    rmse: float
    max: float
    size: tuple[int, int]


class PTVolume(OverlayView[UnstructuredRenderStats], PTView):
    """A volviz PT volume attached to a PyVista plotter (see the module docstring). The CPU side of the PT view
    interface ``volviz.render.pt_view.PTView``; ``mesh`` is what is drawn (a cut of ``whole_mesh`` under clipping)."""

    backend = "cpu"
    job = ("pt", "volume")   # the app's key for its updates, and what its worker makes (an image)

    def __init__(self, plotter: Any, mesh: Any, tf: Any, method: str = "pt", **render_opts: Any) -> None:
        scalars = render_opts.pop("scalars", None)
        if not isinstance(mesh, TetMesh):
            mesh = tetrahedralize(mesh, scalars)
        if method not in METHODS:
            raise ValueError(f"PT volume method must be one of {', '.join(METHODS)}, got {method!r}")
        super().__init__(plotter)
        self.mesh = mesh
        self.whole_mesh = mesh                        # uncut: what clipping cuts and ``bounds`` measures
        self.tf = tf
        self.method = method
        self.render_opts = render_opts
        self._prefetcher: Any = None                  # sorts for a known next camera in the background
        self._thread_images: ThreadPTImages | None = None   # methods "vtk", "pt-gl": a window in a thread of its own
        self._removed = False
        self._thread_lock = threading.Lock()         # the image and the error estimate's workers make one window
        # the app's frames drawn with the shown image's camera while the camera moves (``preview_hold``)
        self.hold = PreviewCameraHold(plotter) if holds_previews(plotter) else None

    @property
    def drawn_by(self) -> str:
        return "gpu" if self.method == "pt-gl" else "cpu"

    def _far(self, cam: Camera) -> float:
        p = self.mesh.points
        lo, hi = point_extent(p)
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        fwd = cam.frame()[2]
        return float(((corners - cam.position) @ fwd).max())

    def begin(self, scale: int = 1, drawn: Optional[Buffers] = None) -> OverlayRequest:
        """GUI-thread part 1: render the opaque scene, read its depth, fix the camera (see the module docstring);
        ``scale`` > 1: a preview image that much smaller, ``drawn``: the opaque scene read back already
        (``OverlayView.begin``). The opaque scene is rendered with the live camera (``hold`` suspended)."""
        if self.hold is None:
            request = super().begin(scale, drawn)
        else:
            self.hold.suspended = True
            try:
                request = super().begin(scale, drawn)
            finally:
                self.hold.suspended = False
            request["held_camera"] = self.hold.snapshot()
        request["tf"], request["mesh"] = self.tf, self.mesh   # what the image is of, whatever is set meanwhile
        return request

    def compute(self, request: OverlayRequest, progress: Optional[ProgressCallback] = None
                ) -> tuple[np.ndarray, UnstructuredRenderStats, np.ndarray]:
        """Any-thread part: the volume image for a request of ``begin`` (pure NumPy/Numba, no VTK), its statistics,
        and the image as VTK will show it (``overlay_rgba8``: straight-alpha 8-bit RGBA, a preview magnified
        to the window), made here so that ``finish`` on the GUI thread only hands it over."""
        if progress is not None:
            progress(0.0, "rendering volume")
        mesh = request["mesh"]
        if self.method in THREAD_METHODS:
            img, st = self._thread_image(request, request["size"], request["depth"])
            return img, st, overlay_rgba8(img, request)
        opts = dict(self.render_opts)
        pre = self._prefetcher
        res = None
        if self.method == "pt" and pre is not None and pre.mesh is mesh and "order" not in opts:
            res = pre.take(request["camera"], request["size"])
        if res is not None:
            opts["order"] = res.order
        img, st = render(mesh, request["tf"], request["camera"], request["size"], self.method,
                         depth=request["depth"], return_stats=True, **opts)
        st.extra["sort_prefetched"] = res is not None
        return img, st, overlay_rgba8(img, request)

    def _thread_image(self, request: OverlayRequest, size: tuple[int, int], depth: Optional[np.ndarray] = None
                      ) -> tuple[np.ndarray, UnstructuredRenderStats]:
        """Methods "vtk" and "pt-gl": the request's image at ``size`` drawn by VTK's projected tetrahedra or volviz's
        GPU PT pass in a window of a thread of their own (made at the first image); a transparent one once the view
        is removed (``remove`` closes that thread: an image of a request begun before is not shown)."""
        with self._thread_lock:
            images = self._thread_images
            if images is None and not self._removed:
                options = {k: v for k, v in self.render_opts.items() if k in _GL_OPTIONS}
                images = self._thread_images = ThreadPTImages(self.method, options)
        if images is not None:
            try:
                return images.render(request["mesh"], request["tf"], request["camera"], size, depth)
            except GLThreadClosed:
                pass
        return np.zeros((size[1], size[0], 4)), UnstructuredRenderStats(method=self.method, size=size)

    def prefetch(self, camera: Camera, size: tuple[int, int] | None = None) -> None:
        """Sort the mesh for ``camera`` (the next frame's; ``size`` defaults to the window's) in the background, so
        that the ``update`` for that camera skips the sort (``volviz.unstructured.prefetch``)."""
        if self.method != "pt":
            return
        if self._prefetcher is None or self._prefetcher.mesh is not self.mesh:
            if self._prefetcher is not None:
                self._prefetcher.close()
            self._prefetcher = SortPrefetcher(self.mesh, sort=self.render_opts.get("sort", "mpvo"),
                                              nonconvex=self.render_opts.get("nonconvex", "auto"))
        if size is None:
            size = window_size(self.plotter.ren_win)
        self._prefetcher.prefetch(camera, size)

    def error_estimate(self, request: OverlayRequest, size: tuple[int, int] = (96, 72),
                       progress: Optional[ProgressCallback] = None) -> ErrorEstimate:
        """Any-thread: the current method's error against the exact float64 reference for this view and TF, measured
        on a small image (``size``, same camera and aspect): RMSE and max abs in 8-bit units. This is what the app's
        statistics show as the error estimate."""
        w, h = request["size"]
        sw, sh = size
        sh = max(8, int(round(sw * h / max(w, 1))))
        mesh = request["mesh"]   # both of the same mesh, though a cut may be shown meanwhile
        if self.method in THREAD_METHODS:
            fast = self._thread_image(request, (sw, sh))[0]
        else:
            fast = render(mesh, request["tf"], request["camera"], (sw, sh), self.method, **self.render_opts)
        if progress is not None:
            progress(0.5, "error estimate: exact reference")
        exact = render(mesh, request["tf"], request["camera"], (sw, sh), "reference")
        return {"rmse": float(rmse(fast, exact)), "max": float(max_abs(fast, exact)), "size": (sw, sh)}

    def finish(self, request: OverlayRequest, img: np.ndarray, st: UnstructuredRenderStats,
               rgba8: np.ndarray | None = None) -> np.ndarray:
        """GUI-thread part 2: show a computed image as the overlay and record the statistics (``OverlayView``)."""
        super().finish(request, img, st, rgba8)
        if self.hold is not None and "held_camera" in request:
            self.hold.shown(request["held_camera"], bool(request.get("preview", False)))
        self.stats.update(method=self.method, sort_prefetched=bool(st.extra.get("sort_prefetched", False)))
        return img

    def _use_tf(self, tf: Any) -> None:
        """A new transfer function for the next image (``update``, or ``begin`` / ``compute`` / ``finish``)."""
        self.tf = tf

    def set_clip(self, clip: ClipSettings) -> bool:
        """Clipping is not done here: the caller shows an exact cut of ``whole_mesh`` as ``mesh``
        (``cut``, ``show_cut``); returns False
        (``PTView.set_clip``)."""
        return False

    def remove(self) -> None:
        """Detach the overlay from the plotter's render window."""
        if self._prefetcher is not None:
            self._prefetcher.close()
            self._prefetcher = None
        with self._thread_lock:
            self._removed = True
            images, self._thread_images = self._thread_images, None
        if images is not None:
            images.close()
        if self.hold is not None:
            self.hold.remove()
        super().remove()

class PTOptions(TypedDict, total=False):
    """``add_pt_volume``'s keywords: ``PTVolume``'s method and scalars, and those of ``volviz.unstructured.render``
    (its table and iso are its own to check)."""

    method: str
    scalars: Optional[str]
    sort: str
    nonconvex: str
    order: Optional[np.ndarray]
    lookup: str
    n_s: Optional[int]
    n_l: int
    degree: Optional[int]
    table: object
    t_min: float
    depth: Optional[np.ndarray]
    iso: object
    iso_mode: str
    iso_shading: str
    classification: str


def add_pt_volume(plotter: pv.BasePlotter, mesh: object, tf: TransferFunction, **opts: Unpack[PTOptions]
                  ) -> PTVolume:
    """Add a volviz PT volume to ``plotter`` (composited through the depth buffer) and render it once.

    ``opts``: ``method`` ("pt" or "reference"), ``scalars`` (point-data name when ``mesh`` is not a TetMesh) and any
    keyword of ``volviz.unstructured.render`` (sort, n_s, n_l, t_min, ...). Call ``handle.update()`` after camera
    moves; ``handle.stats`` holds the timings of the last update."""
    handle = PTVolume(plotter, mesh, tf, **opts)
    handle.update()
    return handle
