"""A dolfinx function written over time steps (``ecosystem/dolfinx-function``: XDMF 3 + HDF5, a temporal collection
of grids on one tetrahedral mesh) opens as a time series of the function on its mesh, every step as VTK's
vtkXdmfReader reads it and equal to the HDF5 datasets the .xdmf names; its .h5 alone points to the .xdmf."""
from __future__ import annotations

import h5py
import numpy as np
import pytest
from vtk.util.numpy_support import vtk_to_numpy

import volviz.io as vio
from conftest import data_file
from volviz.io.errors import ReadWarning
from volviz.model import TimeSeries
from volviz.model.arrays import default_array


def test_every_time_step_of_the_function_as_vtk_reads_it():
    import vtk

    path = data_file("ecosystem/dolfinx-function/no_checkpoint.xdmf")
    series = vio.read(path)
    assert isinstance(series, TimeSeries)
    np.testing.assert_array_equal(series.times, [0, 1, 2, 3, 4])
    reader = vtk.vtkXdmfReader()
    reader.SetFileName(str(path))
    reader.UpdateInformation()
    with h5py.File(path.with_suffix(".h5"), "r") as heavy:
        for step, t in enumerate(series.times):
            reader.UpdateTimeStep(float(t))
            expected = reader.GetOutputDataObject(0)
            mesh = series.frame(step)
            assert (mesh.n_points, mesh.n_cells) == (729, 3072)
            assert list(mesh.point_data) == ["f_5"] and default_array(mesh) == "f_5"
            values = mesh.point_data["f_5"].ravel()
            np.testing.assert_array_equal(values, vtk_to_numpy(expected.GetPointData().GetArray("f_5")).ravel())
            np.testing.assert_array_equal(values, heavy[f"VisualisationVector/{step}"][:, 0])
            np.testing.assert_array_equal(mesh.points, vtk_to_numpy(expected.GetPoints().GetData()))
            assert (values.min(), values.max()) == (step, step + 1.0)   # the function moves up a unit a step


def test_the_heavy_data_alone_names_its_xdmf():
    heavy = data_file("ecosystem/dolfinx-function/no_checkpoint.h5")
    with pytest.warns(ReadWarning, match=r"no_checkpoint.h5: is the heavy data of no_checkpoint.xdmf beside it"):
        vio.read(heavy)
