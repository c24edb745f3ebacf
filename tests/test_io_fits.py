"""FITS image cubes through ``volviz.io.read`` (``volviz_astronomy.fits``, astropy): the voxels laid out x, y, z
from FITS's NAXIS order, scaling and BLANK, the HDU chosen, Stokes planes, tile compression, and damaged files;
every file written by astropy."""
from __future__ import annotations

import random
import warnings

import numpy as np
import pytest
from astropy.io import fits
from conftest import read_mutations

import volviz.io as vio
from volviz.bench import robustness as rb
from volviz.io.errors import NonFiniteWarning, ReadError, ReadWarning
from volviz.model import Image2D, RegularVolume

CUBE = np.random.default_rng(0).normal(size=(6, 5, 4)).astype(np.float32)      # (NAXIS3, NAXIS2, NAXIS1)


def test_a_cube_is_laid_out_x_y_z_with_the_sky_pixels_aspect(tmp_path):
    hdu = fits.PrimaryHDU(CUBE)
    hdu.header["CDELT1"], hdu.header["CDELT2"], hdu.header["BUNIT"] = -0.001, 0.002, "Jy/beam"
    hdu.writeto(tmp_path / "cube.fits")
    volume = vio.read(tmp_path / "cube.fits")
    assert isinstance(volume, RegularVolume) and volume.dimensions == (4, 5, 6) and volume.name == "Jy/beam"
    np.testing.assert_array_equal(volume.data, np.transpose(CUBE, (2, 1, 0)))
    assert volume.data[3, 1, 2] == CUBE[2, 1, 3]                      # NAXIS1 is x
    assert volume.spacing == (1.0, 2.0, 1.0)


def test_scaling_blank_extensions_stokes_and_compression(tmp_path):
    raw = np.arange(60, dtype=np.int16).reshape(3, 4, 5)
    raw[0, 0, 0] = -32768
    ext = fits.ImageHDU(raw, name="FLUX")
    ext.header["BSCALE"], ext.header["BZERO"], ext.header["BLANK"] = 0.5, 10.0, -32768
    fits.HDUList([fits.PrimaryHDU(), ext, fits.ImageHDU(CUBE, name="OTHER")]).writeto(tmp_path / "ext.fits")
    with pytest.warns(NonFiniteWarning):
        scaled = vio.read(tmp_path / "ext.fits")                      # the first cube: the FLUX extension
    assert np.isnan(scaled.data[0, 0, 0])
    np.testing.assert_array_equal(scaled.data[1:, 0, 0], raw[0, 0, 1:] * 0.5 + 10.0)
    np.testing.assert_array_equal(vio.read(tmp_path / "ext.fits", hdu="OTHER").data, np.transpose(CUBE, (2, 1, 0)))
    with pytest.raises(ReadError, match="ext.fits: has no HDU 'SPECTRUM'; its HDUs are 0 \\(PRIMARY\\), 1 \\(FLUX\\)"):
        vio.read(tmp_path / "ext.fits", hdu="SPECTRUM")
    fits.PrimaryHDU(CUBE[None]).writeto(tmp_path / "stokes1.fits")    # (Stokes 1, freq, dec, ra)
    np.testing.assert_array_equal(vio.read(tmp_path / "stokes1.fits").data, np.transpose(CUBE, (2, 1, 0)))
    fits.PrimaryHDU(np.stack([CUBE, -CUBE])).writeto(tmp_path / "stokes2.fits")
    with pytest.warns(ReadWarning, match="2 planes along its fourth axis"):
        np.testing.assert_array_equal(vio.read(tmp_path / "stokes2.fits").data, np.transpose(CUBE, (2, 1, 0)))
    fits.HDUList([fits.PrimaryHDU(), fits.CompImageHDU(CUBE)]).writeto(tmp_path / "tiles.fits.fz")
    np.testing.assert_array_equal(vio.read(tmp_path / "tiles.fits.fz").data, np.transpose(CUBE, (2, 1, 0)))
    fits.PrimaryHDU(CUBE[0]).writeto(tmp_path / "image.fits")
    image = vio.read(tmp_path / "image.fits")
    assert isinstance(image, Image2D) and image.data.shape == (5, 4)
    np.testing.assert_array_equal(image.data, CUBE[0][::-1])            # FITS row 1 is the bottom


def test_damaged_fits_files_are_refused_or_read_whole(tmp_path):
    path = tmp_path / "cube.fits"
    fits.PrimaryHDU(CUBE).writeto(path)
    data = path.read_bytes()
    path.write_bytes(data[:3000])                                      # the data ends at byte 3360
    with pytest.raises(ReadError, match="cube.fits: its data unit .* runs past the end of the file: it is truncated"):
        vio.read(path)
    path.write_bytes(data)
    rng = random.Random("fits")
    mutations = [rb.flip_bits(data, rng, 2880) for _ in range(20)]
    mutations += [rb.truncate(data, at) for at in sorted(rng.sample(range(1, len(data)), 12))]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert read_mutations(path, mutations, truncated_reads_same=True) >= 8     # cut in the padding: whole


def test_a_header_astropy_cannot_parse_leaves_no_file_open(tmp_path):
    """NAXIS1 given as a string: astropy's parse fails inside ``fits.open``, which then left the file it had opened
    open ("unclosed file" ResourceWarnings landing in whichever test collected it); the reader now hands astropy a
    handle of its own and closes it."""
    import gc

    fits.PrimaryHDU(CUBE).writeto(tmp_path / "cube.fits")
    raw = bytearray((tmp_path / "cube.fits").read_bytes())
    at = raw.find(b"NAXIS1")
    raw[at + 10:at + 30] = b"   'four'           "
    (tmp_path / "bad.fits").write_bytes(bytes(raw))
    gc.collect()
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        with pytest.raises(ReadError, match="bad.fits: astropy cannot read it as FITS"):
            vio.read(tmp_path / "bad.fits", isolate=False)
        gc.collect()
    assert not [str(w.message) for w in seen if issubclass(w.category, ResourceWarning)]
