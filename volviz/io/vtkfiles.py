"""VTK legacy (.vtk) and XML (.vti .vtu .vts .vtr .vtp) files through VTK's own readers.

Before VTK sees a file we check its magic and, for legacy files, that no count in the header (POINTS, CELLS,
POINT_DATA, DIMENSIONS, ...) exceeds what the file could hold, so a lying header cannot make VTK allocate a huge
array. VTK's error events are turned into ReadError.
"""
from __future__ import annotations

import re

from volviz.io._checks import file_size, read_bytes
from volviz.io.errors import PathLike, ReadError, human_bytes
from volviz.io.vtkconvert import vtk_to_model

XML_READERS = {
    ".vti": ("ImageData", "vtkXMLImageDataReader"),
    ".vtu": ("UnstructuredGrid", "vtkXMLUnstructuredGridReader"),
    ".vts": ("StructuredGrid", "vtkXMLStructuredGridReader"),
    ".vtr": ("RectilinearGrid", "vtkXMLRectilinearGridReader"),
    ".vtp": ("PolyData", "vtkXMLPolyDataReader"),
}
_LEGACY_COUNTS = re.compile(rb"^(POINTS|CELLS|POINT_DATA|CELL_DATA|POLYGONS|VERTICES|LINES|TRIANGLE_STRIPS|"
                            rb"CELL_TYPES|OFFSETS|CONNECTIVITY)[ \t]+([0-9]+)", re.M)
_LEGACY_DIMS = re.compile(rb"^DIMENSIONS[ \t]+([0-9]+)[ \t]+([0-9]+)[ \t]+([0-9]+)", re.M)
_XML_EXTENT = re.compile(rb'WholeExtent="\s*(-?\d+)\s+(-?\d+)\s+(-?\d+)\s+(-?\d+)\s+(-?\d+)\s+(-?\d+)\s*"')
_XML_NPOINTS = re.compile(rb'Number(?:OfPoints|OfCells)="\s*(\d+)\s*"')
_ZLIB_RATIO = 1100  # deflate cannot expand data by more than ~1032:1


def _run(path: PathLike, reader) -> object:
    """Update a VTK reader with its messages captured (kept off the console); ReadError on any error."""
    import vtk

    previous = vtk.vtkOutputWindow.GetInstance()
    capture = vtk.vtkStringOutputWindow()
    vtk.vtkOutputWindow.SetInstance(capture)
    verbosity = vtk.vtkLogger.GetCurrentVerbosityCutoff()  # the stderr sink is the only one by default
    vtk.vtkLogger.SetStderrVerbosity(vtk.vtkLogger.VERBOSITY_OFF)
    try:
        reader.Update()
    finally:
        vtk.vtkLogger.SetStderrVerbosity(verbosity)
        vtk.vtkOutputWindow.SetInstance(previous)
    text = capture.GetOutput().strip()
    if reader.GetErrorCode() or "ERROR:" in text:
        lines = [ln.split("): ", 1)[-1].strip() for ln in text.splitlines()
                 if ln.strip() and not ln.startswith("ERROR:")]
        detail = "; ".join(lines[:2]) if lines else f"VTK error code {reader.GetErrorCode()}"
        raise ReadError(path, f"VTK's {reader.GetClassName()} failed: {detail[:300]}")
    return reader.GetOutputDataObject(0)


def check_legacy_header(path: PathLike, head: bytes, size: int) -> None:
    """Magic and count sanity of a legacy .vtk file (before VTK allocates anything)."""
    if not head.startswith(b"# vtk DataFile Version"):
        raise ReadError(path, f"not a VTK legacy file: starts with {head[:24]!r}, expected '# vtk DataFile Version'")
    lines = head.split(b"\n", 12)[2:]
    fmt = next((line.strip() for line in lines if line.strip()), b"")
    if fmt.upper() not in (b"ASCII", b"BINARY"):
        raise ReadError(path, f"VTK legacy format line is {fmt[:20]!r}, expected ASCII or BINARY")
    for m in _LEGACY_COUNTS.finditer(head):
        count = int(m.group(2))
        if count > size:
            raise ReadError(path, f"VTK legacy header claims {m.group(1).decode()} {count}, more values than the "
                                  f"file's {size} bytes ({human_bytes(size)}) can hold")
    for m in _LEGACY_DIMS.finditer(head):
        dims = [int(g) for g in m.groups()]
        if min(dims) <= 0:
            raise ReadError(path, f"VTK legacy DIMENSIONS {dims} must be positive")
        if dims[0] * dims[1] * dims[2] > size:
            raise ReadError(path, f"VTK legacy DIMENSIONS {dims} claim {dims[0] * dims[1] * dims[2]} points, more "
                                  f"than the file's {size} bytes can hold")


def check_xml_header(path: PathLike, head: bytes, size: int, expected_type: str) -> None:
    """Magic, data set type and extent sanity of a VTK XML file."""
    text = head.lstrip()
    if not (text.startswith(b"<?xml") or text.startswith(b"<VTKFile")):
        raise ReadError(path, f"not a VTK XML file: starts with {head[:16]!r}")
    m = re.search(rb'<VTKFile[^>]*type="([A-Za-z]+)"', head)
    if m is None:
        raise ReadError(path, "no <VTKFile type=...> element in the first 64 KB")
    if m.group(1).decode() != expected_type:
        raise ReadError(path, f"VTK XML file holds {m.group(1).decode()}, but its extension expects {expected_type}")
    budget = size * (_ZLIB_RATIO if b"compressor=" in head else 1)
    for m in _XML_EXTENT.finditer(head):
        e = [int(g) for g in m.groups()]
        dims = [e[1] - e[0] + 1, e[3] - e[2] + 1, e[5] - e[4] + 1]
        if min(dims) <= 0:
            raise ReadError(path, f"VTK XML WholeExtent {e} gives non-positive dimensions {dims}")
        if dims[0] * dims[1] * dims[2] > budget:
            raise ReadError(path, f"VTK XML WholeExtent {e} claims {dims[0] * dims[1] * dims[2]} points, more "
                                  f"than the file's {size} bytes can hold")
    for m in _XML_NPOINTS.finditer(head):
        if int(m.group(1)) > budget:
            raise ReadError(path, f"VTK XML piece claims {int(m.group(1))} points/cells, more than the file's "
                                  f"{size} bytes can hold")


def read_vtk_file(path: PathLike, allow_nonfinite: bool = True):
    """Read .vtk/.vti/.vtu/.vts/.vtr/.vtp with VTK's reader and convert to the matching model type."""
    import vtk
    from pathlib import Path

    size = file_size(path)
    head = read_bytes(path, 65536)
    ext = Path(path).suffix.lower()
    if ext == ".vtk":
        check_legacy_header(path, head, size)
        reader = vtk.vtkDataSetReader()
        reader.ReadAllScalarsOn()
        reader.ReadAllVectorsOn()
        reader.ReadAllFieldsOn()
    elif ext in XML_READERS:
        expected, cls = XML_READERS[ext]
        check_xml_header(path, head, size, expected)
        reader = getattr(vtk, cls)()
    else:
        raise ReadError(path, f"extension {ext!r} is not a VTK format ({', '.join(['.vtk', *XML_READERS])})")
    reader.SetFileName(str(path))
    return vtk_to_model(path, _run(path, reader), allow_nonfinite)
