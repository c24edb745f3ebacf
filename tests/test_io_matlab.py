"""MATLAB MAT-files (``volviz.io.matlab``) through ``volviz.io.read``: v5 / v7 written by SciPy, v7.3 (HDF5 with
MATLAB's header and transposed storage) written by h5py as MATLAB lays it out; the variable shown, MATLAB's meshgrid
layout (V(r, c, s) at x = c, y = r, z = s), channels, time, images, and files that are no volumes."""
from __future__ import annotations

import h5py
import numpy as np
import pytest
import scipy.io

import volviz.io as vio
from volviz.io.errors import ReadError, ReadWarning
from volviz.model import Image2D, RegularVolume, TimeSeries

V = np.random.default_rng(0).normal(size=(4, 5, 6))          # MATLAB's V(r, c, s): 4 rows, 5 columns, 6 slices
AS_SHOWN = np.transpose(V, (1, 0, 2))                        # x = column, y = row, z = slice


def _v73(path, **variables):
    """A v7.3 MAT-file as MATLAB writes one: a 512-byte text header as HDF5 user block, each array stored as the
    C-order transpose of its column-major data, with its MATLAB_class."""
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, (values, kind) in variables.items():
            f.create_dataset(name, data=np.transpose(values)).attrs["MATLAB_class"] = np.bytes_(kind)
    header = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Wed Nov 25 2026 HDF5 schema 1.00 ."
    with open(path, "r+b") as fh:
        fh.write(header.ljust(116) + b"\0" * 8 + b"\x00\x02IM")
    return path


def test_v5_and_v73_files_show_the_largest_volume_in_meshgrid_layout(tmp_path):
    scipy.io.savemat(tmp_path / "v5.mat", {"V": V, "small": np.ones((2, 2, 2)), "label": "scan"})
    with pytest.warns(ReadWarning, match=r"holds 2 arrays; showing the largest, V \(4x5x6\)\. Others: small"):
        volume = vio.read(tmp_path / "v5.mat", isolate=False)
    assert isinstance(volume, RegularVolume) and volume.name == "V" and volume.dimensions == (5, 4, 6)
    np.testing.assert_array_equal(volume.data, AS_SHOWN)
    assert vio.read(tmp_path / "v5.mat", variable="small").dimensions == (2, 2, 2)
    path = _v73(tmp_path / "v73.mat", V=(V, "double"), mask=(V > 0, "logical"))
    volume = vio.read(path, variable="V")
    np.testing.assert_array_equal(volume.data, AS_SHOWN)
    mask = vio.read(path, variable="mask")
    np.testing.assert_array_equal(mask.data, AS_SHOWN > 0)


def test_channels_time_and_images(tmp_path):
    scipy.io.savemat(tmp_path / "c.mat", {"rgb": np.stack([V, 2 * V, 3 * V], axis=-1)})
    volume = vio.read(tmp_path / "c.mat")
    np.testing.assert_array_equal(volume.arrays["rgb"][..., 2], 3 * AS_SHOWN)
    scipy.io.savemat(tmp_path / "t.mat", {"seq": np.stack([V + t for t in range(5)], axis=-1)})
    series = vio.read(tmp_path / "t.mat")
    assert isinstance(series, TimeSeries) and len(series) == 5
    np.testing.assert_array_equal(series.frame(4).data, AS_SHOWN + 4)
    scipy.io.savemat(tmp_path / "i.mat", {"picture": V[..., 0]})
    assert isinstance(vio.read(tmp_path / "i.mat"), Image2D)


def test_files_that_are_no_volumes(tmp_path):
    scipy.io.savemat(tmp_path / "s.mat", {"name": "scan", "info": {"a": 1.0}})
    with pytest.raises(ReadError, match=r"s.mat: holds no numeric 2D to 4D array \(only "):
        vio.read(tmp_path / "s.mat")
    scipy.io.savemat(tmp_path / "z.mat", {"Z": V + 1j * V})
    with pytest.raises(ReadError, match="z.mat: its variable Z holds complex128 values, not real numbers"):
        vio.read(tmp_path / "z.mat")
    scipy.io.savemat(tmp_path / "v5.mat", {"V": V}, do_compression=True)
    data = (tmp_path / "v5.mat").read_bytes()
    (tmp_path / "cut.mat").write_bytes(data[: len(data) // 2])
    with pytest.raises(ReadError, match="cut.mat"):
        vio.read(tmp_path / "cut.mat")
    with pytest.raises(ReadError, match=r"v5.mat: has no numeric 2D to 4D variable 'W'; its arrays are: V \(4x5x6\)"):
        vio.read(tmp_path / "v5.mat", variable="W")
    (tmp_path / "v4.mat").write_bytes(b"\x00" * 200)
    with pytest.raises(ReadError, match="v4.mat"):
        vio.read(tmp_path / "v4.mat")
