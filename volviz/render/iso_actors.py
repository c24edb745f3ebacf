"""GUI thread: an isosurface component's surfaces (``volviz.scene.isosurfaces.IsoParts``) as VTK actors, with the
iso-spectrum shader (libMini note "Isosurfaces": drawn by VTK as the note's 2-pass blend; inside a regular volume
depth-peeled with it, ``volviz.render.volume_peeling``, so that the volume in front of a surface covers it and the
volume behind it does not)."""
from __future__ import annotations

from typing import TYPE_CHECKING, Optional

from volviz.render.iso_spectrum import iso_actor
from volviz.render.vtk_facade import vtk
from volviz.scene.isosurfaces import IsoParts, isosurface_parts
from volviz.session import Component

if TYPE_CHECKING:   # type-only: PyVista's plotter, the dataset and surfaces, VTK's assembly (through the facade)
    import pyvista as pv

    from volviz.iso.extract import IsoMesh
    from volviz.model.clip import ClipSettings
    from volviz.render.vtk_facade import vtkPropAssembly
    from volviz.scene.datasets import LoadedDataset


def add_isosurface_actors(plotter: pv.BasePlotter, name: str, parts: IsoParts,
                          spectrum: bool = True) -> vtkPropAssembly:
    """GUI thread: the shown surfaces of ``parts`` as one prop assembly of VTK actors named ``name``, with the
    iso-spectrum shader when ``spectrum`` (drawn by VTK as the note's 2-pass blend). The assembly keeps the uncut
    surfaces as ``volviz_meshes`` and the shown ones as ``volviz_shown`` (the CPU transparency modes draw those,
    ``volviz.render.iso_overlay``).

    The shader needs the renderer's lights: a renderer without lights (``pyvista.Plotter.clear`` removes them)
    compiles VTK's unlit shader, which declares no normals (``normalVCVSOutput`` undeclared); the scene controller
    restores the light kit before building."""
    assembly = vtk.vtkPropAssembly()
    translucent = []  # the actors of translucent surfaces (hidden while a CPU mode draws those surfaces)
    # (the VTK camera: pyvista's ``plotter.camera`` re-frames a camera it does not consider set)
    parallel = bool(plotter.renderer.GetActiveCamera().GetParallelProjection())
    for mesh in parts.shown:
        if len(mesh.triangles):
            actor = iso_actor(mesh, parallel=parallel, spectrum=spectrum and parts.settings.shading == "spectrum")
            assembly.AddPart(actor)
            if mesh.style.opacity < 1.0:
                translucent.append(actor)
    assembly.volviz_meshes, assembly.volviz_shown = parts.meshes, parts.shown
    assembly.volviz_shading = parts.settings.shading
    assembly.volviz_translucent = translucent
    assembly.volviz_lod = parts.lod
    plotter.add_actor(assembly, name=name, reset_camera=False, render=False)
    return assembly


def add_isosurfaces(plotter: pv.BasePlotter, comp: Component, dataset: LoadedDataset, t: Optional[float] = None,
                    spectrum: bool = True, clip: Optional[ClipSettings] = None,
                    meshes: Optional[list[IsoMesh]] = None) -> vtkPropAssembly:
    """The isosurfaces of an ``isosurface`` component as one prop assembly, now: ``isosurface_parts`` (``clip``:
    the scene's clipping; ``meshes``: the extracted surfaces when already known) then ``add_isosurface_actors``."""
    return add_isosurface_actors(plotter, comp.id, isosurface_parts(comp, dataset, t, clip, meshes),
                                 spectrum=spectrum)
