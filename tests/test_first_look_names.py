"""A first-look warning names the file by the path its reader read (``volviz.scene.first_look``, issue #28): with
a session file, a dataset's stored path is relative to the session's folder, and the warning named it that way
("../../work/shared/data/...": a path relative to no folder the user sees); now it names the file as the read
warnings of the same file do (the path as given, made absolute against a session file)."""
from __future__ import annotations

import warnings

import numpy as np

from test_first_look_rule import _grid
from volviz.scene.datasets import load_datasets
from volviz.scene.first_look import FirstLookWarning, first_look
from volviz.scene.opening import data_session
from volviz.session import relative_path


def _said(path, session_file) -> list[str]:
    """The first-look warnings of ``path`` opened in a session saved as ``session_file`` (its dataset path stored
    relative to it, as saving does)."""
    session = data_session(path)
    for ref in session.datasets:
        ref.path = relative_path(session_file, ref.path)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        datasets = load_datasets(session, session_file)
        first_look(session, datasets, None)
    return [str(w.message) for w in said if isinstance(w.message, FirstLookWarning)]


def test_a_first_look_warning_names_the_file_by_its_absolute_path(tmp_path) -> None:
    data = tmp_path / "data"
    (tmp_path / "sessions" / "deep").mkdir(parents=True)
    data.mkdir()
    session_file = tmp_path / "sessions" / "deep" / "s.json"
    _grid(data / "const.vti", (20, 20, 20), np.full((20, 20, 20), 3.5), "c")
    said = _said(data / "const.vti", session_file)
    named = (data / "const.vti").resolve()
    assert said == [f"{named}: the field c is constant (3.5 everywhere): drawn as a surface"], said
    r = np.linspace(-1, 1, 12)
    blob = np.exp(-3 * (r[:, None, None] ** 2 + r[None, :, None] ** 2 + r[None, None, :] ** 2))
    for i in range(3):
        _grid(data / f"step_{i}.vti", (12, 12, 12), blob * i, "u")
    said = _said(data / "step_0.vti", session_file)
    assert len(said) == 1 and said[0].startswith(f"{(data / 'step_0.vti').resolve()}: "), said
    assert "u is constant at the first time step; showing step 2 of 3" in said[0]
