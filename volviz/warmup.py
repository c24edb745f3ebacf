"""Compile volviz's Numba kernels ahead of their first use (``volviz warmup``; the setup script runs it at install).

volviz's hot loops are Numba kernels cached on disk (``cache=True``). Without the cache, the first use of each one
compiles it: seconds of CPU per renderer, and while a worker compiles, Numba's compiler lock and the garbage it makes
stall every other thread that needs a kernel, the GUI thread included (event-loop stalls while the app loaded its first
tetrahedral scene on a fresh install, none with the cache: docs/bench/docstring-figures.md). Warming up renders each
kind of scene the app and the CLI draw (natural scene, tetrahedral volume, compressed level-of-detail volume,
isosurfaces and a blended volume of a time series), compresses with every coder and transform, and runs each
unstructured method, all at tiny sizes through the same code paths, so the kernels and the type signatures they are
called with are compiled once and written to the cache. First it writes the bytecode of volviz's modules
(``compile_bytecode``).
"""
from __future__ import annotations

import compileall
import json
import os
import py_compile
import sys
import tempfile
import time
from importlib.metadata import distributions
from importlib.util import find_spec
from pathlib import Path
from typing import Callable, Optional, Sequence

import numpy as np

from volviz.jobs import ProgressCallback, report

SIZE = (64, 48)
#: the bytecode's check against its module: a hash of the source, so that an edited module never runs stale bytecode
BYTECODE_CHECK = py_compile.PycInvalidationMode.CHECKED_HASH


def bytecode_folders() -> list[Path]:
    """The packages whose bytecode ``compile_bytecode`` writes: volviz's, its plugins' (entry points of a
    ``volviz.*`` group) and the app's, where each is a folder of source files (not in a frozen app)."""
    plugins = {ep.module.split(".")[0] for dist in distributions() for ep in dist.entry_points
               if ep.group.startswith("volviz.")}
    names = ["volviz", *sorted(plugins), "volviz_app"]
    folders: list[Path] = []
    for name in dict.fromkeys(names):
        spec = find_spec(name)
        for location in (spec.submodule_search_locations or []) if spec is not None else []:
            if Path(location).is_dir() and Path(location) not in folders:
                folders.append(Path(location))
    return folders


def compile_bytecode(folders: Optional[Sequence[Path]] = None) -> list[Path]:
    """Write the bytecode of every module under ``folders`` (default ``bytecode_folders``) that has none or whose
    source changed, checked against the source's hash (``BYTECODE_CHECK``); returns the folders written to. pip
    compiles a package it installs; an editable install, or ``PYTHONDONTWRITEBYTECODE`` (which stops Python writing
    what it compiles, not ``compileall``), leaves volviz's modules without bytecode, and every fresh process compiled
    the 120-odd modules a render imports again, a large share of each ``volviz render``'s start (issue #30, time to
    the first image; docs/bench/startup-cuts.md). Folders it may not write to (a system install) are left as they
    are."""
    if getattr(sys, "frozen", False):   # a frozen app runs its bundled bytecode
        return []
    written = [Path(f) for f in (bytecode_folders() if folders is None else folders) if os.access(f, os.W_OK)]
    for folder in written:
        compileall.compile_dir(str(folder), quiet=1, invalidation_mode=BYTECODE_CHECK)
    return written


def _blob(n: int, phase: float = 0.0) -> np.ndarray:
    """A smooth uint8 blob of n^3 voxels (Fortran order, as the readers return volumes)."""
    g = np.linspace(-1.0, 1.0, n)
    x, y, z = np.meshgrid(g, g, g, indexing="ij")
    field = 255.0 * np.exp(-3.0 * ((x - 0.2 * phase) ** 2 + y ** 2 + 1.5 * z ** 2))
    return np.asfortranarray(np.clip(field, 0, 255).astype(np.uint8))


def _render(doc: dict, folder: Path, name: str) -> None:
    # heavy: VTK's rendering and pydantic, loaded only when the warm-up runs (not at the CLI's import)
    from volviz.render.export import render_session
    from volviz.session import load

    path = folder / f"{name}.json"
    path.write_text(json.dumps({"format": "volviz-session", "version": 1, **doc}))
    render_session(load(path), path, SIZE)


