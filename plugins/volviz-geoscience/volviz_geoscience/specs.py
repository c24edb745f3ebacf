"""The reader specs this plugin registers (entry point ``volviz.readers``), with their content sniffers.

Importing this module imports neither segyio nor laspy: volviz reads it to know the formats.
"""
from __future__ import annotations

import struct

from volviz.io.registry import ReaderSpec

#: SEG-Y data sample formats (binary header bytes 3225-3226): IBM and IEEE floats, 1/2/4/8-byte integers
SAMPLE_FORMATS = (1, 2, 3, 5, 6, 8, 9, 10, 11, 12, 15, 16)
TEXT_HEADER_BYTES = 3200
BINARY_HEADER_BYTES = 400


def is_segy(head: bytes) -> bool:
    """A SEG-Y file: a 3200-byte textual header starting with ``C`` (EBCDIC or ASCII), then a binary header with a
    known sample format and a positive sample count (either byte order)."""
    if len(head) < TEXT_HEADER_BYTES + 28 or head[:1] not in (b"\xc3", b"C"):
        return False
    for order in (">", "<"):
        samples, = struct.unpack(order + "H", head[TEXT_HEADER_BYTES + 20:TEXT_HEADER_BYTES + 22])
        code, = struct.unpack(order + "H", head[TEXT_HEADER_BYTES + 24:TEXT_HEADER_BYTES + 26])
        if code in SAMPLE_FORMATS and samples > 0:
            return True
    return False


def is_las(head: bytes) -> bool:
    """A LAS or LAZ file: the public header's signature ``LASF`` and a major version 1."""
    return len(head) >= 26 and head[:4] == b"LASF" and head[24] == 1


SPECS: list[ReaderSpec] = [
    ReaderSpec("segy", "SEG-Y seismic", ("*.sgy", "*.segy"), "volviz_geoscience.segy:read_segy", sniff=is_segy,
               arrays="the amplitudes of a post-stack cube (inline, crossline, time) or of a 2D section",
               options=("allow_nonfinite",), isolated=True),
    ReaderSpec("las", "LAS/LAZ lidar points", ("*.las", "*.laz"), "volviz_geoscience.las:read_las", sniff=is_las,
               arrays="points at their scaled, offset coordinates; elevation (shown first), intensity, "
                      "classification, return_number, number_of_returns, gps_time, red/green/blue, extra bytes",
               isolated=True),
]
