"""What one install must do (issue #32), run inside it by ``packaging/check-installs.sh``: import every reader's
module (volviz's own and each installed plugin's, every plugin loading without a warning), import what each
installed extra brings, and open one file of each format of every installed reader plugin -- the shared data's
``ecosystem`` files where it has one, else a small file written with the format's own library (the robustness
bench's seeds, ``volviz.bench.robustness_made`` / ``robustness_formats``). One line per check; exit status 1 when
any failed. Usage: ``python packaging/check_install.py DATA_FOLDER [EXTRA ...]``.
"""
from __future__ import annotations

import importlib
import importlib.metadata as md
import sys
import tempfile
import traceback
import warnings
from functools import partial
from pathlib import Path
from typing import Callable

#: the modules each extra of pyproject.toml brings
EXTRA_MODULES = {"movies": ["imageio_ffmpeg"], "bench": ["matplotlib", "zfpy", "blosc2", "zstandard"],
                 "cluster": ["dask.distributed"], "console": ["qtconsole", "ipykernel"], "packaging": ["PyInstaller"],
                 "test": ["pytest", "pytestqt", "hypothesis", "imageio", "importlinter", "mypy"]}
#: one file of each format of a reader plugin: a path under the data folder, or ("made", format) / ("seed", format)
#: for a file the robustness bench writes
PLUGIN_FILES: dict[str, dict[str, str | tuple[str, str]]] = {
    "volviz-vtk-readers": {"exodus": "ecosystem/disk_out_ref.ex2", "openfoam": "ecosystem/openfoam-cavity/case.foam",
                           "cgns": "ecosystem/sqnz_s.adf.cgns", "netcdf": "ecosystem/sampleCurveGrid4.nc",
                           "tecplot": "ecosystem/cellcentered.tec", "fluent": "ecosystem/fluent-room/room.cas.h5",
                           "xdmf": "ecosystem/dolfinx-function/no_checkpoint.xdmf", "ensight": ("seed", "ensight"),
                           "avs-ucd": ("seed", "avs-ucd")},
    "volviz-imaging": {"nifti": ("made", "nifti"), "nrrd": ("made", "nrrd"), "dicom": ("made", "dicom"),
                       "mrc": ("made", "mrc"), "cube": ("made", "cube"), "minc": ("seed", "minc"),
                       "ome-zarr": ("seed", "ome-zarr")},
    "volviz-astronomy": {"fits": ("made", "fits")},
    "volviz-geoscience": {"segy": ("made", "segy"), "las": ("made", "las"), "laz": ("seed", "laz")},
}


def _check(label: str, run: Callable[[], str]) -> bool:
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", ImportWarning)
            from volviz.io.registry import PluginWarning

            warnings.simplefilter("error", PluginWarning)
            detail = run()
    except BaseException as exc:  # the point: any failure of this install, said in one line
        last = traceback.format_exception_only(type(exc), exc)[-1].strip()
        print(f"FAILED {label}: {last[:300]}")
        return False
    print(f"ok     {label}{': ' + detail if detail else ''}")
    return True


def _readers() -> str:
    from volviz.io.registry import reader_specs

    specs = reader_specs(refresh=True)
    for spec in specs:
        spec.load_function()
    return f"{len(specs)} readers"


def _file(where: str | tuple[str, str], data: Path, folder: Path) -> Path:
    if isinstance(where, str):
        return data / where
    kind, fmt = where
    if kind == "made":
        from volviz.bench.robustness_made import write_made

        return write_made(folder / "made", [fmt])[fmt]
    from volviz.bench.robustness_formats import write_seeds

    seed, at = write_seeds(folder / "seeds", [fmt])[0]
    return at / seed.target


def _import(module: str) -> str:
    importlib.import_module(module)
    return ""


def _open(where: str | tuple[str, str], data: Path, folder: Path) -> str:
    import volviz.io as vio

    path = _file(where, data, folder)
    dataset = vio.read(path)
    return f"{path.name}: {type(dataset).__name__}, {getattr(dataset, 'n_points', 0):,} points"


def main(argv: list[str]) -> int:
    data, extras = Path(argv[0]), argv[1:]
    installed = {d.metadata["Name"] for d in md.distributions()}
    results = [_check("import volviz.io and every reader's module", _readers)]
    for extra in extras:
        for module in EXTRA_MODULES[extra]:
            results.append(_check(f"extra {extra}: import {module}", partial(_import, module)))
    with tempfile.TemporaryDirectory(prefix="volviz-check-install-") as tmp:
        for plugin, files in PLUGIN_FILES.items():
            if plugin not in installed:
                continue
            for fmt, where in files.items():
                results.append(_check(f"{plugin}: open {fmt}", partial(_open, where, data, Path(tmp))))
    if "volviz-dask" in installed:
        results.append(_check("volviz-dask: the compression backend loads", _dask_backend))
    print(f"{sum(results)} of {len(results)} checks passed")
    return 0 if all(results) else 1


def _dask_backend() -> str:
    backends = [ep for ep in md.entry_points(group="volviz.compression_backends") if ep.name == "dask"]
    if not backends:
        raise RuntimeError("no 'dask' entry point in volviz.compression_backends")
    backends[0].load()
    return "volviz_dask:run"


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
