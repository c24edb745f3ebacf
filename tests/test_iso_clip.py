"""Clipping planes and box crop on regular volumes, isosurfaces and tetrahedral meshes (libMini note, Fig. 6)."""
from __future__ import annotations

import json

import numpy as np
import pytest

from volviz.iso.clip import clip_isosurface, clip_tetmesh, clip_volume
from volviz.model.clip import BoxCrop, ClipPlane, ClipSettings
from volviz.iso.extract import extract
from volviz.model.datasets import RegularVolume
from volviz.unstructured.synthetic import box_tets


def _tet_volume(mesh) -> float:
    p, t = mesh.points, mesh.tets
    a, b, c, d = (p[t[:, k]] for k in range(4))
    return float(np.abs(np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a)).sum() / 6.0)


def _sphere() -> RegularVolume:
    x = np.linspace(-1, 1, 21)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    return RegularVolume(data=(1 - np.sqrt(X * X + Y * Y + Z * Z)).astype(np.float32), spacing=(0.1,) * 3,
                         origin=(-1.0,) * 3)


def test_settings_json_round_trip_and_validation():
    cs = ClipSettings((ClipPlane((0, 0, 0.5), (0, 0, 2)), ClipPlane((1, 2, 3), (1, 1, 0))),
                      BoxCrop((0, 0, 0), (1, 2, 3)))
    text = json.dumps(cs.to_dict())
    back = ClipSettings.from_dict(json.loads(text))
    assert back == cs and back.planes[0].normal == (0.0, 0.0, 1.0)
    assert ClipSettings.from_dict({"planes": []}) == ClipSettings()
    with pytest.raises(ValueError, match="normal"):
        ClipPlane((0, 0, 0), (0, 0, 0))
    with pytest.raises(ValueError, match="lo <= hi"):
        BoxCrop((0, 0, 1), (1, 1, 0))
    with pytest.raises(ValueError):
        ClipSettings.from_dict({"planes": [{"point": [0, 0, 0]}]})


def test_tetmesh_cut_exact_volume_and_linear_scalars():
    tm = box_tets(5, field=lambda p: p[..., 0] + 2.0 * p[..., 1])
    cs = ClipSettings((ClipPlane((0.3, 0, 0), (1, 0, 0)), ClipPlane((0, 0, 0.6), (0, 0, -1))),
                      BoxCrop((-1, 0.1, -1), (2, 2, 2)))
    out = clip_tetmesh(tm, cs)
    assert abs(_tet_volume(out) - 0.7 * 0.9 * 0.6) < 1e-12
    assert np.all(cs.inside(out.points, tol=1e-12))
    np.testing.assert_allclose(out.scalars, out.points[:, 0] + 2.0 * out.points[:, 1], atol=1e-12)
    with pytest.raises(ValueError, match="whole"):
        clip_tetmesh(tm, [ClipPlane((5, 0, 0), (1, 0, 0))])


def test_isosurface_cut_lies_inside_and_on_the_plane():
    (m,) = extract(_sphere(), [0.5])
    plane = ClipPlane((0.1, 0, 0), (-1, 0, 0))  # keep x <= 0.1: a little more than half of the sphere
    cut = clip_isosurface(m, [plane])
    assert np.all(plane.distance(cut.points) >= -1e-9)
    on_plane = np.abs(cut.points[:, 0] - 0.1) < 1e-9
    assert on_plane.sum() > 10  # the new boundary lies on the plane, on the sphere (r ≈ 0.5)
    r = np.linalg.norm(cut.points[on_plane], axis=1)
    assert np.all(np.abs(r - 0.5) < 0.02)
    np.testing.assert_allclose(np.linalg.norm(cut.normals, axis=1), 1.0, atol=1e-9)

    def area(mm):
        a, b, c = (mm.points[mm.triangles[:, k]] for k in range(3))
        return 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()
    assert abs(area(cut) / area(m) - 0.6) < 0.02  # spherical zone: area ∝ height, (0.5 + 0.1)/1.0
    boxed = clip_isosurface(m, BoxCrop((-1, -1, -1), (1, 1, 0)))
    assert boxed.points[:, 2].max() <= 1e-9 and abs(area(boxed) / area(m) - 0.5) < 0.02
    assert clip_isosurface(m, [ClipPlane((2, 0, 0), (1, 0, 0))]).n_triangles == 0


def test_regular_volume_box_crop_and_planes():
    v = _sphere()
    c = clip_volume(v, BoxCrop((-0.25, 0.0, -1.0), (0.5, 1.0, 0.0)))
    assert c.data.shape == (8, 11, 11)
    np.testing.assert_allclose(c.origin, (-0.2, 0.0, -1.0))
    np.testing.assert_array_equal(c.data, v.data[8:16, 10:21, 0:11])
    p = clip_volume(v, ClipSettings((ClipPlane((0, 0, 0), (0, 0, 1)),)))
    assert np.all(np.isnan(p.data[:, :, :10])) and not np.any(np.isnan(p.data[:, :, 10:]))
    with pytest.raises(ValueError, match="no sample"):
        clip_volume(v, BoxCrop((3, 3, 3), (4, 4, 4)))
