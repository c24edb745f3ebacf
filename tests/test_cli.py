"""The `volviz` command line: version, info, offscreen render, one-line errors, no Qt."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np

from conftest import data_file

import volviz
from volviz.cli import main


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "volviz.cli", *args], capture_output=True, text=True, timeout=300)


def test_version(capsys) -> None:
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"volviz {volviz.__version__}"


def test_render_demo_offscreen_without_qt(tmp_path: Path) -> None:
    out = tmp_path / "demo.png"
    code = (
        "import sys; from volviz.cli import main; rc = main(['render', 'demo', '-o', sys.argv[1], '--size', '320x200']);"
        "assert not [m for m in sys.modules if m.startswith(('PySide6', 'PyQt', 'pyvistaqt'))], 'Qt imported';"
        "sys.exit(rc)"
    )
    result = subprocess.run([sys.executable, "-c", code, str(out)], capture_output=True, text=True, timeout=300,
                            env={k: v for k, v in __import__("os").environ.items() if k != "DISPLAY"})
    assert result.returncode == 0, result.stderr
    image = iio.imread(out)
    assert image.shape[:2] == (200, 320)
    background = image[0, 0, :3].astype(int)
    differs = np.abs(image[..., :3].astype(int) - background).sum(axis=2) > 30
    assert differs.mean() > 0.05, "rendered image is blank"


def test_render_data_file_at_requested_size(tmp_path: Path) -> None:
    source = data_file("volumes/neghip.slc")
    out = tmp_path / "neghip.png"
    assert main(["render", str(source), "-o", str(out), "--size", "256x192"]) == 0
    image = iio.imread(out)
    assert image.shape[:2] == (192, 256)
    assert image[..., :3].std() > 5.0


def test_info_reports_kind_dimensions_and_range(capsys) -> None:
    source = data_file("volumes/neghip.slc")
    assert main(["info", "--json", str(source)]) == 0
    desc = json.loads(capsys.readouterr().out)
    assert desc["kind"] == "regular volume"
    assert desc["dimensions"] == [66, 66, 66]
    assert desc["points"] == 66 ** 3
    assert 0 <= desc["range"][0] < desc["range"][1] <= 255


def test_user_errors_are_one_line_and_nonzero(tmp_path: Path) -> None:
    bad = tmp_path / "broken.pvm"
    bad.write_bytes(b"PVM\n100000 100000 100000\n1\n" + b"\0" * 100)
    for args, words in [
        (["info", str(bad)], "broken.pvm"),
        (["info", str(tmp_path / "missing.slc")], "missing.slc"),
        (["render", "demo", "-o", str(tmp_path / "x.png"), "--size", "big"], "WIDTHxHEIGHT"),
        (["frobnicate"], "invalid choice"),
        (["compress", str(bad), "-o", str(tmp_path / "x.vvz"), "--quality", "80", "--transform", "haar"],
         "--transform applies to lossless files"),
        (["compress", str(bad), "-o", str(tmp_path / "x.vvz"), "--scheduler", "tcp://127.0.0.1:1"],
         "--scheduler applies to --series"),
    ]:
        result = run_cli(*args)
        assert result.returncode == 2, (args, result.stderr)
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("volviz: error:"), result.stderr
        assert words in lines[0]
        assert "Traceback" not in result.stderr


def test_info_on_a_compressed_series(tmp_path: Path, capsys) -> None:
    storm = data_file("storm/Storm.pvm-t01").parent
    out = tmp_path / "storm.vvs"
    assert main(["compress", str(storm / "Storm.pvm-t%02d"), "-o", str(out), "--series", "--lossless"]) == 0
    capsys.readouterr()
    assert main(["info", "--json", str(out)]) == 0
    desc = json.loads(capsys.readouterr().out)
    assert desc["n"] == 21 and desc["dims"] == [28, 28, 23] and desc["mode"] == "lossless"
    assert desc["ratio"] > 1.0


def test_compress_transform_choice(tmp_path: Path, capsys) -> None:
    """``--transform``: "5/3" codes no node with the S-transform, "auto" keeps the smaller of both per node (never
    larger than the 5/3 alone), and both files decode to the same, original voxels."""
    from volviz.io import read
    from volviz.regular.codec import decompress, info

    src = data_file("volumes/neghip.slc")
    files = {t: tmp_path / f"{t.replace('/', '')}.vvz" for t in ("5/3", "auto")}
    for transform, out in files.items():
        assert main(["compress", str(src), "-o", str(out), "--transform", transform, "--quiet"]) == 0
    capsys.readouterr()
    only_53, auto = info(files["5/3"]), info(files["auto"])
    assert only_53["haar_bricks"] == 0 and auto["haar_bricks"] > 0
    assert auto["file_bytes"] <= only_53["file_bytes"]
    original = read(src).data
    for out in files.values():
        assert np.array_equal(decompress(out).data, original)


def test_output_cut_short_by_the_reader_is_not_an_error() -> None:
    """``volviz info FILE | head -1``: the reader closing the pipe early ends volviz quietly."""
    src = data_file("volumes/neghip.slc")
    result = subprocess.run(f'"{sys.executable}" -m volviz.cli info "{src}" | head -c 1', shell=True,
                            capture_output=True, text=True, timeout=300)
    assert result.stdout and "error" not in result.stderr and "Traceback" not in result.stderr, result.stderr


WARMUP_PROBE = """
import sys
from numba.core import event
compiled = []
class Count(event.Listener):
    def on_start(self, ev): pass
    def on_end(self, ev): compiled.append(ev.data["dispatcher"].py_func.__qualname__)
