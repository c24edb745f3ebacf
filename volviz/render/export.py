"""Offscreen export: render a session or a data file to a PNG of any size, without a display and without Qt."""
from __future__ import annotations

import io
import os
from pathlib import Path
from typing import Any, Optional

import numpy as np

from volviz.jobs import ProgressCallback, report
from volviz.session import Session, atomic_write_bytes


def offscreen_plotter(size: tuple[int, int]) -> Any:
    import pyvista as pv

    return pv.Plotter(off_screen=True, window_size=[int(size[0]), int(size[1])])


def write_png(image: np.ndarray, path: str | os.PathLike) -> None:
    """Encode an (H, W, 3|4) uint8 image as PNG and write it atomically."""
    import imageio.v3 as iio

    buffer = io.BytesIO()
    iio.imwrite(buffer, np.ascontiguousarray(image), extension=".png")
    atomic_write_bytes(path, buffer.getvalue())


def render_session(session: Session, session_file: Optional[str | os.PathLike], size: tuple[int, int],
                   progress: Optional[ProgressCallback] = None) -> np.ndarray:
    """Render a session offscreen; returns the (H, W, 3) uint8 image."""
    from volviz.render.scene import build_scene, load_datasets

    datasets = load_datasets(session, session_file, progress)
    report(progress, 0.8, "rendering")
    plotter = offscreen_plotter(size)
    try:
        build_scene(plotter, session, datasets)
        image = plotter.screenshot(None, return_img=True, window_size=[int(size[0]), int(size[1])])
    finally:
        plotter.close()
    report(progress, 1.0, "rendered")
    return np.asarray(image)


def render_to_png(target: str | os.PathLike, out: str | os.PathLike, size: tuple[int, int] = (1024, 768),
                  progress: Optional[ProgressCallback] = None) -> Path:
    """Render a session file (``.json`` with the volviz-session format) or any readable data file to ``out``."""
    from volviz.render.scene import data_session, demo_session
    from volviz.session import load

    target_path = Path(target) if str(target) != "demo" else None
    if target_path is None:
        session, session_file = demo_session(), None
    elif is_session_file(target_path):
        session, session_file = load(target_path), target_path
    else:
        session, session_file = data_session(target_path), None
    image = render_session(session, session_file, size, progress)
    write_png(image, out)
    return Path(out)


def is_session_file(path: Path) -> bool:
    """Session files are JSON documents whose first bytes open an object with the volviz-session format."""
    if path.suffix.lower() not in (".json", ".vvs") or not path.is_file():
        return False
    with open(path, "rb") as handle:
        head = handle.read(4096)
    return b"volviz-session" in head
