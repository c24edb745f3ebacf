"""The bench's *object visible* measure (issue #30, legible automatic transfer functions): the share of the object's
footprint (where the data differs from the histogram's background mode) whose colour differs visibly from the
background, on made spheres seen head-on through a parallel camera, so that every footprint is known by hand.

The volume: 97^3 points one unit apart from -48 to 48 on each axis, a sphere of radius R = 40 about the origin in a
background of value 10. The camera looks down -z with +y up, parallel scale 60: the 320 x 240 measure image spans
x in [-80, 80] and y in [-60, 60], two pixels per unit, the origin at the image's centre.

- The object's footprint (opaque where the value is not in the background mode's bin [10, 10.74)): a ray at (x, y)
  crosses a sample above 10.74 exactly when the unit square of the grid holding (x, y) has a corner (i, j) of the
  sphere (i^2 + j^2 <= R^2, the ray's cell at z = 0 holds it; the trilinear weight of that corner exceeds 0.74 / 190
  everywhere in the square but a sliver at its far sides): the union of those squares, radius R to R + sqrt(2).
- The data's footprint (opaque over the whole range, the background too): the box's square, x and y in [-48, 48],
  less the scalar bar's strip (x >= 48, the right fifth).
Both to within one pixel of their outlines (where the ray's samples and the rasterisation decide).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from volviz.bench import first_open as bench
from volviz.optics.transfer_function import TransferFunction

R = 40
SCALE = 60.0                   # parallel scale: the image's half-height in world units
PIXELS_PER_UNIT = bench.METRIC_SIZE[1] / (2 * SCALE)


def _pixel_world() -> tuple[np.ndarray, np.ndarray]:
    """The world x, y of every pixel centre of the measure image (row 0 at the top)."""
    width, height = bench.METRIC_SIZE
    x = (np.arange(width) + 0.5 - width / 2) / PIXELS_PER_UNIT
    y = (height / 2 - np.arange(height) - 0.5) / PIXELS_PER_UNIT
    return np.meshgrid(x, y)


def _grow(mask: np.ndarray) -> np.ndarray:
    """``mask`` grown by one pixel (its 3 x 3 neighbourhood)."""
    padded = np.pad(mask, 1)
    out = np.zeros_like(mask)
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            out |= padded[dy:dy + mask.shape[0], dx:dx + mask.shape[1]]
    return out


def _shrink(mask: np.ndarray) -> np.ndarray:
    return ~_grow(~mask)


def _assert_to_a_pixel(measured: np.ndarray, expected: np.ndarray) -> None:
    assert not (_shrink(expected) & ~measured).any(), "pixels inside the expected footprint are missing"
    assert not (measured & ~_grow(expected)).any(), "pixels outside the expected footprint are drawn"


def _object_footprint() -> np.ndarray:
    x, y = _pixel_world()
    i, j = np.floor(x), np.floor(y)
    inside = np.zeros(x.shape, dtype=bool)
    for di in (0, 1):
        for dj in (0, 1):
            inside |= (i + di) ** 2 + (j + dj) ** 2 <= R ** 2
    return inside & (np.abs(x) <= 48) & (np.abs(y) <= 48)


def _box_footprint() -> np.ndarray:
    x, y = _pixel_world()
    width = bench.METRIC_SIZE[0]
    strip = np.arange(width) >= int(0.8 * width)
    return (np.abs(x) <= 48) & (np.abs(y) <= 48) & ~strip[None, :]


def _write_sphere(path: Path, inside: np.ndarray) -> None:
    """A .vti of 97^3 points one unit apart about the origin: ``inside`` (97, 97, 97) within radius R, 10 outside."""
    import pyvista as pv

    axis = np.arange(-48, 49, dtype=np.float64)
    z, y, x = np.meshgrid(axis, axis, axis, indexing="ij")
    values = np.where(x ** 2 + y ** 2 + z ** 2 <= R ** 2, inside, 10.0).astype(np.float32)
    grid = pv.ImageData(dimensions=(97, 97, 97), spacing=(1.0, 1.0, 1.0), origin=(-48.0, -48.0, -48.0))
    grid.point_data["value"] = values.reshape(-1)          # x fastest, as VTK orders points
    grid.save(path)


def _sphere_session(tmp_path: Path, inside: np.ndarray, tf: TransferFunction) -> Path:
    """A session file showing a .vti of the sphere (values ``inside`` of shape (97, 97, 97) within it, 10 outside)
    head-on, with the transfer function ``tf``."""
    from volviz.render.export import open_target
    from volviz.session import CameraState, save

    _write_sphere(tmp_path / "sphere.vti", inside)
    session, _ = open_target(tmp_path / "sphere.vti")
    session.camera = CameraState(position=(0.0, 0.0, 400.0), focal_point=(0.0, 0.0, 0.0), view_up=(0.0, 1.0, 0.0),
                                 parallel=True, parallel_scale=SCALE)
    session.transfer_functions["shown"] = tf
    session.components[0].transfer_function = "shown"
    save(session, tmp_path / "sphere.vvs")
    return tmp_path / "sphere.vvs"


def _measured(path: Path) -> bench.Footprints:
    kind, prints, contrast = bench.legibility(path)
    assert kind == "volume" and prints is not None and contrast is not None
    return prints


def test_the_object_footprint_is_the_sphere_disc_and_the_old_footprint_the_box(tmp_path):
    """Value 200 in a background of 10, a transfer function white and opaque (1 per unit) from 11 up to 300: the
    disc is seen (every ray at least one unit inside it crosses 18 units or more of the sphere) and nothing outside
    the object's footprint, so nearly all the object is visible; the *visible* share divides by the whole box."""

    tf = TransferFunction([10.0, 11.0, 300.0], [(1.0, 1.0, 1.0)] * 3, [0.0, 1.0, 1.0], name="shown")
    prints = _measured(_sphere_session(tmp_path, np.full((97, 97, 97), 200.0), tf))
    expected = _object_footprint()
    _assert_to_a_pixel(prints.object, expected)
    _assert_to_a_pixel(prints.data, _box_footprint())

    x, y = _pixel_world()
    sure = np.hypot(x, y) <= R - 1
    assert not (sure & ~prints.seen).any()
    assert not (prints.seen & prints.data & ~_grow(expected)).any()
    low = sure.sum() / _grow(expected).sum()                  # (39 / 41.4)^2 = 0.89 of the object at least
    assert low <= prints.object_visible <= 1.0 and low > 0.85
    box = _box_footprint().sum()                               # 192 x 192 pixels less a ring
    assert sure.sum() / box <= prints.visible <= _grow(expected).sum() / box
    assert prints.visible < 0.6 < 0.85 < prints.object_visible


