"""The first look's ramp placed by histogram equalization (volviz.optics.auto_tf.equalized_stops, after Chourasia &
Schulze 2007), on made volumes whose value distributions are known in closed form.

The volumes: 97^3 points one unit apart from -48 to 48 on each axis (as in tests/test_bench_first_open_object.py,
whose head-on parallel view and pixel grid these tests share), the object a ball about the origin in a background
of 0 that fills most of the box.

- The long-tailed ball: v = exp(-r / L) inside radius R = 40 (L = 10: values from e^-4 = 0.018 to 1, the object's
  samples crowded at the low end as a molecule's density or a storm's edge is). Of the object's samples a share p
  lies outside the radius R (1 - p)^(1/3) (volume of a ball), so the p-quantile of its values is
  exp(-R (1 - p)^(1/3) / L); on the grid, to half a unit of radius.
- The shell: 200 Phi((r - 30) / 1.5) Phi((36 - r) / 1.5) (a shell of 200 between radii 30 and 36, its boundaries
  blurred), 0 where that is under 0.5.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.special import ndtr

from test_bench_first_open_object import PIXELS_PER_UNIT, SCALE, _pixel_world
from volviz.bench import first_open as bench
from volviz.optics.auto_tf import (HIGH_PERCENTILE, LOW_PERCENTILE, MIN_STOP_GAP, RAMP, auto_transfer_function,
                                   background_mode, equalized_stops, mean_chord, one_sided_range)

R, L = 40.0, 10.0
TARGET = float(np.log(10.0))   # the optical depth of a ray 90 % opaque (see test_a_ray_90_percent_opaque_is_seen)
CHORD = mean_chord((-48.0, 48.0) * 3)     # the rays' mean length through the box: 64 units
BACKGROUND = np.array([0.1, 0.1, 0.12])   # the session's default background


def _radius() -> np.ndarray:
    axis = np.arange(-48, 49, dtype=np.float64)
    z, y, x = np.meshgrid(axis, axis, axis, indexing="ij")
    return np.sqrt(x ** 2 + y ** 2 + z ** 2)


def _ball() -> np.ndarray:
    r = _radius()
    return np.where(r <= R, np.exp(-r / L), 0.0)


def _shell() -> np.ndarray:
    r = _radius()
    v = 200.0 * ndtr((r - 30.0) / 1.5) * ndtr((36.0 - r) / 1.5)
    return np.where(v >= 0.5, v, 0.0)


def _seen_from_the_front(tmp_path: Path, values: np.ndarray) -> bench.Footprints:
    """The bench's footprints of ``values`` (97^3, x fastest) drawn with the first look's own transfer function,
    seen head-on through the parallel camera of tests/test_bench_first_open_object.py (two pixels per unit)."""
    import pyvista as pv

    from volviz.render.export import open_target
    from volviz.session import CameraState, save

    grid = pv.ImageData(dimensions=(97, 97, 97), spacing=(1.0, 1.0, 1.0), origin=(-48.0, -48.0, -48.0))
    grid.point_data["value"] = values.astype(np.float32).reshape(-1)
    grid.save(tmp_path / "ball.vti")
    session, _ = open_target(tmp_path / "ball.vti")
    session.camera = CameraState(position=(0.0, 0.0, 400.0), focal_point=(0.0, 0.0, 0.0), view_up=(0.0, 1.0, 0.0),
                                 parallel=True, parallel_scale=SCALE)
    save(session, tmp_path / "ball.vvs")
    kind, prints, _ = bench.legibility(tmp_path / "ball.vvs")
    assert kind == "volume" and prints is not None
    return prints


def _disc(radius: float) -> np.ndarray:
    """The pixels whose centres lie within ``radius`` units of the origin, less one pixel (the rasterised rim)."""
    x, y = _pixel_world()
    return np.hypot(x, y) <= radius - 1.0 / PIXELS_PER_UNIT


def test_a_ray_90_percent_opaque_is_seen():
    """The bound the rendered tests rely on: a ray of optical depth ``TARGET`` (90 % opaque) over the background
    shows the colour of the values it crosses; each of the first look's colours, 90 % over the background, differs
    from it by more than twice the bench's ΔE 10."""
    from volviz.optics.auto_tf import COOL_WARM
    from volviz.session import Session

    assert tuple(Session().render.background) == tuple(BACKGROUND)
    for color in COOL_WARM:
        assert bench.color_difference(0.9 * np.asarray(color) + 0.1 * BACKGROUND, BACKGROUND) > 2 * bench.VISIBLE_DE


