"""The regular volumes of a scene split at the nearest translucent isosurface, for the CPU transparency modes of the
libMini note §4 drawn with a VTK volume in the scene (issue #28; libMini note "Isosurfaces": along each ray the
volume behind the surfaces, the surfaces and the volume in front composite in that order).

The overlay of ``volviz.render.iso_overlay`` is the modes' premultiplied image I (alpha α = 1 − T, T = Π(1 − α_i)
the surfaces' transmission in every mode) drawn over the rendered scene F, C = I + T·F: the whole volume lies under
the surfaces. With V_f, a_f the volume from the eye to the nearest translucent fragment (premultiplied colour and
alpha) and F = V_f + (1 − a_f)·B (B: the volume behind it and everything further), the composite "volume in front,
surfaces, volume behind" is

    C = V_f + (1 − a_f)·I + T·(F − V_f) = I' + T·F,   I' = (1 − a_f)·I + α·V_f,

an overlay of the same alpha (I' ≤ α where I ≤ α), so only the overlay's image changes. It is exact when a ray
meets one translucent layer (every mode: a plane through a ball, RMSE 0.42 levels against the exact composite of the
scene's own renders, tests/test_iso_modes_volume.py; 27 with the surface over the whole volume). The volume between
two layers is composited behind both: two parallel planes through the ball's dense middle, exact mode, RMSE 8.0
against the exact composite with the volume between them (24 for the surfaces over the whole volume); splitting at
every layer would take one more volume render per layer. The GPU's exact mode peels the surfaces with the volume
instead (``volviz.render.gl_iso``: 0.57 there), so the scene controller draws only the 2/3/4-pass modes this way
when the GPU backend is chosen.

``FrontVolume`` renders V_f, a_f with VTK itself, so that they match the scene's own volume (the same mapper
settings, property, camera and lights; the same pixels as the scene's window gives): the regular volumes alone, the
translucent surfaces drawn as an opaque occluder that writes depth and the colour (0, 0, 0, 0) over a transparent
black background; VTK's ray casters (CPU and GPU) stop at that depth and blend their premultiplied colour and alpha
over it. One more volume render per overlay image (docs/bench/iso_modes_with_volume.md), in an offscreen window of a
thread of its own, off the GUI thread (docs/bench/iso_split_off_gui_thread.md).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from volviz.render.gl_thread import GLThread, GLThreadClosed
from volviz.render.image_overlay import read_premultiplied
from volviz.render.volume_peeling import regular_volumes

if TYPE_CHECKING:   # type-only imports for the signatures
    import pyvista as pv

    from volviz.iso.extract import IsoMesh
    from volviz.render.vtk_facade import vtkActor, vtkRenderer, vtkVolume

__all__ = ["FrontScene", "FrontVolume", "SurfaceOccluder", "in_volume", "shown_regular_volumes"]

# depth only: colour and alpha 0, written after VTK's test that discards fragments of alpha 0
_WRITE_NOTHING = "gl_FragData[0] = vec4(0.0);\n  //VTK::Picking::Impl"


def shown_regular_volumes(renderer: vtkRenderer) -> list[vtkVolume]:
    """The visible props of ``renderer`` that VTK's smart volume mapper draws (volviz's regular volumes)."""
    props = renderer.GetViewProps()
    items: list[Any] = [props.GetItemAsObject(i) for i in range(props.GetNumberOfItems())]
    return [v for v in regular_volumes(items) if v.GetVisibility()]


def _occluder(meshes: Sequence[IsoMesh]) -> vtkActor:
    """One opaque actor of ``meshes`` that writes depth and the colour (0, 0, 0, 0)."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    append = vtk.vtkAppendPolyData()
    for m in meshes:
        if m.n_triangles:
            append.AddInputData(m.to_pyvista())
    append.Update()
    mapper = vtk.vtkOpenGLPolyDataMapper()
    mapper.SetInputData(append.GetOutput())
    mapper.ScalarVisibilityOff()
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    actor.GetProperty().LightingOff()
    actor.GetShaderProperty().AddFragmentShaderReplacement("//VTK::Picking::Impl", False, _WRITE_NOTHING,
                                                           False)
    return actor


