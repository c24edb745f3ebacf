"""View-dependent level of detail for extracted isosurfaces with geomorphing (libMini note, "4D Visualization":
fewer triangles far away, interpolation between the two nearest levels against popping).

Levels come from nested vertex clustering: level k merges the vertices of each cube of edge h·2^(k−1) (h chosen so
level 1 has about ``ratio`` of the triangles) into their mean; a triangle whose corners fall into three different
cubes survives (duplicates removed). The cubes of level k+1 contain whole cubes of level k, so every level-k vertex has
one parent vertex on level k+1: its geomorph target. The displayed mesh at a continuous level λ = k + f uses level
k's topology with positions (1 − f)·p + f·parent(p) and normals blended alike; at f = 1 each triangle coincides with a
level-(k+1) triangle or has collapsed to zero area, so switching to level k+1 moves no vertex. (Quadric decimation
gives better coarse meshes but no vertex correspondence; closest-point targets fold and pop:
docs/bench/docstring-figures.md.)
Levels are chosen per surface from its screen size: the bounding sphere's projected radius r (pixels) asks for about
``triangles_per_pixel2 · π r²`` triangles and λ interpolates log(triangles) between the levels. (The note's C-LOD
refines per region; this picks one level per surface, so a surface far away is coarse everywhere.)
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from volviz.iso.extract import IsoMesh
from volviz.model.camera import Camera

__all__ = ["LodChain", "build_lod", "screen_radius", "select_level", "lod_mesh", "lod_meshes"]


@dataclass
class LodChain:
    """Levels finest first; ``parent[k]`` maps level k's vertices to level k+1's (the geomorph targets)."""

    levels: list[IsoMesh]
    parent: list[np.ndarray]
    centre: np.ndarray
    radius: float

    @property
    def triangle_counts(self) -> list[int]:
        return [m.n_triangles for m in self.levels]


def _unit(n: np.ndarray) -> np.ndarray:
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)


def _cluster(mesh: IsoMesh, key: np.ndarray) -> tuple[IsoMesh, np.ndarray]:
    """Merge the vertices with equal integer ``key`` rows; returns the coarse mesh and the vertex → cluster map."""
    _, inv = np.unique(key, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    n = int(inv.max()) + 1
    cnt = np.bincount(inv, minlength=n).astype(np.float64)[:, None]
    pts = np.zeros((n, 3))
    nrm = np.zeros((n, 3))
    np.add.at(pts, inv, mesh.points)
    np.add.at(nrm, inv, mesh.normals)
    t = inv[mesh.triangles]
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 0] != t[:, 2])]
    if len(t):
        _, first = np.unique(np.sort(t, axis=1), axis=0, return_index=True)
        t = t[np.sort(first)]
    return IsoMesh(pts / cnt, t.reshape(-1, 3), _unit(nrm), mesh.style, mesh.label), inv


def build_lod(mesh: IsoMesh, n_levels: int = 4, ratio: float = 0.25) -> LodChain:
    """Nested vertex-clustering levels (each about ``ratio`` of the previous triangles) with parent maps."""
    if not 0.0 < ratio < 1.0 or n_levels < 1:
        raise ValueError("LOD needs 0 < ratio < 1 and n_levels >= 1")
    levels, parent = [mesh], []
    if mesh.n_triangles:
        lo, hi = mesh.points.min(0), mesh.points.max(0)
        e = mesh.points[mesh.triangles[:, 1]] - mesh.points[mesh.triangles[:, 0]]
        h = float(np.median(np.linalg.norm(e, axis=1))) / math.sqrt(ratio)  # cube edge of level 1
        rel = (mesh.points - lo) / max(h, 1e-12)
        cur, to_cur = mesh, np.arange(len(mesh.points))  # level-0 vertex -> its vertex on the current level
        for k in range(1, n_levels):
            key0 = np.floor(rel / 2 ** (k - 1)).astype(np.int64)
            key = np.empty((len(cur.points), 3), np.int64)
            key[to_cur] = key0  # the cubes nest, so all members of a current vertex share one key
            coarse, inv = _cluster(cur, key)
            if coarse.n_triangles < 8:
                break
            levels.append(coarse)
            parent.append(inv)
            cur, to_cur = coarse, inv[to_cur]
    else:
        lo = hi = np.zeros(3)
    return LodChain(levels, parent, 0.5 * (lo + hi), 0.5 * float(np.linalg.norm(hi - lo)))


def screen_radius(chain: LodChain, camera: Camera, size: tuple[int, int]) -> float:
    """Projected radius in pixels of the surface's bounding sphere."""
    h = int(size[1])
    if camera.parallel:
        return chain.radius / camera.parallel_scale * h / 2.0
    _, _, fwd = camera.frame()
    z = max(float((chain.centre - camera.position) @ fwd), camera.clipping_range[0], 1e-12)
    return chain.radius / (z * math.tan(math.radians(camera.view_angle) / 2.0)) * h / 2.0


def select_level(chain: LodChain, camera: Camera, size: tuple[int, int], triangles_per_pixel2: float = 0.25) -> float:
    """Continuous level λ in [0, n_levels − 1] for this view (0 = finest): log-linear in the triangle counts."""
    wanted = max(triangles_per_pixel2 * math.pi * screen_radius(chain, camera, size) ** 2, 1.0)
    logs = np.log(np.maximum(np.array(chain.triangle_counts, np.float64), 1.0))
    if len(logs) == 1 or math.log(wanted) >= logs[0]:
        return 0.0
    if math.log(wanted) <= logs[-1]:
        return float(len(logs) - 1)
    return float(np.interp(-math.log(wanted), -logs, np.arange(len(logs))))


def lod_mesh(chain: LodChain, level: float) -> IsoMesh:
    """The geomorphed mesh at continuous level λ (topology of floor(λ), vertices morphed toward their parents)."""
    lam = float(min(max(level, 0.0), len(chain.levels) - 1))
    k = int(math.floor(lam))
    f = lam - k
    m = chain.levels[k]
    if f == 0.0 or k >= len(chain.parent):
        return m
    up = chain.levels[k + 1]
    par = chain.parent[k]
    p = (1.0 - f) * m.points + f * up.points[par]
    n = _unit((1.0 - f) * m.normals + f * up.normals[par])
    return IsoMesh(p, m.triangles, n, m.style, m.label, {"lod_level": lam})


def lod_meshes(chains: Sequence[LodChain], camera: Camera, size: tuple[int, int],
               triangles_per_pixel2: float = 0.25) -> list[IsoMesh]:
    """Per surface: the level its screen size asks for, geomorphed."""
    return [lod_mesh(c, select_level(c, camera, size, triangles_per_pixel2)) for c in chains]
