"""The checks the VTK-readers plugin makes before VTK reads a netCDF classic file or an OpenFOAM time step: a file
whose header contradicts itself, or that lost bytes, is refused with a ReadError naming it, where VTK would read it
with a field missing or a grid of another size (cases found by ``volviz bench robustness``)."""
from __future__ import annotations

import shutil
import struct
import warnings

import numpy as np
import pytest
from scipy.io import netcdf_file

import volviz.io as vio
from volviz_vtk_readers.containers import _netcdf_end, check_container

from conftest import data_file

CURVE = "ecosystem/sampleCurveGrid4.nc"


def _dimension_length_at(data: bytes, name: bytes) -> int:
    """The byte offset of the length field of dimension ``name`` in a CDF-1 header."""
    at = data.index(struct.pack(">I", len(name)) + name)
    return at + 4 + len(name) + (-len(name) % 4)


@pytest.mark.parametrize("name", [CURVE, "ecosystem/tos_O1_2001-2002.nc"])
def test_netcdf_cut_by_its_last_byte_is_refused(tmp_path, name):
    data = data_file(name).read_bytes()
    assert _netcdf_end(data) == len(data)  # the data of the last variable reach exactly the end of the file
    cut = tmp_path / "cut.nc"
    cut.write_bytes(data[:-1])
    with pytest.raises(vio.ReadError, match=rf"cut\.nc: netCDF: the netCDF header places data up to byte "
                                            rf"{len(data)}, but the file holds {len(data) - 1} bytes"):
        vio.read(cut)


def test_netcdf_dimension_length_that_disagrees_with_the_variable_sizes(tmp_path):
    data = bytearray(data_file(CURVE).read_bytes())
    at = _dimension_length_at(bytes(data), b"x")
    (length,) = struct.unpack(">I", data[at:at + 4])
    data[at:at + 4] = struct.pack(">I", length + 1)
    bad = tmp_path / "grown.nc"
    bad.write_bytes(bytes(data))
    with pytest.raises(vio.ReadError, match=r"grown\.nc: netCDF: malformed netCDF header \(variable '\w+' has "
                                            r"\d+ bytes by its dimensions but a size field of \d+\)"):
        vio.read(bad)


def test_netcdf_variable_placed_inside_the_header(tmp_path):
    path = tmp_path / "v.nc"
    with netcdf_file(path, "w", version=1) as nc:
        nc.createDimension("x", 4)
        nc.createVariable("a", "f", ("x",))[:] = np.arange(4, dtype=np.float32)
    data = bytearray(path.read_bytes())
    begin = len(data) - 16                   # the one variable's 16 bytes end the file; its begin field is before
    at = bytes(data).rindex(struct.pack(">I", begin))
    data[at:at + 4] = struct.pack(">I", 8)
    path.write_bytes(bytes(data))
    with pytest.raises(vio.ReadError, match=r"v\.nc: netCDF: malformed netCDF header \(variable 'a' starts at "
                                            r"byte 8, inside the \d+-byte header\)"):
        check_container(path, "netCDF")


def test_netcdf_damaged_attribute_name_is_refused(tmp_path):
    """A damaged byte in the name ``bounds`` of an attribute would make VTK's CF reader lose the curvilinear grid
    and read another variable as a regular volume of another size."""
    data = bytearray(data_file(CURVE).read_bytes())
    at = data.index(b"bounds\0\0")
    data[at + 4:at + 8] = b"\x7f\xff\xff\xff"
    bad = tmp_path / "name.nc"
    bad.write_bytes(bytes(data))
    with pytest.raises(vio.ReadError, match=rf"name\.nc: netCDF: malformed netCDF header \(a name at byte {at} is "
                                            r"not UTF-8 text\)"):
        vio.read(bad)


def test_netcdf_bounds_naming_a_missing_variable_is_refused(tmp_path):
    data = data_file(CURVE).read_bytes()
    bad = tmp_path / "bounds.nc"
    bad.write_bytes(data.replace(b"bounds_lon", b"bounds_lom", 1))  # the attribute's value, before the variable
    with pytest.raises(vio.ReadError, match=r"bounds\.nc: netCDF: malformed netCDF header \(variable 'lon' names "
                                            r"'bounds_lom' in its 'bounds' attribute, but the file has no variable"):
        vio.read(bad)


TOS = "ecosystem/tos_O1_2001-2002.nc"


