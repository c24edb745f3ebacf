"""LAS / LAZ lidar point clouds through ``volviz.io.read`` (``volviz_geoscience.las``, laspy; issue #30): the values
laspy wrote, read back; the arrays by point format; UTM-sized coordinates drawn as the same picture as local ones;
`volviz info` and `volviz render` on them; damaged files and a LAZ without a decompressor refused in one line.
Every file is written by laspy itself in the test."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import laspy
import numpy as np
import pytest

import volviz.io as vio
from volviz.io.errors import ReadError
from volviz.io.registry import format_of
from volviz.model import UnstructuredMesh
from volviz.model.arrays import default_array, vertex_colors
from volviz.model.representation import POINTS, representation

VOLVIZ = Path(sys.executable).parent / "volviz"
UTM = (512345.0, 5412345.0, 0.0)


def _survey(path: Path, point_format: int = 3, offset=UTM, n: int = 2000, colour_bits: int = 16,
            extra: bool = False) -> laspy.LasData:
    """A lidar-like cloud: ``n`` points on a 40 m x 40 m patch around ``offset`` at millimetre scale, written by
    laspy (LAZ when ``path`` ends in .laz); returns what was written."""
    header = laspy.LasHeader(point_format=point_format, version="1.4" if point_format >= 6 else "1.2")
    header.offsets, header.scales = np.asarray(offset), np.full(3, 0.001)
    if extra:
        header.add_extra_dim(laspy.ExtraBytesParams(name="amplitude", type=np.float32))
    las = laspy.LasData(header)
    rng = np.random.default_rng(7)
    x, y = rng.uniform(0, 40, n), rng.uniform(0, 40, n)
    las.x, las.y, las.z = offset[0] + x, offset[1] + y, offset[2] + 200 + 3 * np.sin(x / 5) * np.cos(y / 7)
    las.intensity = rng.integers(0, 65535, n, dtype=np.uint16)
    las.classification = rng.choice([2, 5, 6], n).astype(np.uint8)
    las.return_number = rng.integers(1, 4, n).astype(np.uint8)
    las.number_of_returns = np.full(n, 3, np.uint8)
    names = set(las.point_format.dimension_names)
    if "gps_time" in names:
        las.gps_time = 1.6e8 + np.sort(rng.uniform(0, 60, n))
    if "red" in names:
        top = 65535 if colour_bits == 16 else 255
        for c in ("red", "green", "blue"):
            las[c] = rng.integers(0, top + 1, n, dtype=np.uint16)
    if extra:
        las.amplitude = rng.normal(size=n).astype(np.float32)
    las.write(str(path))
    return laspy.read(str(path))


@pytest.mark.parametrize("name", ["scan.las", "scan.laz"])
def test_the_values_laspy_wrote_are_read(tmp_path, name):
    written = _survey(tmp_path / name, extra=True)
    mesh = vio.read(tmp_path / name)
    assert isinstance(mesh, UnstructuredMesh) and mesh.n_points == 2000
    np.testing.assert_array_equal(mesh.points, np.stack([written.x, written.y, written.z], axis=1))
    assert mesh.points[:, 0].min() > UTM[0] and mesh.points[:, 1].min() > UTM[1]      # the survey's own coordinates
    assert list(mesh.point_data) == ["elevation", "intensity", "classification", "return_number", "number_of_returns",
                                     "gps_time", "red", "green", "blue", "amplitude"]
    np.testing.assert_array_equal(mesh.point_data["elevation"], np.asarray(written.z))
    for dim in ("intensity", "classification", "return_number", "number_of_returns", "gps_time", "amplitude"):
        np.testing.assert_array_equal(mesh.point_data[dim], np.asarray(written[dim]))
    for c in ("red", "green", "blue"):                              # 16-bit colours as 0..255
        assert mesh.point_data[c].dtype == np.uint8
        np.testing.assert_array_equal(mesh.point_data[c], np.rint(np.asarray(written[c]) / 257.0).astype(np.uint8))
    assert {int(t) for t, _ in mesh.cells} == {1}
    assert default_array(mesh) == "elevation"
    assert representation(mesh).kind == POINTS


def test_the_arrays_follow_the_point_format(tmp_path):
    _survey(tmp_path / "f0.las", point_format=0)
    bare = vio.read(tmp_path / "f0.las")
    assert list(bare.point_data) == ["elevation", "intensity", "classification", "return_number", "number_of_returns"]
    written = _survey(tmp_path / "f7.las", point_format=7, colour_bits=8)    # LAS 1.4, colours written as 8 bits
    mesh = vio.read(tmp_path / "f7.las")
    assert "gps_time" in mesh.point_data
    for c in ("red", "green", "blue"):                              # kept as they are
        np.testing.assert_array_equal(mesh.point_data[c], np.asarray(written[c]))
    colours = vertex_colors(mesh)                                   # what a surface of them is drawn in
    assert colours is not None
    np.testing.assert_array_equal(colours, np.stack([written.red, written.green, written.blue], axis=1))


def test_a_las_file_is_known_by_its_content(tmp_path):
    _survey(tmp_path / "scan.las")
    (tmp_path / "scan.las").rename(tmp_path / "scan.bin")
    assert format_of(tmp_path / "scan.bin", {}) == "las"
    assert vio.read(tmp_path / "scan.bin").n_points == 2000


def _render(path: Path) -> np.ndarray:
    from volviz.render.export import open_target, render_session

    session, _ = open_target(path)
    session.render.options["outline"] = False     # the outline box is drawn in float32 (not the data): left out
    return render_session(session, None, (320, 240)).astype(np.int32)


def test_utm_coordinates_draw_the_same_picture_as_local_ones(tmp_path):
    """At y = 5.4e6 a float32 coordinate steps by 0.5 m: a cloud drawn from float32 positions would jitter by
    several pixels on this 40 m patch. The picture must be that of the same cloud at the origin."""
    _survey(tmp_path / "utm.las")
    _survey(tmp_path / "local.las", offset=(0.0, 0.0, 0.0))
    utm, local = _render(tmp_path / "utm.las"), _render(tmp_path / "local.las")
    from volviz.bench.first_open import drawn_fraction

    assert drawn_fraction(local) > 0.05
    differs = np.abs(utm - local).sum(axis=2) > 24
    assert differs.mean() < 0.002, f"{differs.mean():.2%} of the pixels differ"


def _volviz(*args: str, env: dict | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([str(VOLVIZ), *args], capture_output=True, text=True, timeout=300,
                          env={**os.environ, **(env or {})})


def test_volviz_info_lists_the_arrays_and_render_draws_a_legible_first_image(tmp_path):
    _survey(tmp_path / "scan.laz")
    info = _volviz("info", str(tmp_path / "scan.laz"))
    assert info.returncode == 0, info.stderr
    rows = info.stdout.split("\narrays", 1)[1].splitlines()
    assert [row.split()[0] for row in rows] == ["elevation", "intensity", "classification", "return_number",
                                                "number_of_returns", "gps_time", "red", "green", "blue"]
    assert "array       elevation" in info.stdout
    done = _volviz("render", str(tmp_path / "scan.laz"), "-o", str(tmp_path / "scan.png"), "--size", "400x300")
    assert done.returncode == 0, done.stderr
    from PIL import Image

    from volviz.bench.first_open import drawn_fraction

    assert drawn_fraction(np.asarray(Image.open(tmp_path / "scan.png").convert("RGB"))) > 0.02


def _damaged(tmp_path: Path) -> dict[str, tuple[Path, str]]:
    _survey(tmp_path / "good.las")
    _survey(tmp_path / "good.laz")
    las, laz = (tmp_path / "good.las").read_bytes(), (tmp_path / "good.laz").read_bytes()
    cases = {"header": (las[:100], r"its LAS header is cut short \(100 bytes of at least 227\)"),
             "points": (las[:-5000], r"its header counts 2,000 points but the file holds 1,852 .*: it is cut short"),
             "laz": (laz[:len(laz) // 2], r"its points cannot be read"),
             "not": (b"LASX" + las[4:], r"is not a LAS file")}
    out = {}
    for key, (data, message) in cases.items():
        path = tmp_path / f"{key}.{'laz' if key == 'laz' else 'las'}"
        path.write_bytes(data)
        out[key] = (path, message)
    return out


def test_damaged_files_are_refused_in_one_line_naming_the_file(tmp_path):
    for key, (path, message) in _damaged(tmp_path).items():
        with pytest.raises(ReadError, match=message) as caught:
            vio.read(path)
        assert str(path) in str(caught.value) and "\n" not in str(caught.value), key
    done = _volviz("info", str(tmp_path / "points.las"))
    assert done.returncode != 0
    assert done.stderr.strip().splitlines() == [f"volviz: error: {tmp_path / 'points.las'}: its header counts 2,000 "
                                                "points but the file holds 1,852 (63,227 bytes of the 68,227 "
                                                "needed): it is cut short"]


def test_a_laz_file_without_a_decompressor_says_what_to_install(tmp_path):
    """lazrs and laszip made unimportable before laspy loads (isolation off, so the reader runs in that process):
    laspy then has no LAZ backend."""
    _survey(tmp_path / "scan.laz")
    script = ("import sys; sys.modules['lazrs'] = sys.modules['laszip'] = None\n"
              "import volviz.io as vio\n"
              "try:\n    vio.read(sys.argv[1])\nexcept vio.ReadError as exc:\n    print(exc)\n")
    done = subprocess.run([sys.executable, "-c", script, str(tmp_path / "scan.laz")], capture_output=True, text=True,
                          timeout=120, env={**os.environ, "VOLVIZ_ISOLATE": "0"})
    assert done.stdout.strip() == (f"{tmp_path / 'scan.laz'}: is a compressed LAS file (LAZ) and no LAZ decompressor "
                                   "is installed; install one: pip install 'laspy[lazrs]'"), done.stderr


def test_choosing_a_colour_array_shows_the_points_in_their_own_colours(tmp_path):
    """A cloud red along x, green along y (16-bit colours): shown by --array red it is drawn in its colours, which
    the transfer function's cool-to-warm map (no green) could not give."""
    header = laspy.LasHeader(point_format=3, version="1.2")
    header.scales = np.full(3, 0.01)
    las = laspy.LasData(header)
    x, y = (a.ravel() for a in np.meshgrid(np.arange(0, 30, 0.3), np.arange(0, 30, 0.3)))
    las.x, las.y, las.z = x, y, np.sin(x / 4)
    las.red, las.green = (x / 30 * 65535).astype(np.uint16), (y / 30 * 65535).astype(np.uint16)
    las.blue = np.full(len(x), 20000, np.uint16)
    las.write(str(tmp_path / "rgb.las"))
    done = _volviz("render", str(tmp_path / "rgb.las"), "--array", "red", "-o", str(tmp_path / "rgb.png"), "--size",
                   "400x300")
    assert done.returncode == 0, done.stderr
    from PIL import Image

    image = np.asarray(Image.open(tmp_path / "rgb.png").convert("RGB")).astype(np.int32)
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    assert ((g > r + 60) & (g > b + 60)).mean() > 0.01          # the green corner
    assert ((r > g + 60) & (r > b + 60)).mean() > 0.01          # the red corner
