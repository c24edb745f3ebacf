"""Mutated copies of the array formats read through ``volviz.io.read`` (TIFF stacks, MATLAB v5 files, .npy): bit
flips (mostly in the first 512 bytes: headers, tags, IFDs) and truncations. Property, as for the other readers'
fuzz tests: a dataset of the original's size whose spacing and origin are finite -- or a ReadError naming the file;
never another exception, never a crash of this process; a truncated file is refused or read with exactly the
original's data (an ImageJ stack cut in its trailing page directories still holds every pixel)."""
from __future__ import annotations

import random

import numpy as np
import pytest
import scipy.io
import tifffile

from conftest import read_mutations
from volviz.bench import robustness as rb

STACK = np.random.default_rng(0).integers(0, 4000, size=(4, 6, 8)).astype(np.uint16)


def _files(folder):
    tifffile.imwrite(folder / "s.tif", STACK, imagej=True, metadata={"axes": "ZYX", "spacing": 2.0})
    tifffile.imwrite(folder / "z.tif", STACK, compression="zlib")
    scipy.io.savemat(folder / "v.mat", {"V": STACK.astype(np.float32)})
    scipy.io.savemat(folder / "c.mat", {"V": STACK.astype(np.float32)}, do_compression=True)
    np.save(folder / "a.npy", STACK)
    return {p.name: p for p in folder.iterdir()}


@pytest.mark.parametrize("name", ["s.tif", "z.tif", "v.mat", "c.mat", "a.npy"])
def test_mutated_array_files_read_consistently_or_raise_read_error(tmp_path, name):
    path = _files(tmp_path)[name]
    data = path.read_bytes()
    rng = random.Random(name)
    mutations = [rb.flip_bits(data, rng, min(512, len(data))) for _ in range(20)]
    mutations += [rb.truncate(data, at) for at in sorted(rng.sample(range(1, len(data)), 12))]
    assert read_mutations(path, mutations, truncated_reads_same=True) >= 8
