"""The Exodus II element connectivity, checked before VTK's reader builds cells from it.

Each element block's ``connect<i>`` variable holds 1-based node numbers (Exodus II format: ``num_nodes`` nodes).
VTK's ``vtkExodusIIReader`` does not check them: a node number past ``num_nodes`` (one flipped bit) made it add a
point whose coordinates it read from past its array, a mesh with one more point than the file has and, depending
on what that memory held, an image or a refusal. Here every node number of every block must lie in 1..num_nodes;
netCDF classic files are read through their checked header (``containers.netcdf_header``), netCDF-4 (HDF5) files
through h5py, both in chunks so that memory stays bounded.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from volviz.io.errors import PathLike, ReadError
from volviz_vtk_readers.containers import HDF5_SIGNATURE, netcdf_header

_CONNECT = re.compile(r"connect\d+$")
_INT_TYPES = {3: ">i2", 4: ">i4", 10: ">i8"}    # NC_SHORT, NC_INT, NC_INT64
CHUNK = 1 << 22                                   # node numbers checked at a time


def _check_range(path: Path, name: str, values: np.ndarray, num_nodes: int) -> None:
    if values.size == 0:
        return
    lo, hi = int(values.min()), int(values.max())
    if lo < 1 or hi > num_nodes:
        bad = lo if lo < 1 else hi
        raise ReadError(path, f"Exodus II: element block connectivity {name!r} refers to node {bad}, but the file "
                              f"has nodes 1 to {num_nodes} (num_nodes)")


def check_exodus_connectivity(path: PathLike) -> None:
    """ReadError naming the block and the node when an element block refers to a node the file does not have."""
    p = Path(path)
    with open(p, "rb") as f:
        head = f.read(8)
    if head.startswith(HDF5_SIGNATURE):
        _check_hdf5(p)
        return
    header = netcdf_header(p, "Exodus II")
    if header is None or "num_nodes" not in header.dims:
        return
    num_nodes = header.dims["num_nodes"]
    for var in header.variables.values():
        dtype = _INT_TYPES.get(var.nc_type)
        if not _CONNECT.match(var.name) or dtype is None or var.record:
            continue
        count = int(np.prod(var.shape, dtype=np.int64))
        data = np.memmap(p, dtype=dtype, mode="r", offset=var.begin, shape=(count,)) if count else np.zeros(0)
        for start in range(0, count, CHUNK):
            _check_range(p, var.name, np.asarray(data[start:start + CHUNK]), num_nodes)


def _check_hdf5(path: Path) -> None:
    """netCDF-4 Exodus: ``num_nodes`` is a dimension scale (a dataset of that length), ``connect<i>`` datasets."""
    import h5py

    with h5py.File(path, "r") as f:
        if "num_nodes" not in f:
            return
        num_nodes = int(f["num_nodes"].shape[0])
        for name, item in f.items():
            if not _CONNECT.match(name) or not isinstance(item, h5py.Dataset) or item.dtype.kind not in "iu":
                continue
            if item.ndim == 0:
                _check_range(path, name, np.asarray(item[()]).reshape(-1), num_nodes)
                continue
            rows = max(1, CHUNK // max(1, int(np.prod(item.shape[1:], dtype=np.int64))))   # whole rows per chunk
            for start in range(0, item.shape[0], rows):
                _check_range(path, name, np.asarray(item[start:start + rows]), num_nodes)
