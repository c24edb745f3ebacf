"""Netpbm grey and color images: PGM (P2 ASCII, P5 binary) and PPM (P3 ASCII, P6 binary), 8 and 16 bit.

Header: magic, width, height, maxval separated by whitespace, ``#`` comments to the end of a line; for P5/P6
exactly one whitespace byte precedes the raster. ``maxval`` < 256 gives one byte per sample, otherwise two bytes,
most significant first (big-endian). Rows are stored top to bottom; ``Image2D.data[0]`` is the top row.
"""
from __future__ import annotations

import numpy as np

from volviz.io._checks import (
    check_dims, describe_bytes, describe_dims, file_size, read_at, read_bytes, require_bytes,
)
from volviz.io.errors import PathLike, ReadError
from volviz.model import Image2D

_MAGICS = {b"P2": (1, False), b"P3": (3, False), b"P5": (1, True), b"P6": (3, True)}
_WS = b" \t\n\r\v\f"
_HEADER_CHUNK = 4096  # the header is read in growing pieces: comments may be any length
_MAX_FIELD = 32     # bytes of one header field (a decimal number): more is a field run into the raster, refused
                    # at once (issue #32: a 3 MB raster without a whitespace byte was read whole, 1.0-1.3 s)
_FIELDS = ("width", "height", "maxval")


def is_pnm(head: bytes) -> bool:
    return head[:2] in _MAGICS and len(head) > 2 and head[2:3] in (b" ", b"\t", b"\n", b"\r", b"#")


class _HeaderCut(ReadError):
    """The header's fields run to the end of the bytes parsed (more of the file may complete them)."""


def _header_tokens(path: PathLike, buf: bytes, count: int, start: int) -> tuple[list[bytes], int]:
    """``count`` whitespace-separated tokens after ``start`` skipping comments; returns (tokens, end offset)."""
    tokens: list[bytes] = []
    pos, n = start, len(buf)
    while len(tokens) < count:
        while pos < n and (buf[pos] in _WS or buf[pos] == 0x23):
            if buf[pos] == 0x23:  # '#': comment to end of line
                end = buf.find(b"\n", pos)
                pos = n if end < 0 else end + 1
            else:
                pos += 1
        if pos >= n:
            raise _HeaderCut(path, f"PNM header ends after {len(tokens)} of {count} fields (width, height, maxval)")
        begin = pos
        while pos < n and buf[pos] not in _WS and buf[pos] != 0x23:
            pos += 1
            if pos - begin > _MAX_FIELD:
                raise ReadError(path, f"PNM {_FIELDS[len(tokens)]} runs on for more than {_MAX_FIELD} bytes without a "
                                      "whitespace byte: the header is damaged")
        tokens.append(buf[begin:pos])
    return tokens, pos


def _number(path: PathLike, token: bytes, what: str) -> int:
    if not token.isdigit():
        raise ReadError(path, f"PNM {what} is {describe_bytes(token)}, not a non-negative integer")
    return int(token)


def parse_pnm_header(path: PathLike, head: bytes) -> tuple[bytes, int, int, int, int]:
    """Return ``(magic, width, height, maxval, data_offset)`` of a P2/P3/P5/P6 header, else ReadError."""
    magic = head[:2]
    if magic in (b"P1", b"P4"):
        raise ReadError(path, "PBM bitmaps (P1/P4) are not supported; use a PGM (P2/P5) or PPM (P3/P6) image")
    if magic == b"P7":
        raise ReadError(path, "PAM images (P7) are not supported; use a PGM (P2/P5) or PPM (P3/P6) image")
    if magic not in _MAGICS:
        raise ReadError(path, f"not a PGM/PPM file: starts with {describe_bytes(head[:4])}, not P2, P3, P5 or P6")
    tokens, pos = _header_tokens(path, head, 3, 2)
    if pos >= len(head):  # the maxval may be cut short, and P5/P6 need a whitespace byte before the raster
        raise _HeaderCut(path, "PNM header is not followed by a whitespace byte and the raster")
    width = _number(path, tokens[0], "width")
    height = _number(path, tokens[1], "height")
    maxval = _number(path, tokens[2], "maxval")
    check_dims(path, (width, height), "PNM width x height")
    if not 0 < maxval < 65536:
        raise ReadError(path, f"PNM maxval is {maxval}; must be 1..65535")
    return magic, width, height, maxval, pos + 1


def _read_header(path: PathLike, size: int) -> tuple[bytes, int, int, int, int]:
    """Parse the header from as many leading bytes as it takes (the first 4 KB, then twice as many each time its
    fields run past what was read), so long comments are accepted without reading a large file whole."""
    limit = _HEADER_CHUNK
    while True:
        head = read_bytes(path, limit)
        try:
            return parse_pnm_header(path, head)
        except _HeaderCut:
            if len(head) >= size:
                raise
        limit *= 2


def read_pnm(path: PathLike) -> Image2D:
    """Read a PGM/PPM image: data (rows, cols) for grey, (rows, cols, 3) for color; uint8 or native uint16."""
    size = file_size(path)
    magic, width, height, maxval, offset = _read_header(path, size)
    channels, binary = _MAGICS[magic]
    shape = (height, width) if channels == 1 else (height, width, channels)
    n_values = width * height * channels
    dtype = np.uint8 if maxval < 256 else np.uint16
    if binary:
        sample = 1 if maxval < 256 else 2
        what = f"{describe_dims((width, height))} {magic.decode()} raster of {sample}-byte samples"
        require_bytes(path, n_values * sample, size - offset, what)
        if size - offset != n_values * sample:  # trailing bytes: an ASCII raster relabelled P5/P6, or a wrong size
            raise ReadError(path, f"{size - offset - n_values * sample} bytes follow the {what} (needs exactly "
                                  f"{n_values * sample} bytes after the header)")
        raw = read_at(path, offset, n_values * sample)
        values = np.frombuffer(raw, dtype=np.uint8 if sample == 1 else ">u2")
        if sample == 2:
            values = values.astype(np.uint16)
    else:
        # each ASCII sample needs at least one digit and one separator
        require_bytes(path, 2 * n_values - 1, size - offset + 1,
                      f"{describe_dims((width, height))} {magic.decode()} ASCII raster")
        text = read_bytes(path)[offset - 1:]
        if b"#" in text:
            text = b"\n".join(line.split(b"#", 1)[0] for line in text.split(b"\n"))
        tokens = text.split()
        if len(tokens) != n_values:
            raise ReadError(path, f"ASCII raster holds {len(tokens)} samples, the header needs {n_values}")
        try:
            values = np.array(tokens[:n_values], dtype=np.int64)
        except (ValueError, OverflowError):
            raise ReadError(path, "ASCII raster holds a sample that is not an integer") from None
        if values.min() < 0:
            raise ReadError(path, "ASCII raster holds a negative sample")
        values = values.astype(dtype) if values.max() <= maxval else values
    if values.max(initial=0) > maxval:
        raise ReadError(path, f"a sample is {int(values.max())}, above the header's maxval {maxval}")
    return Image2D(values.reshape(shape), maxval=maxval, source=str(path))
