"""Numba kernels of the terrain C-LOD (Roettger §3.5.3 / [89], digest §2.4). See ``volviz.nature.terrain``.

Quadtree matrix convention: a node of edge length ``d`` (grid units, a power of two) has its centre at a grid point
whose indices are odd multiples of ``d / 2``; every grid point is the centre of at most one node, so per-node values
live in (N, N) matrices at the node centres (Roettger's "quadtree matrix").
"""
from __future__ import annotations

import numpy as np
from numba import njit, prange

from volviz.nature._frustum_kernels import box_outside


@njit(cache=True, nogil=True)
def local_d2(g: np.ndarray, n: int, unit: float, out: np.ndarray, weight: float) -> None:
    """out[centre] = max(out, weight * d2) with d2 = max_i |dh_i| / d over the 4 edge midpoints and 2 diagonals."""
    d = n - 1
    while d >= 2:
        h = d // 2
        for ci in range(h, n - 1, d):
            for cj in range(h, n - 1, d):
                a = g[ci - h, cj - h]
                b = g[ci + h, cj - h]
                c = g[ci + h, cj + h]
                e = g[ci - h, cj + h]
                m = abs(g[ci, cj - h] - 0.5 * (a + b))
                m = max(m, abs(g[ci + h, cj] - 0.5 * (b + c)))
                m = max(m, abs(g[ci, cj + h] - 0.5 * (c + e)))
                m = max(m, abs(g[ci - h, cj] - 0.5 * (e + a)))
                m = max(m, abs(g[ci, cj] - 0.5 * (a + c)))
                m = max(m, abs(g[ci, cj] - 0.5 * (b + e)))
                v = weight * m / (d * unit)
                if v > out[ci, cj]:
                    out[ci, cj] = v
        d //= 2


@njit(cache=True, nogil=True)
def propagate_d2(d2: np.ndarray, n: int, k: float) -> None:
    """Bottom-up: d2(node) := max(d2_local(node), K * d2(child)) for the 4 children (digest §2.4)."""
    d = 4
    while d <= n - 1:
        h = d // 2
        q = h // 2
        for ci in range(h, n - 1, d):
            for cj in range(h, n - 1, d):
                m = d2[ci, cj]
                for si in (-1, 1):
                    for sj in (-1, 1):
                        v = k * d2[ci + si * q, cj + sj * q]
                        if v > m:
                            m = v
                d2[ci, cj] = m
        d *= 2


@njit(cache=True, nogil=True)
def refine(d2: np.ndarray, height: np.ndarray, n: int, sx: float, sy: float, x0: float, y0: float,
           eye: np.ndarray, big_c: float, small_c: float, geomorph: bool,
           state: np.ndarray, weight: np.ndarray, nodes: np.ndarray, sizes: np.ndarray) -> tuple[int, int]:
    """Top-down, level by level: f = l / (d C max(c d2, 1)), refine if f < 1 (Eq. 3.2), l the L1 eye distance.

    ``state`` gets 1 for every visited node and 2 for refined ones; ``weight`` the effective morph factor
    w = min(clamp(1/f - 1, 0, 1), w(parent), w(constraining neighbours)). A node refines only if the two nodes of
    its parent's size across its outer edges are refined (or outside the grid): the conformity guard that keeps
    neighbouring leaves within one level (it rarely binds thanks to the K propagation; the count is returned).
    Returns (number of visited nodes, number of refinements blocked by the guard).
    """
    m = (n - 1) // 2
    nodes[0, 0] = m
    nodes[0, 1] = m
    sizes[0] = n - 1
    state[m, m] = 1
    start = 0
    end = 1
    d = n - 1
    unit = max(sx, sy)
    blocked = 0
    while True:
        h = d // 2
        nxt = end
        for k in range(start, end):
            ci = nodes[k, 0]
            cj = nodes[k, 1]
            l = abs(eye[0] - (x0 + ci * sx)) + abs(eye[1] - (y0 + cj * sy)) + abs(eye[2] - height[ci, cj])
            denom = d * unit * big_c * max(small_c * d2[ci, cj], 1.0)
            f = l / denom
            if d <= 2 or f >= 1.0:
                continue
            if not geomorph or f <= 0.5:
                w = 1.0
            else:
                w = 1.0 / f - 1.0
            ok = True
            if d < n - 1:
                pi = ci - h if (ci - h) % (2 * d) == d else ci + h
                pj = cj - h if (cj - h) % (2 * d) == d else cj + h
                w = min(w, weight[pi, pj])
                ax = pi + (2 * d if ci > pi else -2 * d)
                if 0 <= ax <= n - 1:
                    if state[ax, pj] != 2:
                        ok = False
                    else:
                        w = min(w, weight[ax, pj])
                ay = pj + (2 * d if cj > pj else -2 * d)
                if 0 <= ay <= n - 1:
                    if state[pi, ay] != 2:
                        ok = False
                    else:
                        w = min(w, weight[pi, ay])
            if not ok:
                blocked += 1
                continue
            state[ci, cj] = 2
            weight[ci, cj] = w
            q = h // 2
            for si in (-1, 1):
                for sj in (-1, 1):
                    nodes[nxt, 0] = ci + si * q
                    nodes[nxt, 1] = cj + sj * q
                    sizes[nxt] = h
                    state[ci + si * q, cj + sj * q] = 1
                    nxt += 1
        if nxt == end:
            break
        start = end
        end = nxt
        d = h
    return end, blocked


