"""The isosurface scene component: session settings and the builder's calls (prepare in the background, render)."""
from __future__ import annotations

import json

import numpy as np
import pytest

from conftest import data_file
from volviz.model.clip import BoxCrop, ClipPlane, ClipSettings
from volviz.iso.composite import render
from volviz.iso.extract import IsoStyle
from volviz.iso.component import IsoSettings, prepare, render_iso
from volviz.optics.metrics import max_abs
from volviz.model.camera import Camera

SETTINGS = IsoSettings([IsoStyle(30, (0.2, 0.45, 1.0), 0.3), IsoStyle(150, (1.0, 0.25, 0.1), 1.0)], mode="3pass",
                       clip=ClipSettings((ClipPlane((13.5, 0, 0), (-1, 0, 0)),), BoxCrop((0, 0, 0), (27, 27, 15))),
                       lod=True)


def test_settings_round_trip_and_named_errors():
    d = json.loads(json.dumps(SETTINGS.to_dict()))
    back = IsoSettings.from_dict(d)
    assert back.to_dict() == SETTINGS.to_dict()
    with pytest.raises(ValueError, match="mode"):
        IsoSettings.from_dict({"mode": "5pass"})
    with pytest.raises(ValueError, match=r"styles\[0\]"):
        IsoSettings.from_dict({"styles": [{"value": 1, "opacity": 3}]})
    with pytest.raises(ValueError, match="unknown"):
        IsoSettings.from_dict({"colour": 1})


def test_prepare_storm_series_clips_and_renders_like_the_direct_call():
    import volviz.io
    storm = volviz.io.read(str(data_file("storm/Storm.pvm-t01")).replace("t01", "t%02d"))
    prep = prepare(storm, SETTINGS, t=14.5)
    assert len(prep.meshes) == 2 and prep.meshes[0].n_triangles > 100
    for m in prep.meshes:
        assert SETTINGS.clip.inside(m.points, tol=1e-6).all()
    assert prep.chains is not None and prep.chains[0].triangle_counts[0] == prep.meshes[0].n_triangles
    cam = Camera.orbit(np.array([[0, 0, 0], [27, 27, 22.0]]), distance=2.5)
    no_lod = IsoSettings.from_dict({**SETTINGS.to_dict(), "lod": False})
    img, stats = render_iso([prepare(storm, no_lod, t=14.5)], no_lod, cam, (64, 64))
    direct, _ = render(prep.meshes, cam, (64, 64), "3pass")
    assert max_abs(img, direct) < 1e-9 and stats.triangles == sum(m.n_triangles for m in prep.meshes)
    _, near = render_iso([prep], SETTINGS, cam, (256, 256))
    far_cam = Camera.orbit(np.array([[0, 0, 0], [27, 27, 22.0]]), distance=40.0)
    _, far = render_iso([prep], SETTINGS, far_cam, (256, 256))
    assert far.triangles < near.triangles <= stats.triangles
