"""ParaView data collections (``.pvd``) through ``volviz.io.read`` (``volviz.io.pvd``): time steps with the file's
times, parts of a step merged, meshes that change size from step to step, and collections that are damaged or list
files that are not there."""
from __future__ import annotations

import math

import numpy as np
import pytest
import pyvista as pv
from conftest import read_every_frame, xml_mutations

import volviz.io as vio
from volviz.io.errors import ReadError
from volviz.model import TimeSeries
from volviz.model.timeseries import frame_at


def _collection(entries: list[tuple[float, int, str]]) -> str:
    rows = "".join(f'    <DataSet timestep="{t}" group="" part="{p}" file="{f}"/>\n' for t, p, f in entries)
    return (f'<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
            f"  <Collection>\n{rows}  </Collection>\n</VTKFile>\n")


def _tets(n: int, origin=(0.0, 0.0, 0.0)) -> pv.UnstructuredGrid:
    grid = pv.ImageData(dimensions=(n, n, n), spacing=(1.0 / (n - 1),) * 3, origin=origin)
    return grid.cast_to_unstructured_grid().triangulate()


def _series(tmp_path, sizes=(4, 4, 4), times=(0.0, 0.25, 1.5)):
    for i, n in enumerate(sizes):
        mesh = _tets(n)
        mesh.point_data["u"] = mesh.points[:, 0] + 10.0 * i
        mesh.save(tmp_path / f"out_{i:04d}.vtu")
    path = tmp_path / "run.pvd"
    path.write_text(_collection([(t, 0, f"out_{i:04d}.vtu") for i, t in enumerate(times)]))
    return path


def test_a_collection_is_a_time_series_at_its_own_times_with_the_members_data(tmp_path):
    series = vio.read(_series(tmp_path))
    assert isinstance(series, TimeSeries) and len(series) == 3
    np.testing.assert_array_equal(series.times, [0.0, 0.25, 1.5])
    for i in range(3):
        member = vio.read(tmp_path / f"out_{i:04d}.vtu")
        np.testing.assert_array_equal(series.frame(i).point_data["u"], member.point_data["u"])
        np.testing.assert_array_equal(series.frame(i).points, member.points)
    assert series.frame(2).point_data["u"].min() == 20.0
    one = vio.read(tmp_path / "run.pvd", time_index=1)
    np.testing.assert_array_equal(one.point_data["u"], series.frame(1).point_data["u"])
    with pytest.raises(ReadError, match=r"run.pvd: time_index 3 is out of range: the collection has 3 time step"):
        vio.read(tmp_path / "run.pvd", time_index=3)


def test_entries_listed_out_of_order_and_a_single_step(tmp_path):
    _series(tmp_path)
    path = tmp_path / "shuffled.pvd"
    path.write_text(_collection([(1.5, 0, "out_0002.vtu"), (0.0, 0, "out_0000.vtu"), (0.25, 0, "out_0001.vtu")]))
    series = vio.read(path)
    np.testing.assert_array_equal(series.times, [0.0, 0.25, 1.5])
    assert series.frame(2).point_data["u"].min() == 20.0
    (tmp_path / "one.pvd").write_text(_collection([(3.0, 0, "out_0001.vtu")]))
    single = vio.read(tmp_path / "one.pvd")
    assert not isinstance(single, TimeSeries) and single.point_data["u"].min() == 10.0


def test_the_parts_of_a_step_are_merged(tmp_path):
    entries = []
    for step in range(2):
        for part in range(3):
            mesh = _tets(3, origin=(part, 0.0, 0.0))
            mesh.point_data["u"] = mesh.points[:, 0] + 100.0 * step
            mesh.save(tmp_path / f"p{step}_{part}.vtu")
            entries.append((0.1 * step, 2 - part, f"p{step}_{part}.vtu"))   # parts listed in reverse
    (tmp_path / "parallel.pvd").write_text(_collection(entries))
    series = vio.read(tmp_path / "parallel.pvd")
    one = _tets(3)
    for step in range(2):
        frame = series.frame(step)
        assert frame.n_points == 3 * one.n_points and frame.n_cells == 3 * one.n_cells
        np.testing.assert_allclose(frame.points[:, 0].max(), 3.0)
        np.testing.assert_allclose(frame.point_data["u"], frame.points[:, 0] + 100.0 * step)


