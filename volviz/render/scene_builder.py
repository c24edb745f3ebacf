"""Build what a session (or a single data file) shows into any PyVista plotter: offscreen for export, or the app's.

Only the components a session lists are loaded and added (DESIGN.md "Model only what a scene needs"); datasets shared
by several components are read once.
"""
from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional

import numpy as np

from volviz.io.folders import MIN_SERIES_FILES, numbered_pattern
from volviz.jobs import ProgressCallback, report
from volviz.model.applicability import DatasetTraits
from volviz.render.backend import backend_setting
from volviz.session import (Component, DatasetRef, RenderSettings, Session, SessionError, missing_files,
                            missing_message, resolve_path)


class SceneError(Exception):
    """A session that cannot be shown: names the component and the problem."""




def series_pattern(path: str | os.PathLike) -> Optional[str]:
    """``Storm.pvm-t%02d`` for ``Storm.pvm-t01`` when at least three numbered siblings exist (opened as one time
    series, as ParaView groups numbered files); None otherwise, and for folders and for files whose reader reads
    them with their siblings (``ReaderSpec.reads_siblings``: the slices of a DICOM series)."""
    p = Path(path)
    if not p.is_file() or _reads_siblings(p):
        return None
    match = re.search(r"(\d+)(?!.*\d)", p.name)
    if match is None:
        return None
    head, tail = p.name[:match.start()], p.name[match.end():]
    rx = re.compile(re.escape(head) + r"(\d+)" + re.escape(tail) + r"\Z")
    try:
        siblings = [name for name in os.listdir(p.parent) if rx.match(name)]
    except OSError:
        return None
    if len(siblings) < MIN_SERIES_FILES:
        return None
    numbers = [rx.match(name).group(1) for name in siblings]  # type: ignore[union-attr]
    return str(p.parent.resolve() / numbered_pattern(head, numbers, tail))


def _shown_in_folder(path: str | os.PathLike) -> str | os.PathLike:
    """A folder that no reader opens itself shows its collection file, or the first file of its largest numbered
    series (``volviz.io.folders``); anything else is shown as it is."""
    from volviz.io import ReadError
    from volviz.io.folders import folder_target
    from volviz.io.registry import spec_of
    from volviz.io.series import expand_pattern

    if not Path(path).is_dir():
        return path
    try:
        spec_of(path)
        return path
    except ReadError:
        target = folder_target(path)
    if target is None:
        return path                           # reading it says why it does not open
    return expand_pattern(target)[0][1] if "%" in Path(target).name else target


def _reads_siblings(path: Path) -> bool:
    from volviz.io import ReadError
    from volviz.io.registry import spec_of

    try:
        return spec_of(path).reads_siblings
    except ReadError:
        return False


def data_session(path: str | os.PathLike, q: Optional[str | os.PathLike] = None) -> Session:
    """A one-dataset session that shows ``path`` with its default visual (what opening a data file does): a file of a
    numbered series opens the whole series at that file's time step; a height map (DEM, PGM) opens as a terrain
    under a sky (``terrain_session``); a PLOT3D grid opens with the solution file ``q`` (default: the one named like
    it), and a PLOT3D solution file opened alone opens with the grid named like it (a ReadError says what to do
    when there is none)."""
    from volviz.io.plot3d_pairs import grid_of_solution, is_plot3d_solution

    path = _shown_in_folder(path)
    if is_height_map(path):
        return terrain_session(path)
    if q is None and Path(path).is_file() and is_plot3d_solution(path):
        grid = grid_of_solution(path)
        if grid is None:
            from volviz.io import ReadError

            raise ReadError(path, "is a PLOT3D solution (q) file, and no grid (xyz) file named like it is beside it",
                            "open it together with its grid file: select both files in the Open dialog (on the "
                            "command line: GRID --q SOLUTION)")
        path, q = grid, path
    pattern = series_pattern(path)
    ref = DatasetRef(id="data", path=pattern or str(Path(path).resolve()))
    if q is not None:
        ref.options["q"] = str(Path(q).resolve())
    if Path(path).suffix.lower() == ".vvz" and vvz_voxels(path) > LOD_VOXELS:
        ref.options["lod"] = True          # too large to decode whole: blocks per view (volviz.render.lod_volume)
    session = Session(datasets=[ref], components=[Component(id="data", type="volume", dataset="data")])
    if pattern is not None:
        from volviz.io.series import member_time

        t = member_time(pattern, path)
        if t is not None:
            session.render.options["time"] = t   # the session's display time (``SceneController.prepare``)
    return session


