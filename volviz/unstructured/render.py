"""``render(mesh, tf, camera, size, method)``: the unstructured volume renderer's entry point.

Methods:

- ``"pt"``: visibility sort (``sort``: "mpvo" with image-space boundary relations by default, or "centroid"/"power"),
  zero-opacity culling of cells by their scalar range (Roettger §9.1, "ZOT"), per-cell projection and the tiled Numba
  rasteriser with exact per-pixel (s_f, s_b, l) and the separable (default) or 3D pre-integration table (``raster``).
- ``"pt-st"``: the classic Shirley-Tuchman split into 3 or 4 triangles with (s_f, s_b, l) at the thick vertex,
  interpolated linearly in screen space (``project``): exact for parallel projection, approximate under perspective;
  cells crossing the near plane are skipped (use "pt" with the camera inside the mesh).
- ``"reference"``: the exact float64 ray caster (``reference``).

The image is premultiplied float RGBA (H, W, 4), row 0 at the top; ``size`` is (W, H). With ``return_stats=True`` the
call returns ``(image, UnstructuredRenderStats)`` with the time split into sort / project / raster seconds.
"""
from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field
from typing import Any, Literal, cast, overload

import numpy as np

from volviz.model.camera import Camera, CameraDict
from volviz.model.datasets import TetMesh
from volviz.model.object_cache import ObjectCache
from volviz.optics import build_table3d
from volviz.optics.integrate import integrate_preclassified
from volviz.optics.separable import SeparableTable, build_separable
from volviz.optics.table3d import Table3D
from volviz.unstructured.iso import iso_lut, iso_segment_rgba, iso_visible, vertex_shade
from volviz.unstructured.project import raster_triangles, shirley_tuchman
from volviz.unstructured.raster import SOS, TILE, bin_tiles, lut_args, project_cells, raster_tiles, ray_images
from volviz.unstructured.reference import depth_limits, render_reference
from volviz.unstructured.sort import visibility_order
from volviz.unstructured.topology import cell_ranges, topology, visible_cells

METHODS = ("pt", "pt-st", "reference")
LOOKUPS = ("auto", "separable", "3d")


def auto_lookup(max_depth: float) -> tuple[str, int]:
    """The lookup for "pt" by the largest optical depth of one cell (max rho x longest edge): the separable table
    with degree 2 up to 6, degree 4 up to 24, else the 3D table: each switches where the cheaper lookup's error
    against the reference grows past the next one's (the errors by depth: docs/bench/docstring-figures.md)."""
    if max_depth <= 6.0:
        return "separable", 2
    if max_depth <= 24.0:
        return "separable", 4
    return "3d", 0


@dataclass(frozen=True)
class Preclassified:
    """The "table" of pre-classification for "pt": the TF itself, evaluated at each segment's ends."""

    preclassified_tf: Any


@dataclass
class UnstructuredRenderStats:
    """Timings (seconds) and counts of one frame."""

    method: str
    size: tuple[int, int]
    n_tets: int = 0
    n_visible: int = 0
    sort_s: float = 0.0
    project_s: float = 0.0
    raster_s: float = 0.0
    table_s: float = 0.0
    total_s: float = 0.0
    fragments: int = 0
    cycles: int = 0
    boundary_relations: int = 0
    sort_method: str = ""
    extra: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def table_size(max_depth: float, n_s: int = 128, n_l: int = 64, depth_per_bin: float = 0.2,
               budget: int = 2 * 128 * 128 * 64) -> tuple[int, int]:
    """Table resolution: enough length bins that one bin spans at most ``depth_per_bin`` of optical depth
    (max rho x l_max / (n_l - 1)); trilinear interpolation of 1 - exp(-tau) across a bin is then accurate to about
    depth_per_bin^2 / 8 (~0.005 = 1.3 of 255 at 0.2). n_s shrinks to keep n_s^2 n_l within ``budget`` entries."""
    need = int(np.ceil(max_depth / depth_per_bin)) + 1
    n_l = max(n_l, min(512, need))
    if n_s * n_s * n_l > budget:
        n_s = max(48, int(np.sqrt(budget / n_l)))
    return n_s, n_l


#: per mesh while it lives, by table kind: (the TF, range and sizes it was made for, the table) (``table_for``)
_TABLES: ObjectCache[dict[str, tuple[tuple[Any, ...], Any]]] = ObjectCache()


