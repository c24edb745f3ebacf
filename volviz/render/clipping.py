"""Scene-wide clipping planes and box crop (libMini note, Fig. 6) applied to every kind of prop a scene shows, so
volumes, isosurfaces and unstructured meshes are cut alike. The settings are ``session.clip`` (a
``volviz.model.clip.ClipSettings``: a plane keeps ``(x − point)·normal ≥ 0``, the box keeps ``lo ≤ x ≤ hi``).

How each prop honours them:

- regular volumes (vtkSmartVolumeMapper → GPU ray caster): mapper clipping planes, evaluated per ray sample in the
  ray caster's shader (any number of planes; the box is six more);
- VTK's projected tetrahedra (vtkProjectedTetrahedraMapper ignores clipping planes): its input is cut exactly and
  re-tetrahedralised (``volviz.iso.clip.clip_grid``);
- volviz PT volumes: the tetrahedral mesh is cut exactly (``clip_tetmesh``) and re-rendered by the caller;
- isosurfaces: the triangles are cut exactly (``clip_isosurfaces``, in ``volviz.scene.isosurfaces.isosurface_parts``);
- any other actor (surfaces, height fields): mapper clipping planes, which OpenGL honours for at most
  ``MAX_GL_PLANES`` planes; further planes are left out with a logged warning.
"""
from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Optional

from volviz.iso.clip import clip_grid
from volviz.model.clip import ClipPlane, ClipSettings

if TYPE_CHECKING:   # type-only: VTK's classes, reached through the facade at run time
    from volviz.render.vtk_facade import vtkAbstractMapper, vtkDataObject, vtkPlane, vtkProp

log = logging.getLogger(__name__)

MAX_GL_PLANES = 6


def vtk_plane(plane: ClipPlane) -> vtkPlane:
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    p = vtk.vtkPlane()
    p.SetOrigin(*plane.point)
    p.SetNormal(*plane.normal)  # VTK's mappers keep the side the normal points to, as ClipPlane does
    return p


def set_mapper_planes(mapper: vtkAbstractMapper, planes: list[ClipPlane], limit: int | None = None) -> None:
    """Replace a mapper's clipping planes (``limit``: the most the mapper can honour)."""
    mapper.RemoveAllClippingPlanes()
    if limit is not None and len(planes) > limit:
        log.warning("this surface honours only %d clipping planes; %d more are ignored", limit, len(planes) - limit)
        planes = planes[:limit]
    for p in planes:
        mapper.AddClippingPlane(vtk_plane(p))
    mapper.Modified()  # else a screenshot re-uses the previous frame


def clip_vtk_prop(prop: vtkProp, clip: ClipSettings,
                  source: Optional[vtkDataObject] = None) -> Optional[vtkDataObject]:
    """Apply ``clip`` to a VTK prop of a scene; returns the original (uncut) mapper input to keep for the next change.

    ``source``: the uncut input kept from an earlier call (tetrahedral volumes are cut on the CPU from it).
    """
    planes = clip.all_planes()
    mapper = prop.GetMapper() if hasattr(prop, "GetMapper") else None
    if mapper is None:
        return source
    if mapper.IsA("vtkProjectedTetrahedraMapper") or mapper.IsA("vtkUnstructuredGridVolumeMapper"):
        if source is None:
            source = mapper.GetInputDataObject(0, 0)
        mapper.SetInputData(clip_grid(source, planes) if planes else source)
        return source
    set_mapper_planes(mapper, planes, None if prop.IsA("vtkVolume") else MAX_GL_PLANES)
    return source
