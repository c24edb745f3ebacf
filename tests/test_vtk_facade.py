"""Issue #31, one VTK import style: ``volviz.render.vtk_facade.vtk`` holds the VTK classes volviz uses, each imported
by name from its ``vtkmodules`` module, not VTK's all-in-one ``vtk`` module (about 150 modules). Its callers use
``vtk.vtkFoo`` as before, so the namespace must hold every name they use (a missing one fails only when that code
runs) and, to stay the list of what volviz uses, nothing else; and a whole ``volviz render`` loads no ``vtk``."""
from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np
from conftest import REPO, data_file

from volviz.bench.unstructured import VTK_MAPPERS
from volviz.render.vtk_facade import vtk

FACADE = "volviz.render.vtk_facade"


def names_used_through_the_facade(base: Path, parts: list[str]) -> dict[str, set[str]]:
    """``vtk.NAME`` -> the files using it, over the files under ``base / part`` that import ``vtk`` from the facade
    (under any alias) or are the facade."""
    used: dict[str, set[str]] = {}
    for path in sorted(p for part in parts for p in (base / part).rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        aliases = {a.asname or a.name for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)
                   and node.module == FACADE for a in node.names if a.name == "vtk"}
        if path == base / "volviz" / "render" / "vtk_facade.py":
            aliases.add("vtk")
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in aliases:
                used.setdefault(node.attr, set()).add(path.relative_to(base).as_posix())
    return used


def test_the_namespace_holds_exactly_the_names_its_callers_use():
    used = names_used_through_the_facade(REPO, ["volviz", "app", "tests"])
    for name in VTK_MAPPERS:                     # the unstructured bench's peers, taken by name with getattr
        used.setdefault(name, set()).add("volviz/bench/unstructured.py")
    held = set(vars(vtk))
    missing = {name: sorted(files) for name, files in used.items() if name not in held}
    assert missing == {}, "import these by name in volviz/render/vtk_facade.py"
    assert sorted(held - set(used)) == [], "no caller uses these any more: drop them from volviz/render/vtk_facade.py"
    assert {getattr(vtk, n).__module__.partition(".")[0] for n in held if not n.startswith("VTK_")} == {"vtkmodules"}


def test_the_scan_sees_a_use_through_an_alias_and_not_vtk_itself(tmp_path):
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "a.py").write_text(f"def f():\n    from {FACADE} import vtk as v\n    return v.vtkNotThere()\n")
    (tmp_path / "pkg" / "b.py").write_text("import vtk\nvtk.vtkElsewhere()\n")
    assert names_used_through_the_facade(tmp_path, ["pkg"]) == {"vtkNotThere": {"pkg/a.py"}}


PROBE = """
import json, sys
{prelude}
from volviz.cli import main
code = main(["render", sys.argv[1], "-o", sys.argv[2], "--size", "160x120"])
print(json.dumps({{"code": code, "vtk": "vtk" in sys.modules, "facade": "volviz.render.vtk_facade" in sys.modules}}))
"""


def _render_in_a_fresh_interpreter(out: Path, prelude: str = "") -> dict:
    done = subprocess.run([sys.executable, "-c", PROBE.format(prelude=prelude), str(data_file("volumes/embryo.slc")),
                           str(out)], cwd=REPO, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_volviz_render_loads_no_vtk_module(tmp_path):
    report = _render_in_a_fresh_interpreter(tmp_path / "x.png")
    assert report == {"code": 0, "vtk": False, "facade": True}
    image = iio.imread(tmp_path / "x.png")
    assert image.shape[:2] == (120, 160) and np.ptp(image[..., :3]) > 50      # the embryo drawn, not a blank frame


def test_the_probe_sees_vtk_loaded(tmp_path):
    """The same probe with ``import vtk`` before the render reports it (the check can fail)."""
    assert _render_in_a_fresh_interpreter(tmp_path / "x.png", "import vtk")["vtk"] is True
