"""Wavelet-octree nodes of a ``.vvz`` file, decoded one level at a time on demand (Guthe §2.3.1, §2.3.4).

Node ``(level, (p0, p1, p2))`` is the 16^3 lowpass block ``p`` of pyramid level ``level`` (level 0 = the full
resolution volume, level ``L`` = the root). Its sample ``i`` sits on full-resolution voxel ``2**level * (16 p + i)``
(5/3 lowpass samples are the even samples). Brick ``(level, tile p)`` of the container holds the detail
coefficients that reconstruct its (up to) 8 children ``(level - 1, 2 p + {0, 1}^3)``: decoding a node's brick with
:meth:`NodeDecoder.children` yields all of them at once, exactly as the whole-volume decoder does (bit-exact), with
the transform recorded for that brick (5/3, or the S-transform in lossless files); the node samples are then the
lowpass of whichever transform each finer node used.

:func:`node_statistics` measures, for every node, the quantities the LOD selector needs (§2.3.4):

- ``l2``: the exact L2 error ``sqrt(sum (V_h - V_l)^2)`` between the full-resolution volume and the node's own
  reconstruction with all finer details zero (the 5/3 linear interpolation the renderer would show), i.e. the
  energy of all wavelets in its subtree; 0 for leaves.
- ``hist_pos`` / ``hist_neg`` (8 bins): the maximum positive / negative deviation ``V_h - V_l`` for the voxels whose
  low-resolution value ``V_l`` falls in each of 8 equal bins over the volume's value range, ``hist_n`` their counts
  (the 8-entry deviation histogram of Eq. 2.7).
- ``vmin`` / ``vmax``: the full-resolution value range in the node's footprint plus a one-voxel apron (for
  transparent-block skipping; the apron covers the interpolation across the block border).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numba import njit

from . import kernels as K
from .codec import _check_meta, _root_undpcm, level_steps, transforms
from .container import KIND_NODE, KIND_ROOT, CorruptBrickError, Reader
from .entropy import CODERS, decode_rans
from .wavelet import HALF, TILE, inverse_tile_t, level_shapes, n_tiles

N_BINS = 8
Key = tuple[int, tuple[int, int, int]]


@njit(cache=True, nogil=True)
def _decode_tile(low, payload, offset, size, steps, coder, transform, n0, n1, n2):
    """Decode one brick: lowpass block ``low`` (ceil(n/2) per axis) + coded details -> the (n0, n1, n2) samples,
    with the brick's own transform (5/3 or S-transform)."""
    w = np.zeros((TILE, TILE, TILE), np.int32)
    l0, l1, l2 = low.shape
    for i in range(l0):
        for j in range(l1):
            for k in range(l2):
                w[i, j, k] = low[i, j, k]
    rc = K.decode_details(payload, offset, size, w, n0, n1, n2, coder, transform, steps[0] > 0)
    if rc != 0:
        decode_rans(payload, 0, 0, w, n0, n1, n2, False)
    K._dequantise(w, n0, n1, n2, steps)
    inverse_tile_t(w, np.empty((TILE, TILE, TILE), np.int32), n0, n1, n2, transform)
    return w[:n0, :n1, :n2].copy(), rc


