"""The first image is never blank and never meaningless (issue #30): one rule (volviz.model.representation) draws a
mesh without a field as plain geometry, a single-layer grid and a constant field as surfaces, a time series from its
first step where the field varies; the automatic transfer function leaves a background mode inside the range
transparent (volviz.optics.auto_tf.background_mode); every shared file gives a drawn image."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from conftest import data_file, data_root


def _scene(path, size=(160, 120)):
    """(image, scalar bar title, session, recorded warnings) of ``path``'s first look."""
    from volviz.render.decorations import scalar_bar_title
    from volviz.render.export import close_scene, offscreen_scene, snapshot
    from volviz.scene.datasets import load_datasets
    from volviz.scene.opening import data_session

    session = data_session(path)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        datasets = load_datasets(session, None)
        plotter, controller = offscreen_scene(session, datasets, size)
        try:
            controller.build()
            image = np.asarray(snapshot(plotter, size)).astype(int)
            title = scalar_bar_title(plotter)
            time = controller.time
        finally:
            close_scene(plotter, controller)
    return image, title, time, datasets["data"], [str(w.message) for w in said]


def test_a_mesh_with_only_block_ids_is_drawn_plain_without_a_scale():
    from volviz.bench.first_open import drawn_fraction
    from volviz.model.arrays import default_array
    from volviz.scene.datasets import drawn_as

    image, title, _, mesh, _ = _scene(data_file("ecosystem/mesh_fs8.exo"))
    assert default_array(mesh) is None and drawn_as(mesh) == "surface"
    assert title is None                                        # no scalar bar: nothing to explain
    assert drawn_fraction(image) > 0.15
    drawn = np.abs(image - image[0, 0]).sum(axis=2) > 40
    drawn[90:, :40] = False                                     # the orientation axes
    hue = image[drawn][:, 0] - image[drawn][:, 2]
    assert np.percentile(np.abs(hue), 95) < 25                  # one neutral grey, shaded: no colour ramp


def _grid(path, dims, values, name):
    import pyvista as pv

    grid = pv.ImageData(dimensions=dims)
    grid.point_data[name] = np.asarray(values, dtype=np.float64).ravel(order="F")
    grid.save(path)


def test_single_layer_grid_constant_field_and_constant_first_step(tmp_path):
    from volviz.bench.first_open import drawn_fraction
    from volviz.scene.datasets import drawn_as

    x, y = np.meshgrid(np.linspace(0, 6, 72), np.linspace(0, 4, 45), indexing="ij")
    _grid(tmp_path / "layer.vti", (72, 45, 1), np.sin(x) * np.cos(y), "tas")
    _grid(tmp_path / "const.vti", (20, 20, 20), np.full((20, 20, 20), 3.5), "c")
    r = np.linspace(-1, 1, 24)
    blob = np.exp(-3 * (r[:, None, None] ** 2 + r[None, :, None] ** 2 + r[None, None, :] ** 2))
    for i in range(4):
        _grid(tmp_path / f"step_{i}.vti", (24, 24, 24), blob * i, "u")

    image, title, _, layer, said = _scene(tmp_path / "layer.vti")
    assert drawn_as(layer) == "surface" and title == "tas"
    assert drawn_fraction(image) > 0.2                          # a coloured surface, not an empty box
    assert len(np.unique(image.reshape(-1, 3) // 16, axis=0)) > 10

    image, _, _, const, said = _scene(tmp_path / "const.vti")
    assert drawn_as(const) == "surface" and drawn_fraction(image) > 0.1
    assert any("const.vti: the field c is constant (3.5 everywhere)" in s for s in said)

    image, _, time, series, said = _scene(tmp_path / "step_0.vti")
    assert time == 1.0 and drawn_as(series) == "volume"          # the first step where u varies
    assert any("u is constant at the first time step; showing step 2 of 4 (time 1)" in s for s in said)
    assert drawn_fraction(image) > 0.05


def test_a_background_mode_inside_the_range_stays_transparent():
    from volviz.optics.auto_tf import auto_transfer_function, background_mode

    rng = np.random.default_rng(3)
    values = np.concatenate([rng.normal(5.0, 0.02, 60_000), rng.uniform(0.0, 10.0, 40_000)])  # a free stream
    low, high, centre = background_mode(values)
    assert low < 5.0 < high and high - low < 0.5 and centre == pytest.approx(5.0, abs=0.05)
    tf = auto_transfer_function(values, chord=4.0)
    rgb, rho = tf.evaluate(np.array([0.3, 5.0, 9.7]))
    assert rho[1] == 0.0 and rho[0] > 0 and rho[2] > 0           # the feature on both sides, not the stream
    assert rgb[0, 2] > rgb[0, 0] and rgb[2, 0] > rgb[2, 2]        # cool below, warm above
    assert background_mode(rng.normal(5.0, 1.0, 100_000)) is None  # one wide hump is data, not background


def test_every_shared_file_gives_a_drawn_image():
    """Each file a user opens in the data folder is drawn (at least 2 % of the pixels differ from the background), or
    refused with a ReadError of one line (headerless slices need their layout)."""
    from volviz.bench.first_open import drawn_fraction, opened_files
    from volviz.io import ReadError
    from volviz.render.export import open_target, render_session

    failed = []
    for path in opened_files(data_root()):
        try:
            session, _ = open_target(path)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                image = render_session(session, None, (160, 120))
        except ReadError as exc:
            assert "\n" not in str(exc) and path.name in str(exc), path
            continue
        if drawn_fraction(image) <= 0.02:
            failed.append((path.name, drawn_fraction(image)))
    assert not failed
