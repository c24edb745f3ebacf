"""What the ray-segment passes (the PT cells, the fog prisms) set per draw and draw last: the pixel ray's uniforms
(``ray_pixel.glsl``: the camera's affine ray basis, so a fragment rebuilds its ray from ``gl_FragCoord`` with no
interpolated varyings) and the resolve's geometry (one triangle over the viewport, in the pass's bounds so that VTK
culls it with the pass)."""
from __future__ import annotations

from typing import TYPE_CHECKING, Sequence

import numpy as np

if TYPE_CHECKING:   # type-only: the camera's ray basis and VTK's classes, not imported at run time
    from volviz.model.camera import RayBasis
    from volviz.render.vtk_facade import vtkPolyData, vtkShaderProgram

__all__ = ["resolve_polydata", "set_ray_uniforms"]


def set_ray_uniforms(program: vtkShaderProgram, rays: RayBasis, view_height: float, clip_range: Sequence[float],
                     parallel: bool) -> None:
    """The uniforms of ``ray_pixel.glsl``: the ray basis ``rays`` (``Camera.rays``: o0, ox, oy, d0, dx, dy) of a
    target ``view_height`` pixels high, the camera's near and far planes ``clip_range``, parallel projection."""
    for name, v in (("rayO0", rays.o0), ("rayOx", rays.ox), ("rayOy", rays.oy), ("rayD0", rays.d0),
                    ("rayDx", rays.dx), ("rayDy", rays.dy)):
        program.SetUniform3f(name, [float(x) for x in v])
    program.SetUniformf("viewHeight", float(view_height))
    program.SetUniform2f("clipRange", [float(x) for x in clip_range])
    program.SetUniformi("parallelView", int(parallel))


def resolve_polydata(bounds: np.ndarray) -> vtkPolyData:
    """The resolve's geometry: the 8 corners of ``bounds`` (3, 2) in the actor's bounds, so that VTK culls it with
    the pass, and the triangle (0, 1, 2), which ``pt_resolve_vs.glsl`` places over the viewport by ``gl_VertexID``
    (vertex 7 of the bounds' zero-area triangle lands on vertex 0)."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import box_corners_polydata

    return box_corners_polydata(bounds, [(0, 1, 2)])