def test_the_stops_are_the_quartiles_of_the_objects_values():
    """The ball's background (0, 75 % of the samples) is the histogram's background mode; the five stops are the
    quantiles 0.02 + 0.975 k / 4 of the object's values (the quartiles between the 2 % and 99.5 % percentiles) to
    half a unit of radius; the evenly spaced ramp of before put 88 % of the object's samples under its first
    segment, under 8 % of the peak extinction; now a quarter of them (26 %: those under the second stop)."""
    values = _ball().reshape(-1)
    mode = background_mode(values)
    assert mode is not None and mode[0] == 0.0 and np.mean(values < mode[1]) > 0.7
    assert values[values > 0].min() > mode[1]                      # every sample of the ball is object
    span = one_sided_range(values, mode)
    stops = equalized_stops(values, *span)
    p = LOW_PERCENTILE / 100 + (HIGH_PERCENTILE - LOW_PERCENTILE) / 100 * np.linspace(0.0, 1.0, len(RAMP))
    radius = -L * np.log(stops)
    np.testing.assert_allclose(radius, R * (1.0 - p) ** (1.0 / 3.0), atol=0.5)

    tf = auto_transfer_function(values, chord=CHORD)
    obj = values[values > mode[1]]
    rho = tf.evaluate(obj)[1]
    faint = float(np.mean(rho < RAMP[1] * tf.max_extinction))
    assert faint <= 0.25 + LOW_PERCENTILE / 100 + 1e-3
    even = np.interp(obj, np.linspace(*span, len(RAMP)), RAMP, left=0.0)
    assert float(np.mean(even < RAMP[1])) > 0.8                    # before: most of the object nearly transparent
    assert tf.evaluate(np.array([0.0]))[1][0] == 0.0               # the background stays transparent


def test_ties_of_integer_data_are_split_by_one_bin():
    """8-bit data where one value holds 30 % of the object's samples (as a storm's edge value 1 does): the first two
    stops would coincide; they are split by ``MIN_STOP_GAP`` of the span, and all stay within it."""
    rng = np.random.default_rng(3)
    obj = np.concatenate([np.ones(30_000), rng.integers(2, 256, 70_000)]).astype(np.float64)
    stops = equalized_stops(obj, 1.0, 255.0)
    gap = MIN_STOP_GAP * 254.0
    assert stops[0] == 1.0 and stops[-1] == 255.0
    assert stops[1] == pytest.approx(1.0 + gap)                   # the first quartile is 1 itself: moved up a bin
    assert stops[2] == pytest.approx(np.quantile(obj, 0.5)) and stops[3] == pytest.approx(np.quantile(obj, 0.75))
    top = equalized_stops(np.full(1000, 255.0), 1.0, 255.0)       # all at the top: moved down from it
    np.testing.assert_allclose(top, [1.0, 255.0 - 3 * gap, 255.0 - 2 * gap, 255.0 - gap, 255.0])


def test_the_long_tailed_ball_is_seen_out_to_where_its_rays_reach_the_target_depth(tmp_path):
    """Where the extinction is at least RAMP[k] of its peak for every value at or above stop k (the ramp rises), a
    ray at distance b from the centre crosses 2 sqrt(r_k^2 - b^2) of such values inside the radius r_k of stop k:
    its optical depth is at least the sum of those. Every ray whose bound reaches ``TARGET`` is seen (its colour
    differs from the background by more than ΔE 10), and that disc is more than half of the object's footprint."""
    values = _ball()
    tf = auto_transfer_function(values, chord=CHORD)
    mode = background_mode(values.reshape(-1))
    stops = equalized_stops(values.reshape(-1), *one_sided_range(values.reshape(-1), mode))
    radii = -L * np.log(stops)
    b = np.linspace(0.0, R, 4001)
    depth = sum((RAMP[k] - RAMP[k - 1]) * tf.max_extinction * 2.0 * np.sqrt(np.clip(radii[k] ** 2 - b ** 2, 0, None))
                for k in range(1, len(RAMP)))
    sure = float(b[depth >= TARGET].max())
    prints = _seen_from_the_front(tmp_path, values)
    assert not (_disc(sure) & ~prints.seen).any()
    assert _disc(sure).sum() / prints.object.sum() > 0.5
    assert prints.object_visible >= _disc(sure).sum() / prints.object.sum()
    assert prints.object_visible > 0.8


def test_a_shell_in_a_large_background_is_seen_out_to_its_outer_boundary(tmp_path):
    """The optical depth of the ray at distance b from the centre, integrated along it through the shell's
    closed-form values (4,801 steps), reaches ``TARGET`` out to past the shell's outer boundary (r = 36, where its
    values fall through 100): the blurred boundary itself is opaque enough to be seen. The rendered rays within half
    a unit of that (trilinear samples of the grid against the closed form) are all seen."""
    values = _shell()
    assert np.mean(values == 0.0) > 0.75
    tf = auto_transfer_function(values, chord=CHORD)
    assert tf.evaluate(np.array([0.0]))[1][0] == 0.0

    def profile(r: np.ndarray) -> np.ndarray:
        v = 200.0 * ndtr((r - 30.0) / 1.5) * ndtr((36.0 - r) / 1.5)
        return np.where(v >= 0.5, v, 0.0)

    s = np.linspace(0.0, 48.0, 4801)
    b = np.arange(0.0, 41.0, 0.05)
    depth = np.array([2.0 * np.trapezoid(tf.evaluate(profile(np.hypot(x, s)))[1], s) for x in b])
    sure = float(b[depth >= TARGET].max())
    assert sure > 36.0
    prints = _seen_from_the_front(tmp_path, values)
    assert not (_disc(sure - 0.5) & ~prints.seen).any()
    # the object's footprint reaches radius 40.2 (where the blurred outer boundary falls under 0.5), plus the
    # rasterised rim: the sure disc is at least ((36 - 0.5 - 0.5) / (40.2 + 1.5))^2 = 0.70 of it
    assert prints.object_visible >= _disc(sure - 0.5).sum() / prints.object.sum() > 0.70
