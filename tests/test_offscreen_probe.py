"""Issue #30, time to the first image: an offscreen plotter is made without pyvista's probe for an X server (a
``xset -q`` subprocess, and where xset is missing a throwaway OpenGL context), which only serves a warning about
on-screen windows; the plotter still draws."""
from __future__ import annotations

import json
import subprocess
import sys

from conftest import REPO

PROBE = """
import json
import numpy as np
import pyvista as pv
from volviz.render.offscreen import offscreen_plotter
from pyvista.plotting import plotter, tools
plotter_ = offscreen_plotter((80, 60))
plotter_.set_background("black")
plotter_.add_mesh(pv.Sphere(), color="white")
image = np.asarray(plotter_.screenshot(None, return_img=True))[..., :3]
plotter_.close()
print(json.dumps({"asked": [tools.SUPPORTS_PLOTTING, tools.SUPPORTS_OPENGL],
                  "skipped": plotter._warn_xserver.has_support,
                  "lit": int((image.max(axis=2) > 128).sum())}))
"""


def test_an_offscreen_plotter_asks_for_no_display_and_draws() -> None:
    done = subprocess.run([sys.executable, "-c", PROBE], cwd=REPO, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    report = json.loads(done.stdout.strip().splitlines()[-1])
    assert report["asked"] == [None, None] and report["skipped"] is True
    assert report["lit"] > 500