def table_for(mesh: TetMesh, tf: Any, kind: str, sizes: tuple[int, int], l_max: float) -> Any:
    """The pre-integration table (``kind`` "3d" or "pre" (pre-classified 3D): sizes = (n_s, n_l); "separable":
    sizes = (n_s, degree)) over the union of the TF range and the data range (so out-of-range parts stay transparent),
    kept per mesh while it lives for the last TF and sizes of each kind."""
    r = cell_ranges(mesh)
    ok = ~r.nan
    lo, hi = tf.range
    if ok.any():
        lo, hi = min(lo, float(r.smin[ok].min())), max(hi, float(r.smax[ok].max()))
    key = (kind, tf.scalars.tobytes(), tf.colors.tobytes(), tf.extinction.tobytes(), lo, hi, sizes, l_max)
    tables = _TABLES.setdefault(mesh, dict)
    cached = tables.get(kind)
    if cached is not None and cached[0] == key:
        return cached[1]
    table: Table3D | SeparableTable
    if kind in ("3d", "pre"):
        table = build_table3d(tf, n_s=sizes[0], n_l=sizes[1], l_max=l_max, s_range=(lo, hi),
                              classification="pre" if kind == "pre" else "post")
    else:
        table = build_separable(tf, n_s=sizes[0], l_max=l_max, degree=sizes[1], s_range=(lo, hi))
    tables[kind] = (key, table)
    return table


@overload
def render(mesh: TetMesh, tf: Any, camera: Camera, size: tuple[int, int] = (512, 512), method: str = "pt", *,
           sort: str = "mpvo", nonconvex: str = "auto", order: np.ndarray | None = None, lookup: str = "auto",
           n_s: int | None = None, n_l: int = 64, degree: int | None = None, table: Any = None, t_min: float = 1e-3,
           depth: np.ndarray | None = None, iso: Any = None, iso_mode: str = "exact", iso_shading: str = "flat",
           classification: str = "post", return_stats: Literal[False] = False
           ) -> np.ndarray: ...


@overload
def render(mesh: TetMesh, tf: Any, camera: Camera, size: tuple[int, int] = (512, 512), method: str = "pt", *,
           sort: str = "mpvo", nonconvex: str = "auto", order: np.ndarray | None = None, lookup: str = "auto",
           n_s: int | None = None, n_l: int = 64, degree: int | None = None, table: Any = None, t_min: float = 1e-3,
           depth: np.ndarray | None = None, iso: Any = None, iso_mode: str = "exact", iso_shading: str = "flat",
           classification: str = "post", return_stats: Literal[True]
           ) -> tuple[np.ndarray, UnstructuredRenderStats]: ...


@overload
def render(mesh: TetMesh, tf: Any, camera: Camera, size: tuple[int, int] = (512, 512), method: str = "pt", *,
           sort: str = "mpvo", nonconvex: str = "auto", order: np.ndarray | None = None, lookup: str = "auto",
           n_s: int | None = None, n_l: int = 64, degree: int | None = None, table: Any = None, t_min: float = 1e-3,
           depth: np.ndarray | None = None, iso: Any = None, iso_mode: str = "exact", iso_shading: str = "flat",
           classification: str = "post", return_stats: bool = False
           ) -> np.ndarray | tuple[np.ndarray, UnstructuredRenderStats]: ...


