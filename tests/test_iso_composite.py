"""Isosurface extraction and the libMini transparency modes (note §4): hand-computed cases and order independence."""
from __future__ import annotations

import numpy as np
import pytest

from conftest import data_file
from volviz.iso.composite import MODES, composite, fragments, render_modes
from volviz.iso.extract import IsoMesh, IsoStyle, extract, extract_many
from volviz.iso.spectrum import exact_alpha, fit_spectrum, spectrum_alpha
from volviz.model.datasets import RegularVolume
from volviz.optics.metrics import max_abs
from volviz.model.camera import Camera
from volviz.unstructured.synthetic import box_tets

N = 17


def _field_volume(fn, n=N, lo=-1.0, hi=1.0) -> RegularVolume:
    x = np.linspace(lo, hi, n)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    return RegularVolume(data=fn(X, Y, Z).astype(np.float32), spacing=((hi - lo) / (n - 1),) * 3, origin=(lo,) * 3)


def _sphere() -> RegularVolume:
    return _field_volume(lambda X, Y, Z: 1.0 - np.sqrt(X * X + Y * Y + Z * Z), n=21)


TOP = Camera((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), parallel=True, parallel_scale=0.8,
             clipping_range=(1.0, 10.0))


def test_extract_sphere_radius_normals_and_several_values():
    meshes = extract(_sphere(), [IsoStyle(0.5, (1, 0, 0), 0.3), 0.2, IsoStyle(5.0)])
    assert [m.n_triangles > 0 for m in meshes] == [True, True, False]
    for m, r_iso in zip(meshes[:2], (0.5, 0.8)):
        r = np.linalg.norm(m.points, axis=1)
        assert abs(r.mean() - r_iso) < 0.01
        outward = np.einsum("ij,ij->i", m.normals, m.points / r[:, None])
        assert outward.min() > 0.9  # normals along −∇s: out of the high-valued blob


def test_extract_tetrahedral_linear_field_is_exact():
    tm = box_tets(5, field=lambda p: p[..., 0] + 2.0 * p[..., 1])
    (m,) = extract(tm, [1.2])
    assert m.n_triangles > 0
    np.testing.assert_allclose(m.points[:, 0] + 2.0 * m.points[:, 1], 1.2, atol=1e-6)
    g = np.array([1.0, 2.0, 0.0]) / np.sqrt(5.0)
    np.testing.assert_allclose(m.normals @ g, -1.0, atol=1e-6)


def test_extract_blunt_fin_curvilinear_three_values():
    import volviz.io
    grid = volviz.io.read(str(data_file("bluntfin/bluntfinxyz.bin")))
    meshes = extract(grid, [0.8, 1.5, 2.5])
    lo, hi = grid.points.reshape(-1, 3).min(0), grid.points.reshape(-1, 3).max(0)
    for m in meshes:
        assert m.n_triangles > 1000
        assert np.all(m.points >= lo - 1e-6) and np.all(m.points <= hi + 1e-6)
        np.testing.assert_allclose(np.linalg.norm(m.normals, axis=1), 1.0, atol=1e-6)


def _planes(sign: float, values, styles_kw):
    """Horizontal sheets s = sign·z at the given z (two separate, overlapping volumes)."""
    vol_a = _field_volume(lambda X, Y, Z: sign * Z)
    vol_b = _field_volume(lambda X, Y, Z: sign * Z, lo=-1.2, hi=1.1)  # a second grid overlapping the first
    out = []
    for vol, z, kw in zip((vol_a, vol_b, vol_a), values, styles_kw):
        out += extract(vol, [IsoStyle(sign * z, **kw)])
    return out


def _flat(meshes, mode, bg=(0.1, 0.2, 0.3, 1.0)):
    fr = fragments(meshes, TOP, (24, 24), shading="flat", lighting=False)
    return composite(fr, mode, bg), fr