HEIGHT_MAP_SUFFIXES = (".dem", ".pgm")
RELIEF = 0.1        # a grey-level height map opened directly rises to at most 1/10 of its width


def is_height_map(path: str | os.PathLike) -> bool:
    """Whether opening ``path`` should show a terrain: a USGS DEM, a grey PGM (not part of a numbered series), an
    SRTM tile or a single-band GeoTIFF (``volviz.io.elevation``)."""
    from volviz.io.elevation import is_elevation_model

    p = Path(path)
    if p.suffix.lower() in HEIGHT_MAP_SUFFIXES and p.is_file() and series_pattern(p) is None:
        return True
    return is_elevation_model(p)


def terrain_session(path: str | os.PathLike) -> Session:
    """A height map (DEM, GeoTIFF or SRTM tile in metres, PGM in grey levels) as a natural scene: its C-LOD terrain
    under a sky, moved to the origin; a PGM's grey levels are scaled so that its relief is at most ``RELIEF`` of its
    width (the others keep their true heights)."""
    from volviz.io import read

    image = read(path)
    settings: dict[str, Any] = {"origin": [0.0, 0.0]}
    if Path(path).suffix.lower() == ".pgm":
        rows, cols = image.data.shape[:2]
        lo, hi = image.scalar_range()
        span = hi - lo if np.isfinite(hi - lo) and hi > lo else 1.0
        settings["height_scale"] = min(1.0, RELIEF * max(rows, cols) / span)
    ref = DatasetRef(id="height_map", path=str(Path(path).resolve()))
    return Session(datasets=[ref], components=[Component(id="terrain", type="terrain", dataset="height_map",
                                                         settings=settings),
                                               Component(id="sky", type="sky")],
                   render=RenderSettings(background=(0.78, 0.85, 0.95)))


#: compressed volumes with more voxels than this open at a view-dependent level of detail instead of being decoded
LOD_VOXELS = 256 ** 3


def vvz_voxels(path: str | os.PathLike) -> int:
    """Number of voxels of a ``.vvz`` file, from its header (nothing is decoded)."""
    from volviz.regular.nodes import NodeDecoder

    return int(np.prod(NodeDecoder(os.fspath(path)).dims))


def demo_session() -> Session:
    """The built-in procedural natural scene (fractal terrain, Perlin ground fog and clouds, sky), generated at
    start-up from no files."""
    from volviz.render.demo import demo_components
    from volviz.session import CameraState

    camera = CameraState(position=(500.0, -150.0, 330.0), focal_point=(500.0, 600.0, 80.0), view_up=(0.0, 0.0, 1.0),
                         view_angle=60.0)
    return Session(components=demo_components(), camera=camera,
                   render=RenderSettings(size=(1024, 768), background=(0.78, 0.85, 0.95)))


def demo_volume_session() -> Session:
    """A tetrahedralised cube carrying an analytic field (``volviz render demo-volume``)."""
    return Session(components=[Component(id="demo", type="demo", settings={"cells_per_edge": 20})])


