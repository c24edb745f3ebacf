"""Netpbm grey and colour images: PGM (P2 ASCII, P5 binary) and PPM (P3 ASCII, P6 binary), 8 and 16 bit.

Header: magic, width, height, maxval separated by whitespace, ``#`` comments to the end of a line; for P5/P6
exactly one whitespace byte precedes the raster. ``maxval`` < 256 gives one byte per sample, otherwise two bytes,
most significant first (big-endian). Rows are stored top to bottom; ``Image2D.data[0]`` is the top row.
"""
from __future__ import annotations

import numpy as np

from volviz.io._checks import (
    check_dims, describe_dims, file_size, read_at, read_bytes, require_bytes,
)
from volviz.io.errors import PathLike, ReadError
from volviz.model import Image2D

_MAGICS = {b"P2": (1, False), b"P3": (3, False), b"P5": (1, True), b"P6": (3, True)}
_WS = b" \t\n\r\v\f"
_HEADER_LIMIT = 4096


def is_pnm(head: bytes) -> bool:
    return head[:2] in _MAGICS and len(head) > 2 and head[2:3] in (b" ", b"\t", b"\n", b"\r", b"#")


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
            raise ReadError(path, f"PNM header ends after {len(tokens)} of {count} fields (width, height, maxval)")
        begin = pos
        while pos < n and buf[pos] not in _WS and buf[pos] != 0x23:
            pos += 1
        tokens.append(buf[begin:pos])
    return tokens, pos


def _number(path: PathLike, token: bytes, what: str) -> int:
    if not token.isdigit():
        raise ReadError(path, f"PNM {what} {token[:20]!r} is not a non-negative integer")
    return int(token)


def parse_pnm_header(path: PathLike, head: bytes) -> tuple[bytes, int, int, int, int]:
    """Return ``(magic, width, height, maxval, data_offset)`` of a P2/P3/P5/P6 header, else ReadError."""
    magic = head[:2]
    if magic in (b"P1", b"P4"):
        raise ReadError(path, "PBM bitmaps (P1/P4) are not supported; use a PGM (P2/P5) or PPM (P3/P6) image")
    if magic == b"P7":
        raise ReadError(path, "PAM images (P7) are not supported; use a PGM (P2/P5) or PPM (P3/P6) image")
    if magic not in _MAGICS:
        raise ReadError(path, f"not a PGM/PPM file: starts with {head[:4]!r}, expected P2, P3, P5 or P6")
    tokens, pos = _header_tokens(path, head, 3, 2)
    width = _number(path, tokens[0], "width")
    height = _number(path, tokens[1], "height")
    maxval = _number(path, tokens[2], "maxval")
    check_dims(path, (width, height), "PNM width x height")
    if not 0 < maxval < 65536:
        raise ReadError(path, f"PNM maxval is {maxval}; must be 1..65535")
    if pos >= len(head) and _MAGICS[magic][1]:
        raise ReadError(path, "PNM header is not followed by a whitespace byte and the raster")
    return magic, width, height, maxval, pos + 1


def read_pnm(path: PathLike) -> Image2D:
    """Read a PGM/PPM image: data (rows, cols) for grey, (rows, cols, 3) for colour; uint8 or native uint16."""
    size = file_size(path)
    head = read_bytes(path, _HEADER_LIMIT)
    magic, width, height, maxval, offset = parse_pnm_header(path, head)
    channels, binary = _MAGICS[magic]
    shape = (height, width) if channels == 1 else (height, width, channels)
    n_values = width * height * channels
    dtype = np.uint8 if maxval < 256 else np.uint16
    if binary:
        sample = 1 if maxval < 256 else 2
        require_bytes(path, n_values * sample, size - offset,
                      f"{describe_dims((width, height))} {magic.decode()} raster of {sample}-byte samples")
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
        if len(tokens) < n_values:
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
