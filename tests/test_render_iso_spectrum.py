"""Iso-spectrum opacity in a real VTK fragment shader (offscreen), against the fitted formula per pixel."""
from __future__ import annotations

import numpy as np
import pyvista as pv
from vtkmodules.vtkRenderingCore import vtkActor
from vtkmodules.vtkRenderingOpenGL2 import vtkOpenGLPolyDataMapper

from volviz.iso.spectrum import spectrum_alpha
from volviz.render.iso_spectrum import apply_spectrum_shader


def _sphere_row(shader: bool) -> tuple[np.ndarray, object]:
    pl = pv.Plotter(off_screen=True, window_size=(128, 128))
    pl.set_background((0.0, 0.0, 0.0))
    mapper = vtkOpenGLPolyDataMapper()
    mapper.SetInputData(pv.Sphere(radius=1.0, theta_resolution=120, phi_resolution=120).compute_normals())
    actor = vtkActor()
    actor.SetMapper(mapper)
    p = actor.GetProperty()
    p.SetAmbient(1.0), p.SetDiffuse(0.0), p.SetSpecular(0.0), p.SetColor(1.0, 1.0, 1.0), p.SetOpacity(0.3)
    p.BackfaceCullingOn()  # one layer: the pixel is α·white over black
    fit = apply_spectrum_shader(actor, 0.3, parallel=True) if shader else None
    pl.renderer.AddActor(actor)
    cam = pl.camera
    cam.position, cam.focal_point, cam.up = (0, 0, 10), (0, 0, 0), (0, 1, 0)
    cam.parallel_projection, cam.parallel_scale = True, 1.1
    img = pl.screenshot(return_img=True).astype(np.float64) / 255.0
    pl.close()
    return img[64, :, 0], fit


def test_shader_alpha_follows_the_fitted_spectrum():
    row, fit = _sphere_row(True)
    x = (np.arange(128) - 63.5) / 64.0 * 1.1
    inside = np.abs(x) < 0.95
    expect = spectrum_alpha(np.sqrt(1.0 - x[inside] ** 2), fit.a, fit.b)
    assert np.max(np.abs(row[inside] - expect)) < 3.0 / 255.0
    assert expect.max() - expect.min() > 0.2  # the test sees the angular variation, not a constant
    flat, _ = _sphere_row(False)
    assert np.max(np.abs(flat[inside] - 0.3)) < 3.0 / 255.0  # without the shader: constant opacity


def test_iso_actor_renders_translucent_and_opaque_surfaces():
    from volviz.iso.extract import IsoMesh, IsoStyle
    s = pv.Sphere(radius=1.0).compute_normals()
    tris = np.asarray(s.faces).reshape(-1, 4)[:, 1:]
    pl = pv.Plotter(off_screen=True, window_size=(64, 64))
    pl.set_background((0.0, 0.0, 0.0))
    for style in (IsoStyle(0.0, (0.0, 0.0, 1.0), 0.4), IsoStyle(0.0, (1.0, 0.0, 0.0), 1.0)):
        pts = np.asarray(s.points) * (0.5 if style.opacity == 1.0 else 1.0)
        mesh = IsoMesh(pts, tris, np.asarray(s.point_data["Normals"]), style)
        from volviz.render.iso_spectrum import iso_actor
        pl.renderer.AddActor(iso_actor(mesh))
    pl.reset_camera()
    img = pl.screenshot(return_img=True).astype(np.float64)
    pl.close()
    centre, rim = img[32, 32], img[32, 18]
    assert centre[0] > 60 and centre[2] > 20  # red opaque core seen through the blue translucent shell
    assert rim[2] > 20 and rim[0] < 5  # only the shell at the rim