def test_single_layer_all_modes_agree_with_exact():
    (m,) = extract(_field_volume(lambda X, Y, Z: Z + 0.3 * np.sin(2 * X) * Y), [IsoStyle(0.1, (0.9, 0.5, 0.2), 0.6)])
    cam = Camera((0.3, -0.2, 4.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), view_angle=25.0, clipping_range=(1.0, 10.0))
    imgs = render_modes([m], cam, (48, 48), background=(0.2, 0.2, 0.2, 1.0))
    assert imgs["exact"][..., 3].max() > 0.5
    for mode in MODES:
        assert max_abs(imgs[mode], imgs["exact"]) < 1e-9


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_two_overlapping_volumes_match_the_optical_model_by_hand(sign):
    c1, a1, c2, a2 = np.array([1.0, 0.2, 0.0]), 0.5, np.array([0.0, 0.6, 1.0]), 0.25
    bg = np.array([0.1, 0.2, 0.3, 1.0])
    meshes = _planes(sign, (0.4, -0.3), [dict(color=tuple(c1), opacity=a1), dict(color=tuple(c2), opacity=a2)])
    e1, e2 = np.append(a1 * c1, a1), np.append(a2 * c2, a2)
    exact = e1 + (1 - a1) * e2 + (1 - a1) * (1 - a2) * bg
    three = e1 + e2 + (1 - a1) * (1 - a2) * bg
    three[3] = 1 - (1 - a1) * (1 - a2) * (1 - bg[3])
    # sign +1: s = z, normals −∇s point down, away from the eye above: both sheets are back faces, the front-most
    # back face is the top sheet and 4-pass drops the lower sheet's emission. sign −1: no back faces, 4-pass = 3-pass.
    four = three - np.append(e2[:3], 0.0) if sign > 0 else three
    img, fr = _flat(meshes, "exact", bg)
    assert len(fr.depth) == 2 * 24 * 24  # top-left rule: one fragment per sheet per pixel, no cracks, no doubles
    np.testing.assert_allclose(img, np.broadcast_to(exact, img.shape), atol=1e-12)
    np.testing.assert_allclose(_flat(meshes, "3pass", bg)[0], np.broadcast_to(three, img.shape), atol=1e-12)
    np.testing.assert_allclose(_flat(meshes, "4pass", bg)[0], np.broadcast_to(four, img.shape), atol=1e-12)
    # 3-pass error = the neglected self-attenuation a1·e2 (color channels)
    err = _flat(meshes, "3pass", bg)[0] - img
    np.testing.assert_allclose(err[..., :3], np.broadcast_to(a1 * e2[:3], err[..., :3].shape), atol=1e-12)


def test_opaque_surface_hides_what_is_behind_it_in_every_mode():
    c1, c3 = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)
    meshes = _planes(1.0, (0.4, -0.3, 0.0), [dict(color=c1, opacity=0.5), dict(color=(0, 0, 1), opacity=0.5),
                                               dict(color=c3, opacity=1.0)])
    expect = 0.5 * np.append(c1, 1.0) + 0.5 * np.append(c3, 1.0)
    for mode in MODES:
        img, _ = _flat(meshes, mode)
        np.testing.assert_allclose(img, np.broadcast_to(expect, img.shape), atol=1e-12)


def test_oit_modes_are_order_independent_2pass_is_not():
    styles = [IsoStyle(0.6, (1, 0, 0), 1.0), IsoStyle(0.35, (0, 1, 0), 0.4), IsoStyle(0.1, (0, 0, 1), 0.3)]
    meshes = extract(_sphere(), styles)
    cam = Camera.orbit(np.array([[-1, -1, -1], [1, 1, 1.0]]), distance=3.0)
    ref = render_modes(meshes, cam, (64, 64))
    rng = np.random.default_rng(1)
    shuffled = [IsoMesh(m.points, m.triangles[rng.permutation(m.n_triangles)], m.normals, m.style) for m in meshes]
    shuf = render_modes(shuffled[::-1], cam, (64, 64))
    for mode in ("3pass", "4pass", "exact"):
        assert max_abs(shuf[mode], ref[mode]) < 1e-9
    assert max_abs(shuf["2pass"], ref["2pass"]) > 5.0
    # with nested closed surfaces (depth complexity 4) the OIT modes differ from exact, 3-pass brighter (no
    # self-attenuation), and the 2-pass baseline's error depends on the triangle order
    assert np.all(ref["3pass"][..., :3] >= ref["exact"][..., :3] - 1e-12)
    assert max_abs(ref["3pass"], ref["exact"]) > 10.0


def test_spectrum_fit_is_computed_and_accurate():
    fits = [fit_spectrum(o) for o in (0.3, 0.5, 0.8)]
    assert len({round(f.a, 6) for f in fits}) == 3
    for f in fits:
        assert f.rms_error < 0.02 and f.max_error < 0.1
        mu = np.linspace(0.2, 1.0, 50)
        assert np.max(np.abs(spectrum_alpha(mu, f.a, f.b) - exact_alpha(mu, f.tau0))) < 0.09
        assert abs(spectrum_alpha(1.0, f.a, f.b) - f.opacity) < 0.03
    with pytest.raises(ValueError):
        fit_spectrum(1.0)


def test_extract_many_pools_volumes_and_bad_input():
    meshes = extract_many([(_sphere(), [0.5]), (_field_volume(lambda X, Y, Z: Z), [IsoStyle(0.0, opacity=0.2)])])
    assert len(meshes) == 2 and meshes[0].label != meshes[1].label
    with pytest.raises(ValueError):
        IsoStyle(0.5, opacity=1.5)
    with pytest.raises(TypeError):
        extract(np.zeros((3, 3, 3)), [0.5])
    with pytest.raises(ValueError):
        composite(fragments(meshes, TOP, (8, 8)), "5pass")
