"""Conforming tetrahedralisation of curvilinear grids and mixed unstructured meshes.

Roettger §8.2 (step 1) and §11.3.3: a prism becomes 3 tetrahedra, a hexahedron 5 with alternating parity so that the
face diagonals of neighbouring hexahedra agree; pyramids become 2. Guthe §4.1: structured grids split into 5 tetrahedra.

Conformity rules used here:

- hexahedra: the 5-split whose central tetrahedron is spanned by the four corners of color 0 in a 2-coloring of the
  mesh vertices along hexahedron edges. For a curvilinear grid the color is ``(i + j + k) % 2`` (the classic
  alternating parity). Every face diagonal then joins the two color-0 corners of that face, so both neighbours pick the
  same diagonal. Unstructured hexahedral meshes whose vertex graph is not bipartite are refused with a clear error.
- prisms and pyramids: every quadrilateral face is split along the diagonal through its smallest vertex in the global
  order (color, id) (Dompierre et al. 1999: any global order is consistent between neighbours); on a face shared with
  a hexahedron this is the hexahedron's color-0 diagonal, so mixed meshes conform.

Degenerate cells (|6V| <= 1e-12 * (longest edge)^3) are dropped and counted.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal, overload

import numpy as np

from volviz.model.datasets import (
    VTK_HEXAHEDRON,
    VTK_PYRAMID,
    VTK_TETRA,
    VTK_WEDGE,
    CurvilinearGrid,
    TetMesh,
    UnstructuredMesh,
)

#: the central tetrahedron and the four corner tetrahedra of a hexahedron (VTK corner order) when the color-0
#: corners are {0, 2, 5, 7}; the other parity uses the complementary corners.
_HEX5_EVEN = np.array([[0, 2, 5, 7], [1, 0, 2, 5], [3, 0, 2, 7], [4, 0, 5, 7], [6, 2, 5, 7]], dtype=np.int64)
_HEX5_ODD = np.array([[1, 3, 4, 6], [0, 1, 3, 4], [2, 1, 3, 6], [5, 1, 4, 6], [7, 3, 4, 6]], dtype=np.int64)

#: prism symmetries that bring vertex v to position 0 (VTK wedge: 0,1,2 bottom, 3,4,5 top, 3 above 0).
_WEDGE_ROT = np.array([[0, 1, 2, 3, 4, 5], [1, 2, 0, 4, 5, 3], [2, 0, 1, 5, 3, 4],
                       [3, 5, 4, 0, 2, 1], [4, 3, 5, 1, 0, 2], [5, 4, 3, 2, 1, 0]], dtype=np.int64)

DEGENERATE_TOLERANCE = 1e-12


@dataclass(frozen=True)
class TetrahedralizeReport:
    """What the tetrahedralisation did: input cells by kind, output tetrahedra, degenerate ones dropped."""

    input_cells: dict[str, int]
    n_tets: int
    n_degenerate: int


def _orient_and_filter(points: np.ndarray, tets: np.ndarray) -> tuple[np.ndarray, int]:
    """Make every tetrahedron positively oriented and drop the (near) zero-volume ones."""
    if len(tets) == 0:
        return tets.reshape(0, 4), 0
    p = points[tets]                                       # (m, 4, 3)
    e1, e2, e3 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]
    vol6 = np.einsum("ij,ij->i", np.cross(e1, e2), e3)
    edges = np.stack([e1, e2, e3, p[:, 2] - p[:, 1], p[:, 3] - p[:, 1], p[:, 3] - p[:, 2]], axis=1)
    longest = np.sqrt((edges ** 2).sum(axis=2).max(axis=1))
    keep = np.abs(vol6) > DEGENERATE_TOLERANCE * longest ** 3
    keep &= np.isfinite(vol6)
    out = tets[keep].copy()
    flip = vol6[keep] < 0
    out[flip, 2], out[flip, 3] = tets[keep][flip, 3], tets[keep][flip, 2]
    return out, int((~keep).sum())


def hexahedra_to_tets(hexes: np.ndarray, even_corner0: np.ndarray) -> np.ndarray:
    """Split hexahedra (k, 8) in VTK corner order into 5 tetrahedra each (Roettger §11.3.3, alternating parity).

    ``even_corner0[c]`` is True when corner 0 of hexahedron c has color 0 (then the central tetrahedron is 0,2,5,7).
    """
    hexes = np.asarray(hexes, dtype=np.int64)
    out = np.empty((len(hexes), 5, 4), dtype=np.int64)
    even = np.asarray(even_corner0, dtype=bool)
    out[even] = hexes[even][:, _HEX5_EVEN]
    out[~even] = hexes[~even][:, _HEX5_ODD]
    return out.reshape(-1, 4)


def wedges_to_tets(wedges: np.ndarray, rank: np.ndarray | None = None) -> np.ndarray:
    """Split prisms (k, 6) into 3 tetrahedra each, quad diagonals through the vertex of smallest ``rank`` (default:
    the vertex id; Dompierre 1999: any global total order gives conforming splits)."""
    w = np.asarray(wedges, dtype=np.int64)
    if len(w) == 0:
        return np.empty((0, 4), dtype=np.int64)
    r = w if rank is None else rank[w]
    rot = _WEDGE_ROT[np.argmin(r, axis=1)]
    v = np.take_along_axis(w, rot, axis=1)
    rv = np.take_along_axis(r, rot, axis=1)
    first = np.minimum(rv[:, 1], rv[:, 5]) < np.minimum(rv[:, 2], rv[:, 4])
    a = np.stack([v[:, [0, 1, 2, 5]], v[:, [0, 1, 5, 4]], v[:, [0, 4, 5, 3]]], axis=1)
    b = np.stack([v[:, [0, 1, 2, 4]], v[:, [0, 4, 2, 5]], v[:, [0, 4, 5, 3]]], axis=1)
    return np.where(first[:, None, None], a, b).reshape(-1, 4)


def pyramids_to_tets(pyramids: np.ndarray, rank: np.ndarray | None = None) -> np.ndarray:
    """Split pyramids (k, 5) into 2 tetrahedra each along the base diagonal through the vertex of smallest rank."""
    p = np.asarray(pyramids, dtype=np.int64)
    if len(p) == 0:
        return np.empty((0, 4), dtype=np.int64)
    r = p if rank is None else rank[p]
    d02 = np.minimum(r[:, 0], r[:, 2]) < np.minimum(r[:, 1], r[:, 3])
    a = np.stack([p[:, [0, 1, 2, 4]], p[:, [0, 2, 3, 4]]], axis=1)
    b = np.stack([p[:, [1, 2, 3, 4]], p[:, [1, 3, 0, 4]]], axis=1)
    return np.where(d02[:, None, None], a, b).reshape(-1, 4)


def _hex_vertex_colors(hexes: np.ndarray, n_points: int) -> np.ndarray:
    """2-color the vertices along hexahedron edges (BFS); raise when the vertex graph is not bipartite."""
    # heavy: SciPy's sparse graphs (about 200 modules), loaded only for hexahedral meshes
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import breadth_first_order

    edges = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [4, 5], [5, 6], [6, 7], [7, 4], [0, 4], [1, 5], [2, 6], [3, 7]])
    a = hexes[:, edges[:, 0]].ravel()
    b = hexes[:, edges[:, 1]].ravel()
    graph = coo_matrix((np.ones(2 * len(a)), (np.r_[a, b], np.r_[b, a])), shape=(n_points, n_points)).tocsr()
    color = np.full(n_points, -1, dtype=np.int64)
    for start in np.unique(hexes):
        if color[start] >= 0:
            continue
        order, pred = breadth_first_order(graph, start, directed=False, return_predecessors=True)
        color[start] = 0
        for v in order[1:]:
            color[v] = 1 - color[pred[v]]
    if np.any(color[a] == color[b]):
        raise ValueError("hexahedral mesh cannot be split conformingly into 5 tetrahedra: its vertex graph is not "
                         "bipartite (use a tetrahedral mesh or a curvilinear grid)")
    return color


def _curvilinear_hexes(dims: tuple[int, int, int]) -> tuple[np.ndarray, np.ndarray]:
    nx, ny, nz = dims
    grid = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1), np.arange(nz - 1), indexing="ij")
    i, j, k = grid[0].ravel(order="F"), grid[1].ravel(order="F"), grid[2].ravel(order="F")

    def idx(di: int, dj: int, dk: int) -> np.ndarray:
        return (i + di) + nx * ((j + dj) + ny * (k + dk))

    hexes = np.stack([idx(0, 0, 0), idx(1, 0, 0), idx(1, 1, 0), idx(0, 1, 0),
                      idx(0, 0, 1), idx(1, 0, 1), idx(1, 1, 1), idx(0, 1, 1)], axis=1)
    return hexes, (i + j + k) % 2 == 0


def _point_scalars(point_data: dict[str, np.ndarray], name: str | None, n: int,
                   order: Literal["C", "F"]) -> tuple[np.ndarray, str]:
    if not point_data:
        raise ValueError("the dataset has no point data to render")
    name = name if name is not None else next(iter(point_data))
    if name not in point_data:
        raise ValueError(f"no point array named {name!r}; available: {sorted(point_data)}")
    arr = np.asarray(point_data[name])
    if arr.size != n:
        raise ValueError(f"point array {name!r} must be scalar (one value per point), got shape {arr.shape}")
    return arr.ravel(order=order).astype(np.float64), name


@overload
def tetrahedralize(source: Any, scalars: str | None = None, report: Literal[False] = False) -> TetMesh: ...


@overload
def tetrahedralize(source: Any, scalars: str | None, report: Literal[True]) -> tuple[TetMesh, TetrahedralizeReport]:
    ...


@overload
def tetrahedralize(source: Any, scalars: str | None = None, *, report: Literal[True]
                   ) -> tuple[TetMesh, TetrahedralizeReport]: ...


@overload
def tetrahedralize(source: Any, scalars: str | None = None, report: bool = False
                   ) -> TetMesh | tuple[TetMesh, TetrahedralizeReport]: ...


def tetrahedralize(source: Any, scalars: str | None = None, report: bool = False
                   ) -> TetMesh | tuple[TetMesh, TetrahedralizeReport]:
    """Convert a CurvilinearGrid, UnstructuredMesh, TetMesh or pyvista grid into a conforming TetMesh.

    ``scalars`` names the point array (default: the active one). With ``report=True`` also returns a
    :class:`TetrahedralizeReport` with the number of degenerate cells dropped.
    """
    counts: dict[str, int] = {}
    if isinstance(source, TetMesh):
        tets, nd = _orient_and_filter(source.points, source.tets)
        mesh = TetMesh(source.points, tets, source.scalars, name=source.name, source=source.source)
        counts["tetra"] = source.n_cells
        rep = TetrahedralizeReport(counts, len(tets), nd)
        return (mesh, rep) if report else mesh
    if isinstance(source, CurvilinearGrid):
        dims = source.dimensions
        if min(dims) < 2:
            raise ValueError(f"curvilinear grid {dims} has no cells (every dimension must be >= 2)")
        points = source.points.reshape(-1, 3, order="F").astype(np.float64)
        values, name = _point_scalars(source.point_data, scalars or source.active, len(points), "F")
        hexes, even = _curvilinear_hexes(dims)
        counts["hexahedron"] = len(hexes)
        tets = hexahedra_to_tets(hexes, even)
        src = source.source
    elif isinstance(source, UnstructuredMesh):
        points = source.points
        values, name = _point_scalars(source.point_data, scalars or source.active, len(points), "C")
        tets, counts = _unstructured_tets(points, source.cells)
        src = source.source
    elif hasattr(source, "celltypes") or hasattr(source, "dimensions") and hasattr(source, "points"):
        return tetrahedralize(_from_pyvista(source, scalars), None, report)
    else:
        raise TypeError(f"cannot tetrahedralize a {type(source).__name__}")
    tets, nd = _orient_and_filter(points, tets)
    mesh = TetMesh(points, tets, values, name=name, source=src)
    rep = TetrahedralizeReport(counts, len(tets), nd)
    return (mesh, rep) if report else mesh


def _unstructured_tets(points: np.ndarray, cells: list[tuple[int, np.ndarray]]
                       ) -> tuple[np.ndarray, dict[str, int]]:
    parts: list[np.ndarray] = []
    counts: dict[str, int] = {}
    n = len(points)
    hexes = [np.asarray(c, dtype=np.int64) for t, c in cells if t == VTK_HEXAHEDRON and len(c)]
    try:
        color = _hex_vertex_colors(np.concatenate(hexes), n) if hexes else np.zeros(n, dtype=np.int64)
    except ValueError:   # no conforming 5-split: VTK's ordered triangulation of every cell
        return _vtk_tets(points, cells)
    # quad diagonals of prisms/pyramids through the smallest (color, id): on faces shared with a hexahedron that is
    # the color-0 diagonal the 5-split uses, so mixed meshes conform too
    rank = np.maximum(color, 0) * n + np.arange(n)
    for cell_type, conn in cells:
        conn = np.asarray(conn, dtype=np.int64)
        if cell_type == VTK_TETRA:
            parts.append(conn)
            counts["tetra"] = counts.get("tetra", 0) + len(conn)
        elif cell_type == VTK_HEXAHEDRON:
            parts.append(hexahedra_to_tets(conn, color[conn[:, 0]] == 0))
            counts["hexahedron"] = counts.get("hexahedron", 0) + len(conn)
        elif cell_type == VTK_WEDGE:
            parts.append(wedges_to_tets(conn, rank))
            counts["wedge"] = counts.get("wedge", 0) + len(conn)
        elif cell_type == VTK_PYRAMID:
            parts.append(pyramids_to_tets(conn, rank))
            counts["pyramid"] = counts.get("pyramid", 0) + len(conn)
        else:
            counts[f"ignored type {cell_type}"] = counts.get(f"ignored type {cell_type}", 0) + len(conn)
    tets = np.concatenate(parts) if parts else np.empty((0, 4), dtype=np.int64)
    return tets, counts


def _vtk_tets(points: np.ndarray, cells: list[tuple[int, np.ndarray]]) -> tuple[np.ndarray, dict[str, int]]:
    """Conforming tetrahedra of any linear 3D cells by VTK's vtkDataSetTriangleFilter (its ordered triangulator
    splits shared faces alike by global point ids), for hexahedral meshes whose vertex graph is not bipartite; the
    points are kept as they are."""
    # heavy: PyVista and VTK's triangulator, only for hexahedra whose vertex graph is not bipartite
    import pyvista as pv
    from vtkmodules.vtkFiltersGeneral import vtkDataSetTriangleFilter

    solid = {int(t): np.asarray(c, dtype=np.int64) for t, c in cells
             if t in (VTK_TETRA, VTK_HEXAHEDRON, VTK_WEDGE, VTK_PYRAMID) and len(c)}
    triangulate = vtkDataSetTriangleFilter()
    triangulate.SetInputData(pv.UnstructuredGrid(solid, points))
    triangulate.TetrahedraOnlyOn()
    triangulate.Update()
    out = pv.wrap(triangulate.GetOutput())
    if out.n_points != len(points):
        raise ValueError("VTK's triangulation added points; the mesh cannot be tetrahedralised in place")
    counts = {"ordered triangulation": sum(len(c) for c in solid.values())}
    return np.asarray(out.cell_connectivity, dtype=np.int64).reshape(-1, 4), counts


def _from_pyvista(grid: Any, scalars: str | None) -> CurvilinearGrid | UnstructuredMesh:
    """Wrap a pyvista StructuredGrid / UnstructuredGrid into the volviz model types."""
    # heavy: PyVista (about 180 modules), loaded only when a PyVista grid is wrapped
    import pyvista as pv

    point_data = {k: np.asarray(grid.point_data[k]) for k in grid.point_data.keys()
                  if np.asarray(grid.point_data[k]).ndim == 1}
    active = scalars or grid.active_scalars_name
    if isinstance(grid, pv.StructuredGrid):
        dims = tuple(int(d) for d in grid.dimensions)
        pts = np.asarray(grid.points, dtype=np.float64).reshape(dims[0], dims[1], dims[2], 3, order="F")
        pdata = {k: v.reshape(dims, order="F") for k, v in point_data.items()}
        return CurvilinearGrid(pts, pdata, active=active if active in pdata else None)
    if not isinstance(grid, pv.UnstructuredGrid):
        grid = grid.cast_to_unstructured_grid()
    cells = [(int(t), np.asarray(c)) for t, c in grid.cells_dict.items()]
    return UnstructuredMesh(np.asarray(grid.points), cells, point_data,
                            active=active if active in point_data else None)
