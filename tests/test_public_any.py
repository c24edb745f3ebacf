"""Typed seams (issue #31): no ``Any`` in the public signatures of ``volviz.render``, ``volviz.scene`` and
``volviz.model`` where a real type exists, and every registered view satisfies its protocol
(``volviz.render.views.View`` / ``ComponentView``) as mypy checks it.

``public_any_signatures`` lists every public function and method (name not starting with "_", in a public class)
whose parameter or return annotation contains ``Any``; ``ALLOWED`` names those that stay ``Any`` and why. A new one
fails the test (give it a real type, or an entry with its reason); so does an entry that no longer has ``Any``."""
from __future__ import annotations

import ast
import shutil
import subprocess
import sys
from collections import Counter
from pathlib import Path
from typing import Iterator, Union

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("render", "scene", "model")


def _has_any(node: Union[ast.expr, None]) -> bool:
    """Whether an annotation names ``Any`` (``Any``, ``typing.Any``, or inside a quoted annotation)."""
    for n in ast.walk(node) if node is not None else ():
        if isinstance(n, ast.Name) and n.id == "Any" or isinstance(n, ast.Attribute) and n.attr == "Any":
            return True
        if isinstance(n, ast.Constant) and isinstance(n.value, str):
            try:
                if _has_any(ast.parse(n.value, mode="eval").body):
                    return True
            except SyntaxError:
                pass
    return False


def _signature_has_any(f: Union[ast.FunctionDef, ast.AsyncFunctionDef]) -> bool:
    a = f.args
    args = a.posonlyargs + a.args + a.kwonlyargs + [x for x in (a.vararg, a.kwarg) if x is not None]
    return any(_has_any(x.annotation) for x in args) or _has_any(f.returns)


def _public_functions(body: list[ast.stmt], prefix: str = "") -> Iterator[tuple[str, ast.AST]]:
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and not node.name.startswith("_"):
            yield prefix + node.name, node
        elif isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
            yield from _public_functions(node.body, prefix + node.name + ".")


def public_any_signatures(root: Path = ROOT, packages: tuple[str, ...] = PACKAGES) -> list[str]:
    """``"volviz.render.module:Class.method"`` for every public function or method of ``volviz.<package>`` whose
    signature's annotations contain ``Any``."""
    out: list[str] = []
    for package in packages:
        for path in sorted((root / "volviz" / package).rglob("*.py")):
            module = ".".join(path.relative_to(root).with_suffix("").parts)
            tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
            out += [f"{module}:{name}" for name, f in _public_functions(tree.body)
                    if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef)) and _signature_has_any(f)]
    return out


VIEWS_OF_EACH_REQUEST = (
    "views of several classes, each with its own request type (View[LodRequest], View[NatureRequest], "
    "View[OrderRequest], View[OverlayRequest]), each paired with its own request and result: each pair's types are "
    "those of its view, an existential type that Python's type system cannot write (a Union of the views loses the "
    "pairing: compute(request) would be refused for every view but one), so the element type is View[Any]")

#: the public signatures allowed to keep ``Any``, with the reason
ALLOWED: dict[str, str] = {
    "volviz.render.controller:SceneController.compute_views": VIEWS_OF_EACH_REQUEST,
    "volviz.render.controller:SceneController.finish_views": VIEWS_OF_EACH_REQUEST,
}


def test_public_signatures_have_no_new_any() -> None:
    found = public_any_signatures()
    new = sorted(set(found) - set(ALLOWED))
    assert not new, "Any in a public signature (give it a real type, or add it to ALLOWED with the reason):\n" + \
        "\n".join(new)


def test_allowed_any_entries_still_exist() -> None:
    """An entry whose signature lost its ``Any`` (or moved) leaves the list, so the list stays what remains."""
    stale = sorted(set(ALLOWED) - set(public_any_signatures()))
    assert not stale, "no longer Any in a public signature; remove from ALLOWED:\n" + "\n".join(stale)


def test_the_counter_sees_any_wherever_it_is_written(tmp_path: Path) -> None:
    pkg = tmp_path / "volviz" / "scene"
    pkg.mkdir(parents=True)
    (pkg / "m.py").write_text(
        "from typing import Any\nimport typing\n"
        "def a(x: Any) -> int: ...\n"
        "def b(x: int) -> dict[str, Any]: ...\n"
        "def c(*r: 'Any') -> None: ...\n"
        "def d(**k: typing.Any) -> None: ...\n"
        "def e(x: int) -> int: ...\n"
        "def _f(x: Any) -> None: ...\n"
        "class C:\n"
        "    def g(self, x: 'list[Any]') -> None: ...\n"
        "    def _h(self, x: Any) -> None: ...\n"
        "class _D:\n"
        "    def g(self, x: Any) -> None: ...\n", encoding="utf-8")
    assert public_any_signatures(tmp_path, ("scene",)) == [
        "volviz.scene.m:a", "volviz.scene.m:b", "volviz.scene.m:c", "volviz.scene.m:d", "volviz.scene.m:C.g"]


