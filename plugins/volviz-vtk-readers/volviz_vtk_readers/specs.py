"""The reader specs this plugin registers (entry point ``volviz.readers``), with their content sniffers.

Importing this module imports neither VTK nor the loaders: volviz reads it to know the formats, and imports
``volviz_vtk_readers.readers`` only when a file of one of them is opened.
"""
from __future__ import annotations

import re
from typing import Any

from volviz.io._checks import is_hdf5
from volviz.io.registry import ReaderSpec

from volviz_vtk_readers.avscheck import NODES_PER_CELL
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
    """AVS UCD: binary files start with byte 7; ASCII ones with a line of counts after their # comments
    (``nodes cells node_values cell_values model_values``; two to four in a header line cut short, which the AVS UCD
    check then refuses by name: issue #32, it went to meshio's Abaqus reader, the other reader of ``.inp``) followed
    by the lines those counts make (``avs_body_fits``). A single number is not taken: other formats start so (an SLC
    file's magic number, a PLOT3D block count). Nor is a header-less point table whose first row is 2-5 whole
    numbers: its rows are not the ``id x y z`` node lines the counts ask for (issue #32)."""
    if head[:1] == b"\x07":
        return True
    lines = _first_lines(head)
    if not lines or re.fullmatch(rb"(\d+\s+){1,4}\d+", lines[0]) is None:
        return False
    complete = lines if head.rstrip(b" \t").endswith((b"\n", b"\r")) else lines[:-1]  # the last may be cut
    return avs_body_fits([int(t) for t in lines[0].split()], [ln.split() for ln in complete[1:AVS_SNIFF_LINES + 1]])


AVS_SNIFF_LINES = 32   # lines after the header line the AVS UCD sniffer holds against the header's counts


def _number(token: bytes) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _whole(tokens: list[bytes]) -> bool:
    return bool(tokens) and all(t.isdigit() for t in tokens)


def _avs_line_fits(kind: str, tokens: list[bytes]) -> bool:
    """Whether a line's tokens are an AVS UCD node line (``id x y z``), cell line (``id material type nodes...``,
    the type one of AVS's) or the first line of a data section (``components size1 ...``, whole numbers)."""
    if kind == "node":
        return len(tokens) == 4 and tokens[0].isdigit() and all(_number(t) for t in tokens[1:])
    if kind == "cell":
        return (len(tokens) >= 4 and _whole(tokens[:2]) and tokens[2].decode("latin-1").lower() in NODES_PER_CELL
                and _whole(tokens[3:]))
    return len(tokens) >= 2 and _whole(tokens)


def avs_body_fits(counts: list[int], body: list[list[bytes]]) -> bool:
    """Whether the lines after an AVS UCD header line are the ones its counts make: ``counts[0]`` node lines, then
    ``counts[1]`` cell lines, then a data section's first line when the header counts values; at least three of
    four of them, so a damaged line or count leaves the file AVS UCD for its check to name (issue #32), or any
    line a cell line (a node or cell count damaged, the cells further on). A header with nothing after it (cut) is
    taken. A header-less point table whose first row is whole numbers fails: its rows are 3 or more numbers, the
    first one rarely whole, and hold no cell type."""
    if not body:
        return True
    nodes, cells = counts[0], counts[1] if len(counts) > 1 else 0
    kinds = ["node"] * min(nodes, len(body)) + ["cell"] * min(cells, len(body))
    kinds += ["data"] if len(counts) == 5 and (counts[2] or counts[3]) else []
    checked = list(zip(kinds, body))
    fits = sum(_avs_line_fits(kind, tokens) for kind, tokens in checked)
    if checked and 4 * fits >= 3 * len(checked):
        return True
    return any(_avs_line_fits("cell", tokens) for tokens in body)


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
