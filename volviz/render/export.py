"""Offscreen export: render a session or a data file to an image (PNG, JPEG, TIFF: the file extension decides) or a
movie (MP4 or a folder of PNG frames), without a display and without Qt.

What is written and where is checked before anything renders (``check_output``, ``check_image_size``): an unknown
extension, a target that is not a regular file (a device, FIFO, folder or symbolic link), or an image too large for
this machine's memory is an ``ExportError`` naming the output, never a temporary file's name.
"""
from __future__ import annotations

import importlib.util
import io
import math
import os
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterator, Optional, Sequence

import numpy as np
from PIL import Image

from volviz.argtypes import MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE, MAX_MOVIE_FRAMES
from volviz.io.atomic import OutputPathError, atomic_write_bytes, check_output_path, remove_stale_temporaries, temp_name
from volviz.jobs import ProgressCallback, report
from volviz.model.camera import Camera
from volviz.model.settings import array_key
from volviz.render.camera_path import frame_times, interpolate_path
from volviz.render.controller import SceneController
from volviz.render.offscreen import draw_projected_tetrahedra_once, offscreen_plotter
from volviz.scene.datasets import load_datasets
from volviz.scene.demo import demo_session, demo_volume_session
from volviz.scene.errors import SceneError
from volviz.scene.opening import data_session
from volviz.session import Session, load

if TYPE_CHECKING:   # type-only imports for the signatures
    import pyvista as pv

    from volviz.scene.datasets import LoadedDataset
    from volviz.session import CameraState

#: image formats by file extension (Pillow's names)
IMAGE_FORMATS = {".png": "PNG", ".jpg": "JPEG", ".jpeg": "JPEG", ".tif": "TIFF", ".tiff": "TIFF"}
#: movie containers by file extension (ffmpeg's names); a path without an extension is a folder of PNG frames
MOVIE_FORMATS = {".mp4": "mp4", ".m4v": "mp4", ".mov": "mov"}
#: memory an offscreen render needs per pixel, about (measured: 8192 x 8192 peaked at 5.9 GB)
RENDER_BYTES_PER_PIXEL = 96


class ExportError(Exception):
    """An output volviz cannot make: a format it does not write, a size it cannot render, or a failed write.
    The message names the output the user gave."""


def output_kind(path: str | os.PathLike, movie: bool = False) -> str:
    """What ``path`` receives: an image format ("PNG", "JPEG", "TIFF") or, for a movie, "mp4", "mov" or "folder".
    ExportError when the extension says neither."""
    p = Path(path)
    suffix = p.suffix.lower()
    if movie:
        if suffix in MOVIE_FORMATS:
            if importlib.util.find_spec("imageio_ffmpeg") is None:
                raise ExportError(f"{p}: writing {suffix} movies needs imageio-ffmpeg, which is not installed: pip "
                                  "install 'volviz[movies]' (or give a folder to receive PNG frames)")
            return MOVIE_FORMATS[suffix]
        if not suffix or p.is_dir():
            return "folder"
        raise ExportError(f"{p}: a movie is written to .mp4, .m4v, .mov or a folder, not {suffix}")
    if suffix in IMAGE_FORMATS:
        return IMAGE_FORMATS[suffix]
    if suffix in MOVIE_FORMATS:
        raise ExportError(f"{p} is a movie: give --orbit, --time or --path NAME (or an image extension)")
    check_output_path(p)  # a folder, device, ... is refused for what it is
    raise ExportError(f"{p}: unknown image format {suffix or '(no extension)'}; use .png, .jpg/.jpeg or .tif/.tiff")


def check_output(path: str | os.PathLike, movie: bool = False) -> str:
    """``output_kind`` of ``path``, after checking that volviz may write there (``check_output_path``: an absent
    target or a regular file, a folder for frames; never a device, FIFO or symbolic link)."""
    kind = output_kind(path, movie)
    check_output_path(path, directory=kind == "folder")
    return kind


def _available_memory() -> Optional[int]:
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):  # not on this platform
        return None


def check_image_size(size: tuple[int, int]) -> None:
    """ExportError when an image of ``size`` cannot be rendered offscreen here: larger than ``MAX_IMAGE_SIDE`` a
    side or ``MAX_IMAGE_PIXELS`` in all, or needing more memory than is free now."""
    w, h = int(size[0]), int(size[1])
    if not (1 <= w <= MAX_IMAGE_SIDE and 1 <= h <= MAX_IMAGE_SIDE) or w * h > MAX_IMAGE_PIXELS:
        raise ExportError(f"image size {w}x{h} cannot be rendered: at most {MAX_IMAGE_SIDE} a side")
    need, free = w * h * RENDER_BYTES_PER_PIXEL, _available_memory()
    if free is not None and need > free:
        raise ExportError(f"an image of {w}x{h} needs about {need / 2 ** 30:.1f} GB of memory to render, and "
                          f"{free / 2 ** 30:.1f} GB is free")


