"""MPVO per view (Williams 1992; Roettger §8.1, Guthe §4.3): which neighbour of each cell is in front, and Kahn's
topological sort of the resulting graph plus the extra (boundary) relations, with cycles broken farthest first.

Only the face sides depend on the view: one pass over the cells, each shared face decided by its lower-numbered
cell's plane. On one core (beside the boundary relations on the other) the pass decides each shared face once and
writes both cells' entries (the neighbour's through ``Topology.back_face``), reading the planes in order from a
float32 copy (``planes32``: 64 bytes per cell instead of 128) and the float64 planes only where the float32 side is
too close to 0 to trust, so the decisions are the float64 ones exactly; split over the cores (large convex meshes)
each cell fills its own entries from the float64 planes. Per cell the pass keeps 1 byte (a bit per neighbour in
front, one for "has extra relations") and a 32-bit in-degree; Kahn then touches the adjacency row (int32), that byte
and the in-degrees of the neighbours in front. Times: ``docs/bench/unstructured.md``,
``docs/bench/docstring-figures.md``.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numba import njit, prange

if TYPE_CHECKING:   # type-only: the topology's module does not import this one, but needs none of it
    from volviz.unstructured.topology import Topology

#: cells from which the face sides are computed on all cores (below, the threads' start-up and the shared cores'
#: scheduling cost more than the pass: a prange on the Blunt Fin's 187,318 cells had a 36 ms median, serial 7 ms)
PARALLEL_CELLS = 1_000_000
#: emitted-by-force marker of an in-degree (decrements keep it negative, so the cell is never pushed again)
FORCED = -(1 << 30)
#: bit of a cell's state byte: the cell has extra out-going relations (in the sorted ``ex_src``)
EXTRA = 16


@njit(cache=True, nogil=True, inline="always")
def _side(face_n: np.ndarray, face_d: np.ndarray, t: int, f: int, eye: np.ndarray, fwd: np.ndarray,
          parallel: bool) -> float:
    """> 0: the eye is outside face f of cell t (its neighbour there is in front of t); < 0: inside."""
    if parallel:
        return -(face_n[t, f, 0] * fwd[0] + face_n[t, f, 1] * fwd[1] + face_n[t, f, 2] * fwd[2])
    return face_n[t, f, 0] * eye[0] + face_n[t, f, 1] * eye[1] + face_n[t, f, 2] * eye[2] - face_d[t, f]


@njit(cache=True, nogil=True, inline="always")
def _cell_sides(t: int, neighbor: np.ndarray, back: np.ndarray, face_n: np.ndarray, face_d: np.ndarray,
                eye: np.ndarray, fwd: np.ndarray, parallel: bool, front: np.ndarray, indeg: np.ndarray) -> None:
    bits = 0
    behind = 0
    for f in range(4):
        u = neighbor[t, f]
        if u < 0:
            continue
        if u > t:
            side = _side(face_n, face_d, t, f, eye, fwd, parallel)
        else:                        # the lower-numbered cell's plane decides a shared face for both
            side = -_side(face_n, face_d, u, (back[t] >> (2 * f)) & 3, eye, fwd, parallel)
        if side > 0.0:
            bits |= 1 << f
        elif side < 0.0:
            behind += 1
    front[t] = bits
    indeg[t] = behind


#: a side taken from the float32 planes is trusted when it exceeds this times (|eye|_1 + |d|) (the planes' rounding,
#: 2^-24 relative, with a 4x margin for the float64 arithmetic); closer to 0 the float64 planes decide, so the
#: decisions are those of the float64 planes bit for bit
PLANE32_TOL = 2.0 ** -22


def planes32(topo: Topology) -> np.ndarray:
    """(m, 4, 4) float32 face planes (nx, ny, nz, d) of ``topo``'s cells (``Topology.planes32``, made once)."""
    return topo.planes32


@njit(cache=True, nogil=True)
def _sides_serial(neighbor: np.ndarray, back: np.ndarray, face_n: np.ndarray, face_d: np.ndarray,
                  planes: np.ndarray, eye: np.ndarray, fwd: np.ndarray, parallel: bool, front: np.ndarray,
                  indeg: np.ndarray) -> None:
    """One core: each shared face decided once, by its lower-numbered cell t (its plane read in order), and written
    to both cells (the neighbour's bit through ``back``); the neighbour's plane is never read, which a per-cell
    pass does for half the faces at scattered addresses. The side comes from the float32 ``planes`` (``planes32``)
    where it is clearly away from 0, else (or with ``planes`` empty) from the float64 ones."""
    m = len(neighbor)
    for t in range(m):
        front[t] = 0
        indeg[t] = 0
    if parallel:                         # the side of an orthographic view: n . (-fwd), no offset
        e0, e1, e2, dsc = -fwd[0], -fwd[1], -fwd[2], 0.0
    else:
        e0, e1, e2, dsc = eye[0], eye[1], eye[2], 1.0
    tol_e = PLANE32_TOL * (abs(e0) + abs(e1) + abs(e2))
    tol_d = PLANE32_TOL * dsc
    f32 = len(planes) == m
    for t in range(m):
        bits = 0
        behind = 0
        for f in range(4):
            u = neighbor[t, f]
            if u <= t:                   # the boundary (-1), or decided by the lower-numbered u
                continue
            side = 0.0
            if f32:
                d = np.float64(planes[t, f, 3])
                side = planes[t, f, 0] * e0 + planes[t, f, 1] * e1 + planes[t, f, 2] * e2 - dsc * d
                if abs(side) <= tol_e + tol_d * abs(d):
                    side = 0.0
            if side == 0.0:
                side = _side(face_n, face_d, t, f, eye, fwd, parallel)
            if side > 0.0:               # u in front of t
                bits |= 1 << f
                indeg[u] += 1
            elif side < 0.0:             # t in front of u: u's bit for the shared face
                behind += 1
                front[u] |= 1 << ((back[t] >> (2 * f)) & 3)
        front[t] |= bits
        indeg[t] += behind


