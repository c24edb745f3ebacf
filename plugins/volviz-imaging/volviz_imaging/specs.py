"""The reader specs this plugin registers (entry point ``volviz.readers``), with their content sniffers.

Importing this module imports neither nibabel, pynrrd nor pydicom: volviz reads it to know the formats.
"""
from __future__ import annotations

import struct
import zlib
from typing import Any

from volviz.io.registry import ReaderSpec

_NIFTI1_MAGIC = (b"n+1\x00", b"ni1\x00")
_NIFTI2_MAGIC = (b"n+2\x00\r\n\x1a\n", b"ni2\x00\r\n\x1a\n")


def inflated_head(head: bytes, limit: int = 4096) -> bytes:
    """The first bytes of a gzip stream's content (``head`` itself when it is not gzip; ``b""`` when its start
    does not inflate)."""
    if head[:2] != b"\x1f\x8b":
        return head
    try:
        return zlib.decompressobj(31).decompress(head, limit)
    except zlib.error:
        return b""


def is_nifti_or_analyze(head: bytes) -> bool:
    """A NIfTI-1 / NIfTI-2 header (magic at byte 344 / 4) or an Analyze 7.5 one (``sizeof_hdr`` 348 either endian),
    gzip-compressed or not."""
    h = inflated_head(head)
    if len(h) < 348:
        return False
    if h[344:348] in _NIFTI1_MAGIC or h[4:12] in _NIFTI2_MAGIC:
        return True
    return 348 in (struct.unpack("<i", h[:4])[0], struct.unpack(">i", h[:4])[0])


def is_mgh(head: bytes) -> bool:
    """FreeSurfer MGH: version 1 (big-endian int32), then width, height, depth, frames and a known data type."""
    h = inflated_head(head)
    if len(h) < 284:
        return False
    version, *dims, dtype = struct.unpack(">5ii", h[:24])
    return version == 1 and all(d > 0 for d in dims) and dtype in (0, 1, 3, 4)


def is_mrc(head: bytes) -> bool:
    """An MRC2014 / CCP4 map: ``MAP `` at byte 208 (gzip-compressed or not)."""
    return inflated_head(head)[208:212] == b"MAP "


def is_minc(head: bytes) -> bool:
    """MINC 1 is a netCDF classic file (``CDF\x01`` / ``CDF\x02``) holding ``image`` variables; MINC 2 an HDF5 file
    with the ``minc-2.0`` group (its name lies in the first kilobytes of the superblock's heap)."""
    if head[:4] in (b"CDF\x01", b"CDF\x02"):
        return b"image" in head and b"space" in head
    return head.startswith(b"\x89HDF\r\n\x1a\n") and b"minc-2.0" in head


def is_nrrd(head: bytes) -> bool:
    return head.startswith(b"NRRD000")


def is_dicom(head: bytes) -> bool:
    """A DICOM Part 10 file: 128 bytes of preamble, then ``DICM``."""
    return head[128:132] == b"DICM"


_P = "volviz_imaging."


def _spec(name: str, description: str, patterns: tuple[str, ...], loader: str, **kwargs: Any) -> ReaderSpec:
    """Run isolated: a compressed file may claim any size (the child's memory limit holds), and pydicom decodes
    compressed pixel data with native codecs."""
    return ReaderSpec(name, description, patterns, _P + loader, isolated=True, **kwargs)


SPECS: list[ReaderSpec] = [
    _spec("nifti", "NIfTI / Analyze", ("*.nii", "*.nii.gz", "*.hdr"), "nifti:read_nifti",
          sniff=is_nifti_or_analyze, claims_name=False,
          arrays="the voxel values through scl_slope / scl_inter; 4D files as a time series",
          options=("time_index", "allow_nonfinite")),
    # the data file of a .hdr / .img pair (no header of its own: known by name only), read with its .hdr
    _spec("nifti-pair-data", "NIfTI / Analyze image data", ("*.img",), "nifti:read_nifti", listed=False,
          options=("time_index", "allow_nonfinite")),
    _spec("mgh", "FreeSurfer MGH", ("*.mgh", "*.mgz"), "nifti:read_nifti", sniff=is_mgh,
          arrays="the voxel values; several frames as a time series", options=("time_index", "allow_nonfinite")),
    _spec("minc", "MINC", ("*.mnc",), "minc:read_minc", sniff=is_minc,
          arrays="the voxel values through the file's scaling; a time dimension as a time series",
          options=("time_index", "allow_nonfinite")),
    _spec("nrrd", "NRRD", ("*.nrrd", "*.nhdr"), "nrrd_files:read_nrrd", sniff=is_nrrd,
          arrays="the voxel values; a vector / color axis as components, a time axis as a time series",
          options=("allow_nonfinite",)),
    _spec("mrc", "MRC / CCP4 map", ("*.mrc", "*.mrcs", "*.map", "*.ccp4", "*.rec", "*.mrc.gz", "*.map.gz"),
          "mrc:read_mrc", sniff=is_mrc, arrays="the density, in the map's axis order laid out x, y, z (Angstrom)",
          options=("allow_nonfinite",)),
    _spec("cube", "Gaussian cube", ("*.cube", "*.cub"), "cube:read_cube",
          arrays="the density, orbital or potential on the grid (Angstrom); orbital= picks an orbital",
          options=("orbital", "allow_nonfinite")),
    _spec("zarr", "OME-Zarr / Zarr", ("*.zarr",), "omezarr:read_zarr",
          folder_markers=(".zattrs", "zarr.json", ".zarray", ".zgroup"),
          arrays="an OME-Zarr image's level of at most 256 M voxels (level= picks one), channels, time; a Zarr array "
                 "read (z, y, x)", options=("level", "allow_nonfinite")),
    _spec("dicom", "DICOM series", ("*.dcm", "*.dicom", "*.ima"), "dicom:read_dicom", sniff=is_dicom,
          folder_markers=("DICOMDIR", "*.dcm", "*.DCM"), sniffs_folders=True,
          reads_siblings=True,
          arrays="the series' slices stacked in patient space, through the modality LUT (e.g. Hounsfield units)",
          options=("series", "allow_nonfinite")),
]
