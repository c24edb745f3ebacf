"""The one module of volviz that imports VTK's rendering side (issue #18): ``volviz.render``'s modules and the
benchmarks that draw get VTK from here (``from volviz.render.vtk_facade import vtk``), never by ``import vtk``;
``tests/test_layering_rendering.py`` checks it. Importing this module loads VTK (about a second), so modules import it
inside the functions that draw, as they did VTK itself.

Besides the VTK module and NumPy's bridge to it, it holds the VTK idioms the GL passes (``gl_pt``, ``gl_fog``,
``gl_iso``, ``gl_nature``) share:

- ``shader_observer(fn)``: a callback for a mapper's ``UpdateShaderEvent`` that hands ``fn`` the shader program
  being bound (VTK passes it only to a callback marked ``CallDataType = VTK_OBJECT``);
- ``premultiplied_texture()``: a 1x1 white texture with premultiplied alpha, which makes VTK blend an actor with
  (ONE, ONE_MINUS_SRC_ALPHA) and restore its own blend state after it;
- ``shared_polydata(points, attributes, connectivity)``: poly data whose points, point arrays and triangles share
  NumPy buffers without a copy (a vertex buffer made on a worker thread, handed to VTK on the GUI thread);
- ``box_corners_polydata(bounds, triangles)``: the 8 corners of a box and a zero-area triangle spanning it, with
  any triangles given (what VTK culls a full-screen pass by, and a bounds holder that draws nothing).
"""
from __future__ import annotations

from typing import Any, Callable, Sequence

import numpy as np
import vtk
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy

__all__ = ["box_corners_polydata", "numpy_to_vtk", "premultiplied_texture", "shader_observer", "shared_polydata",
           "vtk", "vtk_to_numpy"]


def shader_observer(fn: Callable[[Any], None]) -> Callable[..., None]:
    """An ``UpdateShaderEvent`` callback that calls ``fn(program)`` with the program being bound (none: not called)."""

    def on_update_shader(caller: Any, event: str, program: Any = None) -> None:
        if program is not None:
            fn(program)

    on_update_shader.CallDataType = vtk.VTK_OBJECT      # type: ignore[attr-defined]
    return on_update_shader


def premultiplied_texture() -> Any:
    """A 1x1 white texture with PremultipliedAlphaOn: VTK then blends the actor with (ONE, ONE_MINUS_SRC_ALPHA) and
    restores its blend state after it."""
    img = vtk.vtkImageData()
    img.SetDimensions(1, 1, 1)
    img.AllocateScalars(vtk.VTK_UNSIGNED_CHAR, 4)
    img.GetPointData().GetScalars().SetTuple4(0, 255, 255, 255, 255)
    tex = vtk.vtkTexture()
    tex.SetInputData(img)
    tex.PremultipliedAlphaOn()
    return tex


def shared_polydata(points: np.ndarray, attributes: dict[str, np.ndarray],
                    connectivity: np.ndarray | None = None) -> Any:
    """A vtkPolyData sharing NumPy vertex buffers (no copy; the VTK arrays keep them referenced): float32 ``points``
    (n, 3), named per-vertex ``attributes``, triangles ``connectivity`` (3 indices each; None: no cells yet, e.g.
    when a visibility order sets them later). 32-bit ``connectivity`` keeps VTK's cells in 32-bit storage, from which
    VTK builds the index buffer several times faster than from 64-bit cells."""
    pd = vtk.vtkPolyData()
    vp = vtk.vtkPoints()
    vp.SetData(numpy_to_vtk(points, deep=False))
    pd.SetPoints(vp)
    for name, arr in attributes.items():
        va = numpy_to_vtk(arr, deep=False)
        va.SetName(name)
        pd.GetPointData().AddArray(va)
    cells = vtk.vtkCellArray()
    if connectivity is not None:
        cells.SetData(numpy_to_vtk(np.arange(0, len(connectivity) + 1, 3, dtype=connectivity.dtype), deep=True),
                      numpy_to_vtk(connectivity, deep=False))
    pd.SetPolys(cells)
    return pd


def box_corners_polydata(bounds: np.ndarray, triangles: Sequence[tuple[int, int, int]] = ()) -> Any:
    """Poly data with the 8 corners of ``bounds`` (3, 2) as float32 points (corner i at x = bounds[0][i & 1],
    y = bounds[1][(i >> 1) & 1], z = bounds[2][(i >> 2) & 1]), the ``triangles`` given, and the zero-area triangle
    (0, 7, 7) between opposite corners. VTK's mappers take their bounds (frustum culling, the camera's clipping range)
    from the points the cells use, so that triangle makes them the whole box; a zero-area triangle gives GL no
    fragment (as long as the vertex shader places vertex 7 on vertex 0 or on the same point twice)."""
    b = np.asarray(bounds, np.float64).reshape(3, 2)
    corners = np.array([[b[0, i & 1], b[1, (i >> 1) & 1], b[2, (i >> 2) & 1]] for i in range(8)], np.float32)
    pd = vtk.vtkPolyData()
    vp = vtk.vtkPoints()
    vp.SetData(numpy_to_vtk(corners, deep=True))
    pd.SetPoints(vp)
    tris = np.array([*triangles, (0, 7, 7)], np.int64).reshape(-1)
    cells = vtk.vtkCellArray()
    offsets = np.arange(0, len(tris) + 1, 3, dtype=np.int64)
    cells.SetData(numpy_to_vtk(offsets, deep=True), numpy_to_vtk(tris, deep=True))
    pd.SetPolys(cells)
    return pd