def load_datasets(session: Session, session_file: Optional[str | os.PathLike],
                  progress: Optional[ProgressCallback] = None,
                  loaded: Optional[dict[str, Any]] = None, also: tuple[str, ...] = ()) -> dict[str, Any]:
    """Read every dataset that a visible component (or a component in ``also``) uses, once each, with progress;
    those already in ``loaded`` are kept (the dict is filled in and returned)."""
    from volviz.nature.nature_scene import nature_dataset_ids

    used = {c.dataset for c in session.components if (c.visible or c.id in also) and c.dataset is not None}
    used |= nature_dataset_ids([c for c in session.components if c.visible and c.type in NATURE_TYPES])
    loaded = {} if loaded is None else loaded
    refs = [ref for ref in session.datasets if ref.id in used and ref.id not in loaded]
    missing = missing_files(session, session_file, {ref.id for ref in refs})
    if missing:  # each one named at once, before any is read
        raise SessionError(session_file, missing_message(missing), field="datasets")
    for i, ref in enumerate(refs):
        report(progress, i / max(len(refs), 1), f"reading {Path(ref.path).name}")
        path = resolve_path(session_file, ref.path) if session_file else Path(ref.path)
        loaded[ref.id] = read_any(path, ref.options, progress)
    report(progress, 1.0, "datasets read")
    return loaded


def component_dataset(comp: Component, datasets: dict[str, Any]) -> Any:
    """The dataset a component shows: generated for the demo, else the loaded dataset it names."""
    if comp.type == "demo":
        from volviz.model.demo import demo_tet_mesh

        key = f"demo:{int(comp.settings.get('cells_per_edge', 20))}"
        if key not in datasets:
            datasets[key] = demo_tet_mesh(int(comp.settings.get("cells_per_edge", 20)))
        return datasets[key]
    if comp.dataset is None:
        raise SceneError(f"component {comp.id!r} ({comp.type}) names no dataset")
    if comp.type in NATURE_TYPES:
        return datasets[comp.dataset]
    try:
        return shown_array(datasets[comp.dataset], comp.settings.get("array"))
    except ValueError as exc:
        raise SceneError(f"component {comp.id!r}: {exc}") from None


def shown_array(dataset: Any, spec: Optional[str]) -> Any:
    """``dataset`` showing the array ``spec`` (None: its default array; ``volviz.model.arrays``), made once per spec
    and kept on the dataset, so the tetrahedralisation and topology cached on it are made once too."""
    from volviz.model import Image2D

    if isinstance(dataset, Image2D) or is_lod(dataset):
        return dataset
    from volviz.model.arrays import select_array

    views = dataset.__dict__.setdefault("volviz_views", {})
    if spec not in views:
        views[spec] = select_array(dataset, spec)
    return views[spec]


def ensure_transfer_functions(session: Session, datasets: dict[str, Any]) -> None:
    """Give every volume-like component without a transfer function a default one fitted to its data."""
    from volviz.render.vtk_scene import default_transfer_function_for

    from volviz.model import Image2D

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
            session.transfer_functions[name] = tf.to_dict()
            comp.transfer_function = name


def drawn_transfer_function(session: Session, comp: Component, dataset: Any) -> Any:
    """The component's transfer function as drawn (through log10 with the setting ``log_scale``)."""
    from volviz.render.drawn_tf import drawn_tf

    return drawn_tf(comp, component_transfer_function(session, comp), dataset)


def component_transfer_function(session: Session, comp: Component) -> Any:
    from volviz.optics import TransferFunction

    if comp.transfer_function is None:
        return None
    return TransferFunction.from_dict(session.transfer_functions[comp.transfer_function])


NATURE_TYPES = ("terrain", "fog", "clouds", "sky")


def read_any(path: Path, options: dict[str, Any], progress: Optional[ProgressCallback] = None) -> Any:
    """A data file through ``volviz.io.read``, or a volviz-compressed volume (``.vvz``): with the dataset option
    ``lod`` a ``LodTree`` drawn at a view-dependent level of detail (``volviz.render.lod_volume``), else through the
    wavelet decoder
    (damaged bricks are filled from the coarser level and reported as warnings, never silently)."""
    if path.suffix.lower() == ".vvz":
        if options.get("lod"):           # level of detail: blocks decoded on demand for each view
            from volviz.regular.lod import LodTree

            return LodTree(path, cache_bytes=int(options.get("cache_mb", 256)) << 20)
        from volviz.regular.codec import decompress

        return decompress(path, progress=progress)
    from volviz.io import read

    return read(path, **options)


