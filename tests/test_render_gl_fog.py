"""The GPU ground fog pass (``volviz.render.gl_fog``, PCP prisms, Roettger §10.3-10.4) on llvmpipe, offscreen: its
screen image (8-bit) against the CPU ``render_layer`` of the same layer, camera, window size and opaque depth (read
back from VTK's z-buffer), composited over the same opaque scene, and the emissive mode against the exact emissive
integral (``reference_integrals``).

The terrain is a 33x33-vertex fractal with a fog map (2048 triangles, 1428 prisms with fog); the emission field
varies over the layer (bottom and top emissions differ, so the field is not linear along rays).

Bounds in 8-bit units with the measured values they come from (llvmpipe, Mesa, VTK 9.7.2):

- Against the CPU PCP (GPU and CPU compute the same per-pixel integral; the screen's rounding alone gives max 0.5 and
  RMSE ~0.29 over a uniform spread): modes at 256^2 measured RMSE 0.19-0.20, max 0.50-0.51; camera inside the fog
  RMSE 0.29, max 0.500; opaque box RMSE 0.12, max 0.504. Bounds: RMSE 0.4; max 0.75 (rounding plus 0.25 for the
  shader's float32 arithmetic) over all pixels but the grazing ones.
- Grazing pixels: the integral is discontinuous where a pixel's ray lies in the plane of a prism's face (the eye in
  the plane of a fog top triangle: the ray runs along the surface inside the prism for a length, or misses it) or
  touches a prism at an edge (MIP: a segment 1e-5 long still contributes its endpoints' maximum). Whether such a
  pixel's centre is in the prism is decided by float64 plane tests on the CPU and by the rasteriser's fixed-point
  edge functions on the GPU; measured: 1 pixel of 65,536 (MIP, off by 11.3) at 256^2 and 1 of 6,144 at 96x64
  (emissive 7.8, MIP 32). The tests allow 0.01 % of the pixels, at least one, above the max bound.
- Against the reference (dense ray marching, 4000 steps; top-down view: no terrain silhouettes, where the z-buffer
  and the reference's ray-terrain test classify pixels differently): in ``test_emissive_matches_the_reference_*``.
"""
from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv

from volviz.nature import fog, noise
from volviz.nature.heightfield import HeightField
from volviz.nature.terrain import TerrainLOD
from volviz.render.gl_fog import GLFogLayer
from volviz.render.image_overlay import read_buffers, zbuffer_to_depth
from volviz.model.camera import Camera

RMSE, MAX = 0.4, 0.75
COLOR = (0.8, 0.85, 1.0)
GROUND = (0.3, 0.25, 0.2)
OBLIQUE = Camera((-4, -6, 12), (16, 16, 2), (0, 0, 1), 50, clipping_range=(0.5, 80))
TOP_DOWN = Camera((16, 0, 24), (16, 14, 0), (0, 0, 1), 45, clipping_range=(0.5, 80))


@pytest.fixture(scope="module")
def terrain():
    """(mesh, bottom, top, varying emission (e_bottom, e_top), the terrain as a PyVista mesh)."""
    h = noise.fractal_terrain(33, seed=3, relief=8.0)
    thickness = noise.fog_map(h, level=4.0, thickness=2.5, seed=1)
    mesh = TerrainLOD(HeightField(h, (1.0, 1.0)), layers={"fog": h + thickness}, big_c=4.0, small_c=3.0).full_mesh()
    z, top = mesh.points[:, 2], mesh.layers["fog"]
    fogged = top > z
    x, y = mesh.points[:, 0], mesh.points[:, 1]
    emission = ((1.0 + 0.5 * np.sin(x / 3.0)) * fogged, (0.3 + 0.2 * np.cos(y / 4.0)) * fogged)
    faces = np.hstack([np.full((len(mesh.triangles), 1), 3), mesh.triangles]).ravel()
    return mesh, z, top, emission, pv.PolyData(mesh.points, faces)


