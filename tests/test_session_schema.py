"""The typed settings models (``volviz.model.settings``) behind sessions: every component type's settings and the
render options are validated with the field's path on the first problem, their fixed choices are enums in one place,
and the session's JSON schema (``volviz schema``) is the checked-in ``docs/session.schema.json``, which the shipped
sessions satisfy."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

import volviz.session as S
from volviz.model.session_schema import SessionDocument, session_schema, session_schema_text
from volviz.model.settings import SETTINGS_MODELS, FogSettings, SettingsError, typed_settings

ROOT = Path(__file__).resolve().parents[1]
SESSIONS = sorted((ROOT / "resources" / "sessions").glob("*.json"))


def test_volviz_schema_prints_the_checked_in_schema():
    done = subprocess.run([sys.executable, "-m", "volviz.cli", "schema"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    checked_in = (ROOT / "docs" / "session.schema.json").read_text(encoding="utf-8")
    assert done.stdout == checked_in == session_schema_text(), \
        "docs/session.schema.json is stale: regenerate it with `volviz schema -o docs/session.schema.json`"


def test_schema_lists_every_component_type_and_the_fixed_choices():
    schema = session_schema()
    defs = schema["$defs"]
    kinds = {defs[ref["$ref"].split("/")[-1]]["properties"]["type"]["const"]
             for ref in schema["properties"]["components"]["items"]["oneOf"]}
    assert kinds == set(SETTINGS_MODELS) == set(S.COMPONENT_TYPES)
    assert defs["FogSettings"]["properties"]["mode"]["enum"] == ["emissive", "attenuated", "mip"]
    assert defs["RenderOptions"]["properties"]["backend"]["enum"] == list(S.RENDER_BACKENDS) == ["auto", "gpu", "cpu"]
    assert defs["FogSettings"]["additionalProperties"] is False
    assert defs["FogSettings"]["properties"]["density"]["minimum"] == 0


@pytest.mark.parametrize("path", SESSIONS, ids=lambda p: p.stem)
def test_shipped_sessions_satisfy_the_schema(path):
    doc = json.loads(path.read_text(encoding="utf-8"))
    SessionDocument.model_validate(doc)
    S.session_from_dict(doc, path)


def test_a_saved_session_satisfies_the_schema(tmp_path):
    session = S.Session(components=[S.Component(id="fog", type="fog", settings={"density": 0.1, "mode": "mip"}),
                                    S.Component(id="t", type="terrain", settings={"C": 9.0})])
    session.render.options.update(backend="gpu", iso_mode="3pass")
    S.save(session, tmp_path / "s.json")
    SessionDocument.model_validate(json.loads((tmp_path / "s.json").read_text()))


@pytest.mark.parametrize("settings, message", [
    ({"densty": 0.1}, r"components\[0\]\.settings\.densty: unknown setting"),
    ({"density": -1}, r"components\[0\]\.settings\.density: Input should be greater than or equal to 0"),
    ({"density": "thick"}, r"components\[0\]\.settings\.density: expected a number, got a string"),
    ({"mode": "foggy"}, r"components\[0\]\.settings\.mode: expected one of emissive, attenuated, mip, got 'foggy'"),
    ({"colour": [1, 2, 0]}, r"components\[0\]\.settings\.colour: Value error, color components must be in 0\.\.1"),
    ({"color": [1, 2, 0]}, r"components\[0\]\.settings\.color: Value error, color components must be in 0\.\.1"),
    ({"color": [1, 1, 1], "colour": [1, 1, 1]}, r"components\[0\]\.settings\.colour: unknown setting"),
])
def test_component_settings_are_refused_with_their_field_path(settings, message):
    doc = {"format": "volviz-session", "version": 1, "components": [{"id": "f", "type": "fog", "settings": settings}]}
    with pytest.raises(S.SessionError, match=message):
        S.session_from_dict(doc, "bad.json")


@pytest.mark.parametrize("options, message", [
    ({"backend": "fast"}, r"render\.options\.backend: expected one of auto, gpu, cpu, got 'fast'"),
    ({"iso_mode": 3}, r"render\.options\.iso_mode: expected a string, got a number"),
    ({"fly_clearance": 2}, r"render\.options\.fly_clearance: Input should be less than or equal to 0\.5"),
    ({"scalarbar": False}, r"render\.options\.scalarbar: unknown setting"),
])
def test_render_options_are_refused_with_their_field_path(options, message):
    doc = {"format": "volviz-session", "version": 1, "render": {"options": options}}
    with pytest.raises(S.SessionError, match=message):
        S.session_from_dict(doc, "bad.json")


def test_defaults_live_in_the_models():
    fog = typed_settings("fog", {})
    assert (fog.mode, fog.density, fog.color, fog.weight) == ("attenuated", 0.05, (0.75, 0.75, 1.0), 4.0)
    with pytest.raises(SettingsError) as info:
        typed_settings("clouds", {"shape": [2, 129, 17]}, "settings")
    assert info.value.problems == [("settings.shape", "Value error, each size must be in 3..1025")]
    model = FogSettings()
    with pytest.raises(ValueError):
        model.density = -1.0   # assignments are validated too


def test_each_component_type_validates_as_its_model():
    """``typed_settings`` validates by ``SETTINGS_MODELS``; ``validated`` gives a caller the model it names."""
    import volviz.model.settings as M

    for kind, model in SETTINGS_MODELS.items():
        assert type(typed_settings(kind, {})) is model
    fog = M.validated(FogSettings, {"density": 0.2})
    assert type(fog) is FogSettings and fog.density == 0.2
    with pytest.raises(SettingsError) as info:
        M.validated(M.CloudSettings, {"shape": [2, 129, 17]}, "component 'c' settings")
    assert info.value.problems == [("component 'c' settings.shape", "Value error, each size must be in 3..1025")]


def test_a_session_saved_with_the_former_colour_key_opens_and_saves_color(tmp_path):
    """Sessions written before the API spelt it "color" name the fog's color "colour": they open with that color
    and are saved with "color"."""
    doc = {"format": "volviz-session", "version": 1,
           "components": [{"id": "fog", "type": "fog", "settings": {"density": 0.1, "colour": [0.85, 0.87, 0.95]}}]}
    path = tmp_path / "old.json"
    path.write_text(json.dumps(doc))
    session = S.load(path)
    assert session.components[0].settings == {"density": 0.1, "color": [0.85, 0.87, 0.95]}
    assert typed_settings("fog", session.components[0].settings).color == (0.85, 0.87, 0.95)
    assert typed_settings("fog", doc["components"][0]["settings"]).color == (0.85, 0.87, 0.95)
    S.save(session, tmp_path / "new.json")
    saved = json.loads((tmp_path / "new.json").read_text())
    assert saved["components"][0]["settings"] == {"density": 0.1, "color": [0.85, 0.87, 0.95]}
    SessionDocument.model_validate(saved)


def test_the_shown_array_key_of_every_component_type_is_a_setting():
    from volviz.model.settings import array_key

    for kind, model in SETTINGS_MODELS.items():
        if "array" in model.model_fields or "scalars" in model.model_fields:
            assert typed_settings(kind, {array_key(kind): "Density:1"}).model_dump()[array_key(kind)] == "Density:1"
    with pytest.raises(SettingsError, match=r"settings\.array: unknown setting"):
        typed_settings("isosurface", {"array": "Density"})
