"""Natural scenes: the demo scene, session files for Yukon and St. Helens, the sky dome, and the PyVista view."""
from __future__ import annotations


import numpy as np
import pytest

from conftest import REPO, data_file, data_root
from volviz.nature.nature_scene import demo_camera, demo_scene, nature_dataset_ids, scene_from_components
from volviz.render.nature_view import NatureView
from volviz.nature.sky import sky_dome_mesh
from volviz.model.camera import Camera

SESSIONS = REPO / "resources" / "sessions"


@pytest.fixture(scope="module")
def demo():
    return demo_scene(terrain_size=129, cloud_shape=(65, 65, 9))


def test_demo_scene_frame(demo) -> None:
    cam = demo_camera()
    frame = demo.render(cam, (96, 72))
    s = frame.stats
    assert s["terrain_triangles"] > 100 and s["fog_prisms"] > 0 and s["cloud_tets"] > 0
    assert np.all(np.isfinite(frame.rgb)) and frame.rgb.min() >= 0 and frame.rgb.max() <= 1
    assert np.all(np.isinf(frame.depth[:5]))       # sky at the top of the image
    assert np.all(np.isfinite(frame.depth[-5:]))   # terrain at the bottom
    assert frame.overlay[..., 3].max() > 0.3       # fog and clouds are visible
    full = demo.render(cam, (96, 72), full=True)
    assert full.stats["terrain_triangles"] == 2 * 128 * 128
    assert full.stats["cloud_tets"] > s["cloud_tets"]


def test_sky_dome_mesh() -> None:
    dome = sky_dome_mesh(100.0, (1.0, 2.0, 3.0), n_azimuth=16, n_elevation=4)
    tc = np.asarray(dome.active_texture_coordinates)
    pts = np.asarray(dome.points)
    zenith = np.argmax(pts[:, 2])
    assert tc[zenith, 1] == pytest.approx(1.0) and pts[zenith, 2] == pytest.approx(103.0)
    assert tc[:, 0].min() == 0.0 and tc[:, 0].max() == 1.0
    assert np.allclose(np.linalg.norm(pts - (1, 2, 3), axis=1), 100.0)
    with pytest.raises(ValueError, match="radius"):
        sky_dome_mesh(0.0)


def test_pyvista_view_matches_the_cpu_frame(demo) -> None:
    """The VTK side (textured terrain mesh, sky dome, RGBA overlay) shows what the CPU frame shows."""
    import pyvista as pv

    size = (128, 96)
    cam = demo_camera()
    plotter = pv.Plotter(off_screen=True, window_size=size)
    try:
        view = NatureView(plotter, demo, size=size)
        stats = view.update(cam)
        assert stats["terrain_triangles"] > 100
        shot = plotter.screenshot(return_img=True)[..., :3] / 255.0
    finally:
        plotter.close()
    cpu = demo.render(cam, size).rgb
    assert shot.shape == cpu.shape
    rmse = float(np.sqrt(np.mean((shot - cpu) ** 2)) * 255)
    assert rmse < 14.0
    # the sky texture mapping: top rows (sky) agree closely
    assert float(np.abs(shot[:8] - cpu[:8]).mean()) * 255 < 6.0


@pytest.mark.parametrize("name", ["yukon", "sainthelens"])
def test_session_files(name: str, monkeypatch) -> None:
    from volviz import session
    from volviz.io import read

    path = SESSIONS / f"{name}.json"
    sess = session.load(path)
    types = {c.type for c in sess.components}
    assert {"terrain", "fog", "sky"} <= types
    assert name != "sainthelens" or "clouds" in types
    assert all(ref.path.startswith("$VOLVIZ_DATA/") for ref in sess.datasets)
    assert len(sess.camera_paths["flythrough"]) >= 3
    data_file("yukon/Yukon.map.pgm" if name == "yukon" else "terrain/SainteHelens.dem")
    monkeypatch.setenv("VOLVIZ_DATA", str(data_root()))
    ids = nature_dataset_ids(sess.components)
    datasets = {r.id: read(session.resolve_path(path, r.path)) for r in sess.datasets if r.id in ids}
    scene = scene_from_components(sess.components, datasets)
    assert scene.terrain is not None and len(scene.fogs) >= 1
    cam_state = sess.camera_paths["flythrough"][0].camera
    ext = max(scene.terrain.extent)
    cam = Camera(cam_state.position, cam_state.focal_point, cam_state.view_up, cam_state.view_angle,
                 clipping_range=(ext * 1e-3, ext * 20))
    frame = scene.render(cam, (64, 48))
    assert np.all(np.isfinite(frame.rgb))
    assert np.isfinite(frame.depth).mean() > 0.2     # the terrain is in view
    assert frame.overlay[..., 3].max() > 0.2          # and so are its fog / cloud layers
    if name == "yukon":
        assert scene.texture is not None and scene.sky is not None
        assert len(scene.fogs) == 2  # ground fog + the cloud layer between two height fields