@njit(cache=True, nogil=True)
def _stats_kernel(vh, vl, block, lo, binw, sumsq, hpos, hneg, hn, vmin, vmax):
    """Accumulate the per-node deviation statistics of one level (see the module docstring)."""
    s0, s1, s2 = vh.shape
    for i in range(s0):
        b0 = i // block
        for j in range(s1):
            b1 = j // block
            for k in range(s2):
                b2 = k // block
                h = vh[i, j, k]
                l = vl[i, j, k]
                d = h - l
                sumsq[b0, b1, b2] += float(d) * float(d)
                b = int((l - lo) / binw)
                b = min(max(b, 0), 7)
                if hn[b0, b1, b2, b] == 0 or d > hpos[b0, b1, b2, b]:
                    hpos[b0, b1, b2, b] = d
                if hn[b0, b1, b2, b] == 0 or d < hneg[b0, b1, b2, b]:
                    hneg[b0, b1, b2, b] = d
                hn[b0, b1, b2, b] += 1
                # value range with a one-voxel apron (the sample is in the footprint of up to 2 blocks per axis)
                for e0 in range(max(0, (i - 1) // block), min(vmin.shape[0], (i + 1) // block + 1)):
                    for e1 in range(max(0, (j - 1) // block), min(vmin.shape[1], (j + 1) // block + 1)):
                        for e2 in range(max(0, (k - 1) // block), min(vmin.shape[2], (k + 1) // block + 1)):
                            if h < vmin[e0, e1, e2]:
                                vmin[e0, e1, e2] = h
                            if h > vmax[e0, e1, e2]:
                                vmax[e0, e1, e2] = h


@dataclass
class LevelStats:
    """Per-node statistics of one pyramid level; arrays are indexed by the node position ``p``."""
    l2: np.ndarray        # (c0, c1, c2) float64
    hist_pos: np.ndarray  # (c0, c1, c2, 8) int64, max V_h - V_l per V_l bin
    hist_neg: np.ndarray  # (c0, c1, c2, 8) int64, min V_h - V_l per V_l bin
    hist_n: np.ndarray    # (c0, c1, c2, 8) int64, voxel count per bin
    vmin: np.ndarray      # (c0, c1, c2) int64
    vmax: np.ndarray      # (c0, c1, c2) int64


def _expand(low: np.ndarray, shapes: list[tuple[int, int, int]], level: int) -> np.ndarray:
    """Reconstruct level-``level`` lowpass samples to full resolution with all details zero (bit-exact with what
    the decoder shows for a node whose subtree was not refined)."""
    cur = low
    steps = np.zeros(8)
    for lev in range(level, 0, -1):
        shp = shapes[lev - 1]
        nt = n_tiles(shp[0]) * n_tiles(shp[1]) * n_tiles(shp[2])
        det = np.zeros((nt, TILE, TILE, TILE), np.int32)
        a = np.empty(shp, np.int32)
        K.run_tiles(K.reconstruct_level, cur, det, steps, a, False)
        cur = a
    return cur


def node_statistics(data: np.ndarray, transforms: dict[int, np.ndarray] | None = None
                    ) -> tuple[list[LevelStats], float, float]:
    """Statistics of every node of the wavelet octree of ``data`` (integer samples as the codec stores them);
    returns (per-level stats, bin origin, bin width). Memory: two int32 copies of the volume.

    ``transforms`` (:meth:`NodeDecoder.transforms` of the file): the transform of every tile per level, so the
    node samples are the lowpass the file's nodes really hold; without it every node is taken as 5/3 (exact for
    lossy files and for lossless files without S-transform nodes)."""
    vh = np.ascontiguousarray(data, dtype=np.int32)
    shapes = level_shapes(vh.shape)
    lo, hi = float(vh.min()), float(vh.max())
    binw = max((hi - lo) / N_BINS, 1e-9)
    out = []
    cur = vh
    for lev in range(len(shapes)):
        if lev > 0:
            low = np.zeros(shapes[lev], np.int32)
            nt = n_tiles(cur.shape[0]) * n_tiles(cur.shape[1]) * n_tiles(cur.shape[2])
            tfs = np.zeros(nt, np.int64) if transforms is None else np.asarray(transforms[lev], np.int64)
            if tfs.shape != (nt,):
                raise ValueError(f"transforms of level {lev}: {tfs.shape[0]} tiles given, the volume has {nt}")
            K.run_tiles(K.transform_level, cur, low, np.zeros((nt, TILE, TILE, TILE), np.int32), tfs)
            cur = low
        vl = vh if lev == 0 else _expand(cur, shapes, lev)
        c = tuple(n_tiles(2 * s) for s in shapes[lev])  # 16-sample nodes per axis
        block = HALF << lev
        st = LevelStats(np.zeros(c), np.zeros(c + (N_BINS,), np.int64), np.zeros(c + (N_BINS,), np.int64),
                        np.zeros(c + (N_BINS,), np.int64), np.full(c, np.iinfo(np.int64).max, np.int64),
                        np.full(c, np.iinfo(np.int64).min, np.int64))
        _stats_kernel(vh, vl, block, lo, binw, st.l2, st.hist_pos, st.hist_neg, st.hist_n, st.vmin, st.vmax)
        st.l2 = np.sqrt(st.l2)
        out.append(st)
    return out, lo, binw


class NodeDecoder:
    """Random access to the nodes of a ``.vvz`` file: the root, and the 8 children of any decoded inner node."""

    def __init__(self, path: str | Path) -> None:
        self.path = str(path)
        self.reader = Reader(path)
        meta = self.reader.meta
        self.dims, self.levels, coder = _check_meta(meta, self.path)
        self.meta = meta
        self.coder = CODERS[coder]
        self.shapes = level_shapes(self.dims)
        self.steps = level_steps(float(meta["delta"]), self.levels)
        self.index = {(int(r["kind"]), int(r["level"]), int(r["tile"])): i for i, r in enumerate(self.reader.table)}
        self.decoded_bricks = 0

    def transforms(self) -> dict[int, np.ndarray]:
        """The recorded transform of every brick, ``{level: int64 array indexed by tile}`` for levels 1..L (for
        :func:`node_statistics`)."""
        out = {}
        lossless = float(self.meta["delta"]) == 0.0
        for level in range(1, self.levels + 1):
            shp = self.shapes[level - 1]
            nt = n_tiles(shp[0]) * n_tiles(shp[1]) * n_tiles(shp[2])
            idx = np.array([self.index.get((KIND_NODE, level, t), -1) for t in range(nt)], np.int64)
            if (idx < 0).any():
                raise CorruptBrickError(self.path, f"level {level} tile {int(np.argmin(idx))} missing from the "
                                        "brick table")
            out[level] = transforms(self.reader.table, idx, lossless, self.path)
        return out

    def n_nodes(self, level: int) -> tuple[int, int, int]:
        return tuple(n_tiles(2 * s) for s in self.shapes[level])  # type: ignore[return-value]

    def root(self) -> np.ndarray:
        """The root node's samples (shape ``shapes[levels]``)."""
        i = self.index.get((KIND_ROOT, self.levels, 0))
        if i is None or not self.reader.brick_ok(i):
            raise CorruptBrickError(self.path, "root brick missing or failing its checksum")
        rec = self.reader.table[i]
        root = np.zeros(self.shapes[-1], np.int32)
        if K.decode_root(self.reader.payload, int(rec["offset"]), int(rec["size"]), self.coder, root) != 0:
            raise CorruptBrickError(self.path, "root brick stream is inconsistent")
        return _root_undpcm(root)

    def children(self, key: Key, data: np.ndarray) -> dict[Key, np.ndarray]:
        """Decode node ``key``'s brick given the node's own samples ``data``: returns its children's samples. A
        corrupt brick raises :class:`CorruptBrickError` naming it."""
        level, p = key
        if level < 1:
            raise ValueError(f"node {key} is a leaf")
        shp = self.shapes[level - 1]
        c = (n_tiles(shp[0]), n_tiles(shp[1]))
        tile = p[0] + c[0] * (p[1] + c[1] * p[2])
        i = self.index.get((KIND_NODE, level, tile))
        if i is None or not self.reader.brick_ok(i):
            raise CorruptBrickError(self.path, f"brick of node level {level} tile {tile} {p} missing or failing its "
                                    "checksum")
        rec = self.reader.table[i]
        tf = int(transforms(self.reader.table, i, float(self.meta["delta"]) == 0.0, self.path)[0])
        n = tuple(min(TILE, shp[a] - TILE * p[a]) for a in range(3))
        full, rc = _decode_tile(np.ascontiguousarray(data, np.int32), self.reader.payload, int(rec["offset"]),
                                int(rec["size"]), self.steps[level], self.coder, tf, n[0], n[1], n[2])
        if rc != 0:
            raise CorruptBrickError(self.path, f"brick of node level {level} tile {tile} {p}: inconsistent stream")
        self.decoded_bricks += 1
        out = {}
        for d0 in range(2):
            for d1 in range(2):
                for d2 in range(2):
                    s = (d0 * HALF, d1 * HALF, d2 * HALF)
                    if s[0] < n[0] and s[1] < n[1] and s[2] < n[2]:
                        q = (2 * p[0] + d0, 2 * p[1] + d1, 2 * p[2] + d2)
                        out[(level - 1, q)] = full[s[0]:s[0] + HALF, s[1]:s[1] + HALF, s[2]:s[2] + HALF].copy()
        return out

    def close(self) -> None:
        self.reader.close()