#: each registered view's request and result types (``View[Request, *Results]``), as mypy checks them: the imports
#: (one line) and the type arguments
_ND, _NATURE = "from numpy import ndarray", "from volviz.render.nature_view import NatureRequest"
_TERRAIN = "from volviz.nature.terrain import TerrainMesh"
REQUESTS: dict[tuple[str, str], tuple[str, str]] = {
    ("pt", "gpu"): ("from volviz.render.gl_pt_order import OrderRequest; "
                    "from volviz.unstructured.sort import SortResult", "OrderRequest, SortResult | None"),
    ("pt", "cpu"): (f"from volviz.render.image_overlay import OverlayRequest; {_ND}; "
                    "from volviz.unstructured.render import UnstructuredRenderStats",
                    "OverlayRequest, ndarray, UnstructuredRenderStats, ndarray"),
    ("nature", "gpu"): (f"{_NATURE}; {_TERRAIN}; from volviz.render.gl_nature import GLNatureFrame",
                        "NatureRequest, TerrainMesh | None, GLNatureFrame, dict[str, float]"),
    ("nature", "cpu"): (f"{_NATURE}; {_TERRAIN}; {_ND}",
                        "NatureRequest, TerrainMesh | None, ndarray, dict[str, float]"),
    ("iso", "gpu"): ("", "None"),
    ("iso", "cpu"): (f"from volviz.render.image_overlay import OverlayRequest; {_ND}; "
                     "from volviz.render.iso_overlay import IsoStats", "OverlayRequest, ndarray, IsoStats, ndarray"),
    ("lod", "cpu"): ("from volviz.render.lod_volume import LodRequest; from volviz.regular.lod import Block, Selection",
                     "LodRequest, Selection, list[Block], float, float"),
}


def test_every_registered_view_satisfies_its_protocol(tmp_path: Path) -> None:
    """mypy checks each class of ``VIEWS`` against ``View`` of its request type (``REQUESTS``) and each of
    ``COMPONENT_VIEWS`` against ``ComponentView`` (an assignment to ``type[...]`` per class, in a file made from the
    registries), and sees a class that is no view, and a view of another request type, refused."""
    from volviz.render.views import COMPONENT_VIEWS, VIEWS

    mypy = shutil.which("mypy", path=str(Path(sys.executable).parent)) or shutil.which("mypy")
    assert mypy is not None, "mypy is a test dependency (pip install -e .[test])"
    assert set(REQUESTS) == set(VIEWS), "name the request type of every registered view in REQUESTS"
    checks = [(spec, f"View[{REQUESTS[key][1]}]") for key, spec in VIEWS.items()]
    checks += [(spec, "ComponentView") for specs in COMPONENT_VIEWS.values() for spec in specs]
    lines = ["from typing import Any", "from volviz.render.views import ComponentView, View"]
    lines += sorted({imp for imp, _ in REQUESTS.values() if imp})
    for i, (spec, protocol) in enumerate(checks):
        module, name = spec.split(":")
        lines += [f"from {module} import {name} as _C{i}", f"_v{i}: type[{protocol}] = _C{i}"]
    # what must be refused, so a check that cannot fail is seen failing: no view at all, and another request type
    lines += ["from volviz.model.clip import ClipSettings", "_bad: type[View[Any]] = ClipSettings"]
    lines += [f"from {VIEWS[('lod', 'cpu')].split(':')[0]} import LodVolume",
              "_wrong: type[View[NatureRequest, Selection, list[Block], float, float]] = LodVolume"]
    source = tmp_path / "view_protocols.py"
    source.write_text("\n".join(lines) + "\n", encoding="utf-8")
    done = subprocess.run([mypy, "--config-file", str(ROOT / "pyproject.toml"), str(source)], cwd=ROOT,
                          capture_output=True, text=True, timeout=600)
    errors = [line for line in done.stdout.splitlines() if ": error:" in line]
    assert len(checks) == len(set(checks)) >= 12
    expected = [f"{source.name}:{len(lines) - 2}:", f"{source.name}:{len(lines)}:"]
    assert len(errors) == 2 and all(e in error for e, error in zip(expected, errors)), done.stdout[-4000:]


def _count_by_package() -> Counter[str]:
    return Counter(name.split(".")[1] for name in public_any_signatures())


if __name__ == "__main__":   # the count per package, for the note
    print(dict(_count_by_package()), sum(_count_by_package().values()))
