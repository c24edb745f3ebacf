"""The command line as a user meets it: every command's --help, one-line usage errors for every bad argument, output
targets that are refused, image formats by extension, arrays, PLOT3D solution files, series members and movies."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from conftest import data_file

from volviz.cli import main

VOLVIZ = Path(sys.executable).with_name("volviz")  # the installed console script


def volviz(*args: str) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "DISPLAY"}
    return subprocess.run([str(VOLVIZ), *args], capture_output=True, text=True, timeout=300, env=env)


def one_line_error(capsys: pytest.CaptureFixture[str]) -> str:
    """The one line of the error (besides one-line warnings, e.g. of a file's NaN values)."""
    err = [line for line in capsys.readouterr().err.strip().splitlines() if not line.startswith("volviz: warning: ")]
    assert len(err) == 1 and err[0].startswith("volviz: error: "), err
    return err[0]


@pytest.mark.parametrize("args, words", [
    (["--help"], "{info,render,bench,compress,schema,warmup}"),
    (["info", "--help"], "--array"),
    (["render", "--help"], "--orbit"),
    (["bench", "--help"], "unstructured"),
    (["bench", "nature", "--help"], "--cloud-shape"),
    (["compress", "--help"], "--lossless"),
    (["warmup", "--help"], "usage: volviz warmup"),
    (["schema", "--help"], "--output"),
])
def test_every_command_answers_help(args: list[str], words: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(args) == 0
    out = capsys.readouterr().out
    assert out.startswith("usage: volviz") and words in out


def test_help_of_the_installed_command() -> None:
    for args in (["bench", "--help"], ["compress", "--help"], ["bench", "iso", "--help"]):
        result = volviz(*args)
        assert result.returncode == 0, result.stderr
        assert result.stdout.startswith("usage: volviz") and not result.stderr


@pytest.mark.parametrize("args, words", [
    (["render", "demo-volume", "-o", "x.png", "--size", "16384x16384"], "1..8192 on each side"),
    (["render", "demo-volume", "-o", "x.png", "--size", "0x48"], "--size"),
    (["render", "demo-volume", "-o", "x.mp4", "--orbit", "--fps", "nan"], "--fps"),
    (["render", "demo-volume", "-o", "x.mp4", "--orbit", "--fps", "0"], "--fps"),
    (["render", "demo-volume", "-o", "x.mp4", "--orbit", "--fps", "-1"], "--fps"),
    (["render", "demo-volume", "-o", "x.mp4", "--orbit", "--fps", "inf"], "--fps"),
    (["render", "demo-volume", "-o", "x.mp4", "--orbit", "--duration", "1e9"], "--duration"),
    (["render", "demo-volume", "-o", "x.mp4", "--orbit", "--duration", "-1"], "--duration"),
    (["render", "demo-volume", "-o", "x.mp4", "--orbit", "--duration", "nan"], "--duration"),
    (["render", "demo-volume", "-o", "x.mp4", "--orbit", "--duration", "3000", "--fps", "200"], "at most 100000"),
    (["render", "demo-volume", "-o", "x.png", "--duration", "2"], "applies to movies"),
    (["render", "demo-volume", "-o", "x.mp4", "--orbit", "--path", "p"], "give one"),
    (["render", "demo-volume", "-o", "x.gif"], "unknown image format .gif"),
    (["render", "demo-volume", "-o", "x.mp4"], "give --orbit, --time or --path"),
    (["render", "demo-volume", "-o", "x.png", "--orbit"], "a movie is written to"),
    (["render", "demo-volume", "-o", "x.png", "--array", "T"], "--array, --q and --option apply to data files"),
    (["render", "missing.slc", "-o", "x.png"], "missing.slc: no such file"),
    (["render", "demo-volume", "-o", "x.png", "--bogus"], "unrecognized arguments: --bogus"),
    (["info", "missing.slc", "--array", ""], "--array"),
    (["info", "missing.slc", "--array", "V:9"], "out of range"),
    (["bench"], "NAME"),
    (["bench", "nature", "--reps", "0"], "--reps"),
    (["bench", "nature", "--cloud-shape", "9x9"], "--cloud-shape"),
    (["bench", "nature", "--sweep", "2,10;x"], "--sweep"),
    (["bench", "unstructured", "--vtk", "vtkNoSuchMapper"], "vtkNoSuchMapper"),
    (["bench", "iso", "--size", "100000"], "--size"),
    (["bench", "tables", "--points", "-3"], "--points"),
    (["bench", "compression", "--volumes", "nope"], "--volumes"),
    (["compress", "in.slc", "-o", "x.vvz", "--quality", "-5"], "--quality"),
    (["compress", "in.slc", "-o", "x.vvz", "--quality", "nan"], "--quality"),
    (["compress", "in.slc", "-o", "x.vvz", "--psnr", "nan"], "--psnr"),
    (["compress", "in.slc", "-o", "x.vvz", "--raw", "0", "4", "4"], "--raw"),
    (["compress", "in.slc", "-o", "x.vvz", "--dtype", "complex"], "--dtype"),
    (["compress", "in", "-o", "x.vvs", "--series", "--pattern", "BIP"], "--pattern"),
])
def test_invalid_arguments_are_one_line_usage_errors(args: list[str], words: str, tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    """Refused when the command line is read, before any file is read or rendered (none of the inputs exist)."""
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        assert main(args) == 2
    finally:
        os.chdir(cwd)
    assert words in one_line_error(capsys)
    assert list(tmp_path.iterdir()) == []


def test_usage_errors_of_the_installed_command(tmp_path: Path) -> None:
    result = volviz("render", "demo-volume", "-o", str(tmp_path / "x.mp4"), "--orbit", "--fps", "nan")
    assert result.returncode == 2
    assert result.stderr.strip() == "volviz: error: argument --fps: must be a number more than 0 and at most 240, " \
                                    "got 'nan'"


def test_outputs_that_are_not_regular_files_are_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A device, FIFO, symbolic link or folder given to -o is refused with a message and left as it was."""
    fifo = tmp_path / "pipe.png"
    os.mkfifo(fifo)
    target = tmp_path / "kept.png"
    target.write_bytes(b"the user's")
    link = tmp_path / "link.png"
    link.symlink_to(target)
    folder = tmp_path / "folder.png"
    folder.mkdir()
    for out, words in [("/dev/null", "character device"), (fifo, "FIFO"), (link, "symbolic link"),
                       (folder, "folder")]:
        assert main(["render", "demo-volume", "-o", str(out), "--size", "64x48"]) == 2
        assert words in one_line_error(capsys)
    assert Path("/dev/null").is_char_device() and fifo.is_fifo() and link.is_symlink() and folder.is_dir()
    assert target.read_bytes() == b"the user's"
    frames = tmp_path / "frames"
    frames.write_bytes(b"the user's")
    assert main(["render", "demo-volume", "-o", str(frames), "--orbit", "--fps", "1", "--duration", "1"]) == 2
    assert "replaces only folders" in one_line_error(capsys)  # a movie's frame folder is not a file either
    assert frames.read_bytes() == b"the user's"


@pytest.mark.parametrize("name, fmt", [("x.png", "PNG"), ("x.jpg", "JPEG"), ("x.tiff", "TIFF")])
def test_image_format_follows_the_extension(name: str, fmt: str, tmp_path: Path) -> None:
    out = tmp_path / name
    assert main(["render", "demo-volume", "-o", str(out), "--size", "64x48"]) == 0
    with Image.open(out) as image:
        assert image.format == fmt and image.size == (64, 48)
        assert np.asarray(image.convert("RGB")).std() > 5.0
    assert [p.name for p in tmp_path.iterdir()] == [name]  # no temporary left beside it


def test_a_series_member_renders_its_own_time_step(tmp_path: Path) -> None:
    images = {}
    for member in ("Storm.pvm-t01", "Storm.pvm-t05"):
        out = tmp_path / f"{member}.png"
        result = volviz("render", str(data_file(f"storm/{member}")), "-o", str(out), "--size", "64x48")
        assert result.returncode == 0, result.stderr
        images[member] = np.asarray(Image.open(out).convert("RGB"), dtype=np.int16)
    assert np.abs(images["Storm.pvm-t05"] - images["Storm.pvm-t01"]).max() > 20


def test_orbit_movie_into_a_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--orbit needs no recorded path: one turn in 3 frames (1 s at 3 fps), each a different view."""
    out = tmp_path / "orbit"
    assert main(["render", "demo-volume", "--orbit", "--fps", "3", "--duration", "1", "-o", str(out),
                 "--size", "64x48"]) == 0
    frames = sorted(out.iterdir())
    assert [p.name for p in frames] == ["frame_00000.png", "frame_00001.png", "frame_00002.png"]
    images = [np.asarray(Image.open(p).convert("RGB"), dtype=np.int16) for p in frames]
    assert all(image.shape == (48, 64, 3) for image in images)
    for i in range(3):
        assert np.abs(images[i] - images[(i + 1) % 3]).max() > 20


def test_time_movie_of_a_data_file(tmp_path: Path) -> None:
    """``--time`` for a data file (no session): the series of the member, through its time span."""
    import imageio.v2 as iio2

    out = tmp_path / "storm.mp4"
    assert main(["render", str(data_file("storm/Storm.pvm-t05")), "--time", "--fps", "4", "--duration", "1",
                 "-o", str(out), "--size", "64x48"]) == 0
    reader = iio2.get_reader(out, format="FFMPEG")
    assert sum(1 for _ in reader) == 5
    reader.close()
    assert [p.name for p in tmp_path.iterdir()] == ["storm.mp4"]


def test_time_movie_needs_a_time_series(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["render", str(data_file("volumes/neghip.slc")), "--time", "-o", str(tmp_path / "x.mp4"),
                 "--size", "64x48"]) == 2
    assert "no time series" in one_line_error(capsys)
    assert list(tmp_path.iterdir()) == []


def small_vti(path: Path) -> Path:
    """A 4x5x6 VTK image with a scalar T holding 3 NaN values and a 3-component vector V."""
    import pyvista as pv

    grid = pv.ImageData(dimensions=(4, 5, 6))
    t = np.linspace(0.0, 10.0, grid.n_points)
    t[[3, 17, 40]] = np.nan
    grid.point_data["T"] = t
    grid.point_data["V"] = np.stack([np.ones(grid.n_points), np.arange(grid.n_points, dtype=float), -np.ones(grid.n_points)], 1)
    grid.save(path)
    return path


def test_info_lists_every_array(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    source = small_vti(tmp_path / "small.vti")
    assert main(["info", "--json", str(source)]) == 0
    desc = json.loads(capsys.readouterr().out)
    arrays = {a["name"]: a for a in desc["arrays"]}
    assert arrays["T"]["association"] == "point" and arrays["T"]["components"] == 1
    assert arrays["T"]["nonfinite"] == 3 and arrays["T"]["range"][0] == 0.0 and arrays["T"]["range"][1] == 10.0
    assert arrays["V"]["components"] == 3 and arrays["V"]["nonfinite"] == 0
    assert arrays["V"]["choices"] == ["V:magnitude", "V:0", "V:1", "V:2"]
    assert main(["info", "--json", str(source), "--array", "V:1"]) == 0
    desc = json.loads(capsys.readouterr().out)
    assert desc["array"] == "V:1" and desc["range"] == [0.0, 119.0]
    assert main(["info", str(source)]) == 0
    captured = capsys.readouterr()
    lines = [line for line in captured.out.splitlines() if " T " in line or " V " in line]
    assert len(lines) == 2 and "non-finite 3" in lines[0] and "--array V:magnitude | V:0 | V:1 | V:2" in lines[1]
    assert captured.err.count("volviz: warning:") == 1 and "3 non-finite" in captured.err  # reported once


def test_render_an_array_component(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    source = small_vti(tmp_path / "small.vti")
    out = tmp_path / "v1.png"
    assert main(["render", str(source), "--array", "V:1", "-o", str(out), "--size", "64x48"]) == 0
    assert Image.open(out).size == (64, 48)
    assert main(["render", str(source), "--array", "W", "-o", str(tmp_path / "w.png"), "--size", "64x48"]) == 2
    line = one_line_error(capsys)
    assert "no array 'W'" in line and "T" in line and "V" in line
    assert not (tmp_path / "w.png").exists()


def test_info_of_a_series_member_and_of_plot3d_files(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["info", "--json", str(data_file("storm/Storm.pvm-t05"))]) == 0
    series = json.loads(capsys.readouterr().out)["series"]
    assert series["member"] == 5 and series["members"] == 21 and series["time"] == 5.0
    grid, solution = data_file("bluntfin/bluntfinxyz.bin"), data_file("bluntfin/bluntfinq.bin")
    assert main(["info", "--json", str(grid), "--q", str(solution), "--array", "Momentum:2"]) == 0
    desc = json.loads(capsys.readouterr().out)
    momentum = next(a for a in desc["arrays"] if a["name"] == "Momentum")
    assert momentum["components"] == 3 and desc["array"] == "Momentum:2"
    assert main(["info", str(solution)]) == 2
    line = one_line_error(capsys)
    assert "PLOT3D solution (q) file" in line and "--q" in line and "bluntfinxyz.bin" in line


def test_a_failed_write_names_the_output_not_a_temporary(capsys: pytest.CaptureFixture[str]) -> None:
    """/proc takes no new files: the write fails after rendering, and the message names what the user gave."""
    assert main(["render", "demo-volume", "-o", "/proc/volviz-test.png", "--size", "64x48"]) == 2
    line = one_line_error(capsys)
    assert line.startswith("volviz: error: cannot write /proc/volviz-test.png: ") and "volviz-tmp" not in line


def test_image_sizes_beyond_what_renders_here_are_refused() -> None:
    from volviz.render.export import ExportError, check_image_size

    check_image_size((64, 48))
    for size in [(8193, 16), (0, 10), (2 ** 40, 2 ** 40)]:
        with pytest.raises(ExportError, match="cannot be rendered"):
            check_image_size(size)


def test_reader_options_on_the_command_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``--option KEY=VALUE`` reaches the file's reader (``info`` and ``render``; kept in a rendered session's
    dataset); an option the reader does not take is a one-line usage error naming the ones it takes."""
    import h5py

    with h5py.File(tmp_path / "scan.h5", "w") as f:
        f["big"] = np.arange(6 * 5 * 4, dtype=np.float32).reshape(6, 5, 4)
        f["small"] = np.arange(8, dtype=np.float32).reshape(2, 2, 2)
    assert main(["info", "--json", str(tmp_path / "scan.h5")]) == 0
    assert json.loads(capsys.readouterr().out)["dimensions"] == [4, 5, 6]          # the largest by default
    assert main(["info", "--json", str(tmp_path / "scan.h5"), "--option", "dataset=/small"]) == 0
    assert json.loads(capsys.readouterr().out)["dimensions"] == [2, 2, 2]
    assert main(["render", str(tmp_path / "scan.h5"), "--option", "dataset=small", "-o", str(tmp_path / "s.png"),
                 "--size", "64x48"]) == 0
    with Image.open(tmp_path / "s.png") as image:
        assert image.size == (64, 48)
    capsys.readouterr()
    assert main(["info", str(tmp_path / "scan.h5"), "--option", "datset=small"]) == 2
    assert ("--option: the hdf5 reader does not take option(s) datset; it takes dataset, order, allow_nonfinite"
            in one_line_error(capsys))
    assert main(["info", str(tmp_path / "scan.h5"), "--option", "nonsense"]) == 2
    assert "'nonsense' is not KEY=VALUE (e.g. dataset=/entry/data/data)" in one_line_error(capsys)
