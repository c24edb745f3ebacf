"""Plain HDF5 files of arrays (``volviz.io.hdf5arrays``) through ``volviz.io.read``: the largest volume or the one
named, the (z, y, x) layout, voxel sizes from attributes, channels, time, images; VTKHDF files still read as VTK data;
and damaged files. Every file is written here by h5py."""
from __future__ import annotations

import random
import shutil
import warnings

import h5py
import numpy as np
import pytest

import volviz.io as vio
from conftest import data_file
from volviz.io.errors import ChoiceWarning, ReadError, ReadWarning
from volviz.model import Image2D, RegularVolume, TimeSeries

STACK = np.random.default_rng(0).normal(size=(4, 5, 6)).astype(np.float32)      # (z, y, x)


def _file(path, **datasets):
    with h5py.File(path, "w") as f:
        for name, (data, attrs, options) in datasets.items():
            ds = f.create_dataset(name.replace("__", "/"), data=data, **options)
            ds.attrs.update(attrs)
    return path


def test_the_largest_volume_laid_out_z_y_x_with_its_voxel_size(tmp_path):
    path = _file(tmp_path / "scan.nxs", entry__data__data=(STACK, {"element_size_um": [3.0, 2.0, 0.5]},
                                                           {"compression": "gzip"}),
                 flat=(STACK[0], {}, {}), small=(np.ones((2, 2, 2)), {}, {}))
    with pytest.warns(ReadWarning, match=r"holds 2 arrays; showing the largest, /entry/data/data \(4x5x6\)\. "
                                         r"Others: /small \(2x2x2\)"):
        volume = vio.read(path, isolate=False)
    assert isinstance(volume, RegularVolume) and volume.name == "data" and volume.dimensions == (6, 5, 4)
    assert volume.spacing == (0.5, 2.0, 3.0)
    np.testing.assert_array_equal(volume.data, np.transpose(STACK, (2, 1, 0)))   # x fastest in the file
    # the choices as data for the app's chooser (also through the isolated reader), again when one was asked for
    for isolate, asked in ((False, None), (True, None), (True, "/small")):
        with pytest.warns(ChoiceWarning) as caught:
            vio.read(path, isolate=isolate, **({"dataset": asked} if asked else {}))
        choice = next(w.message for w in caught if isinstance(w.message, ChoiceWarning))
        assert (choice.option, choice.chosen) == ("dataset", asked or "/entry/data/data")
        assert choice.choices == ["/entry/data/data", "/small"] and choice.path == str(path)
        assert choice.labels == ["/entry/data/data (4x5x6)", "/small (2x2x2)"]
    assert vio.read(path, dataset="small").dimensions == (2, 2, 2)
    assert isinstance(vio.read(path, dataset="/flat"), Image2D)
    with pytest.raises(ReadError, match=r"scan.nxs: has no numeric 2D to 4D dataset '/nope'; its arrays are: "
                                        r"/entry/data/data \(4x5x6\), /flat \(5x6\), /small \(2x2x2\)"):
        vio.read(path, dataset="nope")


def test_channels_time_images_and_attributes_in_other_names(tmp_path):
    rgb = np.stack([STACK, 2 * STACK, 3 * STACK], axis=-1)                        # (z, y, x, c)
    volume = vio.read(_file(tmp_path / "c.h5", rgb=(rgb, {"spacing": [1.0, 1.0, 0.25]}, {})))
    assert volume.arrays["rgb"].shape == (6, 5, 4, 3) and volume.spacing == (0.25, 1.0, 1.0)
    np.testing.assert_array_equal(volume.arrays["rgb"], np.transpose(rgb, (2, 1, 0, 3)))
    steps = np.stack([STACK + t for t in range(5)])                                # (t, z, y, x)
    series = vio.read(_file(tmp_path / "t.h5", steps=(steps, {}, {})))
    assert isinstance(series, TimeSeries) and len(series) == 5
    np.testing.assert_array_equal(series.frame(4).data, np.transpose(STACK + 4, (2, 1, 0)))
    image = vio.read(_file(tmp_path / "i.hdf5", picture=(STACK[0], {}, {})))
    assert isinstance(image, Image2D)
    with pytest.warns(ReadWarning, match="voxel_size attribute of /v .* is not three positive sizes"):
        assert vio.read(_file(tmp_path / "bad.h5", v=(STACK, {"voxel_size": [0.0, 1.0, 1.0]}, {})),
                        isolate=False).spacing == (1.0, 1.0, 1.0)