def encode_image(image: np.ndarray, image_format: str = "PNG") -> bytes:
    """An (H, W, 3|4) uint8 image encoded as ``image_format`` (PNG, JPEG at quality 95, or deflated TIFF)."""
    picture = Image.fromarray(np.ascontiguousarray(image))
    options: dict[str, Any] = {}
    if image_format == "JPEG":
        picture, options = picture.convert("RGB"), {"quality": 95}
    elif image_format == "TIFF":
        options = {"compression": "tiff_deflate"}
    buffer = io.BytesIO()
    picture.save(buffer, format=image_format, **options)
    return buffer.getvalue()


@contextmanager
def _named_errors(target: Path, tmp: Optional[Path] = None) -> Iterator[None]:
    """A failure inside becomes an ExportError naming ``target`` (never the temporary file ``tmp``)."""
    try:
        yield
    except OutputPathError:
        raise
    except (OSError, RuntimeError, ValueError) as exc:
        text = (getattr(exc, "strerror", None) or str(exc) or type(exc).__name__).strip().splitlines()[0]
        if tmp is not None:
            text = text.replace(str(tmp), str(target)).replace(tmp.name, target.name)
        raise ExportError(f"cannot write {target}: {text}") from None


def write_file(path: str | os.PathLike, data: bytes) -> None:
    """Write ``data`` atomically to ``path``; a failure is an ExportError naming ``path`` (not the temporary)."""
    with _named_errors(Path(path)):
        atomic_write_bytes(path, data)


def write_image(image: np.ndarray, path: str | os.PathLike) -> None:
    """Write an (H, W, 3|4) uint8 image atomically in the format its extension names (``output_kind``)."""
    write_file(path, encode_image(image, output_kind(path)))


def write_png(image: np.ndarray, path: str | os.PathLike) -> None:
    """Encode an (H, W, 3|4) uint8 image as PNG and write it atomically (whatever the extension)."""
    write_file(path, encode_image(image, "PNG"))


def offscreen_scene(session: Session, datasets: dict[str, LoadedDataset],
                    size: tuple[int, int]) -> tuple[pv.Plotter, SceneController]:
    """An offscreen plotter of ``size`` and a ``SceneController`` of ``session`` over it, not built yet: ``build()``
    here, or (the app) ``prepare`` on a worker, ``install(views=False)``, then ``begin_views`` / ``compute_views`` /
    ``finish_views``, and ``snapshot``. The caller ends it with ``close_scene``."""
    plotter = offscreen_plotter(size)
    return plotter, SceneController(plotter, session, datasets)


def close_scene(plotter: pv.BasePlotter, controller: SceneController) -> None:
    """Take the controller's views out (the GPU passes free their GL resources while the plotter's context lives)
    and close the plotter: an offscreen scene's end, however its rendering ended."""
    try:
        controller.clear()
    finally:
        plotter.close()


def size_window(plotter: pv.BasePlotter, size: tuple[int, int]) -> None:
    """Give the offscreen plotter's window ``size`` without rendering. The view-dependent CPU images (the natural
    scene's fog and cloud overlay) are computed at the window's size when they begin: begun at another size, they
    cover only part of the frame (issue #28: an export's first frame showed no clouds or fog)."""
    width, height = int(size[0]), int(size[1])
    if list(plotter.window_size) != [width, height]:
        plotter.render_window.SetSize(width, height)  # type: ignore[union-attr]  # None only once closed


def snapshot(plotter: pv.BasePlotter, size: tuple[int, int], transparent: bool = False) -> np.ndarray:
    """Render the offscreen plotter (VTK side, the thread that owns it) once at ``size`` and return the (H, W, 3) uint8
    image, or with ``transparent`` the (H, W, 4) straight-alpha image without the background, from two renders
    (``separate_background``). (``screenshot(window_size=...)`` renders twice: once after resizing and again after
    sizing back.)"""
    size_window(plotter, size)  # no render here: the one render is below
    if not transparent:
        return _render_image(plotter)
    renderer = plotter.renderer
    kept = renderer.GetBackground()
    try:
        renderer.SetBackground(0.0, 0.0, 0.0)
        on_black = _render_image(plotter)
        renderer.SetBackground(1.0, 1.0, 1.0)
        on_white = _render_image(plotter)
    finally:
        renderer.SetBackground(*kept)
    return separate_background(on_black, on_white)


