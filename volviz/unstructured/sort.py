"""Visibility sorting of tetrahedra, back to front, for perspective and orthographic views (Numba).

Roettger §8.1 and Guthe §4.3 (§3.1 of the thesis):

- ``"centroid"``: approximate, sort by the depth of the cell centroid (Wittenbrink's "numerical" sort).
- ``"power"``: approximate, sort by the power distance |E - c|^2 - r^2 of the eye to the circumsphere (perspective;
  for orthographic views the power "depth" (c . f) + r, i.e. the far end of the sphere along the view direction).
- ``"mpvo"``: Williams' MPVO as a topological sort (Kahn) of the face-adjacency graph, each shared face directed by the
  side of its plane the eye lies on (``volviz.unstructured.mpvo``). Correct for convex, connected, acyclic meshes.
- Non-convex or disconnected meshes (``"mpvo"`` adds them automatically unless the mesh is convex): the missing
  relations between boundary faces, where a ray leaves the mesh (cell A) and re-enters it later (cell B): "B before
  A". By default they come from object space (``volviz.unstructured.boundary_pairs``: the overlapping exit/entry
  pairs of the boundary faces off the convex hull, found through a grid sized by the number of those faces), so the
  cost does not depend on the window size (issue #29) and the order is right for every ray of the view.
  ``nonconvex="sample"`` keeps the previous image-space variant of XMPVO (Cook, Max, Silva, Williams 2004, "SXMPVO"):
  every boundary face ray-cast at every pixel centre of the image it covers, each entry face after an exit face along
  a pixel ray giving a relation; exact for that image's pixel centres, at a cost that grows with the window
  (``docs/bench/docstring-figures.md``); the tests use it as the witness of the object-space relations.
- Visibility cycles (real ones, or ones created by combining relations that hold on different rays) stall Kahn's
  algorithm. They are broken by emitting the farthest remaining cell (by centroid depth); ``SortResult.cycles`` counts
  the breaks.
- Per frame only the order is a new array: the per-cell work arrays (state byte, in-degree, Kahn's stack) are kept
  on the topology and reused (``_take_work``), so a frame neither allocates nor pages them in again.
"""
from __future__ import annotations

import threading
import time
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from functools import partial

import numpy as np
from numba import njit, prange

from volviz.model.camera import Camera
from volviz.model.datasets import TetMesh
from volviz.unstructured import mpvo
from volviz.unstructured.boundary_pairs import inner_boundary, object_relations
from volviz.unstructured.mpvo import add_extra, face_sides, kahn_into
from volviz.unstructured.reference import screen_bboxes
from volviz.unstructured.topology import FACES, Topology, topology

METHODS = ("mpvo", "centroid", "power")
NONCONVEX = ("auto", "object", "sample", "none")


@dataclass
class SortResult:
    """A back-to-front order of cell ids and what it took."""

    order: np.ndarray                 # (m,) cell ids back to front: int32 (mpvo; int64 from 2^31 cells on) or int64
    method: str
    cycles: int = 0                   # Kahn stalls broken by force-emitting a cell
    boundary_relations: int = 0       # distinct relations sampled between boundary faces (non-convex handling)
    seconds: float = 0.0
    stages: dict[str, float] = field(default_factory=dict)   # mpvo: seconds of "relations", "sides", "kahn"
    #                                      (large meshes: "sides", "relations_wait" for the relations made beside them)


# --------------------------------------------------------------------------------------------------------------------
# approximate sorts
@njit(cache=True, nogil=True, parallel=True)
def _centroid_keys(centroid: np.ndarray, eye: np.ndarray, fwd: np.ndarray, parallel: bool) -> np.ndarray:
    m = len(centroid)
    key = np.empty(m)
    for i in prange(m):
        if parallel:
            key[i] = -(centroid[i, 0] * fwd[0] + centroid[i, 1] * fwd[1] + centroid[i, 2] * fwd[2])
        else:
            dx = centroid[i, 0] - eye[0]
            dy = centroid[i, 1] - eye[1]
            dz = centroid[i, 2] - eye[2]
            key[i] = -(dx * dx + dy * dy + dz * dz)
    return key


@njit(cache=True, nogil=True, parallel=True)
def _power_keys(cc: np.ndarray, r2: np.ndarray, eye: np.ndarray, fwd: np.ndarray, parallel: bool) -> np.ndarray:
    m = len(cc)
    key = np.empty(m)
    for i in prange(m):
        if parallel:
            key[i] = -(cc[i, 0] * fwd[0] + cc[i, 1] * fwd[1] + cc[i, 2] * fwd[2] + np.sqrt(r2[i]))
        else:
            dx = cc[i, 0] - eye[0]
            dy = cc[i, 1] - eye[1]
            dz = cc[i, 2] - eye[2]
            key[i] = -(dx * dx + dy * dy + dz * dz - r2[i])
    return key


