"""The optional dependencies (pyproject extras) are asked for by name when missing: a plotting benchmark without
matplotlib and a movie without imageio-ffmpeg are usage errors naming the extra, before any work starts. Each case
runs the real command in a child Python where the package cannot be imported (``sys.modules[name] = None``)."""
from __future__ import annotations

import subprocess
import sys

import pytest

from volviz.bench import PLOTTING


def _run_without(package: str, code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", f"import sys; sys.modules[{package!r}] = None\n{code}"],
                          capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("name", ["tables", "nature"])
def test_plotting_bench_without_matplotlib_is_a_usage_error(name):
    assert name in PLOTTING
    done = _run_without("matplotlib", f"from volviz.cli import main; sys.exit(main(['bench', {name!r}]))")
    assert done.returncode == 2, done.stderr
    assert done.stderr.strip() == (f"volviz: error: volviz bench {name} draws its figures with matplotlib, which is "
                                   "not installed: pip install 'volviz[bench]'")


def test_movie_without_imageio_ffmpeg_names_the_extra(tmp_path):
    target = tmp_path / "orbit.mp4"
    done = _run_without("imageio_ffmpeg", f"from volviz.cli import main; sys.exit(main(['render', 'demo', '-o', "
                                          f"{str(target)!r}, '--orbit', '--size', '64x48']))")
    assert done.returncode != 0 and not target.exists()
    assert (f"{target}: writing .mp4 movies needs imageio-ffmpeg, which is not installed: pip install "
            "'volviz[movies]' (or give a folder to receive PNG frames)") in done.stderr
    frames = tmp_path / "frames"
    done = _run_without("imageio_ffmpeg", f"from volviz.cli import main; sys.exit(main(['render', 'demo', '-o', "
                                          f"{str(frames)!r}, '--orbit', '--size', '32x24', '--duration', '0.5', "
                                          f"'--fps', '4']))")
    assert done.returncode == 0, done.stderr
    assert len(list(frames.glob("*.png"))) == 2
