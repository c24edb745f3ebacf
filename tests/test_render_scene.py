"""Sessions rendered offscreen: isosurface components over a time series, display time, movies, file modes."""
from __future__ import annotations

import json
import os
import stat
from pathlib import Path

import imageio.v3 as iio
import numpy as np

from conftest import data_file
from volviz.cli import main


def storm_iso_session(tmp_path: Path, time: float) -> Path:
    storm = data_file("storm/Storm.pvm-t01").parent
    doc = {
        "format": "volviz-session", "version": 1,
        "datasets": [{"id": "storm", "path": os.path.relpath(storm / "Storm.pvm-t%02d", tmp_path)}],
        "components": [{"id": "iso", "type": "isosurface", "dataset": "storm", "settings": {
            "styles": [{"value": 40, "color": [0.2, 0.5, 1.0], "opacity": 0.3},
                       {"value": 120, "color": [1.0, 0.8, 0.2], "opacity": 0.6}]}}],
        "camera": {"position": [80, -40, 60], "focal_point": [14, 14, 11], "view_up": [0, 0, 1], "view_angle": 30},
        # the lit pixels measured are the surfaces': no outline box or orientation axes
        "render": {"options": {"time": time, "outline": False, "axes": False}, "background": [0, 0, 0]},
    }
    path = tmp_path / f"storm-iso-{time}.json"
    path.write_text(json.dumps(doc))
    return path


def lit_fraction(image: np.ndarray) -> float:
    return float((image[..., :3].astype(int).sum(axis=2) > 30).mean())


def test_isosurface_session_follows_the_display_time(tmp_path: Path) -> None:
    empty, stormy = tmp_path / "t1.png", tmp_path / "t12.png"
    assert main(["render", str(storm_iso_session(tmp_path, 1.0)), "-o", str(empty), "--size", "160x120"]) == 0
    assert main(["render", str(storm_iso_session(tmp_path, 12.5)), "-o", str(stormy), "--size", "160x120"]) == 0
    assert lit_fraction(iio.imread(empty)) == 0.0  # the storm has not formed at t = 1: no isosurface
    assert lit_fraction(iio.imread(stormy)) > 0.02
    mode = stat.S_IMODE(stormy.stat().st_mode)
    assert mode & 0o044, f"exported file is not readable by others (mode {mode:o})"


def test_movie_through_time_as_png_sequence(tmp_path: Path) -> None:
    frames = tmp_path / "frames"
    session = storm_iso_session(tmp_path, 1.0)
    assert main(["render", str(session), "--time", "--fps", "2", "--duration", "2", "-o", str(frames),
                 "--size", "96x64"]) == 0
    images = [iio.imread(p) for p in sorted(frames.glob("frame_*.png"))]
    assert len(images) == 5
    lit = [lit_fraction(im) for im in images]
    assert lit[0] == 0.0 and lit[-1] > 0.02  # from the empty first step to the grown storm


def test_movie_mp4(tmp_path: Path) -> None:
    out = tmp_path / "storm.mp4"
    assert main(["render", str(storm_iso_session(tmp_path, 1.0)), "--time", "--fps", "4", "--duration", "1",
                 "-o", str(out), "--size", "96x64"]) == 0
    import imageio.v2 as iio2

    reader = iio2.get_reader(out, format="FFMPEG")
    count = sum(1 for _ in reader)
    reader.close()
    assert count == 5
    assert not list(tmp_path.glob(".*partial*"))


def test_an_aborted_movie_leaves_nothing_it_wrote(tmp_path: Path) -> None:
    """``MovieWriter.abort`` (cancel, failure, window closed): the partial MP4 and the frames written so far go; a
    folder the export did not make, and what else is in it, stay."""
    from volviz.render.export import MovieWriter

    frame = np.full((64, 96, 3), 120, np.uint8)
    made = MovieWriter(tmp_path / "new-folder", 4.0)
    for _ in range(3):
        made.append(frame)
    assert len(list((tmp_path / "new-folder").glob("frame_*.png"))) == 3
    made.abort()
    assert not (tmp_path / "new-folder").exists()
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("the user's")
    into = MovieWriter(mine, 4.0)
    into.append(frame)
    into.abort()
    assert sorted(p.name for p in mine.iterdir()) == ["notes.txt"]
    movie = MovieWriter(tmp_path / "cut.mp4", 4.0)
    for _ in range(12):
        movie.append(frame)
    movie.abort()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine"]


