"""The ``.vvz`` metadata the decoder does not use (issue #32): mode, lossless, quality, PSNR target, measured PSNR
and its scope, peak, wavelet choice, and any key the codec does not write, in crafted files with every checksum
recomputed, are refused with one line naming the file, the field and the value (``volviz info`` showed them as
written); the files the codec writes in each mode still read."""
from __future__ import annotations

import json

import numpy as np
import pytest
from test_reliability_vvz import _crafted, _parts, _refused, _volume

from volviz.cli import main
from volviz.model.datasets import RegularVolume
from volviz.regular.codec import compress, decompress, info


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """One file of each mode: lossless (uint8), quality 50 and a PSNR target (float32)."""
    folder = tmp_path_factory.mktemp("vvz-modes")
    made = {"lossless": folder / "l.vvz", "quality": folder / "q.vvz", "psnr": folder / "p.vvz"}
    compress(RegularVolume(_volume()), made["lossless"])
    compress(RegularVolume(_volume(dtype=np.float32)), made["quality"], quality=50)
    compress(RegularVolume(_volume(dtype=np.float32)), made["psnr"], psnr=40)
    return made


def test_each_mode_as_written_reads_and_shows_its_fields(files):
    shown = {mode: info(path) for mode, path in files.items()}
    assert (shown["lossless"]["mode"], shown["lossless"]["lossless"], shown["lossless"]["psnr"]) == \
        ("lossless", True, None)
    assert (shown["quality"]["mode"], shown["quality"]["quality"], shown["quality"]["delta"]) == \
        ("quality", 50.0, 2.0 ** 4)
    assert shown["psnr"]["mode"] == "psnr" and shown["psnr"]["psnr"] >= 40 and shown["psnr"]["peak"] == 65535
    for path in files.values():
        assert decompress(path).data.shape == (40, 36, 34)


@pytest.mark.parametrize("mode, field, value, pattern", [
    ("lossless", "mode", "fast", r"'mode' is 'fast'; expected lossless, quality or psnr$"),
    ("lossless", "mode", 3, r"'mode' is 3; expected lossless, quality or psnr$"),
    ("lossless", "lossless", False, r"'lossless' is False; expected true \(delta is 0\.0\)$"),
    ("lossless", "lossless", 1, r"'lossless' is 1; expected true"),
    ("quality", "lossless", True, r"'lossless' is True; expected false \(delta is 16\.0\)$"),
    ("lossless", "quality", 250, r"'quality' is 250; expected null or a number from 0 to 100$"),
    ("lossless", "quality", "high", r"'quality' is 'high'; expected null or a number from 0 to 100$"),
    ("quality", "quality", 60, r"'delta' is 16\.0; expected 8\.0 \(quality 60\)$"),
    ("quality", "quality", None, r"'quality' is None; expected a number from 0 to 100 in a file of mode 'quality'$"),
    ("psnr", "psnr_target", None, r"'psnr_target' is None; expected a number of dB in a file of mode 'psnr'$"),
    ("psnr", "psnr_target", -5, r"'psnr_target' is -5; expected null or a number of dB from 0 to 1000$"),
    ("psnr", "psnr", 1e300, r"'psnr' is 1e\+300; expected null or a number of dB from 0 to 1000$"),
    ("psnr", "psnr", [40], r"'psnr' is \[40\]; expected null or a number of dB"),
    ("lossless", "psnr", 45.0, r"'psnr' is 45\.0; expected null \(lossless\)$"),
    ("psnr", "psnr_scope", "all", r"'psnr_scope' is 'all'; expected volume or central 256\^3 crop$"),
    ("lossless", "peak", 65535, r"'peak' is 65535; expected 255 \(the peak of kind 'uint8'\)$"),
    ("psnr", "peak", -1, r"'peak' is -1; expected 65535 \(the peak of kind 'float'\)$"),
    ("lossless", "transform", "dct", r"'transform' is 'dct'; expected auto, 5/3 or haar$"),
    ("quality", "transform", "haar", r"'transform' is 'haar'; expected 5/3 \(a lossy file\)$"),
    ("lossless", "comment", "x" * 100, r"'comment' is not a \.vvz metadata field \(known: coder, "),
])
def test_each_described_field_is_checked(files, tmp_path, mode, field, value, pattern):
    path = _crafted(files[mode], tmp_path, meta_edit=lambda m: m.update({field: value}))
    _refused(path, f"metadata field {pattern}")


def test_mode_lossless_with_a_quantiser_step_is_refused(files, tmp_path):
    path = _crafted(files["quality"], tmp_path, meta_edit=lambda m: m.update(mode="lossless", quality=None))
    _refused(path, r"metadata field 'delta' is 16\.0; expected 0 in a file of mode 'lossless'$")


def test_a_file_of_an_older_writer_without_the_described_fields_reads(files, tmp_path):
    described = ("mode", "quality", "psnr_target", "psnr", "psnr_scope", "lossless", "peak", "transform")
    path = _crafted(files["lossless"], tmp_path, meta_edit=lambda m: [m.pop(k) for k in described])
    assert set(described).isdisjoint(json.loads(_parts(path.read_bytes())[1]))
    assert np.array_equal(decompress(path).data, _volume())


def test_volviz_info_refuses_a_described_field_in_one_line(files, tmp_path, capsys):
    path = _crafted(files["lossless"], tmp_path, meta_edit=lambda m: m.update(peak="loud"))
    assert main(["info", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"volviz: error: {path}: metadata field 'peak' is 'loud'; expected 255 (the peak of kind 'uint8')"]


def test_a_brick_record_s_reserved_field_and_the_root_s_transform_are_checked(files, tmp_path):
    """The re-run's .vvz cases accepted with checksums recomputed: a record's reserved word set to 4294967295, the
    root brick's transform set to 65535 (the decoder ignores both)."""
    root = lambda t: int(np.nonzero(t["kind"] == 0)[0][0])  # noqa: E731

    path = _crafted(files["lossless"], tmp_path, table_edit=lambda t: t["res1"].__setitem__(0, 4294967295))
    _refused(path, r"brick 0 \(level 1, tile 0\) field reserved is 4294967295; expected 0$")
    path = _crafted(files["lossless"], tmp_path, table_edit=lambda t: t["transform"].__setitem__(root(t), 65535))
    _refused(path, r"brick \d+ \(level \d+, tile 0\) field transform is 65535; the root brick's is 0$")
