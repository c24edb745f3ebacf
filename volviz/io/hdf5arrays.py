"""Plain HDF5 files (.h5, .hdf5, NeXus .nxs, ...) holding arrays: tomography reconstructions, simulation fields,
ilastik and other lab tools' volumes, through h5py. Formats on HDF5 (VTKHDF, Fluent CFF, CGNS, Exodus,
netCDF-4, MAT v7.3: ``volviz.io.hdf5kind``) go to their own readers unless ``dataset=`` names an array.

- Which array: ``dataset="/entry/data/data"`` (its path in the file); by default the largest numeric 3D or 4D
  dataset, the others named in a warning (and every one in the error when none fits).
- Layout: HDF5 stores arrays in C order, and volviz reads a (nz, ny, nx) dataset with x fastest, as XDMF describes
  such arrays to ParaView and as image stacks (slice, row, column) are stored; a 4D dataset whose last axis has 2 to
  4 entries is (z, y, x, channels), any other 4D one (t, z, y, x), a time series (``order="xyz"``: x, y, z instead,
  ``volviz.io.axis_order``). A file with only 2D datasets
  gives the largest as an image.
- Voxel size: the dataset's ``element_size_um`` attribute (ilastik, z y x) or ``spacing`` / ``voxel_size`` (in
  the dataset's axis order); 1 where it has none.
- The dataset's storage is checked against the file before it is read (an uncompressed dataset must fit in the file,
  a compressed one may not claim more than ``MAX_RATIO`` times its stored bytes). The HDF5 library is native code:
  the reader runs isolated (``volviz.io.isolated``).
"""
from __future__ import annotations

import re
import warnings
from typing import Any

import numpy as np

from volviz.io._checks import HDF5_SIGNATURE, check_file, check_finite, file_size, read_bytes
from volviz.io.array_choice import choose_array
from volviz.io.axis_order import check_order, to_xyz
from volviz.io.errors import PathLike, ReadError, ReadWarning, human_bytes
from volviz.io.hdf5kind import check_named_kind, hdf5_kind, read_as_kind
from volviz.model import Image2D, RegularVolume, TimeSeries
from volviz.model.arrays import volume_of

MAX_DATASETS = 10_000    # datasets of a file looked at
MAX_RATIO = 1032         # what deflate can inflate to; other filters are held by the reader process's memory limit
_SPACING_ATTRS = ("element_size_um", "spacing", "voxel_size")


def has_vtkhdf_group(path: PathLike) -> bool:
    # heavy: h5py (about 45 modules), loaded only when an HDF5 file is read
    import h5py

    try:
        with h5py.File(path, "r") as f:
            return "VTKHDF" in f and isinstance(f["VTKHDF"], h5py.Group)
    except (OSError, RuntimeError, ValueError, KeyError, TypeError):
        return False


def _arrays(f: Any) -> list[tuple[str, tuple[int, ...]]]:
    """(path, shape) of every numeric dataset of 2 to 4 dimensions of more than one entry each."""
    # heavy: h5py (about 45 modules), loaded only when an HDF5 file is read
    import h5py

    found: list[tuple[str, tuple[int, ...]]] = []
    seen = 0

    def visit(name: str, obj: Any) -> None:
        nonlocal seen
        seen += 1
        if seen > MAX_DATASETS or not isinstance(obj, h5py.Dataset):
            return
        shape = tuple(int(n) for n in obj.shape or ())
        if 2 <= len(shape) <= 4 and min(shape) > 1 and obj.dtype.kind in "biuf" and obj.dtype.names is None:
            found.append(("/" + name, shape))

    f.visititems(visit)
    return found


def _pick(path: PathLike, f: Any, dataset: str | None) -> str:
    wanted = None if dataset is None else "/" + dataset.lstrip("/")
    return choose_array(path, _arrays(f), wanted, "dataset", "holds no numeric dataset of 2 to 4 dimensions (an "
                        "image, a volume, channels or time steps)")


def _check_storage(path: PathLike, ds: Any) -> None:
    needed = int(np.prod(ds.shape, dtype=object)) * ds.dtype.itemsize
    size = file_size(path)
    limit = size if ds.compression is None and not ds.chunks else MAX_RATIO * size
    if needed > limit:
        raise ReadError(path, f"its dataset {ds.name} claims {'x'.join(map(str, ds.shape))} {ds.dtype} values "
                              f"({human_bytes(needed)}), more than the file's {size} bytes can hold")


