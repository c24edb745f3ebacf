"""TransferFunction: validation, evaluation, dict / VTK / ParaView-preset round trips."""
from __future__ import annotations

import json

import numpy as np
import pytest

from volviz.optics import TransferFunction, list_presets, load_preset, read_paraview_presets, write_paraview_presets
from volviz.optics.presets import tf_from_paraview, tf_to_paraview


def make_tf() -> TransferFunction:
    return TransferFunction([0.0, 0.25, 1.0], [[1, 0, 0], [0, 1, 0], [0, 0, 1]], [0.0, 2.0, 1.0], name="three")


def test_evaluate_interpolates_and_is_transparent_outside_and_at_nan():
    tf = make_tf()
    rgb, rho = tf.evaluate([-0.1, 0.0, 0.125, 0.625, 1.0, 1.5, np.nan])
    np.testing.assert_allclose(rho, [0, 0, 1.0, 1.5, 1.0, 0, 0])
    np.testing.assert_allclose(rgb[2], [0.5, 0.5, 0.0])
    np.testing.assert_allclose(rgb[3], [0.0, 0.5, 0.5])
    assert np.all(rgb[[0, 5, 6]] == 0)
    assert tf.range == (0.0, 1.0)
    np.testing.assert_allclose(tf.emission(0.625), [0.0, 0.75, 0.75])


@pytest.mark.parametrize(
    "args, message",
    [
        (([0, 1], [[0, 0, 0]], [0, 0]), "colors must have shape"),
        (([0, 0], [[0, 0, 0]] * 2, [0, 0]), "strictly increasing"),
        (([1, 0], [[0, 0, 0]] * 2, [0, 0]), "strictly increasing"),
        (([0], [[0, 0, 0]], [0]), "at least 2"),
        (([0, 1], [[0, 0, 0]] * 2, [0, -1]), "extinction must be >= 0"),
        (([0, 1], [[0, -1, 0]] * 2, [0, 1]), "colors must be >= 0"),
        (([0, np.nan], [[0, 0, 0]] * 2, [0, 1]), "finite"),
        (([0, 1], [[0, 0, 0]] * 2, [0, np.inf]), "finite"),
        (([0, 1], [[0, 0, 0]] * 2, [0, 1, 2]), "extinction must have shape"),
        ((["a", "b"], [[0, 0, 0]] * 2, [0, 1]), "numeric"),
    ],
)
def test_bad_input_raises_clear_value_error(args, message):
    with pytest.raises(ValueError, match=message):
        TransferFunction(*args)


def test_arrays_are_copied_and_read_only():
    s = np.array([0.0, 1.0])
    tf = TransferFunction(s, np.ones((2, 3)), [1.0, 1.0])
    s[0] = 5.0
    assert tf.scalars[0] == 0.0
    with pytest.raises(ValueError):
        tf.extinction[0] = 3.0


def test_dict_round_trip_through_json_is_exact():
    tf = TransferFunction([0.0, 1 / 3, 1.0], [[0.1, 0.2, 0.3], [1 / 7, 0, 1], [0, 0, 0]], [0.0, np.pi, 1e6],
                          name="π")
    back = TransferFunction.from_dict(json.loads(json.dumps(tf.to_dict())))
    assert back == tf


@pytest.mark.parametrize(
    "mutate, message",
    [
        (lambda d: d.pop("scalars"), "missing field 'scalars'"),
        (lambda d: d.update(version=99), "version"),
        (lambda d: d.update(format="other"), "format"),
        (lambda d: d.update(colors="red"), "colors"),
        (lambda d: d.update(name=3), "name"),
    ],
)
def test_from_dict_names_the_bad_field(mutate, message):
    d = make_tf().to_dict()
    mutate(d)
    with pytest.raises(ValueError, match=message):
        TransferFunction.from_dict(d)


def test_shipped_presets_load_and_round_trip(tmp_path):
    names = list_presets()
    assert {"viridis", "cool-warm", "grayscale", "inferno", "hot", "three-peaks"} <= set(names)
    for name in names:
        tf = load_preset(name)
        assert tf.name == name and len(tf) >= 3 and tf.range == (0.0, 1.0)
        path = tmp_path / f"{name}.json"
        write_paraview_presets(path, tf, unit_distance=1.0)
        assert read_paraview_presets(path)[0] == tf
    viridis = load_preset("viridis")
    np.testing.assert_allclose(viridis.colors[0], [0.267004, 0.004874, 0.329415])  # viridis starts dark purple
    with pytest.raises(ValueError, match="unknown preset"):
        load_preset("no-such-map")


def test_paraview_import_without_opacity_is_a_ramp_and_unit_distance_scales_rho():
    obj = {"Name": "two", "ColorSpace": "Diverging", "RGBPoints": [-1, 0, 0, 1, 0, 1, 1, 1, 1, 1, 0, 0]}
    tf = tf_from_paraview(obj, unit_distance=0.5)
    np.testing.assert_allclose(tf.scalars, [-1, 0, 1])
    np.testing.assert_allclose(tf.extinction, [0, 1.0, 2.0])  # opacity ramp 0..1 divided by 0.5
    out = tf_to_paraview(tf, unit_distance=0.5)
    assert out["Points"][4:6] == [0.0, 0.5] and out["ColorSpace"] == "RGB"
    assert tf_from_paraview(out) == tf  # VolvizUnitDistance is honoured


def test_paraview_bad_file_names_the_file(tmp_path):
    path = tmp_path / "bad.json"
    path.write_text('[{"Name": "x", "RGBPoints": [0, 1, 1]}]')
    with pytest.raises(ValueError, match="bad.json.*multiple of 4"):
        read_paraview_presets(path)
    path.write_text("{not json")
    with pytest.raises(ValueError, match="bad.json"):
        read_paraview_presets(path)
