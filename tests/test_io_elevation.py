"""Elevation models as terrain (``volviz.io.elevation``): GeoTIFF DEMs in projected and geographic coordinates, SRTM
tiles, missing samples, and TIFFs of float samples that are not DEMs; every file written by tifffile or NumPy."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import tifffile

import volviz.io as vio
from volviz.io.elevation import METRES_PER_DEGREE_LAT, METRES_PER_DEGREE_LON_AT_EQUATOR
from volviz.io.errors import ReadError, ReadWarning
from volviz.model import Image2D
from volviz.scene.opening import data_session

HEIGHTS = (np.random.default_rng(0).random((50, 60)) * 100 + 200).astype(np.float32)


def _geotiff(path, heights=HEIGHTS, model=1, raster=1, scale=(30.0, 30.0), tie=(500000.0, 5100000.0), nodata=None):
    keys = (1, 1, 0, 2, 1024, 0, 1, model, 1025, 0, 1, raster)
    tags = [(34735, 3, len(keys), keys)]
    if scale is not None:
        tags.append((33550, 12, 3, (*scale, 0.0)))
    if tie is not None:
        tags.append((33922, 12, 6, (0.0, 0.0, 0.0, *tie, 0.0)))
    if nodata is not None:
        tags.append((42113, 2, 0, nodata))
    tifffile.imwrite(path, heights, extratags=tags)
    return path


def test_a_projected_geotiff_is_heights_in_metres_placed_by_its_tiepoint(tmp_path):
    dem = vio.read(_geotiff(tmp_path / "dem.tif"))
    assert isinstance(dem, Image2D)
    np.testing.assert_array_equal(dem.data, HEIGHTS)                   # row 0 is the north edge, as in the file
    assert dem.spacing == (30.0, 30.0)
    assert dem.origin == (500015.0, 5100000.0 - 15.0 - 49 * 30.0)      # pixel is area: the tiepoint is a corner
    point = vio.read(_geotiff(tmp_path / "point.tif", raster=2))
    assert point.origin == (500000.0, 5100000.0 - 49 * 30.0)          # pixel is point: the tiepoint is a sample
    session = data_session(tmp_path / "dem.tif")
    assert [c.type for c in session.components] == ["terrain", "sky"]
    assert "height_scale" not in session.components[0].settings          # true heights


def test_a_geographic_geotiff_is_put_into_metres_and_missing_samples_filled(tmp_path):
    heights = HEIGHTS.copy()
    heights[:2, :3] = -9999.0
    path = _geotiff(tmp_path / "geo.tif", heights, model=2, scale=(1 / 3600, 1 / 3600), tie=(-122.0, 46.5),
                    nodata="-9999")
    with pytest.warns(ReadWarning, match="geo.tif: 6 samples are marked missing"):
        dem = vio.read(path)
    assert dem.data[0, 0] == HEIGHTS.min() and dem.data[2, 0] == HEIGHTS[2, 0]
    north = 46.5 - 0.5 / 3600
    centre = north - 24.5 / 3600
    assert dem.spacing[0] == pytest.approx(METRES_PER_DEGREE_LON_AT_EQUATOR * math.cos(math.radians(centre)) / 3600)
    assert dem.spacing[1] == pytest.approx(METRES_PER_DEGREE_LAT / 3600)


def test_srtm_tiles(tmp_path):
    tile = (np.arange(1201 * 1201) % 700 + 100).astype(">i2").reshape(1201, 1201)
    tile[5, 7] = -32768
    tile.tofile(tmp_path / "S12E034.hgt")
    with pytest.warns(ReadWarning, match="1 samples are marked missing"):
        dem = vio.read(tmp_path / "S12E034.hgt")
    assert dem.data.shape == (1201, 1201) and dem.data[5, 7] == 100 and dem.data[0, 1] == 101
    assert dem.spacing[1] == pytest.approx(METRES_PER_DEGREE_LAT * 3 / 3600)
    assert dem.spacing[0] == pytest.approx(METRES_PER_DEGREE_LON_AT_EQUATOR * math.cos(math.radians(-11.5)) * 3
                                           / 3600)
    with warnings.catch_warnings():
        warnings.simplefilter("error")                       # opened as a terrain without reading it
        assert data_session(tmp_path / "S12E034.hgt").components[0].type == "terrain"
    (tmp_path / "N00E000.hgt").write_bytes(bytes(1000))
    with pytest.raises(ReadError, match="N00E000.hgt: is 1000 bytes; an SRTM tile is 1201 x 1201 or 3601 x 3601"):
        vio.read(tmp_path / "N00E000.hgt")


def test_tiffs_that_are_not_dems(tmp_path):
    tifffile.imwrite(tmp_path / "field.tif", HEIGHTS)                  # float samples, no georeference
    field = vio.read(tmp_path / "field.tif")
    np.testing.assert_array_equal(field.data, HEIGHTS)                 # as stored, not turned into a color image
    assert data_session(tmp_path / "field.tif").components[0].type == "volume"
    with pytest.raises(ReadError, match="rot.tif: is a GeoTIFF without ModelPixelScale and ModelTiepoint"):
        vio.read(_geotiff(tmp_path / "rot.tif", scale=None, tie=None))


def test_mutated_geotiffs_read_consistently_or_raise_read_error(tmp_path):
    import random
    import warnings

    from conftest import read_mutations
    from volviz.bench import robustness as rb

    path = _geotiff(tmp_path / "dem.tif", nodata="-9999")
    data = path.read_bytes()
    rng = random.Random("geotiff")
    mutations = [rb.flip_bits(data, rng, 400) for _ in range(20)]
    mutations += [rb.truncate(data, at) for at in sorted(rng.sample(range(1, len(data)), 12))]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert read_mutations(path, mutations, truncated_reads_same=False) >= 12
