"""A translucent plane isosurface through a ball-shaped regular volume, and the exact composite of such a scene made
of its own renders (tests/test_iso_composite_volume.py: VTK's mode; tests/test_iso_modes_volume.py: the note's modes).

The plane (an isosurface of a second dataset, f = y) gives each ray exactly one surface layer, so the right
composite is V_f + (1 − a_f)(S + (1 − a_S) V_b) with F = V_f + (1 − a_f) V_b the volume alone, i.e.
(1 − a_S) F + a_S V_f + (1 − a_f) S: F rendered without the surface, V_f (premultiplied) and a_f the volume cut at
the surface (the surface made opaque, black and then white, unlit), S (premultiplied) and a_S the surface."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import pyvista as pv

from volviz.model.datasets import RegularVolume
from volviz.render.controller import SceneController
from volviz.render.iso_spectrum import apply_spectrum_shader
from volviz.render.volume_peeling import peel_volumes
from volviz.session import CameraState, Component, DatasetRef, Session

SIZE = (200, 150)
N = 32
STYLE = {"value": (N - 1) / 2.0, "color": [0.1, 0.9, 0.2], "opacity": 0.4}
PLAIN = {"scalar_bar": False, "axes": False, "outline": False}
PLOTTERS: list[pv.Plotter] = []     # the scenes' plotters, closed after each test by ``close_plotters``


@pytest.fixture(autouse=True)
def close_plotters():
    """Close the scenes' render windows (before the X server goes away at exit); a test module imports it."""
    yield
    while PLOTTERS:
        PLOTTERS.pop().close()


def datasets() -> dict[str, RegularVolume]:
    g = np.linspace(-1.0, 1.0, N)
    x, y, z = np.meshgrid(g, g, g, indexing="ij")
    ball = np.clip(1.0 - (x * x + y * y + z * z), 0.0, None).astype(np.float32)   # dense in the middle
    plane = np.broadcast_to(np.arange(N, dtype=np.float32)[None, :, None], (N, N, N)).copy()   # f = y (voxels)
    return {"v": RegularVolume(ball), "p": RegularVolume(plane)}


def write_datasets(folder: Path) -> dict[str, str]:
    """``datasets()`` written as .vti files in ``folder``: their paths by dataset id."""
    paths = {}
    for key, volume in datasets().items():
        paths[key] = str(folder / f"{key}.vti")
        volume.to_pyvista().save(paths[key])
    return paths


def session(backend: str, iso_mode: str = "vtk", paths: dict[str, str] | None = None,
            styles: list[dict] | None = None) -> Session:
    """The scene's session (datasets at ``paths``, by default not to be read: ``scene`` hands them over; the plane's
    isosurface ``styles``, by default ``STYLE`` alone)."""
    paths = paths or {"v": "/unused", "p": "/unused"}
    s = Session(datasets=[DatasetRef("v", paths["v"]), DatasetRef("p", paths["p"])],
                components=[Component("vol", "volume", "v", opacity=0.15),
                            Component("iso", "isosurface", "p", settings={"styles": styles or [STYLE]})],
                camera=CameraState((-12.0, -40.0, 34.0), (15.5, 15.5, 15.5), (0.0, 0.0, 1.0)))
    s.render.background = (0.0, 0.0, 0.0)
    s.render.options.update(PLAIN, backend=backend, iso_mode=iso_mode)
    return s


def scene(backend: str, size: tuple[int, int] = SIZE, iso_mode: str = "vtk",
          styles: list[dict] | None = None) -> tuple[SceneController, pv.Plotter]:
    """The scene in a new off-screen plotter (closed after the test by ``close_plotters``)."""
    p = pv.Plotter(off_screen=True, window_size=size)
    p.ren_win.SetMultiSamples(0)
    PLOTTERS.append(p)
    c = SceneController(p, session(backend, iso_mode, styles=styles), datasets())
    c.build()
    return c, p


def shot(p: pv.Plotter) -> np.ndarray:
    p.render()
    return p.screenshot(None, return_img=True)[..., :3].astype(np.float64) / 255.0


