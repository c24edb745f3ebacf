"""Terrain C-LOD (Roettger §3.5.3): crack-freeness, full refinement, geomorph continuity, d2 propagation."""
from __future__ import annotations

import matplotlib.tri as mtri
import numpy as np
import pytest

from conftest import data_file
from volviz.nature.heightfield import HeightField, pow2_plus_one, resample_bilinear
from volviz.nature.terrain import TerrainLOD, frustum_planes, propagation_factor


def rough_field(n: int = 65, seed: int = 0) -> HeightField:
    rng = np.random.default_rng(seed)
    g = np.cumsum(np.cumsum(rng.normal(size=(n, n)), 0), 1) * 0.05
    return HeightField(g, (1.0, 1.0))


def non_conforming_edges(mesh, n: int) -> int:
    """Edges used by one triangle that are not on the grid border (T-junctions / cracks) or by more than two."""
    t = mesh.triangles
    e = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    edges, counts = np.unique(e, axis=0, return_counts=True)
    gi = mesh.grid_index
    a, b = gi[edges[:, 0]], gi[edges[:, 1]]
    border = ((a[:, 0] == b[:, 0]) & np.isin(a[:, 0], (0, n - 1))) | ((a[:, 1] == b[:, 1]) & np.isin(a[:, 1], (0, n - 1)))
    return int(np.sum(counts > 2) + np.sum((counts == 1) & ~border) + np.sum((counts == 2) & border))


@pytest.mark.parametrize("big_c", [2.5, 4.0, 9.0])
def test_no_t_junctions_for_many_eyes(big_c: float) -> None:
    hf = rough_field()
    lod = TerrainLOD(hf, big_c=big_c, small_c=5.0)
    rng = np.random.default_rng(1)
    for eye in rng.uniform([-30, -30, 0], [95, 95, 40], size=(25, 3)):
        mesh = lod.update(eye)
        assert non_conforming_edges(mesh, hf.size) == 0
        # the triangles tile the square exactly (no overlaps, no holes)
        p = mesh.points[:, :2]
        t = mesh.triangles
        u, v = p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]]
        area = 0.5 * (u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])
        assert np.all(area > 0)  # counter-clockwise from above
        assert area.sum() == pytest.approx(64.0 * 64.0)


def test_full_refinement_is_the_full_grid() -> None:
    hf = HeightField(rough_field(33).heights, (2.5, 0.75), origin=(-10.0, 300.0))
    mesh = TerrainLOD(hf).full_mesh()
    assert mesh.n_triangles == 2 * 32 * 32
    assert len(mesh.points) == 33 * 33
    gi = mesh.grid_index
    np.testing.assert_array_equal(mesh.points[:, 2], hf.heights[gi[:, 0], gi[:, 1]])
    np.testing.assert_array_equal(mesh.points[:, 0], -10.0 + gi[:, 0] * 2.5)      # the grid point's place
    np.testing.assert_array_equal(mesh.points[:, 1], 300.0 + gi[:, 1] * 0.75)
    np.testing.assert_array_equal(mesh.tcoords, gi / 32.0)
    assert non_conforming_edges(mesh, 33) == 0


def test_coarse_far_away_and_fine_nearby() -> None:
    hf = rough_field()
    lod = TerrainLOD(hf, big_c=4.0, small_c=2.0)
    far = lod.update((32.0, 32.0, 5000.0))
    near = lod.update((32.0, 32.0, 3.0))
    assert far.n_triangles <= 8
    assert near.n_triangles > 20 * far.n_triangles


def test_d2_propagation_property() -> None:
    hf = rough_field()
    big_c = 6.0
    lod = TerrainLOD(hf, big_c=big_c)
    k = propagation_factor(big_c)
    assert k == pytest.approx(6.0 / 10.0)
    n, d2 = hf.size, lod.d2
    d = 4
    while d <= n - 1:
        h, q = d // 2, d // 4
        for ci in range(h, n - 1, d):
            for cj in range(h, n - 1, d):
                children = [d2[ci + si * q, cj + sj * q] for si in (-1, 1) for sj in (-1, 1)]
                assert d2[ci, cj] >= k * max(children) - 1e-15
                assert d2[ci, cj] == pytest.approx(max(lod.d2_local[ci, cj], k * max(children)))
        d *= 2
    # local d2 of a size-2 node by hand: six differences over the edge length
    g, ci, cj = hf.heights, 5, 7
    diffs = [g[ci, cj - 1] - (g[ci - 1, cj - 1] + g[ci + 1, cj - 1]) / 2, g[ci + 1, cj] - (g[ci + 1, cj - 1] + g[ci + 1, cj + 1]) / 2,
             g[ci, cj + 1] - (g[ci - 1, cj + 1] + g[ci + 1, cj + 1]) / 2, g[ci - 1, cj] - (g[ci - 1, cj - 1] + g[ci - 1, cj + 1]) / 2,
             g[ci, cj] - (g[ci - 1, cj - 1] + g[ci + 1, cj + 1]) / 2, g[ci, cj] - (g[ci + 1, cj - 1] + g[ci - 1, cj + 1]) / 2]
    assert lod.d2_local[ci, cj] == pytest.approx(max(abs(x) for x in diffs) / 2.0)
    with pytest.raises(ValueError, match="C must be > 2"):
        propagation_factor(2.0)