class SurfaceOccluder:
    """The occluder of an overlay's translucent surfaces (``actor``), made again only when the meshes change (the
    overlay passes the same meshes for every image)."""

    def __init__(self) -> None:
        self._meshes: list[IsoMesh] = []
        self._actor: vtkActor | None = None

    def actor(self, meshes: Sequence[IsoMesh]) -> vtkActor:
        same = len(meshes) == len(self._meshes) and all(a is b for a, b in zip(meshes, self._meshes))
        if self._actor is None or not same:
            self._meshes, self._actor = list(meshes), _occluder(meshes)
        return self._actor


@dataclass
class FrontScene:
    """What ``FrontVolume.render`` draws, taken on the GUI thread by ``FrontVolume.snapshot``: the window's size, the
    renderer's viewport, copies of its camera and lights, the shown regular volumes (per volume its mapper's input
    and settings, a copy of its property and its matrix) and the translucent surfaces."""

    size: tuple[int, int]
    viewport: tuple[float, ...]
    camera: Any
    lights: list[Any]
    two_sided: bool
    volumes: list[tuple[int, Any, dict[str, Any], Any, Any]]
    meshes: list[IsoMesh]


#: the smart mapper's settings that change its picture, copied to the offscreen volume (Get/Set pairs)
_MAPPER_SETTINGS = ("RequestedRenderMode", "BlendMode", "InterpolationMode", "SampleDistance",
                    "AutoAdjustSampleDistances", "InteractiveAdjustSampleDistances", "InteractiveUpdateRate",
                    "FinalColorWindow", "FinalColorLevel", "Cropping", "CroppingRegionFlags", "CroppingRegionPlanes",
                    "GlobalIlluminationReach", "VolumetricScatteringBlending")


