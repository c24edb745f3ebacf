"""The check each install of ``packaging/check-installs.sh`` runs (issue #32), run in the test environment: every
reader's module imports, each extra's modules that are installed here import, and one file of each format of every
installed reader plugin opens (the shared data's ecosystem files, else files written with the formats' libraries).
The script itself makes one environment per install the README documents; CI runs it."""
from __future__ import annotations

import importlib.metadata as md
import subprocess
import sys
from pathlib import Path

from conftest import data_root

ROOT = Path(__file__).resolve().parents[1]


def test_this_install_imports_every_reader_and_opens_each_plugin_format():
    installed = {d.metadata["Name"] for d in md.distributions()}
    result = subprocess.run([sys.executable, str(ROOT / "packaging" / "check_install.py"), str(data_root()), "test"],
                            capture_output=True, text=True, timeout=600)
    lines = result.stdout.splitlines()
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-2000:]
    assert lines[0].startswith("ok     import volviz.io and every reader's module: ")
    opened = [line for line in lines if ": open " in line]
    assert all(line.startswith("ok     ") for line in lines[:-1])
    if "volviz-vtk-readers" in installed:
        assert any("volviz-vtk-readers: open fluent: room.cas.h5: UnstructuredMesh" in line for line in opened)
    if "volviz-imaging" in installed:
        assert any("volviz-imaging: open ome-zarr: image.zarr: RegularVolume, 120 points" in line for line in opened)
    assert lines[-1] == f"{len(lines) - 1} of {len(lines) - 1} checks passed"
