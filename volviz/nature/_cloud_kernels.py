"""Numba kernels of the volumetric C-LOD (Roettger Ch. 11, digest §9). See ``volviz.nature.clouds``.

Node addressing: level ``lv`` (0 = root, size R; size = R >> lv grid cells), integer node coordinates (a, b, c) in
units of the node size, per-level dense arrays flattened at ``off[lv] + (a * nb + b) * nc + c`` with
``(na, nb, nc) = roots << lv``. Levels 0 .. L-1 (sizes R .. 2) are stored; size-1 cells never refine.

5-tetrahedra split with global parity: a node's central tetrahedron uses the corners whose local index sum has the
parity ``p = (a + b + c) % 2`` (the corners of global-even parity at the node's level), so neighbouring nodes of the
same level agree on every shared face diagonal, and a finer level's face triangulation refines the coarser one.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from volviz.nature._frustum_kernels import box_outside
from volviz.nature.raster import CUBE_EDGES, clipped_screen_box, dealt_band, dealt_count


@njit(cache=True, nogil=True, inline="always")
def _corner(i: int, j: int, k: int) -> int:
    return (i << 2) | (j << 1) | k


@njit(cache=True, nogil=True, inline="always")
def coarse_value(cv: np.ndarray, ii: int, jj: int, kk: int, p: int) -> float:
    """Value at lattice point (ii, jj, kk) in {0, 1, 2}^3 of the node's own linear 5-tet interpolation of its
    corner values cv[8] (index i<<2 | j<<1 | k): edge midpoint = mean of the edge's ends, face centre = mean of the
    face diagonal of parity p, centroid = mean of the central tetrahedron (the 4 corners of parity p)."""
    odd = (ii & 1) + (jj & 1) + (kk & 1)
    if odd == 0:
        return cv[_corner(ii >> 1, jj >> 1, kk >> 1)]
    if odd == 1:
        if ii == 1:
            return 0.5 * (cv[_corner(0, jj >> 1, kk >> 1)] + cv[_corner(1, jj >> 1, kk >> 1)])
        if jj == 1:
            return 0.5 * (cv[_corner(ii >> 1, 0, kk >> 1)] + cv[_corner(ii >> 1, 1, kk >> 1)])
        return 0.5 * (cv[_corner(ii >> 1, jj >> 1, 0)] + cv[_corner(ii >> 1, jj >> 1, 1)])
    acc = 0.0
    cnt = 0
    for c in range(8):
        i, j, k = c >> 2, (c >> 1) & 1, c & 1
        if (i + j + k) % 2 != p:
            continue
        if odd == 2:  # face centre: the two corners of parity p on that face
            if ii != 1 and i != (ii >> 1):
                continue
            if jj != 1 and j != (jj >> 1):
                continue
            if kk != 1 and k != (kk >> 1):
                continue
        acc += cv[c]
        cnt += 1
    return acc / cnt


@njit(cache=True, nogil=True, inline="always")
def _node_corners(v, x0, y0, z0, s, out):
    """The values of ``v`` at the 8 corners (index i<<2 | j<<1 | k) of the node of edge ``s`` at grid point
    (x0, y0, z0)."""
    for q in range(8):
        out[q] = v[x0 + (q >> 2) * s, y0 + ((q >> 1) & 1) * s, z0 + (q & 1) * s]


@njit(cache=True, nogil=True)
def node_stats(f, g, g_weight, root, levels, roots, off, delta_local):
    """Per stored node the local deviation Δ = max over the 19 non-corner lattice points of max(|f − coarse|,
    g_weight |g − coarse|) (the maximum variant of §11.4)."""
    cf = np.empty(8)
    cg = np.empty(8)
    for lv in range(levels - 1, -1, -1):
        s = root >> lv
        h = s // 2
        na, nb, nc = roots[0] << lv, roots[1] << lv, roots[2] << lv
        for a in range(na):
            for b in range(nb):
                for c in range(nc):
                    x0, y0, z0 = a * s, b * s, c * s
                    p = (a + b + c) % 2
                    _node_corners(f, x0, y0, z0, s, cf)
                    _node_corners(g, x0, y0, z0, s, cg)
                    dev = 0.0
                    for ii in range(3):
                        for jj in range(3):
                            for kk in range(3):
                                if (ii & 1) + (jj & 1) + (kk & 1) == 0:
                                    continue
                                v = f[x0 + ii * h, y0 + jj * h, z0 + kk * h]
                                w = g[x0 + ii * h, y0 + jj * h, z0 + kk * h]
                                dev = max(dev, abs(v - coarse_value(cf, ii, jj, kk, p)))
                                dev = max(dev, g_weight * abs(w - coarse_value(cg, ii, jj, kk, p)))
                    delta_local[(off[lv] + (a * nb + b) * nc + c)] = dev


@njit(cache=True, nogil=True)
def box_max(v, root, levels, roots, off, out):
    """Per stored node the maximum of ``v`` over the grid points of its closed box (bottom-up: the 27 points of a
    2-cell node, then the maximum of the 8 children)."""
    for lv in range(levels - 1, -1, -1):
        s = root >> lv
        h = s // 2
        na, nb, nc = roots[0] << lv, roots[1] << lv, roots[2] << lv
        cb, cc = nb << 1, nc << 1
        for a in range(na):
            for b in range(nb):
                for c in range(nc):
                    m = -np.inf
                    if h == 1:
                        for q in range(27):
                            m = max(m, v[a * s + q // 9, b * s + (q // 3) % 3, c * s + q % 3])
                    else:
                        for q in range(8):
                            ch = off[lv + 1] + ((2 * a + (q >> 2)) * cb + 2 * b + ((q >> 1) & 1)) * cc + 2 * c + (q & 1)
                            m = max(m, out[ch])
                    out[off[lv] + (a * nb + b) * nc + c] = m


@njit(cache=True, nogil=True)
def morph_bound(f, root, levels, roots, hi):
    """Per grid point the largest value the morph can give it for any weights (``hi``, f's shape): the corrected
    Eq. (11.8) S' = (1 − w) coarse + w S is at most max(coarse, S), and the coarse value (``coarse_value``, a mean of
    the introducing node's corners) at most the same mean of the corners' bounds; top-down, the root lattice keeps
    f. A leaf is drawn from its morphed corners, which may exceed the data in its box (a T-vertex takes its coarser
    neighbour's value), so the zero-opacity test of a node must bound these, not the data (``emit``)."""
    hi[...] = f
    cv = np.empty(8)
    for lv in range(levels):
        s = root >> lv
        h = s // 2
        nb, nc = roots[1] << lv, roots[2] << lv
        for t in range((roots[0] << lv) * nb * nc):     # the level's nodes; no dependence within a level
            a, b, c = t // (nb * nc), (t // nc) % nb, t % nc
            _node_corners(hi, a * s, b * s, c * s, s, cv)
            for q in range(27):
                ii, jj, kk = q // 9, (q // 3) % 3, q % 3
                if (ii & 1) + (jj & 1) + (kk & 1) == 0:
                    continue
                xi, yi, zi = a * s + ii * h, b * s + jj * h, c * s + kk * h
                hi[xi, yi, zi] = max(f[xi, yi, zi], coarse_value(cv, ii, jj, kk, (a + b + c) % 2))


@njit(cache=True, nogil=True)
def propagate(delta, levels, roots, off, kmax):
    """Eq. (11.5), bottom-up one level at a time: Δ := max(Δ, K_max Δ_child) over the 8 children."""
    for lv in range(levels - 2, -1, -1):
        na, nb, nc = roots[0] << lv, roots[1] << lv, roots[2] << lv
        cb, cc = nb << 1, nc << 1
        for a in range(na):
            for b in range(nb):
                for c in range(nc):
                    idx = off[lv] + (a * nb + b) * nc + c
                    m = delta[idx]
                    for q in range(8):
                        ch = off[lv + 1] + ((2 * a + (q >> 2)) * cb + 2 * b + ((q >> 1) & 1)) * cc + 2 * c + (q & 1)
                        m = max(m, kmax * delta[ch])
                    delta[idx] = m


@njit(cache=True, nogil=True)
def decide(delta, fmax, cutoff, root, levels, roots, off, origin, spacing, eye, big_c, small_c, geomorph,
           state, eprime, nodes):
    """Top-down, level by level: e = s C max(c Δ, 1) / d (Eq. 11.1), refine if e > 1; e' = clamp(e − 1, 0, 1)
    (Eq. 11.6) capped by the parent's. Nodes with fmax <= cutoff are transparent (ZOT) and never refined.
    Returns the number of nodes written to ``nodes`` (lv, a, b, c), or -1 if the buffer is too small."""
    n = 0
    for a in range(roots[0]):
        for b in range(roots[1]):
            for c in range(roots[2]):
                nodes[n, 0], nodes[n, 1], nodes[n, 2], nodes[n, 3] = 0, a, b, c
                n += 1
    start = 0
    cap = nodes.shape[0]
    for lv in range(levels):
        end = n
        s = root >> lv
        nb, nc = roots[1] << lv, roots[2] << lv
        ex, ey, ez = spacing[0] * s, spacing[1] * s, spacing[2] * s
        edge = max(ex, max(ey, ez))
        for t in range(start, end):
            a, b, c = nodes[t, 1], nodes[t, 2], nodes[t, 3]
            idx = off[lv] + (a * nb + b) * nc + c
            state[idx] = 1
            if fmax[idx] <= cutoff:
                continue
            dx = origin[0] + (a + 0.5) * ex - eye[0]
            dy = origin[1] + (b + 0.5) * ey - eye[1]
            dz = origin[2] + (c + 0.5) * ez - eye[2]
            d = math.sqrt(dx * dx + dy * dy + dz * dz)
            num = edge * big_c * max(small_c * delta[idx], 1.0)
            if d >= num:  # e <= 1
                continue
            e = num / d if d > 0 else 1e30
            w = 1.0 if not geomorph else min(max(e - 1.0, 0.0), 1.0)
            if lv > 0:
                pidx = off[lv - 1] + ((a >> 1) * (nb >> 1) + (b >> 1)) * (nc >> 1) + (c >> 1)
                w = min(w, eprime[pidx])
            state[idx] = 2
            eprime[idx] = w
            if n + 8 > cap:
                return -1
            for q in range(8):
                nodes[n, 0] = lv + 1
                nodes[n, 1] = 2 * a + (q >> 2)
                nodes[n, 2] = 2 * b + ((q >> 1) & 1)
                nodes[n, 3] = 2 * c + (q & 1)
                n += 1
        start = end
        if start == n:
            break
    return n


@njit(cache=True, nogil=True, inline="always")
def _ep(state, eprime, off, lv, na, nb, nc, a, b, c, inside_default):
    """e' of node (lv, a, b, c): 0 if not refined; ``inside_default`` outside the volume."""
    if a < 0 or b < 0 or c < 0 or a >= na or b >= nb or c >= nc:
        return inside_default
    idx = off[lv] + (a * nb + b) * nc + c
    return eprime[idx] if state[idx] == 2 else 0.0


@njit(cache=True, nogil=True)
def morph(f, g, root, roots, off, state, eprime, nodes, count, vf, vg, origin, spacing, planes):
    """Volumetric morphing (§11.4) with the corrected Eq. (11.8): S' = (1 − w) coarse + w S, w = the minimum e' of
    all same-level nodes sharing the vertex (unrefined = 0). Coarse values come from the refining node's own 5-tet
    interpolation of its (already morphed) corners; coarse to fine. Nodes whose box misses the frustum ``planes``
    (``emit``'s test; none: every node) are left out: every corner of a leaf ``emit`` lists is a point its parent
    introduces, and the boxes of a listed leaf's ancestors contain its box, so they pass the test too."""
    nx, ny, nz = f.shape
    for a in range(0, nx, root):
        for b in range(0, ny, root):
            for c in range(0, nz, root):
                vf[a, b, c] = f[a, b, c]
                vg[a, b, c] = g[a, b, c]
    cf = np.empty(8)
    cg = np.empty(8)
    for t in range(count):
        lv, a, b, c = nodes[t, 0], nodes[t, 1], nodes[t, 2], nodes[t, 3]
        if lv >= off.shape[0] - 1:
            continue
        na, nb, nc = roots[0] << lv, roots[1] << lv, roots[2] << lv
        idx = off[lv] + (a * nb + b) * nc + c
        if state[idx] != 2:
            continue
        s = root >> lv
        if planes.shape[0] > 0:
            ex, ey, ez = spacing[0] * s, spacing[1] * s, spacing[2] * s
            bx0, by0, bz0 = origin[0] + a * ex, origin[1] + b * ey, origin[2] + c * ez
            if box_outside(planes, bx0, by0, bz0, bx0 + ex, by0 + ey, bz0 + ez):
                continue
        w0 = eprime[idx]
        h = s // 2
        x0, y0, z0 = a * s, b * s, c * s
        p = (a + b + c) % 2
        for q in range(8):
            i, j, k = q >> 2, (q >> 1) & 1, q & 1
            cf[q] = vf[x0 + i * s, y0 + j * s, z0 + k * s]
            cg[q] = vg[x0 + i * s, y0 + j * s, z0 + k * s]
        for ii in range(3):
            for jj in range(3):
                for kk in range(3):
                    odd = (ii & 1) + (jj & 1) + (kk & 1)
                    if odd == 0:
                        continue
                    w = w0
                    # the other same-level nodes sharing this point (face: 1, edge: 3)
                    da = 0 if ii == 1 else (1 if ii == 2 else -1)
                    db = 0 if jj == 1 else (1 if jj == 2 else -1)
                    dc = 0 if kk == 1 else (1 if kk == 2 else -1)
                    for sa in range(2):
                        if sa == 1 and da == 0:
                            continue
                        for sb in range(2):
                            if sb == 1 and db == 0:
                                continue
                            for sc in range(2):
                                if sc == 1 and dc == 0:
                                    continue
                                if sa + sb + sc == 0:
                                    continue
                                w = min(w, _ep(state, eprime, off, lv, na, nb, nc, a + sa * da, b + sb * db,
                                               c + sc * dc, w0))
                    xi, yi, zi = x0 + ii * h, y0 + jj * h, z0 + kk * h
                    vf[xi, yi, zi] = (1.0 - w) * coarse_value(cf, ii, jj, kk, p) + w * f[xi, yi, zi]
                    vg[xi, yi, zi] = (1.0 - w) * coarse_value(cg, ii, jj, kk, p) + w * g[xi, yi, zi]


@njit(cache=True, nogil=True)
def emit(bound, cutoff, root, levels, roots, off, origin, spacing, eye, planes, state, root_order, vf, full,
         out, stack, corner_test=True):
    """Back-to-front octree traversal (§11.5): roots in a BSP order of the root grid, children far-to-near at every
    level; per node frustum culling and the zero-opacity test (§11.5, on the values drawn: ``bound`` <= cutoff, the
    node's maximum of ``morph_bound``, so that no leaf whose morphed corners exceed the cutoff is dropped; for
    leaves with ``corner_test`` also the max of the morphed corner densities in ``vf``; without it the leaves whose
    morphed corners are all transparent are listed too, for a caller that morphs them itself). Leaves go to ``out``
    (lv, a, b, c) in visibility order. ``full`` refines every node (the full-resolution reference). Returns the
    number of leaves, or -1 if ``out`` is too small."""
    n = 0
    cap = out.shape[0]
    for r in range(root_order.shape[0]):
        top = 0
        stack[0, 0], stack[0, 1], stack[0, 2], stack[0, 3] = 0, root_order[r, 0], root_order[r, 1], root_order[r, 2]
        top = 1
        while top > 0:
            top -= 1
            lv, a, b, c = stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3]
            s = root >> lv
            ex, ey, ez = spacing[0] * s, spacing[1] * s, spacing[2] * s
            bx0, by0, bz0 = origin[0] + a * ex, origin[1] + b * ey, origin[2] + c * ez
            if planes.shape[0] > 0 and box_outside(planes, bx0, by0, bz0, bx0 + ex, by0 + ey, bz0 + ez):
                continue
            refined = False
            if lv < levels:
                nb, nc = roots[1] << lv, roots[2] << lv
                idx = off[lv] + (a * nb + b) * nc + c
                if bound[idx] <= cutoff:
                    continue
                refined = full or state[idx] == 2
            if refined:
                # far-to-near order: bit set = the child half away from the eye on that axis
                fx = 1 if eye[0] < bx0 + 0.5 * ex else 0
                fy = 1 if eye[1] < by0 + 0.5 * ey else 0
                fz = 1 if eye[2] < bz0 + 0.5 * ez else 0
                far = (fx << 2) | (fy << 1) | fz
                for i in range(7, -1, -1):  # push nearest first so that the farthest pops first
                    q = far ^ i
                    stack[top, 0] = lv + 1
                    stack[top, 1] = 2 * a + (q >> 2)
                    stack[top, 2] = 2 * b + ((q >> 1) & 1)
                    stack[top, 3] = 2 * c + (q & 1)
                    top += 1
                continue
            if corner_test:
                m = -np.inf
                x0, y0, z0 = a * s, b * s, c * s
                for q in range(8):
                    m = max(m, vf[x0 + (q >> 2) * s, y0 + ((q >> 1) & 1) * s, z0 + (q & 1) * s])
                if m <= cutoff:
                    continue
            if n >= cap:
                return -1
            out[n, 0], out[n, 1], out[n, 2], out[n, 3] = lv, a, b, c
            n += 1
    return n


# ----------------------------------------------------------------------------------------------- rendering
@njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _coord(x, lo, step, n):
    f = (x - lo) / step
    if f <= 0.0:
        return 0, 0.0
    if f >= n - 1:
        return n - 2, 1.0
    i0 = int(f)
    return i0, f - i0


@njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _lookup(table, s_lo, ds, dl, sf, sb, l, out):
    """Trilinear sample of the 3D pre-integration table (n, n, L, 4) at (sf, sb, l) (l clamps to the last slice)."""
    n = table.shape[0]
    nl = table.shape[2]
    i, wi = _coord(sf, s_lo, ds, n)
    j, wj = _coord(sb, s_lo, ds, n)
    k, wk = _coord(l, 0.0, dl, nl)
    for ch in range(4):
        a = (1 - wk) * table[i, j, k, ch] + wk * table[i, j, k + 1, ch]
        b = (1 - wk) * table[i, j + 1, k, ch] + wk * table[i, j + 1, k + 1, ch]
        c = (1 - wk) * table[i + 1, j, k, ch] + wk * table[i + 1, j, k + 1, ch]
        d = (1 - wk) * table[i + 1, j + 1, k, ch] + wk * table[i + 1, j + 1, k + 1, ch]
        out[ch] = (1 - wi) * ((1 - wj) * a + wj * b) + wi * ((1 - wj) * c + wj * d)


@njit(cache=True, nogil=True)
def _eval(cv, region, u0, u1, u2):
    """The 5-tet piecewise-linear interpolant (even parity: central tet on corners 000, 110, 101, 011) in region
    ``region`` (0..3: corner tet of the odd corner 100, 010, 001, 111; 4: central) at local point (u0, u1, u2)."""
    if region == 4:
        s0, s110, s101, s011 = cv[0], cv[6], cv[5], cv[3]
        be = 0.5 * (s110 + s101 - s011 - s0)
        ga = 0.5 * (s110 + s011 - s101 - s0)
        de = 0.5 * (s101 + s011 - s110 - s0)
        return s0 + be * u0 + ga * u1 + de * u2
    if region == 0:
        qi, qj, qk = 1, 0, 0
    elif region == 1:
        qi, qj, qk = 0, 1, 0
    elif region == 2:
        qi, qj, qk = 0, 0, 1
    else:
        qi, qj, qk = 1, 1, 1
    vq = cv[_corner(qi, qj, qk)]
    return (vq + (cv[_corner(1 - qi, qj, qk)] - vq) * abs(u0 - qi) + (cv[_corner(qi, 1 - qj, qk)] - vq) * abs(u1 - qj)
            + (cv[_corner(qi, qj, 1 - qk)] - vq) * abs(u2 - qk))


@njit(cache=True, nogil=True)
def _l1(region, u0, u1, u2):
    """L1 distance of a local point from the odd corner of corner tet ``region`` (inside the tet if <= 1)."""
    if region == 0:
        return (1 - u0) + u1 + u2
    if region == 1:
        return u0 + (1 - u1) + u2
    if region == 2:
        return u0 + u1 + (1 - u2)
    return (1 - u0) + (1 - u1) + (1 - u2)


@njit(cache=True, nogil=True, inline="always")
def _sort_small(v, n):
    """Insertion sort of v[0:n] (n <= 6)."""
    for i in range(1, n):
        x = v[i]
        j = i - 1
        while j >= 0 and v[j] > x:
            v[j + 1] = v[j]
            j -= 1
        v[j + 1] = x


@njit(cache=True, nogil=True)
def _pieces(uo, ud, t0, t1, ca, cm, ts, sa, sm, cuts):
    """Split [t0, t1] (inside the unit cube in local coordinates uo + t ud, even parity) at the 4 corner-tet planes
    L1 = 1 (linear in t inside the cube); per piece the scalar/modulation at both ends. Returns the piece count."""
    nc = 0
    cuts[nc] = t0
    nc += 1
    for r in range(4):
        g0 = _l1(r, uo[0] + t0 * ud[0], uo[1] + t0 * ud[1], uo[2] + t0 * ud[2])
        g1 = _l1(r, uo[0] + t1 * ud[0], uo[1] + t1 * ud[1], uo[2] + t1 * ud[2])
        if (g0 - 1.0) * (g1 - 1.0) < 0.0:
            cuts[nc] = t0 + (1.0 - g0) / (g1 - g0) * (t1 - t0)
            nc += 1
    cuts[nc] = t1
    nc += 1
    _sort_small(cuts, nc)
    n = 0
    for i in range(nc - 1):
        ta, tb = cuts[i], cuts[i + 1]
        if tb - ta <= 0.0:
            continue
        tm = 0.5 * (ta + tb)
        m0, m1, m2 = uo[0] + tm * ud[0], uo[1] + tm * ud[1], uo[2] + tm * ud[2]
        region = 4
        for r in range(4):
            if _l1(r, m0, m1, m2) < 1.0:
                region = r
                break
        a0, a1, a2 = uo[0] + ta * ud[0], uo[1] + ta * ud[1], uo[2] + ta * ud[2]
        b0, b1, b2 = uo[0] + tb * ud[0], uo[1] + tb * ud[1], uo[2] + tb * ud[2]
        ts[n] = ta
        ts[n + 1] = tb
        sa[n, 0] = _eval(ca, region, a0, a1, a2)
        sa[n, 1] = _eval(ca, region, b0, b1, b2)
        sm[n, 0] = _eval(cm, region, a0, a1, a2)
        sm[n, 1] = _eval(cm, region, b0, b1, b2)
        n += 1
        if n == 3:
            break
    return n


@njit(cache=True, nogil=True)
def cube_segments(o, d, p0, e, flip, t_lo, t_hi, ca, cm, ts, sa, sm, uo, ud, cuts):
    """The ray o + t d inside the box (min corner p0, edges e) and [t_lo, t_hi], split into its 5-tet pieces (front
    to back). ca/cm: corner values, already mirrored in x if ``flip`` (odd parity). uo, ud (3,), cuts (6,) scratch."""
    t0, t1 = t_lo, t_hi
    for ax in range(3):
        uo[ax] = (o[ax] - p0[ax]) / e[ax]
        ud[ax] = d[ax] / e[ax]
    if flip:
        uo[0] = 1.0 - uo[0]
        ud[0] = -ud[0]
    for ax in range(3):
        if ud[ax] != 0.0:
            ta = -uo[ax] / ud[ax]
            tb = (1.0 - uo[ax]) / ud[ax]
            if ta > tb:
                ta, tb = tb, ta
            t0 = max(t0, ta)
            t1 = min(t1, tb)
        elif uo[ax] < 0.0 or uo[ax] > 1.0:
            return 0
    if t1 <= t0:
        return 0
    return _pieces(uo, ud, t0, t1, ca, cm, ts, sa, sm, cuts)


@njit(cache=True, nogil=True)
def _leaf_setup(leaves, nleaf, root, vp, w, h, origin, spacing, boxes):
    """Screen box of every leaf cube, clipped to the near plane (corners in front + edge/near-plane crossings)."""
    cam = np.empty((8, 3))
    box = np.empty(4, dtype=np.int64)
    for t in range(nleaf):
        lv, a, b, c = leaves[t, 0], leaves[t, 1], leaves[t, 2], leaves[t, 3]
        s = root >> lv
        for q in range(8):
            px = origin[0] + (a + (q >> 2)) * s * spacing[0] - vp[0]
            py = origin[1] + (b + ((q >> 1) & 1)) * s * spacing[1] - vp[1]
            pz = origin[2] + (c + (q & 1)) * s * spacing[2] - vp[2]
            cam[q, 0] = px * vp[3] + py * vp[4] + pz * vp[5]
            cam[q, 1] = px * vp[6] + py * vp[7] + pz * vp[8]
            cam[q, 2] = px * vp[9] + py * vp[10] + pz * vp[11]
        if not clipped_screen_box(cam, CUBE_EDGES, vp, w, h, box):
            boxes[t, 0], boxes[t, 1], boxes[t, 2], boxes[t, 3] = 1, 0, 1, 0  # empty
            continue
        for k in range(4):
            boxes[t, k] = box[k]


# odd corners of the even-parity corner tetrahedra (regions 0..3) and their plane normals n (g = c + n . u)
_QC = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]], dtype=np.int64)


