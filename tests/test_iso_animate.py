"""4D isosurfaces of the Storm (libMini note, "4D Visualization"): smooth in display time, extracted in the
background."""
from __future__ import annotations

import threading

import numpy as np
import pytest

from conftest import data_file
from volviz.iso.animate import IsoAnimator, IsoFrame, extract_at, playback_times
from volviz.iso.composite import render
from volviz.iso.extract import IsoStyle
from volviz.jobs import JobRunner
from volviz.model.camera import Camera

STYLES = [IsoStyle(30, (0.2, 0.4, 1.0), 0.3), IsoStyle(80, (0.2, 1.0, 0.3), 0.4), IsoStyle(150, (1.0, 0.2, 0.1), 1.0)]
F = 8  # display frames per time step


@pytest.fixture(scope="module")
def storm():
    import volviz.io
    data_file("storm/Storm.pvm-t01")
    return volviz.io.read(str(data_file("storm/Storm.pvm-t01")).replace("t01", "t%02d"))


def _changes(storm, interpolate: bool) -> np.ndarray:
    cam = Camera.orbit(np.array([[0, 0, 0], [27, 27, 22.0]]), azimuth=30, elevation=25)
    ts = np.linspace(10.0, 12.0, 2 * F + 1)
    imgs = [render(extract_at(storm, t, STYLES, interpolate=interpolate).meshes, cam, (64, 64))[0] for t in ts]
    # mean absolute change in 8-bit units: linear in the image area a moving surface sweeps
    return np.array([255.0 * np.mean(np.abs(a - b)) for a, b in zip(imgs[1:], imgs[:-1])])


def test_storm_isosurfaces_follow_time_smoothly(storm):
    assert len(storm) == 21
    stepped = _changes(storm, interpolate=False)
    smooth = _changes(storm, interpolate=True)
    boundary = np.zeros(2 * F, bool)
    boundary[[F - 1, 2 * F - 1]] = True  # the frames where the nearest earlier step changes
    assert np.all(stepped[~boundary] == 0.0) and np.all(stepped[boundary] > 1.0)
    # interpolated: every frame moves, no frame jumps by more than about a few frames' share of a step's change
    assert np.all(smooth > 0.0)
    assert smooth.max() < 0.35 * stepped[boundary].min()
    # over a whole step the interpolated surfaces travel at least as far as the step itself changes
    assert smooth[:F].sum() >= 0.9 * stepped[F - 1]


def test_playback_times_continuous(storm):
    ts = playback_times(storm, 40)
    assert len(ts) == 20 * 40 + 1 and ts[0] == storm.times[0] and ts[-1] == storm.times[-1]
    assert np.allclose(np.diff(ts), np.diff(ts)[0])


def test_background_extraction_never_blocks_and_newest_request_wins(storm):
    gate = threading.Event()
    started = threading.Event()

    def slow(series, t, styles, **kw):
        started.set()
        gate.wait(10.0)
        return extract_at(series, t, styles, **kw)

    runner = JobRunner(max_workers=1)
    try:
        anim = IsoAnimator(storm, STYLES, runner=runner, extractor=slow)
        assert anim.frame(5.0) is None  # returns at once although the worker is held
        started.wait(5.0)
        for t in (5.5, 6.0, 6.5, 7.25):  # playback continues while the worker is busy
            assert anim.frame(t) is None
        gate.set()
        frame = anim.wait_for(7.25)
        assert isinstance(frame, IsoFrame) and frame.interpolated
        assert anim.delivered <= 2  # stale requests were superseded, not all extracted
        ref = extract_at(storm, 7.25, STYLES)
        for a, b in zip(frame.meshes, ref.meshes):
            np.testing.assert_array_equal(a.points, b.points)
        assert anim.frame(8.0).time == 7.25  # the newest finished surfaces are shown while 8.0 is extracted
        anim.wait_for(8.0)
    finally:
        runner.shutdown()
