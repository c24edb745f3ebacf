"""The regular volumes of a scene split at the nearest translucent isosurface, for the CPU transparency modes of the
libMini note §4 drawn with a VTK volume in the scene (issue #28; libMini note "Isosurfaces": along each ray the
volume behind the surfaces, the surfaces and the volume in front composite in that order).

The overlay of ``volviz.render.iso_overlay`` is the modes' premultiplied image I (alpha α = 1 − T, T = Π(1 − α_i)
the surfaces' transmission in every mode) drawn over the rendered scene F, C = I + T·F: the whole volume lies under
the surfaces. With V_f, a_f the volume from the eye to the nearest translucent fragment (premultiplied colour and
alpha) and F = V_f + (1 − a_f)·B (B: the volume behind it and everything further), the composite "volume in front,
surfaces, volume behind" is

    C = V_f + (1 − a_f)·I + T·(F − V_f) = I' + T·F,   I' = (1 − a_f)·I + α·V_f,

an overlay of the same alpha (I' ≤ α where I ≤ α), so only the overlay's image changes. It is exact when a ray
meets one translucent layer (every mode: a plane through a ball, RMSE 0.42 levels against the exact composite of the
scene's own renders, tests/test_iso_modes_volume.py; 27 with the surface over the whole volume). The volume between
two layers is composited behind both: two parallel planes through the ball's dense middle, exact mode, RMSE 8.0
against the exact composite with the volume between them (24 for the surfaces over the whole volume); splitting at
every layer would take one more volume render per layer. The GPU's exact mode peels the surfaces with the volume
instead (``volviz.render.gl_iso``: 0.57 there), so the scene controller draws only the 2/3/4-pass modes this way
when the GPU backend is chosen.

``front_volume`` renders V_f, a_f with VTK itself, so that they match the scene's own volume: the renderer's other
props hidden, the translucent surfaces drawn as an opaque occluder that writes depth and the colour (0, 0, 0, 0)
over a transparent black background; VTK's ray casters (CPU and GPU) stop at that depth and blend their
premultiplied colour and alpha over it. One more volume render per overlay image (docs/bench/iso_modes_with_volume.md).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from volviz.render.volume_peeling import regular_volumes

if TYPE_CHECKING:   # type-only imports for the signatures
    import pyvista as pv

    from volviz.iso.extract import IsoMesh
    from volviz.render.vtk_facade import vtkActor, vtkRenderer, vtkVolume

__all__ = ["SurfaceOccluder", "front_volume", "in_volume", "shown_regular_volumes"]

# depth only: colour and alpha 0, written after VTK's test that discards fragments of alpha 0
_WRITE_NOTHING = "gl_FragData[0] = vec4(0.0);\n  //VTK::Picking::Impl"


def shown_regular_volumes(renderer: vtkRenderer) -> list[vtkVolume]:
    """The visible props of ``renderer`` that VTK's smart volume mapper draws (volviz's regular volumes)."""
    props = renderer.GetViewProps()
    items: list[Any] = [props.GetItemAsObject(i) for i in range(props.GetNumberOfItems())]
    return [v for v in regular_volumes(items) if v.GetVisibility()]


def _occluder(meshes: Sequence[IsoMesh]) -> vtkActor:
    """One opaque actor of ``meshes`` that writes depth and the colour (0, 0, 0, 0)."""
    from volviz.render.vtk_facade import vtk

    append = vtk.vtkAppendPolyData()
    for m in meshes:
        if m.n_triangles:
            append.AddInputData(m.to_pyvista())
    append.Update()
    mapper = vtk.vtkOpenGLPolyDataMapper()
    mapper.SetInputData(append.GetOutput())
    mapper.ScalarVisibilityOff()
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    actor.GetProperty().LightingOff()
    actor.GetShaderProperty().AddFragmentShaderReplacement("//VTK::Picking::Impl", False, _WRITE_NOTHING,
                                                           False)
    return actor


class SurfaceOccluder:
    """The occluder of an overlay's translucent surfaces (``actor``), made again only when the meshes change (the
    overlay passes the same meshes for every image)."""

    def __init__(self) -> None:
        self._meshes: list[IsoMesh] = []
        self._actor: vtkActor | None = None

    def actor(self, meshes: Sequence[IsoMesh]) -> vtkActor:
        same = len(meshes) == len(self._meshes) and all(a is b for a, b in zip(meshes, self._meshes))
        if self._actor is None or not same:
            self._meshes, self._actor = list(meshes), _occluder(meshes)
        return self._actor


def front_volume(plotter: pv.BasePlotter, meshes: Sequence[IsoMesh], occluder: SurfaceOccluder,
                 others: Sequence[vtkRenderer] = ()) -> np.ndarray | None:
    """GUI thread: the shown regular volumes of ``plotter`` from the eye to the nearest of ``meshes`` (translucent
    surfaces, drawn as ``occluder``) as premultiplied float RGBA (H, W, 4), row 0 at the top, in 8-bit steps
    (module docstring); None when
    the scene shows no regular volume or ``meshes`` no triangle. ``others``: renderers of the window (volviz's
    overlays) kept from drawing meanwhile. The window is left with that render: draw the scene after it."""
    from volviz.render.vtk_facade import vtk, vtk_to_numpy

    ren = plotter.renderer
    volumes = shown_regular_volumes(ren)
    if not volumes or not any(m.n_triangles for m in meshes):
        return None
    actor = occluder.actor(meshes)
    props = ren.GetViewProps()
    hidden = [p for p in (props.GetItemAsObject(i) for i in range(props.GetNumberOfItems()))
              if p.GetVisibility() and not any(p is v for v in volumes)]
    drawn = [o for o in others if o.GetDraw()]
    background, alpha = ren.GetBackground(), ren.GetBackgroundAlpha()
    gradient = ren.GetGradientBackground()
    ren_win = ren.GetRenderWindow()
    try:
        for p in hidden:
            p.SetVisibility(False)
        for o in drawn:
            o.DrawOff()
        ren.AddActor(actor)
        ren.SetBackground(0.0, 0.0, 0.0)
        ren.SetBackgroundAlpha(0.0)
        ren.GradientBackgroundOff()
        ren_win.Render()
        w, h = (int(v) for v in ren_win.GetSize())
        rgba = vtk.vtkUnsignedCharArray()
        ren_win.GetRGBACharPixelData(0, 0, w - 1, h - 1, 0, rgba)
    finally:
        ren.RemoveActor(actor)
        for p in hidden:
            p.SetVisibility(True)
        for o in drawn:
            o.DrawOn()
        ren.SetBackground(*background)
        ren.SetBackgroundAlpha(alpha)
        ren.SetGradientBackground(gradient)
    return vtk_to_numpy(rgba).reshape(h, w, 4)[::-1].astype(np.float64) / 255.0


def in_volume(image: np.ndarray, front: np.ndarray | None) -> np.ndarray:
    """The modes' premultiplied overlay ``image`` (H, W, 4) with the volume in front of the surfaces, ``front``
    (``front_volume``, the same size), over it and the volume behind under it: I' = (1 − a_f)·I + α·V_f (module
    docstring); ``image`` itself when ``front`` is None."""
    if front is None:
        return image
    out = image * (1.0 - front[..., 3:4])
    out[..., :3] += image[..., 3:4] * front[..., :3]
    out[..., 3] = image[..., 3]
    return out
