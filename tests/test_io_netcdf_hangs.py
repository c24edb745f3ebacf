"""The netCDF files on which VTK's reader hung in the robustness campaigns (no answer within 5 s; the outside
campaign's worst case was refused only by the 60 s time limit) are refused by volviz's header check before VTK runs
(issue #32): the message is the check's, not the time limit's. Times are in docs/reliability.md, not asserted."""
from __future__ import annotations

import struct

import pytest

import volviz.io as vio
from conftest import data_file

TOS = "ecosystem/tos_O1_2001-2002.nc"


@pytest.mark.parametrize("at, value, fmt", [(188, 2**63 - 1, ">q"), (528, 2**63 - 1, ">q"), (712, -2**31, ">i"),
                                            (260, 2**63 - 1, ">q")])
def test_a_header_field_on_which_vtk_hung_is_refused_by_the_header_check(tmp_path, at, value, fmt):
    data = bytearray(data_file(TOS).read_bytes())
    raw = struct.pack(fmt, value)
    data[at:at + len(raw)] = raw
    path = tmp_path / "tos.nc"
    path.write_bytes(bytes(data))
    with pytest.raises(vio.ReadError) as info:
        vio.read(path)
    assert str(info.value) == (f"{path}: netCDF: the netCDF header runs past the end of the file (2949152 bytes; "
                               f"it asks for 2147483648 bytes at byte {at + 4}): the file is truncated or a count "
                               "in its header is damaged")  # a name length of 2^31-1 or 2^31, padded to 4 bytes