def test_a_transfer_function_showing_half_of_the_values_shows_half_of_the_object(tmp_path):
    """Values 110 + 90 x / R in the sphere (20 to 200, linear along x, so constant along each ray inside it and
    exact under trilinear interpolation), a transfer function opaque and white from 110 up, transparent below: the
    half disc x >= 0 is seen, the other half not; about half of the object's footprint (the rim of the seen half,
    where the sphere's values mix with the background's, is between 0 and 1.4 units wide)."""

    axis = np.arange(-48, 49, dtype=np.float64)
    x3 = np.broadcast_to(axis[None, None, :], (97, 97, 97))
    tf = TransferFunction([10.0, 109.99, 110.0, 200.0], [(1.0, 1.0, 1.0)] * 4, [0.0, 0.0, 1.0, 1.0], name="half")
    prints = _measured(_sphere_session(tmp_path, 110.0 + 90.0 * x3 / R, tf))
    expected = _object_footprint()
    _assert_to_a_pixel(prints.object, expected)

    x, y = _pixel_world()
    one_pixel = 1.0 / PIXELS_PER_UNIT
    sure = (x >= one_pixel) & (np.hypot(x, y) <= R - 1)
    possible = _grow(expected) & (x >= -one_pixel)
    assert not (sure & ~prints.seen).any()
    assert not (prints.seen & prints.data & ~possible).any()
    low, high = sure.sum() / expected.sum(), possible.sum() / expected.sum()
    assert low <= prints.object_visible <= high
    assert prints.object_visible == pytest.approx(0.5, abs=0.05)


def test_a_legibility_only_run_keeps_each_rows_time_and_measures_the_rest(tmp_path):
    """``--legibility-only`` (a busy machine): the time, CPU time, drawn share and note come from the report's rows,
    read by its header's column names; the legibility columns are measured; a row's old legibility error is measured
    again, a render's error is kept (that file is not measured)."""
    doc = tmp_path / "first-open.md"
    rows = [bench.FirstImage("ball.vti", 3.6, 4.2, 0.31, "volume", 0.9, 0.8, 50.0, "legibility: ValueError: x", 2.75,
                             4.9),
            bench.FirstImage("bad.vti", 0.0, note="bad.vti: cannot be read")]
    bench.write_section(bench.markdown(rows, {}), doc)
    kept = bench.kept_timings(doc)
    assert kept == {"ball.vti": (4.2, 2.75, 0.31, "", 4.9), "bad.vti": (None, None, None, "bad.vti: cannot be read",
                                                                    None)}

    data = tmp_path / "data"
    data.mkdir()
    _write_sphere(data / "ball.vti", np.full((97, 97, 97), 200.0))
    (data / "bad.vti").write_text("not a VTK file")
    bad, ball = bench.measure(data, timings=kept)           # in name order
    assert (ball.name, ball.seconds, ball.cpu, ball.drawn, ball.note, ball.kind, ball.slowest) == \
        ("ball.vti", 4.2, 2.75, 0.31, "", "volume", 4.9)
    assert ball.visible is not None and ball.object_visible is not None and ball.contrast is not None
    assert ball.visible < ball.object_visible          # the sphere covers part of its box's footprint
    assert (bad.seconds, bad.drawn, bad.note, bad.kind, bad.visible) == (None, None, "bad.vti: cannot be read", "",
                                                                         None)
