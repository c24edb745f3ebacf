"""The reader registry: built-in specs, dispatch by option / folder / name / content, and third-party readers
registered through the ``volviz.readers`` entry-point group (a real dist-info folder on sys.path)."""
from __future__ import annotations

import numpy as np
import pytest

import volviz.io as vio
from volviz.io import registry
from volviz.model import RegularVolume

from dist_info import install_dist

PLUGIN_MODULE = '''
import numpy as np

from volviz.io import ReaderSpec, ReadError
from volviz.model import RegularVolume

from dist_info import install_dist


def read_fancy(path, scale=1):
    with open(path, "rb") as fh:
        head = fh.readline()
        if head != b"FANCY\\n":
            raise ReadError(path, "not a fancy file")
        dims = tuple(int(t) for t in fh.readline().split())
        values = np.array(fh.read().split(), dtype=np.float32) * scale
    return RegularVolume(values.reshape(dims, order="F"), name="fancy", source=str(path))


SPECS = [ReaderSpec("fancy", "Fancy volume", ("*.fancy",), "fancy_reader:read_fancy",
                    sniff=lambda head: head.startswith(b"FANCY\\n"), arrays="fancy", options=("scale",))]
'''


@pytest.fixture
def fancy_plugin(tmp_path, monkeypatch):
    """Install a reader plugin the way pip would: a module and a dist-info folder with entry_points.txt."""
    site = install_dist(tmp_path / "site", "fancy-reader", {"volviz.readers": {"fancy": "fancy_reader:SPECS"}},
                        {"fancy_reader": PLUGIN_MODULE})
    monkeypatch.syspath_prepend(str(site))
    registry.reader_specs(refresh=True)
    yield site
    monkeypatch.undo()
    registry.reader_specs(refresh=True)


def _fancy_file(path, dims=(2, 3, 1), values=None):
    values = np.arange(np.prod(dims), dtype=np.float32) if values is None else values
    path.write_bytes(b"FANCY\n" + " ".join(map(str, dims)).encode() + b"\n" + " ".join(map(str, values)).encode())
    return path


def test_third_party_reader_is_found_through_its_entry_point(fancy_plugin, tmp_path):
    spec = registry.get_reader("fancy")
    assert spec.description == "Fancy volume" and spec.options == ("scale",)
    assert ("Fancy volume", ("*.fancy",)) in vio.supported_formats()
    assert "Fancy volume (*.fancy)" in vio.open_dialog_filter()
    vol = vio.read(_fancy_file(tmp_path / "a.fancy"), scale=2)
    assert isinstance(vol, RegularVolume) and vol.dimensions == (2, 3, 1)
    np.testing.assert_array_equal(vol.data.ravel(order="F"), np.arange(6, dtype=np.float32) * 2)
    # found by content too, whatever the file is called
    assert vio.format_of(_fancy_file(tmp_path / "renamed.bin"), {}) == "fancy"


def test_plugin_is_gone_after_refresh_without_it(fancy_plugin, tmp_path):
    path = _fancy_file(tmp_path / "a.fancy")
    assert vio.format_of(path, {}) == "fancy"
    fancy_plugin.joinpath("fancy_reader-1.0.dist-info", "entry_points.txt").write_text("[other.group]\nx = y:z\n")
    registry.reader_specs(refresh=True)
    with pytest.raises(vio.ReadError, match=r"a\.fancy: unknown data format .*supported: PLOT3D"):
        vio.read(path)


def test_broken_plugin_warns_and_is_skipped(tmp_path, monkeypatch):
    site = install_dist(tmp_path / "site", "broken-reader",
                        {"volviz.readers": {"broken": "no_such_module_here:SPECS", "dup": "broken_specs:SPECS"}},
                        {"broken_specs": "from volviz.io import ReaderSpec\n"
                                         "SPECS = ReaderSpec('pvm', 'Another PVM', ('*.pvm',), 'x:y')\n"})
    monkeypatch.syspath_prepend(str(site))
    try:
        with pytest.warns(registry.PluginWarning) as record:
            specs = registry.reader_specs(refresh=True)
        messages = " ".join(str(w.message) for w in record)
        assert "'broken'" in messages and "no_such_module_here" in messages
        assert "'pvm' is skipped: the name is already registered" in messages
        assert [s.description for s in specs if s.name == "pvm"] == ["PVM volume"]
    finally:
        monkeypatch.undo()
        registry.reader_specs(refresh=True)


def test_builtin_dispatch_by_option_name_and_content(tmp_path):
    assert vio.format_of(tmp_path / "anything.bin", {"dims": (2, 2, 2)}) == "raw"
    pvm = tmp_path / "v.dat"
    pvm.write_bytes(b"PVM\n2 2 2\n1\n" + bytes(8))
    assert vio.format_of(pvm, {}) == "pvm"  # content wins when the name says nothing
    assert vio.read(pvm).dimensions == (2, 2, 2)
    legacy = tmp_path / "mesh.txt"
    legacy.write_bytes(b"# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\n")
    with pytest.raises(vio.ReadError, match=r"mesh\.txt: looks like a VTK legacy file; give it its extension "
                                            r"\(\.vtk\)"):
        vio.read(legacy)
    xml = tmp_path / "grid"
    xml.write_bytes(b'<?xml version="1.0"?>\n<VTKFile type="ImageData">')
    with pytest.raises(vio.ReadError, match=r"looks like a VTK XML file; give it its extension \(\.vti \.vtu"):
        vio.read(xml)


def test_folder_without_a_reader_says_which_folders_open(tmp_path):
    with pytest.raises(vio.ReadError, match=r"is a directory, not a file"):
        vio.read(tmp_path)


def test_catch_all_reader_lists_only_unclaimed_extensions():
    formats = dict(vio.supported_formats())
    meshio = formats["Meshes (meshio)"]
    assert "*.msh" in meshio and "*.vtu" not in meshio and "*.vtk" not in meshio
    assert formats["VTK XML"] == ("*.vti", "*.vtu", "*.vts", "*.vtr", "*.vtp")
    assert [s.name for s in vio.reader_specs()][-1] == "meshio"
