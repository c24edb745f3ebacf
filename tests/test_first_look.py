"""The first look at a file: the automatic transfer function (volviz.optics.auto_tf), the framing of the camera
(volviz.render.framing), height maps as terrain scenes and series members at their own time step."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from conftest import data_file
from volviz.optics.auto_tf import (TARGET_DEPTH, auto_transfer_function, foreground, mean_chord,
                                   prefers_log_histogram, robust_range)


def test_mean_chord_is_cauchys_formula():
    assert mean_chord((0, 1, 0, 1, 0, 1)) == pytest.approx(2.0 / 3.0)           # 4 V / S of the unit cube
    assert mean_chord((0, 0.4, 0, 0.1, 0, 0.01)) == pytest.approx(4 * 4e-4 / 0.09)
    assert mean_chord((0, 5, 0, 2, 0, 0)) == 5.0                                  # flat: its largest side


def test_background_bin_is_left_out_and_stays_transparent():
    rng = np.random.default_rng(1)
    values = np.concatenate([np.zeros(70_000), rng.uniform(100, 200, 30_000)])   # 70 % air, as in a CT scan
    fg = foreground(values)
    assert fg.size == 30_000 and fg.min() >= 100
    lo, hi = robust_range(values)
    assert lo == pytest.approx(102, abs=1) and hi == pytest.approx(199.5, abs=1)
    tf = auto_transfer_function(values, chord=10.0)
    assert _rho(tf, np.array([0.0, 50.0]))[0] == 0.0 and _rho(tf, np.array([50.0]))[0] == 0.0
    assert tf.scalars[0] == 0.0 and tf.scalars[-1] == pytest.approx(values.max())  # the whole range is covered


def test_peak_extinction_gives_the_target_depth_for_the_mean_sample():
    values = np.random.default_rng(2).normal(5.0, 1.0, 200_000)
    chord = 3.0
    tf = auto_transfer_function(values, chord)
    depth = float(np.mean(_rho(tf, values))) * chord
    assert depth == pytest.approx(TARGET_DEPTH, rel=0.02)       # the mean sample along a chord, whatever the units
    scaled = auto_transfer_function(values * 1e6 + 3e9, chord)
    assert float(np.mean(_rho(scaled, values * 1e6 + 3e9))) * chord == pytest.approx(depth, rel=1e-6)


def test_degenerate_data_gives_a_valid_function():
    for values in (np.full(100, 7.0), np.full(10, np.nan), np.array([np.inf, 1.0, np.nan, 2.0])):
        tf = auto_transfer_function(values, chord=2.0)
        assert np.all(np.isfinite(tf.scalars)) and np.all(np.isfinite(_rho(tf, tf.scalars)))


def test_long_tailed_histograms_prefer_the_log_scale():
    assert prefers_log_histogram(np.array([90_000, 30, 40, 35, 20, 25]))
    assert not prefers_log_histogram(np.array([10, 20, 30, 25, 15]))
    assert not prefers_log_histogram(np.array([5, 900, 1000, 200, 8, 0, 1]))      # 2 of 6 bins under 1 %

    from volviz.io import read
    from volviz.model.arrays import select_array
    from volviz.model.stats import histogram

    def log_scale(name):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return prefers_log_histogram(histogram(select_array(read(data_file(name)), None))[0])

    assert log_scale("volumes/embryo.slc") and log_scale("volumes/HeadMRVolume.mhd")
    assert not log_scale("bluntfin/bluntfinxyz.bin")


def test_framing_fills_80_percent_of_the_limiting_dimension():
    import pyvista as pv

    from volviz.render.framing import frame_bounds

    plotter = pv.Plotter(off_screen=True, window_size=(320, 240))
    try:
        bounds = (0.0, 9780.0, 0.0, 13950.0, 682.0, 2511.0)
        plotter.add_mesh(pv.Box(bounds), color="white")
        plotter.set_background("black")
        frame_bounds(plotter, bounds)
        image = plotter.screenshot(None, return_img=True)
    finally:
        plotter.close()
    rows, cols = np.nonzero(image[..., 0] > 60)
    centre = np.array([120, 160])
    reach = max((rows.max() - centre[0] + 1) / 120, (centre[0] - rows.min()) / 120,
                (cols.max() - centre[1] + 1) / 160, (centre[1] - cols.min()) / 160)
    assert reach == pytest.approx(0.8, abs=0.02)


def _render(session, size=(160, 120)):
    from volviz.render.export import render_session

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return render_session(session, None, size)


def test_height_maps_open_as_terrain_scenes():
    from volviz.scene.opening import data_session

    dem = data_session(data_file("terrain/SainteHelens.dem"))
    assert [c.type for c in dem.components] == ["terrain", "sky"]
    assert dem.components[0].settings == {"origin": [0.0, 0.0]}                     # true heights in metres
    from volviz.io import read

    pgm = data_session(data_file("yukon/Yukon.map.pgm"))
    lo, hi = read(data_file("yukon/Yukon.map.pgm")).scalar_range()
    assert pgm.components[0].settings["height_scale"] == pytest.approx(0.1 * 689 / (hi - lo))  # relief: 1/10 width
    image = _render(dem)
    sky = np.array([0.78, 0.85, 0.95]) * 255
    ground = np.abs(image.astype(float) - sky).sum(axis=2) > 60
    assert 0.15 < ground.mean() < 0.8                   # the terrain fills the view instead of a speck of it
    rows, cols = np.nonzero(ground)
    assert abs(rows.mean() - 60) < 25 and abs(cols.mean() - 80) < 25             # ... around the centre


def test_series_member_opens_at_its_time_step():
    from volviz.scene.opening import data_session

    first = data_session(data_file("storm/Storm.pvm-t01"))
    member = data_session(data_file("storm/Storm.pvm-t05"))
    assert member.datasets[0].path.endswith("Storm.pvm-t%02d")
    assert member.render.options["time"] == 5.0 and first.render.options["time"] == 1.0
    background = _render(first)                  # the storm's first step is empty
    storm = _render(member)
    assert np.abs(storm.astype(int) - background.astype(int)).max() > 60


def _rho(tf, s):
    return tf.evaluate(np.asarray(s, dtype=np.float64))[1]


def test_flat_grids_and_surface_meshes_are_drawn_as_colored_surfaces():
    """A 2D curvilinear grid carrying a cell array (netCDF CF) shows as a surface colored through the transfer
    function, its NaN (land in an ocean field) not drawn."""
    from volviz.scene.opening import data_session
    from volviz.render.vtk_scene import is_surface

    from volviz.io import read

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        grid = read(data_file("ecosystem/sampleCurveGrid4.nc"))
        ocean = read(data_file("ecosystem/tos_O1_2001-2002.nc"))
    assert is_surface(grid) and is_surface(ocean)
    for path in ("ecosystem/sampleCurveGrid4.nc", "ecosystem/tos_O1_2001-2002.nc"):
        image = _render(data_session(data_file(path)))
        background = image[0, 0].astype(int)
        drawn = np.abs(image.astype(int) - background).sum(axis=2) > 40
        assert drawn.mean() > 0.15                                   # a surface, not an empty volume
        assert len(np.unique(image[drawn].reshape(-1, 3) // 16, axis=0)) > 10   # ... in many colors


def test_pictures_open_flat_and_face_on():
    """A photo or a texture (not a height map) is a flat picture seen face-on, in its own colors."""
    from volviz.render.framing import view_direction
    from volviz.scene.opening import data_session

    assert view_direction((0, 4, 0, 2, 0, 0)) == ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0))
    assert view_direction((0, 1, 0, 1, 0, 1))[0] == (1.0, 1.0, 1.0)
    for name in ("sky/clouds.jpeg", "yukon/Yukon.texmap.ppm"):
        session = data_session(data_file(name))
        assert [c.type for c in session.components] == ["volume"]
        image = _render(session, (160, 120))
        drawn = np.abs(image.astype(int) - image[0, 0].astype(int)).sum(axis=2) > 30
        # face-on, filling the view: the picture alone covers 0.386 (clouds.jpeg) and 0.455 at 160x120; the 0.4 this
        # asked before counted the outline's sides, which llvmpipe drops single-sampled where they lie on pixel edges
        assert drawn.mean() > 0.35
        assert session.transfer_functions == {}            # no transfer function: the picture's own colors


def test_messages_for_headerless_data_say_what_to_open(tmp_path):
    from volviz.io import ReadError, read

    with pytest.raises(ReadError, match=r"is the raw data of HeadMRVolume.mhd; open HeadMRVolume.mhd"):
        read(data_file("volumes/HeadMRVolume.raw"))
    with pytest.raises(ReadError, match=r"numbered slices without a header: .* sample type; write a MetaImage header"):
        read(data_file("headsq/quarter.1"))


def test_demo_scene_bounds_are_its_terrain_and_clouds_not_the_sky_dome():
    from volviz.render.export import offscreen_scene
    from volviz.scene.demo import demo_session

    plotter, controller = offscreen_scene(demo_session(), {}, (160, 120))
    try:
        controller.build()
        nature = controller.nature.scene
        terrain, clouds = nature.terrain.bounds(), nature.cloud_lod.volume.bounds()
        expected = (min(terrain[0], clouds[0]), max(terrain[1], clouds[1]), min(terrain[2], clouds[2]),
                    max(terrain[3], clouds[3]), min(terrain[4], clouds[4]), max(terrain[5], clouds[5]))
        assert controller.bounds() == pytest.approx(expected)
        assert controller.bounds()[:4] == pytest.approx((0.0, 1000.0, 0.0, 1000.0))    # the dome is 3 km wide
    finally:
        plotter.close()


def test_signed_data_around_zero_gets_the_diverging_view():
    """Seismic-like amplitudes: zero transparent and white, both signs alike in opacity, blue below and red above,
    the peak held beyond the robust range on both sides; the mean sample still reaches the target depth."""
    values = np.random.default_rng(5).laplace(0.0, 100.0, 200_000)
    tf = auto_transfer_function(values, chord=4.0)
    lo, hi = robust_range(values)
    reach = max(-lo, hi)
    rho = _rho(tf, np.array([0.0, -0.5 * reach, 0.5 * reach, -reach, reach, values.min(), values.max()]))
    assert rho[0] == 0.0 and rho[1] == pytest.approx(rho[2]) and rho[3] == pytest.approx(rho[4])
    assert rho[3] > rho[1] > 0
    assert rho[5] == pytest.approx(rho[3]) and rho[6] == pytest.approx(rho[4])
    colors = tf.evaluate(np.array([-reach, 0.0, reach]))[0]
    assert colors[0][2] > colors[0][0] and colors[2][0] > colors[2][2]            # blue below, red above
    np.testing.assert_allclose(colors[1], (0.87, 0.87, 0.87), atol=1e-6)
    assert float(np.mean(_rho(tf, values))) * 4.0 == pytest.approx(TARGET_DEPTH, rel=0.02)
    one_sided = auto_transfer_function(np.random.default_rng(6).uniform(-10.0, 100.0, 50_000), chord=4.0)
    assert _rho(one_sided, np.array([-9.0]))[0] == 0.0 < _rho(one_sided, np.array([95.0]))[0]   # mostly positive


def test_surfaces_of_geometry_alone_are_drawn_plain_or_in_their_colours_without_a_scale(tmp_path):
    """An STL (no arrays) and a PLY whose only arrays are its vertex normals (nx, ny, nz as meshio reads them) are
    drawn in one plain colour with no scalar bar (there is no scale to explain; the PLY was colored by nx under a
    bar titled "nx"); a PLY with vertex colours in those colours; a surface with a data array beside its normals
    shows that array, with its bar."""
    import pyvista as pv

    from volviz.model.arrays import default_array, is_appearance_array
    from volviz.render.decorations import scalar_bar_title
    from volviz.render.export import close_scene, offscreen_scene, snapshot
    from volviz.scene.datasets import load_datasets
    from volviz.scene.opening import data_session

    sphere = pv.Sphere(theta_resolution=24, phi_resolution=24)
    sphere.save(tmp_path / "geometry.stl")
    sphere.save(tmp_path / "normals.ply")
    painted = sphere.copy()
    painted["RGB"] = np.tile(np.array([[30, 200, 40]], np.uint8), (painted.n_points, 1))
    painted.save(tmp_path / "painted.ply", texture="RGB")      # uchar red, green, blue: meshio reads them signed
    sphere["height"] = sphere.points[:, 2]
    sphere.save(tmp_path / "data.vtp")
    assert is_appearance_array("Normals") and is_appearance_array("nx") and not is_appearance_array("height")
    for name, title in (("geometry.stl", None), ("normals.ply", None), ("painted.ply", None), ("data.vtp", "height")):
        session = data_session(tmp_path / name)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            datasets = load_datasets(session, None)
        assert (default_array(datasets["data"]) is None) == (title is None), name
        plotter, controller = offscreen_scene(session, datasets, (160, 120))
        try:
            controller.build()
            image = np.asarray(snapshot(plotter, (160, 120))).astype(int)
            assert scalar_bar_title(plotter) == title, name
        finally:
            close_scene(plotter, controller)
        drawn = np.abs(image - image[0, 0]).sum(axis=2) > 40
        drawn[90:, :40] = False                          # the orientation axes
        rows, cols = (int(v.mean()) for v in np.nonzero(drawn))
        middle = image[rows - 8:rows + 8, cols - 8:cols + 8]         # the sphere's middle (the box lines are thin)
        assert (np.abs(middle - image[0, 0]).sum(axis=2) > 40).mean() > 0.8, name
        # shading alone varies a plain surface's brightness, not its hue; data adds a colour ramp (blue to red); a
        # painted surface shows its own green
        spread = float(np.ptp(middle[..., 0] - middle[..., 2]))
        assert (spread < 40) == (title is None), (name, spread)
        green = (middle[..., 1] > 1.5 * np.maximum(middle[..., 0], middle[..., 2])).mean()
        assert (green > 0.6) == (name == "painted.ply") and (green > 0.6 or green < 0.05), (name, green)
