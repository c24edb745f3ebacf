"""NumPy ``.npy`` arrays through ``volviz.io.read`` (``volviz.io.npy``): read (z, y, x) like HDF5 arrays and TIFF
stacks (x fastest, VTK's image layout); channels, time series and images; and files that are not arrays of numbers."""
from __future__ import annotations

import numpy as np
import pytest

import volviz.io as vio
from volviz.io.errors import ReadError
from volviz.model import Image2D, RegularVolume, TimeSeries

ARRAY = np.random.default_rng(0).normal(size=(5, 4, 3)).astype(np.float32)     # (z, y, x)
SHOWN = np.transpose(ARRAY, (2, 1, 0))                                           # (x, y, z)


def test_a_3d_array_is_a_volume_read_z_y_x_as_an_hdf5_array_is(tmp_path):
    import h5py

    np.save(tmp_path / "density.npy", ARRAY)
    volume = vio.read(tmp_path / "density.npy")
    assert isinstance(volume, RegularVolume) and volume.name == "density" and volume.dimensions == (3, 4, 5)
    np.testing.assert_array_equal(volume.data, SHOWN)
    assert volume.data[2, 1, 0] == ARRAY[0, 1, 2]          # a[k, j, i] at (i, j, k): x fastest in memory
    with h5py.File(tmp_path / "density.h5", "w") as f:
        f["density"] = ARRAY
    np.testing.assert_array_equal(vio.read(tmp_path / "density.h5").data, volume.data)   # the same volume


def test_channels_time_series_images_and_booleans(tmp_path):
    np.save(tmp_path / "v.npy", np.stack([ARRAY, -ARRAY, 2 * ARRAY], axis=-1))
    vectors = vio.read(tmp_path / "v.npy")
    assert vectors.arrays["v"].shape == (3, 4, 5, 3)
    np.testing.assert_allclose(vectors.data, np.sqrt(6.0) * np.abs(SHOWN), rtol=1e-6)
    deep = np.concatenate([ARRAY, ARRAY], axis=2)               # x 6: a last axis too long for channels
    np.save(tmp_path / "t.npy", np.stack([deep + t for t in range(3)]))
    series = vio.read(tmp_path / "t.npy")
    assert isinstance(series, TimeSeries) and len(series) == 3
    np.testing.assert_array_equal(series.frame(2).data, np.transpose(deep + 2, (2, 1, 0)))
    np.save(tmp_path / "i.npy", ARRAY[..., 0])
    assert isinstance(vio.read(tmp_path / "i.npy"), Image2D)
    np.save(tmp_path / "mask.npy", ARRAY > 0)
    mask = vio.read(tmp_path / "mask.npy")
    assert mask.data.dtype == np.uint8 and mask.data.sum() == (ARRAY > 0).sum()


def test_files_that_are_not_arrays_of_numbers(tmp_path):
    np.save(tmp_path / "a.npy", ARRAY)
    cut = tmp_path / "cut.npy"
    cut.write_bytes((tmp_path / "a.npy").read_bytes()[:200])
    with pytest.raises(ReadError, match="cut.npy: .*shorter than its header says"):
        vio.read(cut)
    np.save(tmp_path / "objects.npy", np.array([{"a": 1}], dtype=object), allow_pickle=True)
    with pytest.raises(ReadError, match="objects.npy"):                 # never unpickled
        vio.read(tmp_path / "objects.npy")
    np.save(tmp_path / "complex.npy", ARRAY.astype(np.complex64))
    with pytest.raises(ReadError, match="complex.npy: holds complex64 values"):
        vio.read(tmp_path / "complex.npy")
    np.save(tmp_path / "5d.npy", np.zeros((2, 2, 2, 2, 2)))
    with pytest.raises(ReadError, match=r"5d.npy: holds an array of shape \(2, 2, 2, 2, 2\)"):
        vio.read(tmp_path / "5d.npy")


def test_order_xyz_reads_an_array_indexed_x_y_z(tmp_path):
    """``order="xyz"``: a[i, j, k] at (i, j, k), as pyvista.wrap takes an array; an unknown order is refused."""
    import pyvista as pv

    np.save(tmp_path / "f.npy", ARRAY)
    volume = vio.read(tmp_path / "f.npy", order="xyz")
    assert volume.dimensions == (5, 4, 3)
    np.testing.assert_array_equal(volume.data, ARRAY)
    grid = pv.wrap(ARRAY)
    assert tuple(grid.dimensions) == volume.dimensions
    np.testing.assert_array_equal(np.asarray(grid.point_data[grid.array_names[0]]), volume.data.ravel(order="F"))
    with pytest.raises(ReadError, match="f.npy: order='yxz' is not one of zyx, xyz"):
        vio.read(tmp_path / "f.npy", order="yxz")
