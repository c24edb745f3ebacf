"""Level of detail over the wavelet octree of a ``.vvz`` file (Guthe §2.3.1-2.3.5, Eqs. 2.1 and 2.7).

Usage (the render layer)::

    tree = LodTree("head.vvz", cache_bytes=256 << 20)     # statistics: one full decode, or pass volume=
    cam = LodCamera(eye=(..), target=(..), fov_y=30, height=512)
    sel = tree.select(cam, budget=512, tf=tf)             # greedy refinement, transparent blocks skipped
    for block in tree.blocks(sel):                        # decoded via the LRU cache, one-voxel overlap
        block.origin, block.spacing, block.data           # a float32 brick to draw as its own volume

Selection (§2.3.3): start from the root; a priority queue holds the selected inner nodes; the node of highest
priority is replaced by its (non-transparent) children while the number of selected blocks stays within
``budget``. Priorities:

- ``mode="l2"``: ``P = E / z`` with ``E`` the node's exact L2 error (see :mod:`.nodes`) and ``z`` the minimum view
  depth of the node's box (``P = inf`` at ``z <= 0``).
- ``mode="tf"``: the transfer-function dependent screen-space bound of Eq. 2.7 -- per populated deviation-histogram
  bin, ``D``/``C`` (extinction ρ / sum of the κ channels) ranges over the low-resolution bin and its deviations,
  ``err_O = e^{-d D_min} - e^{-d D_max}``, ``err_C = (C_max - C_min)(1 - e^{-d D_max}) + C_min err_O``, ``d`` the
  err_O optimum ``ln(D_max/D_min)/(D_max - D_min)`` clamped to the block diagonal (the diagonal when D_min = 0);
  the node's error is the maximum over bins (cached per TF), weighted by its projected area in pixels.

Nodes whose projected voxel spacing (Eq. 2.1, ``q = tan(fov/2)/(h/2)``) is already <= one pixel, nodes with zero
error, and nodes whose error is below ``max_error`` are not refined; nodes entirely outside the view frustum are
culled; nodes whose value range (footprint + one-voxel apron) maps to ρ = 0 everywhere are skipped (§2.3.5).
"""
from __future__ import annotations

import heapq
import math
import os
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from volviz.model.datasets import RegularVolume

from .cache import NodeCache
from .nodes import HALF, Key, LevelStats, NodeDecoder, _expand, node_statistics


