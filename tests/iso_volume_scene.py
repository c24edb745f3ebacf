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


def session(backend: str, iso_mode: str = "vtk", paths: dict[str, str] | None = None) -> Session:
    """The scene's session (datasets at ``paths``, by default not to be read: ``scene`` hands them over)."""
    paths = paths or {"v": "/unused", "p": "/unused"}
    s = Session(datasets=[DatasetRef("v", paths["v"]), DatasetRef("p", paths["p"])],
                components=[Component("vol", "volume", "v", opacity=0.15),
                            Component("iso", "isosurface", "p", settings={"styles": [STYLE]})],
                camera=CameraState((-12.0, -40.0, 34.0), (15.5, 15.5, 15.5), (0.0, 0.0, 1.0)))
    s.render.background = (0.0, 0.0, 0.0)
    s.render.options.update(PLAIN, backend=backend, iso_mode=iso_mode)
    return s


def scene(backend: str, size: tuple[int, int] = SIZE, iso_mode: str = "vtk") -> tuple[SceneController, pv.Plotter]:
    """The scene in a new off-screen plotter (closed after the test by ``close_plotters``)."""
    p = pv.Plotter(off_screen=True, window_size=size)
    p.ren_win.SetMultiSamples(0)
    PLOTTERS.append(p)
    c = SceneController(p, session(backend, iso_mode), datasets())
    c.build()
    return c, p


def shot(p: pv.Plotter) -> np.ndarray:
    p.render()
    return p.screenshot(None, return_img=True)[..., :3].astype(np.float64) / 255.0


def surface_actor(c: SceneController):
    prop = c.props["iso"]
    assert len(prop.volviz_translucent) == 1
    return prop.volviz_translucent[0]


def volume_cut(c: SceneController, p: pv.Plotter) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(F, V_f, 1 − a_f) over black from renders of VTK's own actors, unpeeled, the note's overlay hidden: F the
    volume alone, V_f and 1 − a_f the volume in front of the surface made opaque black, then white, unlit."""
    volume, actor, overlay = c.props["vol"], surface_actor(c), c.iso_overlay
    shown = actor.GetVisibility()
    if overlay is not None:
        overlay.visible = False
    gl = getattr(c.iso_view, "surfaces", None)        # the GPU passes of a note mode (``GLIsoView``)
    for a in gl.actors.values() if gl is not None else ():
        a.SetVisibility(False)
    peel_volumes(p, [volume], False)
    actor.SetVisibility(False)
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
    actor.SetVisibility(shown)
    if overlay is not None:
        overlay.visible = True
    if gl is not None:
        gl.set_mode(gl.mode)
    return full, cut[0], (cut[1] - cut[0]).mean(axis=-1, keepdims=True)


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
