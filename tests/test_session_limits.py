"""Sessions from untrusted files: every bad input is a SessionError naming the file, never a hang, a crash, a huge
allocation or another exception; messages describe bad values instead of quoting them."""
from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from volviz import session as S

HEADER = {"format": "volviz-session", "version": 1}


def write(path: Path, doc: dict | str) -> Path:
    path.write_text(doc if isinstance(doc, str) else json.dumps(doc), encoding="utf-8")
    return path


def refused(path: Path | str, *words: str) -> S.SessionError:
    with pytest.raises(S.SessionError) as info:
        S.load(path)
    message = str(info.value)
    assert str(path) in message
    for word in words:
        assert word in message
    return info.value


def test_a_5000_digit_number_is_refused(tmp_path: Path) -> None:
    path = write(tmp_path / "digits.json", '{"format": "volviz-session", "version": 1, "layout": {"n": %s}}'
                 % ("9" * 5000))
    refused(path, "number longer than 100 characters")
    path = write(tmp_path / "float.json", '{"format": "volviz-session", "version": 1, "layout": {"n": 0.%s}}'
                 % ("1" * 200))
    refused(path, "number longer than 100 characters")


def test_long_digit_runs_inside_strings_are_text(tmp_path: Path) -> None:
    doc = dict(HEADER, layout={"note": "7" * 500})
    assert S.load(write(tmp_path / "ok.json", doc)).layout["note"] == "7" * 500


def test_900_deep_nesting_is_refused(tmp_path: Path) -> None:
    path = write(tmp_path / "deep.json", '{"format": "volviz-session", "version": 1, "layout": {"x": %s}}'
                 % ("[" * 900 + "]" * 900))
    refused(path, "902 deep", "at most 64")


def test_brackets_and_escaped_quotes_in_strings_do_not_count_as_nesting(tmp_path: Path) -> None:
    doc = dict(HEADER, layout={"a": "[[[{{{" * 100, "b": 'quote \\" [[[ \\\\', "c": [[["x"]]]})
    assert S.load(write(tmp_path / "ok.json", doc)).layout == doc["layout"]


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom"])
def test_devices_are_refused(device: str) -> None:
    refused(device, "character device", "not a session file")


def test_a_fifo_is_refused_without_blocking(tmp_path: Path) -> None:
    fifo = tmp_path / "session.json"
    os.mkfifo(fifo)
    refused(fifo, "FIFO")


def test_a_folder_is_refused(tmp_path: Path) -> None:
    refused(tmp_path, "is a folder")


def test_oversized_file_is_refused_before_reading(tmp_path: Path) -> None:
    path = tmp_path / "huge.json"
    with open(path, "wb") as handle:
        handle.truncate(S.MAX_SESSION_BYTES + 1)  # sparse: no real bytes behind it
    refused(path, f"at most {S.MAX_SESSION_BYTES} bytes")


def test_a_million_point_transfer_function_is_refused(tmp_path: Path) -> None:
    n = 1_000_000
    tf = {"scalars": [0] * n, "colors": [0] * n, "extinction": [0] * n}  # compact, to fit the file-size limit
    path = tmp_path / "tf.json"
    path.write_text(json.dumps(dict(HEADER, transfer_functions={"big": tf}), separators=(",", ":")))
    assert path.stat().st_size < S.MAX_SESSION_BYTES
    refused(path, "values", f"at most {S.MAX_VALUES}")


def test_a_list_over_the_item_limit_names_its_field(tmp_path: Path) -> None:
    n = S.MAX_ITEMS + 1
    tf = {"scalars": list(range(n)), "colors": [[0, 0, 0]] * n, "extinction": [0] * n}
    error = refused(write(tmp_path / "tf.json", dict(HEADER, transfer_functions={"big": tf})), "items")
    assert error.field is not None and error.field.startswith("transfer_functions.big.")


def test_a_long_string_and_a_long_key_are_refused(tmp_path: Path) -> None:
    error = refused(write(tmp_path / "s.json", dict(HEADER, layout={"note": "x" * (S.MAX_STRING_CHARS + 1)})),
                    "characters")
    assert error.field == "layout.note"
    refused(write(tmp_path / "k.json", dict(HEADER, layout={"k" * 1000: 1})), "key of 1000 characters")


@pytest.mark.parametrize("kind", ["fifo", "device", "folder"])
def test_dataset_paths_that_are_not_files_are_refused(tmp_path: Path, kind: str) -> None:
    target = {"fifo": tmp_path / "data.raw", "device": Path("/dev/zero"), "folder": tmp_path / "sub"}[kind]
    if kind == "fifo":
        os.mkfifo(target)
    elif kind == "folder":
        target.mkdir()
    error = refused(write(tmp_path / "s.json", dict(HEADER, datasets=[{"id": "d", "path": str(target)}])),
                    "not a data file")
    assert error.field == "datasets[0].path"


