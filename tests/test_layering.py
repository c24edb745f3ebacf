"""The layering of ``pyproject.toml``'s import-linter contracts holds: ``volviz`` never imports Qt (nor the app),
each package imports only the layers below it (model at the bottom, then io and jobs, optics, the four method
packages, the session, the scene layer, render, the benches and the CLI), and no module of render or scene is in an
import circle (issue #31). The names of issue #18 hold too: one spelling of color in the library, no two classes of
the same name in it and the app, no module named ``scene.py``; ruff and mypy find nothing."""
from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_import_contracts_are_kept():
    lint = shutil.which("lint-imports", path=str(Path(sys.executable).parent)) or shutil.which("lint-imports")
    assert lint is not None, "import-linter is a test dependency (pip install -e .[test])"
    done = subprocess.run([lint], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    assert "volviz never imports Qt KEPT" in done.stdout and "volviz's layers KEPT" in done.stdout
    assert "no import circle in render and scene KEPT" in done.stdout


def test_ruff_finds_nothing():
    """The code style of pyproject.toml's [tool.ruff] (errors, warnings, lines of at most 120 characters)."""
    ruff = shutil.which("ruff", path=str(Path(sys.executable).parent)) or shutil.which("ruff")
    assert ruff is not None, "ruff is a test dependency (pip install -e .[test])"
    done = subprocess.run([ruff, "check", "volviz", "app", "plugins"], cwd=ROOT, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]


def test_mypy_finds_nothing():
    """The types of pyproject.toml's [tool.mypy] (issue #18: not strict yet, the bodies of unannotated functions
    checked too) in the library, the app (the window and its parts, typed through ``volviz_app.window_base``) and the
    plugins."""
    mypy = shutil.which("mypy", path=str(Path(sys.executable).parent)) or shutil.which("mypy")
    assert mypy is not None, "mypy is a test dependency (pip install -e .[test])"
    done = subprocess.run([mypy, "volviz", "app", "plugins"], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]


def _trees(*packages: str):
    import ast

    for package in packages:
        for path in sorted((ROOT / package).rglob("*.py")):
            yield path.relative_to(ROOT), ast.parse(path.read_text(encoding="utf-8"), str(path))


def _identifiers(tree) -> list[tuple[int, str]]:
    """Every name a module defines or uses (modules, functions, classes, parameters, variables, attributes, keyword
    arguments, imported names) and the string keys of its dict literals (settings, stats, options)."""
    import ast

    out: list[tuple[int, str]] = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            out.append((node.lineno, node.name))
        elif isinstance(node, ast.arg):
            out.append((node.lineno, node.arg))
        elif isinstance(node, ast.Name):
            out.append((node.lineno, node.id))
        elif isinstance(node, ast.Attribute):
            out.append((node.lineno, node.attr))
        elif isinstance(node, ast.keyword) and node.arg is not None:
            out.append((node.value.lineno, node.arg))
        elif isinstance(node, ast.alias):
            out += [(node.lineno, part) for part in (node.asname or node.name).split(".")]
        elif isinstance(node, ast.ImportFrom) and node.module:
            out += [(node.lineno, part) for part in node.module.split(".")]
        elif isinstance(node, ast.Dict):
            out += [(k.lineno, k.value) for k in node.keys if isinstance(k, ast.Constant) and isinstance(k.value, str)]
    return out


def test_the_library_spells_color_one_way():
    """Issue #18: "color" in every name of the library (a former session key is read through a validation alias,
    a string, not a name)."""
    found = [f"{path}:{line}: {name}" for path, tree in _trees("volviz") for line, name in _identifiers(tree)
             if "colour" in name.lower()]
    found += [str(path) for path, _ in _trees("volviz") if "colour" in str(path).lower()]
    assert found == [], "\n".join(found)


def test_no_two_classes_share_a_name():
    """Issue #18: a class name says which class it is, across the library's layers and the app."""
    import ast
    from collections import defaultdict

    where: dict[str, list[str]] = defaultdict(list)
    for path, tree in _trees("volviz", "app"):
        for node in ast.walk(tree):
            if isinstance(node, ast.ClassDef):
                where[node.name].append(f"{path}:{node.lineno}")
    shared = {name: places for name, places in where.items() if len(places) > 1}
    assert shared == {}, shared


def test_no_module_is_named_scene():
    """Issue #18: the modules are named by what they hold (iso.component, render.scene_builder,
    nature.nature_scene), not "scene"."""
    named_scene = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "volviz").rglob("scene.py"))
    assert named_scene == [], f"modules named scene.py: {named_scene}"
