"""Wavelet codec (Guthe §2.2.1-2.2.2, §2.3.1): lossless bit-exactness, PSNR targets, float quantisation."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from conftest import data_file

from volviz.io import read, read_slice_stack
from volviz.model.datasets import RegularVolume
from volviz.regular.codec import compress, decompress, info
from volviz.regular.container import CorruptBrickWarning
from volviz.regular.wavelet import TILE, forward_tile, inverse_tile, level_shapes


def _psnr(a: np.ndarray, b: np.ndarray, peak: float) -> float:
    mse = float(np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2))
    return math.inf if mse == 0 else 10 * math.log10(peak * peak / mse)


def test_lifting_matches_the_53_formulas():
    # d[n] = x[2n+1] - floor((x[2n] + x[2n+2]) / 2), s[n] = x[2n] + floor((d[n-1] + d[n] + 2) / 4), mirrored
    x = np.array([3, 9, 4, 1, 7], np.int64)
    d = [9 - (3 + 4) // 2, 1 - (4 + 7) // 2]
    s = [3 + (d[0] + d[0] + 2) // 4, 4 + (d[0] + d[1] + 2) // 4, 7 + (d[1] + d[1] + 2) // 4]
    w = np.zeros((TILE, TILE, TILE), np.int32)
    w[0, 0, :5] = x
    forward_tile(w, 1, 1, 5)
    assert w[0, 0, :5].tolist() == s + d
    inverse_tile(w, 1, 1, 5)
    assert w[0, 0, :5].tolist() == x.tolist()


@pytest.mark.parametrize("shape", [(1, 1, 1), (5, 7, 9), (33, 17, 40), (2, 65, 3)])
def test_tile_transform_is_bit_exact(shape):
    rng = np.random.default_rng(1)
    w = np.zeros((TILE, TILE, TILE), np.int32)
    n = tuple(min(s, TILE) for s in shape)
    x = rng.integers(-40000, 40000, n).astype(np.int32)
    w[:n[0], :n[1], :n[2]] = x
    forward_tile(w, *n)
    inverse_tile(w, *n)
    assert np.array_equal(w[:n[0], :n[1], :n[2]], x)


@pytest.mark.parametrize("coder", ["rans", "arith"])
@pytest.mark.parametrize("shape,dtype", [((5, 7, 9), np.uint8), ((33, 17, 40), np.int16), ((70, 3, 35), np.uint16)])
def test_lossless_random_odd_sizes(tmp_path, coder, shape, dtype):
    rng = np.random.default_rng(7)
    lo, hi = np.iinfo(dtype).min, np.iinfo(dtype).max
    data = rng.integers(lo, int(hi) + 1, shape).astype(dtype)
    data[: shape[0] // 2] = data[0, 0, 0]  # a constant part: stripped (all-zero) nodes
    out = tmp_path / "r.vvz"
    compress(RegularVolume(data), out, coder=coder)
    back = decompress(out).data
    assert back.dtype == dtype and back.shape == shape
    assert np.array_equal(back, data)


@pytest.mark.parametrize("coder", ["rans", "arith"])
def test_lossless_neghip(tmp_path, coder):
    vol = read(data_file("volumes/neghip.slc"))
    out = tmp_path / "n.vvz"
    meta = compress(vol, out, coder=coder)
    back = decompress(out)
    assert np.array_equal(back.data, vol.data)
    assert back.spacing == vol.spacing
    assert meta["lossless"] and meta["levels"] == len(level_shapes((66, 66, 66))) - 1 == 3
    assert meta["ratio"] > 2.0  # measured 3.0 (rans) / 3.2 (arith) on this 8-bit volume


def test_lossless_headsq_16bit(tmp_path):
    vol = read_slice_stack(str(data_file("headsq/quarter.1").parent / "quarter.%d"), dims=(64, 64, 93),
                           dtype="<u2")
    out = tmp_path / "h.vvz"
    meta = compress(vol, out)
    assert np.array_equal(decompress(out).data, vol.data)
    assert meta["dtype"] == "uint16" and meta["ratio"] > 1.5


@pytest.mark.parametrize("target", [40.0, 50.0])
def test_psnr_target_met(tmp_path, target):
    vol = read(data_file("volumes/neghip.slc"))
    out = tmp_path / "p.vvz"
    meta = compress(vol, out, psnr=target)
    achieved = _psnr(decompress(out).data, vol.data, 255.0)
    assert achieved >= target
    assert achieved < target + 3.0  # the search lands near the target, not at lossless
    assert meta["psnr"] == pytest.approx(achieved, abs=1e-3)
    assert meta["file_bytes"] < info(out)["original_bytes"] / 3


@pytest.mark.parametrize("coder", ["rans", "arith"])
def test_quality_trades_rate_for_error(tmp_path, coder):
    vol = read(data_file("volumes/neghip.slc"))
    sizes, errors = [], []
    for q in (90, 70, 50):
        meta = compress(vol, tmp_path / f"q{q}.vvz", quality=q, coder=coder)
        sizes.append(meta["file_bytes"])
        with warnings.catch_warnings():
            warnings.simplefilter("error", CorruptBrickWarning)  # every lossy brick decodes consistently
            errors.append(_psnr(decompress(tmp_path / f"q{q}.vvz").data, vol.data, 255.0))
    assert sizes[0] > sizes[1] > sizes[2]
    assert errors[0] > errors[1] > errors[2]


def test_float_input_quantised_to_16_bits(tmp_path):
    rng = np.random.default_rng(3)
    data = (np.cumsum(rng.normal(size=(20, 21, 22)), axis=2) * 0.1).astype(np.float32)
    out = tmp_path / "f.vvz"
    compress(RegularVolume(data), out)
    back = decompress(out).data
    lo, hi = float(data.min()), float(data.max())
    assert back.dtype == np.float32
    assert np.max(np.abs(back.astype(np.float64) - data)) <= (hi - lo) / 131070 * 1.001 + 1e-6


def test_nonfinite_float_refused(tmp_path):
    data = np.zeros((4, 4, 4), np.float32)
    data[1, 2, 3] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        compress(RegularVolume(data), tmp_path / "x.vvz")