event.register("numba:compile", Count())
from volviz.cli import main
from volviz.warmup import warm_up
if sys.argv[1] == "cli":
    rc = main(["warmup"])         # the exercises in worker processes at once
else:
    print(warm_up(workers=1))     # every exercise in this process, where its compilations are counted
    rc = 0
assert not [m for m in sys.modules if m.startswith(("PySide6", "PyQt", "pyvistaqt"))], "Qt imported"
print("compiled:", len(compiled), sorted(set(compiled)))
sys.exit(rc)
"""


def test_warmup_leaves_every_kernel_it_uses_in_the_disk_cache() -> None:
    """`volviz warmup` draws each kind of scene and runs each codec; run again in a new process, it finds every kernel
    it needs in Numba's disk cache and compiles none (a kernel that cannot be cached would compile in every process,
    on the user's first scene). The first run is the command (its exercises in worker processes at once), the
    second runs every exercise in one process, where Numba's compile events are counted."""
    env = {k: v for k, v in __import__("os").environ.items() if k != "DISPLAY"}
    runs = [subprocess.run([sys.executable, "-c", WARMUP_PROBE, mode], capture_output=True, text=True, timeout=900,
                           env=env) for mode in ("cli", "in-process")]
    for result in runs:
        assert result.returncode == 0, result.stderr
        assert all(name in result.stdout for name in ("natural scene", "tetrahedral volume", "compressed volume",
                                                      "time series")), result.stdout
    assert "compiled: 0 []" in runs[1].stdout, runs[1].stdout


def test_gpu_render_ends_cleanly(tmp_path: Path) -> None:
    """A session on the GPU backend (a GPU PT volume and its float32 render pass, isosurfaces in exact mode through
    the peeling layer) rendered offscreen: the views are taken out before the plotter closes, so VTK reports no GL
    resource left behind (it printed "FrameBufferObject should have been deleted" on every GPU export)."""
    storm = data_file("storm/Storm.pvm-t01").parent
    session = tmp_path / "gpu.json"
    session.write_text(json.dumps({
        "format": "volviz-session", "version": 1,
        "datasets": [{"id": "storm", "path": str(storm / "Storm.pvm-t%02d")}],
        "components": [{"id": "iso", "type": "isosurface", "dataset": "storm",
                        "settings": {"styles": [{"value": 30, "color": [0.3, 0.5, 1.0], "opacity": 0.4}]}},
                       {"id": "demo", "type": "demo", "settings": {"cells_per_edge": 6}}],
        "camera": {"position": [90, -60, 60], "focal_point": [12, 12, 10], "view_up": [0, 0, 1]},
        "render": {"options": {"time": 3.0, "backend": "gpu", "iso_mode": "exact"}}}))
    out = tmp_path / "gpu.png"
    result = run_cli("render", str(session), "-o", str(out), "--size", "160x120")
    assert result.returncode == 0, result.stderr
    assert iio.imread(out)[..., :3].std() > 5.0
    assert "ERR|" not in result.stderr and "should have been deleted" not in result.stderr, result.stderr
