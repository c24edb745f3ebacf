"""Wavelet-octree LOD (Guthe §2.3.1-2.3.5, Eq. 2.7) and the LRU node cache (§2.3.7)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from volviz.model.datasets import RegularVolume
from volviz.optics import TransferFunction
from volviz.regular.codec import compress
from volviz.regular.lod import LodCamera, LodTree, eq27_error


@pytest.fixture(scope="module")
def noisy(tmp_path_factory):
    """64^3: smooth ramp + noise, stronger noise in the block x<32, y<32, z>=32."""
    rng = np.random.default_rng(3)
    x = np.indices((64, 64, 64)).sum(0)
    data = x + rng.integers(0, 8, x.shape)
    data[:32, :32, 32:] += rng.integers(0, 40, (32, 32, 32))
    data = data.astype(np.uint8)
    path = tmp_path_factory.mktemp("lod") / "n.vvz"
    compress(RegularVolume(data), path)
    return data, path


def _covered(tree, sel):
    cover = np.zeros(tree.decoder.dims, np.int32)
    for level, p in sel.nodes:
        s = [p[i] * 16 << level for i in range(3)]
        e = 16 << level
        cover[s[0]:s[0] + e, s[1]:s[1] + e, s[2]:s[2] + e] += 1
    return cover


def test_budget_respected_and_selection_partitions_the_volume(noisy):
    data, path = noisy
    tree = LodTree(path, volume=RegularVolume(data))
    assert tree.levels == 2
    cam = LodCamera(eye=(300.0, 20.0, 40.0), target=(32.0, 32.0, 32.0), fov_y=40, height=512)
    for budget in (1, 7, 8, 15, 20, 40):
        sel = tree.select(cam, budget)
        assert 1 <= len(sel.nodes) <= budget
        assert np.all(_covered(tree, sel) == 1)  # every voxel in exactly one block
    assert len(tree.select(cam, 8).nodes) == 8  # root -> its 8 children
    with pytest.raises(ValueError, match="budget"):
        tree.select(cam, 0)


def test_closer_and_higher_error_nodes_refine_first(noisy):
    data, path = noisy
    tree = LodTree(path, volume=RegularVolume(data))
    # from far above (+z), all top-layer level-1 nodes have the same depth: the noisiest one refines first
    top = LodCamera(eye=(32.0, 32.0, 5000.0), target=(32.0, 32.0, 0.0), fov_y=5, height=1024)
    sel = tree.select(top, 15)
    refined = {k for k in sel.nodes if k[0] == 0}
    assert len(refined) == 8 and all(p[0] < 2 and p[1] < 2 and p[2] >= 2 for _, p in refined)
    errs = {p: tree.l2_error((1, p)) for p in [(a, b, 1) for a in (0, 1) for b in (0, 1)]}
    assert max(errs, key=errs.get) == (0, 0, 1)
    # close to the +x face, depth outweighs the 5x larger error of the noisy -x block: a +x node refines first
    side = LodCamera(eye=(66.0, 16.0, 40.0), target=(0.0, 16.0, 40.0), fov_y=90, height=1024)
    sel = tree.select(side, 15)
    leaves = [p for lvl, p in sel.nodes if lvl == 0]
    assert leaves and all(p[0] >= 2 for p in leaves)
    # looking away from the volume: everything culled
    away = LodCamera(eye=(120.0, 16.0, 16.0), target=(500.0, 16.0, 16.0))
    sel = tree.select(away, 50)
    assert sel.nodes == [] and sel.culled == 1


def test_full_budget_is_lossless_and_blocks_overlap_by_one_voxel(noisy):
    data, path = noisy
    tree = LodTree(path, cache_bytes=1 << 30)
    cam = LodCamera(eye=(32.0, 32.0, 200.0), target=(32.0, 32.0, 0.0), fov_y=90, height=4096)
    sel = tree.select(cam, 10_000)
    assert all(k[0] == 0 for k in sel.nodes) and len(sel.nodes) == 64
    assert np.array_equal(tree.reconstruct(sel), data.astype(np.int32))
    b = tree.block((0, (1, 2, 3)))
    assert b.data.shape == (17, 17, 16) and b.origin == (16.0, 32.0, 48.0) and b.spacing == (1.0, 1.0, 1.0)
    assert np.array_equal(b.data, data[16:33, 32:49, 48:64].astype(np.float32))
    coarse = tree.block((1, (0, 0, 0)))
    assert coarse.data.shape == (17, 17, 17) and coarse.spacing == (2.0, 2.0, 2.0)


def test_transparent_blocks_are_skipped(noisy):
    data, path = noisy
    tree = LodTree(path, volume=RegularVolume(data))
    tf = TransferFunction([150.0, 255.0], [[1, 1, 1], [1, 0, 0]], [0.0, 2.0])  # rho > 0 only above 150
    cam = LodCamera(eye=(32.0, 32.0, 200.0), target=(32.0, 32.0, 0.0), fov_y=90, height=4096)
    sel = tree.select(cam, 10_000, tf=tf, mode="tf")
    assert sel.skipped_transparent > 0
    cover = _covered(tree, sel)
    assert cover.max() == 1
    assert np.all(cover[data > 150] == 1)  # every visible voxel is drawn...
    for key in sel.nodes:  # ...and no drawn block is transparent
        assert not tree.transparent(key, tf)
    # all-transparent TF: nothing at all is drawn
    none = TransferFunction([300.0, 400.0], [[1, 1, 1], [1, 1, 1]], [1.0, 1.0])
    assert tree.select(cam, 100, tf=none, mode="tf").nodes == []


def test_eq27_error_bound():
    diag = 10.0
    # D_min = 0: err_O at the diagonal
    e = eq27_error(np.array([0.0]), np.array([0.5]), np.array([1.0]), np.array([1.0]), diag)
    err_o = 1 - math.exp(-5.0)
    assert e[0] == pytest.approx(err_o + 1.0 * err_o)
    # err_O optimum inside the block: d* = ln(Dmax/Dmin)/(Dmax-Dmin)
    dmin, dmax = 0.1, 0.4
    d = math.log(dmax / dmin) / (dmax - dmin)
    e = eq27_error(np.array([dmin]), np.array([dmax]), np.array([0.0]), np.array([0.0]), diag)
    assert e[0] == pytest.approx(math.exp(-d * dmin) - math.exp(-d * dmax))
    # no deviation: no error
    assert eq27_error(np.array([0.3]), np.array([0.3]), np.array([2.0]), np.array([2.0]), diag)[0] == 0.0


def test_lru_cache_budget_evicts_only_decoded_leaves(noisy):
    data, path = noisy
    tree = LodTree(path, cache_bytes=40 * 16 ** 3 * 4, volume=RegularVolume(data))
    for p in np.ndindex(4, 4, 4):
        got = tree.node((0, p))
        s = [16 * c for c in p]
        assert np.array_equal(got, data[s[0]:s[0] + 16, s[1]:s[1] + 16, s[2]:s[2] + 16])
    c = tree.cache
    assert c.bytes <= c.budget and c.evictions > 0
    for key in list(c._data):  # every cached node keeps its parent chain
        level, p = key
        if level < tree.levels:
            assert (level + 1, tuple(q // 2 for q in p)) in c
    n_dec = tree.decoder.decoded_bricks
    tree.node((0, (3, 3, 3)))  # most recent: a cache hit, no decode
    assert tree.decoder.decoded_bricks == n_dec and c.hits > 0


def test_prefetch_in_a_worker_thread_fills_the_cache(noisy):
    from concurrent.futures import ThreadPoolExecutor

    data, path = noisy
    tree = LodTree(path, volume=RegularVolume(data))
    cam = LodCamera(eye=(32.0, 32.0, 200.0), target=(32.0, 32.0, 0.0), fov_y=90, height=4096)
    sel = tree.select(cam, 64)
    with ThreadPoolExecutor(1) as ex:
        assert ex.submit(tree.prefetch, sel).result() == 1 + 8  # root's and the 8 level-1 nodes' bricks
    n = tree.decoder.decoded_bricks
    assert np.array_equal(tree.reconstruct(sel), data.astype(np.int32))
    assert tree.decoder.decoded_bricks == n  # everything came from the cache


def test_back_to_front_order(noisy):
    data, path = noisy
    tree = LodTree(path, volume=RegularVolume(data))
    cam = LodCamera(eye=(300.0, 20.0, 40.0), target=(32.0, 32.0, 32.0), fov_y=40, height=512)
    order = tree.back_to_front(tree.select(cam, 8), cam)
    assert sorted(order) == sorted(tree.select(cam, 8).nodes)
    assert order[0][1][0] == 0 and order[-1][1][0] == 1  # the -x blocks first, the +x (near) ones last


def test_statistics_sidecar_is_reused_only_for_its_file(tmp_path):
    rng = np.random.default_rng(5)
    data = rng.integers(0, 200, (40, 33, 20)).astype(np.uint8)
    path = tmp_path / "s.vvz"
    compress(RegularVolume(data), path)
    a = LodTree(path)  # full decode, writes s.vvz.lod.npz
    assert a.sidecar.is_file()
    b = LodTree(path)  # from the sidecar
    for sa, sb in zip(a.stats, b.stats):
        assert np.array_equal(sa.l2, sb.l2) and np.array_equal(sa.hist_pos, sb.hist_pos)
        assert np.array_equal(sa.vmin, sb.vmin) and np.array_equal(sa.hist_n, sb.hist_n)
    compress(RegularVolume(data // 2), path)  # a different file at the same path: the sidecar is stale
    c = LodTree(path)
    assert c.stats[1].l2.max() != a.stats[1].l2.max()
