"""USGS DEM (ASCII, the classic 7.5-minute format read by VTK's vtkDEMReader) -> Image2D of heights.

A DEM is a 1024-character type A header (fixed-width fields, Fortran ``D`` exponents) followed by one type B
record per profile: four integers (row, column, number of rows, number of columns), five reals (x, y of the
first sample, local datum elevation, min, max) and the profile's elevations from south to north, all read as
``fscanf`` does (``%6d``, ``%120c``). Elevations are multiplied by the vertical resolution (and 0.3048 for feet).

Placement (``vtk_compatible``):

- ``False`` (default, geographic): a profile is placed at the grid row of its first sample's y coordinate and
  the column of its x coordinate, so profiles that start north of the quadrangle's south edge stay where they
  belong. The grid spans the samples actually present.
- ``True``: exactly vtkDEMReader's grid: columns and rows from the corner coordinates, origin at the south-west
  corner, and every profile placed from row ``profile_row - 1`` upwards (VTK ignores the profile's y).

Either way cells without a sample hold the header's minimum elevation (as VTK). The Image2D has row 0 at the
NORTH edge and column 0 at the west (an image of the map); ``origin`` is the (x, y) of the south-west sample
(VTK's origin) and ``spacing`` the positive (dx, dy) in metres.
"""
from __future__ import annotations

import re

import numpy as np

from volviz.io._checks import describe_bytes, describe_dims, file_size, read_bytes
from volviz.io.errors import PathLike, ReadError, bytes_and_size
from volviz.model import Image2D

FEET = 0.3048
ARC_SECOND = 23.111  # vtkDEMReader's metres per arc-second (VTK_METERS_PER_ARC_SECOND); crude, as in VTK
TYPE_C_BYTES = 1024  # the optional accuracy record (type C) after the profiles
_INT6 = re.compile(rb"[ \t\r\n\f\v]*([-+]?[0-9]{1,6})")


def _field(path: PathLike, rec: bytes, start: int, width: int, what: str, kind=float):
    text = rec[start:start + width].decode("ascii", "replace").strip().replace("D", "E").replace("d", "e")
    try:
        value = kind(float(text)) if kind is int and "." in text else kind(text)
    except (ValueError, OverflowError):
        raise ReadError(path, f"DEM header field {what} at column {start + 1} is {describe_bytes(text)}, not a "
                              "number") from None
    if kind is float and not np.isfinite(value):
        raise ReadError(path, f"DEM header field {what} is {value}")
    return value


def _unit(code: int) -> float:
    return {1: FEET, 3: ARC_SECOND}.get(code, 1.0)


def parse_dem_header(path: PathLike, rec: bytes) -> dict:
    """The type A fields a height grid needs; ReadError if the record is short or a field is not a number."""
    if len(rec) < 864:
        raise ReadError(path, f"DEM type A header is {len(rec)} bytes, needs at least 864 (1024 in the standard)")
    h: dict = {}
    h["plane_unit"] = _field(path, rec, 528, 6, "plane unit", int)
    h["elevation_unit"] = _field(path, rec, 534, 6, "elevation unit", int)
    h["corners"] = np.array([_field(path, rec, 546 + 24 * i, 24, "ground coordinate") for i in range(8)]).reshape(4, 2)
    h["elevation_bounds"] = (_field(path, rec, 738, 24, "minimum elevation"),
                             _field(path, rec, 762, 24, "maximum elevation"))
    h["resolution"] = tuple(_field(path, rec, 816 + 12 * i, 12, "spatial resolution") for i in range(3))
    h["profiles"] = (_field(path, rec, 852, 6, "profile rows", int), _field(path, rec, 858, 6, "profile columns", int))
    if min(h["resolution"][:2]) <= 0 or h["resolution"][2] <= 0:
        raise ReadError(path, f"DEM spatial resolution {h['resolution']} must be positive")
    if h["profiles"][1] <= 0 or h["profiles"][0] <= 0:
        raise ReadError(path, f"DEM profile dimensions {h['profiles']} must be positive")
    return h


def _vtk_grid(h: dict) -> tuple[float, float]:
    """vtkDEMReader::ComputeExtentOriginAndSpacing: (columns, rows), as floats until checked to be sane."""
    c = h["corners"]  # SW, NW, NE, SE
    east, west = max(c[2, 0], c[3, 0]), min(c[1, 0], c[0, 0])
    north, south = max(c[2, 1], c[1, 1]), min(c[0, 1], c[3, 1])
    with np.errstate(all="ignore"):
        return (np.floor((east - west) / h["resolution"][0] + 1.0),
                np.floor((north - south) / h["resolution"][1] + 1.0))


def _grid_fits(path: PathLike, cols: float, rows: float, size: int, what: str) -> tuple[int, int]:
    """Columns and rows as ints once they are finite, positive and not more cells than the file has bytes."""
    ok = np.isfinite(cols) and np.isfinite(rows) and cols >= 1 and rows >= 1 and cols * rows <= max(size, 1)
    if not ok:
        raise ReadError(path, f"{what} a {cols:g} x {rows:g} grid, which does not fit the file's {bytes_and_size(size)}"
                              f": corrupt coordinates or resolution")
    return int(cols), int(rows)