def render(mesh: TetMesh, tf: Any, camera: Camera, size: tuple[int, int] = (512, 512), method: str = "pt", *,
           sort: str = "mpvo", nonconvex: str = "auto", order: np.ndarray | None = None, lookup: str = "auto",
           n_s: int | None = None, n_l: int = 64, degree: int | None = None, table: Any = None, t_min: float = 1e-3,
           depth: np.ndarray | None = None, iso: Any = None, iso_mode: str = "exact", iso_shading: str = "flat",
           classification: str = "post", return_stats: bool = False
           ) -> np.ndarray | tuple[np.ndarray, UnstructuredRenderStats]:
    """Render ``mesh`` with transfer function ``tf`` seen by ``camera`` into a (H, W, 4) premultiplied RGBA image.

    ``order`` (a back-to-front cell order, e.g. from a background sort) skips the sort. ``lookup`` picks the
    pre-integration for "pt": "separable" (Roettger §9.1, n_s x n_s (default 256) with a color polynomial of
    ``degree`` (default 2); exact opacity), "3d" (n_s x n_s x n_l, default n_s = 128, trilinear) or "auto" (by the
    largest optical depth of a cell, see ``auto_lookup``); l_max = the longest edge, over the data and TF range. "pt-st"
    always uses the 3D table. ``table`` overrides it (a ``Table3D`` or a ``SeparableTable``).
    ``depth`` (H, W): a per-pixel far limit on the depth along the direction of projection (the ray parameter t of
    ``Camera.rays``), e.g. opaque geometry from a z-buffer; every ray segment is clipped at it ("pt" and
    "reference"; "pt-st" refuses it).
    ``iso`` (an ``IsoTable`` of ``volviz.optics.isosurface``) renders its flat isosurfaces instead of the volume
    (Roettger §8.8-8.10; ``tf`` is then ignored). "pt" with ``iso_mode="exact"`` evaluates the §8.13 Heaviside
    limit per pixel segment (equal to the reference up to float32 isovalues); ``iso_mode="texture"`` looks up the
    bilinear (s_f, s_b) texture like the GPU method (segments ending within a texel of an isovalue are partly
    covered, an error of a few 8-bit levels: docs/bench/docstring-figures.md). "reference" evaluates
    the Heaviside limit per exact segment. ``iso_shading="smooth"`` (exact mode) shades each surface with a
    headlight through vertex normals interpolated linearly inside cells (Roettger §8.9, ``iso.vertex_shade``);
    "flat" (default) keeps the surfaces' colors.
    ``classification``: "post" (default; the TF applied to the interpolated scalar, exact inside cells) or "pre"
    (Roettger §8.14, the original projected tetrahedra: the TF applied at each segment's ends only, κ and ρ linear in
    between, ``volviz.optics.integrate_preclassified``), for A/B comparisons: "pt" and "reference" then integrate
    the pre-classified segments exactly per pixel (a table in (s_f, s_b) would blur the TF's kinks, which
    pre-classification keeps at the ends), "pt-st" uses a pre-classified 3D table.
    """
    if classification not in ("post", "pre"):
        raise ValueError(f"classification must be 'post' or 'pre', got {classification!r}")
    if classification == "pre" and iso is not None:
        raise ValueError("isosurfaces are post-classified; use classification='post'")
    if iso_shading not in ("flat", "smooth"):
        raise ValueError(f"iso_shading must be 'flat' or 'smooth', got {iso_shading!r}")
    smooth = iso is not None and iso_shading == "smooth"
    if smooth and iso_mode != "exact":
        raise ValueError("smooth isosurfaces need iso_mode='exact'")
    shade = vertex_shade(mesh, camera.frame()[2]) if smooth else None
    if method not in METHODS:
        raise ValueError(f"unknown render method {method!r}; choose one of {METHODS}")
    if lookup not in LOOKUPS:
        raise ValueError(f"unknown lookup {lookup!r}; choose one of {LOOKUPS}")
    if not isinstance(mesh, TetMesh):
        raise TypeError(f"render needs a TetMesh (use volviz.unstructured.tetrahedralize), got {type(mesh).__name__}")
    if isinstance(camera, dict):   # (untyped callers: a camera as Camera.to_dict writes it)
        camera = Camera.from_dict(cast(CameraDict, camera))
    w, h = (int(v) for v in size)
    stats = UnstructuredRenderStats(method, (w, h), n_tets=mesh.n_cells)
    t_start = time.perf_counter()
    if iso is not None and method == "pt-st":
        raise ValueError('isosurfaces need method "pt" or "reference"')
    if method == "reference":
        seg_fn = None if iso is None else (lambda sf, sb, ln, *h: iso_segment_rgba(iso, sf, sb, *h))
        if classification == "pre":
            seg_fn = (lambda sf, sb, ln: integrate_preclassified(tf, sf, sb, ln))
        img = render_reference(mesh, tf, camera, (w, h), depth=depth, segment_rgba=seg_fn, extra=shade)
        stats.total_s = stats.raster_s = time.perf_counter() - t_start
        return (img, stats) if return_stats else img
    topo = topology(mesh)
    t0 = time.perf_counter()
    if iso is not None:
        if iso_mode not in ("exact", "texture"):
            raise ValueError(f"iso_mode must be 'exact' or 'texture', got {iso_mode!r}")
        table = iso if iso_mode == "exact" else iso_lut(iso)
    elif table is None:
        l_max = max(topo.max_edge, 1e-12)
        if lookup == "auto":
            lookup, auto_degree = auto_lookup(tf.max_extinction * l_max)
            degree = degree or auto_degree
        if classification == "pre" and method == "pt":
            table = Preclassified(tf)
        elif lookup == "3d" or method == "pt-st" or classification == "pre":
            kind = "pre" if classification == "pre" else "3d"
            table = table_for(mesh, tf, kind, table_size(tf.max_extinction * l_max, n_s or 128, n_l), l_max)
        else:
            table = table_for(mesh, tf, "separable", (n_s or 256, int(degree or 2)), l_max)
    elif method == "pt-st" and not hasattr(table, "rgba"):
        raise ValueError('method "pt-st" needs a 3D table (Table3D)')
    stats.table_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    if order is None:
        res = visibility_order(topo, camera, (w, h), sort, nonconvex)
        order = res.order
        stats.cycles, stats.boundary_relations = res.cycles, res.boundary_relations
    stats.sort_method = sort
    vis = visible_cells(mesh, tf.scalars, tf.extinction) if iso is None else iso_visible(mesh, iso)
    cells = np.ascontiguousarray(order[vis[order]], dtype=np.int64)
    stats.n_visible = int(len(cells))
    stats.sort_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    rb = camera.rays((w, h), origin=topo.origin)
    r, u, f = camera.frame()
    frame = np.stack([r, u, f, camera.position - topo.origin])
    hx, hy = camera._scales((w, h))
    near, far = camera.clipping_range
    box, coef, vxy = project_cells(topo.points, topo.tets, mesh.scalars, cells, topo.face_n, topo.face_d,
                                   rb.as_array(), frame, np.array([hx, hy]), bool(camera.parallel), near, w, h, SOS)
    tol = 1e-10 * max(float(np.abs(topo.points).max()) + float(np.abs(rb.o0).max()), 1e-300)
    shade_coef = np.empty((0, 6))
    if shade is not None:        # the shading intensity as affine forms per cell, like the scalar's
        shade_coef = np.ascontiguousarray(project_cells(topo.points, topo.tets, shade, cells, topo.face_n, topo.face_d,
                                                        rb.as_array(), frame, np.array([hx, hy]),
                                                        bool(camera.parallel), near, w, h, SOS)[1][:, 24:30])
    stats.project_s = time.perf_counter() - t0
    stats.extra["box_pixels"] = int(np.sum(np.clip(box[:, 1] - box[:, 0] + 1, 0, None)
                                           * np.clip(box[:, 3] - box[:, 2] + 1, 0, None)))
    t0 = time.perf_counter()
    if method == "pt-st":
        if depth is not None:
            raise ValueError('method "pt-st" does not support a depth limit; use "pt"')
        cls, ntri, txy, tval = shirley_tuchman(vxy, coef, mesh.scalars[topo.tets[cells]], rb.as_array(), near, far)
        stats.extra["classes"] = {int(c): int((cls == c).sum()) for c in (0, 1, 2)}
        stats.extra["triangles"] = int(ntri.sum())
        stats.project_s += time.perf_counter() - t0
        t0 = time.perf_counter()
        img = np.zeros((h, w, 4))
        stats.fragments = int(raster_triangles(ntri, txy, tval, table.rgba, table.s_lo, table.ds, table.dl, w, h,
                                               img))
        stats.raster_s = time.perf_counter() - t0
        stats.total_s = time.perf_counter() - t_start
        return (img, stats) if return_stats else img
    ptr, items = bin_tiles(box, w, h, TILE)
    n_tiles = len(ptr) - 1
    # interleave heavy and light tiles across threads: Numba's prange hands out contiguous chunks
    tile_order = np.random.default_rng(12345).permutation(n_tiles).astype(np.int64)
    img = np.zeros((h, w, 4))
    far_img, dn_img = ray_images(rb.as_array(), near, far, depth_limits(depth, w, h), w, h)
    frags = raster_tiles(box, coef, vxy, ptr, items, tile_order, rb.as_array(), near, *lut_args(table, smooth),
                         w, h, TILE, float(t_min), tol, far_img, dn_img, bool(camera.parallel), shade_coef, img)
    stats.fragments = int(frags.sum())
    stats.raster_s = time.perf_counter() - t0
    stats.total_s = time.perf_counter() - t_start
    np.nan_to_num(img, copy=False, nan=0.0, posinf=0.0, neginf=0.0)
    return (img, stats) if return_stats else img
