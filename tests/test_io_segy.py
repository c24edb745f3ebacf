"""SEG-Y files through ``volviz.io.read`` (``volviz_geoscience.segy``, segyio): 3D surveys as volumes in the survey's
frame with time downwards, mirrored surveys, 2D sections, pre-stack files, and damaged files; every file written
by segyio itself."""
from __future__ import annotations

import random
import warnings

import numpy as np
import pytest
import segyio
from conftest import read_mutations

import volviz.io as vio
from volviz.bench import robustness as rb
from volviz.io.errors import ReadError, ReadWarning
from volviz.model import Image2D, RegularVolume

CUBE = np.random.default_rng(0).normal(size=(4, 5, 30)).astype(np.float32)     # (inline, crossline, sample)


def _survey(path, inline_dir=(0.8, 0.6), crossline_dir=(-0.6, 0.8), bins=(25.0, 12.5), data=CUBE):
    """A post-stack survey whose inline step moves ``bins[0]`` along ``inline_dir`` on the map and whose crossline
    step moves ``bins[1]`` along ``crossline_dir``; 4 ms samples from 100 ms; coordinates in centimetres."""
    segyio.tools.from_array(str(path), data, dt=4000, delrt=100)
    with segyio.open(str(path), "r+") as f:
        for i in range(data.shape[0]):
            for j in range(data.shape[1]):
                x = 1000.0 + bins[0] * i * inline_dir[0] + bins[1] * j * crossline_dir[0]
                y = 5000.0 + bins[0] * i * inline_dir[1] + bins[1] * j * crossline_dir[1]
                f.header[i * data.shape[1] + j] = {segyio.TraceField.SourceGroupScalar: -100,
                                                   segyio.TraceField.CDP_X: round(x * 100),
                                                   segyio.TraceField.CDP_Y: round(y * 100)}
    return path


def test_a_survey_is_a_volume_of_bins_with_time_downwards(tmp_path):
    volume = vio.read(_survey(tmp_path / "survey.sgy"))
    assert isinstance(volume, RegularVolume) and volume.dimensions == (4, 5, 30) and volume.name == "amplitude"
    np.testing.assert_allclose(volume.spacing, (25.0, 12.5, 4.0))
    np.testing.assert_allclose(volume.origin, (0.0, 0.0, -(100.0 + 29 * 4.0)))   # the last sample is the lowest
    np.testing.assert_array_equal(volume.data, CUBE[:, :, ::-1])
    top = np.asarray(volume.origin) + (np.asarray(volume.dimensions) - 1) * np.asarray(volume.spacing)
    assert top[2] == -100.0                                                        # the first sample on top
    plain = vio.read(_survey(tmp_path / "no_coordinates.sgy", bins=(0.0, 0.0)))
    np.testing.assert_allclose(plain.spacing, (1.0, 1.0, 4.0))                   # one unit per line


def test_a_mirrored_survey_keeps_the_maps_handedness(tmp_path):
    """Crossline axis clockwise of the inline axis on the map: shown with the crosslines reversed."""
    volume = vio.read(_survey(tmp_path / "mirrored.sgy", crossline_dir=(0.6, -0.8)))
    np.testing.assert_allclose(volume.spacing, (25.0, 12.5, 4.0))
    np.testing.assert_array_equal(volume.data, CUBE[:, ::-1, ::-1])


def test_a_2d_line_is_a_section_and_pre_stack_files_are_refused(tmp_path):
    traces = np.random.default_rng(1).normal(size=(7, 20)).astype(np.float32)
    spec = segyio.spec()
    spec.samples, spec.tracecount, spec.format, spec.sorting = list(range(20)), 7, 5, None
    with segyio.create(str(tmp_path / "line.sgy"), spec) as f:
        f.bin.update(hdt=2000)
        for i in range(7):
            f.trace[i] = traces[i]
            f.header[i] = {segyio.TraceField.TRACE_SAMPLE_INTERVAL: 2000}
    with pytest.warns(ReadWarning, match="line.sgy: shown as a 2D section of 7 traces"):
        section = vio.read(tmp_path / "line.sgy")
    assert isinstance(section, Image2D)
    np.testing.assert_array_equal(section.data, traces.T)                         # a column per trace, time down
    assert section.spacing == (1.0, 2.0) and section.origin == (0.0, -38.0)
    segyio.tools.from_array(str(tmp_path / "gathers.sgy"), np.zeros((3, 4, 2, 10), np.float32), dt=4000)
    with pytest.raises(ReadError, match="gathers.sgy: is a pre-stack file \\(2 offsets per bin\\)"):
        vio.read(tmp_path / "gathers.sgy")


def test_damaged_surveys_are_refused_or_read_whole(tmp_path):
    """Truncations and bit flips (in the headers: the first 3,600 bytes and the first traces' headers): a ReadError
    naming the file, or the survey's full size; a truncated survey is never read."""
    path = _survey(tmp_path / "survey.sgy")
    data = path.read_bytes()
    rng = random.Random("segy")
    mutations = [rb.flip_bits(data, rng, min(4400, len(data))) for _ in range(16)]
    mutations += [rb.truncate(data, at) for at in sorted(rng.sample(range(1, len(data)), 12))]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ReadWarning)
        assert read_mutations(path, mutations, truncated_reads_same=False) >= 12
    path.write_bytes(b"C" + bytes(100))
    with pytest.raises(ReadError, match="survey.sgy: is not a SEG-Y file"):
        vio.read(path)