@njit(cache=True, nogil=True, inline="always")
def _blend(fields: np.ndarray, out: np.ndarray, vi: int, vj: int, ai: int, aj: int, bi: int, bj: int, w: float) -> None:
    for f in range(fields.shape[2]):
        out[vi, vj, f] = (1.0 - w) * 0.5 * (out[ai, aj, f] + out[bi, bj, f]) + w * fields[vi, vj, f]


@njit(cache=True, nogil=True, parallel=True)
def morph(fields: np.ndarray, n: int, state: np.ndarray, weight: np.ndarray, nodes: np.ndarray, sizes: np.ndarray,
          count: int, out: np.ndarray, sx: float, sy: float, x0: float, y0: float, planes: np.ndarray,
          z_range: np.ndarray) -> None:
    """Geomorphing of the (n, n, F) ``fields`` (a point's F values side by side) into ``out``: every vertex a
    refinement introduces is the midpoint of an edge (a, b) of the coarser fan and gets ``(1 - w) (out[a] + out[b])
    / 2 + w * true`` with w the refining node's factor (edge points shared with the neighbour use the minimum of both
    factors). Coarse to fine, so ``out[a]``, ``out[b]`` are already morphed: level by level (``nodes`` lists them
    coarse to fine), the nodes of a level in parallel; a node reads only vertices of coarser levels, and two
    neighbours that both write their shared edge's points write the same values.
    Nodes whose column (their square, heights over ``z_range`` = every field's (min, max), which bounds every morphed
    value) misses the frustum ``planes`` are left out (none: every node): every vertex of a fan ``emit_fans`` keeps is
    introduced by an ancestor of its leaf, whose column contains the leaf's box."""
    m = (n - 1) // 2
    last = n - 1
    for (i, j) in ((0, 0), (last, 0), (0, last), (last, last), (m, m), (m, 0), (last, m), (m, last), (0, m)):
        for f in range(fields.shape[2]):
            out[i, j, f] = fields[i, j, f]
    start = 0
    while start < count:
        stop = start
        while stop < count and sizes[stop] == sizes[start]:
            stop += 1
        for k in prange(start, stop):
            ci, cj, h = nodes[k, 0], nodes[k, 1], sizes[k] // 2
            if planes.shape[0] > 0 and box_outside(planes, x0 + (ci - h) * sx, y0 + (cj - h) * sy, z_range[0],
                                                   x0 + (ci + h) * sx, y0 + (cj + h) * sy, z_range[1]):
                continue
            _morph_node(fields, last, state, weight, ci, cj, sizes[k], out)
        start = stop


