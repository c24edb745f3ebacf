"""The sky dome has no line across it at the horizon (issue #28: 'a thin line across the sky' in the demo)."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np

from volviz.scene.demo import demo_session
from volviz.session import save


def test_demo_sky_is_smooth_down_to_the_terrain(tmp_path: Path) -> None:
    session = demo_session()
    for comp in session.components:
        comp.visible = comp.type in ("terrain", "sky")
    save(session, tmp_path / "sky.json")
    out = tmp_path / "sky.png"
    proc = subprocess.run([sys.executable, "-m", "volviz.cli", "render", str(tmp_path / "sky.json"), "-o", str(out),
                           "--size", "1024x640"], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    img = np.asarray(iio.imread(out))[..., :3].astype(np.float64).sum(axis=2)
    steps = np.abs(np.diff(img[:, 100:920], axis=0)) > 60
    terrain_top = int(np.argmax(steps, axis=0).min())   # above the highest peak: the first big step down any column
    sky = img[:terrain_top - 2, 100:920]
    # the gradient brightens toward the horizon in steps of a few levels; a repeating texture blended the zenith's
    # colour into the horizon row: a row 45 levels (of 765) darker than both neighbours across the whole width
    dip = np.minimum(sky[:-2] - sky[1:-1], sky[2:] - sky[1:-1])
    assert terrain_top > 50 and dip.max() < 6, (terrain_top, dip.max())
