"""Crash-isolated reading: a reader that segfaults, aborts, hangs or eats memory in its child process gives a ReadError
naming the file and what happened, and this process reads the next file as before; the datasets that come back are
exactly those read in-process; the dataset codec refuses what is not a dataset."""
from __future__ import annotations

import json
import os

import numpy as np
import pytest

import volviz.io as vio
from volviz.io import isolated
from volviz.io.isolated import codec
from volviz.model import CurvilinearGrid, Image2D, RegularVolume, TetMesh, TimeSeries, UnstructuredMesh

import isolation_loaders
from conftest import data_file


@pytest.fixture
def test_readers(monkeypatch):
    isolation_loaders.register(monkeypatch)


def assert_same(a, b) -> None:
    """The same dataset: equal codec headers (kinds, names, scalars, every array's dtype and shape) and arrays equal
    element for element (NaN where NaN)."""
    (ha, arrays_a), (hb, arrays_b) = codec.encode(a), codec.encode(b)
    assert ha == hb
    for x, y in zip(arrays_a, arrays_b):
        assert x.dtype == y.dtype and np.array_equal(x, y, equal_nan=x.dtype.kind in "fc")


def still_reads() -> None:
    vol = vio.read(data_file("volumes/hydrogen.vti"))
    assert isinstance(vol, RegularVolume) and vol.dimensions == (64, 64, 64)


def test_a_file_that_crashes_vtk_gives_a_read_error_and_this_process_goes_on(test_readers, tmp_path) -> None:
    path = isolation_loaders.crash_vti(tmp_path / "damaged.uvti")
    with pytest.raises(vio.ReadError) as info:
        vio.read(path)
    message = str(info.value)
    assert message.startswith(str(path) + ":")
    assert ("the reader crashed (segmentation fault) reading it: the file is damaged or not a valid VTK XML file"
            in message)
    base = isolated._exchange_base(0)
    assert not [n for n in os.listdir(base) if n.startswith(f"{isolated.WORKDIR_PREFIX}{os.getpid()}-")]
    still_reads()


def test_an_abort_for_a_huge_allocation_is_reported_as_out_of_memory(test_readers, tmp_path) -> None:
    path = isolation_loaders.huge_vtu(tmp_path / "lying.uvtu")
    with pytest.raises(vio.ReadError, match=r"lying\.uvtu: the reader ran out of memory reading it \(limit "):
        vio.read(path)
    still_reads()


@pytest.mark.parametrize("variable, value, name, match", [
    ("VOLVIZ_READ_SECONDS", "2", "stuck.forever", r"stuck\.forever: the reader did not finish within the time limit "
                                                  r"of 2 s and was stopped"),
    ("VOLVIZ_READ_MEMORY", "256M", "bomb.greedy", r"bomb\.greedy: the reader needs more memory than the limit of "
                                                  r"268 MB"),
])
def test_a_reader_that_hangs_or_eats_memory_is_stopped_at_its_limit(test_readers, tmp_path, monkeypatch, variable,
                                                                      value, name, match) -> None:
    monkeypatch.setenv(variable, value)
    path = tmp_path / name
    path.write_bytes(b"x")
    with pytest.raises(vio.ReadError, match=match):
        vio.read(path)
    still_reads()


def test_a_reader_returning_something_else_than_a_dataset_is_refused(test_readers, tmp_path) -> None:
    path = tmp_path / "thing.foreign"
    path.write_bytes(b"x")
    with pytest.raises(vio.ReadError, match=r"thing\.foreign: the foreign reader's result is refused: the reader "
                                            r"returned a builtins\.dict, not a volviz dataset"):
        vio.read(path)


def test_lazy_frames_are_read_isolated_too(test_readers, tmp_path) -> None:
    path = tmp_path / "run.cseries"
    path.write_bytes(b"x")
    series = vio.read(path)
    assert isinstance(series, TimeSeries) and len(series) == 4
    assert float(series.frame(1).data[0, 0, 0]) == 1.0
    with pytest.raises(vio.ReadError, match=r"run\.cseries: the reader crashed \(segmentation fault\)"):
        series.frame(2)
    assert float(series.frame(3).data[0, 0, 0]) == 3.0


@pytest.mark.parametrize("relative", ["volumes/hydrogen.vti", "volumes/ironProt.vtk", "ecosystem/disk_out_ref.ex2",
                                      "ecosystem/openfoam-cavity", "series/warping_spheres.vtkhdf"])
def test_isolated_reads_equal_in_process_reads_exactly(relative) -> None:
    path = data_file(relative)
    a, b = vio.read(path), vio.read(path, isolate=False)
    assert type(a) is type(b)
    assert_same(a, b)
    if isinstance(a, TimeSeries):
        assert a.loader is not None and len(a) == len(b) > 1
        for i in range(1, len(a)):
            assert_same(a.frame(i), b.frame(i))


