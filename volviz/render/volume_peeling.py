"""Translucent isosurfaces inside a regular volume drawn by VTK (libMini note "Isosurfaces": the surfaces are seen
through the volume, "volume behind, surface, volume in front" along each ray; Guthe §4.5: a ray is composited with
the geometry it meets at that geometry's depth).

VTK draws translucent polygonal geometry before its volumes and without depth writes, so a ray caster ignores a
translucent surface and adds its whole ray, the part behind the surface included, over it: an isosurface at 120 of
neghip with opacity 0.3 changed 0.20 % of a 512 x 384 frame by more than 3 levels (4.0 % at opacity 1, whatever the
colour). ``peel_volumes`` turns on VTK's dual depth peeling with volumes (``vtkDualDepthPeelingPass``): each peel
interleaves the volume's ray segments between the peeled layers, so the surface lies between the volume behind it
and in front of it; the same frame then changes 2.9 % of its pixels. Peeling handles only the GPU ray caster (the
CPU one under peeling drew garbage tiles on llvmpipe), so the regular volumes are drawn by it while peeling is on
and go back to the ray caster they had when it is off. Measured costs on llvmpipe: docs/bench/volume_peeling.md.

A renderer with a custom render pass (``volviz.render.gl.ScenePass``: a GPU PT volume or natural scene) does not peel;
peeling is not turned on there.
"""
from __future__ import annotations

import weakref
from typing import TYPE_CHECKING, Any, Sequence, cast

if TYPE_CHECKING:   # type-only imports for the signatures
    import pyvista as pv
    from volviz.render.vtk_facade import vtkProp, vtkVolume

__all__ = ["PEELS", "peel_volumes", "peeling_volumes", "regular_volumes"]

PEELS = 16          # dual-peeling passes at most (two layers each); with occlusion ratio 0 VTK stops when none is left
#: by plotter while peeling is on: the renderer's settings and the volumes' ray casters (by mapper) to restore
_saved: weakref.WeakKeyDictionary[Any, dict[str, Any]] = weakref.WeakKeyDictionary()


def regular_volumes(props: Sequence[vtkProp]) -> list[vtkVolume]:
    """The props that VTK's smart volume mapper draws (volviz's regular volumes)."""
    volumes: list[vtkVolume] = [cast("vtkVolume", p) for p in props if p is not None and p.IsA("vtkVolume")]
    return [v for v in volumes if v.GetMapper() is not None and v.GetMapper().IsA("vtkSmartVolumeMapper")]


def peeling_volumes(plotter: pv.BasePlotter) -> bool:
    """Whether ``peel_volumes`` has peeling on in ``plotter``."""
    return plotter in _saved


def peel_volumes(plotter: pv.BasePlotter, props: Sequence[vtkProp], on: bool, peels: int = PEELS) -> bool:
    """Depth-peel the translucent geometry of ``plotter``'s renderer together with the regular volumes among
    ``props`` when ``on`` (the caller: translucent surfaces are shown by VTK) and there are such volumes and the
    renderer runs VTK's own passes; otherwise restore what was set before. Returns whether peeling is on."""
    ren = plotter.renderer
    volumes = regular_volumes(props)
    on = bool(on) and bool(volumes) and ren.GetPass() is None
    saved = _saved.get(plotter)
    if on:
        if saved is None:
            saved = _saved[plotter] = {
                "renderer": (ren.GetUseDepthPeeling(), ren.GetUseDepthPeelingForVolumes(),
                             ren.GetMaximumNumberOfPeels(), ren.GetOcclusionRatio()),
                "modes": {}}
        modes: dict[Any, int] = saved["modes"]
        for volume in volumes:
            mapper: Any = volume.GetMapper()     # a vtkSmartVolumeMapper (``regular_volumes``)
            modes.setdefault(mapper, int(mapper.GetRequestedRenderMode()))
            if mapper.GetRequestedRenderMode() != mapper.GPURenderMode:
                mapper.SetRequestedRenderModeToGPU()
        ren.SetUseDepthPeeling(True)
        ren.SetUseDepthPeelingForVolumes(True)
        ren.SetMaximumNumberOfPeels(int(peels))
        ren.SetOcclusionRatio(0.0)
        return True
    if saved is not None:
        del _saved[plotter]
        peel, for_volumes, n, ratio = saved["renderer"]
        if ren.GetPass() is None:      # a scene pass installed meanwhile keeps its own setting (peeling off)
            ren.SetUseDepthPeeling(peel)
        ren.SetUseDepthPeelingForVolumes(for_volumes)
        ren.SetMaximumNumberOfPeels(n)
        ren.SetOcclusionRatio(ratio)
        for mapper, mode in saved["modes"].items():
            mapper.SetRequestedRenderMode(mode)
    return False
