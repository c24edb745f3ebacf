"""Scene-wide clipping in the session file: schema, named errors, and sessions written before it existed."""
from __future__ import annotations

import json

import pytest

from volviz.model.clip import BoxCrop, ClipPlane, ClipSettings
from volviz.session import SessionError, dumps, loads

OLD = {"format": "volviz-session", "version": 1, "components": [{"id": "demo", "type": "demo"}]}


def test_session_without_clip_loads_with_no_clipping_and_round_trips():
    s = loads(json.dumps(OLD))
    assert s.clip == ClipSettings() and json.loads(dumps(s))["clip"] == {"planes": [], "box": None}
    clip = {"planes": [{"point": [1, 2, 3], "normal": [0, 0, 2]}], "box": {"lo": [0, 0, 0], "hi": [1, 1, 1]}}
    s = loads(json.dumps({**OLD, "clip": clip}))
    cs = s.clip                                # the typed model: its normal unit length (the same half-space)
    assert cs.planes[0] == ClipPlane((1.0, 2.0, 3.0), (0.0, 0.0, 1.0)) and cs.box == BoxCrop((0, 0, 0), (1, 1, 1))
    assert len(cs.all_planes()) == 7
    text = dumps(s)                            # saved in the model's form, which then saves byte for byte
    assert json.loads(text)["clip"] == {"planes": [{"point": [1.0, 2.0, 3.0], "normal": [0.0, 0.0, 1.0]}],
                                        "box": {"lo": [0.0, 0.0, 0.0], "hi": [1.0, 1.0, 1.0]}}
    back = loads(text)
    assert back.clip == s.clip and dumps(back) == text


@pytest.mark.parametrize("clip, field", [
    ({"planes": [{"point": [0, 0, 0], "normal": [0, 0, 0]}]}, "clip.planes[0].normal"),
    ({"planes": [{"point": [0, 0], "normal": [1, 0, 0]}]}, "clip.planes[0].point"),
    ({"planes": [], "box": {"lo": [1, 0, 0], "hi": [0, 1, 1]}}, "clip.box"),
    ({"planes": [], "bax": None}, "clip.bax"),
    ({"planes": {}}, "clip.planes"),
])
def test_bad_clip_names_the_field(clip, field):
    with pytest.raises(SessionError) as info:
        loads(json.dumps({**OLD, "clip": clip}))
    assert info.value.field == field