@njit(cache=True, nogil=True)
def _leaf_linear(cv, alpha, beta):
    """Per region (0..3 corner tets, 4 central) the linear interpolant S = alpha + beta . u of corner values cv."""
    for r in range(4):
        qi, qj, qk = _QC[r, 0], _QC[r, 1], _QC[r, 2]
        vq = cv[_corner(qi, qj, qk)]
        alpha[r] = vq
        for ax in range(3):
            if ax == 0:
                dv = cv[_corner(1 - qi, qj, qk)] - vq
                q = qi
            elif ax == 1:
                dv = cv[_corner(qi, 1 - qj, qk)] - vq
                q = qj
            else:
                dv = cv[_corner(qi, qj, 1 - qk)] - vq
                q = qk
            if q == 0:
                beta[r, ax] = dv
            else:
                alpha[r] += dv
                beta[r, ax] = -dv
    s0, s110, s101, s011 = cv[0], cv[6], cv[5], cv[3]
    alpha[4] = s0
    beta[4, 0] = 0.5 * (s110 + s101 - s011 - s0)
    beta[4, 1] = 0.5 * (s110 + s011 - s101 - s0)
    beta[4, 2] = 0.5 * (s101 + s011 - s110 - s0)


@njit(cache=True, nogil=True, error_model="numpy")
def _render_band(leaves, nleaf, boxes, root, origin, spacing, va, vm, m_scale, a_cut, table, s_lo, ds, dl, eye,
                 dirs, invd, dnorm, depth, near, row0, row1, img, trans):
    """Leaves front to back (the reverse of the back-to-front list) composited *under* the pixel with early ray
    termination (transmittance < 1/1024); equivalent to back-to-front "over" up to that cut-off.

    Per leaf the 5 linear pieces are precomputed as functions of the ray parameter's offset (alpha + beta . uo), so
    per pixel only dot products with the local direction remain (the arithmetic of ``cube_segments``)."""
    p0 = np.empty(3)
    e = np.empty(3)
    ca = np.empty(8)
    cm = np.empty(8)
    seg = np.empty(4)
    uo = np.empty(3)
    ud = np.empty(3)
    cuts = np.empty(6)
    lo = np.empty(3)
    hi = np.empty(3)
    al_a = np.empty(5)
    be_a = np.empty((5, 3))
    al_m = np.empty(5)
    be_m = np.empty((5, 3))
    a0 = np.empty(5)
    m0 = np.empty(5)
    g0 = np.empty(4)
    g1 = np.empty(4)
    for t in range(nleaf - 1, -1, -1):
        y_lo = max(boxes[t, 2], row0)
        y_hi = min(boxes[t, 3], row1 - 1)
        if y_lo > y_hi or boxes[t, 0] > boxes[t, 1]:
            continue
        lv, a, b, c = leaves[t, 0], leaves[t, 1], leaves[t, 2], leaves[t, 3]
        s = root >> lv
        flip = (a + b + c) % 2 == 1
        for q in range(8):
            i, j, k = q >> 2, (q >> 1) & 1, q & 1
            src = ((1 - i) if flip else i)
            gx, gy, gz = (a + src) * s, (b + j) * s, (c + k) * s
            ca[q] = va[gx, gy, gz]
            cm[q] = vm[gx, gy, gz] * m_scale
        _leaf_linear(ca, al_a, be_a)
        _leaf_linear(cm, al_m, be_m)
        for ax in range(3):
            e[ax] = s * spacing[ax]
        p0[0] = origin[0] + a * e[0]
        p0[1] = origin[1] + b * e[1]
        p0[2] = origin[2] + c * e[2]
        for ax in range(3):
            lo[ax] = p0[ax] - eye[ax]
            hi[ax] = p0[ax] + e[ax] - eye[ax]
            uo[ax] = (eye[ax] - p0[ax]) / e[ax]
        if flip:
            uo[0] = 1.0 - uo[0]
        for r in range(5):
            a0[r] = al_a[r] + be_a[r, 0] * uo[0] + be_a[r, 1] * uo[1] + be_a[r, 2] * uo[2]
            m0[r] = al_m[r] + be_m[r, 0] * uo[0] + be_m[r, 1] * uo[1] + be_m[r, 2] * uo[2]
        for r in range(4):
            g = 0.0
            for ax in range(3):
                g += (1.0 - uo[ax]) if _QC[r, ax] == 1 else uo[ax]
            g0[r] = g
        inv_e0, inv_e1, inv_e2 = 1.0 / e[0], 1.0 / e[1], 1.0 / e[2]
        for row in range(y_lo, y_hi + 1):
            for col in range(boxes[t, 0], boxes[t, 1] + 1):
                if trans[row, col] < 1.0 / 1024.0:
                    continue
                t0 = near
                t1 = depth[row, col]
                for ax in range(3):
                    ta = lo[ax] * invd[row, col, ax]
                    tb = hi[ax] * invd[row, col, ax]
                    if ta > tb:
                        ta, tb = tb, ta
                    if ta > t0:
                        t0 = ta
                    if tb < t1:
                        t1 = tb
                if t1 <= t0:
                    continue
                ud[0] = dirs[row, col, 0] * inv_e0
                ud[1] = dirs[row, col, 1] * inv_e1
                ud[2] = dirs[row, col, 2] * inv_e2
                if flip:
                    ud[0] = -ud[0]
                nc = 0
                cuts[nc] = t0
                nc += 1
                for r in range(4):
                    gg = 0.0
                    for ax in range(3):
                        gg += -ud[ax] if _QC[r, ax] == 1 else ud[ax]
                    g1[r] = gg
                    if gg != 0.0:
                        tc = (1.0 - g0[r]) / gg
                        if t0 < tc < t1:
                            cuts[nc] = tc
                            nc += 1
                cuts[nc] = t1
                nc += 1
                _sort_small(cuts, nc)
                dn = dnorm[row, col]
                for i in range(nc - 1):
                    ta, tb = cuts[i], cuts[i + 1]
                    if tb <= ta:
                        continue
                    tm = 0.5 * (ta + tb)
                    region = 4
                    for r in range(4):
                        if g0[r] + g1[r] * tm < 1.0:
                            region = r
                            break
                    ba = be_a[region, 0] * ud[0] + be_a[region, 1] * ud[1] + be_a[region, 2] * ud[2]
                    sf = a0[region] + ba * ta
                    sb = a0[region] + ba * tb
                    if sf <= a_cut and sb <= a_cut:
                        continue
                    bm = be_m[region, 0] * ud[0] + be_m[region, 1] * ud[1] + be_m[region, 2] * ud[2]
                    length = (tb - ta) * dn * (m0[region] + bm * tm)
                    if length <= 0.0:
                        continue
                    _lookup(table, s_lo, ds, dl, sf, sb, length, seg)
                    tr = trans[row, col]
                    for ch in range(4):
                        img[row, col, ch] += tr * seg[ch]
                    trans[row, col] = tr * (1.0 - seg[3])


