"""XDMF files through ``volviz.io.read`` (``volviz_vtk_readers.xdmf``, VTK's vtkXdmfReader): meshio's single meshes
and time series, dolfinx's layout (the mesh once, each function a temporal collection including it), regular
volumes (3DCoRectMesh), ``blocks=``, and files whose heavy data is missing, short or damaged."""
from __future__ import annotations

import h5py
import meshio
import numpy as np
import pytest
import pyvista as pv
from conftest import read_every_frame, xml_mutations

import volviz.io as vio
from volviz.io.errors import ReadError
from volviz.model import RegularVolume, TimeSeries

GRID = pv.ImageData(dimensions=(5, 4, 3), spacing=(0.5, 1.0, 2.0)).cast_to_unstructured_grid().triangulate()
POINTS = np.asarray(GRID.points, dtype=np.float64)
TETS = np.asarray(GRID.cells_dict[pv.CellType.TETRA], dtype=np.int64)


def _shown_at(dataset, points: np.ndarray, values: np.ndarray, name: str) -> np.ndarray:
    """The dataset's ``name`` values at ``points``, which must all be among the dataset's points."""
    index = {tuple(p): i for i, p in enumerate(np.asarray(dataset.points))}
    return np.asarray(dataset.point_data[name])[[index[tuple(p)] for p in points]]


def test_a_meshio_mesh_and_time_series(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)                   # meshio writes a time series' HDF5 file in the working folder
    meshio.write(tmp_path / "one.xdmf", meshio.Mesh(POINTS, [("tetra", TETS)], point_data={"T": POINTS[:, 0]}))
    one = vio.read(tmp_path / "one.xdmf")
    assert (one.n_points, one.n_cells) == (len(POINTS), len(TETS))
    np.testing.assert_array_equal(_shown_at(one, POINTS, POINTS[:, 0], "T"), POINTS[:, 0])
    with meshio.xdmf.TimeSeriesWriter(tmp_path / "run.xdmf") as writer:
        writer.write_points_cells(POINTS, [("tetra", TETS)])
        for t in (0.0, 0.5, 2.0):
            writer.write_data(t, point_data={"T": POINTS[:, 0] + 10 * t})
    series = vio.read(tmp_path / "run.xdmf")
    assert isinstance(series, TimeSeries)
    np.testing.assert_array_equal(series.times, [0.0, 0.5, 2.0])
    for i, t in enumerate(series.times):
        frame = series.frame(i)
        assert (frame.n_points, frame.n_cells) == (len(POINTS), len(TETS))     # the bare mesh grid is not added
        np.testing.assert_allclose(_shown_at(frame, POINTS, POINTS[:, 0], "T"), POINTS[:, 0] + 10 * t)


def _dolfinx_like(folder, steps=2):
    """The mesh once (``Grid Name="mesh"``), functions ``u`` and ``p`` as temporal collections including its
    geometry and topology, heavy data in one HDF5 file -- the layout of dolfinx.io.XDMFFile."""
    with h5py.File(folder / "sol.h5", "w") as f:
        f["Mesh/mesh/geometry"] = POINTS
        f["Mesh/mesh/topology"] = TETS
        for t in range(steps):
            f[f"Function/u/{t}"] = POINTS[:, :1] + t
            f[f"Function/p/{t}"] = POINTS[:, 1:2] * (t + 1)
    n, ne = len(POINTS), len(TETS)
    include = ('<xi:include xpointer="xpointer(/Xdmf/Domain/Grid[@GridType=\'Uniform\'][1]/*[self::Topology or '
               'self::Geometry])" />')

    def collection(name):
        grids = "".join(
            f'<Grid Name="{name}" GridType="Uniform">{include}<Time Value="{t}" />'
            f'<Attribute Name="{name}" AttributeType="Scalar" Center="Node"><DataItem Dimensions="{n} 1" '
            f'Format="HDF">sol.h5:/Function/{name}/{t}</DataItem></Attribute></Grid>' for t in range(steps))
        return f'<Grid Name="{name}" GridType="Collection" CollectionType="Temporal">{grids}</Grid>'

    path = folder / "sol.xdmf"
    path.write_text(
        '<?xml version="1.0"?>\n<!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>\n'
        '<Xdmf Version="3.0" xmlns:xi="http://www.w3.org/2001/XInclude"><Domain>\n'
        f'<Grid Name="mesh" GridType="Uniform"><Topology TopologyType="Tetrahedron" NumberOfElements="{ne}" '
        f'NodesPerElement="4"><DataItem Dimensions="{ne} 4" NumberType="Int" Format="HDF">sol.h5:/Mesh/mesh/topology'
        f'</DataItem></Topology><Geometry GeometryType="XYZ"><DataItem Dimensions="{n} 3" Format="HDF">'
        f"sol.h5:/Mesh/mesh/geometry</DataItem></Geometry></Grid>\n{collection('u')}{collection('p')}\n"
        "</Domain></Xdmf>\n")
    return path


