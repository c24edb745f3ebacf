"""Translucent actors depth-peeled by VTK over a renderer's finished image, whatever render pass that renderer uses.

    layer = PeelLayer(plotter.renderer, peels=64)
    layer.add(actor)            # drawn by the layer, peeled with the layer's other actors
    layer.remove()

VTK's depth peeling (``vtkDualDepthPeelingPass``) is the renderer's own translucent stage: a renderer given a custom
pass (``renderer.SetPass``: the float32 scene target that the GPU PT volumes and fog layers install,
``volviz.render.gl.ScenePass``) does not peel. A ``PeelLayer`` is a second renderer on the same layer of
the render window, added after it, so it draws right after that renderer and before any renderer of a higher layer
(volviz's CPU image overlays, ``volviz.render.image_overlay``): it keeps the color and depth buffers the renderer
left (a ``vtkFramebufferPass`` copies its color and depth back to the window), has no opaque props, and peels its
actors with VTK's dual depth peeling against that depth: each actor is hidden by the opaque scene and composited over
everything the renderer drew, translucent props and GPU volumes included. That is how volviz's CPU image overlays
composite too (over the rendered scene, through its depth), so both backends put the same surfaces over the same
image. Verified on llvmpipe: the peeled image is bit-equal to the same actors peeled by the renderer itself (no pass,
no other translucent prop) and unchanged with a ``vtkFramebufferPass`` installed on the renderer
(``tests/test_render_gl_iso.py``).

The layer shares the renderer's camera and viewport (taken again at each of its renders) and is not interactive. It
draws nothing the renderer's bounds do not hold: for each actor a box of its bounds stays in the renderer (its 8
corners and a zero-area triangle between opposite corners, which GL rasterises to no fragment:
``vtk_facade.box_corners_polydata``), so resetting the camera or its clipping range there still sees the peeled
geometry.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:   # type-only: VTK's classes, reached through the facade at run time
    from volviz.render.vtk_facade import vtkActor

__all__ = ["PeelLayer"]


class PeelLayer:
    """A renderer that depth-peels its actors (at most ``peels`` layers, occlusion ratio 0: every layer) over the
    image and depth ``renderer`` leaves (module docstring)."""

    def __init__(self, renderer: Any, peels: int = 64) -> None:
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk

        self.base = renderer
        self.renderer = vtk.vtkRenderer()
        self.renderer.SetLayer(renderer.GetLayer())
        self.renderer.SetPreserveColorBuffer(True)      # after SetLayer, which sets it for layer 0
        self.renderer.SetPreserveDepthBuffer(True)
        self.renderer.InteractiveOff()
        self.renderer.SetUseDepthPeeling(True)
        self.renderer.SetMaximumNumberOfPeels(int(peels))
        self.renderer.SetOcclusionRatio(0.0)
        self._follow()
        self._proxies: dict[int, Any] = {}
        self._tag = self.renderer.AddObserver(vtk.vtkCommand.StartEvent, self._follow)
        renderer.GetRenderWindow().AddRenderer(self.renderer)

    @property
    def peels(self) -> int:
        return int(self.renderer.GetMaximumNumberOfPeels())

    def _follow(self, *_: Any) -> None:
        """The renderer's camera and viewport (PyVista may give the renderer a new camera object)."""
        cam = self.base.GetActiveCamera()
        if self.renderer.GetActiveCamera() is not cam:
            self.renderer.SetActiveCamera(cam)
        self.renderer.SetViewport(self.base.GetViewport())

    def add(self, actor: vtkActor) -> None:
        """Peel ``actor`` from the next render on; a box of its bounds joins the renderer's bounds."""
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import box_corners_polydata, vtk

        self.renderer.AddActor(actor)
        bounds = np.asarray(actor.GetBounds(), np.float64)
        if not np.all(np.isfinite(bounds)) or bounds[0] > bounds[1]:
            return
        mapper = vtk.vtkPolyDataMapper()
        mapper.SetInputData(box_corners_polydata(bounds))   # one zero-area triangle: the bounds, no fragment
        proxy = vtk.vtkActor()
        proxy.SetMapper(mapper)
        proxy.PickableOff()
        self.base.AddActor(proxy)
        self._proxies[id(actor)] = proxy

    def remove(self) -> None:
        """Take the layer and its bounds boxes out of the render window and the renderer."""
        for proxy in self._proxies.values():
            self.base.RemoveActor(proxy)
        self._proxies = {}
        self.renderer.RemoveObserver(self._tag)
        self.renderer.RemoveAllViewProps()
        ren_win = self.base.GetRenderWindow()
        if ren_win is not None:
            ren_win.RemoveRenderer(self.renderer)
