"""A translucent isosurface inside a regular volume drawn by VTK (issue #28; ``volviz.render.volume_peeling``): along
each ray the volume behind the surface, the surface and the volume in front composite in that order, against the
exact composite of the scene's own unpeeled renders (``iso_volume_scene``: a plane isosurface through a ball-shaped
volume, one layer per ray)."""
from __future__ import annotations

import numpy as np
import pyvista as pv

from iso_volume_scene import close_plotters, one_layer_composite, scene, shot, surface_alone, volume_cut  # noqa: F401
from volviz.render.backend import plotter_gl_info
from volviz.render.volume_peeling import peeling_volumes, peel_volumes


def reference(c, p: pv.Plotter) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(expected composite, a_S, F) from the scene's unpeeled renders (``iso_volume_scene``), all over black."""
    full, v_f, one_minus_a_f = volume_cut(c, p)
    s, a_s = surface_alone(c, p)
    return one_layer_composite(full, v_f, one_minus_a_f, s, a_s), a_s, full


def test_surface_lies_between_the_volume_behind_and_in_front():
    """Measured at 200 x 150 on llvmpipe, over the pixels the surface covers (a_S > 0.2, 60 % of the frame): the
    peeled frame against the reference RMSE 0.51, max 2.1 levels; VTK's default order (the surface, then the whole
    volume over it) RMSE 9.3. With the surface every one of those pixels changes by more than 3 levels (median 38)."""
    c, p = scene("gpu")
    assert peeling_volumes(p)                        # a translucent surface with a regular volume: peeled
    peeled = shot(p)
    expected, a_s, full = reference(c, p)
    unpeeled = shot(p)
    on = a_s > 0.2                                   # where the surface lies
    assert on.mean() > 0.3
    err = np.abs(peeled - expected)[on] * 255.0
    old = np.abs(unpeeled - expected)[on] * 255.0
    change = np.abs(peeled - full).max(axis=-1)[on] * 255.0
    print("peeled vs reference: rmse", np.sqrt((err ** 2).mean()), "max", err.max(),
          "| unpeeled: rmse", np.sqrt((old ** 2).mean()), "| surface pixels changed > 3:", (change > 3).mean(),
          "median change", np.median(change))
    assert np.sqrt((err ** 2).mean()) < 1.0 and err.max() <= 3.0     # 8-bit rounding of the reference's pieces
    assert np.sqrt((old ** 2).mean()) > 5.0                           # the order the fix replaces is far off
    assert (change > 3.0).mean() > 0.95 and np.median(change) > 20.0


def test_peeling_follows_the_surfaces_and_draws_the_volume_by_the_gpu_ray_caster_meanwhile():
    """On a software OpenGL ``auto`` draws regular volumes by VTK's CPU ray caster, which VTK cannot peel: while a
    translucent surface is shown in "vtk" mode the volume is drawn by the GPU ray caster, and by its own again when
    the surface is hidden or a mode of the note draws it."""
    c, p = scene("auto")
    mapper, ren = c.props["vol"].GetMapper(), p.renderer
    assert peeling_volumes(p) and ren.GetUseDepthPeeling() and ren.GetUseDepthPeelingForVolumes()
    assert mapper.GetRequestedRenderMode() == mapper.GPURenderMode
    c.set_visible("iso", False)
    assert not peeling_volumes(p) and not ren.GetUseDepthPeeling() and not ren.GetUseDepthPeelingForVolumes()
    own = mapper.GetRequestedRenderMode()
    assert own == (mapper.RayCastRenderMode if plotter_gl_info(p).software else mapper.DefaultRenderMode)
    c.set_visible("iso", True)
    assert peeling_volumes(p) and mapper.GetRequestedRenderMode() == mapper.GPURenderMode
    c.set_iso_mode("3pass")                          # the note's passes draw the surfaces: no peeling
    assert not peeling_volumes(p) and mapper.GetRequestedRenderMode() == own
    c.set_iso_mode("vtk")
    assert peeling_volumes(p)


def test_a_renderer_with_its_own_render_pass_is_not_peeled():
    """The float scene target of the GL passes (``volviz.render.gl.ScenePass``) replaces VTK's passes, under which
    VTK does not peel: peeling stays off there and the renderer's settings untouched."""
    from volviz.render.vtk_facade import vtk

    c, p = scene("gpu")
    peel_volumes(p, [c.props["vol"]], False)
    p.renderer.SetPass(vtk.vtkRenderStepsPass())
    assert not peel_volumes(p, [c.props["vol"]], True)
    assert not p.renderer.GetUseDepthPeeling() and not peeling_volumes(p)
    p.renderer.SetPass(None)