def test_demo_components_build_without_data() -> None:
    from volviz.scene.demo import demo_components

    comps = demo_components()
    assert {c.type for c in comps} == {"terrain", "fog", "clouds", "sky"}
    scene = scene_from_components(comps, {})
    assert scene.terrain.size == 257 and scene.cloud_lod is not None and len(scene.fogs) == 1 and scene.sky is None
    frame = scene.render(demo_camera(), (48, 36))
    assert frame.stats["cloud_tets"] > 0 and np.all(np.isfinite(frame.rgb))


def test_components_with_missing_datasets_are_refused() -> None:
    from volviz.session import Component

    with pytest.raises(ValueError, match="'t'.*not loaded"):
        scene_from_components([Component(id="t", type="terrain", dataset="nope")], {})
    with pytest.raises(ValueError, match="texture_dataset"):
        scene_from_components([Component(id="t", type="terrain", settings={"size": 33, "texture_dataset": "x"})], {})
    with pytest.raises(ValueError, match="needs a terrain"):
        scene_from_components([Component(id="f", type="fog")], {})


def test_sky_shows_with_the_plotters_own_camera(demo) -> None:
    """The app's path: the session camera is applied to an empty renderer (VTK's default clipping range 0.01 ..
    1000.01), then the view renders with the plotter's camera. The dome (radius 3 x the extent) must not be clipped
    away: the top rows show the sky gradient, not the background color."""
    import pyvista as pv

    size = (128, 96)
    cam = demo_camera()
    plotter = pv.Plotter(off_screen=True, window_size=size)
    try:
        plotter.set_background((1.0, 0.0, 1.0))
        pc = plotter.camera
        pc.position, pc.focal_point, pc.up, pc.view_angle = cam.position, cam.focal_point, cam.view_up, cam.view_angle
        plotter.renderer.ResetCameraClippingRange()  # no props yet: VTK's default range
        view = NatureView(plotter, demo, size=size)
        view.update()
        assert plotter.camera.clipping_range[1] >= view.dome_radius
        shot = plotter.screenshot(return_img=True)[..., :3] / 255.0
    finally:
        plotter.close()
    cpu = demo.render(cam, size).rgb
    assert float(np.abs(shot[:8] - cpu[:8]).mean()) * 255 < 6.0


def test_fly_through_does_not_pop_with_geomorphing() -> None:
    """Scene level (terrain + fog + clouds): along a dense camera path the total per-frame change of the C-LOD image
    stays below that of the full-resolution reference (ratio <= 1: the LOD adds no jumps of its own), while the same
    LOD without geomorphing adds popping (measured ratio 0.89 with morphing, 3.2 without)."""
    from volviz.optics.metrics import rmse

    size = (64, 48)
    scene = demo_scene(terrain_size=65, cloud_shape=(33, 33, 9))
    scene.big_c, scene.small_c = 4.0, 4.0  # coarse, so that many nodes refine along the path
    scene.finalize()
    scene.cloud_lod.big_c, scene.cloud_lod.small_c = 2.0, 4.0
    p0 = np.array([500.0, -100.0, 300.0])
    d = np.array([0.0, 1.0, -0.35]) / np.linalg.norm([0.0, 1.0, -0.35])
    cams = [Camera(p0 + i * 0.05 * d, (500.0, 600.0, 80.0), (0.0, 0.0, 1.0), 60.0, clipping_range=(5.0, 10000.0))
            for i in range(26)]

    def variation(images: list[np.ndarray]) -> float:
        rgba = [np.concatenate([im, np.ones(im.shape[:2] + (1,))], axis=-1) for im in images]
        return sum(rmse(a, b) for a, b in zip(rgba[1:], rgba[:-1]))

    reference = variation([scene.render(c, size, full=True).rgb for c in cams])
    ratios = {}
    for morph in (True, False):
        scene.lod.geomorph = scene.cloud_lod.geomorph = morph
        ratios[morph] = variation([scene.render(c, size).rgb for c in cams]) / reference
    assert ratios[True] <= 1.0
    assert ratios[False] > 1.3


def test_preview_keeps_the_terrain_and_draws_a_smaller_overlay(demo) -> None:
    """``begin(scale=2)`` (the app's view while the camera moves): the same C-LOD terrain mesh and cloud leaves as
    the full-size view (nothing pops when it follows), fog and clouds rendered at half the size in each direction,
    which OpenGL magnifies over the viewport; the frame drawn stays close to the full-size one."""
    import pyvista as pv

    size = (160, 120)
    cam = demo_camera()
    plotter = pv.Plotter(off_screen=True, window_size=size)
    try:
        view = NatureView(plotter, demo, size=size)
        view.begin(cam)
        poly, full, st_full = view.compute((cam, size, 1))
        poly2, preview, st_prev = view.compute((cam, size, 2))
        view.finish((cam, size, 1), poly, full, st_full)
        plotter.render()
        drawn_full = plotter.screenshot().astype(float)
        view.finish((cam, size, 2), poly2, preview, st_prev)
        plotter.render()
        drawn_preview = plotter.screenshot().astype(float)
    finally:
        plotter.close()
    assert full.shape == (120, 160, 4) and preview.shape == (60, 80, 4) and preview.dtype == np.uint8
    assert poly2.n_triangles == poly.n_triangles and np.array_equal(poly2.points, poly.points)   # terrain meshes
    assert st_prev["cloud_tets"] == st_full["cloud_tets"]   # (fog prisms drawn differ: those covering no pixel)
    err = np.abs(drawn_preview - drawn_full)
    rmse = float(np.sqrt((err ** 2).mean()))
    print(f"preview vs full frame: mean {err.mean():.2f}, rmse {rmse:.2f}")
    assert 0 < rmse < 8.0, rmse      # silhouettes at half resolution