@dataclass
class PreparedScene:
    """What ``prepare_scene`` computed off the GUI thread for ``install_scene`` (DESIGN.md "Background work")."""

    time: Optional[float]                                   # display time of time series (None without one)
    parts: dict[str, Any] = field(default_factory=dict)     # comp id -> IsoParts | TetMesh (PT) | VTK volume input
    cut: dict[str, Any] = field(default_factory=dict)       # PT comp id -> mesh cut by the scene clip (None: all cut)
    histograms: dict[str, Any] = field(default_factory=dict)  # comp id -> (counts, edges) of its data
    nature: Any = None                                      # the NatureScene of the terrain/fog/clouds/sky components


def prepare_scene(session: Session, datasets: dict[str, Any], t: Optional[float] = None, interpolate: bool = True,
                  progress: Optional[ProgressCallback] = None) -> PreparedScene:
    """Any thread: the heavy part of showing ``session`` (default transfer functions, isosurface extraction with
    clipping and LOD chains, tetrahedralisation and mesh topology, VTK volume inputs and time blending at display
    time ``t``, the natural scene's maps and volumes, data histograms). Touches no plotter; ``install_scene`` adds
    the props on the GUI thread."""
    ensure_transfer_functions(session, datasets)
    from volviz.render.first_look import first_look

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


def prepare_component(session: Session, comp: Component, datasets: dict[str, Any], prepared: PreparedScene,
                      t: Optional[float] = None, interpolate: bool = True) -> None:
    """Any thread: the heavy part of showing one non-nature component (isosurface extraction with clipping and LOD
    chains, tetrahedralisation and topology, the VTK volume input at display time ``t``, its data histogram), put into
    ``prepared``; ``install_component`` adds its prop on the GUI thread."""
    from volviz.model import TimeSeries
    from volviz.model.stats import histogram
    from volviz.render.clipping import clip_settings

    clip = clip_settings(session.clip)
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
    if uses_pt(session, dataset):
        mesh = pt_mesh(dataset)
        prepared.parts[comp.id] = mesh
        if clip.all_planes():
            prepared.cut[comp.id] = cut_tetmesh(mesh, clip)
    else:
        prepared.parts[comp.id] = time_input(dataset, t, interpolate) if series else prepared_volume_input(dataset)


def pt_mesh(dataset: Any) -> Any:
    """Any thread: the tetrahedral mesh a PT volume draws for ``dataset``, with its topology built (cached on it)."""
    from volviz.model.datasets import TetMesh
    from volviz.unstructured.topology import topology

    mesh = dataset
    if not isinstance(dataset, TetMesh):
        from volviz.unstructured.tetrahedralize import tetrahedralize

        mesh = tetrahedralize(dataset, getattr(dataset, "active", None))
    topology(mesh)
    return mesh


def cut_tetmesh(mesh: Any, clip: Any) -> Any:
    """Any thread: ``mesh`` cut exactly by ``clip`` (``volviz.iso.clip.clip_tetmesh``) with its topology built; None
    when the clipping removes all of it."""
    from volviz.iso.clip import clip_tetmesh
    from volviz.unstructured.topology import topology

    try:
        cut = clip_tetmesh(mesh, clip)
    except ValueError:  # everything clipped away
        return None
    topology(cut)
    return cut


def prepared_volume_input(dataset: Any, t: Optional[float] = None, interpolate: bool = True) -> Any:
    """Any thread: the VTK data object a volume mapper draws for ``dataset`` (a time series: blended at display
    time ``t``, libMini note "4D Visualization"), or None when ``add_dataset`` does not draw it as a volume."""
    from volviz.model import Image2D, TimeSeries
    from volviz.render.vtk_scene import is_surface, volume_grid, volume_input

    if isinstance(dataset, TimeSeries):
        from volviz.model.timeseries import frame_at

        dataset = frame_at(dataset, float(dataset.times[0] if t is None else t), interpolate)
    if isinstance(dataset, Image2D) or is_surface(dataset) or volume_grid(dataset).active_scalars is None:
        return None
    return volume_input(dataset)