def _render_image(plotter: Any) -> np.ndarray:
    if plotter._first_time:  # the first image pyvista renders itself (and places a camera that was never set)
        draw_projected_tetrahedra_once(plotter)
    else:
        plotter.render()
    return np.asarray(plotter.screenshot(None, return_img=True))[..., :3]


def separate_background(on_black: np.ndarray, on_white: np.ndarray) -> np.ndarray:
    """The straight-alpha (H, W, 4) uint8 image of a scene rendered over a black and over a white background: every
    blend (volumes, antialiased lines and text, multisampling) is linear in the background, so 1 - alpha is the
    difference of the two and the color premultiplied by alpha is the image on black. Composited over any color it
    is the render over that color within one 8-bit step (rounding). (VTK's own alpha channel disagreed with its color
    on antialiased lines: the outline box came out half transparent, issue #28.)"""
    black = np.asarray(on_black, dtype=np.float64)[..., :3]
    white = np.asarray(on_white, dtype=np.float64)[..., :3]
    alpha = np.clip(255.0 - (white - black).mean(axis=2), 0.0, 255.0)
    alpha8 = np.rint(alpha)
    color = np.where(alpha8[..., None] > 0.0, black * 255.0 / np.maximum(alpha8, 1.0)[..., None], 0.0)
    out = np.empty(black.shape[:2] + (4,), dtype=np.uint8)
    out[..., :3] = np.clip(np.rint(color), 0, 255)
    out[..., 3] = alpha8
    return out


def check_transparency(path: str | os.PathLike) -> None:
    """ExportError when the image ``path`` names cannot keep a transparent background (JPEG has no alpha)."""
    if output_kind(path) == "JPEG":
        raise ExportError(f"{Path(path)}: JPEG has no transparency; use .png or .tif/.tiff for a transparent "
                          "background")


def render_session(session: Session, session_file: Optional[str | os.PathLike], size: tuple[int, int],
                   progress: Optional[ProgressCallback] = None,
                   datasets: Optional[dict[str, LoadedDataset]] = None, transparent: bool = False) -> np.ndarray:
    """Render a session offscreen (its datasets read now unless given); returns the (H, W, 3) uint8 image, or with
    ``transparent`` the (H, W, 4) straight-alpha one without the background (``snapshot``)."""
    datasets = load_datasets(session, session_file, progress, loaded=datasets)
    report(progress, 0.8, "rendering")
    plotter, controller = offscreen_scene(session, datasets, size)
    try:
        controller.build()
        image = snapshot(plotter, size, transparent)
    finally:
        close_scene(plotter, controller)
    report(progress, 1.0, "rendered")
    return np.asarray(image)


def open_target(target: str | os.PathLike, array: Optional[str] = None, q: Optional[str | os.PathLike] = None,
                reader_options: Optional[dict[str, object]] = None) -> tuple[Session, Optional[Path]]:
    """The session a command-line target names, and its file: ``demo``, ``demo-volume``, a session file, or a data
    file shown with the array spec ``array`` (``volviz.model.arrays``), the PLOT3D solution file ``q`` and the
    options of its reader (``dataset=`` of an HDF5 file ...), kept in the session's dataset. A member of a numbered
    series opens the whole series at that member's time step (``data_session``)."""
    if str(target) in ("demo", "demo-volume"):
        return (demo_session() if str(target) == "demo" else demo_volume_session()), None
    path = Path(target)
    if is_session_file(path):
        return load(path), path
    session = data_session(path, q)
    session.datasets[0].options.update(reader_options or {})
    comp = session.components[0]
    if array is not None:
        comp.settings[array_key(comp.type)] = str(array)
    return session, None


def render_to_file(session: Session, session_file: Optional[str | os.PathLike], out: str | os.PathLike,
                   size: tuple[int, int], progress: Optional[ProgressCallback] = None,
                   datasets: Optional[dict[str, LoadedDataset]] = None, transparent: bool = False) -> Path:
    """Render a session to the image ``out`` in the format its extension names (``transparent``: without the
    background, where the format keeps alpha); the output and the size are checked before anything renders
    (ExportError)."""
    check_output(out)
    check_image_size(size)
    if transparent:
        check_transparency(out)
    image = render_session(session, session_file, size, progress, datasets, transparent)
    write_image(image, out)
    return Path(out)