def _natural_scene(folder: Path) -> None:
    # heavy: the natural scene's kernels and VTK's rendering, loaded only when the warm-up runs
    from volviz.nature.fog import FogLayer
    from volviz.render.export import render_session
    from volviz.render.gl_fog import prism_buffers
    from volviz.scene.demo import demo_session

    render_session(demo_session(), None, SIZE)
    # the GPU backend's fog prism buffers (its kernels run on the CPU; the GL drawing needs no warm-up)
    points = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    prism_buffers(points, points[:, 2], points[:, 2] + 1.0, np.array([[0, 1, 2]]), FogLayer())


def _tetrahedral_volume(folder: Path) -> None:
    from volviz.optics import TransferFunction
    from volviz.render.export import render_session
    from volviz.render.preview_upsample import upsample_preview   # the previews of a moving camera (the app's)
    from volviz.scene.demo import demo_volume_session
    from volviz.unstructured import render
    from volviz.model.camera import Camera
    from volviz.model.clip import BoxCrop, ClipSettings
    from volviz.unstructured.probe import probe_tetmesh
    from volviz.unstructured.synthetic import box_tets, holed_box

    render_session(demo_volume_session(), None, SIZE)
    mesh = box_tets(3)
    tf = TransferFunction([0.0, 0.5, 1.0], [[1, 0, 0], [0, 1, 0], [0, 0, 1]], [0.0, 4.0, 1.0])
    camera = Camera.orbit(mesh.points, 35, 25, 2.5)
    for lookup in ("separable", "3d"):
        for classification in ("post", "pre"):
            render(mesh, tf, camera, (24, 24), lookup=lookup, n_s=32, n_l=16, classification=classification)
    render(mesh, tf, camera, (24, 24), method="pt-st", n_s=32, n_l=16)
    render(mesh, tf, camera, (24, 24), method="reference")
    render(holed_box(4), tf, camera, (24, 24))  # a non-convex mesh: the sort's boundary-gap relations
    probe_tetmesh(mesh, camera.position, np.subtract(camera.focal_point, camera.position), tf)  # the app's probe
    clipped = demo_volume_session()
    clipped.clip = ClipSettings(box=BoxCrop((0.0, 0.0, 0.0), (0.5, 0.5, 0.5)))  # a cut mesh
    render_session(clipped, None, SIZE)
    upsample_preview(np.zeros((2, 2, 4)), np.full((2, 2), np.inf), np.full((4, 4), np.inf))


def _compressed_volume(folder: Path) -> None:
    # the wavelet codec's Numba kernels, loaded only when the warm-up runs
    from volviz.model.datasets import RegularVolume
    from volviz.regular.animation import compress_series, decompress_series
    from volviz.regular.codec import compress, decompress

    volume = RegularVolume(_blob(24))
    for coder in ("rans", "arith"):
        for transform in ("auto", "5/3", "haar"):
            out = folder / f"blob-{coder}-{transform.replace('/', '')}.vvz"
            compress(volume, out, mode="lossless", coder=coder, transform=transform)
            decompress(out)
        lossy = folder / f"blob-{coder}-q.vvz"
        compress(volume, lossy, quality=60.0, coder=coder)
        decompress(lossy)
    frames = [_blob(16, phase=t) for t in range(4)]  # a motion-compensated I/P/B series, lossless and lossy
    for mode, quality in (("lossless", None), ("quality", 60.0)):
        store = folder / f"series-{mode}.vvs"
        compress_series(frames, store, pattern="IBP", mode=mode, quality=quality)
        decompress_series(store)
    lod = folder / "lod.vvz"
    compress(RegularVolume(_blob(40)), lod, mode="lossless")
    _render({"datasets": [{"id": "blob", "path": str(lod), "options": {"lod": True}}],
             "components": [{"id": "blob", "type": "volume", "dataset": "blob", "settings": {"budget": 16}}],
             "camera": {"position": [120, -90, 80], "focal_point": [20, 20, 20], "view_up": [0, 0, 1]}},
            folder, "lod")