def test_isolation_can_be_turned_off_for_debugging(test_readers, tmp_path, monkeypatch) -> None:
    path = tmp_path / "thing.foreign"
    path.write_bytes(b"x")
    monkeypatch.setenv("VOLVIZ_ISOLATE", "0")
    assert vio.read(path)["note"] == "not a dataset"  # in-process: the loader's own object, unchecked
    monkeypatch.delenv("VOLVIZ_ISOLATE")
    assert vio.read(path, isolate=False)["note"] == "not a dataset"


def test_reader_messages_and_warnings_come_back_from_the_child(tmp_path) -> None:
    with pytest.raises(TypeError, match="the vtk-xml reader does not take option"):
        vio.read(data_file("volumes/hydrogen.vti"), no_such_option=1)
    bad = tmp_path / "x.vtu"
    bad.write_text("this is a text file, not a mesh\n")
    with pytest.raises(vio.ReadError, match=r"^" + str(bad).replace(".", r"\.") + ": "):
        vio.read(bad)
    import pyvista as pv

    grid = pv.ImageData(dimensions=(2, 2, 2))
    grid.point_data["s"] = np.array([0, 1, np.nan, 3, 4, 5, 6, 7], dtype=np.float32)
    grid.save(tmp_path / "nan.vti")
    with pytest.warns(vio.NonFiniteWarning, match="1 non-finite"):
        vio.read(tmp_path / "nan.vti")


def test_a_childs_choices_come_back_only_in_their_form() -> None:
    """A ``ChoiceWarning``'s choices cross from the child as plain data (strings or integers); anything else of that
    name comes back as its message alone (a ReadWarning without choices: nothing for the app's chooser)."""
    import warnings

    from volviz.io.isolated import _reemit

    good = {"path": "/d/scan.h5", "option": "dataset", "chosen": "/a", "choices": ["/a", "/b"],
            "labels": ["/a (2x2x2)", "/b (3x3x3)"]}
    for fields, choices in ((good, ["/a", "/b"]), (dict(good, option="not an identifier"), []),
                            (dict(good, choices=["/a", 3.5]), []), (dict(good, chosen=True), []),
                            ("not a dict", [])):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            _reemit([["ChoiceWarning", "scan.h5: holds 2 arrays", fields]])
        (warning,) = caught
        assert isinstance(warning.message, vio.ChoiceWarning) and str(warning.message) == "scan.h5: holds 2 arrays"
        assert warning.message.choices == choices
        assert warning.message.labels == (["/a (2x2x2)", "/b (3x3x3)"] if choices else [])


# -- the codec ---------------------------------------------------------------------------------------------------------
def _datasets():
    rng = np.random.default_rng(3)
    data = rng.random((3, 4, 5)).astype(np.float32)
    points = rng.random((8, 3))
    yield RegularVolume(data, spacing=(1, 2, 0.5), origin=(-1, 0, 2), name="d", source="s",
                        arrays={"d": data, "other": data.astype(np.int16)})
    yield CurvilinearGrid(rng.random((2, 3, 4, 3)), point_data={"p": rng.random((2, 3, 4))},
                          cell_data={"c": rng.random((1, 2, 3, 2))}, source="grid")
    yield UnstructuredMesh(points, [(10, np.array([[0, 1, 2, 3], [4, 5, 6, 7]])), (5, np.array([[0, 1, 2]]))],
                           point_data={"t": np.arange(8.0)}, cell_data={"id": np.arange(3, dtype=np.int32)})
    yield TetMesh(points, np.array([[0, 1, 2, 3]]), np.arange(8.0), name="f")
    yield Image2D(np.arange(12, dtype=np.uint16).reshape(3, 4), spacing=(30, 30), origin=(5, 6), maxval=65535)
    yield TimeSeries(np.array([0.0, 0.5]), [Image2D(np.zeros((2, 2, 3), np.uint8)), None], loader=lambda i: None)


@pytest.mark.parametrize("dataset", list(_datasets()), ids=lambda d: type(d).__name__)
def test_codec_round_trip_is_exact(dataset) -> None:
    header, arrays = codec.encode(dataset)
    back = codec.decode(json.loads(json.dumps(header)), [a.copy() for a in arrays])
    assert type(back) is type(dataset)
    assert_same(back, dataset if not isinstance(dataset, TimeSeries) else TimeSeries(dataset.times, dataset.frames))
    if isinstance(back, RegularVolume):
        assert back.arrays["d"] is back.data  # one array in the file, one array again


@pytest.mark.parametrize("damage, match", [
    (lambda h, a: h["dataset"].update(kind="Evil"), "unknown dataset kind 'Evil'"),
    (lambda h, a: h["arrays"][0].update(dtype="|O"), "not a plain numeric type"),
    (lambda h, a: h["arrays"][0].update(shape=[3, 4, 6]), r"array 0 is float32 \(3, 4, 5\), the header says"),
    (lambda h, a: h["dataset"].update(data=7), "not the index of one of the 2 arrays"),
    (lambda h, a: h["dataset"].update(spacing="1 1 1"), "not a list of numbers"),
    (lambda h, a: h["dataset"].update(extra=1), "fields"),
    (lambda h, a: a.pop(), "announces 2 arrays, 1 were given"),
])
def test_codec_refuses_a_header_that_does_not_describe_a_dataset(damage, match) -> None:
    header, arrays = codec.encode(next(_datasets()))
    arrays = list(arrays)
    damage(header, arrays)
    with pytest.raises(codec.CodecError, match=match):
        codec.decode(header, arrays)