def test_missing_camera_path_is_a_clear_error(tmp_path: Path, capsys) -> None:
    assert main(["render", str(storm_iso_session(tmp_path, 1.0)), "--path", "nope", "-o",
                 str(tmp_path / "x.mp4")]) == 2
    assert "no camera path named 'nope'" in capsys.readouterr().err


def test_render_settings_map_to_the_pt_renderer() -> None:
    from volviz.scene.tetra import pt_options

    assert pt_options({}) == {}
    assert pt_options({"table": "3d", "table_resolution": 64, "sort": "centroid"}) == \
        {"lookup": "3d", "n_s": 64, "sort": "centroid"}
    assert pt_options({"table": "separable-4", "table_resolution": 256}) == \
        {"lookup": "separable", "degree": 4, "n_s": 256}
    assert pt_options({"table": "auto", "table_resolution": 256, "sort": "bogus"}) == {}


def test_movie_export_sorts_the_next_frame_in_the_background() -> None:
    from volviz.render.controller import SceneController
    from volviz.render.export import _prefetch_sorts
    from volviz.render.offscreen import offscreen_plotter
    from volviz.session import CameraState, Component, RenderSettings, Session

    session = Session(components=[Component(id="demo", type="demo", settings={"cells_per_edge": 5})],
                      render=RenderSettings(method="pt", size=(64, 48)))
    plotter = offscreen_plotter((64, 48))
    try:
        controller = SceneController(plotter, session, {})
        controller.build()
        pt = controller.pt_volume("demo")
        assert pt is not None
        nxt = CameraState(position=(2.5, -1.5, 1.2), focal_point=(0.5, 0.5, 0.5), view_up=(0, 0, 1))
        controller.set_camera(CameraState(position=(2.0, -2.0, 1.5), focal_point=(0.5, 0.5, 0.5)))
        assert pt.stats["sort_prefetched"] is False
        controller.set_camera(nxt)
        plain = pt.image.copy()
        controller.set_camera(CameraState(position=(2.0, -2.0, 1.5), focal_point=(0.5, 0.5, 0.5)))
        _prefetch_sorts(controller, nxt, (64, 48))             # while this frame is shown, sort for the next
        controller.set_camera(nxt)
        assert pt.stats["sort_prefetched"] is True
        assert np.array_equal(pt.image, plain)
    finally:
        plotter.close()


def test_movie_export_sorts_the_next_frame_of_a_gpu_volume_in_the_background() -> None:
    """The GPU backend's PT volume draws each movie frame with the order sorted while the frame before rendered, and
    that frame is the one a sort in the render gives."""
    from volviz.render.controller import SceneController
    from volviz.render.export import _prefetch_sorts
    from volviz.render.offscreen import offscreen_plotter
    from volviz.render.gl_pt import GLPTVolume
    from volviz.session import CameraState, Component, RenderSettings, Session

    session = Session(components=[Component(id="demo", type="demo", settings={"cells_per_edge": 5})],
                      render=RenderSettings(method="pt", size=(64, 48), options={"backend": "gpu", "gpu_thread": "off"}))
    plotter = offscreen_plotter((64, 48))
    try:
        controller = SceneController(plotter, session, {})
        controller.build()
        gl = controller.gl_pt_volume("demo")
        assert isinstance(gl, GLPTVolume) and controller.pt_volume("demo") is None
        first = CameraState(position=(2.0, -2.0, 1.5), focal_point=(0.5, 0.5, 0.5), view_up=(0, 0, 1))
        nxt = CameraState(position=(2.5, -1.5, 1.2), focal_point=(0.5, 0.5, 0.5), view_up=(0, 0, 1))
        controller.set_camera(nxt)
        plotter.render()
        plain = plotter.screenshot(return_img=True)
        assert gl.stats["sorted"] and not gl.stats["sort_prefetched"]
        controller.set_camera(first)
        plotter.render()
        _prefetch_sorts(controller, nxt, (64, 48))             # while this frame is shown, sort for the next
        controller.set_camera(nxt)
        plotter.render()
        assert gl.stats["sort_prefetched"] is True
        assert np.array_equal(plotter.screenshot(return_img=True), plain)
        controller.clear()                                     # the GL resources go before the context
    finally:
        plotter.close()


