"""Offscreen export: render a session or a data file to a PNG of any size, without a display and without Qt."""
from __future__ import annotations

import io
import os
from pathlib import Path
from typing import Any, Optional

import numpy as np

from volviz.jobs import ProgressCallback, report
from volviz.io.atomic import atomic_write_bytes
from volviz.session import Session


def offscreen_plotter(size: tuple[int, int]) -> Any:
    import pyvista as pv

    if not os.environ.get("DISPLAY"):  # VTK tries X first and warns before it falls back to EGL: not the user's concern
        from vtkmodules.vtkCommonCore import vtkLogger

        vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_ERROR)

    return pv.Plotter(off_screen=True, window_size=[int(size[0]), int(size[1])])


def write_png(image: np.ndarray, path: str | os.PathLike) -> None:
    """Encode an (H, W, 3|4) uint8 image as PNG and write it atomically."""
    import imageio.v3 as iio

    buffer = io.BytesIO()
    iio.imwrite(buffer, np.ascontiguousarray(image), extension=".png")
    atomic_write_bytes(path, buffer.getvalue())


def offscreen_scene(session: Session, datasets: dict[str, Any], size: tuple[int, int]) -> tuple[Any, Any]:
    """An offscreen plotter of ``size`` and a ``SceneController`` of ``session`` over it, not built yet: ``build()``
    here, or (the app) ``prepare`` on a worker, ``install(views=False)``, then ``begin_views`` / ``compute_views`` /
    ``finish_views``, and ``snapshot``. The caller closes the plotter."""
    from volviz.render.controller import SceneController

    plotter = offscreen_plotter(size)
    return plotter, SceneController(plotter, session, datasets)


def snapshot(plotter: Any, size: tuple[int, int]) -> np.ndarray:
    """Render the offscreen plotter (VTK side, the thread that owns it) once at ``size`` and return the (H, W, 3) uint8
    image. (``screenshot(window_size=...)`` renders twice: once after resizing and again after sizing back.)"""
    width, height = int(size[0]), int(size[1])
    if list(plotter.window_size) != [width, height]:
        plotter.render_window.SetSize(width, height)  # no render here: the one render is below
    if not plotter._first_time:  # the first image pyvista renders itself (and places a camera that was never set)
        plotter.render()
    return np.asarray(plotter.screenshot(None, return_img=True))


def render_session(session: Session, session_file: Optional[str | os.PathLike], size: tuple[int, int],
                   progress: Optional[ProgressCallback] = None) -> np.ndarray:
    """Render a session offscreen; returns the (H, W, 3) uint8 image."""
    from volviz.render.scene import load_datasets

    datasets = load_datasets(session, session_file, progress)
    report(progress, 0.8, "rendering")
    plotter, controller = offscreen_scene(session, datasets, size)
    try:
        controller.build()
        image = snapshot(plotter, size)
    finally:
        plotter.close()
    report(progress, 1.0, "rendered")
    return np.asarray(image)


def render_to_png(target: str | os.PathLike, out: str | os.PathLike, size: tuple[int, int] = (1024, 768),
                  progress: Optional[ProgressCallback] = None) -> Path:
    """Render a session file (``.json`` with the volviz-session format) or any readable data file to ``out``."""
    from volviz.render.scene import data_session, demo_session
    from volviz.session import load

    from volviz.render.scene import demo_volume_session

    target_path = Path(target) if str(target) not in ("demo", "demo-volume") else None
    if target_path is None:
        session, session_file = (demo_session() if str(target) == "demo" else demo_volume_session()), None
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


def movie_frames(controller: Any, path_name: Optional[str], fps: float, through_time: bool,
                 duration: Optional[float] = None) -> list[tuple[Optional[Any], Optional[float]]]:
    """(camera, display time) for every frame: along a recorded camera path, through the time series, or both."""
    from volviz.render.camera_path import frame_times, interpolate_path

    session = controller.session
    cameras: list[Optional[Any]] = [None]
    if path_name is not None:
        if path_name not in session.camera_paths:
            from volviz.render.scene import SceneError

            known = ", ".join(sorted(session.camera_paths)) or "none"
            raise SceneError(f"the session has no camera path named {path_name!r} (it has: {known})")
        keys = session.camera_paths[path_name]
        cameras = [interpolate_path(keys, t) for t in frame_times(keys, fps, duration)]
    times: list[Optional[float]] = [None]
    span = controller.time_span()
    if through_time and span is not None:
        n = len(cameras) if len(cameras) > 1 else max(int(round((duration or (span[1] - span[0])) * fps)) + 1, 2)
        times = [span[0] + (span[1] - span[0]) * i / (n - 1) for i in range(n)]
    n = max(len(cameras), len(times))
    return [(cameras[min(i, len(cameras) - 1)], times[min(i, len(times) - 1)]) for i in range(n)]