@njit(cache=True, nogil=True, parallel=True)
def _sides_parallel(neighbor: np.ndarray, back: np.ndarray, face_n: np.ndarray, face_d: np.ndarray, eye: np.ndarray,
                    fwd: np.ndarray, parallel: bool, front: np.ndarray, indeg: np.ndarray) -> None:
    for t in prange(len(neighbor)):
        _cell_sides(t, neighbor, back, face_n, face_d, eye, fwd, parallel, front, indeg)


def face_sides(neighbor: np.ndarray, back: np.ndarray, face_n: np.ndarray, face_d: np.ndarray, eye: np.ndarray,
               fwd: np.ndarray, parallel: bool, cores: bool | None = None,
               out: tuple[np.ndarray, np.ndarray] | None = None, planes: np.ndarray | None = None
               ) -> tuple[np.ndarray, np.ndarray]:
    """Per cell: a byte whose bit f says the neighbour across face f is in front (drawn after it), and the number of
    neighbours behind it (its MPVO in-degree, int32). A face whose plane holds the eye gives no relation. A shared
    face is decided by the plane of its lower-numbered cell for both (``back``: ``Topology.back_face``), so both
    sides agree; every cell fills only its own entries.
    ``parallel``: orthographic view along ``fwd``; else the eye at ``eye``. ``cores``: split the pass over the cores
    (default: from ``PARALLEL_CELLS`` cells on). ``out``: (front, indeg) arrays of ``len(neighbor)`` to fill (a
    sort's reused work arrays) instead of new ones. ``planes``: the float32 planes of the serial pass
    (``planes32``; without them it reads the float64 planes only)."""
    m = len(neighbor)
    front, indeg = out if out is not None else (np.empty(m, np.uint8), np.empty(m, np.int32))
    if m >= PARALLEL_CELLS if cores is None else cores:
        _sides_parallel(neighbor, back, face_n, face_d, eye, fwd, parallel, front, indeg)
    else:
        if planes is None:
            planes = np.empty((0, 4, 4), np.float32)
        _sides_serial(neighbor, back, face_n, face_d, planes, eye, fwd, parallel, front, indeg)
    return front, indeg


@njit(cache=True, nogil=True)
def add_extra(ex_src: np.ndarray, ex_dst: np.ndarray, front: np.ndarray, indeg: np.ndarray) -> None:
    """Count the extra relations ``ex_src[k]`` before ``ex_dst[k]`` in the in-degrees and flag their sources."""
    for k in range(len(ex_dst)):
        indeg[ex_dst[k]] += 1
        front[ex_src[k]] |= EXTRA


@njit(cache=True, nogil=True)
def kahn(neighbor: np.ndarray, front: np.ndarray, indeg: np.ndarray, ex_src: np.ndarray, ex_dst: np.ndarray,
         order: np.ndarray, n_out: int, fallback: np.ndarray) -> tuple[int, int]:
    """``kahn_into`` with a stack of its own."""
    return kahn_into(neighbor, front, indeg, ex_src, ex_dst, order, n_out, fallback,
                     np.empty(len(neighbor), np.int32))


@njit(cache=True, nogil=True)
def kahn_into(neighbor: np.ndarray, front: np.ndarray, indeg: np.ndarray, ex_src: np.ndarray, ex_dst: np.ndarray,
              order: np.ndarray, n_out: int, fallback: np.ndarray, stack: np.ndarray) -> tuple[int, int]:
    """Kahn's algorithm from ``face_sides`` + ``add_extra`` (``ex_src`` sorted), depth first (a stack: the cells
    just freed are near the last one, in space and mostly in memory). Fills ``order[n_out:]`` back to front and
    returns (cells in order, cycle breaks). A stall (a cycle) with an empty ``fallback`` returns (n, -1) with the
    state intact: call again with ``n_out = n`` and a fallback order (farthest first); a stalled run then emits the
    first cell of it not yet emitted (an emitted cell has in-degree <= 0) and carries on. ``stack``: int32 work
    array of ``len(neighbor)`` (a sort's, reused between frames)."""
    m = len(neighbor)
    top = 0
    if n_out == 0:
        for t in range(m):
            if indeg[t] == 0:
                stack[top] = t
                top += 1
    cycles = 0
    fb = 0
    n_ex = len(ex_src)
    while True:
        while top > 0:
            top -= 1
            t = np.uint32(stack[top])          # unsigned: no negative-index wrap-around in the hot loop
            order[n_out] = t
            n_out += 1
            bits = front[t]
            for f in range(4):
                if bits & (1 << f):
                    u = np.uint32(neighbor[t, f])
                    v = indeg[u] - 1
                    indeg[u] = v
                    if v == 0:
                        stack[top] = u
                        top += 1
            if bits & EXTRA:
                k = np.searchsorted(ex_src, t)
                while k < n_ex and ex_src[k] == t:
                    u = np.uint32(ex_dst[k])
                    v = indeg[u] - 1
                    indeg[u] = v
                    if v == 0:
                        stack[top] = u
                        top += 1
                    k += 1
        if n_out == m:
            break
        if len(fallback) == 0:
            return n_out, -1
        while indeg[fallback[fb]] <= 0:
            fb += 1
        stack[0] = fallback[fb]
        indeg[fallback[fb]] = FORCED
        top = 1
        cycles += 1
    return n_out, cycles
