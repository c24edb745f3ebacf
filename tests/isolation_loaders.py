"""Readers for the crash-isolation tests, registered as isolated specs (``register``); the reader child imports this
module through the tests' sys.path, which it is given with each request.

``crash_vti`` builds a real crash file: a VTK XML image whose piece ``Extent`` has its x bounds swapped, which makes
VTK 9.7's vtkXMLImageDataReader write through a wild pointer (SIGSEGV). ``read_vtk_xml_unchecked`` hands a file to
VTK's XML readers without volviz's header checks, so the crash stays VTK's own however thorough those checks become.
"""
from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np

from volviz.io import registry
from volviz.io.registry import ReaderSpec
from volviz.model import RegularVolume, TimeSeries

_UNCHECKED = {".uvti": "vtkXMLImageDataReader", ".uvtu": "vtkXMLUnstructuredGridReader"}


def _write_xml(path: Path, data, writer: str) -> bytes:
    import vtk

    w = getattr(vtk, writer)()
    w.SetInputData(data)
    w.SetFileName(str(path))
    w.SetDataModeToBinary()
    w.Write()
    return path.read_bytes()


def crash_vti(path: Path, n: int = 8) -> Path:
    """A VTK XML image of n^3 float32 samples whose piece Extent says ``n-1 0`` for x: VTK's reader segfaults."""
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk

    image = vtk.vtkImageData()
    image.SetDimensions(n, n, n)
    values = numpy_to_vtk(np.arange(n ** 3, dtype=np.float32), deep=True)
    values.SetName("s")
    image.GetPointData().SetScalars(values)
    text = _write_xml(path, image, "vtkXMLImageDataWriter")
    good = f'<Piece Extent="0 {n - 1} '.encode()
    assert good in text
    path.write_bytes(text.replace(good, f'<Piece Extent="{n - 1} 0 '.encode()))
    return path


def huge_vtu(path: Path) -> Path:
    """A small VTK XML mesh whose piece claims 2^31-1 points: VTK's reader throws std::bad_alloc (abort)."""
    import pyvista as pv

    mesh = pv.ImageData(dimensions=(3, 3, 3)).cast_to_unstructured_grid()
    text = _write_xml(path, mesh, "vtkXMLUnstructuredGridWriter")
    claim = f'NumberOfPoints="{mesh.n_points}"'.encode()
    assert claim in text
    path.write_bytes(text.replace(claim, b'NumberOfPoints="2147483647"'))
    return path


def read_vtk_xml_unchecked(path: str):
    import vtk

    from volviz.io.vtkconvert import vtk_to_model

    reader = getattr(vtk, _UNCHECKED[Path(path).suffix.lower()])()
    reader.SetFileName(path)
    reader.Update()
    return vtk_to_model(path, reader.GetOutputDataObject(0), True)


def read_forever(path: str):
    """A reader that never finishes (the way VTK's legacy reader spins on a FIELD count of 999999)."""
    while True:
        time.sleep(1)


def read_greedy(path: str):
    """A reader that allocates (and touches) 64 MB after 64 MB, 3 GB in all, as a lying size would make it."""
    kept = [np.ones(8 << 20) for _ in range(48)]
    return RegularVolume(np.zeros((2, 2, 2)), source=str(len(kept)))


def read_not_a_dataset(path: str):
    """A third-party-like reader that returns its own object instead of a volviz dataset."""
    return {"points": np.zeros((4, 3)), "note": "not a dataset"}


def _frame_or_crash(index: int) -> RegularVolume:
    if index == 2:
        os.kill(os.getpid(), 11)  # SIGSEGV, as a reader crashing on one damaged time step
    return RegularVolume(np.full((2, 3, 4), float(index), dtype=np.float32), name="step")


def read_series_crashing_at_step_2(path: str):
    """A transient file of 4 steps read lazily, whose step 2 crashes the reader."""
    return TimeSeries(np.arange(4.0), [_frame_or_crash(0), None, None, None], loader=_frame_or_crash, source=path)


SPECS = [
    ReaderSpec("unchecked-vtk-xml", "VTK XML", ("*.uvti", "*.uvtu"),
               "isolation_loaders:read_vtk_xml_unchecked", isolated=True),
    ReaderSpec("forever", "A reader that hangs", ("*.forever",), "isolation_loaders:read_forever", isolated=True),
    ReaderSpec("greedy", "A reader that eats memory", ("*.greedy",), "isolation_loaders:read_greedy", isolated=True),
    ReaderSpec("foreign", "A reader returning its own objects", ("*.foreign",), "isolation_loaders:read_not_a_dataset",
               isolated=True),
    ReaderSpec("crashing-series", "A series crashing at step 2", ("*.cseries",),
               "isolation_loaders:read_series_crashing_at_step_2", isolated=True),
]


def register(monkeypatch) -> None:
    """Put SPECS in front of the registry for one test (monkeypatch restores it)."""
    monkeypatch.setattr(registry, "_registry", SPECS + registry.reader_specs())