# --------------------------------------------------------------------------------------------------------------------
# image-space boundary relations (SXMPVO-style)
@njit(cache=True, nogil=True, parallel=True)
def _boundary_fragments(pts: np.ndarray, tets: np.ndarray, bfaces: np.ndarray, bbox: np.ndarray, off: np.ndarray,
                        rb: np.ndarray, near: float, far: float, width: int,
                        pix: np.ndarray, depth: np.ndarray) -> np.ndarray:
    """Ray-cast every boundary triangle at the pixel centres of its box (Moller-Trumbore, edges inclusive).

    Triangle b writes its fragments to slots off[b]...; returns the number written per triangle."""
    nb = len(bfaces)
    cnt = np.zeros(nb, np.int64)
    for b in prange(nb):
        if bbox[b, 0] > bbox[b, 1] or bbox[b, 2] > bbox[b, 3]:
            continue
        t_id = bfaces[b, 0]
        f = bfaces[b, 1]
        i0 = tets[t_id, FACES[f, 0]]
        i1 = tets[t_id, FACES[f, 1]]
        i2 = tets[t_id, FACES[f, 2]]
        v00, v01, v02 = pts[i0, 0], pts[i0, 1], pts[i0, 2]
        e10, e11, e12 = pts[i1, 0] - v00, pts[i1, 1] - v01, pts[i1, 2] - v02
        e20, e21, e22 = pts[i2, 0] - v00, pts[i2, 1] - v01, pts[i2, 2] - v02
        k = off[b]
        for row in range(bbox[b, 2], bbox[b, 3] + 1):
            for col in range(bbox[b, 0], bbox[b, 1] + 1):
                o0 = rb[0, 0] + col * rb[1, 0] + row * rb[2, 0]
                o1 = rb[0, 1] + col * rb[1, 1] + row * rb[2, 1]
                o2 = rb[0, 2] + col * rb[1, 2] + row * rb[2, 2]
                d0 = rb[3, 0] + col * rb[4, 0] + row * rb[5, 0]
                d1 = rb[3, 1] + col * rb[4, 1] + row * rb[5, 1]
                d2 = rb[3, 2] + col * rb[4, 2] + row * rb[5, 2]
                px = d1 * e22 - d2 * e21
                py = d2 * e20 - d0 * e22
                pz = d0 * e21 - d1 * e20
                det = e10 * px + e11 * py + e12 * pz
                if det == 0.0:
                    continue
                inv = 1.0 / det
                sx = o0 - v00
                sy = o1 - v01
                sz = o2 - v02
                u = (sx * px + sy * py + sz * pz) * inv
                if u < -1e-12 or u > 1.0 + 1e-12:
                    continue
                qx = sy * e12 - sz * e11
                qy = sz * e10 - sx * e12
                qz = sx * e11 - sy * e10
                v = (d0 * qx + d1 * qy + d2 * qz) * inv
                if v < -1e-12 or u + v > 1.0 + 1e-12:
                    continue
                t = (e20 * qx + e21 * qy + e22 * qz) * inv
                if t < near or t > far:
                    continue
                pix[k] = row * width + col
                depth[k] = t
                k += 1
        cnt[b] = k - off[b]
    return cnt


@njit(cache=True, nogil=True)
def _gap_relations(pix: np.ndarray, depth: np.ndarray, fid: np.ndarray, n_pix: int, bfaces: np.ndarray,
                   entry: np.ndarray, m: int) -> np.ndarray:
    """Per pixel, sort fragments by depth; every entry face after an exit face gives the key (B * m + A): B before A."""
    cnt = np.zeros(n_pix + 1, np.int64)
    for k in range(len(pix)):
        cnt[pix[k] + 1] += 1
    for p in range(n_pix):
        cnt[p + 1] += cnt[p]
    pos = cnt[:-1].copy()
    sd = np.empty(len(pix))
    sf = np.empty(len(pix), np.int64)
    for k in range(len(pix)):
        j = pos[pix[k]]
        sd[j] = depth[k]
        sf[j] = fid[k]
        pos[pix[k]] += 1
    keys = np.empty(0, np.int64)
    out = []
    for p in range(n_pix):
        a, b = cnt[p], cnt[p + 1]
        if b - a < 2:
            continue
        for i in range(a + 1, b):           # insertion sort by depth
            x, y = sd[i], sf[i]
            j = i - 1
            while j >= a and sd[j] > x:
                sd[j + 1] = sd[j]
                sf[j + 1] = sf[j]
                j -= 1
            sd[j + 1] = x
            sf[j + 1] = y
        for k in range(a + 1, b):
            if not entry[sf[k]]:
                continue
            texit = np.nan
            for j in range(k - 1, a - 1, -1):
                eps = 1e-9 * max(1.0, abs(sd[j]))
                if not np.isnan(texit) and sd[j] < texit - eps:
                    break
                if not entry[sf[j]]:
                    if np.isnan(texit):
                        texit = sd[j]
                    ta = bfaces[sf[j], 0]
                    tb = bfaces[sf[k], 0]
                    if ta != tb:
                        out.append(tb * m + ta)
    if len(out):
        keys = np.empty(len(out), np.int64)
        for i in range(len(out)):
            keys[i] = out[i]
    return keys