def _prefetch_sorts(controller: Any, camera: Any, size: tuple[int, int]) -> None:
    """Start sorting every visible PT volume for the next frame's camera while this frame renders
    (``volviz.unstructured.prefetch``)."""
    from volviz.unstructured.camera import Camera

    cam = Camera(camera.position, camera.focal_point, camera.view_up, camera.view_angle, camera.parallel,
                 camera.parallel_scale)
    for comp_id in list(controller.props):
        pt = controller.pt_volume(comp_id)
        if pt is not None and pt.visible:
            pt.prefetch(cam, (int(size[0]), int(size[1])))


def render_movie(session: Session, session_file: Optional[str | os.PathLike], out: str | os.PathLike,
                 size: tuple[int, int], path_name: Optional[str] = None, fps: float = 24.0,
                 through_time: bool = False, duration: Optional[float] = None,
                 progress: Optional[ProgressCallback] = None) -> Path:
    """Render a movie offscreen: MP4 (H.264 through imageio-ffmpeg) for ``.mp4``, else a PNG sequence in the folder
    ``out`` (frame_00000.png, ...). The MP4 is written to a temporary file and renamed when complete."""
    from volviz.render.scene import load_datasets

    datasets = load_datasets(session, session_file)
    plotter, controller = offscreen_scene(session, datasets, size)
    target = Path(out)
    try:
        controller.build()
        frames = movie_frames(controller, path_name, fps, through_time, duration)
        writer = MovieWriter(target, fps)
        try:
            for i, (camera, t) in enumerate(frames):
                if i + 1 < len(frames) and frames[i + 1][0] is not None:
                    _prefetch_sorts(controller, frames[i + 1][0], size)
                if camera is not None:
                    controller.set_camera(camera)
                if t is not None:
                    controller.set_time(t)
                writer.append(snapshot(plotter, size))
                report(progress, (i + 1) / len(frames), f"frame {i + 1} of {len(frames)}")
        except BaseException:
            writer.abort()
            raise
        writer.close()
    finally:
        plotter.close()
    return target


class ImageFile:
    """A one-frame sink with ``MovieWriter``'s interface: the PNG ``target``, written atomically."""

    def __init__(self, target: str | os.PathLike):
        self.target = Path(target)

    def append(self, image: np.ndarray) -> None:
        write_png(image, self.target)

    def close(self) -> None:
        pass

    def abort(self) -> None:
        pass


class MovieWriter:
    """MP4 through imageio-ffmpeg (to a temporary name, renamed at the end) or a PNG sequence in a folder. ``abort``
    leaves nothing of an unfinished movie: the partial MP4, or the frames written so far (and the folder if it made
    it)."""

    def __init__(self, target: Path, fps: float):
        self.target = target
        self.count = 0
        self.mp4 = target.suffix.lower() in (".mp4", ".m4v", ".mov")
        self.made_folder = False
        if self.mp4:
            import imageio.v2 as iio2

            self.tmp = target.with_name(f".{target.name}.partial{target.suffix}")
            self.writer = iio2.get_writer(self.tmp, format="FFMPEG", mode="I", fps=fps, codec="libx264",
                                          quality=8, pixelformat="yuv420p", macro_block_size=2)
        else:
            self.made_folder = not target.exists()
            target.mkdir(parents=True, exist_ok=True)

    def _frame_path(self, i: int) -> Path:
        return self.target / f"frame_{i:05d}.png"

    def append(self, image: np.ndarray) -> None:
        if self.mp4:
            h, w = image.shape[:2]
            self.writer.append_data(image[: h - h % 2, : w - w % 2, :3])
        else:
            write_png(image, self._frame_path(self.count))
        self.count += 1

    def close(self) -> None:
        if self.mp4:
            self.writer.close()
            os.replace(self.tmp, self.target)

    def abort(self) -> None:
        if self.mp4:
            try:
                self.writer.close()
            finally:
                self.tmp.unlink(missing_ok=True)
            return
        for i in range(self.count):
            self._frame_path(i).unlink(missing_ok=True)
        if self.made_folder:
            try:
                self.target.rmdir()
            except OSError:  # something else was put there meanwhile: keep it
                pass
