"""Dataset readers: ``read(path)`` picks the format; every reader raises ``ReadError`` naming the file and the
problem, quickly and before any large allocation (sizes are checked against the header first).

Readers (each returns a ``volviz.model`` dataset, convertible with ``.to_pyvista()``):

- PLOT3D whole-grid binary xyz (+ q)      -> CurvilinearGrid (Density, Momentum, StagnationEnergy, derived)
- PVM v1/v2/v3, 8/16 bit (DDS refused)    -> RegularVolume
- SLC (raw or run-length coded)           -> RegularVolume
- MetaImage .mhd/.raw, .mha               -> RegularVolume (3D) or Image2D (2D)
- VisIt brick of values .bov             -> RegularVolume (zonal values at the cell centres)
- raw volumes (explicit dims/type/order)  -> RegularVolume (``read_raw``), slice stacks (``read_slice_stack``)
- VTK legacy .vtk, XML .vti .vtu .vts .vtr .vtp -> RegularVolume / CurvilinearGrid / UnstructuredMesh
- VTKHDF (static or transient)            -> the matching dataset, or TimeSeries with lazy frames
- ParaView collections .pvd               -> TimeSeries at the file's times (a step's parts merged)
- PGM/PPM P2/P3/P5/P6, 8/16 bit           -> Image2D
- USGS DEM (ASCII)                        -> Image2D of heights in metres
- PNG/JPEG/TIFF/BMP (Pillow)              -> Image2D
- anything meshio reads                   -> UnstructuredMesh
- a numbered series (list, glob, ``%d``)  -> TimeSeries with lazy frames (``read_series``)
- a folder no reader opens itself         -> its collection file or largest numbered series (``folders``)

More formats come from reader plugins (entry-point group ``volviz.readers``, see ``volviz.io.registry``); the
optional ``volviz-vtk-readers`` plugin in ``plugins/`` adds Exodus II, OpenFOAM, CGNS, EnSight, netCDF CF, Tecplot,
AVS UCD, Fluent and the multiblock / parallel VTK XML files.

Float data holding NaN/Inf is kept (renderers draw it transparent) with a ``NonFiniteWarning`` giving the count;
``allow_nonfinite=False`` refuses it with a ReadError instead.
"""
from __future__ import annotations

import importlib

from volviz.io.errors import ChoiceWarning, NonFiniteWarning, ReadError, ReadWarning
from volviz.io.raw import read_raw, read_slice_stack
from volviz.io.reading import read, read_series
from volviz.io.registry import ReaderSpec, format_of, open_dialog_filter, reader_specs, supported_formats
from volviz.io.series import expand_pattern


def __getattr__(name: str):
    """Lazy access to the individual readers (``volviz.io.read_pvm`` ...) without importing VTK up front."""
    modules = {
        "read_pvm": "pvm", "read_pnm": "pnm", "read_slc": "slc", "read_dem": "dem", "read_metaimage": "metaimage",
        "read_plot3d": "plot3d", "read_vtk_file": "vtkfiles", "read_vtkhdf": "vtkhdf", "read_meshio": "meshio_reader",
        "read_image": "image",
    }
    if name in modules:
        return getattr(importlib.import_module(f"volviz.io.{modules[name]}"), name)
    raise AttributeError(f"module 'volviz.io' has no attribute {name!r}")


__all__ = [
    "ChoiceWarning", "NonFiniteWarning", "ReadError", "ReadWarning", "ReaderSpec", "reader_specs", "expand_pattern",
    "format_of", "open_dialog_filter", "read", "read_dem", "read_image", "read_meshio", "read_metaimage", "read_plot3d",
    "read_pnm", "read_pvm", "read_raw", "read_series", "read_slc", "read_slice_stack", "read_vtk_file", "read_vtkhdf",
    "supported_formats",
]
