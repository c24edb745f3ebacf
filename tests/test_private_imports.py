"""No module of ``volviz`` imports another module's private names (issue #31): ``from X import _name`` (or
``import X._name``), X another module of volviz, fails. A module may import its own package's private modules
(``from volviz.optics import _interp`` in ``volviz.optics``): that is the package keeping them to itself. Relative
imports are resolved first. The imports left that cannot be removed in this
change are listed below, each with its reason; none is in ``volviz.render``."""
from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# (importing module, imported module, name): why it stays. These helpers are shared inside their packages by modules
# that other changes own; each is to get a public name (or move to a private module of the package) there.
EXCEPTIONS: dict[tuple[str, str, str], str] = {
    ("volviz.io.bov", "volviz.io.raw", "_size_problem"): "the raw reader's size check, shared with the BOV reader",
    ("volviz.io.image", "volviz.io.vtkfiles", "_run"): "the VTK reader call, shared by the io readers",
    ("volviz.io.vtkhdf", "volviz.io.vtkfiles", "_run"): "the VTK reader call, shared by the io readers",
    ("volviz.iso.clip", "volviz.iso.extract", "_poly_to_arrays"): "extract's poly data conversion, shared in iso",
    ("volviz.regular.raycast", "volviz.optics.integrate", "_tf_arrays"): "the TF's arrays for the Numba kernels",
    ("volviz.regular.raycast_kernels", "volviz.optics.integrate", "_segment"): "the segment integral kernel",
    ("volviz.unstructured.project", "volviz.unstructured.raster", "_lookup"): "the table lookup kernel",
    ("volviz.unstructured.raster", "volviz.optics.integrate", "_linear_piece"): "the linear piece kernel",
    ("volviz.regular.lod", "volviz.regular.nodes", "_expand"): "the node codec's expansion, shared in regular",
    ("volviz.regular.nodes", "volviz.regular.codec", "_check_meta"): "the codec's header check, shared in regular",
    ("volviz.regular.nodes", "volviz.regular.codec", "_root_undpcm"): "the codec's root decoder, shared in regular",
    ("volviz.bench.robustness_formats", "volviz.regular.container", "_HDR"): "the .vvz header layout the robustness "
    "bench rewrites with checksums recomputed (343d945)",
}


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _is_private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def private_imports(module: str, source: str, is_package: bool = False) -> list[tuple[str, str, int]]:
    """(imported module, private name, line) of each import in ``source`` (the text of ``module``) that reaches a
    private name of another volviz module."""
    package = module if is_package else module.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            imported = [(target, alias.name) for alias in node.names]
        elif isinstance(node, ast.Import):
            imported = [(alias.name.rpartition(".")[0], alias.name.rpartition(".")[2]) for alias in node.names]
        else:
            continue
        for target, name in imported:
            if target.split(".")[0] != "volviz" or target == module or not _is_private(name):
                continue
            if module.startswith(target + ".") and _is_private_module(target, name):
                continue               # the importer's own package's private module
            found.append((target, name, node.lineno))
    return found


def _is_private_module(package: str, name: str) -> bool:
    """Whether ``package.name`` is a module (or package) of volviz, not a name defined in a module."""
    base = ROOT.joinpath(*package.split("."), name)
    return base.with_suffix(".py").exists() or (base / "__init__.py").exists()


def test_no_module_imports_another_modules_private_names():
    problems = []
    for path in sorted((ROOT / "volviz").rglob("*.py")):
        module = _module_name(path)
        for target, name, line in private_imports(module, path.read_text(encoding="utf-8"),
                                                  path.name == "__init__.py"):
            if (module, target, name) not in EXCEPTIONS:
                problems.append(f"{path.relative_to(ROOT)}:{line}: imports {name} from {target}")
    assert not problems, "\n".join(problems)
    assert not [key for key in EXCEPTIONS if key[0].startswith("volviz.render")]


def test_the_check_finds_what_it_forbids():
    """The rule on small sources: another module's private name, relative or absolute, and another package's
    private module are found; a package's own private module and public names are not."""
    bad = ("from volviz.render.gl_pt import _PASS_MARK\n"
           "from .gl_pt import _resolve_polydata\n"
           "from volviz.render import _prism_kernels\n")
    assert [(t, n) for t, n, _ in private_imports("volviz.render.gl_fog", bad)] == [
        ("volviz.render.gl_pt", "_PASS_MARK"), ("volviz.render.gl_pt", "_resolve_polydata")]
    assert [(t, n) for t, n, _ in private_imports("volviz.bench.nature", bad.replace("from .", "from volviz.render."))
            ] == [("volviz.render.gl_pt", "_PASS_MARK"), ("volviz.render.gl_pt", "_resolve_polydata"),
                  ("volviz.render", "_prism_kernels")]
    good = ("from volviz.optics import _interp\nfrom volviz.render.gl import ScenePass\n"
            "from volviz.optics._interp import lerp\nimport volviz.optics._interp\n")
    assert private_imports("volviz.optics.table3d", good) == []
