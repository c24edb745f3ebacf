"""The reader specs this plugin registers (entry point ``volviz.readers``), with their content sniffers.

Importing this module imports neither VTK nor the loaders: volviz reads it to know the formats, and imports
``volviz_vtk_readers.readers`` only when a file of one of them is opened.
"""
from __future__ import annotations

import re
from typing import Any

from volviz.io._checks import is_hdf5
from volviz.io.registry import ReaderSpec

from volviz_vtk_readers.containers import is_cgns, is_netcdf
from volviz_vtk_readers.xdmf import is_xdmf

_TECPLOT_KEYWORD = re.compile(rb"\s*(TITLE|VARIABLES|ZONE|FILETYPE|DATASETAUXDATA|TEXT|GEOMETRY)\b", re.I)
_XML_TYPE = re.compile(rb'<VTKFile[^>]*\btype="([A-Za-z]+)"')
MULTIBLOCK_TYPES = (b"vtkMultiBlockDataSet", b"vtkPartitionedDataSetCollection", b"vtkPartitionedDataSet")
PARALLEL_TYPES = (b"PUnstructuredGrid", b"PImageData", b"PStructuredGrid", b"PRectilinearGrid", b"PPolyData")


def _first_lines(head: bytes, comment: bytes = b"#") -> list[bytes]:
    return [ln.strip() for ln in head.splitlines() if ln.strip() and not ln.strip().startswith(comment)]


def is_tecplot(head: bytes) -> bool:
    """A Tecplot ASCII header (TITLE, VARIABLES, ZONE ...) or a Tecplot binary file (``#!TDV``)."""
    if head.startswith(b"#!TDV"):
        return True
    lines = _first_lines(head)
    return bool(lines) and _TECPLOT_KEYWORD.match(lines[0]) is not None


def is_avs_ucd(head: bytes) -> bool:
    """AVS UCD: binary files start with byte 7; ASCII ones with a line of counts after their # comments (five;
    two to four in a header line cut short, which the AVS UCD check then refuses by name: issue #32, it went to the
    other reader of ``.inp``, meshio's Abaqus reader, whose files start with ``*`` keywords). A single number is not
    taken: other formats start so (an SLC file's magic number, a PLOT3D block count)."""
    if head[:1] == b"\x07":
        return True
    lines = _first_lines(head)
    return bool(lines) and re.fullmatch(rb"(\d+\s+){1,4}\d+", lines[0]) is not None


def is_fluent(head: bytes) -> bool:
    """Fluent case / data files are sections ``(index ...)``, the first usually ``(0 "comment")``."""
    return re.match(rb"\s*\(\s*\d+\s", head) is not None


def is_ensight_case(head: bytes) -> bool:
    lines = _first_lines(head)
    return bool(lines) and lines[0].upper().startswith(b"FORMAT")


def xml_type(head: bytes) -> str:
    """The ``type`` of a VTK XML file's ``<VTKFile>`` element ('' if there is none)."""
    m = _XML_TYPE.search(head)
    return m.group(1).decode() if m else ""


def _xml_type_in(head: bytes, types: tuple[bytes, ...]) -> bool:
    return xml_type(head).encode() in types


def is_vtk_multiblock(head: bytes) -> bool:
    return _xml_type_in(head, MULTIBLOCK_TYPES)


def is_vtk_parallel(head: bytes) -> bool:
    return _xml_type_in(head, PARALLEL_TYPES)


_R = "volviz_vtk_readers.readers:"
_BLOCKS = ("blocks", "time_index", "allow_nonfinite")


def _spec(name: str, description: str, patterns: tuple[str, ...], loader: str, **kwargs: Any) -> ReaderSpec:
    """Every loader here runs a VTK C++ reader, which a malformed file can crash: ``read`` runs it isolated."""
    return ReaderSpec(name, description, patterns, loader, isolated=True, **kwargs)


SPECS: list[ReaderSpec] = [  # netCDF before Exodus: a netCDF file known by content alone opens as netCDF
    _spec("netcdf-cf", "netCDF (CF conventions)", ("*.nc", "*.nc4", "*.cdf", "*.netcdf"), _R + "read_netcdf_cf",
          sniff=is_netcdf, arrays="every variable on the chosen dimensions (fill values as NaN)",
          options=("dimensions", "spherical", "time_index", "allow_nonfinite")),
    _spec("exodus", "Exodus II", ("*.e", "*.ex2", "*.exo", "*.exii", "*.g", "*.gen"), _R + "read_exodus",
          sniff=is_netcdf,
          arrays="every nodal variable (point data) and element variable (cell data), ObjectId",
          options=_BLOCKS),
    _spec("openfoam", "OpenFOAM case", ("*.foam",), _R + "read_openfoam", folder_markers=("system/controlDict",),
          arrays="every cell field, also interpolated to the points", options=_BLOCKS),
    _spec("cgns", "CGNS", ("*.cgns", "*.adf", "*.hdf5cgns"), _R + "read_cgns", sniff=is_cgns,
          arrays="every point and cell (FlowSolution) array", options=_BLOCKS),
    _spec("ensight", "EnSight", ("*.case",), _R + "read_ensight", sniff=is_ensight_case,
          arrays="every point and cell variable", options=_BLOCKS),
    _spec("tecplot", "Tecplot ASCII", ("*.dat", "*.plt", "*.tec"), _R + "read_tecplot", sniff=is_tecplot,
          claims_name=False, arrays="every variable of every zone", options=("blocks", "allow_nonfinite")),
    _spec("avs-ucd", "AVS UCD", ("*.inp", "*.ucd"), _R + "read_avs_ucd", sniff=is_avs_ucd, claims_name=False,
          arrays="every node and cell component", options=("allow_nonfinite",)),
    _spec("fluent", "Fluent case", ("*.cas", "*.dat"), _R + "read_fluent", sniff=is_fluent, claims_name=False,
          arrays="every cell field of the case's .dat file", options=("blocks", "allow_nonfinite")),
    _spec("fluent-cff", "Fluent CFF case (HDF5)", ("*.cas.h5", "*.dat.h5"),
          "volviz_vtk_readers.fluentcff:read_fluent_cff", sniff=is_hdf5,
          arrays="every cell field (SV_*) of the case's .dat.h5", options=("blocks", "allow_nonfinite")),
    _spec("vtk-multiblock", "VTK multiblock", ("*.vtm", "*.vtmb", "*.vtpd"), _R + "read_vtk_multiblock",
          sniff=is_vtk_multiblock, sniff_opens=False, arrays="every point and cell array of every block",
          options=("blocks", "allow_nonfinite")),
    _spec("xdmf", "XDMF", ("*.xdmf", "*.xmf"), _R + "read_xdmf", sniff=is_xdmf,
          arrays="every attribute of the temporal collections (or of every grid); fields on one mesh together",
          options=_BLOCKS),
    _spec("vtk-parallel", "VTK parallel XML", ("*.pvtu", "*.pvti", "*.pvts", "*.pvtr", "*.pvtp"),
          _R + "read_vtk_parallel", sniff=is_vtk_parallel, sniff_opens=False,
          arrays="every point and cell array, pieces joined", options=("allow_nonfinite",)),
]
