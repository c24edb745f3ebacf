"""Tecplot zone headers that disagree with their values (issue #32, found by the robustness campaign and rebuilt
with ``volviz bench robustness --replay``): ``cellcentered.tec``'s second zone with ``J=2`` emptied to ``J=`` was
read by VTK as a zone of the default J = 1 (2 points) with its values shifted, and a zone holding more values than
its header needs was read without a word. Both are refused before VTK runs, naming the zone, the line and the
counts; the file as written still reads."""
from __future__ import annotations

import pytest

import volviz.io as vio
from conftest import data_file


@pytest.fixture
def tec(tmp_path):
    text = data_file("ecosystem/cellcentered.tec").read_text()
    assert "I=2, J=2, K=1" in text and text.rstrip().endswith("0.2 0.25 0.3 0.05")
    return tmp_path / "cellcentered.tec", text


def test_the_file_as_written_reads(tec):
    path, text = tec
    path.write_text(text)
    assert vio.read(path).n_points == 8


def test_a_count_emptied_is_refused_naming_the_zone(tec):
    path, text = tec
    path.write_text(text.replace("J=2,", "J=,"))
    with pytest.raises(vio.ReadError, match=rf"^{path}: zone 2 \(ZONE2\), at line 10: J= has no value; a count "
                                            r"must be a whole number$"):
        vio.read(path)


def test_a_zone_with_more_values_than_its_header_needs_is_refused(tec):
    path, text = tec
    path.write_text(text.rstrip("\n") + " 0.07\n")
    with pytest.raises(vio.ReadError, match=rf"^{path}: zone 2 \(ZONE2\), at line 10, holds 20 values where its "
                                            r"header needs 19 \(7 variables on 2x2x1 points\): the zone header is "
                                            r"wrong$"):
        vio.read(path)


def test_a_count_that_is_not_a_whole_number_is_refused(tec):
    path, text = tec
    path.write_text(text.replace("I=2, J=2", "I=abc, J=2"))      # the re-run's case 2706: VTK read it as I = 1
    with pytest.raises(vio.ReadError, match=rf"^{path}: zone 2 \(ZONE2\), at line 10: I=abc; a count must be a "
                                            r"whole number$"):
        vio.read(path)


def test_a_value_that_is_not_a_number_is_refused(tec):
    path, text = tec
    head, _, tail = text.rpartition("0.05")                       # zone 2's last value: the re-run's case 2865
    path.write_text(head + "abc" + tail)
    with pytest.raises(vio.ReadError, match=rf"^{path}: line 15 holds 'abc' among the values of zone 2; a value must "
                                            r"be a number$"):
        vio.read(path)


def test_a_nan_value_is_a_value(tec):
    """NaN is data a writer of floats may print, not damage: the file reads with its 8 points."""
    path, text = tec
    head, _, tail = text.rpartition("0.05")
    path.write_text(head + "NaN" + tail)
    assert vio.read(path).n_points == 8
