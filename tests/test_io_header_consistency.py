"""Headers that are consistent in themselves but contradict the data they describe, found by the fuzz campaign
(``volviz bench robustness``): VTK would read them with made-up values."""
from __future__ import annotations

import shutil

import h5py
import pytest

import volviz.io as vio

from conftest import data_file


def test_vti_whole_extent_larger_than_its_piece_is_refused(tmp_path):
    data = data_file("volumes/hydrogen.vti").read_bytes()
    assert b'WholeExtent="0 63 0 63 0 63"' in data
    bad = tmp_path / "grown.vti"
    bad.write_bytes(data.replace(b'WholeExtent="0 63 0 63 0 63"', b'WholeExtent="-1 63 0 63 0 63"', 1))
    with pytest.raises(vio.ReadError, match=r"grown\.vti: VTK XML pieces \(extents \[\[0, 63, 0, 63, 0, 63\]\]\) do "
                                            r"not fill the WholeExtent \[-1, 63, 0, 63, 0, 63\]"):
        vio.read(bad)
    assert vio.read(data_file("volumes/hydrogen.vti")).dimensions == (64, 64, 64)


def test_vti_piece_without_the_whole_extent_before_it_is_refused(tmp_path):
    """A Piece with no ImageData element (and so no WholeExtent) before it is a ReadError, not a TypeError."""
    data = data_file("volumes/hydrogen.vti").read_bytes()
    bad = tmp_path / "headless.vti"
    bad.write_bytes(data.replace(b"<ImageData WholeExtent=", b"<ImageDatum WholeExtent=", 1))
    with pytest.raises(vio.ReadError, match=r"headless\.vti: VTK XML Piece comes before the ImageData element that "
                                            r"gives its WholeExtent"):
        vio.read(bad)


def test_vtkhdf_step_without_points_but_with_cells_is_refused(tmp_path):
    bad = tmp_path / "steps.vtkhdf"
    shutil.copy(data_file("series/warping_spheres.vtkhdf"), bad)
    with h5py.File(bad, "r+") as f:
        f["VTKHDF/NumberOfPoints"][3] = 0
    with pytest.raises(vio.ReadError, match=r"steps\.vtkhdf: VTKHDF /VTKHDF/NumberOfPoints entry 3 is 0, but that "
                                            r"part's Polygons/cells connect 5040 point ids"):
        vio.read(bad)
