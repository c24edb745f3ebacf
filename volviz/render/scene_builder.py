"""Build what a session (or a single data file) shows into any PyVista plotter: offscreen for export, or the app's.

The VTK side of showing a scene: what a file or session becomes, its datasets and the CPU work that makes no VTK
object are the scene layer's (``volviz.scene``); here the VTK inputs are prepared (``prepare_scene``, any thread) and
the props and views are made (``install_scene``, GUI thread). Only the components a session lists are added.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Optional, Union, cast, overload

from volviz.jobs import ProgressCallback, report
from volviz.model import CurvilinearGrid, Image2D, RegularVolume, TetMesh, TimeSeries, UnstructuredMesh
from volviz.model.stats import histogram
from volviz.model.timeseries import frame_at
from volviz.render.backend import backend_setting, choose_backend, gpu_in_thread, plotter_gl_info
from volviz.render.component_views import IsoSurfacesView, VtkPropView
from volviz.render.decorations import legend_margin
from volviz.render.framing import frame_bounds, nature_bounds, points_bounds, union
from volviz.render.slices import SlicesView
from volviz.render.views import view_class
from volviz.render.vtk_scene import (add_dataset, add_surface, apply_camera, default_transfer_function_for, is_surface,
                                     make_volume, ray_casts_on_cpu, surface_input, volume_grid, volume_input,
                                     volume_prop)
from volviz.scene.datasets import NATURE_TYPES, component_dataset
from volviz.scene.drawn_tf import component_transfer_function, drawn_transfer_function
from volviz.scene.errors import SceneError
from volviz.scene.first_look import first_look
from volviz.scene.isosurfaces import isosurface_parts
from volviz.scene.lod import is_lod, lod_bounds
from volviz.scene.nature import prepare_nature
from volviz.session import Component, Session

if TYPE_CHECKING:   # type-only imports for the signatures
    import pyvista as pv

    from volviz.nature.nature_scene import NatureScene
    from volviz.optics.transfer_function import TransferFunction
    from volviz.render.gl_nature import EitherNatureView
    from volviz.regular.lod import LodTree
    from volviz.render.lod_volume import LodVolume
    from volviz.render.views import ComponentView
    from volviz.model.datasets import Dataset
    from volviz.render.vtk_scene import MapperInput
    from volviz.render.vtk_facade import vtkVolume
    from volviz.scene.datasets import LoadedDataset


def ensure_transfer_functions(session: Session, datasets: dict[str, LoadedDataset]) -> None:
    """Give every volume-like component without a transfer function a default one fitted to its data."""
    for comp in session.components:
        if comp.transfer_function is None and comp.type in ("volume", "mesh", "demo", "slices"):
            if comp.dataset is not None and comp.dataset not in datasets:
                continue  # a hidden component's data is not read: it gets its TF when shown
            if comp.dataset is not None and isinstance(datasets.get(comp.dataset), Image2D):
                continue  # an image shows its own colors (``vtk_scene.add_dataset``)
            name = comp.id
            while name in session.transfer_functions:
                name += "'"
            tf = default_transfer_function_for(component_dataset(comp, datasets), name)
            session.transfer_functions[name] = tf
            comp.transfer_function = name


@dataclass
class PreparedScene:
    """What ``prepare_scene`` computed off the GUI thread for ``install_scene`` (docs/design.md "Background work")."""

    time: Optional[float]                                   # display time of time series (None without one)
    parts: dict[str, Any] = field(default_factory=dict)     # comp id -> IsoParts | TetMesh (PT) | VTK volume input
    cut: dict[str, Any] = field(default_factory=dict)       # PT comp id -> mesh cut by the scene clip (None: all cut)
    histograms: dict[str, Any] = field(default_factory=dict)  # comp id -> (counts, edges) of its data
    nature: Any = None                                      # the NatureScene of the terrain/fog/clouds/sky components
    volumes: dict[str, vtkVolume] = field(default_factory=dict)   # comp id -> made before install (GUI thread)


def prepare_scene(session: Session, datasets: dict[str, LoadedDataset], t: Optional[float] = None,
                  interpolate: bool = True, progress: Optional[ProgressCallback] = None) -> PreparedScene:
    """Any thread: the heavy part of showing ``session`` (default transfer functions, isosurface extraction with
    clipping and LOD chains, tetrahedralisation and mesh topology, VTK volume inputs and time blending at display
    time ``t``, the natural scene's maps and volumes, data histograms). Touches no plotter; ``install_scene`` adds
    the props on the GUI thread."""
    ensure_transfer_functions(session, datasets)
    t = first_look(session, datasets, t)   # a series constant at its first step: from where it varies
    prepared = PreparedScene(time=t)
    shown = [c for c in session.components if c.visible and c.type not in NATURE_TYPES]
    for i, comp in enumerate(shown):
        report(progress, i / max(len(shown) + 1, 1), f"preparing {comp.id}")
        prepare_component(session, comp, datasets, prepared, t, interpolate)
    report(progress, len(shown) / max(len(shown) + 1, 1), "natural scene")
    prepared.nature = prepare_nature(session, datasets)
    report(progress, 1.0, "scene prepared")
    return prepared


def prepare_component(session: Session, comp: Component, datasets: dict[str, LoadedDataset], prepared: PreparedScene,
                      t: Optional[float] = None, interpolate: bool = True) -> None:
    """Any thread: the heavy part of showing one non-nature component (isosurface extraction with clipping and LOD
    chains, tetrahedralisation and topology, the VTK volume input at display time ``t``, its data histogram), put into
    ``prepared``; ``install_component`` adds its prop on the GUI thread. A mesh is tetrahedralised here whichever
    projected tetrahedra draw it (``uses_pt``): volviz's and VTK's draw the same cells."""
    clip = session.clip
    dataset = component_dataset(comp, datasets)
    series = isinstance(dataset, TimeSeries)
    if comp.type == "isosurface":
        if series:  # the 4D blend of the display time (as ``SceneController.set_time`` does)
            comp.settings = {**comp.settings, "interpolate": bool(interpolate)}
        prepared.parts[comp.id] = isosurface_parts(comp, dataset, t if series else None, session.clip)
        return
    if comp.type == "slices":  # cheap planes, made on the GUI thread (``volviz.render.slices``)
        return
    if comp.transfer_function is not None and not is_lod(dataset):
        prepared.histograms[comp.id] = histogram(dataset)
    if is_lod(dataset):
        return
    if uses_pt(dataset):
        from volviz.scene.tetra import cut_tetmesh, pt_mesh   # the tetrahedra's modules: only for meshes (start-up)

        mesh = pt_mesh(display_frame(dataset, t, interpolate))   # a time series: its mesh at display time ``t``
        prepared.parts[comp.id] = mesh
        if clip.all_planes():
            prepared.cut[comp.id] = cut_tetmesh(mesh, clip)
    else:   # arrays: ``frame_input`` makes the mapper's input in ``install_component``, on the GUI thread
        prepared.parts[comp.id] = display_frame(dataset, t, interpolate)


def prepared_volume_input(dataset: Union[Dataset, TimeSeries], t: Optional[float] = None, interpolate: bool = True
                          ) -> Optional[MapperInput]:
    """Any thread: the VTK data object a volume mapper draws for ``dataset`` (a time series: blended at display
    time ``t``, libMini note "4D Visualization"), or None when ``add_dataset`` does not draw it as a volume."""
    if isinstance(dataset, TimeSeries):
        dataset = frame_at(dataset, float(dataset.times[0] if t is None else t), interpolate)
    if isinstance(dataset, Image2D) or is_surface(dataset) or volume_grid(dataset).active_scalars is None:
        return None
    return volume_input(dataset)


@overload
def display_frame(dataset: TimeSeries, t: Optional[float] = None, interpolate: bool = True) -> Dataset: ...


@overload
def display_frame(dataset: LoadedDataset, t: Optional[float] = None, interpolate: bool = True) -> LoadedDataset: ...


def display_frame(dataset: LoadedDataset, t: Optional[float] = None, interpolate: bool = True) -> LoadedDataset:
    """Any thread: ``dataset`` at display time ``t`` as the model has it, arrays and no VTK object: a time series'
    frame there (the blend of the neighbouring steps when interpolating, libMini note "4D Visualization"), else the
    dataset itself. ``frame_input`` makes its VTK object on the GUI thread: a job that makes VTK objects while the
    GUI thread renders can freeze the window for good (issue #28; ``volviz.jobs``)."""
    if isinstance(dataset, TimeSeries):
        return frame_at(dataset, float(dataset.times[0] if t is None else t), interpolate)
    return dataset


def frame_input(dataset: LoadedDataset, frame: Union[Dataset, TimeSeries, None]) -> Optional[MapperInput]:
    """GUI thread: what the VTK prop of ``dataset`` draws for ``frame`` (``display_frame``'s; None: nothing
    prepared): a volume mapper's input (``prepared_volume_input``), a time series' surface (``vtk_scene.surface_input``
    of the frame), or None for what ``add_dataset`` draws its own way (a 2D image, geometry alone)."""
    if frame is None:
        return None
    if isinstance(dataset, TimeSeries):
        if isinstance(dataset.frame(0), Image2D):
            return None
        if is_surface(dataset):
            return surface_input(frame)
    return prepared_volume_input(frame)


def time_input(series: TimeSeries, t: Optional[float] = None, interpolate: bool = True) -> Optional[MapperInput]:
    """Any thread: what a VTK prop of a time series draws at display time ``t`` (default: the first step): a
    volume's mapper input (``prepared_volume_input``, blended) or a surface's (``vtk_scene.surface_input`` of the
    frame at ``t``: points and values blended between steps of one topology); None for what does not follow the
    time (a 2D image)."""
    return frame_input(series, display_frame(series, t, interpolate))


def add_volume_prop(plotter: pv.BasePlotter, dataset: Union[Dataset, TimeSeries], data: Optional[MapperInput],
                    tf: Optional[TransferFunction], opacity: float, name: str, backend: str = "auto",
                    shade: bool = False) -> object:
    """GUI thread: a vtkVolume drawing ``data`` (from ``prepared_volume_input``), the surface of a time series at
    its display time (``data`` from ``time_input``), or (``data`` None) ``add_dataset``'s default visual;
    ``backend``: the render option (``volviz.render.backend``), which picks VTK's GPU or CPU ray caster; ``shade``:
    the component's lighting setting (``vtk_scene.set_volume_shading``; regular volumes only)."""
    if data is None:
        return add_dataset(plotter, dataset, tf=tf, opacity=opacity, name=name)
    if is_surface(dataset):        # a time series' surface at the display time (``time_input``)
        return add_surface(plotter, cast("pv.DataSet", data), tf, opacity, name)   # surface_input's
    if tf is None:   # (ensure_transfer_functions gives every volume one; an image takes add_dataset's way)
        raise SceneError(f"volume {name!r} has no transfer function")
    regular = isinstance(dataset.frame(0) if isinstance(dataset, TimeSeries) else dataset, RegularVolume)
    return volume_prop(plotter, data, regular, tf, opacity, name, backend, shade)


def install_nature(plotter: pv.BasePlotter, scene: Optional[NatureScene], views: bool = True,
                   backend: str = "cpu") -> Optional[EitherNatureView]:
    """GUI thread: a view of a prepared NatureScene (None: none): ``NatureView`` (fog and clouds rendered on the CPU
    as an overlay) or, for ``backend`` "gpu", ``volviz.render.gl_nature.GLNatureView`` (drawn by VTK's OpenGL; see
    ``view_backend``). Its first view is computed now when ``views`` (the app computes it in the background:
    ``begin`` / ``compute`` / ``finish``)."""
    if scene is None:
        return None
    view: EitherNatureView = view_class("nature", backend)(plotter, scene)
    if views:
        view.update()
    return view


def install_scene(plotter: pv.BasePlotter, session: Session, datasets: dict[str, LoadedDataset],
                  prepared: PreparedScene,
                  spectrum: bool = True, views: bool = True) -> dict[str, ComponentView]:
    """GUI thread: add the props of a ``prepare_scene`` result to ``plotter``; returns the view of each component by
    id (``install_component``), and under ``"nature"`` the NatureView that draws the terrain, fog, clouds and sky
    components together. The view-dependent parts (PT volume images, LOD block selections, the natural scene's
    terrain and overlay) are drawn now when ``views``; otherwise they stay empty until the caller updates them (the
    app does that in the background)."""
    props: dict[str, Any] = {}
    pt_components = []
    lod_components = []
    for comp in session.components:
        if not comp.visible or comp.type in NATURE_TYPES:
            continue
        dataset = component_dataset(comp, datasets)
        if comp.type not in ("isosurface", "slices") and is_lod(dataset):
            lod_components.append((comp, dataset))   # selected for the final camera
        elif comp.type not in ("isosurface", "slices") and uses_pt(dataset):
            pt_components.append((comp, prepared.parts[comp.id]))  # drawn last: over the opaque scene's depth
        else:
            props[comp.id] = install_component(plotter, session, comp, datasets, prepared, spectrum, views)
    plotter.set_background(session.render.background)  # type: ignore[arg-type]  # pyvista's _Wrapped decorator
    if session.camera is None:  # framed on every component before the view-dependent parts are drawn

        boxes = [view.bounds() for view in props.values()] + [points_bounds(m.points) for _, m in pt_components]
        boxes += [lod_bounds(d) for _, d in lod_components]
        if prepared.nature is not None:
            boxes.append(nature_bounds(prepared.nature))
        frame_bounds(plotter, union([b for b in boxes if b is not None]),
                     right_margin=legend_margin(session, datasets))
    else:
        apply_camera(plotter, session.camera)
    nature = install_nature(plotter, prepared.nature, views, view_backend(plotter, session, "nature"))
    if nature is not None:
        props["nature"] = nature
    for comp, _ in lod_components + pt_components:
        props[comp.id] = install_component(plotter, session, comp, datasets, prepared, spectrum, views)
    return props


def install_component(plotter: pv.BasePlotter, session: Session, comp: Component, datasets: dict[str, LoadedDataset],
                      prepared: PreparedScene, spectrum: bool = True, views: bool = True) -> ComponentView:
    """GUI thread: add one non-nature component from its ``prepare_component`` result; returns its view
    (``volviz.render.views.ComponentView``: a PT volume, a LOD volume, its isosurfaces, or a VTK prop's view). A PT
    volume's image and a LOD volume's blocks are drawn now when ``views`` (else the caller updates them in the
    background)."""
    dataset = component_dataset(comp, datasets)
    if comp.type == "isosurface":
        return IsoSurfacesView(plotter, comp, prepared.parts[comp.id], spectrum=spectrum)
    if comp.type == "slices":
        return SlicesView(plotter, comp, dataset, component_transfer_function(session, comp))
    if is_lod(dataset):
        return add_lod_component(plotter, session, comp, dataset, update=views)
    if uses_pt(dataset):
        return add_pt_component(plotter, session, comp, prepared.parts[comp.id], update=views,
                                series=isinstance(dataset, TimeSeries))
    made = prepared.volumes.pop(comp.id, None)   # made (and set up) before: ``make_ray_cast_volumes``
    if made is None:
        made = ray_cast_volume(plotter, session, comp, dataset, prepared.parts.get(comp.id))
    if made is not None:
        plotter.add_actor(made, name=comp.id, reset_camera=False, render=False)  # type: ignore[arg-type]  # _Wrapped
        return VtkPropView(made)
    tf = drawn_transfer_function(session, comp, dataset)
    return VtkPropView(add_volume_prop(plotter, dataset, frame_input(dataset, prepared.parts.get(comp.id)), tf,
                                       comp.opacity, comp.id,
                                       backend_setting(session.render.options), bool(comp.settings.get("shade"))))


def make_ray_cast_volumes(plotter: pv.BasePlotter, session: Session, datasets: dict[str, LoadedDataset],
                          prepared: PreparedScene) -> dict[str, vtkVolume]:
    """GUI thread: the vtkVolumes of ``prepared``'s visible components that VTK's CPU ray caster draws in ``plotter``
    (``ray_cast_volume``), made in no renderer and kept in ``prepared.volumes``, which ``install_component`` adds:
    between the two the caller sets them up off the GUI thread (``volviz.render.volume_setup``). Returns them by
    component id."""
    for comp in session.components:
        if comp.visible and comp.id in prepared.parts and comp.id not in prepared.volumes:
            volume = ray_cast_volume(plotter, session, comp, component_dataset(comp, datasets),
                                     prepared.parts[comp.id])
            if volume is not None:
                prepared.volumes[comp.id] = volume
    return dict(prepared.volumes)


def ray_cast_volume(plotter: pv.BasePlotter, session: Session, comp: Component, dataset: LoadedDataset,
                    frame: object) -> Optional[vtkVolume]:
    """GUI thread: the vtkVolume, in no renderer, of a component that ``install_component`` draws as a regular volume
    by VTK's CPU ray caster (``vtk_scene.ray_casts_on_cpu`` for the session's backend in ``plotter``), from its
    prepared ``frame``; None for any other component (isosurfaces, slices, LOD, PT, surfaces, the GPU ray caster)."""
    if comp.type in NATURE_TYPES or comp.type in ("isosurface", "slices") or is_lod(dataset):
        return None
    first = dataset.frame(0) if isinstance(dataset, TimeSeries) else dataset
    if not isinstance(first, RegularVolume) or is_surface(dataset) \
            or not ray_casts_on_cpu(plotter, backend_setting(session.render.options)):
        return None
    tf = drawn_transfer_function(session, comp, dataset)
    data = frame_input(dataset, cast("Union[Dataset, TimeSeries, None]", frame))
    if tf is None or data is None:
        return None
    return make_volume(data, True, tf, comp.opacity, True, bool(comp.settings.get("shade")))


def build_scene(plotter: pv.BasePlotter, session: Session, datasets: dict[str, LoadedDataset],
                spectrum: bool = True) -> dict[str, ComponentView]:
    """Add every visible component to ``plotter`` now (``prepare_scene`` then ``install_scene``)."""
    return install_scene(plotter, session, datasets, prepare_scene(session, datasets), spectrum)


def add_lod_component(plotter: pv.BasePlotter, session: Session, comp: Component, dataset: LodTree,
                      update: bool = True) -> LodVolume:
    """A compressed volume at a view-dependent level of detail (``volviz.render.lod_volume``); the component
    setting ``budget`` is the number of blocks per view (default 256). Its blocks are selected now when ``update``
    (the app selects them in the background: ``select`` / ``decode`` / ``show``)."""
    if session.camera is None:
        lo, hi = dataset.node_box((dataset.levels, (0, 0, 0)))
        plotter.view_isometric(render=False)  # type: ignore[call-arg]  # pyvista's _Wrapped decorator hides self from mypy
        plotter.renderer.ResetCamera(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])
        plotter.camera_set = True
    from volviz.render.lod_volume import LodVolume   # the LOD codec's modules: only for compressed volumes

    lod = LodVolume(plotter, dataset, drawn_transfer_function(session, comp, dataset),
                    budget=int(comp.settings.get("budget", 256)), opacity=comp.opacity)
    if update:
        lod.update()
    return lod


PT_DATASETS = ("TetMesh", "UnstructuredMesh", "CurvilinearGrid")


def uses_pt(dataset: object) -> bool:
    """Unstructured and curvilinear data, and time series of them, are drawn as a PT volume
    (``volviz.render.pt_view``; a series' at its display time): by volviz's pre-integrated projected tetrahedra, or by
    VTK's when the session asks for VTK's own mappers (render method "vtk"); regular volumes go to VTK's ray
    casters."""
    meshes = (TetMesh, UnstructuredMesh, CurvilinearGrid)
    frame = dataset.frame(0) if isinstance(dataset, TimeSeries) else dataset
    return isinstance(frame, meshes) and isinstance(dataset, (TimeSeries, *meshes)) and not is_surface(dataset)


def add_pt_component(plotter: pv.BasePlotter, session: Session, comp: Component, dataset: object,
                     update: bool = True, series: bool = False) -> ComponentView:
    """A PT volume for a component (``volviz.render.pt_view``), with its TF scaled by its opacity: drawn on the GPU
    (``volviz.render.gl_pt``) or the CPU (``volviz.render.pt_prop``) as the render option ``backend`` picks for this
    plotter's OpenGL (``volviz.render.backend``; the exact "reference" method and VTK's projected tetrahedra, "vtk",
    are images made by ``pt_prop``'s view on any OpenGL, as is the mesh of a time ``series``, which each display
    time gives a new mesh: ``SceneController.show_volumes``). A CPU volume's image is rendered now when ``update``
    (the app renders it in the background: ``begin`` / ``compute`` / ``finish``); so is the GPU pass's where it
    draws in a thread of its own (``backend.gpu_in_thread``: ``pt_prop``'s method "pt-gl"), a series' too."""
    tf = drawn_transfer_function(session, comp, dataset)
    if tf is None:   # (ensure_transfer_functions gives every mesh one)
        raise SceneError(f"component {comp.id!r} has no transfer function")
    if comp.opacity != 1.0:
        tf = tf.scaled_extinction(comp.opacity)
    method = session.render.method if session.render.method in ("reference", "vtk") else "pt"
    from volviz.scene.tetra import pt_options   # the tetrahedra's modules: only for meshes (start-up)

    opts = pt_options(session.render.options) if method == "pt" else {}
    gpu = method == "pt" and pt_backend(plotter, session) == "gpu"
    if gpu and gpu_in_thread(session.render.options, plotter_gl_info(plotter)):
        method = "pt-gl"
    elif gpu and not series:
        volume = view_class("pt", "gpu")(plotter, dataset, tf, **{"lookup": "auto", **opts})  # the CPU path's table
        if not update:       # its first draw's arrays made with its first order, in the background
            volume.hold_until_finished()
        return volume
    handle = view_class("pt", "cpu")(plotter, dataset, tf, method=method, scalars=getattr(dataset, "active", None),
                                     **opts)
    if update:
        handle.update()
    return handle


def pt_backend(plotter: pv.BasePlotter, session: Session) -> str:
    """"gpu" or "cpu": where the session's PT volumes are drawn in ``plotter`` (``volviz.render.backend``)."""
    return view_backend(plotter, session, "pt")


def view_backend(plotter: pv.BasePlotter, session: Session, view_kind: str) -> str:
    """"gpu" or "cpu": where the session's views of ``view_kind`` ("pt", "nature", "iso", ...) are drawn in
    ``plotter``, as the render option ``backend`` picks for the plotter's OpenGL (``volviz.render.backend``)."""
    return choose_backend(backend_setting(session.render.options), view_kind, plotter_gl_info(plotter))


def build_nature(plotter: pv.BasePlotter, session: Session, datasets: dict[str, LoadedDataset]
                 ) -> Optional[EitherNatureView]:
    """The NatureView of the session's visible terrain / fog / clouds / sky components (None when it has none)."""
    return install_nature(plotter, prepare_nature(session, datasets), backend=view_backend(plotter, session, "nature"))
