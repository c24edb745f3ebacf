"""Issue #18's layering of VTK's rendering classes: nothing below ``volviz.render`` (model, io, jobs, optics, the four
method packages, the session, the scene layer) builds actors, mappers, renderers or plotters; VTK's data classes,
readers and filters are fine there. Read from the source (names imported or used), not from import-linter: it sees
``vtkmodules`` as one package and cannot tell ``vtkRenderingCore`` from ``vtkIOXML``. The iso-spectrum actor and the
transfer function's VTK functions live in ``volviz.render`` (``iso_spectrum``, ``vtk_tf``)."""
from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1] / "volviz"
BELOW_RENDER = ("model", "io", "jobs", "optics", "unstructured", "regular", "nature", "iso", "session.py", "scene")
RENDERING = re.compile(r"^(vtk\w*(Actor|Mapper|Renderer|RenderWindow|Texture|ShaderProperty|Light)\w*|vtkRendering\w+|"
                       r"Plotter|BackgroundPlotter|add_mesh|add_actor|add_volume)$")


def _rendering_names(path: Path) -> set[str]:
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Name):
            names.add(node.id)
        elif isinstance(node, ast.Attribute):
            names.add(node.attr)
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.update(node.module.split("."))
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.Import):
            names.update(part for a in node.names for part in a.name.split("."))
    return {n for n in names if RENDERING.match(n)}


def test_only_render_builds_vtk_actors():
    found = {}
    for part in BELOW_RENDER:
        files = [ROOT / part] if part.endswith(".py") else sorted((ROOT / part).rglob("*.py"))
        for f in files:
            names = _rendering_names(f)
            if names:
                found[f.relative_to(ROOT).as_posix()] = sorted(names)
    assert found == {}


def test_the_check_sees_a_rendering_class(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text("def f(plotter):\n    from vtkmodules.vtkRenderingCore import vtkActor\n"
                     "    return plotter.add_mesh(vtkActor())\n")
    assert _rendering_names(probe) == {"vtkRenderingCore", "vtkActor", "add_mesh"}
    probe.write_text("import vtk\nfrom vtkmodules.vtkIOXML import vtkXMLImageDataReader\n"
                     "r = vtk.vtkXMLUnstructuredGridReader()\n")
    assert _rendering_names(probe) == set()


def _imports_vtk(path: Path) -> bool:
    """Whether ``path`` imports VTK itself (``import vtk``, ``vtk.*``, ``vtkmodules.*``), not through the facade."""
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import) and any(a.name.split(".")[0] in ("vtk", "vtkmodules") for a in node.names):
            return True
        if isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] in ("vtk", "vtkmodules"):
            return True
    return False


def test_render_reaches_vtk_through_its_facade_only():
    """Issue #18: ``volviz.render.vtk_facade`` is the one module of ``volviz.render`` that imports VTK, and a module
    elsewhere in volviz that imports VTK itself (readers, filters) uses none of its rendering classes."""
    direct = {f.relative_to(ROOT).as_posix() for f in sorted(ROOT.rglob("*.py")) if _imports_vtk(f)}
    assert {f for f in direct if f.startswith("render/")} == {"render/vtk_facade.py"}
    assert {f: sorted(_rendering_names(ROOT / f)) for f in direct - {"render/vtk_facade.py"}
            if _rendering_names(ROOT / f)} == {}


def test_the_facade_check_sees_a_direct_import(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text("def f():\n    from vtkmodules.vtkRenderingCore import vtkActor\n    return vtkActor()\n")
    assert _imports_vtk(probe)
    probe.write_text("def f():\n    from volviz.render.vtk_facade import vtk\n    return vtk.vtkActor()\n")
    assert not _imports_vtk(probe)
