"""A Fluent CFF case whose root group lost its name (issue #32, the re-run's bit flips of ``room.cas.h5``, cases
1210 and 1216, rebuilt with ``volviz bench robustness --replay``): ``settings`` became ``setdings`` or ``meshes``
``meshEs``, the file no longer showed Fluent's groups, and the HDF5-arrays reader showed it as a 4565 x 2 image of its
node coordinates. A file named like Fluent CFF whose root lacks Fluent's groups is now refused, naming what it holds."""
from __future__ import annotations

import shutil

import h5py
import pytest

import volviz.io as vio
from conftest import data_file


@pytest.fixture
def room(tmp_path):
    for name in ("room.cas.h5", "room.dat.h5"):
        shutil.copyfile(data_file(f"ecosystem/fluent-room/{name}"), tmp_path / name)
    return tmp_path / "room.cas.h5"


def test_the_case_as_written_reads_as_a_mesh(room):
    mesh = vio.read(room)
    assert type(mesh).__name__ == "UnstructuredMesh" and (mesh.n_points, mesh.n_cells) == (4565, 4338)


@pytest.mark.parametrize("old, new, held", [("settings", "setdings", "meshes, setdings"),
                                            ("meshes", "meshEs", "meshEs, settings")])
def test_a_case_whose_root_group_was_renamed_is_refused(room, old, new, held):
    with h5py.File(room, "r+") as f:
        f.move(old, new)
    with pytest.raises(vio.ReadError, match=rf"^{room}: is named like a Fluent CFF file but its root lacks the "
                                            rf"/settings group with /meshes \(case\) or /results \(data\) \(it holds: "
                                            rf"{held}\): the file is damaged or not Fluent CFF; pass dataset="):
        vio.read(room)
