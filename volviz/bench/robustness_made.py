"""Files of the formats the shared data folder lacks, written for ``volviz bench robustness`` (issue #32).

The campaign mutates real files; for the built-in and plugin formats with no file in ``../shared/data`` (MATLAB v5
plain and compressed, TIFF stacks, NRRD raw and gzip, NIfTI, DICOM, Gaussian cube, FITS, MRC, NumPy ``.npy``, LAS,
SEG-Y) it writes one small, valid file each with the format's own library, so that every reader meets damaged
files. Each comes with its VTK reader where VTK has one (NIfTI, TIFF, DICOM, MRC, NRRD).
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import Callable

import numpy as np

#: a small volume with distinct values, x fastest (z, y, x) = (6, 5, 4)
_VALUES = (np.arange(6 * 5 * 4, dtype=np.int64) * 37 % 251).reshape(6, 5, 4)


def _mat(path: Path, compress: bool) -> None:
    # heavy: SciPy, only for this case
    import scipy.io

    scipy.io.savemat(path, {"V": _VALUES.astype(np.float64), "label": "scan", "M": np.eye(3)},
                     do_compression=compress)


def _tiff(path: Path) -> None:
    # tifffile: only the robustness seeds in its format need it (imported where they are written)
    import tifffile

    tifffile.imwrite(path, _VALUES.astype(np.uint16), photometric="minisblack")


def _nrrd(path: Path, encoding: str) -> None:
    # optional: nrrd (a reader plugin's dependency), only to write the files it reads
    import nrrd

    nrrd.write(str(path), _VALUES.astype(np.int16), {"encoding": encoding, "space": "left-posterior-superior",
                                                     "space directions": np.eye(3) * 0.5,
                                                     "space origin": np.array([1.0, 2.0, 3.0])}, index_order="C")


def _nifti(path: Path) -> None:
    # optional: nibabel (a reader plugin's dependency), only to write the files it reads
    import nibabel as nib

    nib.save(nib.Nifti1Image(_VALUES.T.astype(np.int16), np.diag([0.5, 0.5, 2.0, 1.0])), str(path))


def _dicom(path: Path) -> None:
    # optional: pydicom (a reader plugin's dependency), only to write the files it reads
    import pydicom
    from pydicom.dataset import FileMetaDataset
    from pydicom.uid import UID, ExplicitVRLittleEndian, generate_uid

    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = UID("1.2.840.10008.5.1.4.1.1.2")
    meta.MediaStorageSOPInstanceUID = generate_uid(entropy_srcs=["volviz-robustness"])
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = pydicom.Dataset()
    ds.file_meta = meta
    ds.SOPClassUID, ds.SOPInstanceUID = meta.MediaStorageSOPClassUID, meta.MediaStorageSOPInstanceUID
    ds.SeriesInstanceUID = generate_uid(entropy_srcs=["volviz-robustness-series"])
    ds.Modality, ds.SeriesDescription, ds.InstanceNumber = "CT", "robustness", 1
    ds.ImageOrientationPatient, ds.ImagePositionPatient = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0]
    ds.PixelSpacing, ds.RescaleSlope, ds.RescaleIntercept = [0.5, 0.5], 1.0, -1024.0
    ds.Rows, ds.Columns = _VALUES.shape[1:]
    ds.SamplesPerPixel, ds.PhotometricInterpretation = 1, "MONOCHROME2"
    ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 1
    ds.PixelData = _VALUES[0].astype("<i2").tobytes()
    ds.save_as(path, enforce_file_format=True)


def _cube(path: Path) -> None:
    lines = ["cube file written by volviz bench robustness", "total density",
             "    2     0.000000     0.000000     0.000000"]
    lines += [f"{n:5d} " + " ".join(f"{0.4 if a == b else 0.0:12.6f}" for b in range(3))
              for a, n in enumerate(_VALUES.shape)]
    lines += ["    8     8.000000     0.000000     0.000000     0.000000",
              "    1     1.000000     1.400000     0.000000     1.100000"]
    for row in (_VALUES / 251.0).reshape(-1, _VALUES.shape[2]):
        lines.append(" ".join(f"{v:13.5E}" for v in row))
    path.write_text("\n".join(lines) + "\n")


def _fits(path: Path) -> None:
    # optional: astropy (a reader plugin's dependency), only to write the files it reads
    from astropy.io import fits

    fits.PrimaryHDU(_VALUES.astype(np.float32)).writeto(path)


def _mrc(path: Path) -> None:
    # optional: mrcfile (a reader plugin's dependency), only to write the files it reads
    import mrcfile

    with mrcfile.new(str(path)) as mrc:
        mrc.set_data(_VALUES.astype(np.float32))
        mrc.voxel_size = 1.5


def _npy(path: Path) -> None:
    np.save(path, _VALUES.astype(np.float32))


def _las(path: Path) -> None:
    import laspy  # type: ignore[import-untyped]   # laspy ships no type information

    header = laspy.LasHeader(point_format=3, version="1.2")
    header.scales, header.offsets = np.array([0.01, 0.01, 0.01]), np.array([500000.0, 5400000.0, 0.0])
    las = laspy.LasData(header)
    n = 120
    las.x = 500000.0 + np.arange(n) * 0.37
    las.y = 5400000.0 + (np.arange(n) * 7 % 40) * 0.5
    las.z = 100.0 + np.arange(n) % 17
    las.intensity = (np.arange(n) * 97 % 65535).astype(np.uint16)
    las.write(str(path))


def _segy(path: Path) -> None:
    # optional: segyio (a reader plugin's dependency), only to write the files it reads
    import segyio

    spec = segyio.spec()
    spec.format, spec.samples = 5, list(range(0, 24, 4))
    spec.ilines, spec.xlines = [1, 2, 3, 4], [10, 11, 12, 13, 14]
    with segyio.create(str(path), spec) as f:
        for i, (il, xl) in enumerate((il, xl) for il in spec.ilines for xl in spec.xlines):
            f.header[i] = {segyio.su.iline: il, segyio.su.xline: xl, segyio.su.cdpx: il * 100, segyio.su.cdpy: xl * 100}
            f.trace[i] = (np.arange(6, dtype=np.float32) + i) / 7.0
        f.bin.update(tsort=segyio.TraceSortingFormat.INLINE_SORTING)


#: format label -> (file name, writer, header layout, binary byte order, VTK recipe or None)
MADE: dict[str, tuple[str, Callable[[Path], None], str, str, str | None]] = {
    "matlab": ("v.mat", lambda p: _mat(p, False), "binary", "<", None),
    "matlab-z": ("z.mat", lambda p: _mat(p, True), "binary", "<", None),
    "tiff": ("stack.tif", _tiff, "binary", "<", "tiff"),
    "nrrd": ("v.nrrd", lambda p: _nrrd(p, "raw"), "text", ">", "nrrd"),
    "nrrd-gzip": ("g.nrrd", lambda p: _nrrd(p, "gzip"), "text", ">", "nrrd"),
    "nifti": ("v.nii", _nifti, "binary", "<", "nifti"),
    "dicom": ("one.dcm", _dicom, "binary", "<", "dicom"),
    "cube": ("density.cube", _cube, "text", ">", None),
    "fits": ("cube.fits", _fits, "text", ">", None),
    "mrc": ("map.mrc", _mrc, "binary", "<", "mrc"),
    "npy": ("v.npy", _npy, "text", ">", None),
    "las": ("points.las", _las, "binary", "<", None),
    "segy": ("cube.sgy", _segy, "binary", ">", None),
}


#: the writing time some libraries put in a header (SciPy's MATLAB header, pynrrd's comment, mrcfile's label)
_STAMPS = ((re.compile(rb"\d{4}-\d\d-\d\d \d\d:\d\d:\d\d"), b"2026-01-01 00:00:00"),
           (re.compile(rb"[A-Z][a-z]{2} [A-Z][a-z]{2} [ \d]\d \d\d:\d\d:\d\d \d{4}"), b"Thu Jan  1 00:00:00 2026"))


def _pinned(data: bytes) -> bytes:
    """The file with its writing time set to a fixed one (same length), so that a run's files are the same
    whenever they are written and a recorded case can be rebuilt byte for byte (``robustness_replay``)."""
    for pattern, fixed in _STAMPS:
        data = pattern.sub(fixed, data, count=1)
    return data


def write_made(folder: Path, formats: list[str] | None = None) -> dict[str, Path]:
    """Write one file of each made format (those named, else all whose library imports) into ``folder``; a format
    whose library is not installed is left out."""
    folder.mkdir(parents=True, exist_ok=True)
    written: dict[str, Path] = {}
    for fmt, (name, write, *_rest) in MADE.items():
        if formats and fmt not in formats:
            continue
        path = folder / fmt / name
        path.parent.mkdir(exist_ok=True)
        try:
            write(path)
        except ImportError:
            continue
        path.write_bytes(_pinned(path.read_bytes()))
        written[fmt] = path
    return written
