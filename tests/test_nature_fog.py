"""Ground fog with PCP (Roettger §10.3–10.4): the per-pixel PCP equivalent against the reference emissive integral."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.nature import fog, noise
from volviz.nature.heightfield import HeightField
from volviz.nature.raster import bake_color_map, mip_pyramid, render_terrain
from volviz.nature.terrain import TerrainLOD
from volviz.model.camera import Camera

SIZE = (48, 36)


def fog_scene():
    n = 33
    h = noise.fractal_terrain(n, seed=3, relief=8.0)
    hf = HeightField(h, (1.0, 1.0))
    thickness = noise.fog_map(h, level=4.0, thickness=2.5, seed=1)
    lod = TerrainLOD(hf, layers={"fog": h + thickness}, curvature=[(thickness, 3.0)], big_c=4.0, small_c=3.0)
    return hf, lod


def terrain_depth(hf, mesh, cam):
    depth, _ = render_terrain(mesh.points, mesh.triangles, mesh.tcoords, cam, SIZE, mip_pyramid(bake_color_map(hf.normals())))
    return depth


@pytest.mark.parametrize("field", ["constant", "height"])
def test_pcp_matches_the_reference_emissive_integral(field: str) -> None:
    hf, lod = fog_scene()
    cam = Camera((-6, -8, 10), (16, 16, 2), (0, 0, 1), 50, clipping_range=(0.5, 80))
    mesh = lod.update(cam.position)
    z, top = mesh.points[:, 2], mesh.layers["fog"]
    if field == "constant":
        eb = et = np.ones(len(z))
    else:  # 0 at the bottom, the thickness at the top: the MIP field, linear along every ray
        eb, et = np.zeros(len(z)), top - z
    depth = terrain_depth(hf, mesh, cam)
    emis, mip, drawn = fog.pcp_integrals(mesh.points, z, top, mesh.triangles, eb, et, cam, SIZE, depth)
    ref_e, ref_m = fog.reference_integrals(mesh.points, z, z, top, mesh.triangles, eb, et, cam, SIZE, steps=2500)
    assert 0 < drawn < len(mesh.triangles)  # prisms without fog are discarded
    assert emis.max() > 3.0
    # the marching reference has O(step) error at each of a ray's layer crossings: step = 79.5/2500 * |D| <= 0.04
    diff = np.abs(emis - ref_e)
    assert np.mean(diff) < 0.01
    assert np.mean(diff > 0.15) < 0.002  # only silhouette pixels may disagree more
    if field == "height":
        assert np.mean(np.abs(mip - ref_m) > 0.1) < 0.002
        assert mip.max() == pytest.approx(ref_m.max(), abs=0.05)


def test_camera_inside_fog_uses_the_near_plane_cap() -> None:
    """A flat fog slab of thickness T over flat ground, the camera inside it: emission = in-fog ray length."""
    n, T, zc = 17, 4.0, 1.5
    hf = HeightField(np.zeros((n, n)), (10.0, 10.0))
    lod = TerrainLOD(hf, layers={"fog": np.full((n, n), T)}, big_c=4.0, small_c=1.0)
    cam = Camera((80, 20, zc), (80, 120, zc + 1.0), (0, 0, 1), 60, clipping_range=(0.5, 60))
    mesh = lod.update(cam.position)
    depth = terrain_depth(hf, mesh, cam)
    e = np.ones(len(mesh.points))
    emis, _, _ = fog.pcp_integrals(mesh.points, mesh.points[:, 2], mesh.layers["fog"], mesh.triangles, e, e, cam, SIZE, depth)
    rb = cam.rays(SIZE)
    cols, rows = np.meshgrid(np.arange(SIZE[0]), np.arange(SIZE[1]))
    d = rb.d0 + cols[..., None] * rb.dx + rows[..., None] * rb.dy
    o = rb.o0
    near, far = cam.clipping_range
    t_top = np.where(d[..., 2] > 0, (T - o[2]) / np.where(d[..., 2] > 0, d[..., 2], 1), np.inf)
    t_ground = np.where(d[..., 2] < 0, -o[2] / np.where(d[..., 2] < 0, d[..., 2], 1), np.inf)
    t_end = np.minimum(np.minimum(t_top, t_ground), far)
    expected = (t_end - near) * np.linalg.norm(d, axis=-1)
    assert np.all(emis > 0)  # every ray starts inside the fog at the near plane
    np.testing.assert_allclose(emis, expected, rtol=1e-6, atol=1e-6)


def test_render_layer_modes() -> None:
    hf, lod = fog_scene()
    cam = Camera((-6, -8, 10), (16, 16, 2), (0, 0, 1), 50, clipping_range=(0.5, 80))
    mesh = lod.update(cam.position)
    z, top = mesh.points[:, 2], mesh.layers["fog"]
    depth = terrain_depth(hf, mesh, cam)
    em, _ = fog.render_layer(mesh.points, z, top, mesh.triangles, fog.FogLayer(mode="emissive", density=0.1), cam, SIZE, depth)
    at, _ = fog.render_layer(mesh.points, z, top, mesh.triangles, fog.FogLayer(mode="attenuated", density=0.1), cam, SIZE, depth)
    mp, _ = fog.render_layer(mesh.points, z, top, mesh.triangles, fog.FogLayer(mode="mip"), cam, SIZE, depth)
    assert np.all(em[..., 3] == 0) and em[..., :3].max() > 0
    # attenuated: alpha = 1 - exp(-tau), color = kappa * alpha with tau the emissive integral / color
    tau = em[..., 2] / 1.0
    np.testing.assert_allclose(at[..., 3], 1 - np.exp(-tau), atol=1e-12)
    np.testing.assert_allclose(at[..., 0], 0.75 * at[..., 3], atol=1e-12)
    assert 0 < mp[..., 3].max() <= 1 and np.all(np.isfinite(mp))
    with pytest.raises(ValueError, match="fog mode"):
        fog.FogLayer(mode="fancy")