@dataclass(frozen=True)
class LodCamera:
    """The selection's pinhole camera in world coordinates: vertical field of view ``fov_y`` (degrees) and the image
    ``width x height`` the pixel error is measured in (``volviz.model.camera.Camera`` carries no image size)."""
    eye: tuple[float, float, float]
    target: tuple[float, float, float]
    up: tuple[float, float, float] = (0.0, 0.0, 1.0)
    fov_y: float = 30.0
    width: int = 512
    height: int = 512

    def frame(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        e = np.asarray(self.eye, float)
        f = np.asarray(self.target, float) - e
        if not np.linalg.norm(f) > 0:
            raise ValueError("camera eye and target coincide")
        f /= np.linalg.norm(f)
        r = np.cross(f, np.asarray(self.up, float))
        if np.linalg.norm(r) < 1e-12:
            r = np.cross(f, [1.0, 0.0, 0.0] if abs(f[0]) < 0.9 else [0.0, 1.0, 0.0])
        r /= np.linalg.norm(r)
        return e, f, r, np.cross(r, f)

    @property
    def q(self) -> float:
        """World size of one pixel per unit depth (Eq. 2.1)."""
        return math.tan(math.radians(self.fov_y) / 2) / (self.height / 2)


@dataclass
class Selection:
    """The blocks chosen for one frame (keys ``(level, p)``) and the numbers behind them."""
    nodes: list[Key]
    priority: dict[Key, float] = field(default_factory=dict)
    skipped_transparent: int = 0
    culled: int = 0
    refinements: int = 0


@dataclass
class Block:
    """A renderable brick: samples at ``origin + spacing * index`` (world units), one-voxel overlap included."""
    key: Key
    data: np.ndarray
    origin: tuple[float, float, float]
    spacing: tuple[float, float, float]


def _tf_minmax(tf: Any, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, ...]:
    """Min and max of ρ and of κ_r + κ_g + κ_b over scalar intervals [lo, hi] (piecewise linear: extremes at the
    ends or at control points; outside the TF's range both are 0)."""
    s = np.asarray(tf.scalars, float)
    rho_c = np.asarray(tf.extinction, float)
    col_c = np.asarray(tf.colors, float).sum(axis=1)
    rgb_lo, r_lo = tf.evaluate(lo)
    rgb_hi, r_hi = tf.evaluate(hi)
    c_lo, c_hi = rgb_lo.sum(-1), rgb_hi.sum(-1)
    dmin, dmax = np.minimum(r_lo, r_hi), np.maximum(r_lo, r_hi)
    cmin, cmax = np.minimum(c_lo, c_hi), np.maximum(c_lo, c_hi)
    for k in range(len(s)):
        inside = (lo <= s[k]) & (s[k] <= hi)
        dmin = np.where(inside, np.minimum(dmin, rho_c[k]), dmin)
        dmax = np.where(inside, np.maximum(dmax, rho_c[k]), dmax)
        cmin = np.where(inside, np.minimum(cmin, col_c[k]), cmin)
        cmax = np.where(inside, np.maximum(cmax, col_c[k]), cmax)
    out = (lo < s[0]) | (hi > s[-1])  # part of the interval is transparent
    dmin = np.where(out, 0.0, dmin)
    cmin = np.where(out, 0.0, cmin)
    return dmin, dmax, cmin, cmax


def eq27_error(dmin: np.ndarray, dmax: np.ndarray, cmin: np.ndarray, cmax: np.ndarray,
               diagonal: float) -> np.ndarray:
    """Guthe Eq. 2.7: ``err''_O + err''_C`` at the worst ray length ``d`` inside a block of the given diagonal."""
    with np.errstate(divide="ignore", invalid="ignore"):
        dopt = np.where((dmin > 0) & (dmax > dmin), np.log(dmax / np.maximum(dmin, 1e-300)) / (dmax - dmin),
                        diagonal)
    d = np.minimum(np.nan_to_num(dopt, nan=diagonal, posinf=diagonal), diagonal)
    err_o = np.exp(-d * dmin) - np.exp(-d * dmax)
    err_c = (cmax - cmin) * (1.0 - np.exp(-d * dmax)) + cmin * err_o
    # err_C peaks at the diagonal: evaluate it there too and keep the larger total
    err_o2 = np.exp(-diagonal * dmin) - np.exp(-diagonal * dmax)
    err_c2 = (cmax - cmin) * (1.0 - np.exp(-diagonal * dmax)) + cmin * err_o2
    return np.maximum(err_o + err_c, err_o2 + err_c2)


_STAT_FIELDS = ("l2", "hist_pos", "hist_neg", "hist_n", "vmin", "vmax")


def _save_stats(path: Path, dec: NodeDecoder, stats: list[LevelStats], lo: float, w: float) -> None:
    arrays = {f"{f}_{lev}": getattr(st, f) for lev, st in enumerate(stats) for f in _STAT_FIELDS}
    arrays["key"] = np.array([dec.reader.header["table_crc"], len(stats), lo, w], np.float64)
    tmp = path.with_name(path.name + ".tmp.npz")
    try:
        np.savez(tmp, **arrays)
        os.replace(tmp, path)
    except OSError:
        tmp.unlink(missing_ok=True)


def _load_stats(path: Path, dec: NodeDecoder) -> tuple[list[LevelStats], float, float] | None:
    """Statistics from a sidecar written for this very file (same brick-table CRC), else None. Never unpickles."""
    try:
        with np.load(path, allow_pickle=False) as z:
            key = z["key"]
            if int(key[0]) != dec.reader.header["table_crc"] or int(key[1]) != dec.levels + 1:
                return None
            stats = [LevelStats(*(z[f"{f}_{lev}"] for f in _STAT_FIELDS)) for lev in range(dec.levels + 1)]
    except (OSError, KeyError, ValueError):
        return None
    for lev, st in enumerate(stats):
        if st.l2.shape != dec.n_nodes(lev):
            return None
    return stats, float(key[2]), float(key[3])


class LodTree:
    """A ``.vvz`` wavelet octree with per-node statistics, an LRU node cache and view-dependent selection."""

    def __init__(self, path: str | Path, cache_bytes: int = 256 << 20, volume: RegularVolume | None = None,
                 sidecar: bool = True) -> None:
        """Open ``path``. Node statistics come from the sidecar ``PATH.lod.npz`` when it matches the file (same
        brick-table checksum), else from ``volume`` (the original, in memory) or one full decode of the file; in the
        latter case (with ``sidecar``) they are saved next to the file (atomic write; silently skipped when not
        writable)."""
        self.decoder = NodeDecoder(path)
        meta = self.decoder.meta
        self.levels = self.decoder.levels
        self.shapes = self.decoder.shapes
        self.spacing = np.asarray(meta.get("spacing", (1, 1, 1)), float)
        self.origin = np.asarray(meta.get("origin", (0, 0, 0)), float)
        self.cache = NodeCache(cache_bytes, self.levels)
        self._lock = threading.RLock()  # node decoding and the cache may be driven from a background worker
        kind = str(meta["kind"])
        if kind in ("float", "int-quantised"):
            lo, hi = float(meta["float_lo"]), float(meta["float_hi"])
            self._scale = (lo, (hi - lo) / 65535.0)
        else:
            self._scale = (0.0, 1.0)
        self.sidecar = Path(str(path) + ".lod.npz")
        loaded = _load_stats(self.sidecar, self.decoder) if volume is None and sidecar else None
        if loaded is None:
            save = sidecar and volume is None  # a sidecar always describes the decoded file
            if volume is None:
                from .codec import decompress  # statistics of the decoded (possibly lossy) volume
                volume = decompress(path)
            data = np.asarray(volume.data)
            if kind in ("float", "int-quantised"):
                data = np.clip(np.rint((data.astype(np.float64) - self._scale[0]) / max(self._scale[1], 1e-300)),
                               0, 65535)
            loaded = node_statistics(data, self.decoder.transforms())  # the nodes' own 5/3 or S-transform lowpass
            if save:
                _save_stats(self.sidecar, self.decoder, *loaded)
        self.stats, self.bin_lo, self.bin_w = loaded
        self._tf_err: dict[int, np.ndarray] = {}
        self._tf_clear: dict[int, np.ndarray] = {}
        self._tf_obj: Any = None
        self._tf_key: Any = None

    # -- geometry -------------------------------------------------------------------------------------------------
    def node_box(self, key: Key) -> tuple[np.ndarray, np.ndarray]:
        """World bounding box (lo, hi) of the node, including the one-voxel overlap to its +x/+y/+z neighbours."""
        level, p = key
        step = 1 << level
        dims = np.asarray(self.decoder.dims)
        lo_i = np.asarray(p) * HALF * step
        hi_i = np.minimum((np.asarray(p) + 1) * HALF * step, dims - 1)
        return self.origin + lo_i * self.spacing, self.origin + hi_i * self.spacing

    def children_keys(self, key: Key) -> list[Key]:
        level, p = key
        c = self.decoder.n_nodes(level - 1)
        return [(level - 1, (2 * p[0] + a, 2 * p[1] + b, 2 * p[2] + d)) for d in range(2) for b in range(2)
                for a in range(2) if 2 * p[0] + a < c[0] and 2 * p[1] + b < c[1] and 2 * p[2] + d < c[2]]

    def _stat(self, key: Key) -> LevelStats:
        return self.stats[key[0]]

    def l2_error(self, key: Key) -> float:
        return float(self.stats[key[0]].l2[key[1]])

    # -- transfer function -------------------------------------------------------------------------------------------
    def _to_data(self, v: np.ndarray) -> np.ndarray:
        return self._scale[0] + np.asarray(v, float) * self._scale[1]

    def _tf_cache(self, tf: Any) -> None:
        """Drop the per-TF caches when the TF changes (by value; the same object is checked once)."""
        if tf is self._tf_obj:
            return
        tk = tf.to_dict() if hasattr(tf, "to_dict") else id(tf)
        if tk != self._tf_key:
            self._tf_err, self._tf_clear, self._tf_key = {}, {}, tk
        self._tf_obj = tf

    def transparent(self, key: Key, tf: Any) -> bool:
        """True when ρ = 0 over the node's value range (footprint plus one-voxel apron). Cached per TF."""
        self._tf_cache(tf)
        level = key[0]
        if level not in self._tf_clear:
            st = self.stats[level]
            _, dmax, _, _ = _tf_minmax(tf, self._to_data(st.vmin), self._to_data(st.vmax))
            self._tf_clear[level] = dmax <= 0.0
        return bool(self._tf_clear[level][key[1]])

    def tf_error(self, key: Key, tf: Any) -> float:
        """Eq. 2.7 bound for the node under ``tf`` (per ray through the block; 0 for leaves). Cached per TF."""
        self._tf_cache(tf)
        level = key[0]
        if level not in self._tf_err:
            st = self.stats[level]
            b = np.arange(8)
            blo = self.bin_lo + b * self.bin_w
            bhi = blo + self.bin_w
            lo = np.minimum(blo, blo + st.hist_neg)  # broadcast over nodes
            hi = np.maximum(bhi, bhi + st.hist_pos)
            dmin, dmax, cmin, cmax = _tf_minmax(tf, self._to_data(lo), self._to_data(hi))
            diag = float(np.linalg.norm(self.spacing * (HALF << level)))
            err = np.where(st.hist_n > 0, eq27_error(dmin, dmax, cmin, cmax, diag), 0.0)
            err = np.where(st.l2[..., None] > 0, err, 0.0)
            self._tf_err[level] = err.max(axis=-1)
        return float(self._tf_err[level][key[1]])

    # -- selection -------------------------------------------------------------------------------------------------
    def select(self, camera: LodCamera, budget: int, tf: Any = None, mode: str = "l2",
               max_error: float = 0.0) -> Selection:
        """Greedy refinement under a block budget (see the module docstring)."""
        if budget < 1:
            raise ValueError(f"block budget must be >= 1, got {budget}")
        if mode not in ("l2", "tf"):
            raise ValueError(f"unknown priority mode {mode!r} (l2, tf)")
        if mode == "tf" and tf is None:
            raise ValueError("mode 'tf' needs a transfer function")
        e, f, r, u = camera.frame()
        q = camera.q
        th = math.atan(math.tan(math.radians(camera.fov_y) / 2))
        tw = math.atan(math.tan(math.radians(camera.fov_y) / 2) * camera.width / camera.height)
        planes = np.array([f * math.sin(th) + u * math.cos(th), f * math.sin(th) - u * math.cos(th),
                           f * math.sin(tw) + r * math.cos(tw), f * math.sin(tw) - r * math.cos(tw), f]).T
        sel = Selection(nodes=[])
        corner_idx = np.array([[a, b, c] for a in (0, 1) for b in (0, 1) for c in (0, 1)])

        def classify(key: Key) -> tuple[bool, float, float]:
            """(visible, priority, pixel size of a voxel)"""
            lo, hi = self.node_box(key)
            dist = (np.where(corner_idx == 0, lo, hi) - e) @ planes  # (8 corners, 4 side planes + view axis)
            if (dist < 0).all(axis=0).any():
                return False, 0.0, 0.0
            z = max(0.0, float(dist[:, 4].min()))
            vox = float(np.max(self.spacing)) * (1 << key[0])
            if z <= 0:
                return True, math.inf, math.inf
            pix = vox / (z * q)
            if mode == "l2":
                return True, self.l2_error(key) / z, pix
            area = (float(np.linalg.norm(hi - lo)) / (z * q)) ** 2
            return True, self.tf_error(key, tf) * area, pix

        root: Key = (self.levels, (0, 0, 0))
        if tf is not None and self.transparent(root, tf):
            sel.skipped_transparent += 1
            return sel
        vis, pr, pix = classify(root)
        if not vis:
            sel.culled += 1
            return sel
        chosen: dict[Key, float] = {root: pr}
        heap: list[tuple[float, Key, float]] = []

        def push(key: Key, prio: float, px: float) -> None:
            err = self.l2_error(key) if mode == "l2" else self.tf_error(key, tf)
            if key[0] > 0 and err > 0 and px > 1.0 and (mode == "l2" or err > max_error):
                heapq.heappush(heap, (-prio, key, px))

        push(root, pr, pix)
        while heap:
            negp, key, _ = heapq.heappop(heap)
            kids, clear, culled = [], 0, 0
            for c in self.children_keys(key):
                if tf is not None and self.transparent(c, tf):
                    clear += 1
                    continue
                vis, pr, pix = classify(c)
                if not vis:
                    culled += 1
                    continue
                kids.append((c, pr, pix))
            if len(chosen) - 1 + len(kids) > budget:
                continue
            del chosen[key]
            sel.refinements += 1
            sel.skipped_transparent += clear
            sel.culled += culled
            for c, pr, pix in kids:
                chosen[c] = pr
                push(c, pr, pix)
        sel.nodes = sorted(chosen, key=lambda k: (-k[0], k[1]))
        sel.priority = chosen
        return sel

    def back_to_front(self, selection: Selection, camera: LodCamera) -> list[Key]:
        """The selected nodes sorted by decreasing distance of their box centres from the eye (the drawing order
        for "over" compositing of non-overlapping blocks, §2.3.6)."""
        e = np.asarray(camera.eye, float)

        def dist(k: Key) -> float:
            lo, hi = self.node_box(k)
            return float(np.linalg.norm((lo + hi) / 2 - e))

        return sorted(selection.nodes, key=dist, reverse=True)

    # -- decoding ---------------------------------------------------------------------------------------------------
    def node(self, key: Key) -> np.ndarray:
        """The node's samples (int32, up to 16^3), decoded one level at a time through the LRU cache. Thread-safe
        (one lock; the Numba decode kernel releases the GIL, so a worker thread decodes while the UI renders)."""
        with self._lock:
            level, p = key
            if level == self.levels:
                return self.cache.get_or_make(key, self.decoder.root)
            a = self.cache.get(key)
            if a is not None:
                return a
            parent: Key = (level + 1, (p[0] // 2, p[1] // 2, p[2] // 2))
            kids = self.decoder.children(parent, self.node(parent))
            for k, v in kids.items():
                self.cache.put(k, v)
            return kids[key]

    def prefetch(self, selection: Selection, cancelled: Any = None) -> int:
        """Decode every node of ``selection`` into the cache (for a background worker: the next frame's blocks
        while the current one renders); ``cancelled()`` -> True stops early. Returns the bricks decoded."""
        before = self.decoder.decoded_bricks
        for key in selection.nodes:
            if cancelled is not None and cancelled():
                break
            self.node(key)
        return self.decoder.decoded_bricks - before

    def block(self, key: Key) -> Block:
        """The node's samples as float32 in data units, extended by one voxel from its +x/+y/+z neighbours at the
        same level (decoded on demand, their neighbours never), so adjacent blocks share their border samples."""
        with self._lock:
            return self._block(key)

    def _block(self, key: Key) -> Block:
        level, p = key
        c = self.decoder.n_nodes(level)
        a = self.node(key)
        ext = [a.shape[i] + (1 if p[i] + 1 < c[i] else 0) for i in range(3)]
        out = np.empty(ext, np.int32)
        for d0 in range(2):
            for d1 in range(2):
                for d2 in range(2):
                    q = (p[0] + d0, p[1] + d1, p[2] + d2)
                    if q[0] >= c[0] or q[1] >= c[1] or q[2] >= c[2]:
                        continue
                    n = self.node((level, q)) if (d0, d1, d2) != (0, 0, 0) else a
                    s = [(0, a.shape[i]) if (d0, d1, d2)[i] == 0 else (a.shape[i], ext[i]) for i in range(3)]
                    out[s[0][0]:s[0][1], s[1][0]:s[1][1], s[2][0]:s[2][1]] = \
                        n[:s[0][1] - s[0][0], :s[1][1] - s[1][0], :s[2][1] - s[2][0]]
        self.cache.touch(key)
        step = self.spacing * (1 << level)
        origin = self.origin + np.asarray(p) * HALF * step
        return Block(key, self._to_data(out).astype(np.float32), tuple(origin), tuple(step))

    def blocks(self, selection: Selection) -> Iterator[Block]:
        for key in selection.nodes:
            yield self.block(key)

    def reconstruct(self, selection: Selection) -> np.ndarray:
        """Full-resolution int32 volume of a selection (unselected regions 0): each node is expanded with zero
        details. With every leaf selected (or all non-zero-error nodes refined) this equals the decoded volume."""
        out = np.zeros(self.decoder.dims, np.int32)
        for key in selection.nodes:
            level, p = key
            a = self.node(key)
            if level:
                full = self.shapes
                shapes = [tuple(min(HALF << (level - j), full[j][i] - (p[i] * HALF << (level - j))) for i in range(3))
                          for j in range(level + 1)]
                a = _expand(a, shapes, level)  # type: ignore[arg-type]
            s = [p[i] * HALF << level for i in range(3)]
            out[s[0]:s[0] + a.shape[0], s[1]:s[1] + a.shape[1], s[2]:s[2] + a.shape[2]] = a
        return out
