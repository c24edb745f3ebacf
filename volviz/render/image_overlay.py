"""volviz's own images (premultiplied float RGBA from a CPU renderer) drawn over a PyVista plotter's scene and
composited with its opaque geometry through the depth buffer (Guthe §4.5: a volume behind an opaque surface is
hidden, in front of it it blends). Shared by the projected-tetrahedra volumes (``pt_prop``), the isosurface
overlay (``iso_overlay``) and the LOD block ray caster (``lod_volume``).

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
last one is removed: with MSAA a silhouette pixel of opaque geometry has a blended colour (object and what is behind
it) but VTK's depth read-back gives one depth, so the image was cut there by that one depth for the whole pixel: a
one-pixel edge around opaque objects (max 18 of 255 against 1.6 without MSAA on the PT test scene at 256x192).
Compositing per sample would need every sample's depth, which ``GetZbufferData`` does not give.
"""
from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["ImageOverlay", "read_buffers", "unpremultiply_rgba8", "zbuffer_to_depth"]

_SIBLINGS = "_volviz_pt_overlays"           # plotter attribute: every overlay renderer of the plotter
_MULTISAMPLES = "_volviz_pt_multisamples"   # plotter attribute: the MSAA setting to restore


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


def unpremultiply_rgba8(image: np.ndarray) -> np.ndarray:
    """Premultiplied float RGBA (H, W, 4) -> straight-alpha uint8 RGBA (H, W, 4) for (SRC_ALPHA, 1 - SRC_ALPHA)."""
    a = np.clip(image[..., 3:4], 0.0, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(a > 0, image[..., :3] / a, 0.0)
    out = np.empty(image.shape[:2] + (4,), np.uint8)
    out[..., :3] = np.rint(np.clip(c, 0.0, 1.0) * 255.0)
    out[..., 3] = np.rint(a[..., 0] * 255.0)
    return out


def read_buffers(ren_win: Any, w: int, h: int) -> tuple[np.ndarray, np.ndarray]:
    """(z (H, W) float64, rgb (H, W, 3) uint8) of the render window, row 0 at the top."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    z = vtk.vtkFloatArray()
    ren_win.GetZbufferData(0, 0, w - 1, h - 1, z)
    rgb = vtk.vtkUnsignedCharArray()
    ren_win.GetRGBACharPixelData(0, 0, w - 1, h - 1, 0, rgb)
    zz = vtk_to_numpy(z).reshape(h, w)[::-1].astype(np.float64)
    cc = vtk_to_numpy(rgb).reshape(h, w, 4)[::-1, :, :3].copy()
    return zz, cc


class ImageOverlay:
    """One full-window image over a plotter's scene (see the module docstring). Starts hidden."""

    def __init__(self, plotter: Any) -> None:
        import vtk

        self.plotter = plotter
        ren_win = plotter.ren_win
        if _MULTISAMPLES not in plotter.__dict__:          # one depth per pixel (see the module docstring)
            plotter.__dict__[_MULTISAMPLES] = int(ren_win.GetMultiSamples())
            ren_win.SetMultiSamples(0)
        layer = max(1, ren_win.GetNumberOfLayers())
        ren_win.SetNumberOfLayers(layer + 1)
        self.renderer = vtk.vtkRenderer()
        self.renderer.SetLayer(layer)
        self.renderer.InteractiveOff()
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
        self.siblings: list[Any] = plotter.__dict__.setdefault(_SIBLINGS, [])
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
        or the plotter's rendering is suppressed."""
        from vtk.util.numpy_support import numpy_to_vtk

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
        if not self.siblings and _MULTISAMPLES in self.plotter.__dict__:
            self.plotter.ren_win.SetMultiSamples(self.plotter.__dict__.pop(_MULTISAMPLES))
