"""The one module of volviz that imports VTK's rendering side (issue #18): ``volviz.render``'s modules and the
benchmarks that draw get VTK from here (``from volviz.render.vtk_facade import vtk``), never by ``import vtk``;
``tests/test_layering_rendering.py`` checks it. Importing this module loads VTK's rendering libraries, so modules
import it inside the functions that draw.

``vtk`` is not VTK's all-in-one module (about 150 modules; what that cost is in ``docs/architecture.md``) but a
namespace of the classes volviz uses, each imported by name from its ``vtkmodules`` module, as PyVista's ``_vtk``
does; ``tests/test_vtk_facade.py`` checks that it holds exactly the names its callers use. The modules that only
register VTK's factory overrides (the OpenGL classes behind ``vtkRenderer``, ``vtkActor``, the volume mappers; text;
the interactor styles) are imported here too, since nothing else may be loaded when volviz draws.

Besides that namespace and NumPy's bridge to VTK, it holds the VTK idioms the GL passes (``gl_pt``, ``gl_fog``,
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

from types import SimpleNamespace
from typing import TYPE_CHECKING, Any, Callable, Sequence

import numpy as np

# factory overrides only: without them VTK makes abstract renderers, mappers and windows that draw nothing
import vtkmodules.vtkInteractionStyle  # noqa: F401 - the interactor styles (VTK's default trackball camera)
import vtkmodules.vtkRenderingFreeType  # noqa: F401 - text (scalar bar, text actors)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401 - OpenGL renderers, windows, actors, poly data mappers
import vtkmodules.vtkRenderingUI  # noqa: F401 - the platform's render window interactor
import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401 - the GPU ray caster, OpenGL projected tetrahedra
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy

# the classes and constants ``vtk`` (below) holds, by module (F401: they are used through it)
from vtkmodules.vtkCommonCore import (  # noqa: F401
    VTK_FLOAT, VTK_OBJECT, VTK_UNSIGNED_CHAR, VTK_UNSTRUCTURED_GRID, vtkCommand, vtkFloatArray, vtkIdList, vtkLogger,
    vtkPoints, vtkUnsignedCharArray)
from vtkmodules.vtkCommonDataModel import (  # noqa: F401
    vtkCellArray, vtkCellLocator, vtkDataObject, vtkImageData, vtkMultiBlockDataSet, vtkPiecewiseFunction, vtkPlane,
    vtkPolyData)
from vtkmodules.vtkCommonTransforms import vtkTransform  # noqa: F401
from vtkmodules.vtkFiltersCore import vtkAppendPolyData  # noqa: F401
from vtkmodules.vtkFiltersGeneral import vtkDataSetTriangleFilter, vtkTransformPolyDataFilter  # noqa: F401
from vtkmodules.vtkInteractionStyle import vtkInteractorStyleTrackballCamera  # noqa: F401
from vtkmodules.vtkRenderingAnnotation import vtkScalarBarActor  # noqa: F401
from vtkmodules.vtkRenderingCore import (  # noqa: F401
    vtkActor, vtkCamera, vtkCellPicker, vtkColorTransferFunction, vtkCoordinate, vtkDataSetMapper,
    vtkImageActor, vtkPolyDataMapper, vtkPolyDataMapper2D, vtkPropAssembly, vtkRenderer, vtkRenderWindow,
    vtkRenderWindowInteractor, vtkShaderProperty, vtkTextActor, vtkTexture, vtkTexturedActor2D, vtkVolume,
    vtkVolumeProperty, vtkWindowToImageFilter)
from vtkmodules.vtkRenderingOpenGL2 import (  # noqa: F401
    vtkFramebufferPass, vtkOpenGLFramebufferObject, vtkOpenGLPolyDataMapper, vtkRenderStepsPass, vtkTextureObject)
from vtkmodules.vtkRenderingVolume import (  # noqa: F401
    vtkProjectedTetrahedraMapper, vtkUnstructuredGridVolumeRayCastMapper, vtkUnstructuredGridVolumeZSweepMapper)
from vtkmodules.vtkRenderingVolumeOpenGL2 import vtkMultiBlockVolumeMapper, vtkSmartVolumeMapper  # noqa: F401

if TYPE_CHECKING:   # types other modules of render annotate with; not ones ``vtk`` holds (no caller makes one)
    from vtkmodules.vtkRenderingCore import vtkAbstractMapper, vtkProp  # noqa: F401
    from vtkmodules.vtkRenderingOpenGL2 import vtkOpenGLRenderWindow, vtkShaderProgram  # noqa: F401

#: the VTK classes and constants imported above, by their VTK names: ``vtk.vtkActor()`` as with VTK's own module
vtk = SimpleNamespace(**{name: value for name, value in dict(globals()).items()
                         if name.startswith("VTK_") or (name.startswith("vtk") and name[3:4].isupper())})

__all__ = ["box_corners_polydata", "numpy_to_vtk", "premultiplied_texture", "shader_observer", "shared_polydata",
           "vtk", "vtk_to_numpy"]


def shader_observer(fn: Callable[[vtkShaderProgram], None]) -> Callable[..., None]:
    """An ``UpdateShaderEvent`` callback that calls ``fn(program)`` with the program being bound (none: not called)."""

    def on_update_shader(caller: Any, event: str, program: vtkShaderProgram | None = None) -> None:
        if program is not None:
            fn(program)

    on_update_shader.CallDataType = vtk.VTK_OBJECT      # type: ignore[attr-defined]
    return on_update_shader


def premultiplied_texture() -> vtkTexture:
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
                    connectivity: np.ndarray | None = None) -> vtkPolyData:
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


def box_corners_polydata(bounds: np.ndarray, triangles: Sequence[tuple[int, int, int]] = ()) -> vtkPolyData:
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
