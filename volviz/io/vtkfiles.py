"""VTK legacy (.vtk) and XML (.vti .vtu .vts .vtr .vtp) files through VTK's own readers.

Before VTK sees a file, every count in it is checked against the file's size and against the others (legacy files
in ``volviz.io.vtklegacy``, XML files in ``volviz.io.vtkxml``), so a lying header cannot make VTK allocate a huge
array, read past a buffer or loop for ever. VTK's error events are turned into ReadError.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

from volviz.io.errors import PathLike, ReadError
from volviz.io.vtk_lazy import vtk
from volviz.io.vtkconvert import vtk_to_model
from volviz.io.vtklegacy import check_legacy_file
from volviz.io.vtkxml import check_xml_file

XML_READERS = {
    ".vti": ("ImageData", "vtkXMLImageDataReader"),
    ".vtu": ("UnstructuredGrid", "vtkXMLUnstructuredGridReader"),
    ".vts": ("StructuredGrid", "vtkXMLStructuredGridReader"),
    ".vtr": ("RectilinearGrid", "vtkXMLRectilinearGridReader"),
    ".vtp": ("PolyData", "vtkXMLPolyDataReader"),
}


def _run(path: PathLike, reader) -> Any:
    """Update a VTK reader with its messages captured (kept off the console); ReadError on any error."""
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
    text = capture.GetOutput()
    if isinstance(text, bytes):  # a message quoting bytes of the file that are not UTF-8
        text = text.decode("utf-8", "replace")
    text = "".join(c if (c.isprintable() and c.isascii()) or c == "\n" else "?" for c in text.strip())
    if reader.GetErrorCode() or "ERROR:" in text:
        lines = [ln.split("): ", 1)[-1].strip() for ln in text.splitlines()
                 if ln.strip() and not ln.startswith(("ERROR:", "Warning:"))]
        detail = "; ".join(lines[:2]) if lines else f"VTK error code {reader.GetErrorCode()}"
        raise ReadError(path, f"VTK's {reader.GetClassName()} failed: {detail[:300]}")
    return reader.GetOutputDataObject(0)


def read_vtk_file(path: PathLike, allow_nonfinite: bool = True):
    """Read .vtk/.vti/.vtu/.vts/.vtr/.vtp with VTK's reader and convert to the matching model type.

    The file is checked first (VTK is imported only for a file that passed)."""
    ext = Path(path).suffix.lower()
    if ext == ".vtk":
        check_legacy_file(path)
    elif ext in XML_READERS:
        check_xml_file(path, XML_READERS[ext][0])
    else:
        raise ReadError(path, f"extension {ext!r} is not a VTK format ({', '.join(['.vtk', *XML_READERS])})")

    if ext == ".vtk":
        reader = vtk.vtkDataSetReader()
        reader.ReadAllScalarsOn()
        reader.ReadAllVectorsOn()
        reader.ReadAllFieldsOn()
    else:
        reader = getattr(vtk, XML_READERS[ext][1])()
    reader.SetFileName(str(path))
    return vtk_to_model(path, _run(path, reader), allow_nonfinite)
