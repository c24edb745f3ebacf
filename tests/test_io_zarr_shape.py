"""An OME-Zarr / Zarr array's shape held against its chunk shape, the chunks it stores and the multiscale's other
levels (``volviz_imaging.omezarr.check_stored_chunks`` / ``check_levels``, issue #32). The campaign's case of seed 33
set a ``.zarray``'s ``shape[0]`` from 6 to 1 and the image read as one slice of six, the second chunk ignored; now
such a file is refused in one line naming the metadata file, the field and both values, and the valid file still
reads the same voxels."""
from __future__ import annotations

import json

import numpy as np
import pytest

import volviz.io as vio
from volviz.io.errors import ReadError

pytest.importorskip("volviz_imaging")
zarr = pytest.importorskip("zarr")

AXES = [{"name": n, "type": "space", "unit": "micrometer"} for n in "zyx"]
VALUES = (np.arange(6 * 5 * 4, dtype=np.uint16) * 7 % 1000).reshape(6, 5, 4)      # (z, y, x)


def _image(path, levels=((VALUES, [2.0, 0.5, 0.5]),), chunks=(3, 5, 4), zarr_format=2, separator=None):
    """An OME-Zarr image (zarr-python, zlib chunks as the bench's ``ome-zarr-zlib`` seed): one array per level."""
    import numcodecs

    root = zarr.open_group(str(path), mode="w", zarr_format=zarr_format)
    datasets = []
    for i, (data, scale) in enumerate(levels):
        extra = {"chunk_key_encoding": {"name": "v2", "separator": separator}} if separator else {}
        codec = {"compressors": numcodecs.Zlib(level=1)} if zarr_format == 2 else {}
        array = root.create_array(str(i), shape=data.shape, dtype=data.dtype,
                                  chunks=tuple(min(c, n) for c, n in zip(chunks, data.shape)), **codec, **extra)
        array[:] = data
        datasets.append({"path": str(i), "coordinateTransformations": [{"type": "scale", "scale": scale}]})
    multiscales = [{"version": "0.4", "axes": AXES, "datasets": datasets}]
    if zarr_format == 2:
        root.attrs["multiscales"] = multiscales
    else:
        root.attrs["ome"] = {"version": "0.5", "multiscales": multiscales}
    return path


def _edit(meta, key, index, value):
    found = json.loads(meta.read_text())
    if index is None:
        found[key] = value
    else:
        found[key][index] = value
    meta.write_text(json.dumps(found, indent=4))


@pytest.mark.parametrize("zarr_format", [2, 3])
def test_the_valid_image_reads_its_voxels(tmp_path, zarr_format):
    volume = vio.read(_image(tmp_path / "image.zarr", zarr_format=zarr_format))
    assert volume.dimensions == (4, 5, 6) and volume.spacing == (0.5, 0.5, 2.0)
    np.testing.assert_array_equal(volume.data, np.transpose(VALUES, (2, 1, 0)))


def test_the_campaigns_shape_set_to_one_is_refused(tmp_path):
    path = _image(tmp_path / "image.zarr")
    meta = path / "0" / ".zarray"
    _edit(meta, "shape", 0, 1)
    with pytest.raises(ReadError) as caught:
        vio.read(path)
    assert str(caught.value) == (f"{meta}: its shape [1, 5, 4] (chunks [3, 5, 4]: a grid of 1 x 1 x 1 chunks) "
                                 "disagrees with its stored chunk 1.0.0, which lies outside it: the shape or the "
                                 "chunk shape is damaged")


@pytest.mark.parametrize("zarr_format, separator, stored", [(3, None, "c/0/1/0"), (2, "/", "0/1/0")])
def test_a_shrunk_shape_is_refused_with_nested_chunk_keys(tmp_path, zarr_format, separator, stored):
    path = _image(tmp_path / "image.zarr", chunks=(6, 3, 4), zarr_format=zarr_format, separator=separator)
    meta = path / "0" / (".zarray" if zarr_format == 2 else "zarr.json")
    _edit(meta, "shape", 1, 2)
    with pytest.raises(ReadError, match=f"^{meta}: its shape \\[6, 2, 4\\] \\(chunks \\[6, 3, 4\\]: a grid of "
                                        f"1 x 1 x 1 chunks\\) disagrees with its stored chunk {stored}, "):
        vio.read(path)


@pytest.mark.parametrize("chunks, problem", [
    ([3, 0, 4], r"its chunk shape \[3, 0, 4\] is not 3 sizes >= 1 \(one per axis of the shape \[6, 5, 4\]\)$"),
    ([3, 5], r"its chunk shape \[3, 5\] is not 3 sizes >= 1"),
])
def test_a_chunk_shape_that_is_no_sizes_is_refused_naming_it(tmp_path, chunks, problem):
    path = _image(tmp_path / "image.zarr")
    meta = path / "0" / ".zarray"
    _edit(meta, "chunks", None, chunks)
    with pytest.raises(ReadError, match=f"^{meta}: {problem}"):
        vio.read(path)


def test_a_level_whose_shape_disagrees_with_its_scale_is_refused(tmp_path):
    coarse = VALUES[::2, ::2, ::2]                                      # (3, 3, 2) at twice the voxel size
    levels = ((VALUES, [2.0, 0.5, 0.5]), (coarse, [4.0, 1.0, 1.0]))
    valid = vio.read(_image(tmp_path / "valid.zarr", levels), level=1)
    np.testing.assert_array_equal(valid.data, np.transpose(coarse, (2, 1, 0)))
    path = _image(tmp_path / "image.zarr", levels)
    _edit(path / "1" / ".zarray", "shape", 0, 6)              # six slices at 4.0: twice the image's depth
    with pytest.raises(ReadError) as caught:
        vio.read(path)
    assert str(caught.value) == (f"{path / '1'}: its shape [6, 3, 2] disagrees with level 0's [6, 5, 4] at the "
                                 "scales [4.0, 1.0, 1.0] and [2.0, 0.5, 0.5] (expected about [3.0, 2.5, 2.0]): a "
                                 "shape or a scale is damaged")