def test_codec_refuses_objects_and_object_arrays() -> None:
    with pytest.raises(codec.CodecError, match="not a volviz dataset"):
        codec.encode({"data": np.zeros(3)})
    with pytest.raises(codec.CodecError, match="dtype object"):
        codec.encode(RegularVolume(np.zeros((2, 2, 2)), arrays={"o": np.empty((2, 2, 2), dtype=object)}))


def test_limits_follow_the_file_size_and_the_environment(monkeypatch) -> None:
    limits = isolated.Limits()
    monkeypatch.delenv("VOLVIZ_READ_MEMORY", raising=False)
    monkeypatch.delenv("VOLVIZ_READ_SECONDS", raising=False)
    assert limits.min_memory <= limits.memory(1000) <= 2 << 30 and limits.memory(10 ** 9) >= limits.memory(1000)
    assert limits.seconds(10_000_000) == 65.0
    monkeypatch.setenv("VOLVIZ_READ_MEMORY", "1.5G")
    monkeypatch.setenv("VOLVIZ_READ_SECONDS", "7")
    assert (limits.memory(1000), limits.seconds(10 ** 9)) == (3 << 29, 7.0)


def test_a_reader_child_started_from_a_thread_that_ended_keeps_serving() -> None:
    """The app reads on worker threads that come and go: a warm child started from one of them must outlive it
    (a parent-death signal tied to the starting thread killed it, and the next read looked like an out-of-memory
    death)."""
    import threading
    import warnings

    path = data_file("ecosystem/tos_O1_2001-2002.nc")
    got: list = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        worker = threading.Thread(target=lambda: got.append(vio.read(path)))
        worker.start()
        worker.join()
        series = got[0]
        frames = [series.frame(i) for i in (1, 12, 23)]          # read by the warm child, from this thread
    direct = vio.read(path, isolate=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for frame, i in zip(frames, (1, 12, 23)):
            expected = direct.frame(i)
            for name, values in expected.cell_data.items():
                np.testing.assert_array_equal(frame.cell_data[name], values)


def test_block_names_are_listed_in_the_reader_child(tmp_path) -> None:
    """``list_blocks`` runs VTK's reader too: a multiblock file whose piece crashes VTK gives a ReadError naming the
    file, and the names of a sound file equal those found in-process."""
    import vtk

    from volviz_vtk_readers import list_blocks
    from volviz_vtk_readers.readers import list_blocks as list_blocks_here

    folder = tmp_path / "parts"
    folder.mkdir()
    isolation_loaders.crash_vti(folder / "piece.vti")
    vtm = tmp_path / "damaged.vtm"
    vtm.write_text('<?xml version="1.0"?>\n<VTKFile type="vtkMultiBlockDataSet" version="1.0">\n'
                   '<vtkMultiBlockDataSet><DataSet index="0" name="piece" file="parts/piece.vti"/>'
                   '</vtkMultiBlockDataSet>\n</VTKFile>\n')
    with pytest.raises(vio.ReadError, match=r"damaged\.vtm: VTK's reader crashed \(segmentation fault\) reading it"):
        list_blocks(vtm)
    still_reads()
    mb = vtk.vtkMultiBlockDataSet()
    for i, name in enumerate(("left", "right")):
        image = vtk.vtkImageData()
        image.SetDimensions(2, 2, 2 + i)
        mb.SetBlock(i, image)
        mb.GetMetaData(i).Set(vtk.vtkCompositeDataSet.NAME(), name)
    writer = vtk.vtkXMLMultiBlockDataWriter()
    writer.SetInputData(mb)
    writer.SetFileName(str(tmp_path / "two.vtm"))
    writer.Write()
    assert list_blocks(tmp_path / "two.vtm") == list_blocks_here(tmp_path / "two.vtm") == ["left", "right"]


def test_a_child_that_died_leaves_no_pipe_open(test_readers, tmp_path) -> None:
    """A reader child that crashed is killed and its three pipes closed at once (before, its stdin and stdout stayed
    open until the collector found the worker, and its stderr for good: "unclosed file" ResourceWarnings that
    landed in whichever test collected them)."""
    import gc
    import warnings

    path = isolation_loaders.crash_vti(tmp_path / "damaged.uvti")
    gc.collect()
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always", ResourceWarning)
        with pytest.raises(vio.ReadError, match="segmentation fault"):
            vio.read(path)
        gc.collect()
    assert not [str(w.message) for w in seen if issubclass(w.category, ResourceWarning)]
    still_reads()
