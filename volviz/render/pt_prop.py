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
4. the premultiplied result is un-premultiplied to 8-bit straight RGBA and drawn as a full-window image in an overlay
   renderer (a higher layer) with VTK's (SRC_ALPHA, ONE_MINUS_SRC_ALPHA) blending, which gives the premultiplied
   "over" C = C_vol + (1 - a_vol) C_scene. The 8-bit round trip costs at most about 1/255 per channel (measured in
   the tests).

Later renders of the plotter (screenshots, interaction) keep showing the last volume image over the live scene; call
``update()`` after the camera or the opaque geometry changed. Several PT volumes in one plotter are each clipped by
the opaque depth and blended in the order they were added (their own depths are not interleaved: overlapping
volumes should be merged into one mesh).

Multisampling (PyVista's default, 4 samples) is switched off while a PT volume is in the plotter, and back on when the
last one is removed: with MSAA a silhouette pixel of opaque geometry has a blended colour (object and what is behind
it) but VTK's depth read-back gives one depth, so the volume was cut there by that one depth for the whole pixel: a
one-pixel edge around opaque objects (max 18 of 255 against the compositing of the same opaque image, against 1.6
without MSAA, on the test scene at 256x192). Compositing per sample would need every sample's depth, which VTK's
``GetZbufferData`` does not give; an exact composite is preferred to antialiased silhouettes.
"""
from __future__ import annotations

import time
from typing import Any

import numpy as np

from volviz.model.datasets import TetMesh
from volviz.unstructured.camera import Camera
from volviz.unstructured.render import render


def zbuffer_to_depth(z: np.ndarray, clipping_range: tuple[float, float], parallel: bool) -> np.ndarray:
    """OpenGL window depth z in [0, 1] -> eye-space depth along the direction of projection; z >= 1 -> +inf."""
    n, f = (float(v) for v in clipping_range)
    z = np.asarray(z, dtype=np.float64)
    if parallel:
        d = n + z * (f - n)
    else:
        with np.errstate(divide="ignore"):
            d = n * f / (f - z * (f - n))
    d = np.where((z >= 1.0) | ~np.isfinite(z), np.inf, d)
    return d


def unpremultiply_rgba8(image: np.ndarray) -> np.ndarray:
    """Premultiplied float RGBA (H, W, 4) -> straight-alpha uint8 RGBA (H, W, 4) for (SRC_ALPHA, 1 - SRC_ALPHA)."""
    a = np.clip(image[..., 3:4], 0.0, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(a > 0, image[..., :3] / a, 0.0)
    out = np.empty(image.shape[:2] + (4,), np.uint8)
    out[..., :3] = np.rint(np.clip(c, 0.0, 1.0) * 255.0)
    out[..., 3] = np.rint(a[..., 0] * 255.0)
    return out


def _read_buffers(ren_win: Any, w: int, h: int) -> tuple[np.ndarray, np.ndarray]:
    """(z (H, W) float64, rgb (H, W, 3) uint8), row 0 at the top."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    z = vtk.vtkFloatArray()
    ren_win.GetZbufferData(0, 0, w - 1, h - 1, z)
    rgb = vtk.vtkUnsignedCharArray()
    ren_win.GetRGBACharPixelData(0, 0, w - 1, h - 1, 0, rgb)
    zz = vtk_to_numpy(z).reshape(h, w)[::-1].astype(np.float64)
    cc = vtk_to_numpy(rgb).reshape(h, w, 4)[::-1, :, :3].copy()
    return zz, cc


class PTVolume:
    """A volviz PT volume attached to a PyVista plotter (see the module docstring)."""

    def __init__(self, plotter: Any, mesh: Any, tf: Any, method: str = "pt", **render_opts: Any) -> None:
        import vtk

        scalars = render_opts.pop("scalars", None)
        if not isinstance(mesh, TetMesh):
            from volviz.unstructured.tetrahedralize import tetrahedralize

            mesh = tetrahedralize(mesh, scalars)
        if method not in ("pt", "reference"):
            raise ValueError(f"PT volume method must be 'pt' or 'reference', got {method!r}")
        self.plotter = plotter
        self.mesh = mesh
        self.tf = tf
        self.method = method
        self.render_opts = render_opts
        self.stats: dict[str, Any] = {}
        self.image: np.ndarray | None = None          # last premultiplied volume image (H, W, 4)
        self.depth: np.ndarray | None = None          # last per-pixel depth limit (H, W)
        self.scene_rgb: np.ndarray | None = None      # last opaque scene colour (H, W, 3) uint8
        self.camera: Camera | None = None
        self._prefetcher: Any = None                  # sorts for a known next camera in the background
        ren_win = plotter.ren_win
        if "_volviz_pt_multisamples" not in plotter.__dict__:  # one depth per pixel (see the module docstring)
            plotter.__dict__["_volviz_pt_multisamples"] = int(ren_win.GetMultiSamples())
            ren_win.SetMultiSamples(0)
        self._layer = max(1, ren_win.GetNumberOfLayers())
        ren_win.SetNumberOfLayers(self._layer + 1)
        self._overlay = vtk.vtkRenderer()
        self._overlay.SetLayer(self._layer)
        self._overlay.InteractiveOff()
        self._overlay.SetViewport(plotter.renderer.GetViewport())
        self._data = vtk.vtkImageData()
        self._actor = vtk.vtkImageActor()
        self._actor.GetMapper().SetInputData(self._data)
        self._actor.InterpolateOff()
        self._actor.ForceTranslucentOn()
        self._overlay.AddActor(self._actor)
        self._overlay.GetActiveCamera().ParallelProjectionOn()
        ren_win.AddRenderer(self._overlay)
        self._overlay.DrawOff()
        self._siblings = plotter.__dict__.setdefault("_volviz_pt_overlays", [])
        self._siblings.append(self._overlay)

    def _mesh_far(self, cam: Camera) -> float:
        p = self.mesh.points
        lo, hi = p.min(axis=0), p.max(axis=0)
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        fwd = cam.frame()[2]
        return float(((corners - cam.position) @ fwd).max())

    def update(self) -> np.ndarray:
        """Re-render the volume for the plotter's current camera and opaque scene; returns the premultiplied image."""
        request = self.begin()
        return self.finish(request, *self.compute(request))

    def begin(self) -> dict[str, Any]:
        """GUI-thread part 1: render the opaque scene, read its depth, fix the camera (see the module docstring)."""
        t_start = time.perf_counter()
        ren_win = self.plotter.ren_win
        w, h = (int(v) for v in ren_win.GetSize())
        shown = [o.GetDraw() for o in self._siblings]            # every PT overlay off: opaque depth only
        for o in self._siblings:
            o.DrawOff()
        ren_win.Render()
        z, rgb = _read_buffers(ren_win, w, h)
        for o, on in zip(self._siblings, shown):
            o.SetDraw(on)
        vcam = self.plotter.renderer.GetActiveCamera()
        cam = Camera.from_pyvista(vcam)
        depth = zbuffer_to_depth(z, cam.clipping_range, cam.parallel)
        near, far = cam.clipping_range
        far = max(far, 1.01 * self._mesh_far(cam))                  # VTK's range only covers its own props
        cam = Camera(cam.position, cam.focal_point, cam.view_up, cam.view_angle, cam.parallel, cam.parallel_scale,
                     (near, far))
        return {"camera": cam, "depth": depth, "rgb": rgb, "size": (w, h), "tf": self.tf, "t_start": t_start,
                "t_read": time.perf_counter()}

    def compute(self, request: dict[str, Any], progress: Any = None) -> tuple[np.ndarray, Any, np.ndarray]:
        """Any-thread part: the volume image for a request of ``begin`` (pure NumPy/Numba, no VTK), its statistics,
        and the image as VTK will show it (straight-alpha 8-bit RGBA, bottom row first), made here so that ``finish``
        on the GUI thread only hands it over."""
        if progress is not None:
            progress(0.0, "rendering volume")
        opts = dict(self.render_opts)
        pre = self._prefetcher
        res = None
        if self.method == "pt" and pre is not None and pre.mesh is self.mesh and "order" not in opts:
            res = pre.take(request["camera"], request["size"])
        if res is not None:
            opts["order"] = res.order
        img, st = render(self.mesh, request["tf"], request["camera"], request["size"], self.method,
                         depth=request["depth"], return_stats=True, **opts)
        st.extra["sort_prefetched"] = res is not None
        return img, st, np.ascontiguousarray(unpremultiply_rgba8(img)[::-1])

    def prefetch(self, camera: Camera, size: tuple[int, int] | None = None) -> None:
        """Sort the mesh for ``camera`` (the next frame's; ``size`` defaults to the window's) in the background, so
        that the ``update`` for that camera skips the sort (``volviz.unstructured.prefetch``)."""
        from volviz.unstructured.prefetch import SortPrefetcher

        if self.method != "pt":
            return
        if self._prefetcher is None or self._prefetcher.mesh is not self.mesh:
            if self._prefetcher is not None:
                self._prefetcher.close()
            self._prefetcher = SortPrefetcher(self.mesh, sort=self.render_opts.get("sort", "mpvo"),
                                              nonconvex=self.render_opts.get("nonconvex", "auto"))
        if size is None:
            size = tuple(int(v) for v in self.plotter.ren_win.GetSize())
        self._prefetcher.prefetch(camera, size)

    def error_estimate(self, request: dict[str, Any], size: tuple[int, int] = (96, 72),
                       progress: Any = None) -> dict[str, Any]:
        """Any-thread: the current method's error against the exact float64 reference for this view and TF, measured
        on a small image (``size``, same camera and aspect): RMSE and max abs in 8-bit units. This is what the app's
        statistics show as the error estimate."""
        from volviz.optics.metrics import max_abs, rmse

        w, h = request["size"]
        sw, sh = size
        sh = max(8, int(round(sw * h / max(w, 1))))
        fast = render(self.mesh, request["tf"], request["camera"], (sw, sh), self.method, **self.render_opts)
        if progress is not None:
            progress(0.5, "error estimate: exact reference")
        exact = render(self.mesh, request["tf"], request["camera"], (sw, sh), "reference")
        return {"rmse": float(rmse(fast, exact)), "max": float(max_abs(fast, exact)), "size": (sw, sh)}

    def finish(self, request: dict[str, Any], img: np.ndarray, st: Any, rgba8: np.ndarray | None = None) -> np.ndarray:
        """GUI-thread part 2: show a computed image as the overlay and record the statistics. ``rgba8``: the image
        as ``compute`` converted it (else converted here). The render window redraws unless the plotter's rendering
        is suppressed (the caller then draws once itself)."""
        from vtk.util.numpy_support import numpy_to_vtk

        t_vol = time.perf_counter()
        w, h = request["size"]
        ren_win = self.plotter.ren_win
        if rgba8 is None:
            rgba8 = unpremultiply_rgba8(img)[::-1]                    # VTK images start at the bottom row
        self._data.SetDimensions(w, h, 1)
        arr = numpy_to_vtk(np.ascontiguousarray(rgba8.reshape(-1, 4)), deep=True)
        arr.SetName("rgba")
        self._data.GetPointData().SetScalars(arr)
        self._data.Modified()
        oc = self._overlay.GetActiveCamera()
        oc.SetFocalPoint((w - 1) / 2.0, (h - 1) / 2.0, 0.0)
        oc.SetPosition((w - 1) / 2.0, (h - 1) / 2.0, 1.0)
        oc.SetViewUp(0.0, 1.0, 0.0)
        oc.SetParallelScale(h / 2.0)
        oc.SetClippingRange(0.5, 1.5)
        self._overlay.DrawOn()
        if not getattr(self.plotter, "suppress_rendering", False):
            ren_win.Render()
        t_end = time.perf_counter()
        depth = request["depth"]
        self.image, self.depth, self.scene_rgb, self.camera = img, depth, request["rgb"], request["camera"]
        self.stats = {"readback_s": request["t_read"] - request["t_start"], "sort_s": st.sort_s,
                      "project_s": st.project_s, "raster_s": st.raster_s, "volume_s": st.total_s,
                      "upload_s": t_end - t_vol, "total_s": request["t_read"] - request["t_start"] + st.total_s
                      + (t_end - t_vol), "fragments": st.fragments, "n_visible": st.n_visible,
                      "occluded_px": int(np.isfinite(depth).sum()), "size": (w, h), "method": self.method,
                      "sort_prefetched": bool(st.extra.get("sort_prefetched", False))}
        return img

    @property
    def visible(self) -> bool:
        return bool(self._overlay.GetDraw())

    @visible.setter
    def visible(self, on: bool) -> None:
        if bool(on) == self.visible:
            return
        self._overlay.SetDraw(bool(on))
        if not getattr(self.plotter, "suppress_rendering", False):
            self.plotter.ren_win.Render()      # PyVista's screenshot() does not notice a foreign renderer's change

    def remove(self) -> None:
        """Detach the overlay from the plotter's render window."""
        if self._prefetcher is not None:
            self._prefetcher.close()
            self._prefetcher = None
        self.plotter.ren_win.RemoveRenderer(self._overlay)
        if self._overlay in self._siblings:
            self._siblings.remove(self._overlay)
        if not self._siblings and "_volviz_pt_multisamples" in self.plotter.__dict__:  # the last one: MSAA back
            self.plotter.ren_win.SetMultiSamples(self.plotter.__dict__.pop("_volviz_pt_multisamples"))


def add_pt_volume(plotter: Any, mesh: Any, tf: Any, **opts: Any) -> PTVolume:
    """Add a volviz PT volume to ``plotter`` (composited through the depth buffer) and render it once.

    ``opts``: ``method`` ("pt" or "reference"), ``scalars`` (point-data name when ``mesh`` is not a TetMesh) and any
    keyword of ``volviz.unstructured.render`` (sort, n_s, n_l, t_min, ...). Call ``handle.update()`` after camera
    moves; ``handle.stats`` holds the timings of the last update."""
    handle = PTVolume(plotter, mesh, tf, **opts)
    handle.update()
    return handle
