"""The reader specs this plugin registers (entry point ``volviz.readers``), with their content sniffers.

Importing this module imports no astropy: volviz reads it to know the formats.
"""
from __future__ import annotations

import zlib

from volviz.io.registry import ReaderSpec


def is_fits(head: bytes) -> bool:
    """A FITS file: its first header card is ``SIMPLE  =`` (gzip-compressed or not)."""
    if head[:2] == b"\x1f\x8b":
        try:
            head = zlib.decompressobj(31).decompress(head, 16)
        except zlib.error:
            return False
    return head.startswith(b"SIMPLE  =")


SPECS: list[ReaderSpec] = [
    ReaderSpec("fits", "FITS image cube", ("*.fits", "*.fit", "*.fts", "*.fits.gz", "*.fits.fz"),
               "volviz_astronomy.fits:read_fits", sniff=is_fits,
               arrays="the first image HDU of three axes (hdu= picks one) through BSCALE / BZERO, BLANK as NaN",
               options=("hdu", "allow_nonfinite"), isolated=True),
]
