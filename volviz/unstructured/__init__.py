"""Unstructured volume rendering: tetrahedralisation, visibility sorting, projected tetrahedra with pre-integration,
and the exact reference ray caster (Roettger Ch. 8-9, Guthe Ch. 3).

    from volviz.unstructured import tetrahedralize, render, Camera
    mesh = tetrahedralize(grid)                         # CurvilinearGrid / UnstructuredMesh / pyvista grid
    image, stats = render(mesh, tf, Camera.orbit(mesh.points), (512, 512), "pt", return_stats=True)

Sorting for the next camera can run in a worker thread (the Numba kernels release the GIL):
``visibility_order(mesh, camera, size).order`` is then passed to ``render(..., order=...)``.
"""
from volviz.model.camera import Camera
from volviz.unstructured.render import UnstructuredRenderStats, render
from volviz.unstructured.sort import SortResult, visibility_order
from volviz.unstructured.tetrahedralize import TetrahedralizeReport, tetrahedralize

__all__ = ["Camera", "UnstructuredRenderStats", "SortResult", "TetrahedralizeReport", "render", "tetrahedralize",
           "visibility_order"]