def test_terrain_texture_is_mip_mapped_on_a_hardware_driver_only(demo) -> None:
    """The terrain's color map is mip-mapped, trilinear and isotropic where that is free (a hardware OpenGL driver) or
    asked for; on a software rasteriser (this machine's llvmpipe) the app draws it unfiltered by default."""
    import pyvista as pv

    from volviz.render import backend
    from volviz.render.backend import GLInfo, plotter_gl_info
    from volviz.render.nature_view import texture_filtering

    plotter = pv.Plotter(off_screen=True, window_size=[64, 48])
    try:
        assert plotter_gl_info(plotter).software and not texture_filtering(plotter)
        plain = NatureView(plotter, demo)._texture
        assert not plain.GetMipmap() and not plain.GetInterpolate()
        asked = NatureView(plotter, demo, filter_texture=True)._texture
        assert asked.GetMipmap() and asked.GetInterpolate() and asked.GetMaximumAnisotropicFiltering() == 1.0
        backend._plotter_gl_info[plotter] = GLInfo("NVIDIA Corporation", "NVIDIA H100/PCIe/SSE2", "4.6.0")
        assert texture_filtering(plotter) and NatureView(plotter, demo)._texture.GetMipmap()
    finally:
        plotter.close()


def test_the_terrain_texture_image_is_made_with_the_scene_not_by_its_view(monkeypatch) -> None:
    """The 8-bit image of the terrain's color map is made by ``finalize`` (run by ``prepare_nature`` on the app's
    worker), not by the view the GUI thread makes (issue #28: a 132 ms stall while a Yukon session opened); the view's
    texture holds exactly that image (row 0 at the largest y)."""
    import pyvista as pv

    from volviz.nature import nature_scene
    from volviz.render.vtk_facade import vtk_to_numpy

    scene = demo_scene(terrain_size=65, cloud_shape=(17, 17, 5))
    scene.finalize()
    image = scene.texture_image()
    assert image is not None and image.dtype == np.uint8 and image.flags.c_contiguous
    expected = np.clip(scene.color_map.transpose(1, 0, 2)[::-1] * 255.0, 0, 255).astype(np.uint8)
    np.testing.assert_array_equal(image, expected)

    def made_again(*args: object) -> None:
        raise AssertionError("the view made the texture's image again")

    monkeypatch.setattr(nature_scene, "_texture_bytes", made_again)
    plotter = pv.Plotter(off_screen=True, window_size=[64, 48])
    try:
        texture = NatureView(plotter, scene)._texture
        shown = vtk_to_numpy(texture.GetInput().GetPointData().GetScalars())
        h, w = image.shape[:2]
        np.testing.assert_array_equal(shown.reshape(h, w, 3)[::-1], image)   # (VTK's rows from the bottom)
    finally:
        plotter.close()


def test_a_move_draws_the_coarse_terrain_of_the_last_full_frame(demo, monkeypatch) -> None:
    """Each full-size frame also makes the terrain at preview detail, and the first ``begin(scale > 1)`` after it (a
    drag or a flight starts) draws that coarse terrain at once, whatever the mode: drawing the full C-LOD mesh until
    the first preview came cost 60-150 ms of the GUI thread per frame on llvmpipe with Yukon's 512k triangles, the
    first seconds of a flight's event-loop gaps over 100 ms (issue #28, docs/bench/flight.md)."""
    import pyvista as pv
    import volviz.render.nature_view as nature_view

    monkeypatch.setattr(nature_view, "PREVIEW_TRIANGLES", 1500)
    size = (160, 120)
    cam = demo_camera()
    plotter = pv.Plotter(off_screen=True, window_size=size)
    try:
        view = NatureView(plotter, demo, size=size)
        view.update(cam)
        full = view.terrain_actor.mapper.GetInput().GetNumberOfCells()
        view.begin(cam, scale=4)
        moving = view.terrain_actor.mapper.GetInput().GetNumberOfCells()
    finally:
        plotter.close()
    print(f"full frame {full} triangles, first moving frame {moving}")
    assert full > 4 * 1500 and 0 < moving < 1.5 * 1500   # (the first fit of the preview detail undershoots here)
