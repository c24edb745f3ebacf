"""Headers that claim less data than the file holds (issue #32): a NIfTI dim, a .npy shape or a FITS NAXISn made
smaller is refused with one line naming the file, the header's fields and both sizes; a few extra bytes (less than
a slice) are read past with a ReadWarning, never silently."""
from __future__ import annotations

import struct
import warnings
from pathlib import Path

import nibabel as nib
import numpy as np
import pytest
from astropy.io import fits

import volviz.io as vio
from volviz.io.errors import ReadError, ReadWarning

CUBE = (np.arange(16 * 14 * 12) % 300).astype(np.int16).reshape(16, 14, 12)


def _read_clean(path: Path):
    with warnings.catch_warnings():
        warnings.simplefilter("error", ReadWarning)
        return vio.read(path)


def _refused(path: Path, message: str) -> None:
    with pytest.raises(ReadError) as caught:
        vio.read(path)
    assert str(caught.value) == f"{path}: {message}"


def _nifti(tmp_path: Path, dim1: int | None = None, extra: bytes = b"") -> Path:
    good = tmp_path / "a.nii"
    nib.save(nib.Nifti1Image(CUBE, np.eye(4)), good)
    raw = bytearray(good.read_bytes())
    if dim1 is not None:
        raw[42:44] = struct.pack("<h", dim1)  # dim[1]
    path = tmp_path / "crafted.nii"
    path.write_bytes(bytes(raw) + extra)
    return path


def test_nifti_dim_smaller_than_the_data_is_refused(tmp_path):
    assert np.array_equal(_read_clean(_nifti(tmp_path)).data, CUBE)
    _refused(_nifti(tmp_path, 7), "its header gives dim[1] 7, dim[2] 14, dim[3] 12 of int16: 2352 bytes of data, but "
                                  "the file holds 3024 bytes more (5376 in all; one slice is 196 bytes): the header "
                                  "claims less data than the file holds")


def test_nifti_trailing_bytes_are_a_warning(tmp_path):
    path = _nifti(tmp_path, extra=b"\0" * 10)
    with pytest.warns(ReadWarning, match=r"crafted\.nii: 10 bytes follow the 5376 bytes of data that its header "
                                         r"gives \(dim\[1\] 16, dim\[2\] 14, dim\[3\] 12 of int16\); they are ignored"):
        vol = vio.read(path)
    assert np.array_equal(vol.data, CUBE)


def test_npy_shape_smaller_than_the_data_is_refused(tmp_path):
    good = tmp_path / "a.npy"
    np.save(good, CUBE.astype(np.float32))
    assert _read_clean(good).data.shape == (12, 14, 16)
    path = tmp_path / "crafted.npy"
    path.write_bytes(good.read_bytes().replace(b"(16, 14, 12)", b"(15, 14, 12)"))
    _refused(path, "its header gives shape (15, 14, 12) of float32: 10080 bytes of data, but the file holds 672 "
                   "bytes more (10752 in all; one slice is 672 bytes): the header claims less data than the file holds")
    path.write_bytes(good.read_bytes() + b"\0" * 8)
    with pytest.warns(ReadWarning, match=r"8 bytes follow the 10752 bytes of data that its header gives \(shape "
                                         r"\(16, 14, 12\) of float32\); they are ignored"):
        assert np.array_equal(vio.read(path).data, np.transpose(CUBE, (2, 1, 0)).astype(np.float32))
    fortran = tmp_path / "f.npy"
    np.save(fortran, np.asfortranarray(CUBE))
    assert np.array_equal(_read_clean(fortran).data, np.transpose(CUBE, (2, 1, 0)))


def _fits(tmp_path: Path, cube: np.ndarray, naxis3: int | None = None, extra: bytes = b"") -> Path:
    good = tmp_path / "a.fits"
    fits.PrimaryHDU(cube).writeto(good, overwrite=True)
    raw = good.read_bytes()
    if naxis3 is not None:
        i = raw.index(b"NAXIS3  =")
        raw = raw[:i] + f"NAXIS3  = {naxis3:>20}".encode() + raw[i + 30:]
    path = tmp_path / "crafted.fits"
    path.write_bytes(raw + extra)
    return path


def test_fits_naxis3_smaller_than_the_data_is_refused(tmp_path):
    cube = CUBE.transpose(2, 1, 0).astype(np.float32)  # FITS lists NAXIS1 (x) first: numpy shape (12, 14, 16)
    assert _read_clean(_fits(tmp_path, cube)).data.shape == (16, 14, 12)
    # the rest of the data fills more than the padding: what follows is no extension header
    _refused(_fits(tmp_path, cube, 8), "its header gives NAXIS1 16, NAXIS2 14, NAXIS3 8 of BITPIX -32: 7168 bytes of "
                                       "data, but 4352 bytes follow them that are no FITS extension (no XTENSION "
                                       "header): the header claims less data than the file holds")
    # the rest of the data hides in the 2880-byte padding: the padding is not zeros
    small = np.ones((12, 14, 16), np.int8)
    _refused(_fits(tmp_path, small, 11), "its header gives NAXIS1 16, NAXIS2 14, NAXIS3 11 of BITPIX 8: 2464 bytes "
                                         "of data, but the file holds 224 bytes more (2688 in all; one slice is 224 "
                                         "bytes): the header claims less data than the file holds")


def test_fits_bytes_after_the_last_block_are_a_warning(tmp_path):
    cube = CUBE.transpose(2, 1, 0).astype(np.float32)
    path = _fits(tmp_path, cube, extra=b"\0" * 100)
    with pytest.warns(ReadWarning, match=r"868 bytes follow the 10752 bytes of data that its header gives \(NAXIS1 "
                                         r"16, NAXIS2 14, NAXIS3 12 of BITPIX -32\); they are ignored"):
        vol = vio.read(path)
    assert np.array_equal(vol.data, CUBE.astype(np.float32))