def time_input(series: Any, t: Optional[float] = None, interpolate: bool = True) -> Any:
    """Any thread: what a VTK prop of a time series draws at display time ``t`` (default: the first step): a
    volume's mapper input (``prepared_volume_input``, blended) or a surface's (``vtk_scene.surface_input`` of the
    frame at ``t``: points and values blended between steps of one topology); None for what does not follow the
    time (a 2D image)."""
    from volviz.model import Image2D
    from volviz.model.timeseries import frame_at
    from volviz.render.vtk_scene import is_surface, surface_input

    t = float(series.times[0] if t is None else t)
    if isinstance(series.frame(0), Image2D):
        return None
    if is_surface(series):
        return surface_input(frame_at(series, t, interpolate))
    return prepared_volume_input(series, t, interpolate)


def add_volume_prop(plotter: Any, dataset: Any, data: Any, tf: Any, opacity: float, name: str,
                    backend: str = "auto", shade: bool = False) -> Any:
    """GUI thread: a vtkVolume drawing ``data`` (from ``prepared_volume_input``), the surface of a time series at
    its display time (``data`` from ``time_input``), or (``data`` None) ``add_dataset``'s default visual;
    ``backend``: the render option (``volviz.render.backend``), which picks VTK's GPU or CPU ray caster; ``shade``:
    the component's lighting setting (``vtk_scene.set_volume_shading``; regular volumes only)."""
    from volviz.model import RegularVolume, TimeSeries
    from volviz.render.vtk_scene import add_dataset, add_surface, is_surface, volume_prop

    if data is None:
        return add_dataset(plotter, dataset, tf=tf, opacity=opacity, name=name)
    if is_surface(dataset):        # a time series' surface at the display time (``time_input``)
        return add_surface(plotter, data, tf, opacity, name)
    regular = isinstance(dataset.frame(0) if isinstance(dataset, TimeSeries) else dataset, RegularVolume)
    return volume_prop(plotter, data, regular, tf, opacity, name, backend, shade)


def prepare_nature(session: Session, datasets: dict[str, Any]) -> Any:
    """Any thread: the NatureScene of the session's visible terrain / fog / clouds / sky components (None when it has
    none): maps read into height fields, fog prisms, cloud volumes and lighting; ``NatureView`` shows it."""
    components = [c for c in session.components if c.visible and c.type in NATURE_TYPES]
    if not components:
        return None
    from volviz.nature.nature_scene import scene_from_components

    try:
        scene = scene_from_components(components, datasets)
    except (ValueError, KeyError) as exc:
        raise SceneError(f"natural scene: {exc}") from None
    scene.finalize()
    return scene


def install_nature(plotter: Any, scene: Any, views: bool = True, backend: str = "cpu") -> Any:
    """GUI thread: a view of a prepared NatureScene (None: none): ``NatureView`` (fog and clouds rendered on the CPU
    as an overlay) or, for ``backend`` "gpu", ``volviz.render.gl_nature.GLNatureView`` (drawn by VTK's OpenGL; see
    ``view_backend``). Its first view is computed now when ``views`` (the app computes it in the background:
    ``begin`` / ``compute`` / ``finish``)."""
    if scene is None:
        return None
    from volviz.render.views import view_class

    view = view_class("nature", backend)(plotter, scene)
    if views:
        view.update()
    return view


