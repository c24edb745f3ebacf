"""Transparency modes for many semi-transparent isosurfaces from many volumes (libMini note §4), on per-pixel
fragment lists from the CPU rasteriser. Every mode sees the fragments of ALL surfaces of ALL volumes at once (each
"pass" runs across all volumes), so overlapping volumes are per-pixel exact under the mode's optical model.

Per pixel, with B the opaque result (nearest opaque fragment, else the background; premultiplied RGBA) and the
transparent fragments i in front of it, each with opacity α_i and premultiplied emission e_i = α_i·c_i:

- ``"exact"``  (reference; per-pixel sorted fragments = depth peeling to full depth): front-to-back "over" in depth
  order, C = Σ_i e_i Π_{j<i}(1 − α_j) + Π_i(1 − α_i)·B.
- ``"2pass"``  (naive baseline): opaque pass, then unsorted blending in draw (triangle) order, C ← e_i + (1 − α_i)·C.
  Correct only for depth complexity ≤ 1; depends on triangle order.
- ``"3pass"``  (order-independent): C = Π_i(1 − α_i)·B + Σ_i e_i (self-attenuation neglected). Its error against
  exact is Σ_i e_i (1 − Π_{j<i}(1 − α_j)) ≥ 0 per channel.
- ``"4pass"``  (order-independent, depth cue): as 3pass, but the sum runs only over fragments with depth ≤ z_b, the
  front-most back face of the transparent surfaces (z_b = ∞ if the pixel has no back face).

Color channels of the order-independent sums saturate at 1 (as a fixed-point frame buffer does); the alpha channel
is 1 − Π(1 − α_i)(1 − α_B) for 3pass/4pass, the "over" result for the others.

Shading: ``"spectrum"`` gives transparent fragments the iso-spectrum opacity α(μ) = 1 − clamp(μ^a − b, 0, 1) with
(a, b) least-squares fitted per surface opacity (``volviz.iso.spectrum``); ``"flat"`` uses the surface opacity as is.
Colors are lit by a head light, c·(k_a + (1 − k_a)·μ) with μ = |cos θ| between normal and view ray (``lighting``).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
from numba import njit, prange

from volviz.iso.extract import IsoMesh, merge_meshes
from volviz.iso.raster import clip_near_plane, rasterize
from volviz.iso.spectrum import fit_spectrum, spectrum_alpha
from volviz.model.camera import Camera

__all__ = ["MODES", "Fragments", "fragments", "composite", "render", "render_modes", "IsoRenderStats"]

MODES = ("2pass", "3pass", "4pass", "exact")
_MODE_ID = {"exact": 0, "2pass": 1, "3pass": 2, "4pass": 3}
AMBIENT = 0.25


@dataclass
class Fragments:
    """Per-pixel fragment lists of one view (CSR by pixel, draw order kept inside each pixel)."""

    size: tuple[int, int]
    ptr: np.ndarray          # (W·H + 1,) start of each pixel's fragments
    depth: np.ndarray        # (k,) view depth
    rgba: np.ndarray         # (k, 4) premultiplied (α·c, α)
    opaque: np.ndarray       # (k,) bool
    back: np.ndarray         # (k,) bool: fragment of a back-facing triangle
    n_triangles: int = 0
    n_opaque_triangles: int = 0
    seconds: float = 0.0


@dataclass
class IsoRenderStats:
    mode: str
    seconds: float
    triangles: int
    triangles_drawn: int
    fragments: int
    extra: dict = field(default_factory=dict)


def _view_mu(points: np.ndarray, normals: np.ndarray, camera: Camera) -> np.ndarray:
    _, _, fwd = camera.frame()
    if camera.parallel:
        v = np.broadcast_to(fwd, points.shape)
    else:
        v = points - camera.position
        v = v / np.maximum(np.linalg.norm(v, axis=1, keepdims=True), 1e-300)
    return np.abs(np.einsum("ij,ij->i", normals, v))


def _back_facing(points: np.ndarray, tris: np.ndarray, normals: np.ndarray, camera: Camera) -> np.ndarray:
    """A triangle is a back face when its (vertex-normal oriented) normal points away from the eye."""
    if len(tris) == 0:
        return np.zeros(0, bool)
    a, b, c = points[tris[:, 0]], points[tris[:, 1]], points[tris[:, 2]]
    gn = np.cross(b - a, c - a)
    vn = normals[tris[:, 0]] + normals[tris[:, 1]] + normals[tris[:, 2]]
    gn = np.where((np.einsum("ij,ij->i", gn, vn) < 0.0)[:, None], -gn, gn)
    _, _, fwd = camera.frame()
    view = np.broadcast_to(fwd, gn.shape) if camera.parallel else (a + b + c) / 3.0 - camera.position
    return np.einsum("ij,ij->i", gn, view) > 0.0


def fragments(meshes: Sequence[IsoMesh], camera: Camera, size: tuple[int, int] = (256, 256),
              shading: str = "spectrum", lighting: bool = True) -> Fragments:
    """Rasterise all surfaces of all volumes once; fragment colors and opacities per the shading model."""
    if shading not in ("spectrum", "flat"):
        raise ValueError(f"shading must be 'spectrum' or 'flat', got {shading!r}")
    t0 = time.perf_counter()
    w, h = (int(v) for v in size)
    pts, tris, nrm, sid = merge_meshes(meshes)
    n_input = len(tris)
    n_opaque = int(sum(m.n_triangles for m in meshes if m.style.opacity >= 1.0))
    _, _, fwd = camera.frame()
    n_pts = len(pts)
    pts, tris, nrm, parent = clip_near_plane(pts, tris, nrm, np.asarray(camera.position), fwd,
                                             camera.clipping_range[0])
    sid = sid[parent]  # triangles crossing the near plane are cut there, as OpenGL does
    if len(pts) > n_pts:  # normals interpolated along cut edges: unit length again
        nrm[n_pts:] /= np.maximum(np.linalg.norm(nrm[n_pts:], axis=1, keepdims=True), 1e-300)
    mu_v = _view_mu(pts, nrm, camera) if len(pts) else np.zeros(0)
    scr = camera.project(pts, (w, h)) if len(pts) else np.zeros((0, 3))
    pix, dep, mu, tid = rasterize(scr, mu_v, tris, (w, h), perspective=not camera.parallel)
    mu = np.clip(mu, 0.0, 1.0)
    s = sid[tid]
    styles = [m.style for m in meshes]
    color = np.array([st.color for st in styles], np.float64).reshape(-1, 3)
    opac = np.array([st.opacity for st in styles], np.float64)
    is_opaque = opac >= 1.0
    alpha = opac[s].copy()
    if shading == "spectrum":
        for k, st in enumerate(styles):
            if 0.0 < st.opacity < 1.0:
                sel = s == k
                fit = fit_spectrum(float(st.opacity))
                alpha[sel] = spectrum_alpha(mu[sel], fit.a, fit.b)
    shade = (AMBIENT + (1.0 - AMBIENT) * mu) if lighting else np.ones_like(mu)
    rgba = np.empty((len(pix), 4))
    rgba[:, :3] = color[s] * (alpha * shade)[:, None]
    rgba[:, 3] = alpha
    order = np.argsort(pix, kind="stable")  # keeps draw order inside each pixel
    ptr = np.zeros(w * h + 1, np.int64)
    np.cumsum(np.bincount(pix, minlength=w * h), out=ptr[1:])
    back = _back_facing(pts, tris, nrm, camera)[tid]
    return Fragments((w, h), ptr, np.ascontiguousarray(dep[order]), np.ascontiguousarray(rgba[order]),
                     np.ascontiguousarray(is_opaque[s][order]), np.ascontiguousarray(back[order]),
                     n_input, n_opaque, time.perf_counter() - t0)


@njit(cache=True, nogil=True, parallel=True)
def _composite(ptr: np.ndarray, depth: np.ndarray, rgba: np.ndarray, opaque: np.ndarray, back: np.ndarray,
               bg: np.ndarray, mode: int, out: np.ndarray) -> None:
    n_pix = ptr.shape[0] - 1
    for p in prange(n_pix):
        a, b = ptr[p], ptr[p + 1]
        # pass 1: opaque geometry (nearest opaque fragment) over the background
        zop = np.inf
        base = bg.copy()
        for i in range(a, b):
            if opaque[i] and depth[i] < zop:
                zop = depth[i]
                for ch in range(4):
                    base[ch] = rgba[i, ch]
        col = np.zeros(4)
        if mode == 0:  # exact: sorted front to back
            idx = np.argsort(depth[a:b]) + a
            trans = 1.0
            for i in idx:
                if opaque[i] or depth[i] >= zop:
                    continue
                for ch in range(4):
                    col[ch] += trans * rgba[i, ch]
                trans *= 1.0 - rgba[i, 3]
            for ch in range(4):
                col[ch] += trans * base[ch]
        elif mode == 1:  # 2-pass: blend in draw order over the opaque result
            for ch in range(4):
                col[ch] = base[ch]
            for i in range(a, b):
                if opaque[i] or depth[i] >= zop:
                    continue
                for ch in range(4):
                    col[ch] = rgba[i, ch] + (1.0 - rgba[i, 3]) * col[ch]
        else:  # 3-pass / 4-pass
            zb = np.inf
            if mode == 3:  # pass 3: front-most back face of the transparent surfaces
                for i in range(a, b):
                    if back[i] and not opaque[i] and depth[i] < zop and depth[i] < zb:
                        zb = depth[i]
            att = 1.0
            for i in range(a, b):  # pass 2: product of attenuations
                if not opaque[i] and depth[i] < zop:
                    att *= 1.0 - rgba[i, 3]
            for ch in range(3):
                col[ch] = att * base[ch]
            for i in range(a, b):  # pass 3 (4): sum of emissions (up to z_b)
                if not opaque[i] and depth[i] < zop and depth[i] <= zb:
                    for ch in range(3):
                        col[ch] += rgba[i, ch]
            for ch in range(3):
                col[ch] = min(col[ch], 1.0)
            col[3] = 1.0 - att * (1.0 - base[3])
        for ch in range(4):
            out[p, ch] = col[ch]


def composite(frags: Fragments, mode: str = "exact", background: Sequence[float] = (0.0, 0.0, 0.0, 0.0)
              ) -> np.ndarray:
    """Image (H, W, 4) premultiplied float64 of one mode from the fragment lists; row 0 at the top."""
    if mode not in _MODE_ID:
        raise ValueError(f"unknown transparency mode {mode!r}; choose from {MODES}")
    bg = np.asarray(background, dtype=np.float64).reshape(4)
    w, h = frags.size
    out = np.zeros((w * h, 4))
    _composite(frags.ptr, frags.depth, frags.rgba, frags.opaque, frags.back, bg, _MODE_ID[mode], out)
    return out.reshape(h, w, 4)


def triangles_drawn(frags: Fragments, mode: str) -> int:
    """Triangles a GPU would submit in this mode: opaque once, transparent once per pass (exact: per peeled layer)."""
    n_t = frags.n_triangles - frags.n_opaque_triangles
    if mode == "exact":
        counts = np.diff(frags.ptr)
        layers = int(counts.max()) if counts.size else 0
        return frags.n_opaque_triangles + 2 * layers * n_t  # depth peeling: 2 passes per layer
    passes = {"2pass": 1, "3pass": 2, "4pass": 3}[mode]
    return frags.n_opaque_triangles + passes * n_t


def render(meshes: Sequence[IsoMesh], camera: Camera, size: tuple[int, int] = (256, 256), mode: str = "exact",
           background: Sequence[float] = (0.0, 0.0, 0.0, 0.0), shading: str = "spectrum", lighting: bool = True
           ) -> tuple[np.ndarray, IsoRenderStats]:
    """Rasterise and composite in one call: image (H, W, 4) premultiplied float64 and its statistics."""
    t0 = time.perf_counter()
    fr = fragments(meshes, camera, size, shading=shading, lighting=lighting)
    img = composite(fr, mode, background)
    return img, IsoRenderStats(mode, time.perf_counter() - t0, fr.n_triangles, triangles_drawn(fr, mode), len(fr.depth))


def render_modes(meshes: Sequence[IsoMesh], camera: Camera, size: tuple[int, int] = (256, 256),
                 modes: Sequence[str] = MODES, background: Sequence[float] = (0.0, 0.0, 0.0, 0.0),
                 shading: str = "spectrum", lighting: bool = True) -> dict[str, np.ndarray]:
    """Images of several modes sharing one rasterisation (for side-by-side comparisons)."""
    fr = fragments(meshes, camera, size, shading=shading, lighting=lighting)
    return {m: composite(fr, m, background) for m in modes}