def _spacing(path: PathLike, ds: Any, order: str) -> tuple[float, float, float]:
    """(x, y, z) from the first voxel-size attribute in the dataset's axis order; 1 where it has none."""
    for key in _SPACING_ATTRS:
        if key in ds.attrs:
            try:
                values = np.asarray(ds.attrs[key], dtype=np.float64).ravel()
            except (TypeError, ValueError):
                continue
            if values.size >= 3 and np.all(np.isfinite(values[-3:])) and np.all(values[-3:] > 0):
                a, b, c = (float(v) for v in values[-3:])
                return (c, b, a) if order == "zyx" else (a, b, c)
            warnings.warn(f"{path}: the {key} attribute of {ds.name} ({values.tolist()}) is not three positive "
                          "sizes; unit voxels are used", ReadWarning, stacklevel=4)
    return 1.0, 1.0, 1.0


def _volume(path: PathLike, data: np.ndarray, spacing: tuple[float, float, float], name: str, order: str,
            allow_nonfinite: bool) -> RegularVolume:
    """(z, y, x[, c]) (or in ``order``) -> a volume (x, y, z[, c])."""
    data = to_xyz(data, order)
    if data.dtype.kind == "b":
        data = data.astype(np.uint8)
    check_finite(path, data, allow_nonfinite)
    return volume_of(data, name, spacing, source=str(path))


#: the most XDMF files beside an HDF5 file looked at, and the bytes read of each
MAX_XDMF_SIBLINGS = 20
XDMF_HEAD_BYTES = 1 << 20


def _warn_if_heavy_data(p: Any) -> None:
    """A ReadWarning when an XDMF file beside ``p`` names it as its heavy data (meshio, dolfinx, FEniCS and many
    solvers write a .xdmf describing the mesh and a .h5 holding its arrays): the .xdmf is what shows the data as the
    solver meant (the .h5 alone is a list of arrays: points, cell connectivity, fields)."""
    for sibling in sorted(p.parent.glob("*.xmf"))[:MAX_XDMF_SIBLINGS] + sorted(
            p.parent.glob("*.xdmf"))[:MAX_XDMF_SIBLINGS]:
        try:
            head = read_bytes(sibling, XDMF_HEAD_BYTES).decode("utf-8", errors="replace")
        except OSError:
            continue
        if re.search(r"(^|[\s/\\>\"])" + re.escape(p.name) + r"\s*:", head):
            warnings.warn(f"{p}: is the heavy data of {sibling.name} beside it, which describes the mesh and fields "
                          f"its arrays hold; open {sibling.name} to see them as meant", ReadWarning, stacklevel=3)
            return


def read_hdf5(path: PathLike, dataset: str | None = None, order: str = "zyx",
              allow_nonfinite: bool = True) -> RegularVolume | TimeSeries | Image2D | Any:
    """An HDF5 file's array as a volume, a time series or an image (see the module; ``order``:
    ``volviz.io.axis_order``); VTKHDF files as VTK data."""
    # heavy: h5py (about 45 modules), loaded only when an HDF5 file is read
    import h5py

    p = check_file(path)
    check_order(p, order)
    kind = hdf5_kind(p) if dataset is None else None
    if kind is not None:  # a format on HDF5 (Fluent CFF, CGNS, Exodus, netCDF-4, VTKHDF, MAT v7.3): its own reader
        return read_as_kind(p, kind, allow_nonfinite)
    if read_bytes(p, 8) != HDF5_SIGNATURE:
        raise ReadError(p, "not an HDF5 file (no HDF5 signature at its start)")
    if dataset is None:
        _warn_if_heavy_data(p)
    try:
        with h5py.File(p, "r") as f:
            if dataset is None:
                check_named_kind(p, f)
            name = _pick(p, f, dataset)
            ds = f[name]
            _check_storage(p, ds)
            spacing = _spacing(p, ds, order)
            data = ds[()]
    except ReadError:
        raise
    except (OSError, RuntimeError, KeyError, ValueError, TypeError, IndexError, MemoryError) as exc:
        raise ReadError(p, f"the HDF5 library could not read it ({type(exc).__name__}: {str(exc)[:200]})") from None
    label = name.rsplit("/", 1)[-1] or "data"
    if data.ndim == 2:
        check_finite(p, data, allow_nonfinite)
        return Image2D(np.ascontiguousarray(data), source=str(p))
    if data.ndim == 3 or 2 <= data.shape[3] <= 4:
        return _volume(p, data, spacing, label, order, allow_nonfinite)
    frames: list[Any] = [_volume(p, data[t], spacing, label, order, allow_nonfinite) for t in range(len(data))]
    return TimeSeries(np.arange(len(frames), dtype=np.float64), frames, source=str(p))
