"""A CF time coordinate checked before VTK's netCDF reader runs (issue #32): a NaN time was refused only by the
isolation's codec ("the isolated reader's result is not a valid dataset (TimeSeries.times ...)"), and equal or
decreasing times made VTK's reader keep one step and drop the other 23 without a word."""
from __future__ import annotations

import shutil

import numpy as np
import pytest
import scipy.io

import volviz.io as vio
from conftest import data_file
from volviz.io.errors import ReadError, ReadWarning
from volviz.model import TimeSeries

TOS = "ecosystem/tos_O1_2001-2002.nc"


def _with_times(tmp_path, edit) -> str:
    path = tmp_path / "tos.nc"
    shutil.copy(data_file(TOS), path)
    path.chmod(0o644)
    with scipy.io.netcdf_file(path, "a", mmap=False) as f:
        times = f.variables["time"][:].copy()
        f.variables["time"][:] = edit(times)
    return path


def test_the_real_file_reads_its_24_steps_without_a_warning(tmp_path):
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", ReadWarning)
        series = vio.read(_with_times(tmp_path, lambda t: t))
    assert isinstance(series, TimeSeries) and len(series.times) == 24


def test_a_nan_time_is_refused_naming_the_variable_and_index(tmp_path):
    path = _with_times(tmp_path, lambda t: np.where(np.arange(t.size) == 2, np.nan, t))
    with pytest.raises(ReadError) as info:
        vio.read(path)
    assert str(info.value) == (f"{path}: netCDF: time coordinate 'time' holds nan at index 2 (of 24): the file is "
                               "damaged")


@pytest.mark.parametrize("edit, where", [(lambda t: np.zeros_like(t), "0 at index 0, 0 at index 1"),
                                         (lambda t: t[::-1].copy(), "705 at index 0, 675 at index 1")])
def test_times_that_do_not_increase_are_read_with_a_warning(tmp_path, edit, where):
    path = _with_times(tmp_path, edit)
    with pytest.warns(ReadWarning, match=f"time coordinate 'time' does not increase: {where} \\(of 24\\)"):
        vio.read(path)