@njit(cache=True, nogil=True, parallel=True)
def _directions(rb, w, h, dirs, invd, dnorm):
    for row in prange(h):
        for col in range(w):
            n2 = 0.0
            for ax in range(3):
                v = rb[3, ax] + col * rb[4, ax] + row * rb[5, ax]
                dirs[row, col, ax] = v
                invd[row, col, ax] = 1.0 / v if v != 0.0 else (1e300 if not math.copysign(1.0, v) < 0 else -1e300)
                n2 += v * v
            dnorm[row, col] = math.sqrt(n2)


@njit(cache=True, nogil=True, parallel=True)
def render(leaves, nleaf, root, origin, spacing, va, vm, m_scale, a_cut, table, s_lo, ds, dl, rb, vp, depth, bands,
           w, h, img, threads=2):
    """Perspective only (all rays start at the eye ``vp[0:3]``). ``threads``: Numba's thread count (the row bands
    are dealt out so that each thread's contiguous share of iterations covers the whole image)."""
    boxes = np.empty((nleaf, 4), dtype=np.int64)
    _leaf_setup(leaves, nleaf, root, vp, w, h, origin, spacing, boxes)
    dirs = np.empty((h, w, 3))
    invd = np.empty((h, w, 3))
    dnorm = np.empty((h, w))
    _directions(rb, w, h, dirs, invd, dnorm)
    trans = np.ones((h, w))
    eye = vp[0:3].copy()
    nb = bands.shape[0] - 1
    for ii in prange(dealt_count(nb, threads)):
        bi = dealt_band(ii, nb, threads)
        if bi >= 0:
            _render_band(leaves, nleaf, boxes, root, origin, spacing, va, vm, m_scale, a_cut, table, s_lo, ds, dl,
                         eye, dirs, invd, dnorm, depth, vp[14], bands[bi], bands[bi + 1], img, trans)
