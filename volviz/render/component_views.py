"""The views of the components that VTK draws with its own props, behind the calls ``SceneController`` makes of every
component's view (``volviz.render.views.ComponentView``): a volume drawn by VTK's ray casters (or its projected
tetrahedra for a time series of meshes), a surface, and the surfaces of an isosurface component (libMini note §3-4:
extracted once, cut exactly by the scene's clipping and scaled by the component's opacity on the CPU, drawn by VTK;
a transparency mode of the note draws their translucent part through the scene-wide iso view).

volviz's own views (``volviz.render.pt_view.PTView``, ``volviz.render.lod_volume.LodVolume``) answer the same calls
themselves.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Optional

from volviz.render.framing import Bounds, points_bounds, prop_bounds, union
from volviz.render.vtk_scene import update_volume_property
from volviz.scene.isosurfaces import isosurface_parts

if TYPE_CHECKING:   # type-only imports for the signatures
    from volviz.iso.extract import IsoMesh
    from volviz.jobs import ProgressCallback
    from volviz.model.clip import ClipSettings
    from volviz.optics.transfer_function import TransferFunction
    from volviz.scene.isosurfaces import IsoParts

__all__ = ["IsoSurfacesView", "VtkPropView"]


class VtkPropView:
    """A component VTK draws with its own mapper (``prop``: a vtkVolume or an actor). Clipping: the mapper's clipping
    planes, or an exact cut of a tetrahedral input kept uncut here (``volviz.render.clipping.clip_vtk_prop``)."""

    kind = "vtk"
    camera_dependent = False  # VTK draws it for any camera

    def __init__(self, prop: Any) -> None:
        self.prop = prop
        self._uncut: Any = None
        self.stats: dict[str, Any] = {}

    @property
    def backend(self) -> str:
        mapper = self.prop.GetMapper() if hasattr(self.prop, "GetMapper") else None
        return "cpu" if mapper is not None and mapper.IsA("vtkFixedPointVolumeRayCastMapper") else "gpu"

    @property
    def visible(self) -> bool:
        return bool(self.prop.GetVisibility())

    @visible.setter
    def visible(self, on: bool) -> None:
        self.prop.SetVisibility(bool(on))

    def set_tf(self, tf: Optional[TransferFunction], opacity: float = 1.0) -> None:
        """A volume's color and opacity functions, or a surface's opacity."""
        if self.prop.IsA("vtkVolume"):
            if tf is None:
                return

            update_volume_property(self.prop.GetProperty(), tf, opacity)
        else:
            self.prop.GetProperty().SetOpacity(float(opacity))

    def set_clip(self, clip: ClipSettings) -> bool:
        """Clip by ``volviz.model.clip.ClipSettings`` at once (True: nothing for the caller to cut)."""
        # heavy: the clip's Numba kernels and SciPy, loaded only when a component is clipped
        from volviz.render.clipping import clip_vtk_prop

        self._uncut = clip_vtk_prop(self.prop, clip, self._uncut)
        return True

    def set_input(self, data: object, clip: ClipSettings) -> None:
        """A new mapper input (a time series' volume at a new display time), cut by ``clip``."""
        self._uncut = None
        self.prop.GetMapper().SetInputData(data)
        if clip.all_planes():
            self.set_clip(clip)

    def update(self) -> dict[str, object]:
        """Nothing to re-make: VTK draws it at every render."""
        return {}

    def bounds(self) -> Optional[Bounds]:
        return prop_bounds(self.prop)

    def remove(self) -> None:
        """The plotter's ``clear`` removes the prop."""


class IsoSurfacesView(VtkPropView):
    """The surfaces of an isosurface component (``volviz.scene.isosurfaces.IsoParts``) as VTK actors (``prop``: a
    vtkPropAssembly, ``add_isosurface_actors``). A new clipping or opacity is a new cut of the extracted surfaces:
    ``cut(clip)`` on any thread, ``show_cut(parts)`` here (or ``update`` does both now)."""

    kind = "isosurfaces"
    camera_dependent = False  # the transparency modes draw them through the scene-wide iso view

    def __init__(self, plotter: Any, comp: Any, parts: Any, spectrum: bool = True) -> None:
        super().__init__(None)
        self.plotter, self.comp, self.spectrum = plotter, comp, spectrum
        self.parts = parts
        self.clip = parts.clip
        self.show(parts)

    @property
    def meshes(self) -> list[IsoMesh]:
        """The extracted, uncut surfaces."""
        return list(self.parts.meshes)

    def set_tf(self, tf: Optional[TransferFunction], opacity: float = 1.0) -> None:
        """The surfaces keep their own colors; an opacity other than the shown cut's makes it stale (``update``)."""

    def set_clip(self, clip: ClipSettings) -> bool:
        """Keep ``clip`` for the next cut; True when the shown cut already is of it and of the current opacity."""
        self.clip = clip
        return not self.stale()

    def stale(self) -> bool:
        return self.parts.clip != self.clip or self.parts.opacity != float(self.comp.opacity)

    def cut(self, clip: Optional[ClipSettings] = None, meshes: Optional[list[IsoMesh]] = None,
            progress: Optional[ProgressCallback] = None) -> IsoParts:
        """Any thread: the surfaces (``meshes``, default the extracted ones) cut by ``clip`` (default: the last
        ``set_clip``), scaled by the component's opacity, with their LOD chains."""
        return isosurface_parts(self.comp, meshes=self.meshes if meshes is None else list(meshes),
                                clip=self.clip if clip is None else clip)

    def show_cut(self, parts: IsoParts, visible: bool = True) -> None:
        """GUI thread: show a ``cut`` (new actors, not rendered)."""
        self.show(parts)
        self.visible = visible

    def show(self, parts: IsoParts) -> None:
        if self.prop is not None:
            self.plotter.remove_actor(self.prop, render=False)
        self.parts = parts
        from volviz.render.iso_actors import add_isosurface_actors  # volviz.iso: only for isosurfaces (start-up)

        self.prop = add_isosurface_actors(self.plotter, self.comp.id, parts, spectrum=self.spectrum)

    def update(self) -> dict[str, object]:
        """Cut again now when the clipping or the opacity changed."""
        if self.stale():
            self.show_cut(self.cut(), self.visible)
        return {}

    def bounds(self) -> Optional[Bounds]:
        return union([points_bounds(m.points) for m in self.parts.meshes if len(m.points)])

    def remove(self) -> None:
        self.plotter.remove_actor(self.prop, render=False)