def _time_series(folder: Path) -> None:
    # heavy: PyVista and VTK's rendering, loaded only when the warm-up runs
    import pyvista as pv

    from volviz.render.controller import ISO_MODES

    for t in range(3):
        grid = pv.ImageData(dimensions=(24, 24, 24))
        grid.point_data["density"] = _blob(24, phase=t).ravel(order="F")
        grid.save(folder / f"series-t{t:02d}.vti")
    dataset = [{"id": "series", "path": str(folder / "series-t%02d.vti")}]
    camera = {"position": [80, -60, 50], "focal_point": [12, 12, 12], "view_up": [0, 0, 1]}
    for mode in ISO_MODES:  # every way the app composites semi-transparent isosurfaces (the CPU's Numba kernels)
        options = {"time": 0.5, "iso_mode": mode, "backend": "cpu"}
        _render({"datasets": dataset, "camera": camera, "render": {"options": options},
                 "components": [{"id": "iso", "type": "isosurface", "dataset": "series", "settings": {
                     "styles": [{"value": 60, "color": [0.2, 0.5, 1.0], "opacity": 0.4},
                                {"value": 160, "color": [1.0, 0.8, 0.2], "opacity": 0.7}]}}]}, folder, "iso")
    _render({"datasets": dataset, "camera": camera, "render": {"options": {"time": 1.5}},
             "components": [{"id": "vol", "type": "volume", "dataset": "series"}]}, folder, "blend")


#: the exercises, longest first (the codec's kernels take most of the compile time), so that parallel workers end
#: together
EXERCISES: list[tuple[str, Callable[[Path], None]]] = [
    ("compressed volume", _compressed_volume),
    ("tetrahedral volume", _tetrahedral_volume),
    ("natural scene", _natural_scene),
    ("time series", _time_series),
]


def _run_exercise(index: int) -> float:
    """Run ``EXERCISES[index]`` in a folder of its own; its seconds (a worker process's task)."""
    with tempfile.TemporaryDirectory(prefix="volviz-warmup-") as tmp:
        start = time.perf_counter()
        EXERCISES[index][1](Path(tmp))
        return time.perf_counter() - start


def warm_up(progress: Optional[ProgressCallback] = None, workers: Optional[int] = None) -> list[tuple[str, float]]:
    """Write volviz's bytecode (``compile_bytecode``), then run every exercise once (compiling, or loading from the
    cache, what it uses); returns (name, seconds): "bytecode", then the exercises in ``EXERCISES``' order. The
    exercises compile mostly disjoint kernels (Numba's cache takes concurrent writers), so they run in ``workers``
    processes at once (one per core, at most one per exercise; Numba compiles on one thread): on 2 cores the warm-up
    takes about its longest exercise instead of their sum."""
    # process pools (multiprocessing): only when the warm-up compiles in parallel
    from concurrent.futures import ProcessPoolExecutor, as_completed
    from multiprocessing import get_context

    report(progress, 0.0, "compiling volviz's modules to bytecode")
    start = time.perf_counter()
    compile_bytecode()
    timings = [("bytecode", time.perf_counter() - start)]
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    workers = max(1, min(len(EXERCISES), workers or cores))
    seconds: dict[int, float] = {}
    if workers == 1:
        for i, (name, _) in enumerate(EXERCISES):
            report(progress, i / len(EXERCISES), f"compiling the kernels of the {name}")
            seconds[i] = _run_exercise(i)
        report(progress, 1.0, "kernels compiled")
        return timings + [(name, seconds[i]) for i, (name, _) in enumerate(EXERCISES)]
    report(progress, 0.0, "compiling the kernels of " + ", ".join(name for name, _ in EXERCISES))
    with ProcessPoolExecutor(workers, mp_context=get_context("spawn")) as pool:
        futures = {pool.submit(_run_exercise, i): i for i in range(len(EXERCISES))}
        for future in as_completed(futures):
            seconds[futures[future]] = future.result()
            report(progress, len(seconds) / len(EXERCISES),
                   f"compiled the kernels of the {EXERCISES[futures[future]][0]}")
    report(progress, 1.0, "kernels compiled")
    return timings + [(name, seconds[i]) for i, (name, _) in enumerate(EXERCISES)]