def render_to_png(target: str | os.PathLike, out: str | os.PathLike, size: tuple[int, int] = (1024, 768),
                  progress: Optional[ProgressCallback] = None) -> Path:
    """Render a session file (``.json`` with the volviz-session format), ``demo``, ``demo-volume`` or any readable
    data file to the image ``out`` (PNG, JPEG or TIFF by its extension)."""
    session, session_file = open_target(target)
    return render_to_file(session, session_file, out, size, progress)


def is_session_file(path: Path) -> bool:
    """Session files are JSON documents whose first bytes open an object with the volviz-session format."""
    if path.suffix.lower() not in (".json", ".vvs") or not path.is_file():
        return False
    with open(path, "rb") as handle:
        head = handle.read(4096)
    return b"volviz-session" in head


def orbit_cameras(camera: CameraState, n: int, turns: float = 1.0) -> list[CameraState]:
    """``n`` cameras evenly spaced over ``turns`` full turns of ``camera`` around its view-up axis through the focal
    point (the last frame stops one step short of the first, so the movie loops)."""
    focal = np.asarray(camera.focal_point, dtype=np.float64)
    axis = np.asarray(camera.view_up, dtype=np.float64)
    axis = axis / (np.linalg.norm(axis) or 1.0)
    offset = np.asarray(camera.position, dtype=np.float64) - focal
    cameras = []
    for i in range(n):
        a = 2.0 * math.pi * turns * i / n
        # Rodrigues: the offset rotated by a about the axis (the view-up vector is on the axis: it stays)
        rotated = (offset * math.cos(a) + np.cross(axis, offset) * math.sin(a)
                   + axis * float(np.dot(axis, offset)) * (1.0 - math.cos(a)))
        cameras.append(replace(camera, position=tuple(float(v) for v in focal + rotated)))  # type: ignore[arg-type]
    return cameras


def movie_frames(controller: SceneController, path_name: Optional[str], fps: float, through_time: bool,
                 duration: Optional[float] = None,
                 orbit: bool = False) -> list[tuple[Optional[CameraState], Optional[float]]]:
    """(camera, display time) for every frame: along a recorded camera path or an orbit of the current camera
    (one turn over ``duration``, default 8 s), through the time series, or both. ExportError past
    ``MAX_MOVIE_FRAMES``."""
    session = controller.session
    cameras: Sequence[Optional[CameraState]] = [None]
    if path_name is not None:
        if path_name not in session.camera_paths:
            known = ", ".join(sorted(session.camera_paths)) or "none"
            raise SceneError(f"the session has no camera path named {path_name!r} (it has: {known})")
        keys = session.camera_paths[path_name]
        cameras = [interpolate_path(keys, t) for t in frame_times(keys, fps, duration)]
    elif orbit:
        cameras = orbit_cameras(controller.camera(), frame_count(fps, 8.0 if duration is None else duration))
    times: list[Optional[float]] = [None]
    span = controller.time_span()
    if through_time and span is None:
        raise ExportError("--time: the scene shows no time series (open a numbered series or a time-varying file)")
    if through_time and span is not None:
        n = len(cameras) if len(cameras) > 1 else max(frame_count(fps, duration or (span[1] - span[0])) + 1, 2)
        times = [span[0] + (span[1] - span[0]) * i / (n - 1) for i in range(n)]
    n = max(len(cameras), len(times))
    return [(cameras[min(i, len(cameras) - 1)], times[min(i, len(times) - 1)]) for i in range(n)]


def frame_count(fps: float, seconds: float) -> int:
    """Frames of ``seconds`` at ``fps`` (at least 1); ExportError past ``MAX_MOVIE_FRAMES``."""
    n = max(int(round(fps * seconds)), 1)
    if n > MAX_MOVIE_FRAMES:
        raise ExportError(f"a movie of {seconds:g} s at {fps:g} frames per second has {n} frames; at most "
                          f"{MAX_MOVIE_FRAMES} are made")
    return n


def _prefetch_sorts(controller: Any, camera: Any, size: tuple[int, int]) -> None:
    """Start sorting every visible PT volume (either backend) for the next frame's camera while this frame renders
    (``volviz.unstructured.prefetch``)."""
    cam = Camera(camera.position, camera.focal_point, camera.view_up, camera.view_angle, camera.parallel,
                 camera.parallel_scale)
    for comp_id in list(controller.props):
        pt = controller.pt_volume(comp_id) or controller.gl_pt_volume(comp_id)
        if pt is not None and pt.visible:
            pt.prefetch(cam, (int(size[0]), int(size[1])))


