"""Session files a user may hand volviz (issue #32): a UTF-8 byte-order mark is accepted; a dataset option of the
wrong type, an unknown or missing option and a dataset path that is a loop of symbolic links are refused with one
line naming the session file and the field, through the library and the command line (never "internal error")."""
from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Literal, Optional, Sequence

import numpy as np
import pytest
from PIL import Image

from volviz.cli import main
from volviz.io.option_check import OptionProblem, check_reader_options, fits
from volviz.session import SessionError, load, session_to_dict

RAW_OPTIONS = {"dims": [8, 6, 4], "dtype": "uint8"}


def _session(folder: Path, options: dict[str, Any], path: str = "cube.raw", bom: bool = False,
             name: str = "s.json") -> Path:
    data = (np.arange(8 * 6 * 4) % 251).astype(np.uint8)
    (folder / "cube.raw").write_bytes(data.tobytes())
    doc = {"format": "volviz-session", "version": 1,
           "datasets": [{"id": "d", "path": path, "options": options}],
           "components": [{"id": "v", "type": "volume", "dataset": "d"}], "render": {"size": [64, 48]}}
    file = folder / name
    file.write_bytes((b"\xef\xbb\xbf" if bom else b"") + json.dumps(doc).encode())
    return file


def _cli_error(capsys: pytest.CaptureFixture[str], session: Path, tmp_path: Path) -> str:
    assert main(["render", str(session), "-o", str(tmp_path / "x.png")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"volviz: error: {session}: "), err
    assert not (tmp_path / "x.png").exists()
    return err[0].removeprefix(f"volviz: error: {session}: ")


def test_a_byte_order_mark_is_accepted(tmp_path, capsys):
    plain = _session(tmp_path, RAW_OPTIONS)
    marked = _session(tmp_path, RAW_OPTIONS, bom=True, name="bom.json")
    assert marked.read_bytes()[:3] == b"\xef\xbb\xbf"
    assert session_to_dict(load(marked)) == session_to_dict(load(plain))
    out = tmp_path / "bom.png"
    assert main(["render", str(marked), "-o", str(out)]) == 0
    assert Image.open(out).size == (64, 48)


@pytest.mark.parametrize("options, message", [
    ({"dims": [8, 6, "4"], "dtype": "uint8"},
     "datasets[0].options.dims: is [8, 6, '4']; the raw reader takes a list of integers"),
    ({"dims": [8, 6, 4], "dtype": 5},
     "datasets[0].options.dtype: is 5; the raw reader takes a list of 2 values or a list of values or a string"),
    ({**RAW_OPTIONS, "allow_nonfinite": "yes"},
     "datasets[0].options.allow_nonfinite: is 'yes'; the raw reader takes true or false"),
    ({**RAW_OPTIONS, "header_bytes": 1.5}, "datasets[0].options.header_bytes: is 1.5; the raw reader takes an integer"),
    ({**RAW_OPTIONS, "spacing": [1, 1]}, None),  # the right type: the reader's own check of the value stays
    ({**RAW_OPTIONS, "header": 16},
     "datasets[0].options.header: the raw reader does not take option(s) header; it takes dims, dtype, byteorder, "),
    ({"dims": [8, 6, 4]}, "datasets[0].options: the raw reader needs option(s) dtype"),
])
def test_dataset_options_are_checked_against_the_reader(tmp_path, capsys, options, message):
    session = _session(tmp_path, options)
    if message is None:
        load(session)
        return
    line = _cli_error(capsys, session, tmp_path)
    assert line.startswith(message), line
    with pytest.raises(SessionError) as caught:
        load(session)
    assert str(caught.value) == f"{session}: {line}"
    assert caught.value.field == message.split(":")[0]


def test_a_dataset_path_that_loops_is_refused(tmp_path, capsys):
    os.symlink(tmp_path / "loop-a", tmp_path / "loop-b")
    os.symlink(tmp_path / "loop-b", tmp_path / "loop-a")
    session = _session(tmp_path, {}, path="loop-a")
    assert _cli_error(capsys, session, tmp_path) == "datasets[0].path: loop-a is a loop of symbolic links, not a " \
                                                    "data file"
    with pytest.raises(SessionError) as caught:
        load(session)
    assert caught.value.field == "datasets[0].path"


def test_options_of_a_missing_file_are_left_to_the_read(tmp_path):
    check_reader_options(tmp_path / "absent.raw", {"bogus": 1})  # the read reports the missing file
    with pytest.raises(OptionProblem, match="does not take option"):
        check_reader_options(_session(tmp_path, {}).with_name("cube.raw"), {**RAW_OPTIONS, "bogus": 1})


@pytest.mark.parametrize("value, hint, expected", [
    (3, int, True), (True, int, False), (3, float, True), (3.5, int, False), ("a", str, True),
    (None, Optional[int], True), ("x", Optional[int], False), ([1, 2], Sequence[int], True),
    ("12", Sequence[int], False), ([1, 2], tuple[int, int, int], False), ([1, 2, 3], tuple[int, int, int], True),
    ([1.0, 2], tuple[float, ...], True), ("b", Literal["a", "b"], True), ("c", Literal["a", "b"], False),
    ([True], list[bool], True), ({"a": 1}, Sequence[int], False), (5, Any, True),
])
def test_fits(value, hint, expected):
    assert fits(value, hint) is expected