def _renamed_dimension(data: bytes, old: bytes, new: bytes) -> bytes:
    """A CDF-1 file whose dimension ``old`` is called ``new`` (a one-bit flip in the fuzz campaign): still valid
    netCDF, but the coordinate variable ``old`` is no longer on a dimension of its own name."""
    at = data.index(struct.pack(">I", len(old)) + old)
    assert at < 64  # the dimension list comes first in the header
    return data[:at + 4] + new + data[at + 4 + len(new):]


def test_netcdf_coordinate_whose_dimension_was_renamed_is_read_with_a_warning(tmp_path):
    """``lat`` renamed ``lau`` in the dimension list: VTK's CF reader then takes the latitudes for the data and shows a
    line of 170 points instead of the 180x170 map; the read says so, naming the file and the variable."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", vio.ReadWarning)  # the valid file warns of nothing
        original = vio.read(data_file(TOS))
    bad = tmp_path / "lau.nc"
    bad.write_bytes(_renamed_dimension(data_file(TOS).read_bytes(), b"lat", b"lau"))
    with pytest.warns(vio.ReadWarning, match=r"lau\.nc: variable 'lat' has cell bounds \('lat_bnds'\) as a "
                                             r"coordinate has, but it is not one: it is on dimension 'lau'"):
        misread = vio.read(bad)
    assert misread.n_points == 170 and original.frame(0).n_points == 181 * 171


def test_netcdf_auxiliary_coordinates_with_bounds_warn_of_nothing(tmp_path):
    """2D latitudes named in the data's ``coordinates`` attribute (CF §5.2) may have bounds; a coordinate variable of
    its own dimension too. A variable with bounds that is neither is the doubtful case."""
    from volviz_vtk_readers.containers import _cf_notes

    coord = ("lat", ["lat"], {"bounds": "lat_bnds"})
    aux = ("lat2d", ["y", "x"], {"bounds": "lat2d_v"})
    data = ("t", ["y", "x"], {"coordinates": "lat2d"})
    assert _cf_notes([coord, aux, data]) == []
    notes = _cf_notes([coord, aux, ("t", ["y", "x"], {})])
    assert len(notes) == 1 and notes[0].startswith("variable 'lat2d' has cell bounds ('lat2d_v')") \
        and "on dimensions ('y', 'x')" in notes[0]


def test_the_fuzz_campaign_counts_a_warned_read_apart_from_silent_garbage(tmp_path):
    from volviz.bench import robustness as rb

    bad = tmp_path / "lau.nc"
    bad.write_bytes(_renamed_dimension(data_file(TOS).read_bytes(), b"lat", b"lau"))
    answer = rb._serve_volviz({"path": str(bad), "options": {}})
    assert answer["status"] == "ok" and "variable 'lat' has cell bounds" in answer["warned"]
    original = rb._serve_volviz({"path": str(data_file(TOS)), "options": {}})
    assert original["warned"] == "" and original["n_points"] != answer["n_points"]
    mutation = rb.Mutation("bitflip", "bits flipped at [34]", None)
    assert rb._judge(answer, original, mutation) == "warned"
    assert rb._judge({**answer, "warned": ""}, original, mutation) == "garbage"


@pytest.mark.parametrize("version", [1, 2])
def test_netcdf_written_without_padding_or_with_one_record_variable_is_accepted(tmp_path, version):
    """Odd-sized variables (no padding after the last one) and a single record variable (records not padded)."""
    path = tmp_path / "ok.nc"
    with netcdf_file(path, "w", version=version) as nc:
        nc.createDimension("t", None)
        nc.createDimension("x", 3)
        nc.createVariable("a", "b", ("t", "x"))[:] = np.ones((5, 3))
        nc.createVariable("c", "h", ("x",))[:] = [1, 2, 3]
    assert check_container(path, "netCDF") == path
    assert _netcdf_end(path.read_bytes()) == path.stat().st_size


@pytest.fixture
def cavity(tmp_path):
    case = tmp_path / "cavity"
    shutil.copytree(data_file("ecosystem/openfoam-cavity"), case)
    return case


@pytest.mark.parametrize("field, keep, problem", [
    ("0.5/p", 37, "has no complete FoamFile header"),           # cut inside the banner comment
    ("0.5/U", 162, "has no complete FoamFile header"),
    ("0.5/p", 900, "ends before its boundaryField"),             # cut inside internalField
    ("2.5/p", -120, "ends inside its boundaryField"),            # cut inside boundaryField
])
def test_openfoam_field_file_cut_short_is_refused(cavity, field, keep, problem):
    """VTK's reader drops such a field silently (the step opens without it); the frame that reads it is refused."""
    path = cavity / field
    data = path.read_bytes()
    path.write_bytes(data[:keep])
    step = ["0", "0.5", "1", "1.5", "2", "2.5"].index(field.split("/")[0])
    message = rf"cavity: the OpenFOAM (field )?file {field} {problem}"
    if step == 0:
        with pytest.raises(vio.ReadError, match=message):
            vio.read(cavity / "case.foam")
        return
    series = vio.read(cavity / "case.foam")
    with pytest.raises(vio.ReadError, match=message):
        series.frame(step)
    other = 1 if step != 1 else 2
    assert set(series.frame(other).cell_data) == {"p", "U"}   # the other steps still read, with every field