def _surface(mesh, x, y):
    tri = mtri.Triangulation(mesh.points[:, 0], mesh.points[:, 1], mesh.triangles)
    return mtri.LinearTriInterpolator(tri, mesh.points[:, 2])(x, y).filled(np.nan)


def test_geomorph_is_continuous() -> None:
    hf = rough_field()
    xs = np.linspace(0.25, 63.75, 90)
    x, y = np.meshgrid(xs, xs)

    def max_step_change(geomorph: bool, step: float) -> float:
        lod = TerrainLOD(hf, big_c=4.0, small_c=3.0, geomorph=geomorph)
        prev, worst = None, 0.0
        for s in np.arange(0.0, 30.0, step):
            surf = _surface(lod.update((s, 10 + 0.5 * s, 8.0)), x, y)
            if prev is not None:
                worst = max(worst, float(np.nanmax(np.abs(surf - prev))))
            prev = surf
        return worst

    coarse_step = max_step_change(True, 0.2)
    fine_step = max_step_change(True, 0.05)
    popping = max_step_change(False, 0.2)
    assert popping > 0.5              # without geomorphing a refinement pops by a visible height
    assert coarse_step < popping / 20  # with geomorphing the change per step is small ...
    assert fine_step < 0.5 * coarse_step  # ... and shrinks with the step (continuity, no jump hidden in it)


def test_layers_morph_with_the_terrain_and_culling() -> None:
    hf = rough_field()
    top = hf.heights + 2.0 + np.linspace(0, 1, hf.size)[:, None]
    lod = TerrainLOD(hf, layers={"fog_top": top}, curvature=[(top - hf.heights, 4.0)], big_c=4.0, small_c=3.0)
    mesh = lod.update((10.0, 20.0, 6.0))
    # the morphed top minus the morphed terrain is the linearly morphed thickness (>= 2 everywhere)
    assert np.all(mesh.layers["fog_top"] - mesh.points[:, 2] >= 2.0 - 1e-12)
    from volviz.model.camera import Camera

    cam = Camera((-10, 32, 20), (30, 32, 0), (0, 0, 1), 40.0, clipping_range=(0.5, 500))
    culled = lod.update(cam.position, frustum_planes(cam, (64, 48)))
    full = lod.update(cam.position)
    assert 0 < culled.n_triangles < full.n_triangles
    px = cam.project(full.points, (64, 48))
    # every triangle with a vertex well inside the image survives culling
    inside = (px[:, 0] > 2) & (px[:, 0] < 61) & (px[:, 1] > 2) & (px[:, 1] < 45) & (px[:, 2] > 1)
    kept = {tuple(sorted(tuple(full.grid_index[v]) for v in tri)) for tri in full.triangles[inside[full.triangles].any(1)]}
    have = {tuple(sorted(tuple(culled.grid_index[v]) for v in tri)) for tri in culled.triangles}
    assert kept <= have


def test_resampling_and_yukon_map() -> None:
    assert pow2_plus_one(689) == 1025 and pow2_plus_one(513) == 513 and pow2_plus_one(3) == 3
    a = np.arange(12.0).reshape(3, 4)
    r = resample_bilinear(a, (5, 7))
    assert r[0, 0] == 0 and r[-1, -1] == 11 and r[2, 3] == pytest.approx(a.mean())
    from volviz.io import read

    img = read(data_file("yukon/Yukon.map.pgm"))
    hf = HeightField.from_image(img, extent=(1000.0, 1000.0), height_scale=0.33)
    assert hf.size == 1025 and hf.spacing == pytest.approx((1000 / 1024, 1000 / 1024))
    # north-west corner of the image is grid (0, N-1)
    assert hf.heights[0, -1] == pytest.approx(0.33 * float(img.data[0, 0]))
    lod = TerrainLOD(hf, big_c=9.0, small_c=2.0)
    mesh = lod.update((500.0, -200.0, 250.0))
    assert non_conforming_edges(mesh, hf.size) == 0
    assert 1000 < mesh.n_triangles < 2 * 1024 * 1024 / 10
    assert mesh.tcoords.min() >= 0 and mesh.tcoords.max() <= 1


