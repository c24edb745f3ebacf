"""Per-node transform choice of lossless .vvz files: integer 5/3 or Haar / S-transform per octree node, recorded in
the brick table (container version 2) and honoured by the whole-volume decoder and the on-demand node decoder."""
from __future__ import annotations


import numpy as np
import pytest

from volviz.model.datasets import RegularVolume
from volviz.regular.codec import compress, decompress, info
from volviz.regular.container import KIND_NODE, KIND_ROOT, Reader, VVZError, Writer
from volviz.regular.nodes import NodeDecoder
from volviz.regular.wavelet import (HALF, TILE, TRANSFORM_53, TRANSFORM_HAAR, forward_tile_t, haar_forward_tile,
                                    inverse_tile_t, level_shapes, n_tiles)


def test_s_transform_matches_its_formulas_and_inverts():
    # d[n] = x[2n+1] - x[2n], s[n] = floor((x[2n] + x[2n+1]) / 2); a lone last sample passes through
    x = np.array([3, 9, 4, -1, 7], np.int64)
    w = np.zeros((TILE, TILE, TILE), np.int32)
    w[0, 0, :5] = x
    haar_forward_tile(w, 1, 1, 5)
    assert w[0, 0, :5].tolist() == [(3 + 9) // 2, (4 - 1) // 2, 7, 9 - 3, -1 - 4]
    rng = np.random.default_rng(2)
    for n in [(1, 1, 1), (2, 2, 2), (5, 7, 9), (32, 17, 32), (3, 32, 1)]:
        v = np.zeros((TILE, TILE, TILE), np.int32)
        v[:n[0], :n[1], :n[2]] = rng.integers(-(1 << 20), 1 << 20, n)
        ref = v.copy()
        forward_tile_t(v, *n, TRANSFORM_HAAR)
        inverse_tile_t(v, np.empty_like(v), *n, TRANSFORM_HAAR)
        assert np.array_equal(v[:n[0], :n[1], :n[2]], ref[:n[0], :n[1], :n[2]])


def _single_voxel() -> np.ndarray:
    a = np.zeros((37, 16, 50), np.uint8)
    a[21, 5, 33] = 255
    return a


def _full_range_u16() -> np.ndarray:
    rng = np.random.default_rng(4)
    a = rng.integers(0, 65536, (33, 18, 20)).astype(np.uint16)
    a[:, :9] = 0  # sparse half
    a[0, 0, 0], a[1, 0, 0] = 65535, 0
    return a


def _full_range_i16() -> np.ndarray:
    rng = np.random.default_rng(5)
    a = rng.integers(-32768, 32768, (17, 20, 9)).astype(np.int16)
    a[::2, ::3] = -32768
    a[1, 1, 1] = 32767
    return a


def _sparse_noise(shape) -> np.ndarray:
    rng = np.random.default_rng(6)
    return (rng.integers(1, 4, shape) * (rng.random(shape) < 0.1)).astype(np.uint8)


CASES = {
    "zeros": lambda: np.zeros((40, 33, 17), np.uint8),
    "single_voxel": _single_voxel,
    "u16_full_range": _full_range_u16,
    "i16_full_range": _full_range_i16,
    "tiny": lambda: np.array([[[200]]], np.uint8),
    "odd_shape": lambda: _sparse_noise((65, 2, 31)),
}


@pytest.mark.parametrize("transform", ["5/3", "haar", "auto"])
@pytest.mark.parametrize("coder", ["rans", "arith"])
@pytest.mark.parametrize("case", sorted(CASES))
def test_lossless_round_trip_of_each_transform(tmp_path, case, coder, transform):
    data = CASES[case]()
    path = tmp_path / "c.vvz"
    meta = compress(RegularVolume(data), path, coder=coder, transform=transform)
    back = decompress(path).data
    assert back.dtype == data.dtype and back.shape == data.shape
    assert np.array_equal(back, data)
    tfs = Reader(path).table["transform"]
    if transform == "5/3":
        assert meta["haar_bricks"] == 0 and (tfs == TRANSFORM_53).all()
    elif transform == "haar":  # every node brick says S-transform (the root's record is 0)
        kinds = Reader(path).table["kind"]
        assert (tfs[kinds == KIND_NODE] == TRANSFORM_HAAR).all() and (tfs[kinds == KIND_ROOT] == 0).all()
    assert meta["transform"] == transform


@pytest.mark.parametrize("transform", ["5/3", "haar", "auto"])
def test_float_input_through_the_quantisation(tmp_path, transform):
    rng = np.random.default_rng(8)
    data = (rng.standard_normal((20, 35, 18)) * (rng.random((20, 35, 18)) < 0.2) * 3.5 - 1.25).astype(np.float32)
    path = tmp_path / "f.vvz"
    compress(RegularVolume(data), path, coder="arith", transform=transform)
    back = decompress(path).data
    lo, hi = float(data.min()), float(data.max())
    q = np.rint((data.astype(np.float64) - lo) / (hi - lo) * 65535)
    assert back.dtype == np.float32
    assert np.array_equal(back, (lo + q * ((hi - lo) / 65535.0)).astype(np.float32))  # exact on the 16-bit grid
    # the documented bound (hi - lo) / 131070, plus the float32 rounding of the output
    assert np.abs(back.astype(np.float64) - data).max() <= (hi - lo) / 131070 + 2 ** -23 * max(abs(lo), abs(hi))


def _mixed_volume() -> np.ndarray:
    """64^3 8-bit: a smooth ramp in x < 32 (the 5/3 codes it smaller), sparse low-valued noise in x >= 32
    (the S-transform does)."""
    x, y, z = np.indices((64, 64, 64))
    data = (2 * x + y + z) // 2
    data[32:] = _sparse_noise((32, 64, 64))
    return data.astype(np.uint8)


@pytest.fixture(scope="module")
def mixed(tmp_path_factory):
    data = _mixed_volume()
    path = tmp_path_factory.mktemp("tf") / "m.vvz"
    compress(RegularVolume(data), path, coder="arith")
    return data, path


def test_per_node_choice_is_recorded_and_honoured(mixed, tmp_path):
    data, path = mixed
    rd = Reader(path)
    table = rd.table.copy()
    level1 = table[(table["kind"] == KIND_NODE) & (table["level"] == 1)]
    t0 = level1["tile"] % 2  # tiles x-fastest: 2 tiles per axis; x >= 32 is t0 == 1
    assert (level1["transform"][t0 == 0] == TRANSFORM_53).all()
    assert (level1["transform"][t0 == 1] == TRANSFORM_HAAR).all()
    assert info(path)["haar_bricks"] >= 4
    assert np.array_equal(decompress(path).data, data)
    # the decoder follows the record: the same payloads with one transform flipped decode differently there only
    flip = int(np.nonzero((table["kind"] == KIND_NODE) & (table["level"] == 1) & (table["transform"] == 1))[0][0])
    other = tmp_path / "flipped.vvz"
    with Writer(other) as w:
        for i, rec in enumerate(table):
            off, size = int(rec["offset"]), int(rec["size"])
            tf = int(rec["transform"]) ^ (1 if i == flip else 0)
            w.add(int(rec["level"]), int(rec["kind"]), int(rec["tile"]), np.asarray(rd.payload[off:off + size]), tf)
        w.close(dict(rd.meta))
    rd.close()
    back = decompress(other).data
    t = int(table[flip]["tile"])
    box = tuple(slice(c * TILE, (c + 1) * TILE) for c in (t % 2, (t // 2) % 2, t // 4))
    assert not np.array_equal(back[box], data[box])
    outside = np.ones(data.shape, bool)
    outside[box] = False
    assert np.array_equal(back[outside], data[outside])


def test_s_transform_record_in_a_lossy_file_is_refused(tmp_path):
    src, bad = tmp_path / "q.vvz", tmp_path / "bad.vvz"
    compress(RegularVolume(_mixed_volume()), src, quality=70)
    assert info(src)["haar_bricks"] == 0  # lossy files always use the 5/3
    rd = Reader(src)
    with Writer(bad) as w:
        for i, rec in enumerate(rd.table):
            off, size = int(rec["offset"]), int(rec["size"])
            w.add(int(rec["level"]), int(rec["kind"]), int(rec["tile"]), np.asarray(rd.payload[off:off + size]),
                  1 if rec["kind"] == KIND_NODE and rec["level"] == 1 else 0)
        w.close(dict(rd.meta))
    rd.close()
    with pytest.raises(VVZError, match=r"bad\.vvz.*brick \d+ \(level 1, tile \d+\) names transform 1, not valid in "
                                        r"a lossy"):
        decompress(bad)


def _reference_pyramid(data: np.ndarray, table: np.ndarray) -> list[np.ndarray]:
    """Lowpass pyramid with the recorded transform of every tile (independent of the encoder's choice logic)."""
    shapes = level_shapes(data.shape)
    cur = data.astype(np.int32)
    out = [cur]
    for lev in range(1, len(shapes)):
        low = np.zeros(shapes[lev], np.int32)
        c = [n_tiles(s) for s in cur.shape]
        for t2 in range(c[2]):
            for t1 in range(c[1]):
                for t0 in range(c[0]):
                    tile = t0 + c[0] * (t1 + c[1] * t2)
                    rec = table[(table["kind"] == KIND_NODE) & (table["level"] == lev) & (table["tile"] == tile)]
                    blk = cur[t0 * TILE:(t0 + 1) * TILE, t1 * TILE:(t1 + 1) * TILE, t2 * TILE:(t2 + 1) * TILE]
                    n = blk.shape
                    w = np.zeros((TILE, TILE, TILE), np.int32)
                    w[:n[0], :n[1], :n[2]] = blk
                    forward_tile_t(w, *n, int(rec["transform"][0]))
                    m = [(s + 1) // 2 for s in n]
                    low[t0 * HALF:t0 * HALF + m[0], t1 * HALF:t1 * HALF + m[1], t2 * HALF:t2 * HALF + m[2]] = \
                        w[:m[0], :m[1], :m[2]]
        cur = low
        out.append(cur)
    return out


def test_octree_nodes_with_mixed_transforms(mixed):
    data, path = mixed
    table = Reader(path).table.copy()
    pyramid = _reference_pyramid(data, table)
    assert len(set(table["transform"][table["kind"] == KIND_NODE].tolist())) == 2
    dec = NodeDecoder(path)
    try:
        assert np.array_equal(dec.root(), pyramid[dec.levels])
        frontier = {(dec.levels, (0, 0, 0)): dec.root()}
        seen = {dec.levels: 1}
        while frontier:  # refine every node one level at a time, on demand
            key, block = frontier.popitem()
            level = key[0]
            p = key[1]
            ref = pyramid[level][p[0] * HALF:(p[0] + 1) * HALF, p[1] * HALF:(p[1] + 1) * HALF,
                                 p[2] * HALF:(p[2] + 1) * HALF]
            assert np.array_equal(block, ref), key  # coarse node = lowpass of the transforms its subtree used
            if level > 0:
                kids = dec.children(key, block)
                seen[level - 1] = seen.get(level - 1, 0) + len(kids)
                frontier.update(kids)
        assert seen[0] == 4 ** 3 and seen[1] == 2 ** 3  # every 16^3 leaf of the 64^3 volume was reached
    finally:
        dec.close()


def test_node_statistics_follow_the_recorded_transforms(mixed):
    from volviz.regular.nodes import _expand, node_statistics

    data, path = mixed
    dec = NodeDecoder(path)
    try:
        tfs = dec.transforms()
        assert sorted(set(tfs[1].tolist())) == [TRANSFORM_53, TRANSFORM_HAAR]
        stats, _, _ = node_statistics(data, tfs)
        stats53, _, _ = node_statistics(data)
    finally:
        dec.close()
    pyramid = _reference_pyramid(data, Reader(path).table.copy())
    shapes = level_shapes(data.shape)
    v_l = _expand(pyramid[1], shapes, 1)  # what the renderer shows for the level-1 nodes
    for c in np.ndindex(2, 2, 2):
        box = tuple(slice(32 * c[a], 32 * c[a] + 32) for a in range(3))
        l2 = np.sqrt(np.sum((data[box].astype(np.float64) - v_l[box]) ** 2))
        assert stats[1].l2[c] == pytest.approx(l2, rel=1e-12)
    haar = tfs[1].reshape(2, 2, 2, order="F") == TRANSFORM_HAAR
    assert not np.allclose(stats[1].l2[haar], stats53[1].l2[haar])  # the 5/3 assumption would differ there
    assert np.allclose(stats[1].l2[~haar], stats53[1].l2[~haar])
    assert (stats[0].l2 == 0).all()


def test_corrupt_s_transform_brick_is_named_and_the_rest_loads(mixed, tmp_path):
    import warnings

    from volviz.regular.container import CorruptBrickError, CorruptBrickWarning

    data, src = mixed
    path = tmp_path / "c.vvz"
    path.write_bytes(src.read_bytes())
    table = Reader(path).table.copy()
    # level-1 tile 3 (t = 1, 1, 0: voxels x 32..64, y 32..64, z 0..32) lies in the sparse half: S-transform
    i = int(np.nonzero((table["level"] == 1) & (table["kind"] == KIND_NODE) & (table["tile"] == 3))[0][0])
    assert table[i]["transform"] == TRANSFORM_HAAR and table[i]["size"] > 0
    raw = bytearray(path.read_bytes())
    raw[int(table[i]["offset"]) + int(table[i]["size"]) // 2] ^= 0x5A
    path.write_bytes(bytes(raw))
    report: list = []
    with pytest.warns(CorruptBrickWarning, match=rf"brick {i} \(node, level 1, tile 3"):
        back = decompress(path, report=report).data
    assert len(report) == 1 and report[0]["region"] == [[32, 64], [32, 64], [0, 32]]
    mask = np.zeros(data.shape, bool)
    mask[32:64, 32:64, 0:32] = True
    assert np.array_equal(back[~mask], data[~mask])
    # the damaged tile shows its own transform with zero details: constant 2x2x2 blocks of the S-transform lowpass
    low = _reference_pyramid(data, table)[1][16:32, 16:32, 0:16]
    assert np.array_equal(back[mask].reshape(32, 32, 32), np.repeat(np.repeat(np.repeat(low, 2, 0), 2, 1), 2, 2))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(CorruptBrickError, match="tile 3"):
            decompress(path, strict=True)