def test_openfoam_first_step_damaged_refuses_the_open(cavity):
    path = cavity / "0" / "p"
    path.write_bytes(path.read_bytes()[:318])
    with pytest.raises(vio.ReadError, match=r"cavity: the OpenFOAM file 0/p has no complete FoamFile header: it is "
                                            r"damaged or not an OpenFOAM file; repair it, or move it out"):
        vio.read(cavity / "case.foam")


def test_openfoam_backup_files_in_a_time_folder_are_left_alone(cavity):
    (cavity / "0" / "p.orig").write_text("an old copy, cut")
    (cavity / "0" / "notes~").write_text("editor backup")
    series = vio.read(cavity / "case.foam")
    assert set(series.frame(0).cell_data) == {"p", "U"}


def test_netcdf_unit_text_that_is_not_text_is_refused(tmp_path):
    """A NaN written over the ``units`` of ``lat`` ("degrees_north"): VTK's CF reader would no longer see a latitude
    and read another variable as a regular volume."""
    data = data_file(CURVE).read_bytes()
    at = data.index(b"degrees_north") + 8
    bad = tmp_path / "units.nc"
    bad.write_bytes(data[:at] + struct.pack(">d", float("nan")) + data[at + 8:])
    with pytest.raises(vio.ReadError, match=r"units\.nc: netCDF: malformed netCDF header \(the 'units' attribute "
                                            r"at byte \d+ is not printable text\)"):
        vio.read(bad)


EXODUS = "ecosystem/disk_out_ref.ex2"


@pytest.mark.parametrize("node", [0, 8500, 19057])
def test_exodus_connectivity_past_the_nodes_is_refused(tmp_path, node):
    """A node number outside 1..num_nodes in an element block (a flipped bit in the fuzz campaign: VTK then added a
    point read from past its array) is refused, naming the block and the node."""
    from volviz_vtk_readers.containers import netcdf_header

    data = bytearray(data_file(EXODUS).read_bytes())
    header = netcdf_header(data_file(EXODUS), "Exodus II")
    assert header is not None and header.dims["num_nodes"] == 8499
    connect = header.variables["connect1"]
    at = connect.begin + 4 * 1000                  # the 1001st node number of block 1 (big-endian int32)
    data[at:at + 4] = struct.pack(">i", node)
    bad = tmp_path / "bad.ex2"
    bad.write_bytes(bytes(data))
    with pytest.raises(vio.ReadError, match=rf"bad\.ex2: Exodus II: element block connectivity 'connect1' refers to "
                                            rf"node {node}, but the file has nodes 1 to 8499 \(num_nodes\)"):
        vio.read(bad)
    assert vio.read(data_file(EXODUS)).n_points == 8499


def test_exodus_connectivity_in_a_netcdf4_file_is_checked(tmp_path):
    """netCDF-4 (HDF5) Exodus files: ``num_nodes`` is a dimension scale, the blocks ``connect<i>`` datasets."""
    import h5py

    from volviz_vtk_readers.exodus_check import check_exodus_connectivity

    path = tmp_path / "mesh.exo"
    with h5py.File(path, "w") as f:
        f.create_dataset("num_nodes", data=np.zeros(4))
        f.create_dataset("connect1", data=np.array([[1, 2, 3, 4]], dtype=np.int32))
    check_exodus_connectivity(path)
    with h5py.File(path, "a") as f:
        f.create_dataset("connect2", data=np.array([[1, 2, 3, 5]], dtype=np.int64))
    with pytest.raises(vio.ReadError, match=r"'connect2' refers to node 5, but the file has nodes 1 to 4"):
        check_exodus_connectivity(path)