def _plotter(size, cam, scene) -> pv.Plotter:
    pl = pv.Plotter(off_screen=True, window_size=size)
    pl.ren_win.SetMultiSamples(0)          # one color and depth per pixel (the float target is not multisampled)
    pl.set_background("black")
    cam.apply_to(pl.renderer.GetActiveCamera())
    pl.camera_set = True                   # keep PyVista from resetting the camera at the first render
    for mesh, kw in scene:
        pl.add_mesh(mesh, **kw)
    return pl


def _opaque(size, cam, scene) -> tuple[np.ndarray, np.ndarray]:
    """(the opaque scene's 8-bit image as float 0..1, its depth along the view) from a plotter without fog."""
    pl = _plotter(size, cam, scene)
    img = pl.screenshot(return_img=True).astype(np.float64) / 255.0
    z, _ = read_buffers(pl.ren_win, *size)
    pl.close()
    return img, zbuffer_to_depth(z, cam.clipping_range, cam.parallel)


def _gpu(size, cam, scene, terrain, layer, emission=None, after=()) -> np.ndarray:
    mesh, z, top = terrain[:3]
    pl = _plotter(size, cam, scene)
    layer_gl = GLFogLayer(pl, mesh.points, z, top, mesh.triangles, layer, emission)
    for m, kw in after:
        pl.add_mesh(m, **kw)
    img = pl.screenshot(return_img=True).astype(np.float64)
    layer_gl.remove()
    pl.close()
    return img


def _cpu(size, cam, terrain, layer, depth, emission=None) -> np.ndarray:
    mesh, z, top = terrain[:3]
    rgba, _ = fog.render_layer(mesh.points, z, top, mesh.triangles, layer, cam, size, depth, emission)
    return rgba


def _err(screen: np.ndarray, expected_rgb: np.ndarray) -> tuple[float, float]:
    d = screen[..., :3] - np.clip(expected_rgb, 0.0, 1.0) * 255.0
    return float(np.sqrt((d ** 2).mean())), float(np.abs(d).max())