def test_parallel_geomorphing_matches_the_node_by_node_order():
    """``morph`` blends the nodes of a level in parallel: every vertex of the mesh gets the value the coarse-to-fine
    node order gives (``_morph_node`` applied node by node), exactly."""
    from volviz.nature import _terrain_kernels as K
    from volviz.nature import noise

    h = noise.fractal_terrain(257, seed=1, relief=84.0)
    lod = TerrainLOD(HeightField(h, (2.0, 2.0)), layers={"fog": h + 5.0}, big_c=9.0, small_c=60.0)
    for eye in ([100.0, 50.0, 200.0], [400.0, 300.0, 120.0]):
        mesh = lod.update(eye)
        count = int(mesh.stats["nodes"])
        serial = np.zeros_like(lod._morphed)
        m, last = (lod.n - 1) // 2, lod.n - 1
        for i, j in ((0, 0), (last, 0), (0, last), (last, last), (m, m), (m, 0), (last, m), (m, last), (0, m)):
            serial[i, j] = lod.fields[i, j]
        for k in range(count):
            K._morph_node(lod.fields, last, lod._state, lod._weight, lod._nodes[k, 0], lod._nodes[k, 1],
                          lod._sizes[k], serial)
        gi, gj = mesh.grid_index[:, 0], mesh.grid_index[:, 1]
        assert mesh.n_triangles > 100_000 and (lod._weight[lod._state == 2] < 1.0).any()   # morphing under way
        np.testing.assert_array_equal(lod._morphed[gi, gj], serial[gi, gj])


def test_culled_geomorphing_gives_every_kept_vertex_its_full_value():
    """With frustum planes, nodes whose column misses the frustum are not morphed; every vertex of the culled mesh
    still gets exactly the value of the morph over all nodes, and the skipped part is real (points outside the
    frustum keep no value)."""
    from volviz.model.camera import Camera
    from volviz.nature import noise

    h = noise.fractal_terrain(257, seed=1, relief=84.0)
    hf = HeightField(h, (2.0, 2.0))
    cam = Camera((100.0, 80.0, 150.0), (300.0, 250.0, 20.0), (0, 0, 1), 40.0, clipping_range=(1.0, 2000.0))
    planes = frustum_planes(cam, (64, 48), margin=0.05)
    culled_lod, full_lod = (TerrainLOD(hf, layers={"fog": h + 5.0}, big_c=9.0, small_c=60.0) for _ in range(2))
    culled = culled_lod.update(cam.position, planes)
    full_lod.update(cam.position)
    gi, gj = culled.grid_index[:, 0], culled.grid_index[:, 1]
    assert culled.n_triangles > 10_000 and (culled_lod._weight[culled_lod._state == 2] < 1.0).any()
    np.testing.assert_array_equal(culled_lod._morphed[gi, gj], full_lod._morphed[gi, gj])
    np.testing.assert_array_equal(culled.points[:, 2], full_lod._morphed[gi, gj, 0])
    refined_vertices = full_lod._morphed != 0.0
    skipped = refined_vertices & (culled_lod._morphed == 0.0)
    assert skipped[..., 0].sum() > 1000


def test_fan_emission_is_the_same_on_any_number_of_threads():
    """The parallel fan emission numbers the vertices row by row and writes the fans in node order: one thread and
    all threads give the same mesh, array for array."""
    import numba

    from volviz.model.camera import Camera
    from volviz.nature import noise
    from volviz.numba_threads import numba_threads

    h = noise.fractal_terrain(257, seed=3, relief=84.0)
    hf = HeightField(h, (2.0, 2.0))
    cam = Camera((80.0, 60.0, 120.0), (300.0, 250.0, 20.0), (0, 0, 1), 50.0, clipping_range=(1.0, 2000.0))
    planes = frustum_planes(cam, (64, 48), margin=0.05)
    meshes = []
    for threads in (1, numba.config.NUMBA_NUM_THREADS):
        lod = TerrainLOD(hf, layers={"fog": h + 5.0}, big_c=9.0, small_c=60.0)
        with numba_threads(threads):
            meshes.append(lod.update(cam.position, planes))
    one, many = meshes
    assert one.n_triangles > 10_000
    for a, b in ((one.points, many.points), (one.triangles, many.triangles), (one.grid_index, many.grid_index),
                 (one.layers["fog"], many.layers["fog"])):
        np.testing.assert_array_equal(a, b)
    gi = one.grid_index
    assert np.all(np.diff(gi[:, 0] * hf.size + gi[:, 1]) > 0)        # row-major, each grid point once