def test_vtkhdf_files_stay_vtk_data_and_a_plain_hdf_reads_its_arrays(tmp_path):
    series = tmp_path / "spheres.h5"
    shutil.copy(data_file("series/warping_spheres.vtkhdf"), series)
    assert isinstance(vio.read(series), TimeSeries)                   # /VTKHDF: read by vtkHDFReader
    plain = _file(tmp_path / "arrays.hdf", v=(STACK, {}, {}))
    np.testing.assert_array_equal(vio.read(plain).data, np.transpose(STACK, (2, 1, 0)))


def test_damaged_and_empty_files(tmp_path):
    with h5py.File(tmp_path / "none.h5", "w") as f:
        f.create_dataset("text", data=np.array([b"a", b"b"]))
        f.attrs["note"] = "no arrays"
    with pytest.raises(ReadError, match="none.h5: holds no numeric dataset of 2 to 4 dimensions"):
        vio.read(tmp_path / "none.h5")
    path = _file(tmp_path / "v.h5", v=(np.zeros((40, 40, 40), np.float32), {}, {}))
    data = path.read_bytes()
    rng = random.Random(1)
    outcomes = []
    for at in sorted(rng.sample(range(1, len(data)), 12)):          # truncated: refused, never a smaller volume
        (tmp_path / "cut.h5").write_bytes(data[:at])
        with pytest.raises(ReadError, match="cut.h5"):
            vio.read(tmp_path / "cut.h5")
    for _ in range(16):                                             # damaged metadata: a volume of its size or refused
        flipped = bytearray(data)
        for pos in rng.sample(range(0, 2048), 4):
            flipped[pos] ^= 1 << rng.randrange(8)
        (tmp_path / "flip.h5").write_bytes(bytes(flipped))
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                volume = vio.read(tmp_path / "flip.h5")
        except ReadError as exc:
            assert "flip.h5" in str(exc)
            outcomes.append("refused")
            continue
        assert volume.dimensions == (40, 40, 40)
        outcomes.append("read")
    assert "refused" in outcomes


def test_order_xyz_reads_a_fortran_style_dataset_and_its_spacing(tmp_path):
    path = _file(tmp_path / "sim.h5", u=(STACK, {"spacing": [0.5, 1.0, 2.0]}, {}))
    volume = vio.read(path, order="xyz")
    assert volume.dimensions == (4, 5, 6) and volume.spacing == (0.5, 1.0, 2.0)
    np.testing.assert_array_equal(volume.data, STACK)


def test_the_heavy_data_of_an_xdmf_file_points_to_it(tmp_path):
    """An .h5 that an .xdmf beside it names as its heavy data (meshio, dolfinx) is read, with a warning that the
    .xdmf shows its arrays as meant; an .xdmf that names another file, or a dataset asked for by name, says nothing."""
    import warnings

    import h5py

    with h5py.File(tmp_path / "mesh.h5", "w") as f:
        f["data0"] = np.zeros((10, 3))
        f["data1"] = np.zeros((4, 4, 4))
    (tmp_path / "other.xdmf").write_text('<Xdmf><DataItem Format="HDF">results.h5:/data0</DataItem></Xdmf>')
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        vio.read(tmp_path / "mesh.h5", isolate=False)
    assert not [w for w in caught if "heavy data" in str(w.message)]
    (tmp_path / "mesh.xdmf").write_text('<Xdmf Version="3.0"><Domain><Grid><Geometry><DataItem Format="HDF">'
                                        'mesh.h5:/data0</DataItem></Geometry></Grid></Domain></Xdmf>')
    with pytest.warns(ReadWarning, match=r"mesh.h5: is the heavy data of mesh.xdmf beside it, .* open mesh.xdmf"):
        vio.read(tmp_path / "mesh.h5")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        vio.read(tmp_path / "mesh.h5", dataset="/data1", isolate=False)
    assert not [w for w in caught if "heavy data" in str(w.message)]