def test_a_mesh_refined_between_steps_shows_each_step_as_read(tmp_path):
    series = vio.read(_series(tmp_path, sizes=(3, 5, 9), times=(0.0, 1.0, 2.0)))
    assert [series.frame(i).n_points for i in range(3)] == [27, 125, 729]
    between = frame_at(series, 0.5)              # no blend of different meshes: the earlier step
    assert between is series.frame(0)
    same = vio.read(_series(tmp_path / "..", sizes=(4, 4, 4), times=(0.0, 1.0, 2.0)))
    np.testing.assert_allclose(frame_at(same, 0.5).point_data["u"],
                               same.frame(0).point_data["u"] + 5.0, rtol=1e-6)   # one mesh: blended


@pytest.mark.parametrize("text, problem", [
    ("", "is not a ParaView data collection .*empty"),
    ('<VTKFile type="Collection"><Collection></Collection></VTKFile>', "lists no data set"),
    ('<VTKFile type="Collection"><Collection><DataSet timestep="0" file="out_0000.vtu"/>', "its XML does not parse"),
    (_collection([(0.0, 0, "out_0000.vtu"), (1.0, 0, "gone.vtu")]),
     r"DataSet 2 \(time 1.0\): its file gone.vtu is missing"),
    (_collection([(0.0, 0, "out_0000.vtu")]).replace('timestep="0.0"', 'timestep="nan"'),
     "DataSet 1: its timestep is not finite"),
    (_collection([(0.0, 0, "out_0000.vtu")]).replace('timestep="0.0"', 'timestep="soon"'),
     "DataSet 1: its timestep is text, not a number"),
    (_collection([(0.0, 0, "run.pvd")]), "DataSet 1 is itself a collection"),
    (_collection([(0.0, 0, "")]), "DataSet 1 names no file"),
    ('<?xml version="1.0"?><!DOCTYPE l [<!ENTITY a "aaaaaaaaaa">'
     + "".join(f'<!ENTITY {chr(98 + i)} "{("&" + chr(97 + i) + ";") * 10}">' for i in range(8))
     + ']><VTKFile type="Collection"><Collection><DataSet file="&i;"/></Collection></VTKFile>',
     "its XML does not parse .*amplification"),
])
def test_damaged_collections_are_refused_naming_the_file(tmp_path, text, problem):
    _series(tmp_path)
    path = tmp_path / "bad.pvd"
    path.write_text(text)
    with pytest.raises(ReadError, match=f"bad.pvd: {problem}"):
        vio.read(path)


def test_a_damaged_member_is_refused_naming_the_member(tmp_path):
    path = _series(tmp_path)
    member = tmp_path / "out_0001.vtu"
    member.write_bytes(member.read_bytes()[:300])
    series = vio.read(path)                       # step 0 is fine; step 1 fails when it is shown
    with pytest.raises(ReadError, match="out_0001.vtu"):
        series.frame(1)


def test_mutated_collections_are_read_consistently_or_refused(tmp_path):
    """Bit flips, truncations and XML attribute mutations of a collection: each is read with finite, increasing
    times and frames made of its members, or refused with a ReadError naming a file; nothing else escapes."""
    path = _series(tmp_path)
    mutations = xml_mutations(path.read_bytes(), "pvd", flips=24, cuts=12, per_kind=8)
    refused, read = read_every_frame(path, mutations, (".pvd", ".vtu"))
    for mutation, found, frames in read:
        if isinstance(found, TimeSeries):
            assert all(math.isfinite(t) for t in found.times) and np.all(np.diff(found.times) > 0)
        assert all(f.n_points % 64 == 0 and np.isfinite(f.point_data["u"]).all() for f in frames), mutation.detail
    assert refused >= len(mutations) // 3