@njit(cache=True, nogil=True, inline="always")
def _morph_node(fields: np.ndarray, last: int, state: np.ndarray, weight: np.ndarray, ci: int, cj: int, d: int,
                out: np.ndarray) -> None:
    """``morph`` of the vertices node (ci, cj) of size ``d`` introduces, if it is refined."""
    if state[ci, cj] != 2:
        return
    h = d // 2
    q = h // 2
    w = weight[ci, cj]
    for si in (-1, 1):
        for sj in (-1, 1):  # children centres on the centre-corner diagonals
            _blend(fields, out, ci + si * q, cj + sj * q, ci, cj, ci + si * h, cj + sj * h, w)
    for s in (-1, 1):  # inner child-edge midpoints on the centre-to-edge-midpoint spokes
        _blend(fields, out, ci + s * q, cj, ci, cj, ci + s * h, cj, w)
        _blend(fields, out, ci, cj + s * q, ci, cj, ci, cj + s * h, w)
    for s in (-1, 1):  # outer child-edge midpoints on this node's border, shared with the neighbour
        ni = ci + s * d
        wn = w if (ni < 0 or ni > last) else min(w, weight[ni, cj])
        for t in (-1, 1):
            _blend(fields, out, ci + s * h, cj + t * q, ci + s * h, cj, ci + s * h, cj + t * h, wn)
        nj = cj + s * d
        wn = w if (nj < 0 or nj > last) else min(w, weight[ci, nj])
        for t in (-1, 1):
            _blend(fields, out, ci + t * q, cj + s * h, ci, cj + s * h, ci + t * h, cj + s * h, wn)


@njit(cache=True, nogil=True, inline="always")
def _ring(ci: int, cj: int, d: int, last: int, state: np.ndarray, ring_i: np.ndarray, ring_j: np.ndarray) -> int:
    """The fan ring of leaf (ci, cj) of size ``d``, counter-clockwise seen from above (x east, y north): its corners
    and the edge midpoints whose same-size neighbour exists (or that lie on the grid's border), the T-vertex rule of
    §3.5.3. Returns the ring's length (4 to 8)."""
    h = d // 2
    r = 0
    ring_i[r] = ci - h
    ring_j[r] = cj - h
    r += 1
    if cj - d < 0 or state[ci, cj - d] != 0:
        ring_i[r] = ci
        ring_j[r] = cj - h
        r += 1
    ring_i[r] = ci + h
    ring_j[r] = cj - h
    r += 1
    if ci + d > last or state[ci + d, cj] != 0:
        ring_i[r] = ci + h
        ring_j[r] = cj
        r += 1
    ring_i[r] = ci + h
    ring_j[r] = cj + h
    r += 1
    if cj + d > last or state[ci, cj + d] != 0:
        ring_i[r] = ci
        ring_j[r] = cj + h
        r += 1
    ring_i[r] = ci - h
    ring_j[r] = cj + h
    r += 1
    if ci - d < 0 or state[ci - d, cj] != 0:
        ring_i[r] = ci - h
        ring_j[r] = cj
        r += 1
    return r


@njit(cache=True, nogil=True, inline="always")
def _fan_outside(ci: int, cj: int, h: int, r: int, ring_i: np.ndarray, ring_j: np.ndarray, morphed: np.ndarray,
                 planes: np.ndarray, sx: float, sy: float, x0: float, y0: float) -> bool:
    """Whether the fan's box (its square, heights over its own morphed vertices in every field) misses the
    frustum ``planes``."""
    zl = np.inf
    zh = -np.inf
    for f in range(morphed.shape[2]):
        zl = min(zl, morphed[ci, cj, f])
        zh = max(zh, morphed[ci, cj, f])
        for a in range(r):
            v = morphed[ring_i[a], ring_j[a], f]
            zl = min(zl, v)
            zh = max(zh, v)
    return box_outside(planes, x0 + (ci - h) * sx, y0 + (cj - h) * sy, zl, x0 + (ci + h) * sx, y0 + (cj + h) * sy, zh)


#: chunks of the node list that ``emit_fans`` deals out to its threads
FAN_CHUNKS = 64