def _copy_planes(mapper: Any) -> list[Any]:
    """Copies of ``mapper``'s clipping planes."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    planes = mapper.GetClippingPlanes()
    out = []
    for i in range(planes.GetNumberOfItems() if planes is not None else 0):
        src, dst = planes.GetItemAsObject(i), vtk.vtkPlane()
        dst.SetOrigin(src.GetOrigin())
        dst.SetNormal(src.GetNormal())
        out.append(dst)
    return out


class FrontVolume:
    """The shown regular volumes of a plotter from the eye to the nearest translucent surface, rendered in an
    offscreen window of a thread of its own (``volviz.render.gl_thread``; the module docstring says how): the GUI
    thread only takes a ``snapshot`` (copies of the camera, lights and volume properties); ``render`` draws it from
    any thread, so the GUI thread no longer draws it after every camera change
    (``docs/bench/iso_split_off_gui_thread.md``). ``close`` ends the thread."""

    def __init__(self) -> None:
        self.gl = GLThread("volviz-front-volume")

    def snapshot(self, plotter: pv.BasePlotter, meshes: Sequence[IsoMesh]) -> FrontScene | None:
        """GUI thread: what ``render`` needs of ``plotter``'s scene now; None when it shows no regular volume or
        ``meshes`` (the translucent surfaces) no triangle."""
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk

        ren = plotter.renderer
        shown = shown_regular_volumes(ren)
        if not shown or not any(m.n_triangles for m in meshes):
            return None
        camera = vtk.vtkCamera()
        camera.DeepCopy(ren.GetActiveCamera())
        lights = []
        for light in (ren.GetLights().GetItemAsObject(i) for i in range(ren.GetLights().GetNumberOfItems())):
            copy = light.NewInstance()
            copy.DeepCopy(light)
            lights.append(copy)
        volumes = []
        for v in shown:
            mapper = v.GetMapper()
            settings = {k: getattr(mapper, f"Get{k}")() for k in _MAPPER_SETTINGS if hasattr(mapper, f"Get{k}")}
            settings["planes"] = _copy_planes(mapper)
            prop = vtk.vtkVolumeProperty()
            prop.DeepCopy(v.GetProperty())
            matrix = vtk.vtkTransform()
            matrix.SetMatrix(v.GetMatrix())     # a copy of the prop's matrix, which the GUI thread goes on changing
            volumes.append((id(v), mapper.GetInputDataObject(0, 0), settings, prop, matrix))
        w, h = (int(s) for s in ren.GetRenderWindow().GetSize())
        return FrontScene((w, h), tuple(ren.GetViewport()), camera, lights, bool(ren.GetTwoSidedLighting()),
                          volumes, list(meshes))

    def render(self, scene: FrontScene) -> np.ndarray | None:
        """Any thread: ``scene``'s volumes in front of its surfaces as premultiplied float RGBA (H, W, 4), row 0 at
        the top, in 8-bit steps (drawn on the window's thread); None once ``close``d (the overlay was removed: an
        image of a request begun before is not shown)."""
        try:
            return self.gl.call(_draw, self.gl.state, scene)
        except GLThreadClosed:
            return None

    def close(self) -> None:
        """End the thread, its window closed there after the drawing in progress, without waiting for it (the caller
        is the GUI thread, removing the overlay)."""
        self.gl.close(wait=False)


def _draw(ren: vtkRenderer, state: dict[str, Any], scene: FrontScene) -> np.ndarray:
    """On the window's thread: bring ``ren`` to ``scene`` (the volumes made or updated, the occluder of the surfaces,
    the camera and lights), render and read back."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    kept: dict[int, Any] = state.setdefault("volumes", {})
    for key in set(kept) - {v[0] for v in scene.volumes}:
        ren.RemoveVolume(kept.pop(key))
    for key, data, settings, prop, matrix in scene.volumes:
        volume = kept.get(key)
        if volume is None:
            volume = kept[key] = vtk.vtkVolume()
            volume.SetMapper(vtk.vtkSmartVolumeMapper())
            ren.AddVolume(volume)
        mapper = volume.GetMapper()
        if mapper.GetInputDataObject(0, 0) is not data:
            mapper.SetInputData(data)
        for k, value in settings.items():
            if k != "planes" and getattr(mapper, f"Get{k}")() != value:
                getattr(mapper, f"Set{k}")(value)
        mapper.RemoveAllClippingPlanes()
        for plane in settings["planes"]:
            mapper.AddClippingPlane(plane)
        volume.SetProperty(prop)
        volume.SetUserTransform(matrix)
    occluder: SurfaceOccluder = state.setdefault("occluder", SurfaceOccluder())
    actor = occluder.actor(scene.meshes)
    if state.get("actor") is not actor:
        if state.get("actor") is not None:
            ren.RemoveActor(state["actor"])
        ren.AddActor(actor)
        state["actor"] = actor
    ren.SetViewport(*scene.viewport)
    camera = ren.GetActiveCamera()
    camera.DeepCopy(scene.camera)
    camera.Modified()           # DeepCopy keeps the time stamp: VTK's CPU ray caster would re-use its last image
    ren.AutomaticLightCreationOff()
    ren.RemoveAllLights()
    for light in scene.lights:
        ren.AddLight(light)
    ren.SetTwoSidedLighting(scene.two_sided)
    ren.SetBackground(0.0, 0.0, 0.0)
    ren.SetBackgroundAlpha(0.0)
    window = ren.GetRenderWindow()
    w, h = scene.size
    if tuple(window.GetSize()) != (w, h):
        window.SetSize(w, h)
    window.Render()
    return read_premultiplied(window, w, h)


def in_volume(image: np.ndarray, front: np.ndarray | None) -> np.ndarray:
    """The modes' premultiplied overlay ``image`` (H, W, 4) with the volume in front of the surfaces, ``front``
    (``FrontVolume.render``, the same size), over it and the volume behind under it: I' = (1 − a_f)·I + α·V_f (module
    docstring); ``image`` itself when ``front`` is None."""
    if front is None:
        return image
    out = image * (1.0 - front[..., 3:4])
    out[..., :3] += image[..., 3:4] * front[..., :3]
    out[..., 3] = image[..., 3]
    return out
