"""The layering of ``pyproject.toml``'s import-linter contracts holds: ``volviz`` never imports Qt (nor the app),
and each package imports only the layers below it (model at the bottom, then io and jobs, optics, the four method
packages, the session, render, the benches and the CLI)."""
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


def test_ruff_finds_nothing():
    """The code style of pyproject.toml's [tool.ruff] (errors, warnings, lines of at most 120 characters)."""
    ruff = shutil.which("ruff", path=str(Path(sys.executable).parent)) or shutil.which("ruff")
    assert ruff is not None, "ruff is a test dependency (pip install -e .[test])"
    done = subprocess.run([ruff, "check", "volviz", "app", "plugins"], cwd=ROOT, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
