"""Session files: round trip, validation naming the field, version handling, atomic save."""
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from volviz import session as S
from volviz.model.clip import BoxCrop, ClipPlane, ClipSettings
from volviz.optics.transfer_function import TransferFunction


def sample_session() -> S.Session:
    tf = {"scalars": [0.0, 0.5, 1.0], "colors": [[0, 0, 1], [1, 1, 1], [1, 0, 0]], "extinction": [0.0, 2.0, 5.0],
          "name": "ramp"}
    cam = S.CameraState(position=(3.0, -2.0, 1.5), focal_point=(0.1, 0.2, 0.3), view_up=(0.0, 0.0, 1.0),
                        view_angle=35.0)
    return S.Session(
        datasets=[S.DatasetRef(id="fin", path="data/bluntfinxyz.bin", options={"q": "data/bluntfinq.bin"})],
        components=[S.Component(id="fin", type="mesh", dataset="fin", opacity=0.75, transfer_function="ramp",
                                settings={"array": "Density", "budget": 128})],
        transfer_functions={"ramp": TransferFunction.from_dict(tf)},
        camera=cam,
        camera_paths={"orbit": [S.CameraKey(0.0, cam), S.CameraKey(2.5, S.CameraState(position=(0, 5, 1)))]},
        bookmarks={"front": cam},
        render=S.RenderSettings(method="pt", size=(640, 480), background=(0.0, 0.0, 0.0), options={"sort": "mpvo"}),
        layout={"docks": {"tf": {"visible": True, "area": "right"}}},
    )


def test_round_trip_is_identity(tmp_path: Path) -> None:
    original = sample_session()
    path = tmp_path / "a.json"
    S.save(original, path)
    assert S.load(path) == original
    doc = json.loads(path.read_text())
    assert doc["format"] == "volviz-session" and doc["version"] == S.VERSION
    S.save(S.load(path), tmp_path / "b.json")
    S.save(S.load(tmp_path / "b.json"), tmp_path / "c.json")
    assert (tmp_path / "b.json").read_text() == (tmp_path / "c.json").read_text()


@pytest.mark.parametrize("mutate, field, words", [
    (lambda d: d["components"][0].__setitem__("opacity", 1.5), "components[0].opacity", "[0.0, 1.0]"),
    (lambda d: d["components"][0].__setitem__("type", "teapot"), "components[0].type", "expected one of"),
    (lambda d: d["components"][0].__setitem__("dataset", "nope"), "components[0].dataset", "no dataset"),
    (lambda d: d["datasets"][0].__setitem__("path", 7), "datasets[0].path", "expected a string"),
    (lambda d: d["camera"].__setitem__("view_angle", "wide"), "camera.view_angle", "finite number"),
    (lambda d: d["render"].__setitem__("size", [0, 10]), "render.size", "whole numbers"),
    (lambda d: d["camera_paths"]["orbit"][1].__setitem__("time", -1.0), "camera_paths.orbit[1].time", "increase"),
    (lambda d: d.__setitem__("colour", 3), "colour", "unknown field"),
    (lambda d: d["transfer_functions"]["ramp"].__setitem__("extinction", [0, -1, 2]), "transfer_functions.ramp",
     "invalid transfer function"),
    (lambda d: d["transfer_functions"]["ramp"].__setitem__("gamma", 2.2), "transfer_functions.ramp.gamma",
     "unknown field"),
])
def test_validation_names_the_offending_field(tmp_path: Path, mutate, field: str, words: str) -> None:
    doc = S.session_to_dict(sample_session())
    mutate(doc)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(S.SessionError) as info:
        S.load(path)
    assert info.value.field == field
    assert words in str(info.value)
    assert str(path) in str(info.value)


def test_transfer_functions_and_clipping_load_as_typed_models_and_save_byte_for_byte(tmp_path: Path) -> None:
    original = sample_session()
    original.camera_paths["orbit"][1].camera.position = (0.0, 5.0, 1.0)   # (whole numbers would be written as floats)
    original.set_clip(ClipSettings((ClipPlane((1.5, 2.0, 3.0), (0.6, 0.8, 0.0)),), BoxCrop((0, 0, 0), (10, 20, 30.5))))
    S.save(original, tmp_path / "a.json")
    text = (tmp_path / "a.json").read_text()
    doc = json.loads(text)
    assert doc["transfer_functions"] == {"ramp": {
        "format": "volviz-transfer-function", "version": 1, "name": "ramp", "scalars": [0.0, 0.5, 1.0],
        "colors": [[0.0, 0.0, 1.0], [1.0, 1.0, 1.0], [1.0, 0.0, 0.0]], "extinction": [0.0, 2.0, 5.0]}}
    assert doc["clip"] == {"planes": [{"point": [1.5, 2.0, 3.0], "normal": [0.6, 0.8, 0.0]}],
                           "box": {"lo": [0.0, 0.0, 0.0], "hi": [10.0, 20.0, 30.5]}}
    loaded = S.load(tmp_path / "a.json")
    assert isinstance(loaded.transfer_functions["ramp"], TransferFunction) and isinstance(loaded.clip, ClipSettings)
    assert loaded.transfer_function("fin") == original.transfer_functions["ramp"] and loaded.clip == original.clip
    assert S.dumps(loaded) == text                            # what volviz wrote is written again to the byte


