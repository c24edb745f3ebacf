"""VTK's projected tetrahedra (vtkProjectedTetrahedraMapper, the render method "vtk") drawn as an image in an
offscreen window of a thread of its own, to be shown over the scene as volviz's CPU PT image is
(``volviz.render.pt_prop``; issue #28: in the scene's window the mapper's per-frame work, the cells' depth sort and
projection on the CPU, held the GUI thread at every frame).

The image is the one the scene's window would draw: VTK's mapper blends the cells front to back into a transparent
black background, which leaves the premultiplied colour and alpha of the volume (the "over" of
``volviz.render.image_overlay``). Its cells are depth-tested against the opaque scene as in the scene's window: the
opaque scene's depth (read back by the overlay's ``begin``) is written into the window's depth buffer before the
volume is drawn (``SetZbufferData`` when the renderer starts, the renderer keeping its depth buffer), in the window
depth of the image's camera (``window_z``: its far plane is moved to the volume's far side). Guthe §4.5: the volume
behind an opaque surface is hidden.
"""
from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any, Optional

import numpy as np

from volviz.model.camera import Camera
from volviz.render.gl_thread import GLThread
from volviz.render.image_overlay import read_premultiplied
from volviz.unstructured.render import UnstructuredRenderStats

if TYPE_CHECKING:   # type-only imports for the signatures
    from volviz.model.datasets import TetMesh
    from volviz.optics.transfer_function import TransferFunction
    from volviz.render.vtk_facade import vtkRenderer

__all__ = ["VTKProjectedTetrahedra", "window_z"]


def window_z(depth: np.ndarray, clipping_range: tuple[float, float], parallel: bool) -> np.ndarray:
    """Eye-space depth along the direction of projection (+inf: nothing) -> OpenGL window depth in [0, 1] for the
    clipping range (n, f): ``z = f (d - n) / (d (f - n))`` for perspective and ``z = (d - n) / (f - n)`` for
    parallel projection (the inverse of ``image_overlay.zbuffer_to_depth``); +inf and beyond f -> 1."""
    n, f = (float(v) for v in clipping_range)
    d = np.asarray(depth, dtype=np.float64)
    finite = np.isfinite(d)
    d_safe = np.where(finite, np.maximum(d, n), f)
    z = (d_safe - n) / (f - n) if parallel else f * (d_safe - n) / (d_safe * (f - n))
    return np.where(finite, np.clip(z, 0.0, 1.0), 1.0)


class VTKProjectedTetrahedra:
    """Images of a TetMesh drawn by VTK's projected tetrahedra in a window of a thread of its own
    (``volviz.render.gl_thread``): ``render`` from any thread; ``close`` ends the thread."""

    def __init__(self) -> None:
        self.gl = GLThread("volviz-vtk-pt")

    def render(self, mesh: TetMesh, tf: TransferFunction, camera: Camera, size: tuple[int, int],
               depth: Optional[np.ndarray] = None) -> tuple[np.ndarray, UnstructuredRenderStats]:
        """Any thread: ``mesh`` with ``tf`` seen by ``camera`` at ``size`` (w, h) as premultiplied float RGBA
        (H, W, 4), row 0 at the top, in 8-bit steps, and its statistics; ``depth`` (H, W): the opaque scene's
        eye-space depth (+inf: nothing), which hides the cells behind it."""
        t0 = time.perf_counter()
        z = None if depth is None else window_z(depth, camera.clipping_range, camera.parallel)
        image = self.gl.call(_draw, self.gl.state, mesh, tf, camera, size, z)
        stats = UnstructuredRenderStats(method="vtk", size=size, n_tets=mesh.n_cells,
                                        total_s=time.perf_counter() - t0)
        return image, stats

    def close(self) -> None:
        """End the thread, its window closed there after the image in progress, without waiting for it (the caller is
        the GUI thread, removing the view)."""
        self.gl.close(wait=False)


def _volume(state: dict[str, Any], mesh: TetMesh, tf: TransferFunction) -> Any:
    """The window's vtkVolume drawing ``mesh`` with ``tf`` (its input and property made again when either is new)."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk
    from volviz.render.vtk_scene import volume_input, vtk_volume_property

    volume = state.get("volume")
    if volume is None:
        volume = state["volume"] = vtk.vtkVolume()
        volume.SetMapper(vtk.vtkProjectedTetrahedraMapper())
    if state.get("mesh") is not mesh:
        volume.GetMapper().SetInputData(volume_input(mesh))
        state["mesh"] = mesh
    if state.get("tf") is not tf:
        volume.SetProperty(vtk_volume_property(tf))
        state["tf"] = tf
    return volume


def _draw(ren: vtkRenderer, state: dict[str, Any], mesh: TetMesh, tf: TransferFunction, camera: Camera,
          size: tuple[int, int], z: Optional[np.ndarray]) -> np.ndarray:
    """On the window's thread: draw ``mesh`` over the depth ``z`` (window depth, row 0 at the top; None: none) and
    read the image back."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import numpy_to_vtk, vtk

    volume = _volume(state, mesh, tf)
    if not ren.HasViewProp(volume):
        ren.AddVolume(volume)
        ren.SetBackground(0.0, 0.0, 0.0)
        ren.SetBackgroundAlpha(0.0)
        ren.AddObserver(vtk.vtkCommand.StartEvent, lambda *_: _write_depth(ren, state))
    camera.apply_to(ren.GetActiveCamera())
    window = ren.GetRenderWindow()
    w, h = (int(v) for v in size)
    if not state.get("drawn"):
        # VTK's mapper leaves cells out of the first frame a window draws with it (``offscreen``'s
        # ``draw_projected_tetrahedra_once``): a first frame at 8 x 8 costs its sort and no raster
        window.SetSize(8, 8)
        ren.PreserveDepthBufferOff()
        window.Render()
        state["drawn"] = True
    if tuple(window.GetSize()) != (w, h):
        window.SetSize(w, h)
    state["depth"] = None if z is None else (
        numpy_to_vtk(np.ascontiguousarray(z[::-1], dtype=np.float32).ravel(), deep=1), (w, h))
    ren.SetPreserveDepthBuffer(z is not None)
    window.Render()
    return read_premultiplied(window, w, h)


def _write_depth(ren: vtkRenderer, state: dict[str, Any]) -> None:
    """The renderer's start: the opaque scene's depth written into the window's depth buffer, which the renderer
    keeps (``PreserveDepthBuffer``) and the mapper's depth test reads."""
    if state.get("depth") is not None:
        depth, (w, h) = state["depth"]
        ren.GetRenderWindow().SetZbufferData(0, 0, w - 1, h - 1, depth)