def test_missing_dataset_files_and_patterns_still_load(tmp_path: Path) -> None:
    (tmp_path / "v.slc").write_bytes(b"11111\n")
    doc = dict(HEADER, datasets=[{"id": "a", "path": "v.slc"}, {"id": "b", "path": "gone.pvm"},
                                 {"id": "c", "path": "frames%03d.pvm"}])
    assert [d.path for d in S.load(write(tmp_path / "s.json", doc)).datasets] == ["v.slc", "gone.pvm",
                                                                                 "frames%03d.pvm"]


@pytest.mark.parametrize("options, field", [
    ({"dims": {"x": 1}}, "datasets[0].options.dims"),
    ({"dims": list(range(17))}, "datasets[0].options.dims"),
    ({"dims": [[1, 2]]}, "datasets[0].options.dims[0]"),
    ({"bad name": 1}, "datasets[0].options"),
    ({"scale": 1e400}, "datasets[0].options.scale"),
])
def test_dataset_options_are_plain_values(tmp_path: Path, options: dict, field: str) -> None:
    text = json.dumps(dict(HEADER, datasets=[{"id": "d", "path": "x.raw", "options": options}]))
    error = refused(write(tmp_path / "s.json", text.replace("Infinity", "1e400")))
    assert error.field == field


def test_valid_dataset_options_round_trip(tmp_path: Path) -> None:
    options = {"dims": [64, 64, 32], "dtype": "uint16", "byteorder": "<", "allow_nonfinite": True, "q": None,
               "scale": 0.5}
    doc = dict(HEADER, datasets=[{"id": "d", "path": "x.raw", "options": options}])
    assert S.load(write(tmp_path / "s.json", doc)).datasets[0].options == options


def test_messages_describe_values_instead_of_quoting_them(tmp_path: Path) -> None:
    junk = "\x00\x01\x02binary" * 20
    error = refused(write(tmp_path / "m.json", dict(HEADER, render={"method": junk})), "a string of 180 characters")
    assert "binary" not in str(error)
    error = refused(write(tmp_path / "v.json", {"format": "volviz-session", "version": "secret " * 30}))
    assert "secret" not in str(error)
    refused(write(tmp_path / "q.json", dict(HEADER, render={"method": "fast"})), "got 'fast'")  # short names: quoted
    (tmp_path / "b.json").write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR" + bytes(range(256)))
    error = refused(tmp_path / "b.json", "binary data")
    assert "PNG" not in str(error)


# -- fuzz: anything at all is a Session or a SessionError -------------------------------------------------------------
_scalars = st.one_of(st.none(), st.booleans(), st.integers(-10 ** 30, 10 ** 30),
                     st.floats(allow_nan=False, allow_infinity=False), st.text(max_size=12))
_json = st.recursive(_scalars, lambda inner: st.one_of(st.lists(inner, max_size=5),
                                                      st.dictionaries(st.text(max_size=8), inner, max_size=5)),
                     max_leaves=30)
_fields = st.sampled_from(["datasets", "components", "transfer_functions", "camera", "camera_paths", "bookmarks",
                           "render", "layout", "clip", "version", "format"])
_documents = st.one_of(
    st.dictionaries(_fields, _json, max_size=6).map(lambda d: {**HEADER, **d}),
    _json,
)


def _mutated(text: str, data: st.DataObject) -> str:
    """The JSON text with a few characters replaced, deleted or inserted (bytes a damaged file would hold)."""
    chars = list(text)
    for _ in range(data.draw(st.integers(0, 4))):
        op = data.draw(st.sampled_from(["replace", "delete", "insert"]))
        i = data.draw(st.integers(0, max(len(chars) - 1, 0)))
        c = data.draw(st.sampled_from(list('[]{}",:0123456789e.-\\ \x00tfn') + ["\ud800", "é"]))
        if op == "insert" or not chars:
            chars.insert(i, c)
        elif op == "delete":
            del chars[i]
        else:
            chars[i] = c
    return "".join(chars)


@settings(max_examples=400, deadline=2000, suppress_health_check=[HealthCheck.too_slow,
                                                                   HealthCheck.function_scoped_fixture])
@given(doc=_documents, data=st.data())
def test_fuzz_loader_gives_a_session_or_a_session_error(tmp_path: Path, doc, data) -> None:
    text = _mutated(json.dumps(doc), data)
    path = tmp_path / "fuzz.json"
    path.write_bytes(text.encode("utf-8", "surrogatepass"))
    try:
        result = S.load(path)
    except S.SessionError as exc:
        assert str(path) in str(exc)
    else:
        assert isinstance(result, S.Session)