def test_a_hand_written_transfer_function_is_saved_in_the_models_form() -> None:
    doc = S.session_to_dict(sample_session())
    doc["transfer_functions"]["ramp"] = {"scalars": [0, 1, 2.5], "colors": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
                                         "extinction": [0, 2, 1]}
    session = S.loads(json.dumps(doc))
    assert session.transfer_functions["ramp"] == TransferFunction([0.0, 1.0, 2.5], np.eye(3), [0.0, 2.0, 1.0])
    text = S.dumps(session)
    assert json.loads(text)["transfer_functions"]["ramp"] == {
        "format": "volviz-transfer-function", "version": 1, "name": "", "scalars": [0.0, 1.0, 2.5],
        "colors": [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], "extinction": [0.0, 2.0, 1.0]}
    assert S.dumps(S.loads(text)) == text


def test_newer_version_is_refused_clearly(tmp_path: Path) -> None:
    doc = S.session_to_dict(sample_session())
    doc["version"] = S.VERSION + 1
    path = tmp_path / "future.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(S.SessionError, match="newer than this volviz supports"):
        S.load(path)


@pytest.mark.parametrize("text, words", [
    ("{", "not valid JSON"),
    ('{"format": "something-else", "version": 1}', "not a volviz session"),
    ('{"format": "volviz-session", "version": "1"}', "whole number"),
    ('{"format": "volviz-session", "version": 1, "camera": {"view_angle": NaN}}', "NaN is not allowed"),
])
def test_malformed_documents(tmp_path: Path, text: str, words: str) -> None:
    path = tmp_path / "x.json"
    path.write_text(text)
    with pytest.raises(S.SessionError, match=words):
        S.load(path)


def test_missing_file_and_directory(tmp_path: Path) -> None:
    with pytest.raises(S.SessionError, match="no such file"):
        S.load(tmp_path / "missing.json")
    with pytest.raises(S.SessionError, match="is a folder"):
        S.load(tmp_path)


def test_failed_save_leaves_old_file_intact(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "keep.json"
    S.save(sample_session(), path)
    before = path.read_bytes()

    def broken_fsync(fd: int) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "fsync", broken_fsync)
    changed = sample_session()
    changed.components[0].opacity = 0.1
    with pytest.raises(S.SessionError, match="No space left"):
        S.save(changed, path)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["keep.json"]  # no temporary file left behind


def test_invalid_session_is_not_written(tmp_path: Path) -> None:
    bad = sample_session()
    bad.components[0].opacity = 3.0
    with pytest.raises(S.SessionError, match="opacity"):
        S.save(bad, tmp_path / "bad.json")
    assert not (tmp_path / "bad.json").exists()


def test_relative_paths(tmp_path: Path) -> None:
    session_file = tmp_path / "sessions" / "s.json"
    session_file.parent.mkdir()
    data = tmp_path / "data" / "v.slc"
    stored = S.relative_path(session_file, data)
    assert stored == "../data/v.slc"
    assert S.resolve_path(session_file, stored) == data.resolve()


def test_older_versions_are_migrated_step_by_step(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Version 1 is the first format; this exercises the migration chain the way a version 2 will use it."""
    def v1_to_v2(doc: dict) -> dict:
        doc["render"]["options"]["time"] = 1.5   # a version 2 would rename or convert fields like this
        return doc

    doc = S.session_to_dict(sample_session())
    path = tmp_path / "old.json"
    path.write_text(json.dumps(doc))
    monkeypatch.setattr(S, "VERSION", 2)
    monkeypatch.setitem(S.MIGRATIONS, 1, v1_to_v2)
    loaded = S.load(path)
    assert loaded.render.options["time"] == 1.5
    S.save(loaded, tmp_path / "new.json")
    assert json.loads((tmp_path / "new.json").read_text())["version"] == 2
