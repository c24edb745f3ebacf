"""SLC volumes (the VolVis "slice" format read by VTK's vtkSLCReader), 8-bit, raw or run-length encoded.

Layout (text fields are whitespace separated, as read by ``fscanf``)::

    11111                                   magic
    nx ny nz bits                           dimensions, bits per voxel (8)
    sx sy sz                                voxel spacing
    unit_type data_origin data_modification compression      (compression 0 = raw, 1 = RLE)
    iw ih X<3*iw*ih bytes>                  an RGB icon, three planes of iw*ih bytes, skipped
    nz slices of nx*ny voxels, x fastest:
      compression 0: the raw bytes
      compression 1: "<n> X" followed by n bytes of run-length code: a byte c with count = c & 0x7f; count 0
                     ends the slice; c & 0x80 means "count literal bytes follow", otherwise the next byte is
                     repeated count times.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from volviz.io._checks import check_dims, describe_bytes, describe_dims, file_size, read_bytes, require_bytes
from volviz.io.errors import PathLike, ReadError
from volviz.model import RegularVolume

SLC_MAGIC = 11111

# Real files are sloppy: every slice of shared/data/volumes/embryo.slc decodes to 65535 of its 65536 voxels (the
# encoder dropped the last voxel). vtkSLCReader leaves such voxels uninitialised; we set that one voxel to 0. Any
# larger shortfall means the header's dimensions do not describe the data (an x size one too large would otherwise
# pad every slice with a row of zeros) and is refused, as is code that does not end exactly at its slice's end.
_SLICE_SLACK = 1
_WS = b" \t\n\r\v\f"


@njit(cache=True, nogil=True)
def rle_decode_slice(src: np.ndarray, start: int, stop: int, out: np.ndarray) -> tuple[int, int]:
    """Decode SLC run-length code ``src[start:stop]`` into ``out``.

    Returns ``(voxels written, position after the code)``; the count is ``-1`` if the code writes past ``out`` and
    ``-2`` if it reads past ``stop`` in the middle of a run. Decoding stops after a zero count byte or at ``stop``.
    """
    pos = start
    n = 0
    size = out.shape[0]
    while pos < stop:
        c = src[pos]
        pos += 1
        count = c & 0x7F
        if count == 0:
            break
        if n + count > size:
            return -1, pos
        if c & 0x80:
            if pos + count > stop:
                return -2, pos
            for k in range(count):
                out[n + k] = src[pos + k]
            pos += count
        else:
            if pos >= stop:
                return -2, pos
            v = src[pos]
            pos += 1
            for k in range(count):
                out[n + k] = v
        n += count
    return n, pos


class _Scanner:
    """fscanf-like reading of whitespace-separated text fields from a byte buffer."""

    def __init__(self, path: PathLike, buf: bytes, pos: int = 0) -> None:
        self.path, self.buf, self.pos = path, buf, pos

    def token(self, what: str) -> bytes:
        buf, n = self.buf, len(self.buf)
        pos = self.pos
        while pos < n and buf[pos] in _WS:
            pos += 1
        begin = pos
        while pos < n and buf[pos] not in _WS and pos - begin < 64:
            pos += 1
        if begin == pos:
            raise ReadError(self.path, f"SLC file ends before the {what}")
        self.pos = pos
        return buf[begin:pos]

    def integer(self, what: str) -> int:
        tok = self.token(what)
        try:
            return int(tok)
        except ValueError:
            raise ReadError(self.path, f"SLC {what} is {describe_bytes(tok)}, not an integer") from None

    def number(self, what: str) -> float:
        tok = self.token(what)
        try:
            value = float(tok)
        except ValueError:
            raise ReadError(self.path, f"SLC {what} is {describe_bytes(tok)}, not a number") from None
        if not np.isfinite(value) or value <= 0:
            raise ReadError(self.path, f"SLC {what} must be a positive finite number, got {value:g}")
        return value

    def integer_then_x(self, what: str) -> int:
        """``%d X``: an integer, optional whitespace, the letter X; the position ends right after the X."""
        buf, n = self.buf, len(self.buf)
        pos = self.pos
        while pos < n and buf[pos] in _WS:
            pos += 1
        begin = pos
        while pos < n and 0x30 <= buf[pos] <= 0x39 and pos - begin < 12:
            pos += 1
        if begin == pos:
            raise ReadError(self.path, f"SLC {what} is missing or not a number at byte {begin}")
        value = int(buf[begin:pos])
        while pos < n and buf[pos] in _WS:
            pos += 1
        if pos >= n or buf[pos] != 0x58:  # 'X'
            raise ReadError(self.path, f"SLC {what} at byte {begin} is not followed by the letter X")
        self.pos = pos + 1
        return value


def parse_slc_header(path: PathLike, buf: bytes):
    """Parse the SLC header: ``(dims, bits, spacing, compression, data_offset)``; ReadError if malformed."""
    sc = _Scanner(path, buf)
    first = buf[:16].lstrip()
    if not first.startswith(b"11111"):
        raise ReadError(path, f"not an SLC file: starts with {describe_bytes(buf[:16])}, not the magic number 11111")
    magic = sc.integer("magic number")
    if magic != SLC_MAGIC:
        raise ReadError(path, f"not an SLC file: magic number {magic}, expected {SLC_MAGIC}")
    dims = check_dims(path, [sc.integer("dimension") for _ in range(3)], "SLC dimensions")
    bits = sc.integer("bits per voxel")
    spacing = tuple(sc.number("spacing") for _ in range(3))
    for what in ("unit type", "data origin", "data modification"):
        sc.integer(what)
    compression = sc.integer("compression")
    if bits != 8:
        raise ReadError(path, f"SLC with {bits} bits per voxel is not supported (only 8-bit, as vtkSLCReader)")
    if compression not in (0, 1):
        raise ReadError(path, f"unknown SLC compression {compression} (0 = raw, 1 = run-length)")
    icon_w = sc.integer("icon width")
    icon_h = sc.integer_then_x("icon height")
    if icon_w < 0 or icon_h < 0:
        raise ReadError(path, f"SLC icon size {icon_w}x{icon_h} is negative")
    offset = sc.pos + 3 * icon_w * icon_h
    return dims, bits, spacing, compression, offset


def read_slc(path: PathLike) -> RegularVolume:
    """Read an SLC volume (raw or RLE) into a uint8 RegularVolume with the header's spacing."""
    size = file_size(path)
    head = read_bytes(path, 512)
    dims, _bits, spacing, compression, offset = parse_slc_header(path, head)
    nx, ny, nz = dims
    plane = nx * ny
    what = f"SLC header's {describe_dims(dims)} voxels"
    require_bytes(path, offset, size, "SLC header and icon")
    if compression == 0:
        require_bytes(path, plane * nz, size - offset, what)
    else:
        # the densest run-length code spends 2 bytes per 127 voxels, plus "1 X" and a terminator per slice
        require_bytes(path, nz * (2 * -(-plane // 127) + 3), size - offset, what + " (run-length coded)")
    buf = np.frombuffer(read_bytes(path), dtype=np.uint8)
    if compression == 0:
        require_bytes(path, offset + plane * nz, len(buf), what)
        if len(buf) != offset + plane * nz:
            raise ReadError(path, f"{len(buf) - offset - plane * nz} bytes follow the {what}")
        volume = buf[offset:offset + plane * nz].copy()
    else:
        raw = buf.tobytes()
        sc = _Scanner(path, raw, offset)
        volume = np.empty(plane * nz, dtype=np.uint8)
        for z in range(nz):
            n = sc.integer_then_x(f"compressed size of slice {z}")
            start = sc.pos
            if start + n > len(buf):
                raise ReadError(path, f"slice {z} claims {n} compressed bytes but only {len(buf) - start} remain")
            got, end = rle_decode_slice(buf, start, start + n, volume[z * plane:(z + 1) * plane])
            if got < plane - _SLICE_SLACK or got > plane:
                problem = {-1: "decodes to more voxels than a slice holds",
                           -2: "ends in the middle of a run"}.get(got, f"decodes to {got} of the {plane} voxels of "
                                                                      f"the header's {nx}x{ny} slice")
                raise ReadError(path, f"run-length code of slice {z} {problem}")
            if end != start + n:
                raise ReadError(path, f"run-length code of slice {z} ends after {end - start} of its {n} bytes")
            volume[z * plane + got:(z + 1) * plane] = 0
            sc.pos = start + n
        if sc.pos != len(buf):
            raise ReadError(path, f"{len(buf) - sc.pos} bytes follow the last of the header's {nz} slices")
    return RegularVolume(volume.reshape(dims, order="F"), spacing=spacing, name="SLCImage", source=str(path))
