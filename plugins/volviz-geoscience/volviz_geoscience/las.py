"""LAS and LAZ lidar point clouds (``.las``, ``.laz``; LAS 1.0-1.4, point formats 0-10) through laspy.

- The points at their real coordinates: laspy applies the header's scale and offset to the stored integers, in
  float64, so UTM coordinates (x ~ 5e5, y ~ 5e6 m) keep their millimetres; VTK's OpenGL mapper draws them shifted to
  their own centre (its automatic shift and scale of vertex buffers), so they render without float32 jitter, and
  probes, bounds and the axes show the survey's own coordinates.
- Point arrays: ``elevation`` (z, the one shown first: what a lidar viewer colours by), then ``intensity``,
  ``classification``, ``return_number``, ``number_of_returns``, ``gps_time`` (formats 1 and 3-10), ``red``,
  ``green``, ``blue`` (formats 2, 3, 5, 7, 8, 10; 16-bit colours scaled to 0-255, 8-bit ones stored in 16 bits
  kept; choosing any of them shows the points in their own colours), and every numeric scalar extra-bytes dimension
  under its name. The points are vertices of an ``UnstructuredMesh``, drawn as points (``volviz.model.representation``).
- LAZ needs a decompressor (lazrs, laspy's ``[lazrs]`` extra); without one the file is refused saying so. A header
  that is cut short, a point count larger than the file holds, or compressed points that end early are refused in
  one line naming the file. The loader runs isolated (lazrs is native code).
"""
from __future__ import annotations

import struct
from pathlib import Path
from typing import Any

import numpy as np

from volviz.io._checks import check_file, describe_bytes, read_bytes
from volviz.io.errors import PathLike, ReadError
from volviz.model import UnstructuredMesh

HEADER_BYTES = 227          # the public header of LAS 1.0-1.2; 1.3 and 1.4 add to it
#: byte 104 of the public header: the point data format; LAZ writers set bit 7 (bit 6 by older ones) on it
FORMAT_BYTE = 104
COMPRESSED_BITS = 0xC0
#: the point dimensions kept as arrays, in laspy's names (those the point format has)
DIMENSIONS = ("intensity", "classification", "return_number", "number_of_returns", "gps_time")
COLOURS = ("red", "green", "blue")


def _open(p: Path) -> Any:
    import laspy  # type: ignore[import-untyped]  # laspy ships no types

    try:
        return laspy.open(str(p))
    except (laspy.errors.LaspyException, ValueError, OSError, EOFError) as exc:
        raise ReadError(p, f"its LAS header cannot be read ({exc})") from None


def _check_layout(p: Path, head: bytes) -> None:
    """The public header block's sizes against each other and the file (LAS 1.4 R15, table 3: header size at byte
    94, offset to point data at 96, number of VLRs at 100, each VLR at least 54 bytes) before laspy reads: an offset
    of 2^31 made laspy run past the reader's time limit."""
    header_size, offset, vlrs = struct.unpack_from("<HII", head, 94)
    size = p.stat().st_size
    if not HEADER_BYTES <= header_size <= offset <= size:
        raise ReadError(p, f"its LAS header size ({header_size}) and offset to the point data ({offset}) do not fit "
                           f"a file of {size} bytes (header size at least {HEADER_BYTES}, offset between it and the "
                           "end of the file)")
    if vlrs * 54 > offset - header_size:
        room = offset - header_size
        raise ReadError(p, f"its LAS header counts {vlrs} variable-length records, more than the {room} bytes "
                           "between the header and the point data hold (54 bytes each at least)")


def _check_room(p: Path, header: Any, compressed: bool) -> None:
    """An uncompressed file must hold the points its header counts."""
    if compressed:
        return
    need = int(header.offset_to_point_data) + int(header.point_count) * int(header.point_format.size)
    size = p.stat().st_size
    if size < need:
        room = max(size - int(header.offset_to_point_data), 0) // int(header.point_format.size)
        raise ReadError(p, f"its header counts {int(header.point_count):,} points but the file holds {room:,} "
                           f"({size:,} bytes of the {need:,} needed): it is cut short")


def _colours(points: Any) -> dict[str, np.ndarray]:
    """red, green, blue as 0-255: LAS stores 16-bit colours, which many writers fill with 8-bit values."""
    channels = [np.asarray(points[c]) for c in COLOURS]
    wide = max(int(c.max(initial=0)) for c in channels) > 255
    return {name: (np.rint(c / 257.0) if wide else c).astype(np.uint8) for name, c in zip(COLOURS, channels)}


def read_las(path: PathLike) -> UnstructuredMesh:
    """A LAS / LAZ point cloud as vertices with its point attributes as arrays (see the module docstring)."""
    import laspy

    p = check_file(path)
    head = read_bytes(p, 4096)
    if not head.startswith(b"LASF"):
        raise ReadError(p, f"is not a LAS file (it does not begin with LASF; its content is {describe_bytes(head)})")
    if len(head) < HEADER_BYTES:
        raise ReadError(p, f"its LAS header is cut short ({len(head)} bytes of at least {HEADER_BYTES})")
    compressed = len(head) > FORMAT_BYTE and bool(head[FORMAT_BYTE] & COMPRESSED_BITS)
    if compressed and not laspy.LazBackend.detect_available():
        raise ReadError(p, "is a compressed LAS file (LAZ) and no LAZ decompressor is installed",
                        "install one: pip install 'laspy[lazrs]'")
    _check_layout(p, head)
    with _open(p) as reader:
        header = reader.header
        _check_room(p, header, compressed)
        try:
            points = reader.read_points(int(header.point_count))
        except (laspy.errors.LaspyException, ValueError, RuntimeError, OSError, EOFError) as exc:
            raise ReadError(p, f"its points cannot be read ({exc})") from None
    if len(points) < int(header.point_count):
        raise ReadError(p, f"its header counts {int(header.point_count):,} points but only {len(points):,} could be "
                           "read: it is cut short")
    if not len(points):
        raise ReadError(p, "holds no points")
    xyz = np.stack([np.asarray(points.x, dtype=np.float64), np.asarray(points.y, dtype=np.float64),
                    np.asarray(points.z, dtype=np.float64)], axis=1)
    names = set(points.point_format.dimension_names)
    arrays: dict[str, np.ndarray] = {"elevation": xyz[:, 2].copy()}
    arrays.update({name: np.asarray(points[name]) for name in DIMENSIONS if name in names})
    if all(c in names for c in COLOURS):
        arrays.update(_colours(points))
    for name in points.point_format.extra_dimension_names:
        values = np.asarray(points[name])
        if values.ndim == 1 and values.dtype.kind in "biuf" and name not in arrays:
            arrays[name] = values
    # points only: the mesh makes one vertex cell per point
    return UnstructuredMesh(xyz, [], point_data=arrays, active="elevation", source=str(p))