def _read_profiles(path: PathLike, buf: bytes, h: dict):
    """Every profile as (row id, column id, x, y, elevations int64)."""
    pos, out = 1024, []
    n_profiles = h["profiles"][1]
    for column in range(n_profiles):
        ints: list[int] = []
        for _ in range(4):
            m = _INT6.match(buf, pos)
            if m is None:
                if not ints and buf[pos:].strip() == b"":
                    raise ReadError(path, f"DEM file ends after {column} of the header's {n_profiles} profiles")
                raise ReadError(path, f"DEM profile {column + 1} header at byte {pos} is not four integers")
            ints.append(int(m.group(1)))
            pos = m.end()
        row_id, col_id, n_rows, n_cols = ints
        if n_rows < 0 or n_cols < 0 or row_id < 1 or col_id < 1:
            raise ReadError(path, f"DEM profile {column + 1} has invalid ids/sizes {ints}")
        reals = buf[pos:pos + 120]
        if len(reals) < 120:
            raise ReadError(path, f"DEM profile {column + 1} header is truncated at byte {pos}")
        pos += 120
        x = _field(path, reals, 0, 24, f"x of profile {column + 1}")
        y = _field(path, reals, 24, 24, f"y of profile {column + 1}")
        count = n_rows * n_cols
        if count > (len(buf) - pos) // 2 + 1:
            raise ReadError(path, f"DEM profile {column + 1} claims {count} elevations but only "
                                  f"{len(buf) - pos} bytes remain")
        values = np.empty(count, dtype=np.int64)
        for k in range(count):
            m = _INT6.match(buf, pos)
            if m is None:
                raise ReadError(path, f"DEM profile {column + 1} ends after {k} of {count} elevations "
                                      f"(byte {pos})")
            values[k] = int(m.group(1))
            pos = m.end()
        out.append((row_id, col_id, x, y, values))
    rest = len(buf[pos:].strip())
    if rest > TYPE_C_BYTES:  # more than an accuracy record: profiles the header's count leaves out (issue #32)
        raise ReadError(path, f"DEM header gives {n_profiles} profile columns, but {rest} bytes of data follow the "
                              f"last of them (from byte {pos}): the header's count is less than the file holds")
    return out


def read_dem(path: PathLike, vtk_compatible: bool = False) -> Image2D:
    """Read a USGS ASCII DEM into an Image2D of float64 heights in metres (see the module docstring)."""
    size = file_size(path)
    buf = read_bytes(path)
    h = parse_dem_header(path, buf[:1024])
    dx, dy, dz = h["resolution"]
    plane, elev = _unit(h["plane_unit"]), _unit(h["elevation_unit"])
    low = h["elevation_bounds"][0] * elev
    cols, rows = _grid_fits(path, *_vtk_grid(h), size, "DEM header corners describe")
    profiles = _read_profiles(path, buf, h)
    if not profiles:
        raise ReadError(path, "DEM holds no elevation profiles")
    peak = max(float(np.abs(p[4]).max(initial=0)) for p in profiles)
    if not (np.isfinite(peak * dz * elev) and np.isfinite(low)):
        raise ReadError(path, f"DEM heights overflow: elevations times the vertical resolution {dz:g} are not finite "
                              "numbers")
    if vtk_compatible:
        grid = np.full((rows, cols), low, dtype=np.float64)  # row 0 = south here, flipped below
        for row_id, col_id, _x, _y, values in profiles:
            r0, c = row_id - 1, col_id - 1
            if c >= cols or r0 + len(values) > rows:
                raise ReadError(path, f"DEM profile in column {col_id} with {len(values)} rows from row {row_id} "
                                      f"falls outside vtkDEMReader's {describe_dims((cols, rows))} grid")
            grid[r0:r0 + len(values), c] = values * (dz * elev)
        origin = (h["corners"][0, 0] * plane, h["corners"][0, 1] * plane)
    else:
        xs = np.array([p[2] for p in profiles])
        ys = np.array([p[3] for p in profiles])
        x0, y0 = xs.min(), ys.min()
        with np.errstate(all="ignore"):
            col_f = np.rint((xs - x0) / dx)
            row_f = np.rint((ys - y0) / dy)
            span_rows = max(float(r) + len(p[4]) for r, p in zip(row_f, profiles))
        n_cols, n_rows = _grid_fits(path, float(col_f.max()) + 1.0, span_rows, size, "DEM profiles span")
        col_idx, row_idx = col_f.astype(np.int64), row_f.astype(np.int64)
        if len(np.unique(col_idx)) < len(profiles):  # a resolution that does not fit the profiles' x positions
            raise ReadError(path, f"DEM horizontal resolution {dx:g} puts {len(profiles)} profiles (x "
                                  f"{xs.min():g} to {xs.max():g}) on {len(np.unique(col_idx))} columns: the header "
                                  "does not match the profiles")
        grid = np.full((n_rows, n_cols), low, dtype=np.float64)
        for r, c, (_, _, _, _, values) in zip(row_idx, col_idx, profiles):
            grid[r:r + len(values), c] = values * (dz * elev)
        origin = (x0 * plane, y0 * plane)
    return Image2D(np.ascontiguousarray(grid[::-1]), spacing=(dx * plane, dy * plane), origin=origin,
                   source=str(path))
