"""Bookkeeping arrays (ids, ghost levels, masks: ``volviz.model.arrays.is_bookkeeping_array``) are never the default
array while a physical field exists, whatever their order or association; a surface mesh with nothing else shows no
array (drawn plain). Checked on made meshes and on files written by VTK's own filters and read back."""
from __future__ import annotations

import numpy as np
import pyvista as pv

import volviz.io as vio
from conftest import data_file
from volviz.model import RegularVolume, UnstructuredMesh, VTK_HEXAHEDRON
from volviz.model.arrays import default_array, is_bookkeeping_array

VTK_TRIANGLE = 5


def _hexes(point_data, cell_data) -> UnstructuredMesh:
    pts = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1, 2)], float)
    hexes = np.array([[0, 1, 4, 3, 6, 7, 10, 9], [1, 2, 5, 4, 7, 8, 11, 10]])
    return UnstructuredMesh(pts, [(VTK_HEXAHEDRON, hexes)], point_data, cell_data)


def test_the_names_vtk_and_exodus_give_their_bookkeeping():
    for name in ("vtkOriginalCellIds", "vtkOriginalPointIds", "ObjectId", "GlobalNodeId", "GlobalElementId",
                 "PedigreeElementId", "PedigreeNodeId", "vtkGhostType", "ElementBlockIds", "vtkCompositeIndex",
                 "Global Ids", "vtk_ghost_type", "BlockId"):
        assert is_bookkeeping_array(name), name
    for name in ("Temp", "p", "U", "SV_T", "ObjectIdentity", "density", "Ids_of_nothing", "ghost"):
        assert not is_bookkeeping_array(name), name


def test_a_physical_field_is_the_default_over_ids_first_in_line():
    ids = np.arange(12, dtype=np.int64)
    mesh = _hexes({"GlobalNodeId": ids, "vtkOriginalPointIds": ids, "vtkGhostType": np.arange(12) % 2},
                  {"ObjectId": np.array([1, 2]), "pressure": np.array([0.5, 2.5])})
    mesh.active = "GlobalNodeId"
    assert default_array(mesh) == "pressure"
    volume = RegularVolume(np.arange(24, dtype=np.float32).reshape(4, 3, 2), name="vtkGhostType",
                           arrays={"vtkGhostType": np.arange(24, dtype=np.uint8).reshape(4, 3, 2),
                                   "density": np.linspace(0, 1, 24).reshape(4, 3, 2)})
    assert default_array(volume) == "density"


def test_a_mesh_with_only_ids_is_drawn_plain():
    tri = UnstructuredMesh(np.eye(3), [(VTK_TRIANGLE, np.array([[0, 1, 2]]))], {"GlobalNodeId": np.arange(3)},
                           {"ObjectId": np.array([7]), "Normals": np.eye(3)[:1]})
    assert default_array(tri) is None
    solid = _hexes({}, {"ObjectId": np.array([1, 2])})  # drawn as plain geometry (volviz.model.representation)
    assert default_array(solid) is None


def test_files_from_vtk_filters_open_on_their_field(tmp_path):
    wavelet = pv.Wavelet(extent=(0, 5, 0, 4, 0, 3))
    cut = wavelet.extract_cells(np.arange(0, wavelet.n_cells, 2))      # adds vtkOriginalPointIds / CellIds
    grid = pv.UnstructuredGrid()
    grid.copy_structure(cut)
    grid.point_data["vtkOriginalPointIds"] = cut.point_data["vtkOriginalPointIds"]
    grid.cell_data["vtkOriginalCellIds"] = cut.cell_data["vtkOriginalCellIds"]
    grid.cell_data["temperature"] = np.linspace(280.0, 300.0, grid.n_cells)
    grid.save(tmp_path / "cut.vtu")
    mesh = vio.read(tmp_path / "cut.vtu")
    assert set(mesh.point_data) == {"vtkOriginalPointIds"} and default_array(mesh) == "temperature"
    surface = cut.extract_surface(algorithm="dataset_surface")
    surface.clear_data()
    surface.point_data["vtkOriginalPointIds"] = np.arange(surface.n_points)
    surface.cell_data["vtkOriginalCellIds"] = np.arange(surface.n_cells)
    surface.save(tmp_path / "skin.vtp")
    assert default_array(vio.read(tmp_path / "skin.vtp")) is None
    exodus = vio.read(data_file("ecosystem/disk_out_ref.ex2"))
    assert "ObjectId" in exodus.cell_data and default_array(exodus) == "Temp"
