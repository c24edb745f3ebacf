"""``volviz warmup`` writes the bytecode of volviz's modules (issue #30, time to the first image): a fresh process then
imports them without compiling, even where ``PYTHONDONTWRITEBYTECODE`` keeps Python from writing it, and an edited
module never runs from bytecode of its old source."""
from __future__ import annotations

import os
import subprocess
import sys
from importlib.util import cache_from_source
from pathlib import Path

import volviz
from volviz.warmup import bytecode_folders, compile_bytecode

#: imports ``made.mod`` in a fresh interpreter, counting the modules compiled from source, and prints the count and
#: the module's VALUE
IMPORT_PROBE = """
import importlib.machinery
compiled = []
loader = importlib.machinery.SourceFileLoader
plain = loader.source_to_code
def counting(self, data, path, *args, **kwargs):
    compiled.append(path)
    return plain(self, data, path, *args, **kwargs)
loader.source_to_code = counting
from made import mod
print(len(compiled), mod.VALUE)
"""


def _import_in_fresh_process(root: Path) -> tuple[int, int]:
    env = {**os.environ, "PYTHONPATH": str(root), "PYTHONDONTWRITEBYTECODE": "1"}
    done = subprocess.run([sys.executable, "-c", IMPORT_PROBE], capture_output=True, text=True, env=env, timeout=60)
    assert done.returncode == 0, done.stderr
    count, value = done.stdout.split()
    return int(count), int(value)


def _made_package(root: Path) -> Path:
    package = root / "made"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "mod.py").write_text("VALUE = 1\n")
    return package


def test_a_compiled_package_imports_without_compiling(tmp_path: Path) -> None:
    package = _made_package(tmp_path)
    assert _import_in_fresh_process(tmp_path) == (2, 1)   # the package and its module, each compiled again
    assert not Path(cache_from_source(str(package / "mod.py"))).exists()
    assert compile_bytecode([package]) == [package]
    assert _import_in_fresh_process(tmp_path) == (0, 1)


def test_an_edited_module_never_runs_its_old_bytecode(tmp_path: Path) -> None:
    """The bytecode is checked against a hash of its source: an edit of the same size in the same second (which a
    check by modification time and size takes for no edit) runs the new source."""
    package = _made_package(tmp_path)
    compile_bytecode([package])
    source = package / "mod.py"
    stamp = source.stat()
    source.write_text("VALUE = 2\n")
    os.utime(source, ns=(stamp.st_atime_ns, stamp.st_mtime_ns))
    assert _import_in_fresh_process(tmp_path) == (1, 2)


def test_the_folders_are_volvizs_and_its_plugins_packages() -> None:
    import volviz_vtk_readers   # the reader plugin of VTK's formats, installed beside volviz

    folders = bytecode_folders()
    assert folders[0] == Path(volviz.__file__).parent
    assert Path(volviz_vtk_readers.__file__).parent in folders
    assert all((folder / "__init__.py").is_file() for folder in folders)
    assert len(set(folders)) == len(folders)