def install_scene(plotter: Any, session: Session, datasets: dict[str, Any], prepared: PreparedScene,
                  spectrum: bool = True, views: bool = True) -> dict[str, Any]:
    """GUI thread: add the props of a ``prepare_scene`` result to ``plotter``; returns the view of each component by
    id (``install_component``), and under ``"nature"`` the NatureView that draws the terrain, fog, clouds and sky
    components together. The view-dependent parts (PT volume images, LOD block selections, the natural scene's
    terrain and overlay) are drawn now when ``views``; otherwise they stay empty until the caller updates them (the
    app does that in the background)."""
    from volviz.render.vtk_scene import apply_camera

    props: dict[str, Any] = {}
    pt_components = []
    lod_components = []
    for comp in session.components:
        if not comp.visible or comp.type in NATURE_TYPES:
            continue
        dataset = component_dataset(comp, datasets)
        if comp.type not in ("isosurface", "slices") and is_lod(dataset):
            lod_components.append((comp, dataset))   # selected for the final camera
        elif comp.type not in ("isosurface", "slices") and uses_pt(session, dataset):
            pt_components.append((comp, prepared.parts[comp.id]))  # drawn last: over the opaque scene's depth
        else:
            props[comp.id] = install_component(plotter, session, comp, datasets, prepared, spectrum, views)
    plotter.set_background(session.render.background)
    if session.camera is None:  # framed on every component before the view-dependent parts are drawn
        from volviz.render.decorations import legend_margin
        from volviz.render.framing import frame_bounds, nature_bounds, points_bounds, union
        from volviz.render.lod_volume import lod_bounds

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


def install_component(plotter: Any, session: Session, comp: Component, datasets: dict[str, Any],
                      prepared: PreparedScene, spectrum: bool = True, views: bool = True) -> Any:
    """GUI thread: add one non-nature component from its ``prepare_component`` result; returns its view
    (``volviz.render.views.ComponentView``: a PT volume, a LOD volume, its isosurfaces, or a VTK prop's view). A PT
    volume's image and a LOD volume's blocks are drawn now when ``views`` (else the caller updates them in the
    background)."""
    from volviz.render.component_views import IsoSurfacesView, VtkPropView

    dataset = component_dataset(comp, datasets)
    if comp.type == "isosurface":
        return IsoSurfacesView(plotter, comp, prepared.parts[comp.id], spectrum=spectrum)
    if comp.type == "slices":
        from volviz.render.slices import SlicesView

        return SlicesView(plotter, comp, dataset, component_transfer_function(session, comp))
    if is_lod(dataset):
        return add_lod_component(plotter, session, comp, dataset, update=views)
    if uses_pt(session, dataset):
        return add_pt_component(plotter, session, comp, prepared.parts[comp.id], update=views)
    tf = drawn_transfer_function(session, comp, dataset)
    return VtkPropView(add_volume_prop(plotter, dataset, prepared.parts.get(comp.id), tf, comp.opacity, comp.id,
                                       backend_setting(session.render.options), bool(comp.settings.get("shade"))))


def build_scene(plotter: Any, session: Session, datasets: dict[str, Any], spectrum: bool = True) -> dict[str, Any]:
    """Add every visible component to ``plotter`` now (``prepare_scene`` then ``install_scene``)."""
    return install_scene(plotter, session, datasets, prepare_scene(session, datasets), spectrum)


def is_lod(dataset: Any) -> bool:
    from volviz.regular.lod import LodTree

    return isinstance(dataset, LodTree)


def dataset_traits(dataset: Any) -> DatasetTraits:
    """What a loaded dataset (as ``read_any`` gives it) is, for the settings that apply to some datasets only
    (``volviz.model.applicability``): a time series, a compressed volume drawn at a level of detail."""
    from volviz.model import TimeSeries

    return DatasetTraits(time_series=isinstance(dataset, TimeSeries), lod_volume=is_lod(dataset))


def drawn_as(dataset: Any) -> str:
    """How a volume component draws a loaded dataset: ``"points"`` (a mesh of vertices only, e.g. a point table),
    ``"surface"`` (surface cells, a flat grid, no field or a constant one: ``volviz.model.representation``) or
    ``"volume"``."""
    from volviz.model.representation import representation

    return "volume" if is_lod(dataset) else representation(dataset).kind


def add_lod_component(plotter: Any, session: Session, comp: Component, dataset: Any, update: bool = True) -> Any:
    """A compressed volume at a view-dependent level of detail (``volviz.render.lod_volume``); the component
    setting ``budget`` is the number of blocks per view (default 256). Its blocks are selected now when ``update``
    (the app selects them in the background: ``select`` / ``decode`` / ``show``)."""
    from volviz.render.lod_volume import LodVolume

    if session.camera is None:
        lo, hi = dataset.node_box((dataset.levels, (0, 0, 0)))
        plotter.view_isometric()
        plotter.renderer.ResetCamera(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])
        plotter.camera_set = True
    lod = LodVolume(plotter, dataset, drawn_transfer_function(session, comp, dataset),
                    budget=int(comp.settings.get("budget", 256)), opacity=comp.opacity)
    if update:
        lod.update()
    return lod