def volume_cut(c: SceneController, p: pv.Plotter, layer: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(F, V_f, 1 − a_f) over black from renders of VTK's own actors, unpeeled, the note's views hidden, the volume
    by the ray caster that drew the frame: F the volume alone, V_f and 1 − a_f the volume in front of the translucent
    surface ``layer`` made opaque black, then white, unlit (the other surfaces hidden)."""
    volume, overlay = c.props["vol"], c.iso_overlay
    actors = c.props["iso"].volviz_translucent
    actor, shown = actors[layer], [a.GetVisibility() for a in actors]
    if overlay is not None:
        overlay.visible = False
    gl = getattr(c.iso_view, "surfaces", None)        # the GPU passes of a note mode (``GLIsoView``)
    peeled = gl is not None and gl.peels_volumes
    for a in gl.actors.values() if gl is not None else ():
        a.SetVisibility(False)
    mapper = volume.GetMapper()
    caster = mapper.GetRequestedRenderMode()
    peel_volumes(p, [volume], False)
    own = mapper.GetRequestedRenderMode()
    mapper.SetRequestedRenderMode(caster)          # the frame's ray caster (the GPU's while peeled)
    for a in actors:
        a.SetVisibility(False)
    full = shot(p)
    actor.SetVisibility(True)
    prop, shader = actor.GetProperty(), actor.GetShaderProperty()
    kept = (prop.GetOpacity(), prop.GetColor(), prop.GetLighting())
    shader.ClearAllFragmentShaderReplacements()
    prop.SetOpacity(1.0)
    prop.LightingOff()
    cut = []
    for grey in (0.0, 1.0):                           # V_f over the opaque surface in black, then white
        prop.SetColor(grey, grey, grey)
        cut.append(shot(p))
    prop.SetOpacity(kept[0])
    prop.SetColor(*kept[1])
    prop.SetLighting(kept[2])
    apply_spectrum_shader(actor, kept[0])
    for a, on in zip(actors, shown):
        a.SetVisibility(on)
    if overlay is not None:
        overlay.visible = True
    mapper.SetRequestedRenderMode(own)
    if gl is not None:
        gl.set_mode(gl.mode)
    if peeled:
        peel_volumes(p, [volume], True)
    return full, cut[0], (cut[1] - cut[0]).mean(axis=-1, keepdims=True)


def surface_image(c: SceneController, p: pv.Plotter, mode: str, layer: int | None = None) -> np.ndarray:
    """The mode's premultiplied image (``volviz.iso.composite.render``, the CPU compositor's optics) of the shown
    translucent surfaces (only the ``layer``-th when given) for the plotter's camera and size (the overlay's near
    plane: VTK's clipping range ignores the hidden actors)."""
    from volviz.iso.composite import render
    from volviz.model.camera import Camera

    cam = Camera.from_pyvista(p.renderer.GetActiveCamera())
    near = min(cam.clipping_range[0], 1e-3 * cam.clipping_range[1])
    cam = Camera(cam.position, cam.focal_point, cam.view_up, cam.view_angle, cam.parallel, cam.parallel_scale,
                 (near, cam.clipping_range[1]))
    meshes = [m for m in c.props["iso"].volviz_shown if m.style.opacity < 1.0]
    img, _ = render(meshes if layer is None else [meshes[layer]], cam, tuple(int(v) for v in p.ren_win.GetSize()),
                    mode)
    return img


def two_layer_composite(c: SceneController, p: pv.Plotter) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(the exact composite, the surfaces over the whole volume, the pixels both surfaces cover with α > 0.2) over
    black for a scene of two translucent surfaces, the first in front of the second on every ray: with G_k, A_k the
    volume in front of surface k (``volume_cut``) and S_k, α_k its image, C = G_1 + (1 − A_1) S_1
    + (1 − α_1)[(G_2 − G_1) + (1 − A_2) S_2 + (1 − α_2)(F − G_2)]."""
    full, g1, one_minus_a1 = volume_cut(c, p, 0)
    _, g2, one_minus_a2 = volume_cut(c, p, 1)
    s1, s2 = surface_image(c, p, "exact", 0), surface_image(c, p, "exact", 1)
    t1, t2 = 1.0 - s1[..., 3:4], 1.0 - s2[..., 3:4]
    exact = g1 + one_minus_a1 * s1[..., :3] + t1 * ((g2 - g1) + one_minus_a2 * s2[..., :3] + t2 * (full - g2))
    over_all = s1[..., :3] + t1 * (s2[..., :3] + t2 * full)
    return exact, over_all, (s1[..., 3] > 0.2) & (s2[..., 3] > 0.2)


def surface_alone(c: SceneController, p: pv.Plotter) -> tuple[np.ndarray, np.ndarray]:
    """(S premultiplied over black, a_S (H, W)) of VTK's surface actor, the volume hidden."""
    from volviz.render.export import separate_background

    volume = c.props["vol"]
    peel_volumes(p, [volume], False)
    volume.SetVisibility(False)
    ren = p.renderer
    on_black = shot(p)
    ren.SetBackground(1.0, 1.0, 1.0)
    on_white = shot(p)
    ren.SetBackground(0.0, 0.0, 0.0)
    volume.SetVisibility(True)
    surf = separate_background(np.rint(on_black * 255).astype(np.uint8), np.rint(on_white * 255).astype(np.uint8))
    return on_black, surf[..., 3].astype(np.float64) / 255.0


def one_layer_composite(full: np.ndarray, v_f: np.ndarray, one_minus_a_f: np.ndarray, s: np.ndarray,
                        a_s: np.ndarray) -> np.ndarray:
    """The exact composite over black where each ray meets one surface layer (module docstring)."""
    return (1.0 - a_s[..., None]) * full + a_s[..., None] * v_f + one_minus_a_f * s
