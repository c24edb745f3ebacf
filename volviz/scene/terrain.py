"""Height maps open as natural scenes: a DEM, a grey PGM, an SRTM tile or a single-band GeoTIFF becomes a C-LOD terrain
under a sky (Lindstrom-Pascucci terrain of the nature seeds), moved to the origin."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from volviz.io import read
from volviz.io.elevation import is_elevation_model
from volviz.scene.series import series_pattern
from volviz.session import Component, DatasetRef, RenderSettings, Session

HEIGHT_MAP_SUFFIXES = (".dem", ".pgm")
RELIEF = 0.1        # a grey-level height map opened directly rises to at most 1/10 of its width


def is_height_map(path: str | os.PathLike) -> bool:
    """Whether opening ``path`` should show a terrain: a USGS DEM, a grey PGM (not part of a numbered series), an
    SRTM tile or a single-band GeoTIFF (``volviz.io.elevation``)."""
    p = Path(path)
    if p.suffix.lower() in HEIGHT_MAP_SUFFIXES and p.is_file() and series_pattern(p) is None:
        return True
    return is_elevation_model(p)


def terrain_session(path: str | os.PathLike) -> Session:
    """A height map (DEM, GeoTIFF or SRTM tile in metres, PGM in grey levels) as a natural scene: its C-LOD terrain
    under a sky, moved to the origin; a PGM's grey levels are scaled so that its relief is at most ``RELIEF`` of its
    width (the others keep their true heights, so only a PGM is read here: opening a file runs this on the GUI
    thread, and reading an ASCII DEM takes as long as its loading does)."""
    settings: dict[str, Any] = {"origin": [0.0, 0.0]}
    if Path(path).suffix.lower() == ".pgm":
        image = read(path)
        rows, cols = image.data.shape[:2]
        lo, hi = image.scalar_range()
        span = hi - lo if np.isfinite(hi - lo) and hi > lo else 1.0
        settings["height_scale"] = min(1.0, RELIEF * max(rows, cols) / span)
    ref = DatasetRef(id="height_map", path=str(Path(path).resolve()))
    return Session(datasets=[ref], components=[Component(id="terrain", type="terrain", dataset="height_map",
                                                         settings=settings),
                                               Component(id="sky", type="sky")],
                   render=RenderSettings(background=(0.78, 0.85, 0.95)))
