"""What opening a data file or folder shows: a one-dataset session with the file's default visual. A folder shows its
collection file or largest numbered series, a series member the whole series at its time step, a height map a
terrain (``volviz.scene.terrain``), a PLOT3D grid its solution file beside it, a large compressed volume its level of
detail (``volviz.scene.lod``)."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Optional

from volviz.io import ReadError
from volviz.io.folders import folder_target
from volviz.io.plot3d_pairs import grid_of_solution, is_plot3d_solution
from volviz.io.registry import spec_of
from volviz.io.series import expand_pattern, member_time
from volviz.scene.lod import LOD_VOXELS, vvz_voxels
from volviz.scene.series import series_pattern
from volviz.scene.terrain import is_height_map, terrain_session
from volviz.session import Component, DatasetRef, Session


def _shown_in_folder(path: str | os.PathLike) -> str | os.PathLike:
    """A folder that no reader opens itself shows its collection file, or the first file of its largest numbered
    series (``volviz.io.folders``); anything else is shown as it is."""
    if not Path(path).is_dir():
        return path
    try:
        spec_of(path)
        return path
    except ReadError:
        target = folder_target(path)
    if target is None:
        return path                           # reading it says why it does not open
    return expand_pattern(target)[0][1] if "%" in Path(target).name else target


def data_session(path: str | os.PathLike, q: Optional[str | os.PathLike] = None) -> Session:
    """A one-dataset session that shows ``path`` with its default visual (what opening a data file does): a file of a
    numbered series opens the whole series at that file's time step; a height map (DEM, PGM) opens as a terrain
    under a sky (``terrain_session``); a PLOT3D grid opens with the solution file ``q`` (default: the one named like
    it), and a PLOT3D solution file opened alone opens with the grid named like it (a ReadError says what to do
    when there is none)."""
    path = _shown_in_folder(path)
    if is_height_map(path):
        return terrain_session(path)
    if q is None and Path(path).is_file() and is_plot3d_solution(path):
        grid = grid_of_solution(path)
        if grid is None:
            raise ReadError(path, "is a PLOT3D solution (q) file, and no grid (xyz) file named like it is beside it",
                            "open it together with its grid file: select both files in the Open dialog (on the "
                            "command line: GRID --q SOLUTION)")
        path, q = grid, path
    pattern = series_pattern(path)
    ref = DatasetRef(id="data", path=pattern or str(Path(path).resolve()))
    if q is not None:
        ref.options["q"] = str(Path(q).resolve())
    if Path(path).suffix.lower() == ".vvz" and vvz_voxels(path) > LOD_VOXELS:
        ref.options["lod"] = True          # too large to decode whole: blocks per view (volviz.render.lod_volume)
    session = Session(datasets=[ref], components=[Component(id="data", type="volume", dataset="data")])
    if pattern is not None:
        t = member_time(pattern, path)
        if t is not None:
            session.render.options["time"] = t   # the session's display time (``SceneController.prepare``)
    return session
