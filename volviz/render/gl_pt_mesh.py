"""The GPU PT pass's static vertex buffer (Roettger Ch. 8-9; ``volviz.render.gl_pt``): 4 vertices per tetrahedron,
each carrying its cell's face planes, scalar form and range (relative to the mesh's centre: meshes offset by 1e6 keep
their precision), uploaded once. The index buffer, made per order, is ``volviz.unstructured.index_buffer``'s; with
the order as a texture (``GLPTVolume(order_texture=True)``) the same data are texels, ``cell_texels``, read by cell
id, and the vertex buffer keeps only the corners."""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from volviz.model.datasets import TetMesh
from volviz.unstructured.iso import vertex_normals
from volviz.unstructured.topology import cell_ranges, topology

if TYPE_CHECKING:   # type-only: VTK's classes, reached through the facade at run time
    from volviz.render.vtk_facade import vtkPolyData

__all__ = ["cell_attributes", "cell_texels", "tet_polydata", "texels_per_cell"]


def cell_attributes(mesh: TetMesh, smooth: bool = False) -> dict[str, np.ndarray]:
    """Per-cell (m, 4) float32 attributes, relative to the mesh centre: the four face planes (n, d) and the scalar
    form (g, c) with s(x) = g . x + c inside the cell (x relative to the centre); the cell's scalar (min, max, 0, 0).
    Zero-volume cells get g = 0 (they hold no medium; their segments have zero length). ``smooth`` adds the x, y and
    z of the normals of the cell's 4 vertices (``volviz.unstructured.iso.vertex_normals``; vertex f opposite face f)
    and 1 / (d_f - n_f . p_f), which turns face f's plane into the barycentric coordinate of vertex f."""
    topo = topology(mesh)
    p = topo.points[topo.tets]                                       # (m, 4, 3)
    s = np.nan_to_num(mesh.scalars[topo.tets].astype(np.float64))    # NaN cells are culled from the order
    edges = p[:, 1:] - p[:, :1]                                      # (m, 3, 3)
    ds = s[:, 1:] - s[:, :1]
    det = np.linalg.det(edges)
    ok = np.abs(det) > 1e-300
    g = np.zeros((len(p), 3))
    g[ok] = np.linalg.solve(edges[ok], ds[ok][..., None])[..., 0]
    c = s[:, 0] - np.einsum("ij,ij->i", g, p[:, 0])
    r = cell_ranges(mesh)
    out = {f"ptPlane{f}": np.concatenate([topo.face_n[:, f], topo.face_d[:, f, None]], axis=1) for f in range(4)}
    out["ptScalar"] = np.concatenate([g, c[:, None]], axis=1)
    out["ptRange"] = np.stack([r.smin, r.smax, np.zeros_like(r.smin), np.zeros_like(r.smin)], axis=1)
    if smooth:
        normals = vertex_normals(mesh)[topo.tets]                     # (m, 4, 3)
        for axis, name in enumerate("XYZ"):
            out[f"ptNormal{name}"] = normals[..., axis]
        height = topo.face_d - np.einsum("mfk,mfk->mf", topo.face_n, p)
        out["ptBary"] = np.divide(1.0, height, out=np.zeros_like(height), where=height > 1e-300)
    return {k: np.ascontiguousarray(v, dtype=np.float32) for k, v in out.items()}


def texels_per_cell(smooth: bool) -> int:
    """Texels of one cell in ``cell_texels``: 4 corners, 4 planes, scalar form, range (and 3 normals, barycentric)."""
    return 14 if smooth else 10


def cell_texels(mesh: TetMesh, smooth: bool = False) -> np.ndarray:
    """(m * ``texels_per_cell``, 4) float32: per cell its 4 corners (x, y, z, 0; relative to the centre) and then
    ``cell_attributes`` in their order (the layout ``pt_tet_vs.glsl`` reads with ``PT_ORDER_TEXTURE``)."""
    topo = topology(mesh)
    corners = np.zeros((topo.n_tets, 4, 4), np.float32)
    corners[..., :3] = topo.points[topo.tets]
    parts = [corners] + [a[:, None, :] for a in cell_attributes(mesh, smooth).values()]
    return np.concatenate(parts, axis=1).reshape(-1, 4)


def tet_polydata(mesh: TetMesh, smooth: bool = False, attributes: bool = True) -> vtkPolyData:
    """The static vertex buffer as vtkPolyData: 4 points per tetrahedron (relative to the centre) with the cell
    attributes repeated at each (unless ``attributes`` is False: the order texture's layout reads them from
    ``cell_texels``), and no cells yet (the order sets them)."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import numpy_to_vtk, vtk

    topo = topology(mesh)
    pd = vtk.vtkPolyData()
    pts = vtk.vtkPoints()
    pts.SetData(numpy_to_vtk(np.ascontiguousarray(topo.points[topo.tets].reshape(-1, 3), np.float32), deep=True))
    pd.SetPoints(pts)
    for name, arr in (cell_attributes(mesh, smooth) if attributes else {}).items():
        va = numpy_to_vtk(np.ascontiguousarray(np.repeat(arr, 4, axis=0)), deep=True)
        va.SetName(name)
        pd.GetPointData().AddArray(va)
    pd.SetPolys(vtk.vtkCellArray())
    return pd

