"""Animated volumes (Guthe §2.2.3): motion estimation, windowed MC, I/P/B in MPEG order, playback schedule."""
from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import data_file

from volviz.io import read
from volviz.regular import animation as A


def _field(shape, shift=(0, 0, 0), t=0.0):
    x, y, z = np.indices(shape).astype(np.float64)
    x, y, z = x - shift[0], y - shift[1], z - shift[2]
    f = (60 * np.sin(0.21 * x + 0.07 * y + 0.3 * t) + 50 * np.cos(0.17 * y - 0.11 * z) +
         40 * np.sin(0.19 * z + 0.05 * x) + 128)
    return np.clip(np.rint(f), 0, 255).astype(np.uint8)


def _moving_series(n, shape=(24, 20, 18)):
    return [_field(shape, shift=(t, -t // 2, (t * 2) // 3), t=0.0) for t in range(n)]


@pytest.mark.parametrize("search", ["local", "full"])
def test_motion_estimation_finds_a_known_shift(search):
    s = (3, -2, 5)
    ref = _field((40, 40, 40))
    cur = _field((40, 40, 40), shift=s)  # cur(x) = ref(x - s): the vector is -s
    mv = A.estimate_motion(cur, ref, search=search)
    assert mv.shape == (5, 5, 5, 3) and mv.dtype == np.int8
    interior = mv[1:4, 1:4, 1:4].reshape(-1, 3)
    assert np.all(interior == -np.array(s))
    pred = A.compensate(ref, mv)
    core = (slice(10, 30),) * 3  # windows of the interior blocks only
    assert np.array_equal(np.rint(pred[core]).astype(np.uint8), cur[core])


def test_cosine_windows_partition_unity_and_zero_motion_is_identity():
    w = A.window_weights()
    assert w.shape == (12,) and np.all(w > 0) and np.all(w[4:8] == 1)
    assert np.allclose(w[8:12] + w[0:4], 1.0, atol=1e-15)  # neighbour's rise + this block's fall
    ref = np.random.default_rng(0).integers(0, 256, (19, 9, 17)).astype(np.uint8)
    pred = A.compensate(ref, np.zeros(A.n_blocks(ref.shape) + (3,), np.int8))
    assert np.allclose(pred, ref, atol=1e-9)


def test_gop_types_and_mpeg_storage_order():
    fr = A.frame_types(12, "IBBPBBPPB")
    assert "".join(f.kind for f in fr) == "IBBPBBPPBIPP"  # trailing Bs -> P
    assert fr[1].refs == (0, 3) and fr[3].refs == (0,) and fr[8].refs == (7, 9) and fr[9].refs == ()
    assert A.storage_order(fr) == [0, 3, 1, 2, 6, 4, 5, 7, 9, 8, 10, 11]
    with pytest.raises(ValueError, match="pattern"):
        A.frame_types(5, "PBB")


@pytest.mark.parametrize("pattern", ["I", "IPP", "IBB", "IBBPBBPPB"])
@pytest.mark.parametrize("n", [1, 2, 7, 21])
def test_schedule_decodes_one_volume_per_frame(pattern, n):
    order = A.storage_order(A.frame_types(n, pattern))
    setup, per_frame = A.schedule(order)
    assert len(setup) <= 2 and len(setup) == (2 if "B" in pattern and n > 2 else 1)
    decoded = set(setup)
    for t in range(n):
        assert t in decoded  # shown only after it was decoded
        if per_frame[t] is not None:
            decoded.add(per_frame[t])
    assert all(x is not None for x in per_frame[:n - len(setup)])  # one decode per frame until the end
    assert setup + [x for x in per_frame if x is not None] == order  # each volume decoded once, in storage order


@pytest.mark.parametrize("pattern", ["IPP", "IBBPBBPPB"])
def test_lossless_series_round_trip_and_player(tmp_path, pattern):
    vols = _moving_series(11)
    info = A.compress_series(vols, tmp_path / "m.vvs", pattern=pattern)
    assert info["n"] == 11 and info["ratio"] > 1.0
    back = A.decompress_series(tmp_path / "m.vvs")
    assert all(np.array_equal(a, b) for a, b in zip(vols, back))
    player = A.SeriesPlayer(tmp_path / "m.vvs")
    for t in range(11):
        assert np.array_equal(player.frame(t), vols[t])
        if t < 10:
            mid = player.at(t + 0.25)  # 4D interpolation
            assert np.allclose(mid, 0.75 * vols[t] + 0.25 * vols[t + 1].astype(np.float32))
    k = len(player.setup_list)
    assert player.decodes_per_frame == [1] * (11 - k) + [0] * k
    assert len(player._have) <= 4  # released what is no longer needed
    with pytest.raises(ValueError, match="sequential"):
        player.frame(3)


def test_lossy_b_volumes_are_motion_compensation_only(tmp_path):
    vols = _moving_series(7)
    A.compress_series(vols, tmp_path / "q.vvs", pattern="IBB", mode="quality", quality=80)
    meta = json.loads((tmp_path / "q.vvs" / "series.json").read_text())
    kinds = {r["display"]: (r["type"], r["file"]) for r in meta["storage"]}
    assert all(f is None for k, f in kinds.values() if k == "B") and kinds[0][1] is not None
    back = A.decompress_series(tmp_path / "q.vvs")
    assert min(A.psnr(a, b) for a, b in zip(vols, back)) > 30.0


def test_storm_series_lossless(tmp_path):
    data_file("storm/Storm.pvm-t01")
    series = read(str(data_file("storm/Storm.pvm-t01")).replace("t01", "t%02d"))
    assert len(series) == 21
    A.compress_series(series, tmp_path / "storm.vvs", pattern="IBBPBBPPB")
    back = A.decompress_series(tmp_path / "storm.vvs")
    for t in (0, 5, 12, 20):
        assert np.array_equal(back[t], np.asarray(series.frame(t).data))
    (tmp_path / "storm.vvs" / "series.json").write_text("{}")
    with pytest.raises(A.SeriesError, match="storm.vvs"):
        A.SeriesDecoder(tmp_path / "storm.vvs")


def test_cli_compress_series(tmp_path, capsys):
    from volviz.regular.cli import compress_main

    pattern = str(data_file("storm/Storm.pvm-t01")).replace("t01", "t%02d")
    assert compress_main([pattern, "-o", str(tmp_path / "s.vvs"), "--series", "--pattern", "IPP", "--quiet"]) == 0
    assert "21 volumes (28, 28, 23)  pattern IPP  lossless" in capsys.readouterr().out
    back = A.decompress_series(tmp_path / "s.vvs")
    assert np.array_equal(back[20], np.asarray(read(pattern).frame(20).data))


def test_damaged_store_and_bad_input_name_the_problem(tmp_path):
    vols = _moving_series(4)
    store = tmp_path / "d.vvs"
    A.compress_series(vols, store, pattern="IPP")
    mv = sorted(store.glob("m*.bin"))[0]
    mv.write_bytes(b"\x00" + mv.read_bytes()[1:])
    with pytest.raises(A.SeriesError, match=mv.name):
        A.decompress_series(store)
    A.compress_series(vols, store, pattern="IPP")
    vvz = sorted(store.glob("v*.vvz"))[1]
    vvz.unlink()
    with pytest.raises(A.SeriesError, match=vvz.name):
        A.decompress_series(store)
    with pytest.raises(ValueError, match="8-bit"):
        A.compress_series([v.astype(np.uint16) for v in vols], tmp_path / "e.vvs")


def _store_bytes(path):
    return {p.name: p.read_bytes() for p in sorted(path.iterdir())}


def test_dask_cluster_encoding_is_bit_identical(tmp_path):
    from distributed import LocalCluster

    from volviz.regular.cli import compress_main

    vols = _moving_series(20, shape=(20, 16, 18))  # IBBPBBPPB: I at 0, 9, 18 -> three parts
    # in-process workers watch this process's memory, which is the whole test run's: without memory_limit=0 they
    # pause once it passes 80 % of their share of the machine, and the encoding waits for them for ever
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None,
                      memory_limit=0) as cluster:
        for kw in ({}, {"mode": "quality", "quality": 70}):
            A.compress_series(vols, tmp_path / "seq.vvs", **kw)
            A.compress_series(vols, tmp_path / "dask.vvs", scheduler=cluster.scheduler_address, **kw)
            seq, dist = _store_bytes(tmp_path / "seq.vvs"), _store_bytes(tmp_path / "dask.vvs")
            assert len(seq) > 20 and seq == dist
        # the CLI on the Storm series
        pattern = str(data_file("storm/Storm.pvm-t01")).replace("t01", "t%02d")
        args = [pattern, "--series", "--pattern", "IBBPBBPPB", "--quality", "80", "--quiet"]
        assert compress_main(args + ["-o", str(tmp_path / "s1.vvs")]) == 0
        assert compress_main(args + ["-o", str(tmp_path / "s2.vvs"), "--scheduler", cluster.scheduler_address]) == 0
    assert _store_bytes(tmp_path / "s1.vvs") == _store_bytes(tmp_path / "s2.vvs")