def _boundary_box(cam: Camera, topo: Topology, size: tuple[int, int]) -> np.ndarray:
    tri = topo.tets[topo.boundary[:, 0][:, None], FACES[topo.boundary[:, 1]]]     # (b, 3)
    tri4 = np.concatenate([tri, tri[:, :1]], axis=1)
    return screen_bboxes(cam, topo.points + topo.origin, tri4, size)


def boundary_relations(topo: Topology, cam: Camera, size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """(src, dst) cell pairs, src drawn before dst, sampled at the pixel centres of an image of ``size``."""
    w, h = size
    bf = topo.boundary
    if len(bf) == 0:
        return np.empty(0, np.int64), np.empty(0, np.int64)
    n = topo.face_n[bf[:, 0], bf[:, 1]]
    dd = topo.face_d[bf[:, 0], bf[:, 1]]
    r, u, f = cam.frame()
    if cam.parallel:
        entry = (n @ f) < 0
    else:
        entry = (n @ (cam.position - topo.origin) - dd) > 0
    box = _boundary_box(cam, topo, size)
    rb = cam.rays(size, origin=topo.origin).as_array()
    near, far = cam.clipping_range
    area = np.maximum(box[:, 1] - box[:, 0] + 1, 0) * np.maximum(box[:, 3] - box[:, 2] + 1, 0)
    parts: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    start = 0
    while start < len(bf):               # chunks of at most ~8M candidate pixels (whole-screen boxes near the eye)
        stop = start + max(1, int(np.searchsorted(np.cumsum(area[start:]), 8_000_000)))
        off = np.zeros(stop - start + 1, np.int64)
        np.cumsum(area[start:stop], out=off[1:])
        pix, depth = np.empty(off[-1], np.int64), np.empty(off[-1])
        cnt = _boundary_fragments(topo.points, topo.tets, bf[start:stop], box[start:stop], off, rb, near, far, w,
                                  pix, depth)
        idx = np.repeat(off[:-1] - np.concatenate([[0], np.cumsum(cnt)[:-1]]), cnt) + np.arange(cnt.sum())
        parts.append((pix[idx], depth[idx], np.repeat(np.arange(start, stop), cnt)))
        start = stop
    pix, depth, fid = (np.concatenate([p[i] for p in parts]) for i in range(3))
    m = topo.n_tets
    keys = np.unique(_gap_relations(pix, depth, fid, w * h, bf, entry, m))
    return keys // m, keys % m


def is_convex(topo: Topology) -> bool:
    """True when every boundary face lies on the convex hull of the mesh (convex and connected: MPVO is exact)."""
    return len(inner_boundary(topo)) == 0


_SECOND_CORE: ThreadPoolExecutor | None = None
_SECOND_CORE_LOCK = threading.Lock()


def _beside(fn: Callable[[], tuple[np.ndarray, np.ndarray]]) -> Future[tuple[np.ndarray, np.ndarray]] | None:
    """``fn`` started on the sort's worker thread (made when first needed), or None where no thread can start any
    more (the interpreter shutting down while a background job sorts): the caller then runs it itself."""
    global _SECOND_CORE
    with _SECOND_CORE_LOCK:
        if _SECOND_CORE is None:
            _SECOND_CORE = ThreadPoolExecutor(1, thread_name_prefix="volviz-sort")
        try:
            return _SECOND_CORE.submit(fn)
        except RuntimeError:
            return None


_WORK_LOCK = threading.Lock()


def _take_work(topo: Topology) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A sort's work arrays for ``topo`` (per cell: state byte, in-degree, Kahn's stack; int32), taken from a pool
    kept on ``topo`` so a frame does not allocate (and page in) them anew; sorts running at once (the app's worker
    and its GUI thread) take different ones. Hand them back with ``_give_work``."""
    with _WORK_LOCK:
        pool = topo._sort_work
        if pool:
            return pool.pop()
    m = topo.n_tets
    return np.empty(m, np.uint8), np.empty(m, np.int32), np.empty(m, np.int32)


def _give_work(topo: Topology, work: tuple[np.ndarray, np.ndarray, np.ndarray]) -> None:
    with _WORK_LOCK:
        pool = topo._sort_work
        if len(pool) < 2:
            pool.append(work)


def _view(cam: Camera, topo: Topology) -> tuple[np.ndarray, np.ndarray]:
    _, _, f = cam.frame()
    return np.ascontiguousarray(cam.position - topo.origin), np.ascontiguousarray(f)


def visibility_order(mesh: TetMesh | Topology, camera: Camera, size: tuple[int, int] = (512, 512),
                     method: str = "mpvo", nonconvex: str = "auto") -> SortResult:
    """Back-to-front order of all cells of ``mesh`` for ``camera``.

    ``nonconvex``: "auto" (boundary relations in object space, ``boundary_pairs``, unless the mesh is convex),
    "object" (always), "sample" (always, sampled at the pixel centres of an image of ``size``: the previous method,
    whose cost grows with the window; kept as the tests' witness) or "none" (plain MPVO). ``size``: the image the
    order is for (with "auto"/"object" only its aspect matters).
    """
    if method not in METHODS:
        raise ValueError(f"unknown sort method {method!r}; choose one of {METHODS}")
    t0 = time.perf_counter()
    topo = mesh if isinstance(mesh, Topology) else topology(mesh)
    eye, fwd = _view(camera, topo)
    if method == "centroid":
        order = np.argsort(_centroid_keys(topo.centroid, eye, fwd, camera.parallel), kind="stable")
        return SortResult(order.astype(np.int64), method, seconds=time.perf_counter() - t0)
    if method == "power":
        # ties (cospherical cells, e.g. the 5 tetrahedra of a cube) are broken by centroid depth
        order = np.lexsort((_centroid_keys(topo.centroid, eye, fwd, camera.parallel),
                            _power_keys(topo.circ_center, topo.circ_r2, eye, fwd, camera.parallel)))
        return SortResult(order.astype(np.int64), method, seconds=time.perf_counter() - t0)
    m = topo.n_tets
    if nonconvex not in NONCONVEX:
        raise ValueError(f"nonconvex must be one of {NONCONVEX}, got {nonconvex!r}")
    t1 = time.perf_counter()
    relations: partial[tuple[np.ndarray, np.ndarray]] | None = None
    if nonconvex == "sample":
        relations = partial(boundary_relations, topo, camera, size)
    elif nonconvex == "object" or (nonconvex == "auto" and not is_convex(topo)):
        relations = partial(object_relations, topo, camera, size)
    pending = _beside(relations) if relations is not None and m >= mpvo.PARALLEL_CELLS else None
    beside = pending is not None
    work = _take_work(topo)
    front, indeg, stack = work
    try:
        if pending is not None:  # both stages release the GIL: the relations on a second core beside the sides
            face_sides(topo.neighbor, topo.back_face, topo.face_n, topo.face_d, eye, fwd, camera.parallel,
                       cores=False, out=(front, indeg), planes=topo.planes32)
            t2 = time.perf_counter()
            src, dst = pending.result()
        else:
            src, dst = relations() if relations is not None else (np.empty(0, np.int64), np.empty(0, np.int64))
            t2 = time.perf_counter()
            face_sides(topo.neighbor, topo.back_face, topo.face_n, topo.face_d, eye, fwd, camera.parallel,
                       out=(front, indeg), planes=None if m >= mpvo.PARALLEL_CELLS else topo.planes32)
        t3 = time.perf_counter()
        by_src = np.argsort(src, kind="stable")
        idx = topo.neighbor.dtype
        ex_src, ex_dst = src[by_src].astype(idx), dst[by_src].astype(idx)
        add_extra(ex_src, ex_dst, front, indeg)
        order = np.empty(m, idx)
        n_out, cycles = kahn_into(topo.neighbor, front, indeg, ex_src, ex_dst, order, 0, np.empty(0, idx), stack)
        if cycles < 0:                  # a cycle: carry on from the stall, breaking it farthest first
            fallback = np.argsort(_centroid_keys(topo.centroid, eye, fwd, camera.parallel),
                                  kind="stable").astype(idx)
            n_out, cycles = kahn_into(topo.neighbor, front, indeg, ex_src, ex_dst, order, n_out, fallback, stack)
    finally:
        _give_work(topo, work)
    t4 = time.perf_counter()
    # with the relations beside the sides: "sides" is the face sides alone, "relations_wait" the wait for them after
    stages = {"sides": t2 - t1, "relations_wait": t3 - t2} if beside else {"relations": t2 - t1, "sides": t3 - t2}
    return SortResult(order, method, int(cycles), int(len(src)), t4 - t0, {**stages, "kahn": t4 - t3})
