"""A visibility order as the GPU PT pass's index buffer (Roettger Ch. 8-9: cells drawn back to front, 4 triangles
each), in one Numba pass: the zero-opacity cull (Roettger §9.1, cells whose scalar range meets no rho > 0) and the
int32 triangle connectivity for ``vtkCellArray.SetData`` written together into buffers kept between frames, so a new
camera's order costs no numpy temporaries (the previous chain ``order[visible[order]]``, ``4 * cells``, broadcast
add, made 3 passes and 4 arrays per frame; ``docs/bench/unstructured.md``).

Vertex ``4 c + k`` is corner k of cell c in the static vertex buffer (``volviz.render.gl_pt_mesh.tet_polydata``);
triangle f of a cell is its face f, ``topology.FACES``.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from volviz.unstructured.topology import FACES

__all__ = ["IndexBuffer", "fill_cells", "fill_triangles", "load_kernels"]

#: the 12 corner ids of a cell's 4 faces, in FACES order
_CORNERS = np.ascontiguousarray(FACES.reshape(12), dtype=np.int32)


@njit(cache=True, nogil=True)
def fill_triangles(order: np.ndarray, visible: np.ndarray, cells: np.ndarray, conn: np.ndarray) -> int:
    """The cells of ``order`` with ``visible[cell]`` into ``cells[:n]`` (same order) and their 4 faces' vertex ids
    into ``conn[:12 n]`` (int32: vertex 4 c + corner); returns n. ``cells`` and ``conn`` hold at least
    ``len(order)`` and ``12 len(order)`` entries."""
    n = 0
    for i in range(len(order)):
        c = order[i]
        if not visible[c]:
            continue
        base = np.int32(4 * c)
        k = 12 * n
        for j in range(12):
            conn[k + j] = base + _CORNERS[j]
        cells[n] = c
        n += 1
    return n


@njit(cache=True, nogil=True)
def fill_cells(order: np.ndarray, visible: np.ndarray, cells: np.ndarray) -> int:
    """The cells of ``order`` with ``visible[cell]`` into ``cells[:n]`` as float32 (the GPU pass's order texture,
    exact for ids below 2^24); returns n."""
    n = 0
    for i in range(len(order)):
        c = order[i]
        if visible[c]:
            cells[n] = c
            n += 1
    return n


def load_kernels(order: np.ndarray, visible: np.ndarray) -> None:
    """Any thread: call both fills on no cells for the types of ``order`` and ``visible``. A Numba kernel's first
    call in a process loads its compiled code from the cache while holding the GIL; the worker that makes a volume's
    first order calls this, so that the first frame's fill on the GUI thread finds them loaded (issue #28)."""
    none = np.empty(0, np.int32)
    fill_triangles(order[:0], visible[:0], none, none)
    fill_cells(order[:0], visible[:0], np.empty(0, np.float32))


class IndexBuffer:
    """Buffers for the index buffer of a mesh of ``n_cells`` cells, made once and refilled per order: ``fill``
    returns views of them (offsets 0, 3, 6, ..., connectivity, drawn cells), which VTK can share without a copy
    (``numpy_to_vtk(..., deep=False)``). A fill overwrites the previous one's views, so fill on the thread that
    renders, between renders (VTK reads the arrays when it builds its index buffer during a render)."""

    def __init__(self, n_cells: int) -> None:
        if 4 * n_cells >= 2 ** 31:
            raise ValueError(f"too many tetrahedra for 32-bit vertex indices: {n_cells}")
        self.cells = np.empty(n_cells, np.int32)
        self.conn = np.empty(12 * n_cells, np.int32)
        self.offsets = np.arange(0, 3 * (4 * n_cells + 1), 3, dtype=np.int32)

    def fill(self, order: np.ndarray, visible: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(offsets, connectivity, cells) of the cells of ``order`` (back to front) with ``visible[cell]``."""
        if len(order) > len(self.cells):
            raise ValueError(f"order of {len(order)} cells for an index buffer of {len(self.cells)}")
        n = fill_triangles(order, visible, self.cells, self.conn)
        return self.offsets[:4 * n + 1], self.conn[:12 * n], self.cells[:n]
