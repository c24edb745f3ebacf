"""The `bench` extra beside the imaging plugin (issue #32): zfpy 1.0.1.post0 made numcodecs' version parsing fail,
so `import zarr` -- and every OME-Zarr open -- failed once `pip install -e .[bench]` was done. The extra pins a zfpy
numcodecs accepts; with the extra installed (CI installs it), zarr imports, numcodecs' ZFPY codec is live and an
OME-Zarr image opens."""
from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest
from packaging.requirements import Requirement

ROOT = Path(__file__).resolve().parents[1]


def _bench_requirement(name: str) -> Requirement:
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    return next(r for r in map(Requirement, extras["bench"]) if r.name == name)


def test_the_bench_extra_excludes_the_zfpy_numcodecs_cannot_parse():
    zfpy = _bench_requirement("zfpy")
    assert not zfpy.specifier.contains("1.0.1.post0")
    assert not zfpy.specifier.contains("1.0.0")  # built against NumPy 1: numcodecs turns it off under NumPy 2
    assert zfpy.specifier.contains("1.0.1")


def test_zarr_imports_and_an_ome_zarr_opens_with_the_bench_extra_installed(tmp_path):
    zfpy = pytest.importorskip("zfpy", reason="the bench extra is not installed here")
    from importlib.metadata import version

    import zarr
    from numcodecs import zfpy as codec

    assert _bench_requirement("zfpy").specifier.contains(version("zfpy")), "the installed zfpy is not the pinned one"
    assert codec._zfpy_version, "numcodecs turned its ZFPY codec off"
    values = np.linspace(0.0, 1.0, 4 * 5 * 6).reshape(4, 5, 6)
    assert np.abs(zfpy.decompress_numpy(zfpy.compress_numpy(values, tolerance=1e-6)) - values).max() < 1e-6
    import volviz.io as vio

    group = zarr.open_group(str(tmp_path / "img.ome.zarr"), mode="w", zarr_format=2)
    group.create_array("0", data=values.astype(np.float32))
    group.attrs["multiscales"] = [{"version": "0.4", "axes": [{"name": a, "type": "space"} for a in "zyx"],
                                   "datasets": [{"path": "0", "coordinateTransformations": [
                                       {"type": "scale", "scale": [1.0, 1.0, 1.0]}]}]}]
    volume = vio.read(tmp_path / "img.ome.zarr")
    assert volume.dimensions == (6, 5, 4)
