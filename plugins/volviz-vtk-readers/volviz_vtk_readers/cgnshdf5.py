"""A check of CGNS files in HDF5 (CGNS/HDF5) with h5py, made before VTK's vtkCGNSReader opens them.

Every group and dataset of the file is visited, so damaged object headers make h5py fail here, as a ReadError
naming the file, rather than in VTK; and no dataset (a node's `` data``) may claim more bytes than the file could
hold even compressed (``volviz.io.vtkhdfcheck.check_dataset_sizes``), so a damaged shape cannot make VTK allocate a
huge array. The HDF5 superblock's end-of-file address is checked before, by ``containers.check_container``. ADF
files are checked by ``volviz_vtk_readers.adf``; without h5py this check is skipped.
"""
from __future__ import annotations

from volviz.io._checks import HDF5_SIGNATURE, check_file, file_size, read_bytes
from volviz.io.errors import PathLike, ReadError



def check_cgns_hdf5(path: PathLike) -> None:
    """ReadError when the CGNS/HDF5 file ``path`` has metadata h5py cannot read or a dataset larger than the file
    could hold; files that are not HDF5 (ADF) pass untouched."""
    p = check_file(path)
    if read_bytes(p, len(HDF5_SIGNATURE)) != HDF5_SIGNATURE:
        return
    try:
        import h5py
    except ImportError:  # pragma: no cover - h5py is a dependency
        return
    from volviz.io.vtkhdf import _printable
    from volviz.io.vtkhdfcheck import check_dataset_sizes

    try:
        with h5py.File(p, "r") as f:
            check_dataset_sizes(p, f, file_size(p))
    except ReadError as exc:
        raise ReadError(p, f"CGNS/HDF5: {exc.problem}") from None
    except PermissionError:
        raise ReadError(p, "permission denied (the file is not readable)") from None
    except (RuntimeError, OSError, KeyError, ValueError, TypeError, AttributeError, IndexError) as exc:
        raise ReadError(p, f"CGNS/HDF5: the HDF5 library could not read the file's structure ({type(exc).__name__}: "
                           f"{_printable(exc)}): the file is damaged") from None