def _check(screen: np.ndarray, expected_rgb: np.ndarray, label: str) -> None:
    """RMSE <= RMSE over all pixels and max <= MAX over all but the grazing pixels (module docstring): at most
    0.01 % of the pixels, and at least one, may exceed MAX."""
    rmse, worst = _err(screen, expected_rgb)
    d = np.abs(screen[..., :3] - np.clip(expected_rgb, 0.0, 1.0) * 255.0).max(axis=2)
    over = int((d > MAX).sum())
    print(label, f"RMSE {rmse:.3f} max {worst:.3f}, max without grazing pixels {np.sort(d.ravel())[-1 - over]:.3f}, "
          f"grazing pixels {over}")
    assert rmse <= RMSE and over <= max(1, d.size // 10000), (label, rmse, worst, over)


def _layer(mode: str) -> fog.FogLayer:
    return fog.FogLayer(color=COLOR, density={"emissive": 0.1, "attenuated": 0.4, "mip": 0.0}[mode], mode=mode,
                        mip_gain=0.3)


@pytest.mark.parametrize("mode", ["emissive", "attenuated", "mip"])
def test_modes_match_the_cpu(terrain, mode):
    """Each mode at 256^2 against the CPU PCP of the same layer, over the same terrain (a varying emission field for
    the emissive and attenuated modes; MIP uses the height above the bottom)."""
    size = (256, 256)
    scene = [(terrain[4], {"color": GROUND, "lighting": False})]
    base, depth = _opaque(size, OBLIQUE, scene)
    layer = _layer(mode)
    emission = None if mode == "mip" else terrain[3]
    rgba = _cpu(size, OBLIQUE, terrain, layer, depth, emission)
    assert rgba[..., :3].max() > 0.4 and (rgba[..., 0] > 0.01).mean() > 0.1      # a substantial fog
    expected = rgba[..., :3] + (1.0 - rgba[..., 3:]) * base
    _check(_gpu(size, OBLIQUE, scene, terrain, layer, emission), expected, mode)


@pytest.mark.parametrize("field", ["constant", "height"])
def test_emissive_matches_the_reference_integral(terrain, field):
    """The emissive mode at 128^2 against the exact emissive integral by dense ray marching, for fields that are
    linear along every ray (so PCP's trapezoid is exact): 1 in the fog, and the height above the fog's bottom.

    Measured: constant RMSE 0.30 / max 1.26, height 0.25 / max 1.42 (the marching's O(step) error at the layer's
    boundaries plus the screen's rounding; no grazing pixels here); bounds 0.4 / 2.0."""
    size = (128, 128)
    mesh, z, top = terrain[:3]
    fogged = (top > z).astype(np.float64)
    eb, et = (fogged, fogged) if field == "constant" else (np.zeros_like(z), np.maximum(top - z, 0.0))
    scene = [(terrain[4], {"color": GROUND, "lighting": False})]
    base, _ = _opaque(size, TOP_DOWN, scene)
    layer = fog.FogLayer(color=COLOR, density=0.15, mode="emissive")
    emis, _ = fog.reference_integrals(mesh.points, z, z, top, mesh.triangles, eb, et, TOP_DOWN, size, steps=4000)
    expected = layer.density * emis[..., None] * np.asarray(COLOR) + base
    assert emis.max() * layer.density > 0.3
    e = _err(_gpu(size, TOP_DOWN, scene, terrain, layer, (eb, et)), expected)
    print(field, "RMSE / max", e)
    assert e[0] <= 0.4 and e[1] <= 2.0, e


def test_camera_inside_the_fog(terrain):
    """The camera in a fog-filled valley, below the fog's top: every prism around it is cut by the near plane and
    starts there (the §10.4 cap); every pixel's ray starts in fog."""
    mesh, z, top = terrain[:3]
    thick = top - z
    p = mesh.points
    j = np.flatnonzero((thick > 1.5) & (np.abs(p[:, 0] - 16) < 12) & (np.abs(p[:, 1] - 16) < 12))[0]
    eye = (p[j, 0], p[j, 1], z[j] + 0.5 * thick[j])
    cam = Camera(eye, (16, 16, eye[2] + 1.0), (0, 0, 1), 60, clipping_range=(0.05, 60))
    size = (128, 96)
    scene = [(terrain[4], {"color": GROUND, "lighting": False})]
    base, depth = _opaque(size, cam, scene)
    for mode in ("emissive", "attenuated", "mip"):
        layer = _layer(mode)
        rgba = _cpu(size, cam, terrain, layer, depth)
        assert rgba[..., 2].min() > 0.02                       # fog in front of every pixel
        _check(_gpu(size, cam, scene, terrain, layer), rgba[..., :3] + (1.0 - rgba[..., 3:]) * base, mode)


def test_opaque_box_in_the_fog(terrain):
    """A box standing in a fog-filled valley: the fog behind it is hidden (each ray ends at the box's depth), the fog
    in front of it kept. Expected: the CPU PCP given the depth of terrain and box."""
    mesh, z, top = terrain[:3]
    j = np.argmax(top - z)
    cx, cy = mesh.points[j, :2]
    box = pv.Box((cx - 1.5, cx + 1.5, cy - 1.5, cy + 1.5, z[j] - 2.0, z[j] + 6.0))
    size = (128, 128)
    cam = Camera((cx - 12, cy - 14, z[j] + 8), (cx, cy, z[j] + 1), (0, 0, 1), 50, clipping_range=(0.5, 80))
    scene = [(terrain[4], {"color": GROUND, "lighting": False}), (box, {"color": (0.9, 0.3, 0.2), "lighting": False})]
    layer = _layer("attenuated")
    base, depth = _opaque(size, cam, scene)
    _, depth_terrain = _opaque(size, cam, scene[:1])
    rgba = _cpu(size, cam, terrain, layer, depth, terrain[3])
    on_box = depth < depth_terrain - 1e-3
    hidden = _cpu(size, cam, terrain, layer, depth_terrain, terrain[3])[..., 3] - rgba[..., 3]
    assert on_box.sum() > 300 and hidden[on_box].max() > 0.2          # the box hides fog behind it
    assert rgba[..., 3][on_box].max() > 0.2                             # and has fog in front of it
    _check(_gpu(size, cam, scene, terrain, layer, terrain[3]), rgba[..., :3] + (1.0 - rgba[..., 3:]) * base, "box")


@pytest.mark.parametrize("mode", ["emissive", "attenuated", "mip"])
def test_second_translucent_actor_keeps_its_pixels(terrain, mode):
    """A translucent quad drawn after the fog (added later), partly over fog and partly over fog-free terrain and sky:
    where there is no fog the screen is exactly the image of the same plotter with the fog layer hidden (the blend
    function and equation are VTK's again after the pass); where the quad covers fog it is quad over (fog over
    terrain), straight alpha."""
    size = (96, 64)
    mesh, z, top = terrain[:3]
    scene = [(terrain[4], {"color": GROUND, "lighting": False})]
    quad = pv.Plane(center=(14.0, 14.0, 6.0), direction=(-1.0, -1.0, 0.5), i_size=16.0, j_size=10.0)
    layer = _layer(mode)
    base, depth = _opaque(size, OBLIQUE, scene)
    rgba = _cpu(size, OBLIQUE, terrain, layer, depth)
    pl = _plotter(size, OBLIQUE, scene)
    layer_gl = GLFogLayer(pl, mesh.points, z, top, mesh.triangles, layer)
    pl.add_mesh(quad, color=(1.0, 0.0, 0.0), opacity=0.5, lighting=False)
    img = pl.screenshot(return_img=True).astype(np.float64)
    layer_gl.visible = False
    pl.render()
    without = pl.screenshot(return_img=True).astype(np.float64)
    layer_gl.visible = True
    pl.render()
    again = pl.screenshot(return_img=True).astype(np.float64)
    layer_gl.remove()
    pl.close()
    quad_px = np.abs(without - base * 255.0).max(axis=2) > 20
    no_fog = (rgba == 0.0).all(axis=2)
    fog_px = rgba[..., 3] + rgba[..., 0] > 0.05
    print(mode, "quad pixels without / with fog", (quad_px & no_fog).sum(), (quad_px & fog_px).sum())
    assert (quad_px & no_fog).sum() > 50 and (quad_px & fog_px).sum() > 50
    assert np.array_equal(img[no_fog], without[no_fog]) and np.array_equal(img, again)
    fogged = rgba[..., :3] + (1.0 - rgba[..., 3:]) * base
    expected = np.where(quad_px[..., None], 0.5 * np.array([1.0, 0.0, 0.0]) + 0.5 * fogged, fogged)
    _check(img, expected, mode)


def test_set_layer_and_resize(terrain):
    """One layer object through a mode change (attenuated -> mip: a new emission field is uploaded) and a window
    resize (the layer's float target is made again at the new size): each frame against the CPU."""
    mesh, z, top = terrain[:3]
    scene = [(terrain[4], {"color": GROUND, "lighting": False})]
    pl = _plotter((80, 60), OBLIQUE, scene)
    layer_gl = GLFogLayer(pl, mesh.points, z, top, mesh.triangles, _layer("attenuated"))
    frames = [("attenuated", (80, 60), pl.screenshot(return_img=True).astype(np.float64))]
    layer_gl.set_layer(_layer("mip"))
    pl.render()
    frames.append(("mip", (80, 60), pl.screenshot(return_img=True).astype(np.float64)))
    pl.window_size = (120, 72)
    pl.render()
    frames.append(("mip", (120, 72), pl.screenshot(return_img=True).astype(np.float64)))
    layer_gl.remove()
    pl.close()
    for mode, size, img in frames:
        assert img.shape[:2] == (size[1], size[0])
        base, depth = _opaque(size, OBLIQUE, scene)
        rgba = _cpu(size, OBLIQUE, terrain, _layer(mode), depth)
        assert rgba[..., 3].max() > 0.3
        _check(img, rgba[..., :3] + (1.0 - rgba[..., 3:]) * base, f"{mode} {size}")