PT_DATASETS = ("TetMesh", "UnstructuredMesh", "CurvilinearGrid")


def uses_pt(session: Session, dataset: Any) -> bool:
    """Unstructured and curvilinear data are drawn by volviz's pre-integrated projected tetrahedra unless the
    session asks for VTK's own mappers (render method "vtk"); regular volumes go to VTK's ray casters."""
    from volviz.model import TimeSeries

    from volviz.render.vtk_scene import is_surface

    if isinstance(dataset, TimeSeries):
        return False  # time-varying meshes stay on VTK's mapper for now
    return session.render.method != "vtk" and type(dataset).__name__ in PT_DATASETS and not is_surface(dataset)


def add_pt_component(plotter: Any, session: Session, comp: Component, dataset: Any, update: bool = True) -> Any:
    """A PT volume for a component (``volviz.render.pt_view``), with its TF scaled by its opacity: drawn on the GPU
    (``volviz.render.gl_pt``) or the CPU (``volviz.render.pt_prop``) as the render option ``backend`` picks for this
    plotter's OpenGL (``volviz.render.backend``; the exact "reference" method is CPU only). A CPU volume's image is
    rendered now when ``update`` (the app renders it in the background: ``begin`` / ``compute`` / ``finish``)."""
    tf = drawn_transfer_function(session, comp, dataset)
    if comp.opacity != 1.0:
        tf = tf.scaled_extinction(comp.opacity)
    method = "reference" if session.render.method == "reference" else "pt"
    opts = pt_options(session.render.options) if method == "pt" else {}
    from volviz.render.views import view_class

    if method == "pt" and pt_backend(plotter, session) == "gpu":
        return view_class("pt", "gpu")(plotter, dataset, tf, **{"lookup": "auto", **opts})  # the CPU path's table
    handle = view_class("pt", "cpu")(plotter, dataset, tf, method=method, scalars=getattr(dataset, "active", None),
                                     **opts)
    if update:
        handle.update()
    return handle


def pt_backend(plotter: Any, session: Session) -> str:
    """"gpu" or "cpu": where the session's PT volumes are drawn in ``plotter`` (``volviz.render.backend``)."""
    return view_backend(plotter, session, "pt")


def view_backend(plotter: Any, session: Session, view_kind: str) -> str:
    """"gpu" or "cpu": where the session's views of ``view_kind`` ("pt", "nature", "iso", ...) are drawn in
    ``plotter``, as the render option ``backend`` picks for the plotter's OpenGL (``volviz.render.backend``)."""
    from volviz.render.backend import choose_backend, plotter_gl_info

    return choose_backend(backend_setting(session.render.options), view_kind, plotter_gl_info(plotter))


def pt_options(options: dict[str, Any]) -> dict[str, Any]:
    """Render settings -> keywords of ``volviz.unstructured.render``: sort ("mpvo", "centroid", "power"), table
    ("auto" by optical depth, "3d", or "separable-N" with a color polynomial of degree N) and its resolution."""
    out: dict[str, Any] = {}
    sort = options.get("sort")
    if sort in ("mpvo", "centroid", "power"):
        out["sort"] = sort
    table = str(options.get("table", "auto"))
    resolution = options.get("table_resolution")
    if table == "3d":
        out["lookup"] = "3d"
    elif table.startswith("separable-") and table[len("separable-"):] in ("1", "2", "4"):
        out.update(lookup="separable", degree=int(table[len("separable-"):]))
    if table != "auto" and isinstance(resolution, int) and 16 <= resolution <= 1024:
        out["n_s"] = resolution
    return out


