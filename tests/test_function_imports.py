"""Imports inside functions only for optional or heavy dependencies, each with a one-line reason (issue #31).

An import whose nearest enclosing scope is a function (a lazy import: an optional package, a heavy one such as VTK's
rendering or Numba's kernels that only some commands need, or one that would close an import circle) carries its
reason as a comment: on its line, on the line right above it, or on any line of the run of consecutive import
statements it belongs to (one reason for a block of imports). Whether the reason is a good one is for review; this
test sees that one is written, and that no module gains a lazy import without one.

``REASONLESS`` was, per module, the lazy imports still without a reason, each module's ceiling; it is empty now:
every lazy import in ``volviz`` carries its reason.
"""
from __future__ import annotations

import ast
from pathlib import Path
from typing import Iterator, Union

ROOT = Path(__file__).resolve().parents[1]
Import = Union[ast.Import, ast.ImportFrom]


def _bodies(node: ast.AST, in_function: bool) -> Iterator[tuple[list[ast.stmt], bool]]:
    """Every statement list under ``node`` with whether it lies inside a function."""
    for name in ("body", "orelse", "finalbody"):
        body = getattr(node, name, None)
        if isinstance(body, list) and body and isinstance(body[0], ast.stmt):
            yield body, in_function
    for handler in getattr(node, "handlers", []):
        yield handler.body, in_function
    for case in getattr(node, "cases", []):
        yield case.body, in_function
    for child in ast.iter_child_nodes(node):
        if isinstance(child, ast.stmt):
            yield from _bodies(child, in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)))


def _runs(body: list[ast.stmt]) -> Iterator[list[Import]]:
    """The runs of consecutive import statements of one statement list."""
    run: list[Import] = []
    for stmt in body:
        if isinstance(stmt, (ast.Import, ast.ImportFrom)):
            run.append(stmt)
            continue
        if run:
            yield run
        run = []
    if run:
        yield run


def reasonless_imports(source: str) -> list[int]:
    """Line numbers of the function-level imports of ``source`` that carry no reason (see the module's docstring)."""
    lines = source.splitlines()
    tree = ast.parse(source)
    out: list[int] = []
    seen: set[int] = set()
    for body, in_function in _bodies(tree, False):
        if not in_function or id(body) in seen:
            continue
        seen.add(id(body))
        for run in _runs(body):
            first, last = run[0].lineno, run[-1].end_lineno or run[-1].lineno
            above = lines[first - 2].strip() if first >= 2 else ""
            if not (above.startswith("#") or any("#" in line for line in lines[first - 1:last])):
                out += [stmt.lineno for stmt in run]
    return sorted(out)


def reasonless_by_module(root: Path = ROOT) -> dict[str, int]:
    """``{"volviz/x.py": count}`` of the lazy imports without a reason, modules with none left out."""
    counts: dict[str, int] = {}
    for path in sorted((root / "volviz").rglob("*.py")):
        found = reasonless_imports(path.read_text(encoding="utf-8"))
        if found:
            counts[path.relative_to(root).as_posix()] = len(found)
    return counts


#: per module, the lazy imports without a reason when this test was written (issue #31); see the module's docstring
REASONLESS: dict[str, int] = {}


def test_no_module_gains_a_lazy_import_without_a_reason() -> None:
    found = reasonless_by_module()
    above = {m: (n, REASONLESS.get(m, 0)) for m, n in found.items() if n > REASONLESS.get(m, 0)}
    assert not above, ("imports inside functions without a one-line reason (a comment on the line, the line above, "
                       "or the block of imports), module: (found, allowed):\n" +
                       "\n".join(f"{m}: {n}" for m, n in sorted(above.items())))


def test_the_counter_sees_reasons_where_they_are_written() -> None:
    source = (
        "import json\n"                       # module level: not counted
        "def a():\n"
        "    import numpy\n"                  # 3: no reason
        "def b():\n"
        "    import vtk  # heavy: rendering only\n"
        "def c():\n"
        "    # optional: h5py may be missing\n"
        "    import h5py\n"
        "    from h5py import File\n"         # the same run: one reason for the block
        "def d():\n"
        "    x = 1\n"
        "    from numba import njit\n"        # 12: no reason
        "    if x:\n"
        "        from scipy import linalg\n"  # 14: inside a branch of a function, no reason
        "    def inner():\n"
        "        import pyvista  # heavy\n"
        "    return lambda: None\n"
        "class K:\n"
        "    import os\n"                     # a class body, not a function: not counted
        "    def m(self):\n"
        "        try:\n"
        "            import zarr\n"           # 22: no reason
        "        except ImportError:  # optional\n"
        "            pass\n")
    assert reasonless_imports(source) == [3, 12, 14, 22]


if __name__ == "__main__":   # the counts, for the note and for REASONLESS
    counts = reasonless_by_module()
    print(sum(counts.values()), "lazy imports without a reason in", len(counts), "modules")
    for module, n in sorted(counts.items()):
        print(f'    "{module}": {n},')
