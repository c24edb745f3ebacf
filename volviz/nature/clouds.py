"""Volumetric C-LOD clouds with morphing and pre-integrated cell projection (Roettger Ch. 11, digest §9).

- **Volume** (§11.3.1): density f and light intensity γ on a grid of (R·a + 1, R·b + 1, R·c + 1) points, R = 2^L;
  a forest of a·b·c octrees of root size R (Roettger's 513 × 513 × 65 clouds are 8 × 8 × 1 roots of 64^3 cells).
  Other sizes are resampled (``CloudVolume.fit``). Leaves are split into 5 tetrahedra with alternating (global)
  parity, so same-level neighbours share face diagonals.
- **Error** (§11.3.2, §11.4): per node the maximum deviation Δ of both fields at the 19 non-corner lattice points
  (edge midpoints, face centres, centroid) from the node's own 5-tet interpolation; propagated bottom-up with
  Eq. (11.5) Δ := max(Δ, K_max Δ_child), K_max = C / (2C − ½√3) (Eq. 11.4, C > √3).
- **Refinement** Eq. (11.1): e = s C max(c Δ, 1) / d, refine if e > 1 (s the node edge, d the Euclidean eye distance
  to its centre). Transparent nodes (density max <= the TF's zero cutoff) are never refined (ZOT).
- **Optical Δ** (``extinction`` = ρ_max > 0): Δ_local is scaled by ρ_max s before the propagation, i.e. Δ becomes the
  optical-depth error of a ray crossing the node. A field deviation δ over a node of edge s changes the pixel's
  opacity by up to about ρ_max δ s — a coarse node's error grows with its size, which the bare scalar Δ ignores (it
  treats a 32-cell node like a 2-cell one): for the same cloud error it draws fewer tetrahedra than the scalar Δ
  (docs/bench/docstring-figures.md, docs/bench/nature.md).
- **Morphing** Eq. (11.6) e' = clamp(e − 1, 0, 1) and the CORRECTED Eq. (11.8) S' = (1 − w) coarse + w S (digest
  §14 erratum), w the minimum e' of all same-level nodes sharing the vertex (unrefined or non-existent = 0) and
  capped by the parent's. Coarse values: edge = mean of its ends, face = mean of the parity diagonal, centroid = mean
  of the central tetrahedron. A T-vertex next to a coarser leaf therefore carries exactly the coarse leaf's linear
  interpolation: the scalar field is continuous across levels (no cracks), and every vertex moves continuously with
  the eye (no popping) — both tested.
- **Visibility** (§11.5): children back to front at every level (a BSP order), roots in a BSP order of the root grid;
  frustum culling and the zero-opacity test per node, on the values drawn: a node is dropped when the morphed
  density cannot exceed the cutoff in it (``fbound``: the largest value the morph gives any of its grid points for
  any weights), not when the data cannot (``fmax``). A leaf whose data is transparent but whose corners carry a
  coarser neighbour's values (T-vertices, morphing) is drawn; dropped, its neighbour's cloud ended at their shared
  face: straight vertical and horizontal seams along the leaves' faces (issue #28; tests/test_cloud_seams.py, the
  figures in docs/bench/docstring-figures.md). It draws a few more leaves, each with a morphed corner above the
  cutoff.
- **Projection**: ``render_cloud_image`` is an exact per-pixel equivalent of pre-integrated projected tetrahedra:
  per leaf and pixel the ray is clipped to the cube and to [near, terrain depth] (volumetric near-plane clipping and
  terrain occlusion are exact), split into its ≤ 3 tetrahedra, and each piece looked up in the 3D pre-integration
  table (s_f, s_b, l') and composited back to front. ``CloudFrame.to_tetmesh`` gives the same leaves as a TetMesh for
  the unstructured PT renderer.
- **Shading** (§11.6): two fields; the table is indexed by one field and the segment length is modulated by the
  other, l' = l · m̄ (m the modulating field over its maximum, averaged over the piece):
  ``"physical"`` (§11.6.1): κ(γ) pre-integrated at ρ = ρ_max, l' = l f / f_max;
  ``"npr"`` (§11.6.2): κ(f) an inverse color ramp, ρ(f) linear and zero below a cutoff, l' = l γ / γ_max.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numba
import numpy as np

from volviz.model.datasets import TetMesh
from volviz.nature import _cloud_kernels as K
from volviz.nature.heightfield import pow2_plus_one, resample_bilinear
from volviz.nature.raster import row_bands, view_params
from volviz.nature.terrain import frustum_planes
from volviz.optics import TransferFunction


def kmax(big_c: float) -> float:
    """Eq. (11.4): K_max = C / (2C − ½√3), the propagation factor; valid for C > √3."""
    if not big_c > math.sqrt(3.0):
        raise ValueError(f"the minimum resolution C must be > sqrt(3) for the error propagation, got {big_c}")
    return big_c / (2.0 * big_c - 0.5 * math.sqrt(3.0))


def _root_size(shape: tuple[int, int, int]) -> int:
    g = 0
    for n in shape:
        g = math.gcd(g, n - 1)
    r = 1
    while g % (2 * r) == 0:
        r *= 2
    return r


@dataclass
class CloudVolume:
    """Density ``f`` and light ``gamma`` (float32, (nx, ny, nz), x fastest in VTK order) on a grid whose sizes minus
    one share a power-of-two factor R >= 2 (the octree root size)."""

    f: np.ndarray
    gamma: np.ndarray
    spacing: tuple[float, float, float] = (1.0, 1.0, 1.0)
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        self.f = np.ascontiguousarray(self.f, dtype=np.float32)
        self.gamma = np.ascontiguousarray(self.gamma, dtype=np.float32)
        if self.f.ndim != 3 or self.f.shape != self.gamma.shape:
            raise ValueError(f"cloud fields must be 3D and of equal shape, got {self.f.shape} and {self.gamma.shape}")
        if min(self.f.shape) < 3:
            raise ValueError(f"cloud volume needs at least 3 points per axis, got {self.f.shape}")
        if _root_size(self.f.shape) < 2:
            raise ValueError(f"cloud volume shape {self.f.shape} has no common power-of-two cell count; use "
                             "CloudVolume.fit")
        if not (np.all(np.isfinite(self.f)) and np.all(np.isfinite(self.gamma))):
            raise ValueError("cloud fields must be finite")
        if self.f.min() < 0:
            raise ValueError("cloud density must be >= 0")
        self.spacing = tuple(float(v) for v in self.spacing)  # type: ignore[assignment]
        self.origin = tuple(float(v) for v in self.origin)  # type: ignore[assignment]
        if min(self.spacing) <= 0:
            raise ValueError(f"spacing must be positive, got {self.spacing}")

    @property
    def shape(self) -> tuple[int, int, int]:
        return tuple(int(v) for v in self.f.shape)  # type: ignore[return-value]

    @property
    def root(self) -> int:
        return _root_size(self.shape)

    @property
    def n_tets_full(self) -> int:
        nx, ny, nz = self.shape
        return 5 * (nx - 1) * (ny - 1) * (nz - 1)

    def bounds(self) -> tuple[float, ...]:
        hi = [o + (n - 1) * s for o, n, s in zip(self.origin, self.shape, self.spacing)]
        return (self.origin[0], hi[0], self.origin[1], hi[1], self.origin[2], hi[2])

    @classmethod
    def fit(cls, f: np.ndarray, gamma: np.ndarray, extent: tuple[float, float, float],
            origin=(0.0, 0.0, 0.0)) -> "CloudVolume":
        """Resample (trilinear, corners kept) every axis to the next 2^k + 1 points over the same ``extent``."""
        shape = tuple(pow2_plus_one(n) for n in f.shape)
        out = []
        for arr in (f, gamma):
            a = np.asarray(arr, dtype=np.float64)
            if a.shape != shape:
                tmp = np.stack([resample_bilinear(a[:, :, k], (shape[0], shape[1])) for k in range(a.shape[2])], axis=2)
                a = np.stack([resample_bilinear(tmp[i], (shape[1], shape[2])) for i in range(shape[0])], axis=0)
            out.append(a.astype(np.float32))
        spacing = tuple(e / (n - 1) for e, n in zip(extent, shape))
        return cls(out[0], out[1], spacing, origin)  # type: ignore[arg-type]


@dataclass
class CloudShading:
    """How the two fields are shaded (§11.6): table field, length-modulating field and the transfer function."""

    mode: str
    tf: Any                      # volviz.optics.TransferFunction over the table field
    cutoff: float = 0.0          # densities <= cutoff are transparent (the ZOT threshold on f)

    @property
    def table_field(self) -> str:
        return "f" if self.mode == "npr" else "gamma"

    @classmethod
    def npr(cls, rho_max: float = 0.08, cutoff: float = 0.04, bright=(1.0, 1.0, 1.0), dark=(0.42, 0.46, 0.56)
            ) -> "CloudShading":
        """§11.6.2: κ(f) an inverse color ramp (bright where thin, dark where dense), ρ(f) zero up to ``cutoff``
        then linear to ``rho_max`` at f = 1; γ modulates the segment length."""
        tf = TransferFunction([0.0, cutoff, 1.0], [bright, bright, dark], [0.0, 0.0, rho_max], name="clouds-npr")
        return cls("npr", tf, cutoff)

    @classmethod
    def physical(cls, rho_max: float = 0.08, color=(1.0, 1.0, 1.0), dark=(0.25, 0.28, 0.35)) -> "CloudShading":
        """§11.6.1: κ(γ) pre-integrated at the maximum optical density ρ_max; f modulates the length."""
        tf = TransferFunction([0.0, 1.0], [dark, color], [rho_max, rho_max], name="clouds-physical")
        return cls("physical", tf, 0.0)


@dataclass
class CloudFrame:
    """One frame of the cloud LOD: the visible leaves in back-to-front order and the morphed fields."""

    leaves: np.ndarray           # (n, 4) int64: level, a, b, c
    lod: "CloudLOD"
    stats: dict[str, float] = field(default_factory=dict)

    @property
    def n_tets(self) -> int:
        return 5 * int(len(self.leaves))

    def to_tetmesh(self, which: str = "f", eye: Any = None):
        """The leaves as a ``TetMesh`` (5 tets each, alternating parity) carrying the morphed ``which`` field;
        returns (TetMesh, the other field per vertex). With ``eye`` the tets are in back-to-front order (leaves
        back to front; per leaf the corner tets behind the central one, the central one, then those in front), ready
        for PT with ``order=np.arange(n)``."""
        lod = self.lod
        vol = lod.volume
        nx, ny, nz = vol.shape
        root = vol.root
        lv, a, b, c = (self.leaves[:, k] for k in range(4))
        s = root >> lv
        corners = np.empty((len(self.leaves), 8), dtype=np.int64)
        for q in range(8):
            i, j, k = q >> 2, (q >> 1) & 1, q & 1
            corners[:, q] = ((a + i) * s * ny + (b + j) * s) * nz + (c + k) * s
        even = np.array([[0, 6, 5, 3], [4, 0, 6, 5], [2, 0, 6, 3], [1, 0, 5, 3], [7, 6, 5, 3]])
        odd = np.array([[4, 2, 1, 7], [0, 4, 2, 1], [6, 4, 2, 7], [5, 4, 1, 7], [3, 2, 1, 7]])
        par = ((a + b + c) % 2).astype(bool)
        local = np.where(par[:, None, None], odd[None], even[None])  # (n, 5, 4) corner indices
        if eye is not None:
            # eye in leaf-local coordinates; a corner tet is in front of the central one iff the eye lies on the
            # corner's side of the plane through the corner's three neighbours: sum_k |u_k - q_k| < 1 with the
            # absolute values opened as inside the cube (a linear function, valid beyond the cube)
            p0 = np.asarray(vol.origin) + np.stack([a, b, c], 1) * s[:, None] * np.asarray(vol.spacing)
            u = (np.asarray(eye, dtype=np.float64) - p0) / (s[:, None] * np.asarray(vol.spacing))
            key = np.zeros((len(self.leaves), 5))
            for t in range(1, 5):
                qt = local[:, t, 0]
                cq = np.stack([qt >> 2, (qt >> 1) & 1, qt & 1], 1)
                front = np.where(cq == 0, u, 1.0 - u).sum(1) < 1.0
                key[:, t] = np.where(front, 1.0, -1.0)
            local = np.take_along_axis(local, np.argsort(key, axis=1, kind="stable")[:, :, None], axis=1)
        tets = corners[np.arange(len(self.leaves))[:, None, None], local]
        tets = tets.reshape(-1, 4)
        ids, inv = np.unique(tets, return_inverse=True)
        xi, rem = np.divmod(ids, ny * nz)
        yi, zi = np.divmod(rem, nz)
        pts = np.stack([vol.origin[0] + xi * vol.spacing[0], vol.origin[1] + yi * vol.spacing[1],
                        vol.origin[2] + zi * vol.spacing[2]], axis=1)
        vf, vg = lod.morphed
        main, other = (vf, vg) if which == "f" else (vg, vf)
        return (TetMesh(pts, inv.reshape(-1, 4), main.ravel()[ids].astype(np.float64), name=which,
                        source="cloud C-LOD"), other.ravel()[ids].astype(np.float64))


class CloudLOD:
    """Precomputed octree errors and the per-frame refinement, morphing and back-to-front leaf list."""

    def __init__(self, volume: CloudVolume, big_c: float = 4.0, small_c: float = 8.0, cutoff: float = 0.0,
                 gamma_weight: float = 1.0, geomorph: bool = True, extinction: float = 0.0) -> None:
        self.volume = volume
        self.big_c = float(big_c)
        self.small_c = float(small_c)
        self.cutoff = float(cutoff)
        self.geomorph = bool(geomorph)
        self.k = kmax(self.big_c)
        root = volume.root
        self.levels = int(round(math.log2(root)))
        self.roots = np.array([(n - 1) // root for n in volume.shape], dtype=np.int64)
        sizes = [int(np.prod(self.roots << lv)) for lv in range(self.levels)]
        self.off = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        total = int(self.off[-1])
        f, g = volume.f, volume.gamma
        g_range = float(g.max() - g.min())
        f_range = float(f.max() - f.min())
        gw = gamma_weight * (f_range / g_range if g_range > 0 and f_range > 0 else 1.0)
        self.delta_local = np.zeros(total)
        K.node_stats(f, g, gw, root, self.levels, self.roots, self.off, self.delta_local)
        self.fmax = np.zeros(total)          # the data's maximum per node: transparent nodes are never refined
        K.box_max(f, root, self.levels, self.roots, self.off, self.fmax)
        hi = np.empty_like(f)
        K.morph_bound(f, root, self.levels, self.roots, hi)
        self.fbound = np.zeros(total)        # the morphed field's maximum per node: the zero-opacity test's bound
        K.box_max(hi, root, self.levels, self.roots, self.off, self.fbound)
        self.extinction = float(extinction)
        if self.extinction > 0:  # optical deviation: Δ ρ_max s, the optical-depth error along the node's edge
            unit = float(max(volume.spacing))
            for lv in range(self.levels):
                self.delta_local[self.off[lv]:self.off[lv + 1]] *= self.extinction * (root >> lv) * unit
        self.delta = self.delta_local.copy()
        K.propagate(self.delta, self.levels, self.roots, self.off, self.k)
        self._state = np.zeros(total, dtype=np.int8)
        self._eprime = np.zeros(total)
        self._nodes = np.zeros((max(1024, total // 8), 4), dtype=np.int64)
        self._leaves = np.zeros((65536, 4), dtype=np.int64)
        self._stack = np.zeros((8 * (self.levels + 2) + 8, 4), dtype=np.int64)
        self._vf = np.zeros_like(f)
        self._vg = np.zeros_like(g)
        self._count = 0

    @property
    def morphed(self) -> tuple[np.ndarray, np.ndarray]:
        return self._vf, self._vg

    def _root_order(self, eye: np.ndarray) -> np.ndarray:
        """A BSP (back-to-front) order of the root grid: per axis the slabs away from the eye first."""
        vol = self.volume
        orders = []
        for ax in range(3):
            n = int(self.roots[ax])
            size = vol.root * vol.spacing[ax]
            k = int(np.clip(np.floor((eye[ax] - vol.origin[ax]) / size), -1, n))
            if k >= n:
                orders.append(list(range(n)))
            elif k < 0:
                orders.append(list(range(n - 1, -1, -1)))
            else:
                orders.append(list(range(0, k)) + list(range(n - 1, k, -1)) + [k])
        return np.array([(i, j, k) for i in orders[0] for j in orders[1] for k in orders[2]], dtype=np.int64)

    def refinement_thresholds(self) -> np.ndarray:
        """Per stored node (``off`` order) the distance below which Eq. (11.1) refines it, as float32: e = num / d
        with num = s C max(c Δ, 1) (s the node's longest edge), so e > 1 iff d < num; 0 for transparent nodes
        (fmax <= cutoff, never refined). ``decide``'s test in closed form, for a renderer that computes the morph
        weights e' (Eq. 11.6) itself from the eye; cached until C, c or the cutoff change."""
        key = (self.big_c, self.small_c, self.cutoff)
        if getattr(self, "_thresholds_key", None) != key:
            vol = self.volume
            edge = np.concatenate([np.full(int(self.off[lv + 1] - self.off[lv]),
                                           (vol.root >> lv) * max(vol.spacing)) for lv in range(self.levels)])
            num = edge * self.big_c * np.maximum(self.small_c * self.delta, 1.0)
            self._thresholds = np.where(self.fmax > self.cutoff, num, 0.0).astype(np.float32)
            self._thresholds_key = key
        return self._thresholds

    def update(self, camera: Any, size: tuple[int, int] | None = None, cull: bool = True, full: bool = False,
               morph: bool = True) -> CloudFrame:
        """Refine, morph and list the visible leaves for ``camera`` (``full``: every cell, the reference). With
        ``cull`` and a ``size``, only the leaves in the view frustum are listed and only their values are morphed
        (``morphed`` holds stale values elsewhere). Without ``morph`` the fields are left unmorphed and the leaves
        whose morphed corners are all transparent are listed too: for a renderer that morphs the leaves itself
        (``resources/shaders/cloud_leaf_vs.glsl``)."""
        t0 = time.perf_counter()
        eye = np.asarray(camera.position, dtype=np.float64)
        vol = self.volume
        origin = np.asarray(vol.origin, dtype=np.float64)
        spacing = np.asarray(vol.spacing, dtype=np.float64)
        planes = frustum_planes(camera, size) if (cull and size is not None) else np.zeros((0, 4))
        # reset the previous frame's nodes only
        prev = self._nodes[: self._count]
        if len(prev):
            keep = prev[:, 0] < self.levels
            lv = prev[keep, 0]
            nb, nc = self.roots[1] << lv, self.roots[2] << lv
            idx = self.off[lv] + (prev[keep, 1] * nb + prev[keep, 2]) * nc + prev[keep, 3]
            self._state[idx] = 0
            self._eprime[idx] = 0.0
        if full:
            count = 0
            self._vf[...] = vol.f
            self._vg[...] = vol.gamma
        else:
            while True:
                count = K.decide(self.delta, self.fmax, self.cutoff, vol.root, self.levels, self.roots, self.off,
                                 origin, spacing, eye, self.big_c, self.small_c, self.geomorph, self._state,
                                 self._eprime, self._nodes)
                if count >= 0:
                    break
                self._state.fill(0)
                self._eprime.fill(0.0)
                self._nodes = np.zeros((2 * len(self._nodes), 4), dtype=np.int64)
            if morph:
                K.morph(vol.f, vol.gamma, vol.root, self.roots, self.off, self._state, self._eprime, self._nodes,
                        count, self._vf, self._vg, origin, spacing, planes)
        self._count = count
        t1 = time.perf_counter()
        order = self._root_order(eye)
        while True:
            n = K.emit(self.fbound, self.cutoff, vol.root, self.levels, self.roots, self.off, origin, spacing, eye,
                       planes, self._state, order, self._vf, full, self._leaves, self._stack, morph or full)
            if n >= 0:
                break
            self._leaves = np.zeros((2 * len(self._leaves), 4), dtype=np.int64)
        t2 = time.perf_counter()
        stats = {"nodes": float(count), "leaves": float(n), "tets": 5.0 * n, "lod_s": t1 - t0, "emit_s": t2 - t1}
        return CloudFrame(self._leaves[:n].copy(), self, stats)


def build_cloud_table(shading: CloudShading, l_max: float, n_s: int = 64, n_l: int = 256):
    """The 3D pre-integration table over the table field's range [0, 1] (64 x 64 x 256 by default)."""
    # the table kernels (Numba): loaded when a cloud table is built
    from volviz.optics import build_table3d

    return build_table3d(shading.tf, n_s=n_s, n_l=n_l, l_max=float(l_max), s_range=(0.0, 1.0))


def render_cloud_image(frame: CloudFrame, shading: CloudShading, table: Any, camera: Any, size: tuple[int, int],
                       depth: np.ndarray | None = None) -> np.ndarray:
    """Premultiplied RGBA (H, W, 4) float64 of the frame's leaves over an optional opaque depth (terrain)."""
    w, h = (int(v) for v in size)
    lod = frame.lod
    vol = lod.volume
    vf, vg = lod.morphed
    if shading.table_field == "f":
        va, vm = vf, vg
        m_scale = 1.0 / max(float(vol.gamma.max()), 1e-12)
    else:
        va, vm = vg, vf
        m_scale = 1.0 / max(float(vol.f.max()), 1e-12)
    a_cut = shading.cutoff if shading.table_field == "f" else -np.inf
    vp = view_params(camera, (w, h))
    far = camera.clipping_range[1]
    dep = np.full((h, w), far) if depth is None else np.minimum(np.asarray(depth, dtype=np.float64), far)
    img = np.zeros((h, w, 4))
    if len(frame.leaves):
        rgba = np.ascontiguousarray(table.rgba)
        K.render(frame.leaves, len(frame.leaves), vol.root,
                 np.asarray(vol.origin, float), np.asarray(vol.spacing, float),
                 va, vm, m_scale, a_cut, rgba, float(table.s_lo), float(table.ds), float(table.dl),
                 camera.rays((w, h)).as_array(), vp, dep, row_bands(h, 16), w, h, img,
                 numba.get_num_threads())
    return img
