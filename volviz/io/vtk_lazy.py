"""VTK for volviz's readers, each VTK module imported when a class of it is first asked for.

``import vtk`` loads every VTK module, most of the cold start of a reader child (``volviz.io.isolated``), which a fresh
``volviz render FILE`` waits for before it reads (issue #30: time to the first image, ``docs/first-open.md``; its cost:
docs/bench/docstring-figures.md). The readers use ``from volviz.io.vtk_lazy import vtk`` as they used the ``vtk``
module: a name of ``MODULE_OF`` (the classes volviz's readers and the reader plugins use) or a ``VTK_*`` constant
imports only its own module, any other name the whole of VTK, so every name VTK has is still there.
"""
from __future__ import annotations

import importlib
from typing import Any

#: the VTK module (under ``vtkmodules``) of each class the readers use
MODULE_OF: dict[str, str] = {
    **dict.fromkeys(("vtkOutputWindow", "vtkStringOutputWindow", "vtkLogger", "vtkIdTypeArray", "vtkPoints",
                     "vtkDoubleArray", "vtkFloatArray", "vtkInformation"), "vtkCommonCore"),
    **dict.fromkeys(("vtkCompositeDataSet", "vtkDataSet", "vtkImageData", "vtkMultiBlockDataSet",
                     "vtkPartitionedDataSet", "vtkPartitionedDataSetCollection", "vtkPointSet", "vtkRectilinearGrid",
                     "vtkStructuredGrid", "vtkUnstructuredGrid", "vtkPolyData", "vtkCellArray",
                     "vtkCompositeDataIterator", "vtkDataObject"), "vtkCommonDataModel"),
    "vtkStreamingDemandDrivenPipeline": "vtkCommonExecutionModel",
    "vtkCellDataToPointData": "vtkFiltersCore", "vtkAppendFilter": "vtkFiltersCore",
    **dict.fromkeys(("vtkLZ4DataCompressor", "vtkLZMADataCompressor", "vtkZLibDataCompressor"), "vtkIOCore"),
    "vtkDataSetReader": "vtkIOLegacy",
    **dict.fromkeys(("vtkXMLImageDataReader", "vtkXMLMultiBlockDataReader", "vtkXMLPImageDataReader",
                     "vtkXMLPPolyDataReader", "vtkXMLPRectilinearGridReader", "vtkXMLPStructuredGridReader",
                     "vtkXMLPUnstructuredGridReader", "vtkXMLPartitionedDataSetCollectionReader",
                     "vtkXMLPartitionedDataSetReader", "vtkXMLPolyDataReader", "vtkXMLRectilinearGridReader",
                     "vtkXMLStructuredGridReader", "vtkXMLUnstructuredGridReader", "vtkXMLGenericDataObjectReader"),
                    "vtkIOXML"),
    "vtkExodusIIReader": "vtkIOExodus",
    "vtkHDFReader": "vtkIOHDF",
    "vtkJPEGReader": "vtkIOImage",
    **dict.fromkeys(("vtkAVSucdReader", "vtkFLUENTReader", "vtkOpenFOAMReader", "vtkTecplotReader"), "vtkIOGeometry"),
    "vtkNetCDFCFReader": "vtkIONetCDF",
    "vtkCGNSReader": "vtkIOCGNSReader",
    "vtkXdmfReader": "vtkIOXdmf2",
    "vtkFLUENTCFFReader": "vtkIOFLUENTCFF",
    "vtkGenericEnSightReader": "vtkIOEnSight",
    "vtkMultiBlockPLOT3DReader": "vtkIOParallel",
}


class LazyVTK:
    """Stands for the ``vtk`` module: attributes resolve (and are kept) on first use (see the module docstring)."""

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        module = MODULE_OF.get(name) or ("vtkCommonCore" if name.startswith("VTK_") else None)
        found = getattr(importlib.import_module(f"vtkmodules.{module}"), name, None) if module else None
        if found is None:
            # heavy: all of VTK (1.2-2 s), only for a name outside MODULE_OF
            import vtk as everything

            found = getattr(everything, name)
        setattr(self, name, found)
        return found


vtk: Any = LazyVTK()
