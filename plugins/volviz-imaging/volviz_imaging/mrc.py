"""MRC / CCP4 density maps (.mrc, .map, .ccp4, .rec, also gzip-compressed), the volumes of cryo-EM and
crystallography, through mrcfile.

- Values: the map's densities as stored (mode 0-2, 6, 12; mode 4, complex, is refused).
- Axes: the sections, rows and columns of the file are the world axes MAPS, MAPR and MAPC (a CCP4 map may store them
  in any order): the volume is laid out x, y, z whatever the order.
- Voxel size: mrcfile's ``voxel_size`` (cell size over samples, Angstrom); placement: the header's ORIGIN when it
  is set, else the start indices (NXSTART, NYSTART, NZSTART) times the voxel size, as ChimeraX places maps.
- mrcfile validates the header and checks the data size against the file before the data is mapped.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from volviz.io._checks import check_finite, check_file
from volviz.io.errors import PathLike, ReadError
from volviz.model import RegularVolume


def read_mrc(path: PathLike, allow_nonfinite: bool = True) -> RegularVolume:
    """An MRC / CCP4 map as a volume in Angstrom (see the module)."""
    import mrcfile

    p = check_file(path)
    try:
        with mrcfile.open(p, mode="r", permissive=False) as mrc:
            header = mrc.header
            voxel = mrc.voxel_size
            sx, sy, sz = (float(v) if np.isfinite(v) and v > 0 else 1.0 for v in (voxel.x, voxel.y, voxel.z))
            order = [int(header.mapc), int(header.mapr), int(header.maps)]   # world axis of columns, rows, sections
            start = np.array([int(header.nxstart), int(header.nystart), int(header.nzstart)], dtype=np.float64)
            origin = np.array([float(header.origin.x), float(header.origin.y), float(header.origin.z)])
            if np.iscomplexobj(mrc.data):
                raise ReadError(p, "holds complex (Fourier) data, not a density map")
            data = np.array(mrc.data)
    except ReadError:
        raise
    except (ValueError, OSError, EOFError, RuntimeError, TypeError) as exc:
        raise ReadError(p, f"not an MRC / CCP4 map mrcfile can read ({exc})") from None
    if sorted(order) != [1, 2, 3]:
        raise ReadError(p, f"its axis order MAPC, MAPR, MAPS = {order} is not a permutation of 1, 2, 3")
    if data.ndim == 2:
        data = data[None]
    if data.ndim != 3:
        raise ReadError(p, f"holds a {data.ndim}D stack of volumes; volviz reads one volume")
    # data[section, row, column] -> volume[x, y, z]: the file axis that holds world axis a is (2, 1, 0)[order.index(a)]
    data = np.transpose(data, [(2, 1, 0)[order.index(a)] for a in (1, 2, 3)])
    if not np.any(origin) and np.all(np.isfinite(origin)):
        origin = start * np.array([sx, sy, sz])
    if not np.all(np.isfinite(origin)):
        origin = np.zeros(3)
    check_finite(p, data, allow_nonfinite)
    ox, oy, oz = (float(v) for v in origin)
    return RegularVolume(data, spacing=(sx, sy, sz), origin=(ox, oy, oz), name="density", source=str(Path(p)))