@dataclass
class IsoParts:
    """An isosurface component's surfaces ready for actors (``isosurface_parts``): the extracted ones (uncut by the
    scene clipping), the shown ones (cut, opacity scaled) and the LOD chains of the shown ones."""

    meshes: list[Any]
    shown: list[Any]
    lod: Optional[list[Any]]
    settings: Any
    clip: dict[str, Any] = field(default_factory=dict)  # the scene clipping they were cut by (``to_dict``)
    opacity: float = 1.0                                 # the component opacity they were scaled by


def isosurface_parts(comp: Component, dataset: Any = None, t: Optional[float] = None, clip: Any = None,
                     meshes: Optional[list[Any]] = None, progress: Optional[ProgressCallback] = None) -> IsoParts:
    """Any thread: the surfaces of an ``isosurface`` component (settings: ``volviz.iso.IsoSettings``) extracted at
    display time ``t`` (skipped when ``meshes`` are known), cut exactly by the scene's ``clip`` (``session.clip`` or
    ClipSettings) on top of the component's own clipping, scaled by its opacity, with their LOD chains."""
    from volviz.iso import IsoSettings, prepare
    from volviz.iso.clip import clip_isosurfaces
    from volviz.render.clipping import clip_settings

    try:
        settings = IsoSettings.from_dict(comp.settings)
    except ValueError as exc:
        raise SceneError(f"component {comp.id!r}: {exc}") from None
    if not settings.styles:
        raise SceneError(f"component {comp.id!r}: settings.styles lists no iso-values")
    if meshes is None:
        meshes = list(prepare(dataset, settings, t, progress=progress).meshes)
    scene_clip = clip_settings(clip)
    shown = clip_isosurfaces(meshes, scene_clip) if scene_clip.all_planes() else list(meshes)
    if comp.opacity < 1.0:  # the component's opacity scales every surface's
        from dataclasses import replace

        shown = [replace(m, style=replace(m.style, opacity=m.style.opacity * comp.opacity)) for m in shown]
    lod = None  # LOD chains of the shown surfaces (the CPU modes draw them view-dependently)
    if settings.lod:
        from volviz.iso.lod import build_lod

        lod = [(build_lod(m), settings.triangles_per_pixel2) if m.n_triangles else None for m in shown]
    return IsoParts(list(meshes), shown, lod, settings, scene_clip.to_dict(), float(comp.opacity))


def add_isosurface_actors(plotter: Any, name: str, parts: IsoParts, spectrum: bool = True) -> Any:
    """GUI thread: the shown surfaces of ``parts`` as one prop assembly of VTK actors named ``name``, with the
    iso-spectrum shader when ``spectrum`` (drawn by VTK as the note's 2-pass blend). The assembly keeps the uncut
    surfaces as ``volviz_meshes`` and the shown ones as ``volviz_shown`` (the CPU transparency modes draw those,
    ``volviz.render.iso_overlay``).

    The shader needs the renderer's lights: a renderer without lights (``pyvista.Plotter.clear`` removes them)
    compiles VTK's unlit shader, which declares no normals (``normalVCVSOutput`` undeclared); the scene controller
    restores the light kit before building."""
    from volviz.render.vtk_facade import vtk

    from volviz.render.iso_spectrum import iso_actor

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
    plotter.add_actor(assembly, name=name, reset_camera=False)
    return assembly


def add_isosurfaces(plotter: Any, comp: Component, dataset: Any, t: Optional[float] = None,
                    spectrum: bool = True, clip: Any = None, meshes: Optional[list[Any]] = None) -> Any:
    """The isosurfaces of an ``isosurface`` component as one prop assembly, now: ``isosurface_parts`` (``clip``:
    the scene's clipping; ``meshes``: the extracted surfaces when already known) then ``add_isosurface_actors``."""
    return add_isosurface_actors(plotter, comp.id, isosurface_parts(comp, dataset, t, clip, meshes),
                                 spectrum=spectrum)


def build_nature(plotter: Any, session: Session, datasets: dict[str, Any]) -> Any:
    """The NatureView of the session's visible terrain / fog / clouds / sky components (None when it has none)."""
    return install_nature(plotter, prepare_nature(session, datasets), backend=view_backend(plotter, session, "nature"))