def test_dolfinx_functions_are_fields_of_one_mesh_over_time(tmp_path):
    series = vio.read(_dolfinx_like(tmp_path))
    assert isinstance(series, TimeSeries) and list(series.times) == [0.0, 1.0]
    for t in range(2):
        frame = series.frame(t)
        assert (frame.n_points, frame.n_cells) == (len(POINTS), len(TETS))     # one mesh, not three laid over it
        assert set(frame.point_data) == {"u", "p"}
        np.testing.assert_allclose(_shown_at(frame, POINTS, None, "u"), POINTS[:, 0] + t)
        np.testing.assert_allclose(_shown_at(frame, POINTS, None, "p"), POINTS[:, 1] * (t + 1))
    bare = vio.read(tmp_path / "sol.xdmf", blocks=["mesh"], time_index=0)
    assert bare.n_points == len(POINTS) and not bare.point_data
    with pytest.raises(ReadError, match="no block named 'velocity'; the file's blocks are: mesh, u, p"):
        vio.read(tmp_path / "sol.xdmf", blocks=["velocity"])


def test_a_regular_volume(tmp_path):
    rho = np.arange(4 * 5 * 6, dtype=np.float32).reshape(4, 5, 6)            # (z, y, x) as XDMF lists them
    with h5py.File(tmp_path / "vol.h5", "w") as f:
        f["rho"] = rho
    (tmp_path / "vol.xmf").write_text(
        '<?xml version="1.0"?><Xdmf Version="2.0"><Domain><Grid Name="box" GridType="Uniform">'
        '<Topology TopologyType="3DCoRectMesh" Dimensions="4 5 6"/><Geometry GeometryType="ORIGIN_DXDYDZ">'
        '<DataItem Dimensions="3" Format="XML">3 2 1</DataItem><DataItem Dimensions="3" Format="XML">0.5 0.25 0.1'
        '</DataItem></Geometry><Attribute Name="rho" Center="Node"><DataItem Dimensions="4 5 6" NumberType="Float" '
        'Precision="4" Format="HDF">vol.h5:/rho</DataItem></Attribute></Grid></Domain></Xdmf>')
    volume = vio.read(tmp_path / "vol.xmf")
    assert isinstance(volume, RegularVolume) and volume.dimensions == (6, 5, 4)
    np.testing.assert_allclose(volume.spacing, (0.1, 0.25, 0.5))
    np.testing.assert_allclose(volume.origin, (1.0, 2.0, 3.0))
    np.testing.assert_array_equal(volume.data, np.transpose(rho, (2, 1, 0)))


@pytest.mark.parametrize("edit, problem", [
    (lambda s: s.replace("sol.h5:", "gone.h5:"), r"its heavy data file gone.h5 is missing"),
    (lambda s: s.replace(f'Dimensions="{len(POINTS)} 3"', f'Dimensions="{10 * len(POINTS)} 3"'),
     rf"declares {10 * len(POINTS)} x 3 values in sol.h5:/Mesh/mesh/geometry, which holds {3 * len(POINTS)}"),
    (lambda s: s.replace("/Function/u/1", "/Function/u/7"), "names the dataset /Function/u/7 in sol.h5"),
    (lambda s: s.replace(f'Dimensions="{len(POINTS)} 1"', 'Dimensions="many 1"', 1), "are not whole numbers"),
    (lambda s: s[:len(s) // 2], "its XML does not parse"),
])
def test_damaged_files_are_refused_naming_the_file(tmp_path, edit, problem):
    path = _dolfinx_like(tmp_path)
    path.write_text(edit(path.read_text()))
    with pytest.raises(ReadError, match=f"sol.xdmf: .*{problem}"):
        vio.read(path)


def test_mutated_markup_is_read_or_refused(tmp_path):
    """Attribute and bit mutations of the XML (VTK's reader runs isolated): each gives a ReadError naming a file, or
    data sets with finite points."""
    path = _dolfinx_like(tmp_path)
    refused, read = read_every_frame(path, xml_mutations(path.read_bytes(), "xdmf", flips=8, cuts=4, per_kind=6),
                                     ("sol.xdmf", "sol.h5"))
    assert all(np.isfinite(f.points).all() for mutation, _, frames in read for f in frames)
    assert refused >= 4