def test_the_session_keeps_the_scenes_interpolation_switch():
    """4D interpolation is one switch for the scene, kept in the components' ``interpolate`` settings: on unless a
    component turns it off."""
    from volviz.render.controller import session_interpolates
    from volviz.session import Component, Session

    assert session_interpolates(Session(components=[Component("a", "volume"), Component("b", "isosurface")]))
    assert session_interpolates(Session(components=[Component("a", "volume", settings={"interpolate": True})]))
    assert not session_interpolates(Session(components=[Component("a", "volume"),
                                                        Component("b", "volume", settings={"interpolate": False})]))


def test_first_offscreen_image_of_a_pt_volume_sees_the_outline_box() -> None:
    """A data file of unstructured cells (notch_disp.vtu, a thin slab) rendered offscreen with the default outline
    box, whose edges lie on the mesh's surface: the CPU PT image of the first frame is made over the whole opaque
    scene, outline included, as every later update is (it was made before the outline was added, so the box's edges
    on the near side were covered by the volume in the first frame only: 291 pixels off by up to 229), and the GPU
    backend gives the same viewport. Measured: first frame equal to the second; GPU vs CPU RMSE 0.17, max 2."""
    from volviz.render.export import close_scene, offscreen_scene, snapshot
    from volviz.scene.datasets import load_datasets
    from volviz.scene.opening import data_session

    images = {}
    for backend in ("cpu", "gpu"):
        session = data_session(data_file("ecosystem/notch_disp.vtu"))
        session.render.options["backend"] = backend
        assert session.render.options.get("outline", True)
        plotter, controller = offscreen_scene(session, load_datasets(session, None), (320, 240))
        try:
            controller.build()
            first = snapshot(plotter, (320, 240)).astype(float)
            controller.update_views()
            second = snapshot(plotter, (320, 240)).astype(float)
            assert controller.pt_backends() == {"data": backend}
        finally:
            close_scene(plotter, controller)
        assert np.array_equal(first, second), backend
        images[backend] = first
    d = images["gpu"] - images["cpu"]
    rmse, worst = float(np.sqrt((d ** 2).mean())), float(np.abs(d).max())
    print(f"notch_disp.vtu GPU vs CPU: RMSE {rmse:.3f} max {worst:.0f}")
    assert rmse <= 0.5 and int((np.abs(d).max(axis=2) > 3).sum()) <= 2


def test_a_time_series_of_surfaces_follows_the_display_time() -> None:
    """A deforming surface over 100 steps (warping_spheres.vtkhdf, points and values change): a display-time change
    gives the surface actor the frame at that time (it kept the first step: the timeline played a still picture), a
    scene opened at a later display time shows that time, and between steps the points move with the values."""
    from volviz.model.timeseries import frame_at
    from volviz.render.export import close_scene, offscreen_scene, snapshot
    from volviz.scene.datasets import load_datasets
    from volviz.scene.opening import data_session

    session = data_session(data_file("series/warping_spheres.vtkhdf"))
    datasets = load_datasets(session, None)
    series = datasets[session.components[0].dataset]
    plotter, controller = offscreen_scene(session, datasets, (160, 120))
    try:
        controller.build()
        assert controller.time_volumes() == ["data"]
        start = snapshot(plotter, (160, 120)).astype(float)
        controller.set_time(1.53)
        later = snapshot(plotter, (160, 120)).astype(float)
        shown = controller.views["data"].prop.GetMapper().GetInput()
        expected = frame_at(series, 1.53)
        assert shown.GetNumberOfPoints() == len(expected.points)
        drawn = np.array([shown.GetPoint(i) for i in range(shown.GetNumberOfPoints())])
        assert np.allclose(np.sort(drawn, axis=0), np.sort(expected.points, axis=0), atol=1e-5)
        assert np.abs(later - start).mean() > 1.0
        camera = controller.camera()
    finally:
        close_scene(plotter, controller)
    session.render.options["time"] = 1.53
    session.camera = camera                              # (framed on the first step's bounds, as above)
    plotter, controller = offscreen_scene(session, datasets, (160, 120))
    try:
        controller.build()
        opened_later = snapshot(plotter, (160, 120)).astype(float)
    finally:
        close_scene(plotter, controller)
    assert np.array_equal(opened_later, later)
