"""Volumetric C-LOD clouds (Roettger Ch. 11): K_max propagation, crack-free morphed field, morph continuity, tet
counts, and the per-pixel renderer against the unstructured PT renderer."""
from __future__ import annotations

import math

import numpy as np
import pytest

from volviz.nature import _cloud_kernels as K
from volviz.nature import noise
from volviz.nature.clouds import CloudLOD, CloudShading, CloudVolume, build_cloud_table, kmax, render_cloud_image
from volviz.model.camera import Camera

SIZE = (48, 36)


def small_volume(light: bool = True) -> CloudVolume:
    shape = (17, 17, 9)
    f = noise.cloud_density(shape, seed=2, coverage=0.4)
    g = noise.cloud_light(f, (1.0, 1.0, 1.0)) if light else np.ones(shape, np.float32)
    return CloudVolume(f, g, (1.0, 1.0, 1.0), (0.0, 0.0, 0.0))


def camera(eye=(-8.1, -12.4, 14.3)) -> Camera:
    return Camera(eye, (8.05, 7.93, 4.11), (0, 0, 1), 50, clipping_range=(0.5, 100))


def test_kmax_and_propagation_property() -> None:
    assert kmax(4.0) == pytest.approx(4.0 / (8.0 - 0.5 * math.sqrt(3.0)))
    with pytest.raises(ValueError, match="sqrt"):
        kmax(1.5)
    vol = small_volume()
    lod = CloudLOD(vol, big_c=3.0, small_c=4.0)
    k = kmax(3.0)
    for lv in range(lod.levels - 1):
        na, nb, nc = lod.roots << lv
        for a in range(na):
            for b in range(nb):
                for c in range(nc):
                    idx = lod.off[lv] + (a * nb + b) * nc + c
                    kids = [lod.off[lv + 1] + ((2 * a + (q >> 2)) * (2 * nb) + 2 * b + ((q >> 1) & 1)) * (2 * nc)
                            + 2 * c + (q & 1) for q in range(8)]
                    assert lod.delta[idx] >= k * lod.delta[kids].max() - 1e-12
                    assert lod.delta[idx] == pytest.approx(max(lod.delta_local[idx], k * lod.delta[kids].max()))
    assert lod.fmax[0] == pytest.approx(float(vol.f.max()))


def _leaf_value(vf, root, leaf, p):
    """The morphed 5-tet interpolant of leaf (lv, a, b, c) at world point p (grid units, spacing 1)."""
    lv, a, b, c = leaf
    s = root >> lv
    flip = (a + b + c) % 2 == 1
    u = np.clip((np.asarray(p) - np.array([a, b, c]) * s) / s, 0.0, 1.0)
    cv = np.empty(8)
    for q in range(8):
        i, j, k = q >> 2, (q >> 1) & 1, q & 1
        src = 1 - i if flip else i
        cv[q] = vf[(a + src) * s, (b + j) * s, (c + k) * s]
    if flip:
        u[0] = 1.0 - u[0]
    region = 4
    for r in range(4):
        if K._l1(r, *u) < 1.0 - 1e-12:
            region = r
            break
    return K._eval(cv, region, *u)


def test_morphed_field_is_continuous_across_levels() -> None:
    vol = small_volume()
    lod = CloudLOD(vol, big_c=2.5, small_c=6.0)
    rng = np.random.default_rng(0)
    checked = 0
    for eye in [(-6.0, -4.0, 9.0), (30.2, 8.1, 4.3), (-10.0, 20.0, 12.0)]:
        frame = lod.update(camera(eye), SIZE, cull=False)
        levels = set(frame.leaves[:, 0].tolist())
        assert len(levels) >= 2  # mixed resolutions, so there are level transitions to check
        vf, vg = lod.morphed
        cell_leaf = -np.ones((16, 16, 8), dtype=np.int64)  # every cell's leaf
        for i, (lv, a, b, c) in enumerate(frame.leaves):
            s = vol.root >> lv
            cell_leaf[a * s:(a + 1) * s, b * s:(b + 1) * s, c * s:(c + 1) * s] = i
        for i, leaf in enumerate(frame.leaves):
            lv, a, b, c = leaf
            s = vol.root >> lv
            for ax in range(3):
                for side in (0, 1):
                    for _ in range(2):
                        p = (np.array([a, b, c]) + rng.uniform(0, 1, 3)) * s
                        p[ax] = ([a, b, c][ax] + side) * s
                        cell = np.floor(p).astype(int)
                        cell[ax] += -1 if side == 0 else 0
                        if np.any(cell < 0) or np.any(cell >= (16, 16, 8)):
                            continue
                        j = cell_leaf[tuple(cell)]
                        if j < 0 or j == i:
                            continue
                        for field in (vf, vg):
                            assert _leaf_value(field, vol.root, leaf, p) == pytest.approx(
                                _leaf_value(field, vol.root, frame.leaves[j], p), abs=1e-5)
                        checked += 1
    assert checked > 100


