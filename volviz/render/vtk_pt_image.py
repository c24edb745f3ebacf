"""PT volumes drawn by VTK's OpenGL as an image in an offscreen window of a thread of its own, to be shown over the
scene as volviz's CPU PT image is (``volviz.render.pt_prop``; issue #28): VTK's projected tetrahedra
(vtkProjectedTetrahedraMapper, the render method "vtk"), whose per-frame work, the cells' depth sort and projection on
the CPU, held the GUI thread at every frame in the scene's window; and volviz's GPU PT pass (``volviz.render.gl_pt``,
"pt-gl") where it is drawn off the scene's window (``volviz.render.backend.gpu_in_thread``: on a software rasteriser
its raster is CPU work, which held the GUI thread for a whole still frame).

The image is the one the scene's window would draw: both blend the cells into a transparent black background, which
leaves the premultiplied colour and alpha of the volume (the "over" of ``volviz.render.image_overlay``). The cells
are depth-tested against the opaque scene as in the scene's window: the opaque scene's depth (read back by the
overlay's ``begin``) is written into the window's depth buffer before the volume is drawn (``SetZbufferData`` when
the renderer starts, the renderer keeping its depth buffer), in the window depth of the image's camera
(``window_z``: its far plane is moved to the volume's far side). Guthe §4.5: the volume behind an opaque surface is
hidden.
"""
from __future__ import annotations

import time
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any, Callable, Optional

import numpy as np

from volviz.model.camera import Camera
from volviz.render.gl_thread import GLThread
from volviz.render.image_overlay import read_premultiplied
from volviz.unstructured.render import UnstructuredRenderStats

if TYPE_CHECKING:   # type-only imports for the signatures
    from volviz.model.datasets import TetMesh
    from volviz.optics.transfer_function import TransferFunction
    from volviz.render.vtk_facade import vtkRenderer

__all__ = ["THREAD_METHODS", "ThreadPTImages", "window_z"]

#: the PT methods drawn here: VTK's projected tetrahedra, volviz's GPU PT pass
THREAD_METHODS = ("vtk", "pt-gl")


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


class ThreadPTImages:
    """Images of a TetMesh drawn by ``method`` (``THREAD_METHODS``) in a window of a thread of its own
    (``volviz.render.gl_thread``): ``render`` from any thread; ``close`` ends the thread. ``options``: the GPU PT
    pass's keywords (``GLPTVolume``'s lookup, table and sort)."""

    def __init__(self, method: str = "vtk", options: Optional[dict[str, Any]] = None) -> None:
        if method not in THREAD_METHODS:
            raise ValueError(f"a thread's PT method must be one of {', '.join(THREAD_METHODS)}, got {method!r}")
        self.method = method
        self.options = dict(options or {})
        self.gl = GLThread(f"volviz-{method}")

    def render(self, mesh: TetMesh, tf: TransferFunction, camera: Camera, size: tuple[int, int],
               depth: Optional[np.ndarray] = None) -> tuple[np.ndarray, UnstructuredRenderStats]:
        """Any thread: ``mesh`` with ``tf`` seen by ``camera`` at ``size`` (w, h) as premultiplied float RGBA
        (H, W, 4), row 0 at the top, in 8-bit steps, and its statistics; ``depth`` (H, W): the opaque scene's
        eye-space depth (+inf: nothing), which hides the cells behind it."""
        t0 = time.perf_counter()
        z = None if depth is None else window_z(depth, camera.clipping_range, camera.parallel)
        image = self.gl.call(_draw, self.gl.state, _PROPS[self.method], mesh, tf, camera, size, z, self.options)
        stats = UnstructuredRenderStats(method=self.method, size=size, n_tets=mesh.n_cells,
                                        total_s=time.perf_counter() - t0)
        return image, stats

    def close(self) -> None:
        """End the thread, its window closed there after the image in progress, without waiting for it (the caller is
        the GUI thread, removing the view); a GPU PT volume's graphics resources are released there first."""
        if self.method == "pt-gl":
            self.gl.submit(_release, self.gl.state)
        self.gl.close(wait=False)


def _volume(ren: vtkRenderer, state: dict[str, Any], mesh: TetMesh, tf: TransferFunction,
            options: dict[str, Any]) -> None:
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
    if not ren.HasViewProp(volume):
        ren.AddVolume(volume)
    if not state.get("drawn"):
        # VTK's mapper leaves cells out of the first frame a window draws with it (``offscreen``'s
        # ``draw_projected_tetrahedra_once``): a first frame at 8 x 8 costs its sort and no raster
        window = ren.GetRenderWindow()
        window.SetSize(8, 8)
        ren.PreserveDepthBufferOff()
        window.Render()
        state["drawn"] = True


def _pt_gl_volume(ren: vtkRenderer, state: dict[str, Any], mesh: TetMesh, tf: TransferFunction,
                  options: dict[str, Any]) -> None:
    """The window's GPU PT volume (``volviz.render.gl_pt.GLPTVolume`` with ``options``) drawing ``mesh`` with
    ``tf``: made again for a new mesh (a cut under clipping), given a new ``tf``; every frame at full size, its
    cells sorted for the frame's camera here."""
    # heavy: VTK (all of it, through gl_pt), loaded where VTK objects are made
    from volviz.render.gl_pt import GLPTVolume

    volume = state.get("pt-gl")
    if volume is not None and volume.whole_mesh is not mesh:
        volume.remove()
        volume = state["pt-gl"] = None
    if volume is None:
        # the window's own renderer, single-sampled, no scene pass: the cells read the depth buffer written by
        # ``_write_depth``
        volume = state["pt-gl"] = GLPTVolume(SimpleNamespace(renderer=ren), mesh, tf, keep_multisampling=True,
                                             **{"lookup": "auto", **options})
        volume.set_interactive(False)
    elif volume.tf is not tf:
        volume.set_tf(tf)


#: what puts each method's volume into the window's renderer
_PROPS: dict[str, Callable[..., None]] = {"vtk": _volume, "pt-gl": _pt_gl_volume}


def _release(ren: vtkRenderer, state: dict[str, Any]) -> None:
    """On the window's thread: the GPU PT volume's textures and targets released while its context is current."""
    volume = state.pop("pt-gl", None)
    if volume is not None:
        volume.remove()


def _draw(ren: vtkRenderer, state: dict[str, Any], prop: Callable[..., None], mesh: TetMesh, tf: TransferFunction,
          camera: Camera, size: tuple[int, int], z: Optional[np.ndarray], options: dict[str, Any]) -> np.ndarray:
    """On the window's thread: draw ``mesh`` (the volume ``prop`` puts in the renderer) over the depth ``z``
    (window depth, row 0 at the top; None: none) and read the image back."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import numpy_to_vtk, vtk

    if not state.get("set up"):
        ren.SetBackground(0.0, 0.0, 0.0)
        ren.SetBackgroundAlpha(0.0)
        ren.AddObserver(vtk.vtkCommand.StartEvent, lambda *_: _write_depth(ren, state))
        state["set up"] = True
    prop(ren, state, mesh, tf, options)
    camera.apply_to(ren.GetActiveCamera())
    window = ren.GetRenderWindow()
    w, h = (int(v) for v in size)
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