def render_movie(session: Session, session_file: Optional[str | os.PathLike], out: str | os.PathLike,
                 size: tuple[int, int], path_name: Optional[str] = None, fps: float = 24.0,
                 through_time: bool = False, duration: Optional[float] = None,
                 progress: Optional[ProgressCallback] = None, orbit: bool = False,
                 datasets: Optional[dict[str, LoadedDataset]] = None) -> Path:
    """Render a movie offscreen (``movie_frames``): MP4/MOV (H.264 through imageio-ffmpeg) for ``.mp4``, ``.m4v``
    and ``.mov``, else a PNG sequence in the folder ``out`` (frame_00000.png, ...). The output and the size are
    checked first; the MP4 is written to a temporary file and renamed when complete."""
    check_output(out, movie=True)
    check_image_size(size)
    datasets = load_datasets(session, session_file, loaded=datasets)
    plotter, controller = offscreen_scene(session, datasets, size)
    target = Path(out)
    try:
        controller.build()
        frames = movie_frames(controller, path_name, fps, through_time, duration, orbit)
        if len(frames) > MAX_MOVIE_FRAMES:
            raise ExportError(f"{target}: the movie would have {len(frames)} frames; at most {MAX_MOVIE_FRAMES}")
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
        close_scene(plotter, controller)
    return target


class ImageFile:
    """A one-frame sink with ``MovieWriter``'s interface: the image ``target`` (PNG, JPEG or TIFF by its
    extension), written atomically."""

    def __init__(self, target: str | os.PathLike):
        self.target = Path(target)

    def append(self, image: np.ndarray) -> None:
        write_image(image, self.target)

    def close(self) -> None:
        pass

    def abort(self) -> None:
        pass


class MovieWriter:
    """MP4/MOV through imageio-ffmpeg (to a temporary name beside the target, renamed at the end) or a PNG sequence
    in a folder. ``abort`` leaves nothing of an unfinished movie: the partial file, or the frames written so far (and
    the folder if it made it). Failures are ExportErrors naming the target, never the temporary."""

    def __init__(self, target: Path, fps: float):
        self.target = target
        self.count = 0
        self.container = MOVIE_FORMATS.get(target.suffix.lower())
        self.mp4 = self.container is not None
        self.made_folder = False
        self.tmp: Optional[Path] = None
        self.fps = fps
        self.writer: Any = None  # the ffmpeg process, started by the first frame (it needs the frame size)
        if self.mp4:
            check_output_path(target)
            remove_stale_temporaries(target.parent)
            self.tmp = temp_name(target)
        else:
            check_output_path(target, directory=True)
            self.made_folder = not target.exists()
            with _named_errors(self.target, self.tmp):
                target.mkdir(exist_ok=True)

    def _start(self, width: int, height: int) -> Any:
        """The ffmpeg process writing H.264 into the temporary file (its container named, as the temporary's name
        has no extension)."""
        # optional: imageio-ffmpeg (volviz[movies]), needed only to write a movie
        import imageio_ffmpeg

        writer = imageio_ffmpeg.write_frames(str(self.tmp), (width, height), fps=self.fps, codec="libx264",
                                             quality=8, pix_fmt_out="yuv420p", macro_block_size=2,
                                             output_params=["-f", str(self.container)])
        writer.send(None)  # start the generator
        return writer

    def _frame_path(self, i: int) -> Path:
        return self.target / f"frame_{i:05d}.png"

    def append(self, image: np.ndarray) -> None:
        if self.mp4:
            h, w = image.shape[:2]
            frame = np.ascontiguousarray(image[: h - h % 2, : w - w % 2, :3])
            with _named_errors(self.target, self.tmp):
                if self.writer is None:
                    self.writer = self._start(frame.shape[1], frame.shape[0])
                self.writer.send(frame)
        else:
            write_png(image, self._frame_path(self.count))
        self.count += 1

    def close(self) -> None:
        if self.mp4:
            assert self.tmp is not None  # named in __init__ for a movie
            try:
                with _named_errors(self.target, self.tmp):
                    if self.writer is None:
                        raise ExportError(f"{self.target}: a movie needs at least one frame")
                    self.writer.close()
                    check_output_path(self.target)  # it may have become something else while we wrote
                    os.replace(self.tmp, self.target)
            except BaseException:
                self.tmp.unlink(missing_ok=True)
                raise

    def abort(self) -> None:
        if self.mp4:
            assert self.tmp is not None  # named in __init__ for a movie
            try:
                if self.writer is not None:
                    self.writer.close()
            except Exception:  # the movie is being abandoned: its writer's own failure is not news
                pass
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