def test_morph_continuity_and_counts() -> None:
    vol = small_volume()
    shading = CloudShading.npr(rho_max=0.6)
    table = build_cloud_table(shading, l_max=8 * math.sqrt(3), n_s=32, n_l=64)

    def max_step(geomorph: bool, step: float) -> tuple[float, int]:
        """Largest per-step change of the LOD error image (LOD image minus full-resolution image)."""
        lod = CloudLOD(vol, big_c=2.5, small_c=4.0, cutoff=shading.cutoff, geomorph=geomorph)
        prev, worst, tets = None, 0.0, 0
        for s in np.arange(0.0, 3.0, step):
            cam = camera((-8.1 + s, -12.4 + 1.5 * s, 14.3 - s))
            reference = render_cloud_image(lod.update(cam, SIZE, full=True), shading, table, cam, SIZE)
            frame = lod.update(cam, SIZE)
            tets = max(tets, frame.n_tets)
            img = render_cloud_image(frame, shading, table, cam, SIZE) - reference
            if prev is not None:
                worst = max(worst, float(np.abs(img - prev).max()))
            prev = img
        return worst, tets

    morph_coarse, tets = max_step(True, 0.1)
    morph_fine, _ = max_step(True, 0.025)
    pop_fine, _ = max_step(False, 0.025)
    assert tets < vol.n_tets_full
    assert pop_fine > 3 * morph_fine        # without morphing refinements pop, however small the step
    assert morph_fine < 0.6 * morph_coarse  # with morphing the change shrinks with the step: no hidden jump
    # far away: the root level only; full: every non-empty cell
    lod = CloudLOD(vol, big_c=2.5, small_c=4.0, cutoff=shading.cutoff)
    far = lod.update(camera((-800.0, -1200.0, 1400.0)), SIZE, cull=False)
    assert set(far.leaves[:, 0].tolist()) <= {0} and far.stats["nodes"] == 4  # only the 4 roots, none refined
    full = lod.update(camera(), SIZE, cull=False, full=True)
    assert set(full.leaves[:, 0].tolist()) == {lod.levels}
    assert len(full.leaves) <= 16 * 16 * 8


def test_renderer_matches_the_unstructured_pt_renderer() -> None:
    """With a constant modulation field (l' = l) the cloud renderer must equal PT on the same tetrahedra."""
    from volviz.unstructured.render import render

    vol = small_volume(light=False)
    shading = CloudShading.npr(rho_max=0.5)
    table = build_cloud_table(shading, l_max=8 * math.sqrt(3), n_s=128, n_l=256)
    lod = CloudLOD(vol, big_c=2.5, small_c=4.0, cutoff=shading.cutoff)
    cam = camera()
    frame = lod.update(cam, SIZE)
    mine = render_cloud_image(frame, shading, table, cam, SIZE)
    mesh, _ = frame.to_tetmesh("f", eye=cam.position)
    assert mesh.n_cells == frame.n_tets
    # the octree's back-to-front order (a T-junction mesh defeats face-adjacency sorts)
    pt = render(mesh, shading.tf, cam, SIZE, method="pt", order=np.arange(mesh.n_cells), table=table)
    assert mine[..., 3].max() > 0.5
    diff = np.abs(mine - pt) * 255
    assert diff.max() < 0.5 and np.sqrt(np.mean(diff ** 2)) < 0.05


def test_bad_volumes_are_refused() -> None:
    with pytest.raises(ValueError, match="power-of-two"):
        CloudVolume(np.zeros((4, 5, 6)), np.zeros((4, 5, 6)))
    with pytest.raises(ValueError, match=">= 0"):
        CloudVolume(-np.ones((5, 5, 5)), np.zeros((5, 5, 5)))
    fit = CloudVolume.fit(np.ones((10, 12, 6)), np.ones((10, 12, 6)), (9.0, 11.0, 5.0))
    assert fit.shape == (17, 17, 9) and fit.root == 8


def test_culled_morphing_gives_every_listed_leaf_its_full_values() -> None:
    """With a view frustum, refined nodes whose box misses it are not morphed; every corner of every listed leaf
    still has exactly the value of the morph over all nodes, and the skipped part is real."""
    vol = small_volume()
    culled_lod, full_lod = CloudLOD(vol, big_c=2.5, small_c=6.0), CloudLOD(vol, big_c=2.5, small_c=6.0)
    cam = Camera((-6.0, -4.0, 6.0), (2.0, 12.0, 3.0), (0, 0, 1), 30, clipping_range=(0.5, 100))
    frame = culled_lod.update(cam, SIZE)
    full = full_lod.update(cam, SIZE, cull=False)
    assert 0 < frame.n_tets < full.n_tets
    for lv, a, b, c in frame.leaves:
        s = vol.root >> lv
        corners = np.array([[a + (q >> 2), b + ((q >> 1) & 1), c + (q & 1)] for q in range(8)]) * s
        for mine, theirs in zip(culled_lod.morphed, full_lod.morphed):
            np.testing.assert_array_equal(mine[tuple(corners.T)], theirs[tuple(corners.T)])
    vf_culled, vf_full = culled_lod.morphed[0], full_lod.morphed[0]
    assert np.count_nonzero(vf_culled != vf_full) > 20
