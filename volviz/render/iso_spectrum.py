"""Iso-spectrum opacity in a VTK fragment shader (libMini note, "Shaded Iso-Surfaces": "a fragment shader that applies
the cosine term ... to the alpha channel").

``apply_spectrum_shader(actor, opacity)`` fits (a, b) for the surface's normal-incidence opacity
(``volviz.iso.spectrum.fit_spectrum``) and replaces the fragment alpha of a ``vtkOpenGLPolyDataMapper`` actor by
α = 1 − clamp(μ^a − b, 0, 1), μ = |n·v| from the interpolated view-space normal and the view ray (−vertexVC, or the
view axis for parallel projection). Only the alpha is replaced, right after ``//VTK::Light::Impl``: measured here
(VTK 9.7, llvmpipe), a replacement at ``//VTK::CustomEnd::Impl`` had no effect on a ``vtkOpenGLPolyDataMapper`` and
none at all through pyvista's ``vtkDataSetMapper``, so use a plain ``vtkOpenGLPolyDataMapper``. The actor must have
point normals; its property opacity is set to the normal-incidence opacity so VTK draws it in the
translucent pass (VTK blends straight alpha, SRC_ALPHA / ONE_MINUS_SRC_ALPHA, so the color follows α).

The renderer must have at least one light: without lights VTK builds its unlit shader, which declares neither
``normalVCVSOutput`` nor ``vertexVC``, and the replacement fails to compile (this was the "does not compile in the Qt
viewport" failure: ``pyvista.Plotter.clear`` removes all lights; ``volviz.render.controller.ensure_lights`` restores
them).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from volviz.iso.spectrum import SpectrumFit, fit_spectrum

if TYPE_CHECKING:   # type-only: the surface and VTK's actor, not imported at run time
    from volviz.iso.extract import IsoMesh
    from volviz.render.vtk_facade import vtkActor

__all__ = ["apply_spectrum_shader", "iso_actor", "SPECTRUM_GLSL"]

SPECTRUM_GLSL = """//VTK::Light::Impl
  {
    vec3 isoN = normalize(normalVCVSOutput);
    vec3 isoV = isoParallel > 0.5 ? vec3(0.0, 0.0, 1.0) : normalize(-vertexVC.xyz);
    float isoMu = clamp(abs(dot(isoN, isoV)), 0.0, 1.0);
    gl_FragData[0].a = 1.0 - clamp(pow(isoMu, isoA) - isoB, 0.0, 1.0);
  }
"""


def apply_spectrum_shader(actor: vtkActor, opacity: float, parallel: bool = False) -> SpectrumFit:
    """Install the iso-spectrum alpha on ``actor`` (a vtkActor with a vtkOpenGLPolyDataMapper); returns the fit.

    ``parallel``: the camera uses parallel projection (call again when it changes).
    """
    fit = fit_spectrum(float(opacity))
    prop = actor.GetShaderProperty()
    prop.ClearAllFragmentShaderReplacements()
    prop.AddFragmentShaderReplacement("//VTK::Light::Impl", True, SPECTRUM_GLSL, False)
    uni = prop.GetFragmentCustomUniforms()
    uni.SetUniformf("isoA", float(fit.a))
    uni.SetUniformf("isoB", float(fit.b))
    uni.SetUniformf("isoParallel", 1.0 if parallel else 0.0)
    actor.GetProperty().SetOpacity(float(opacity))
    return fit


def iso_actor(mesh: IsoMesh, parallel: bool = False, spectrum: bool = True) -> vtkActor:
    """A vtkActor for an ``IsoMesh`` (vtkOpenGLPolyDataMapper, the surface color, Phong-interpolated normals).

    Translucent surfaces get the iso-spectrum shader when ``spectrum`` is true, else constant opacity; VTK then
    blends them unsorted (the note's 2-pass mode). The accurate modes are the CPU compositor's
    (``volviz.iso.composite``); opaque surfaces are plain opaque actors.
    """
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    mapper = vtk.vtkOpenGLPolyDataMapper()
    mapper.SetInputData(mesh.to_pyvista())
    mapper.ScalarVisibilityOff()
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    prop = actor.GetProperty()
    prop.SetColor(*(float(c) for c in mesh.style.color))
    prop.SetInterpolationToPhong()
    prop.SetOpacity(float(mesh.style.opacity))
    if spectrum and 0.0 < float(mesh.style.opacity) < 1.0:
        apply_spectrum_shader(actor, float(mesh.style.opacity), parallel=parallel)
    return actor