@njit(cache=True, nogil=True, parallel=True)
def emit_fans(n: int, sx: float, sy: float, x0: float, y0: float, state: np.ndarray, nodes: np.ndarray,
              sizes: np.ndarray, count: int, morphed: np.ndarray, planes: np.ndarray,
              vmap: np.ndarray, stamp: int, verts: np.ndarray, vals: np.ndarray, tris: np.ndarray) -> tuple[int, int]:
    """Triangle fans around the centre of every leaf (``_ring``: the T-vertex rule of §3.5.3). Leaves whose box
    misses the frustum ``planes`` are skipped (emission only); the box's height range is that of the fan's own morphed
    vertices over every field (``morphed`` (n, n, F)), which bounds its planar triangles exactly. (The unmorphed height
    range of the node does not: a morphed vertex averages ancestors' vertices outside the node, so visible fans near
    the image border were culled — holes that appeared and vanished from frame to frame.)
    In parallel, in three passes: the kept fans are found and their vertices marked per chunk of the node list
    (``vmap`` (n, n, 2): the stamp of the frame that marked a grid point, and its number), the marked points numbered
    in row-major order (``verts`` gets their grid indices, ``vals`` their F morphed values), the fans' triangles
    written at their chunk's offset in node order; the result does not depend on the number of threads. Returns
    (n_vertices, n_triangles)."""
    last = n - 1
    kept = np.zeros(count, dtype=np.bool_)
    chunk_tris = np.zeros(FAN_CHUNKS + 1, dtype=np.int64)
    marked_row = np.zeros(n, dtype=np.bool_)
    for chunk in prange(FAN_CHUNKS):
        ring_i = np.empty(8, dtype=np.int64)
        ring_j = np.empty(8, dtype=np.int64)
        t = 0
        for k in range(chunk * count // FAN_CHUNKS, (chunk + 1) * count // FAN_CHUNKS):
            ci = nodes[k, 0]
            cj = nodes[k, 1]
            if state[ci, cj] != 1:
                continue
            h = sizes[k] // 2
            r = _ring(ci, cj, sizes[k], last, state, ring_i, ring_j)
            if planes.shape[0] > 0 and _fan_outside(ci, cj, h, r, ring_i, ring_j, morphed, planes, sx, sy, x0, y0):
                continue
            kept[k] = True
            t += r
            # every thread that marks a point writes the same stamp
            vmap[ci, cj, 0] = stamp
            marked_row[ci] = True
            for a in range(r):
                vmap[ring_i[a], ring_j[a], 0] = stamp
                marked_row[ring_i[a]] = True
        chunk_tris[chunk + 1] = t
    for chunk in range(FAN_CHUNKS):
        chunk_tris[chunk + 1] += chunk_tris[chunk]
    row_start = np.zeros(n + 1, dtype=np.int64)
    for i in prange(n):
        if marked_row[i]:
            c = 0
            for j in range(n):
                if vmap[i, j, 0] == stamp:
                    c += 1
            row_start[i + 1] = c
    for i in range(n):
        row_start[i + 1] += row_start[i]
    for i in prange(n):
        if marked_row[i]:
            v = row_start[i]
            for j in range(n):
                if vmap[i, j, 0] == stamp:
                    vmap[i, j, 1] = v
                    verts[v, 0] = i
                    verts[v, 1] = j
                    for f in range(morphed.shape[2]):
                        vals[v, f] = morphed[i, j, f]
                    v += 1
    for chunk in prange(FAN_CHUNKS):
        ring_i = np.empty(8, dtype=np.int64)
        ring_j = np.empty(8, dtype=np.int64)
        t = chunk_tris[chunk]
        for k in range(chunk * count // FAN_CHUNKS, (chunk + 1) * count // FAN_CHUNKS):
            if not kept[k]:
                continue
            ci = nodes[k, 0]
            cj = nodes[k, 1]
            r = _ring(ci, cj, sizes[k], last, state, ring_i, ring_j)
            c_id = vmap[ci, cj, 1]
            for a in range(r):
                b = (a + 1) % r
                tris[t, 0] = c_id
                tris[t, 1] = vmap[ring_i[a], ring_j[a], 1]
                tris[t, 2] = vmap[ring_i[b], ring_j[b], 1]
                t += 1
    return row_start[n], chunk_tris[FAN_CHUNKS]


@njit(cache=True, nogil=True, parallel=True)
def mesh_arrays(verts: np.ndarray, vals: np.ndarray, x0: float, y0: float, sx: float, sy: float, n: int
                ) -> tuple[np.ndarray, np.ndarray]:
    """The emitted vertices' positions (x0 + i sx, y0 + j sy, morphed height) and texture coordinates
    (i / (n - 1), j / (n - 1)), from their grid indices ``verts`` (nv, 2) and morphed fields ``vals`` (nv, F; the
    height first), in one parallel pass."""
    nv = verts.shape[0]
    pts = np.empty((nv, 3))
    tc = np.empty((nv, 2))
    last = float(n - 1)
    for v in prange(nv):
        i, j = verts[v, 0], verts[v, 1]
        pts[v, 0] = x0 + i * sx
        pts[v, 1] = y0 + j * sy
        pts[v, 2] = vals[v, 0]
        tc[v, 0] = i / last
        tc[v, 1] = j / last
    return pts, tc
