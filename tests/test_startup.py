"""Issue #31, start-up: what a fresh ``volviz`` process imports on its way to an answer (docs/architecture.md
"Start-up"). ``volviz info`` of a file whose reader needs no Numba loads none of the heavy libraries; ``volviz render``
of a regular volume loads none of the layers that only other kinds of data use (the natural scene's kernels, the
isosurface kernels, the tetrahedral meshes' modules), and a mesh's render does load the mesh modules (the check can
fail). ``volviz render`` starts an isolated reader's child ahead of the render layer's imports."""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pyvista as pv

from conftest import REPO, data_file

#: heavy libraries a fresh ``volviz info`` of a plain regular volume must not load
HEAVY = ("numba", "scipy", "matplotlib", "dask", "pyvista", "pandas", "vtkmodules.vtkRenderingCore")
#: volviz layers a render of a regular volume must not load (imported where their data is drawn)
OTHER_KINDS = ("volviz.nature", "volviz.iso", "volviz.unstructured")

PROBE = """
import json, sys
from volviz.cli import main
code = main(sys.argv[2:])
watched = tuple(sys.argv[1].split(","))
print(json.dumps({"code": code, "loaded": sorted(m for m in sys.modules
                                                  if any(m == w or m.startswith(w + ".") for w in watched))}))
"""


def _loaded(*argv: str) -> list[str]:
    """The watched modules (and their submodules) a fresh interpreter has loaded after ``volviz ARGV``."""
    done = subprocess.run([sys.executable, "-c", PROBE, ",".join(HEAVY + OTHER_KINDS), *argv], cwd=REPO,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    report = json.loads(done.stdout.strip().splitlines()[-1])
    assert report["code"] == 0
    return report["loaded"]


def test_volviz_info_loads_no_heavy_library() -> None:
    assert _loaded("info", str(data_file("volumes/HeadMRVolume.mhd"))) == []


def test_rendering_a_regular_volume_loads_no_other_kind_of_view(tmp_path) -> None:
    loaded = _loaded("render", str(data_file("volumes/HeadMRVolume.mhd")), "-o", str(tmp_path / "v.png"),
                     "--size", "64x48")
    assert "pyvista" in loaded and "vtkmodules.vtkRenderingCore" in loaded      # it did render
    assert [m for m in loaded if m.startswith(OTHER_KINDS)] == []


def test_rendering_a_mesh_loads_the_mesh_modules(tmp_path) -> None:
    grid = pv.ImageData(dimensions=(4, 4, 4)).triangulate()      # tetrahedra
    grid.point_data["v"] = np.arange(grid.n_points, dtype=np.float64)
    grid.save(tmp_path / "mesh.vtu")
    loaded = _loaded("render", str(tmp_path / "mesh.vtu"), "-o", str(tmp_path / "m.png"), "--size", "64x48")
    assert "volviz.unstructured" in loaded and "volviz.nature" not in loaded
    assert [m for m in loaded if m.startswith("volviz.iso")] == []     # the isosurfaces' modules: only for a clip


def test_render_starts_an_isolated_reader_ahead() -> None:
    """``volviz render`` of a file read in a child starts the child before importing the render layer; a file
    read in-process starts none."""
    from volviz.cli import _start_reader
    from volviz.io import isolated

    isolated.shutdown()
    try:
        _start_reader(data_file("volumes/HeadMRVolume.mhd"), {})
        assert isolated._pool.idle_pids() == []
        _start_reader(data_file("volumes/hydrogen.vti"), {})
        assert len(isolated._pool.idle_pids()) == 1
    finally:
        isolated.shutdown()


def test_the_app_reports_its_first_frame() -> None:
    """``volviz-app --first-frame FILE`` (what ``volviz bench startup`` times): opens the file in a throwaway window,
    prints the epoch time of its first complete frame and the seconds since its ``main`` began, and exits 0."""
    import time

    start = time.time()
    done = subprocess.run([sys.executable, "-m", "volviz_app.main", "--first-frame",
                           str(data_file("volumes/HeadMRVolume.mhd"))], cwd=REPO, capture_output=True, text=True,
                          timeout=600)   # under pytest-xvfb's display
    end = time.time()
    assert done.returncode == 0, done.stderr[-3000:]
    line = [l for l in done.stdout.splitlines() if l.startswith("first frame ")]
    assert len(line) == 1
    at, since_main = (float(v) for v in line[0].split()[2:])
    assert start < at < end and 0 < since_main < at - start


READER_PROBE = """
import json, sys
from volviz.io import isolated
calls = []
plain = isolated.prewarm
def prewarm(*args, **kwargs):
    calls.append({"render_layer": "volviz.render.export" in sys.modules, "args": list(args), "kwargs": kwargs})
    plain(*args, **kwargs)
isolated.prewarm = prewarm
from volviz.cli import main
code = main(sys.argv[1:])
print(json.dumps({"code": code, "calls": calls}))
"""


def test_render_starts_the_reader_child_before_the_render_layer_for_its_read_at_hand(tmp_path) -> None:
    """The child's start (Python, numpy, ``volviz.io``) overlaps the render layer's imports, and the child, started
    for that one read, loads no reader's VTK modules while it waits for it."""
    done = subprocess.run([sys.executable, "-c", READER_PROBE, "render", str(data_file("volumes/hydrogen.vti")),
                           "-o", str(tmp_path / "h.png"), "--size", "64x48"], cwd=REPO, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    report = json.loads(done.stdout.strip().splitlines()[-1])
    assert report == {"code": 0, "calls": [{"render_layer": False, "args": [], "kwargs": {"idle_load": False}}]}


def _maps_vtk_module(pid: int, module: str) -> bool:
    with open(f"/proc/{pid}/maps") as maps:
        return module in maps.read()


def test_a_child_for_the_read_at_hand_loads_no_readers_vtk_modules_while_idle() -> None:
    """A child kept warm loads every reader's VTK modules while it waits (the Exodus reader's among them); one
    started for the read at hand (``worker.AT_HAND``) loads none of them in that time."""
    import time

    from volviz.io.isolated.worker import Worker

    warm, at_hand = Worker(), Worker(idle_load=False)
    try:
        warm.wait_ready()
        at_hand.wait_ready()
        deadline = time.monotonic() + 60
        while not _maps_vtk_module(warm.proc.pid, "vtkIOExodus") and time.monotonic() < deadline:
            time.sleep(0.1)
        assert _maps_vtk_module(warm.proc.pid, "vtkIOExodus")
        assert not _maps_vtk_module(at_hand.proc.pid, "vtkIOExodus")
        assert not _maps_vtk_module(at_hand.proc.pid, "vtkIOXML")
    finally:
        warm.close()
        at_hand.close()
