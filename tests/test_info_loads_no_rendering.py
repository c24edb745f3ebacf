"""Issue #31: ``volviz info FILE`` and the readers load no VTK rendering. A fresh interpreter runs what the command
runs (``volviz.cli.main(["info", FILE])``) after importing ``volviz.io`` and the scene layer's file rules, and lists
the rendering modules it loaded: VTK's rendering libraries and ``volviz.render``. The scene layer
(``volviz.scene``) is what lets ``info`` say which numbered series a file belongs to without the render layer."""
from __future__ import annotations

import json
import subprocess
import sys

from conftest import REPO, data_file

#: modules a process that only reads and describes data must not load
RENDERING = ("vtkmodules.vtkRenderingCore", "vtkmodules.vtkRenderingOpenGL2", "volviz.render")

PROBE = """
import json, sys
import volviz.io, volviz.scene.opening, volviz.scene.series, volviz.scene.datasets
from volviz.cli import main
code = main(["info", sys.argv[1]])
loaded = sorted(m for m in sys.modules if m.startswith({rendering!r}))
print(json.dumps({{"code": code, "loaded": loaded, "cli": "volviz.cli" in sys.modules}}))
"""


def _loaded_by_info(path: str) -> dict:
    done = subprocess.run([sys.executable, "-c", PROBE.format(rendering=RENDERING), path], cwd=REPO,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]    # the probe's own exit: main returns the command's code
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_volviz_info_loads_no_rendering_module():
    report = _loaded_by_info(str(data_file("volumes/embryo.slc")))
    assert report["code"] == 0 and report["cli"]
    assert report["loaded"] == []


def test_a_refused_file_loads_no_rendering_module(tmp_path):
    """A file ``volviz info`` refuses is one line and exit 2, and its error handling imports no render layer (the
    CLI's user errors are taken from the modules the command loaded: before, ``render.export`` was imported for its
    ExportError, VTK's rendering with it, 0.7-0.9 s of a refusal)."""
    bad = tmp_path / "bad.vti"
    bad.write_text("junk")
    report = _loaded_by_info(str(bad))
    assert report["code"] == 2
    assert report["loaded"] == []


def test_the_probe_sees_a_rendering_module():
    """The same probe, with the render layer imported on top, lists it (the check can fail). The scene builder
    imports VTK's rendering through the facade only where it draws (issue #31, start-up): the facade is imported too."""
    probe = PROBE.replace("from volviz.cli import main",
                          "import volviz.render.scene_builder, volviz.render.vtk_facade\nfrom volviz.cli import main")
    done = subprocess.run([sys.executable, "-c", probe.format(rendering=RENDERING),
                           str(data_file("volumes/embryo.slc"))], cwd=REPO, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    loaded = json.loads(done.stdout.strip().splitlines()[-1])["loaded"]
    assert {"volviz.render", "volviz.render.scene_builder", "vtkmodules.vtkRenderingCore"} <= set(loaded)
