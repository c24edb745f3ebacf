"""Elevation models in the formats users download them in, as height maps (``Image2D`` of heights in metres, row 0
at the north edge, ``spacing`` the metres between samples): the terrain of a natural scene.

- GeoTIFF DEMs (USGS 3DEP, Copernicus, SRTM and ASTER GeoTIFFs, any single-band GeoTIFF; through tifffile): the
  sample spacing from ModelPixelScale and the placement from ModelTiepoint (a pixel-is-area tiepoint is the pixel's
  corner); a geographic raster (degrees) is put into metres at its centre's latitude (111,320 m per degree of
  longitude times the cosine of the latitude, 110,574 m per degree of latitude).
- SRTM ``.hgt`` tiles: 1201 x 1201 (3 arc-seconds) or 3601 x 3601 (1 arc-second) big-endian 16-bit heights, the
  tile's south-west corner from its name (``N46W122.hgt``).
- Samples marked as missing (GDAL_NODATA, the SRTM void -32768) hold the lowest valid height, as the USGS DEM
  reader fills its gaps, with a warning naming how many.
"""
from __future__ import annotations

import math
import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from volviz.io._checks import check_file, file_size, read_bytes
from volviz.io.errors import PathLike, ReadError, ReadWarning
from volviz.model import Image2D

METRES_PER_DEGREE_LAT = 110_574.0
METRES_PER_DEGREE_LON_AT_EQUATOR = 111_320.0
SRTM_VOID = -32768
SRTM_SIZES = {1201: 3.0, 3601: 1.0}            # samples per side -> arc-seconds between samples
_SRTM_NAME = re.compile(r"([NS])(\d{1,2})([EW])(\d{1,3})", re.I)


def geotiff_tags(path: PathLike) -> dict[str, Any] | None:
    """The GeoTIFF tags of a single-band, one-image TIFF (a DEM), or None for any other TIFF."""
    # heavy: tifffile (about 15 modules), loaded only when a GeoTIFF is read
    import tifffile

    try:
        with tifffile.TiffFile(str(path)) as tif:
            page = tif.pages.first
            tags = page.geotiff_tags
            if not tags or page.samplesperpixel != 1 or len(page.shape) != 2:
                return None
            nodata = page.tags.get("GDAL_NODATA")
            return {**tags, "GDAL_NODATA": nodata.value if nodata is not None else None}
    except (tifffile.TiffFileError, ValueError, OSError, EOFError, KeyError, IndexError, TypeError):
        return None


def is_elevation_model(path: PathLike) -> bool:
    """Whether ``path`` is an SRTM tile or a single-band GeoTIFF (opened as terrain)."""
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".hgt":
        return p.is_file()
    return suffix in (".tif", ".tiff") and p.is_file() and geotiff_tags(p) is not None


def _filled(path: PathLike, heights: np.ndarray, missing: np.ndarray) -> np.ndarray:
    """``heights`` with the ``missing`` samples at the lowest valid height (a warning says how many)."""
    heights = heights.astype(np.float32)
    missing = missing | ~np.isfinite(heights)
    if missing.all():
        raise ReadError(path, "holds no valid height (every sample is marked missing)")
    if missing.any():
        heights[missing] = float(heights[~missing].min())
        warnings.warn(f"{path}: {int(missing.sum())} samples are marked missing; they are shown at the lowest valid "
                      "height", ReadWarning, stacklevel=3)
    return heights


def read_geotiff_dem(path: PathLike, tags: dict[str, Any]) -> Image2D:
    """A single-band GeoTIFF (``tags``: ``geotiff_tags``) as heights in metres."""
    # heavy: tifffile (about 15 modules), loaded only when a GeoTIFF is read
    import tifffile

    scale = tags.get("ModelPixelScale")
    tie = tags.get("ModelTiepoint")
    if scale is None or tie is None or len(scale) < 2 or len(tie) < 6:
        raise ReadError(path, "is a GeoTIFF without ModelPixelScale and ModelTiepoint (a rotated or "
                              "transform-matrix raster, which volviz does not place)")
    sx, sy = abs(float(scale[0])), abs(float(scale[1]))
    if not (math.isfinite(sx) and math.isfinite(sy) and sx > 0 and sy > 0):
        raise ReadError(path, f"its ModelPixelScale {tuple(scale[:2])} is not a positive pixel size")
    try:
        with tifffile.TiffFile(str(path)) as tif:
            heights = tif.pages.first.asarray()
    except (tifffile.TiffFileError, ValueError, OSError, EOFError, MemoryError) as exc:
        raise ReadError(path, f"its heights could not be read ({exc})") from None
    missing = np.zeros(heights.shape, dtype=bool)
    nodata = tags.get("GDAL_NODATA")
    if nodata is not None:
        try:
            missing = heights == float(str(nodata).strip("\x00 "))
        except ValueError:
            pass
    heights = _filled(path, heights, missing)
    rows = heights.shape[0]
    half = 0.5 if int(tags.get("GTRasterTypeGeoKey", 1)) == 1 else 0.0          # pixel is area: tie at a corner
    west = float(tie[3]) + (half - float(tie[0])) * sx
    north = float(tie[4]) - (half - float(tie[1])) * sy
    south = north - (rows - 1) * sy
    if int(tags.get("GTModelTypeGeoKey", 1)) == 2:                              # geographic: degrees
        metres_x = METRES_PER_DEGREE_LON_AT_EQUATOR * math.cos(math.radians(0.5 * (north + south)))
        sx, west = sx * metres_x, west * metres_x
        sy, south = sy * METRES_PER_DEGREE_LAT, south * METRES_PER_DEGREE_LAT
    return Image2D(heights, spacing=(sx, sy), origin=(west, south), source=str(path))


def read_hgt(path: PathLike) -> Image2D:
    """An SRTM ``.hgt`` tile as heights in metres (see the module)."""
    p = check_file(path)
    size = file_size(p)
    side = int(round(math.sqrt(size / 2)))
    if side not in SRTM_SIZES or side * side * 2 != size:
        raise ReadError(p, f"is {size} bytes; an SRTM tile is 1201 x 1201 or 3601 x 3601 16-bit samples "
                           f"({2 * 1201 ** 2} or {2 * 3601 ** 2} bytes)")
    heights = np.frombuffer(read_bytes(p), dtype=">i2").reshape(side, side).astype(np.int16)
    heights = _filled(p, heights, heights == SRTM_VOID)
    match = _SRTM_NAME.match(p.stem)
    lat = (1 if match.group(1).upper() == "N" else -1) * int(match.group(2)) if match else 0
    lon = (1 if match.group(3).upper() == "E" else -1) * int(match.group(4)) if match else 0
    step = SRTM_SIZES[side] / 3600.0
    metres_x = METRES_PER_DEGREE_LON_AT_EQUATOR * math.cos(math.radians(lat + 0.5))
    return Image2D(heights, spacing=(step * metres_x, step * METRES_PER_DEGREE_LAT),
                   origin=(lon * metres_x, lat * METRES_PER_DEGREE_LAT), source=str(p))
