"""A live scene in one plotter: what the app's docks change and what export renders, through one code path.

The controller is the adapter from the session's edits to the views (issue #31): each edit of the session's state
(a component's visibility, opacity or transfer function, the clipping, the isosurfaces' mode) is made in the model
(``volviz.session.Session.set_transfer_function`` ..., by a dock, an undo step or a script), which announces it
(``Session.changes``, ``volviz.model.events``); the installed controller hears it, gives it to its views, and passes
it on to the subscribers of its own ``changes`` (e.g. the app's window, which marks the session edited, shows the
new state in its docks and refreshes the camera views in the background). Its ``set_transfer_function`` ... are
that edit of the model with the choice of what the views re-make at once (``update``).

``SceneController`` owns one view per shown component (``views``: ``volviz.render.views.ComponentView``, made by
``volviz.render.scene_builder.install_component``; the natural scene's view under ``"nature"``) and talks to every
kind through the same calls. Transfer-function edits, visibility, opacity, clipping and display time update the views
in place (no rebuild), so live previews stay cheap. The scene-wide clipping
(``session.clip``, ``set_clip``) cuts every prop alike (``volviz.render.clipping``); the isosurfaces' transparency
mode (``session.render.options["iso_mode"]``: "vtk" = VTK's own 2-pass blend, or one of the modes "2pass", "3pass",
"4pass", "exact" of the libMini note §4) is chosen per scene. A note mode is drawn by the ``iso_view`` of the backend
that ``volviz.render.backend`` picks for the view kind "iso": on "gpu" ``volviz.render.gl_iso.GLIsoView`` (passes of
VTK actors, drawn at every render), on "cpu" ``volviz.render.iso_overlay.IsoOverlay`` (a depth-composited overlay
image, re-made by ``update`` or ``begin`` / ``compute`` / ``finish``; also ``iso_overlay``, what the app renders in
the background).
"""
from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Iterator, Mapping, Optional, Union, cast

from volviz.jobs import report
from volviz.model import TimeSeries
from volviz.model.applicability import DatasetTraits
from volviz.model.events import ChangeNotifier, SceneChange
from volviz.model.json_types import json_float
from volviz.render.decorations import apply_decorations, legend_margin, update_legend, update_outline
from volviz.render.framing import frame_scene, union
from volviz.render.image_overlay import OverlayView, single_sample_on_software
from volviz.render.scene_builder import (PreparedScene, ensure_transfer_functions, install_component, install_nature,
                                         display_frame, frame_input, install_scene, make_ray_cast_volumes,
                                         prepare_component, prepare_scene, view_backend)
from volviz.render.pt_view import is_pt_view
from volviz.render.views import view_class
from volviz.render.volume_peeling import peel_volumes, regular_volumes
from volviz.render.vtk_scene import apply_camera, camera_state, is_surface
from volviz.scene.datasets import NATURE_TYPES, component_dataset, dataset_traits, drawn_as
from volviz.scene.drawn_tf import component_transfer_function, drawn_tf
from volviz.scene.errors import SceneError
from volviz.scene.isosurfaces import IsoParts, isosurface_parts
from volviz.scene.nature import prepare_nature
from volviz.session import ISO_MODES, CameraState, Component, Session

if TYPE_CHECKING:   # type-only imports for the signatures
    import pyvista as pv

    from volviz.iso.extract import IsoMesh
    from volviz.jobs import ProgressCallback
    from volviz.model.clip import ClipSettings
    from volviz.model.datasets import TetMesh
    from volviz.nature.nature_scene import NatureScene
    from volviz.nature.terrain import TerrainMesh
    from volviz.optics.transfer_function import TransferFunction
    from volviz.render.gl_nature import EitherNatureView
    from volviz.render.gl_pt import GLPTVolume
    from volviz.render.iso_overlay import IsoOverlay
    from volviz.render.lod_volume import LodVolume
    from volviz.render.nature_view import FrameT, NatureRequest, NatureSceneView
    from volviz.render.pt_prop import PTVolume
    from volviz.render.vtk_facade import vtkProp, vtkVolume
    from volviz.model.datasets import Dataset
    from volviz.scene.datasets import LoadedDataset

    #: a view that re-makes something for a new camera; ``kind`` (a Literal on each class) tells them apart
    CameraView = Union[EitherNatureView, LodVolume, PTVolume, GLPTVolume, IsoOverlay]

__all__ = ["Cut", "ISO_MODES", "MeshFrame", "SceneController", "ensure_lights", "iso_summary", "no_render",
           "session_interpolates"]

#: a component's data cut by the clipping, as its view draws it: a PT volume's tetrahedra (None: nothing left), an
#: isosurface component's parts
Cut = Union["TetMesh", IsoParts, None]


@dataclass(frozen=True)
class MeshFrame:
    """A PT volume's mesh at a display time (``SceneController.blend_volume``): the whole tetrahedral mesh, what is
    drawn of it (its cut by the clipping; None: nothing left), and that clipping."""

    whole: TetMesh
    shown: Optional[TetMesh]
    clip: ClipSettings


def _vtk_props(props: dict[str, object]) -> list[vtkProp]:
    """The VTK props among ``props`` (volviz's own views stand in as their props and are no VTK objects)."""
    return [cast("vtkProp", p) for p in props.values() if hasattr(p, "IsA")]


def iso_summary(stats: Mapping[str, object]) -> str:
    """One line of an isosurface view's statistics (``SceneController.iso_stats``: ``volviz.render.iso_overlay.
    IsoOverlay`` or ``volviz.render.gl_iso.GLIsoView``): the mode, the triangles, those a GPU draws per frame where
    known, and the seconds of the last image (CPU) or frame (GPU)."""
    drawn = stats.get("triangles_drawn")
    drawn_text = "" if drawn is None else f", {drawn:,} drawn"
    ms = json_float(stats["volume_s"]) * 1000
    return f"{stats['method']}: {stats['triangles']:,} triangles{drawn_text}, {ms:.0f} ms"


@contextmanager
def no_render(plotter: pv.BasePlotter) -> Iterator[None]:
    """PyVista renders after every added actor or mesh (``render=True``); inside this block it does not, and the
    caller draws once afterwards (each render of a big scene on a software rasteriser blocks the GUI thread for a
    noticeable time; docs/bench/docstring-figures.md)."""
    suppressed = getattr(plotter, "suppress_rendering", False)
    plotter.suppress_rendering = True
    try:
        yield
    finally:
        plotter.suppress_rendering = suppressed


def ensure_lights(plotter: pv.BasePlotter) -> None:
    """Give a renderer without lights PyVista's default light kit again (``Plotter.clear`` removes all lights; unlit,
    VTK compiles shaders without normals, and the iso-spectrum shader cannot compile)."""
    if plotter.renderer.GetLights().GetNumberOfItems() == 0:
        plotter.enable_lightkit()


def session_interpolates(session: Session) -> bool:
    """Whether the scene blends neighbouring time steps (4D interpolation): one switch for the whole scene, kept in
    each component's ``interpolate`` setting (``SceneController.set_time`` writes it to every time series); off
    when a component's setting turns it off."""
    return all(comp.settings.get("interpolate", True) is not False for comp in session.components)


@dataclass(frozen=True)
class _Remake:
    """What the views re-make at once for an edit of the model: camera-dependent parts (``update``: a CPU PT image,
    a cut), the natural scene (``nature``), a component hidden at build time (``build``)."""

    update: bool = True
    nature: bool = True
    build: bool = True


#: the kinds of view VTK draws with its own mappers (``drawn_by_vtk_alone``)
_VTK_DRAWN = frozenset({"vtk", "slices", "isosurfaces"})


class SceneController:
    def __init__(self, plotter: Any, session: Session, datasets: dict[str, LoadedDataset], on_screen: bool = False):
        self.plotter = plotter
        # the Qt viewport: an edit made in the model re-makes nothing at once (the window refreshes the camera views,
        # rebuilds the natural scene and shows hidden components in the background); off screen (scripts, export)
        # it re-makes all at once
        self.on_screen = on_screen
        self._unsubscribe: Optional[Callable[[], None]] = None  # from ``session.changes`` while installed
        self._session = session
        self.datasets = datasets
        self.views: dict[str, Any] = {}  # comp id -> its view (``ComponentView``); "nature" -> the natural scene's
        self.iso_view: Any = None         # GLIsoView or IsoOverlay while a mode of the note is on
        self.histograms: dict[str, Any] = {}   # comp id -> (counts, edges) of its data, from ``prepare``
        self.time = 0.0
        self.interpolate_time = session_interpolates(session)
        self.changes = ChangeNotifier()   # each edit of the session (``Session.changes``) once the views show it
        self.pending: list[str] = []      # after an opacity or clipping edit: the ids whose CPU cut is stale
        self._edit = _Remake(not on_screen, not on_screen, not on_screen)  # for edits made in the model directly

    @property
    def session(self) -> Session:
        return self._session

    @session.setter
    def session(self, session: Session) -> None:
        """Another session object for the scene shown (the app's File > Save captures one): its edits reach the
        views from now on."""
        listening = self._unsubscribe is not None
        if listening:
            self._stop_listening()
        self._session = session
        if listening:
            self._listen()

    @property
    def props(self) -> dict[str, object]:
        """What each view shows by id: volviz's own views themselves (PT, LOD, the natural scene), the VTK prop of
        the others (a vtkVolume, an actor, an isosurface component's prop assembly)."""
        return {comp_id: getattr(view, "prop", view) for comp_id, view in self.views.items()}

    def _views_of(self, kind: str) -> dict[str, Any]:
        return {comp_id: view for comp_id, view in self.views.items() if getattr(view, "kind", "") == kind}

    # -- building ---------------------------------------------------------------------------------------------------
    def build(self) -> None:
        """Build the scene now (``prepare`` then ``install``, both on this thread)."""
        self.install(self.prepare())

    def prepare(self, progress: Optional[ProgressCallback] = None, t: Optional[float] = None) -> PreparedScene:
        """Any thread, before ``install``: the heavy part of building (``volviz.render.scene_builder.prepare_scene``) at
        display time ``t`` of a time series (default: the session's display time). Touches no plotter, so the app
        runs it in the background."""
        span = self.time_span()
        if t is None or not span:
            t = span[0] if span else None
            start = self.session.render.options.get("time")
            if span and isinstance(start, (int, float)):
                t = float(start)  # the session's display time
        return prepare_scene(self.session, self.datasets, t, self.interpolate_time, progress)

    def install(self, prepared: PreparedScene, views: bool = True) -> None:
        """GUI thread: add the props of a ``prepare`` result to the plotter without rendering. The view-dependent
        parts (PT images, LOD blocks, terrain and overlay) are drawn now when ``views``; the app instead updates them
        in the background (``pt_volume``, ``lod_volumes``, ``nature``: ``begin`` / ``compute`` / ``finish``)."""
        self._listen()

        ensure_lights(self.plotter)
        single_sample_on_software(self.plotter)   # the app's window and ``volviz render`` alike
        with no_render(self.plotter):  # the caller draws once afterwards
            # the views are drawn last, over the whole opaque scene (the outline box of ``decorate`` included, as
            # every later update sees it)
            self.views = install_scene(self.plotter, self.session, self.datasets, prepared, spectrum=True,
                                       views=False)
            self.plotter.camera_set = True  # install_scene chose the view; PyVista must not re-frame the props
            self.installed_bounds = self.bounds()  # (what the clipping dock starts from)
            if self._views_of("pt"):
                # VTK fits the clipping range to its own props only: a previous scene's near plane cut through a PT
                # mesh (a 700k-tetrahedron first frame took minutes instead of 0.3 s)
                self.plotter.renderer.ResetCameraClippingRange(self.installed_bounds)
            self.histograms = dict(prepared.histograms)
            self.time = prepared.time if prepared.time is not None else 0.0
            for comp_id, cut in prepared.cut.items():  # meshes cut in ``prepare`` (a GPU PT volume clips itself)
                self._show_prepared_cut(comp_id, cut)
            if self.clip.all_planes():
                self.apply_clip(update=False)
            self.decorate()  # after the cuts: the outline box is around what is drawn, as after a clip edit
            self.set_iso_mode(self.iso_mode, update=False)
            if views:
                self.update_views()

    def volumes_to_set_up(self, prepared: PreparedScene) -> list[vtkVolume]:
        """GUI thread: the vtkVolumes that VTK's CPU ray caster will draw for ``prepared`` (``install`` or
        ``install_component`` adds them), made now and in no renderer, for the caller to set up off the GUI thread
        first (``volviz.render.volume_setup``); none where the GPU ray caster draws them."""
        return list(make_ray_cast_volumes(self.plotter, self.session, self.datasets, prepared).values())

    def clear(self) -> None:
        """Remove everything this controller added, including PT overlay renderers, which ``plotter.clear()`` keeps."""
        for view in self.views.values():
            view.remove()
        if self.iso_view is not None:
            self.iso_view.remove()
            self.iso_view = None
        self.views = {}
        self.plotter.clear()
        self._stop_listening()   # the session's edits no longer reach this scene

    # -- the model's edits ------------------------------------------------------------------------------------------
    def _listen(self) -> None:
        if self._unsubscribe is None:
            self._unsubscribe = self.session.changes.subscribe(self._model_changed)

    def _stop_listening(self) -> None:
        if self._unsubscribe is not None:
            self._unsubscribe()
            self._unsubscribe = None

    @contextmanager
    def _editing(self, edit: _Remake) -> Iterator[None]:
        """An edit of the model made through this controller: its views re-make what ``edit`` says (heard even
        before ``install``)."""
        previous, listening = self._edit, self._unsubscribe is not None
        self._edit = edit
        self._listen()
        try:
            yield
        finally:
            self._edit = previous
            if not listening:
                self._stop_listening()

    def _model_changed(self, change: SceneChange) -> None:
        """The session announced an edit: give it to the views (what they re-make at once: ``_edit``), then pass it
        on to ``changes``."""
        edit, comp_id = self._edit, change.component
        self.pending = []
        if change.what == "transfer_function" and comp_id is not None:
            self._show_transfer_function(comp_id, edit.update)
        elif change.what == "visible" and comp_id is not None:
            try:
                self._show_visible(comp_id, edit.nature, edit.build)
            finally:
                self.decorate()        # the outline and the scalar bar follow what is shown
        elif change.what == "opacity" and comp_id is not None:
            self.pending = self._show_opacity(comp_id, edit.update)
        elif change.what == "clip":
            self.pending = self.apply_clip(edit.update)
        elif change.what == "iso_mode":
            self._show_iso_mode(edit.update)
        self.changes.notify(change)

    def decorate(self) -> None:
        """(Re)draw the scalar bar, orientation axes and outline box as the session's render options say
        (``volviz.render.decorations``); call after a transfer function, visibility or option changed."""
        apply_decorations(self.plotter, self.session, self.shown_props(), self.datasets)

    def shown_props(self) -> dict[str, object]:
        """The props of the visible components (the natural scene's view under ``"nature"``)."""
        visible = {c.id for c in self.session.components if c.visible}
        return {k: p for k, p in self.props.items() if k == "nature" or k in visible}

    def component(self, comp_id: str) -> Component:
        return self.session.component(comp_id)

    def dataset_of(self, comp_id: str) -> LoadedDataset:
        return component_dataset(self.component(comp_id), self.datasets)

    def dataset_traits(self, comp_id: str) -> Optional[DatasetTraits]:
        """What the component's dataset is, for the settings that apply to some datasets only
        (``volviz.model.applicability``): no traits for a component without a dataset, None while its dataset is
        not read (a component hidden at load)."""
        comp = self.component(comp_id)
        if comp.dataset is None:
            return DatasetTraits()
        return dataset_traits(self.datasets[comp.dataset]) if comp.dataset in self.datasets else None

    def drawn_as(self, comp_id: str) -> Optional[str]:
        """How a volume component draws its dataset (``volviz.scene.datasets.drawn_as``); None for other components
        and while the dataset is not read."""
        comp = self.component(comp_id)
        if comp.type != "volume" or comp.dataset not in self.datasets:
            return None
        return drawn_as(self.datasets[comp.dataset])

    # -- transfer functions, visibility, opacity --------------------------------------------------------------------
    def transfer_function(self, comp_id: str) -> Optional[TransferFunction]:
        return component_transfer_function(self.session, self.component(comp_id))

    def _drawn(self, comp: Component, tf: Any) -> Any:
        """``tf`` as the component is drawn with it (through log10 with its setting ``log_scale``)."""
        return tf if comp.dataset not in self.datasets else drawn_tf(comp, tf, self.dataset_of(comp.id))

    def set_transfer_function(self, comp_id: str, tf: TransferFunction, update: bool = True) -> None:
        """Store ``tf`` in the session (``Session.set_transfer_function``), which the component's view then shows; a
        view that re-makes something for a new TF (a CPU PT volume's image, a LOD volume's block selection) does so
        now only when ``update`` (the app does it in the background: ``camera_views``, then ``begin`` / ``compute``
        / ``finish``)."""
        with self._editing(_Remake(update=update)):
            self.session.set_transfer_function(comp_id, tf)

    def _show_transfer_function(self, comp_id: str, update: bool) -> None:
        comp = self.component(comp_id)
        view = self.views.get(comp_id)
        if view is not None:
            view.set_tf(self._drawn(comp, self.session.transfer_function(comp_id)), comp.opacity)
            if update:
                view.update()

        update_legend(self.plotter, self.session, self.datasets)   # the scalar bar shows the new colors and range

    def set_visible(self, comp_id: str, visible: bool, nature: bool = True, build: bool = True) -> None:
        """Show or hide a component (``Session.set_visible``). A terrain / fog / clouds / sky component rebuilds the
        natural scene now unless ``nature`` is false (the app rebuilds it in the background: ``prepare_nature``,
        ``install_nature``). Another component hidden at build time is built now unless ``build`` is false (the app
        prepares it in the background: ``prepare_component``, ``install_component``)."""
        with self._editing(_Remake(nature=nature, build=build)):
            self.session.set_visible(comp_id, visible)

    def _show_visible(self, comp_id: str, nature: bool, build: bool) -> None:
        comp = self.component(comp_id)
        visible = comp.visible
        if comp.type in NATURE_TYPES:  # the natural scene is one view of all its components
            if nature:
                self.rebuild_nature()
            return
        view = self.views.get(comp_id)
        if view is None and visible:  # hidden at build time: add it now
            if build:
                self.install_component(comp_id, self.prepare_component(comp_id), views=True)
            return
        if view is not None:
            view.visible = bool(visible)
        self._sync_iso_overlay()

    def needs_build(self, comp_id: str) -> bool:
        """Whether showing the component needs ``prepare_component`` / ``install_component`` (it has no view yet)."""
        return self.component(comp_id).type not in NATURE_TYPES and self.views.get(comp_id) is None

    def prepare_component(self, comp_id: str, progress: Optional[ProgressCallback] = None) -> PreparedScene:
        """Any thread: the heavy part of showing a non-nature component that was hidden at build time
        (``volviz.render.scene_builder.prepare_component`` at the display time). Touches no plotter."""
        ensure_transfer_functions(self.session, self.datasets)
        prepared = PreparedScene(time=self.time if self.time_series() else None)
        report(progress, 0.0, f"preparing {comp_id}")
        prepare_component(self.session, self.component(comp_id), self.datasets, prepared, prepared.time,
                          self.interpolate_time)
        report(progress, 1.0, f"{comp_id} prepared")
        return prepared

    def install_component(self, comp_id: str, prepared: PreparedScene, views: bool = True) -> object:
        """GUI thread: add the view of a ``prepare_component`` result without rendering (a PT volume's image and a
        LOD volume's blocks are drawn now when ``views``; the app updates them in the background)."""
        comp = self.component(comp_id)
        with no_render(self.plotter):
            view = install_component(self.plotter, self.session, comp, self.datasets, prepared, spectrum=True,
                                     views=views)
            self.views[comp_id] = view
            self.histograms.update(prepared.histograms)
            if comp_id in prepared.cut:
                self._show_prepared_cut(comp_id, prepared.cut[comp_id])
            if self.clip.all_planes():
                self.apply_clip(update=False)
            self.set_iso_mode(self.iso_mode, update=views)  # new surfaces, or a GPU PT pass that rules out exact GL
        return getattr(view, "prop", view)

    def _show_prepared_cut(self, comp_id: str, cut: Any) -> None:
        view = self.views.get(comp_id)
        if view is not None and not view.set_clip(self.clip):
            view.show_cut(cut, self.component(comp_id).visible)

    def set_opacity(self, comp_id: str, opacity: float, update: bool = True) -> list[str]:
        """Set a component's opacity (``Session.set_opacity``; its view's ``set_tf``). What that re-makes (a PT
        image, a cut of the isosurfaces) is made now when ``update``; otherwise returns the ids whose cut is stale
        (``pending``), which the app makes in the background (``cut`` on a worker, then ``show_cut``; images through
        ``camera_views``)."""
        with self._editing(_Remake(update=update)):
            self.session.set_opacity(comp_id, opacity)
        return self.pending

    def _show_opacity(self, comp_id: str, update: bool) -> list[str]:
        comp = self.component(comp_id)
        view = self.views.get(comp_id)
        stale: list[str] = []
        if view is not None:
            view.set_tf(self._drawn(comp, self.transfer_function(comp_id)), comp.opacity)
            if update:
                view.update()
            self._sync_iso_overlay()
            is_stale = getattr(view, "stale", None)
            stale = [comp_id] if is_stale is not None and is_stale() else []
        return stale

    # -- time -------------------------------------------------------------------------------------------------------
    def time_series(self) -> dict[str, TimeSeries]:
        out = {}
        for comp in self.session.components:
            if comp.dataset is not None and isinstance(self.datasets.get(comp.dataset), TimeSeries):
                shown = self.dataset_of(comp.id)    # the series showing the component's array: a series too
                if isinstance(shown, TimeSeries):
                    out[comp.id] = shown
        return out

    def time_span(self) -> Optional[tuple[float, float]]:
        series = self.time_series()
        if not series:
            return None
        return (min(float(s.times[0]) for s in series.values()), max(float(s.times[-1]) for s in series.values()))

    def time_steps(self) -> list[float]:
        steps: set[float] = set()
        for s in self.time_series().values():
            steps.update(float(t) for t in s.times)
        return sorted(steps)

    def set_time(self, t: float, interpolate: Optional[bool] = None, update: bool = True,
                 isosurfaces: bool = True, volumes: bool = True) -> None:
        """Show display time ``t`` (blending neighbouring steps when interpolating). The CPU-mode isosurface overlay
        re-renders at once when ``update`` (the app renders it in the background instead). Isosurfaces of a time
        series are re-extracted here when ``isosurfaces``; the app instead extracts them in the background
        (``time_isosurfaces`` → ``isosurface_parts`` on a worker → ``show_isosurfaces``). Volumes of a time series
        are blended here when ``volumes``; the app instead blends them in the background (``time_volumes`` →
        ``blend_volume`` on a worker → ``show_volumes``)."""
        if interpolate is not None:
            self.interpolate_time = bool(interpolate)
            for comp_id in self.time_series():     # the session keeps the switch (``session_interpolates``)
                comp = self.component(comp_id)
                comp.settings = {**comp.settings, "interpolate": self.interpolate_time}
        self.time = float(t)
        for comp_id in self.time_isosurfaces():  # re-extract at the new time (the 4D blend happens in prepare)
            if isosurfaces:
                self.show_isosurfaces({comp_id: self.extract_isosurfaces(comp_id, self.time)})
        if volumes:
            self.show_volumes({comp_id: self.blend_volume(comp_id, self.time) for comp_id in self.time_volumes()})
        self._sync_iso_overlay()
        if update:
            for comp_id in self.time_volumes():     # a PT volume's image of its new mesh
                view = self.views[comp_id]
                if is_pt_view(view) and view.visible:
                    view.update()
            if self.iso_overlay is not None:
                self.iso_overlay.update()

    def time_volumes(self) -> list[str]:
        """The volumes and surfaces shown from a time series (what a display-time change re-blends): VTK's volumes
        and surfaces, and PT volumes (a series of meshes)."""
        views = self.views
        series = self.time_series()
        return [comp_id for comp_id in series if comp_id in views
                and (is_pt_view(views[comp_id])
                     or (getattr(views[comp_id], "kind", "") == "vtk"
                         and (views[comp_id].prop.IsA("vtkVolume")
                              or (views[comp_id].prop.IsA("vtkActor") and is_surface(series[comp_id])))))]

    def blend_volume(self, comp_id: str, t: float, interpolate: Optional[bool] = None,
                     progress: Optional[ProgressCallback] = None) -> Union[Dataset, MeshFrame]:
        """Any thread: a time-series volume or surface at display time ``t`` (the 4D blend of the neighbouring
        steps when interpolating, libMini note "4D Visualization"; ``scene_builder.display_frame``): arrays, no VTK
        object; ``show_volumes`` makes its VTK input and puts it on screen. (Made in the job, the VTK input froze the
        window: playing a surface series while orbiting, issue #28.) For a PT volume: its tetrahedra with their
        topology and their cut by the clipping (``MeshFrame``), made here too."""
        interpolate = self.interpolate_time if interpolate is None else bool(interpolate)
        frame = display_frame(self.time_series()[comp_id], float(t), interpolate)
        if not is_pt_view(self.views.get(comp_id)):
            return frame
        # the tetrahedra's modules: only for a series of meshes (start-up)
        from volviz.scene.tetra import cut_tetmesh, pt_mesh

        whole = pt_mesh(frame)
        clip = self.clip
        return MeshFrame(whole, cut_tetmesh(whole, clip) if clip.all_planes() else whole, clip)

    def show_volumes(self, inputs: Mapping[str, Union[Dataset, TimeSeries, MeshFrame, None]]) -> list[str]:
        """GUI thread: give time-series volumes and surfaces new inputs made here from their frames
        (``comp_id → blend_volume(...)``; ``scene_builder.frame_input``), cut by the clipping, and PT volumes their
        new mesh (its image re-made after, as after a cut); the outline box follows data that moves. Returns the PT
        volumes whose frame was cut by a clipping changed since: they keep the mesh they show, their new whole mesh
        is to be cut again (``cut``, ``show_cut``)."""
        changed = False
        stale = []
        series = self.time_series()
        for comp_id, frame in inputs.items():
            view = self.views.get(comp_id)
            if view is None or comp_id not in series:
                continue
            before = view.bounds()
            if isinstance(frame, MeshFrame):             # (``blend_volume`` makes one for a PT volume only)
                view.whole_mesh = frame.whole
                if frame.clip != self.clip:
                    stale.append(comp_id)
                    continue
                view.show_cut(frame.shown, self.component(comp_id).visible)
            else:
                data = frame_input(series[comp_id], frame)
                if data is None:
                    continue
                view.set_input(data, self.clip)
            changed = changed or view.bounds() != before
        if changed:
            update_outline(self.plotter, self.session, self.shown_props())
        return stale

    def time_isosurfaces(self) -> list[str]:
        """The isosurface components shown from a time series (what a display-time change re-extracts)."""
        views = self._views_of("isosurfaces")
        return [comp_id for comp_id in self.time_series() if comp_id in views]

    def extract_isosurfaces(self, comp_id: str, t: float, interpolate: Optional[bool] = None,
                            progress: Optional[ProgressCallback] = None) -> list[IsoMesh]:
        """Any thread: the surfaces of an isosurface component at display time ``t`` (the 4D blend of the
        neighbouring steps when interpolating, libMini note "4D Visualization"), cut by the component's own
        clipping (``volviz.iso.prepare``); ``show_isosurfaces`` puts them on screen."""
        # heavy: volviz.iso's Numba kernels and SciPy, loaded only when an isosurface is extracted
        from volviz.iso import IsoSettings, prepare

        comp = self.component(comp_id)
        settings_doc = dict(comp.settings)  # a snapshot: the GUI thread replaces (never mutates) comp.settings
        settings_doc["interpolate"] = self.interpolate_time if interpolate is None else bool(interpolate)
        try:
            settings = IsoSettings.from_dict(settings_doc)
        except ValueError as exc:
            raise SceneError(f"component {comp_id!r}: {exc}") from None
        return list(prepare(self.dataset_of(comp_id), settings, float(t), progress=progress).meshes)

    def isosurface_parts(self, comp_id: str, t: float, interpolate: Optional[bool] = None,
                         progress: Optional[ProgressCallback] = None) -> IsoParts:
        """Any thread: ``extract_isosurfaces`` cut by the scene's clipping, with their LOD chains
        (``volviz.scene.isosurfaces.IsoParts``), so that ``show_isosurfaces`` only makes actors."""
        meshes = self.extract_isosurfaces(comp_id, t, interpolate, progress)
        return isosurface_parts(self.component(comp_id), meshes=meshes, clip=self.session.clip)

    def show_isosurfaces(self, meshes: Mapping[str, Union[IsoParts, list[IsoMesh]]]) -> None:
        """GUI thread: replace the actors of isosurface components by new surfaces (``comp_id →`` the meshes of
        ``extract_isosurfaces``, or better the ``isosurface_parts``, whose clipping and LOD chains were made off this
        thread and are redone here only when the clipping or opacity changed since); the overlay's meshes follow
        (not re-rendered)."""
        with no_render(self.plotter):  # no render per added actor: the caller draws once afterwards
            for comp_id, surfaces in meshes.items():
                view = self.views.get(comp_id)
                if view is None:
                    continue
                comp = self.component(comp_id)
                parts, given = (surfaces, surfaces.meshes) if isinstance(surfaces, IsoParts) else (None, surfaces)
                if parts is None or parts.clip != self.clip or parts.opacity != comp.opacity:
                    parts = view.cut(self.clip, meshes=list(given))
                view.show(parts)
        self._sync_iso_overlay()

    # -- camera -----------------------------------------------------------------------------------------------------
    def camera(self) -> CameraState:
        return camera_state(self.plotter)

    def set_camera(self, camera: Optional[CameraState], update: bool = True) -> None:
        """Apply ``camera`` (None: frame the scene); re-run the view-dependent parts when ``update`` (the app runs
        them in the background instead)."""
        if camera is None:
            frame_scene(self.plotter, self.shown_props(), right_margin=legend_margin(self.session, self.datasets))
        else:
            apply_camera(self.plotter, camera)
        if update:
            self.update_views()

    # -- view-dependent parts (terrain LOD, fog and cloud images) ---------------------------------------------------
    @property
    def nature(self) -> Optional[EitherNatureView]:
        view: Optional[EitherNatureView] = self.views.get("nature")
        return view

    def drawn_by_vtk_alone(self) -> bool:
        """Whether VTK's own mappers draw the whole scene (volumes, surfaces, slices, isosurfaces as VTK actors): no
        camera view, no custom OpenGL pass and no image of ours in it, so a frame can be drawn in strips
        (``volviz.render.strips``)."""
        return (not self.camera_views()
                and all(getattr(view, "kind", "") in _VTK_DRAWN for view in self.views.values()))

    def drawn_in_strips(self) -> bool:
        """Whether a still frame of the scene can be drawn in strips (``volviz.render.strips``): VTK's own mappers
        draw it, and what else there is are images of ours over it (``OverlayView``: a PT volume's CPU image, the
        isosurfaces' CPU modes), each drawn by a renderer of its own in a layer above, which the strips' last pass
        draws over them; no custom OpenGL pass, and no view that re-makes VTK's props for a new camera."""
        return (all(isinstance(view, OverlayView) for view in self.camera_views().values())
                and all(getattr(view, "kind", "") in _VTK_DRAWN or isinstance(view, OverlayView)
                        for view in self.views.values()))

    def camera_views(self) -> dict[str, CameraView]:
        """The shown views that re-make something for a new camera (``volviz.render.views.View``: ``begin`` /
        ``compute`` / ``finish``), by the key of their updates (``view.job[0]``, with the component's id): the natural
        scene, volumes at a level of detail, PT volumes (a CPU volume's image, a GPU volume's visibility order) and
        the isosurfaces' CPU overlay, in this order (the later ones read the opaque scene's depth)."""
        out: dict[str, CameraView] = {}
        if self.nature is not None:
            out[self.nature.job[0]] = self.nature
        for kind in ("lod", "pt"):
            for comp_id, view in self._views_of(kind).items():
                if self.component(comp_id).visible:   # (a CPU image is not drawn before its first update)
                    out[f"{view.job[0]}:{comp_id}"] = view
        if self.iso_overlay is not None:
            out[self.iso_overlay.job[0]] = self.iso_overlay
        return out

    def update_views(self, pt: bool = True, nature: bool = True, lod: bool = True) -> dict[str, object]:
        """Re-make what depends on the camera now (``update`` of each of ``camera_views``; the natural scene unless
        ``nature`` is false, PT volumes and the isosurface view unless ``pt`` is false, volumes at a level of detail
        unless ``lod`` is false: for callers that do those in the background); returns their statistics."""
        skip = {kind for kind, on in (("nature", nature), ("pt", pt), ("iso", pt), ("lod", lod)) if not on}
        stats: dict[str, object] = {}
        views = {key.split(":", 1)[-1]: view for key, view in self.camera_views().items() if view.kind != "iso"}
        if self.iso_view is not None:
            views["iso"] = self.iso_view  # the CPU overlay's image, or only the GPU passes' statistics
        for key, view in views.items():
            if view.kind in skip:
                continue
            if view.kind == "nature":   # (its Literal narrows the view: the natural scene's update gives its stats)
                stats.update(view.update())
            else:
                view.update()
                stats[key] = dict(view.stats)
        return stats

    def begin_views(self, stage: int) -> list[tuple[str, object, object]]:
        """GUI thread: the requests of the view-dependent parts for the current camera, in two stages because the
        PT volumes and the isosurfaces' CPU mode read the opaque scene's depth: stage 0 the natural scene and the
        volumes at a level of detail, stage 1 (after stage 0 is finished) the CPU images of PT volumes and the iso
        overlay (a GPU PT volume sorts in VTK's render). Then ``compute_views`` (any thread) and ``finish_views``
        (GUI thread); ``update_views`` does all three here."""
        first = ("nature", "lod")
        return [(key, view, view.begin()) for key, view in self.camera_views().items()
                if (view.kind in first) == (stage == 0) and (stage == 0 or view.backend == "cpu")]

    @staticmethod
    def compute_views(requests: list[tuple[str, Any, Any]], progress: Optional[ProgressCallback] = None) -> list[Any]:
        """Any thread: the CPU images and meshes of ``begin_views`` requests (NumPy/Numba; no VTK call on the
        calling thread: the iso overlay's volume in front of its surfaces renders on its own GL thread,
        ``volviz.render.gl_thread``): each view's ``compute`` (``volviz.render.views.View``)."""
        results: list[Any] = []
        for i, (_, view, request) in enumerate(requests):
            report(progress, i / max(len(requests), 1), f"rendering view {i + 1} of {len(requests)}")
            results.append(view.compute(request))
        report(progress, 1.0, "views rendered")
        return results

    def finish_views(self, requests: list[tuple[str, Any, Any]], results: list[Any]) -> None:
        """GUI thread: show the results of ``compute_views`` (each view's ``finish``: hands data to VTK; draws
        nothing)."""
        with no_render(self.plotter):
            for (_, view, request), result in zip(requests, results):
                view.finish(request, *result)

    def lod_volumes(self) -> dict[str, LodVolume]:
        """The visible volumes drawn at a level of detail (``volviz.render.lod_volume.LodVolume``) by component."""
        return {comp_id: view for comp_id, view in self._views_of("lod").items() if view.visible}

    def pt_volume(self, comp_id: str) -> Optional[PTVolume]:
        """The PT volume of a component whose images are made off the GUI thread (``begin`` / ``compute`` /
        ``finish``: volviz's CPU PT or reference, or VTK's projected tetrahedra in a window of their own), or None when
        it is drawn in the scene's window (the GPU backend)."""
        view = self._views_of("pt").get(comp_id)
        return view if view is not None and view.backend == "cpu" else None

    def gl_pt_volume(self, comp_id: str) -> Optional[GLPTVolume]:
        """The GPU PT volume of a component (VTK draws it; its visibility order can be made on a worker:
        ``begin`` / ``compute`` / ``finish``), or None."""
        view = self._views_of("pt").get(comp_id)
        return view if view is not None and view.backend == "gpu" else None

    def pt_stats(self) -> dict[str, dict[str, object]]:
        """The last frame statistics of every PT volume (sort / project / raster seconds, fragments, method)."""
        return {comp_id: dict(view.stats) for comp_id, view in self._views_of("pt").items()}

    def pt_backends(self) -> dict[str, str]:
        """Where every PT volume is drawn, "gpu" or "cpu" (``volviz.render.backend``; ``PTView.drawn_by``)."""
        return {comp_id: view.drawn_by for comp_id, view in self._views_of("pt").items()}

    def rebuild_nature(self) -> None:
        """Rebuild the natural scene for the visible nature components now (``prepare_nature``, ``install_nature``)."""
        self.install_nature(self.prepare_nature())

    def prepare_nature(self, progress: Optional[ProgressCallback] = None) -> Optional[NatureScene]:
        """Any thread: the NatureScene of the visible terrain / fog / clouds / sky components (None: none)."""
        return prepare_nature(self.session, self.datasets)

    def install_nature(self, scene: Optional[NatureScene], views: bool = True) -> Optional[EitherNatureView]:
        """GUI thread: show a ``prepare_nature`` result. With ``views`` its first view is computed now; otherwise
        the old terrain and overlay stay on screen until the new view's first ``finish_nature`` replaces them."""
        old = self.views.pop("nature", None)
        backend = view_backend(self.plotter, self.session, "nature")
        if old is not None and "gpu" in (old.backend, backend):
            old.remove()   # the GL layers go with their view (float targets, observers)
        names = ("nature-sky", "nature-terrain", "nature-overlay") if views or scene is None else ()
        for name in names:
            self.plotter.remove_actor(name, render=False)
        view = install_nature(self.plotter, scene, views, backend)  # adds its actors with ``render=False``
        if view is not None:
            self.views["nature"] = view
        if self.iso_view is not None:
            with no_render(self.plotter):
                self.set_iso_mode(self.iso_mode, update=views)  # the GPU scene's pass may rule out exact GL
        return view

    def finish_nature(self, view: NatureSceneView[FrameT], request: NatureRequest,
                      result: tuple[Optional[TerrainMesh], FrameT, dict[str, float]]) -> dict[str, float]:
        """GUI thread: show a computed view of the natural scene (``view.compute``; a scene without terrain drops
        the terrain of the view it replaced)."""
        return view.finish(request, *result)  # adds its actors with ``render=False``

    def bounds(self) -> tuple[float, float, float, float, float, float]:
        """(xmin, xmax, ymin, ymax, zmin, zmax) of everything the visible components show, including what VTK does
        not see (PT volumes, isosurfaces drawn by a CPU mode, the natural scene's terrain and clouds; not the sky
        dome around the eye); uncut extents."""
        visible = {c.id for c in self.session.components if c.visible}
        boxes = [view.bounds() for comp_id, view in self.views.items() if comp_id == "nature" or comp_id in visible]
        return union([box for box in boxes if box is not None]) or (-1.0, 1.0, -1.0, 1.0, -1.0, 1.0)

    # -- clipping (scene-wide) --------------------------------------------------------------------------------------
    @property
    def clip(self) -> ClipSettings:
        return self.session.clip

    def set_clip(self, clip: dict[str, object] | ClipSettings, update: bool = True) -> list[str]:
        """Store new clipping (``session.clip`` JSON or ClipSettings: ``Session.set_clip``), which every view is then
        given (``apply_clip``); returns the ids of the views drawn from a cut made on the CPU (a CPU PT volume's mesh,
        an isosurface component's surfaces; ``pending``), which are cut and re-made here when ``update``; the app
        instead cuts them in the background (``cut`` on a worker, then ``show_cut``) and re-renders."""
        with self._editing(_Remake(update=update)):
            self.session.set_clip(clip)
        return self.pending

    def apply_clip(self, update: bool = True) -> list[str]:
        """Give the session's clipping to every view (``set_clip``: VTK's mapper planes, a GPU PT volume's
        per-fragment planes at once); returns the ids of those drawn from a CPU cut, which are cut now and the scene
        drawn when ``update`` (see ``set_clip``; else the caller draws it: the app, in strips when a still frame is
        slow)."""
        clip = self.clip
        pending = []
        for comp_id, view in self.views.items():
            if comp_id == "nature" or view.set_clip(clip):
                continue
            pending.append(comp_id)
            if update:
                self.show_cut(comp_id, self.cut(comp_id, clip))
                if view.camera_dependent and view.visible:
                    view.update()
        self._sync_iso_overlay()
        if update:
            self.plotter.render()
        return pending

    def cut(self, comp_id: str, clip: Optional[ClipSettings] = None,
            progress: Optional[ProgressCallback] = None) -> Cut:
        """Any thread: the component's data cut by ``clip`` (default: the session's) as its view draws it (the
        view's ``cut``: the exact cut of a PT volume's tetrahedra, ``volviz.iso.clip.clip_tetmesh``; the isosurfaces'
        triangles, ``clip_isosurfaces``, scaled by the opacity, with their LOD chains)."""
        return self.views[comp_id].cut(self.clip if clip is None else clip)

    def show_cut(self, comp_id: str, cut: Cut) -> None:
        """GUI thread: show a ``cut`` (not rendered; a CPU PT volume's image is re-made afterwards); the outline box
        follows the cut data, as it does in a scene built with this clipping (``volviz render``)."""
        view = self.views.get(comp_id)
        if view is not None:
            view.show_cut(cut, self.component(comp_id).visible)
            self._sync_iso_overlay()

            update_outline(self.plotter, self.session, self.shown_props())

    # -- isosurface transparency mode (per scene) -------------------------------------------------------------------
    @property
    def iso_overlay(self) -> Optional[IsoOverlay]:
        """The isosurfaces' CPU overlay (``IsoOverlay``: ``begin`` / ``compute`` / ``finish``) while a mode of the note
        is drawn on the CPU backend; None otherwise (VTK draws the GPU's ``GLIsoView`` at every render)."""
        view = self.iso_view
        return view if view is not None and view.backend == "cpu" else None

    def iso_stats(self) -> dict[str, object]:
        """The isosurface view's last statistics (``iso_summary`` prints them); {} with
        none."""
        view = self.iso_view
        if view is not None and view.backend == "gpu":
            view.update()
        return dict(view.stats) if view is not None else {}

    @property
    def iso_mode(self) -> str:
        mode = self.session.render.options.get("iso_mode", "vtk")
        return mode if mode in ISO_MODES else "vtk"

    def set_iso_mode(self, mode: str, update: bool = True) -> None:
        """Draw the isosurfaces with VTK's blend ("vtk") or a mode of the note on the backend's ``iso_view`` (the CPU
        overlay is rendered now when ``update``; the app renders it in the background: ``iso_overlay.begin`` /
        ``compute`` / ``finish``). A new mode is an edit of the session (``Session.set_iso_mode``); the current one
        is applied again (after a build) without one."""
        with self._editing(_Remake(update=update)):
            changed = mode != self.iso_mode
            self.session.set_iso_mode(mode)   # checks the mode; a new one is announced, and shown through it
        if not changed:
            self._show_iso_mode(update)

    def _iso_backend(self) -> str:
        """Where a mode of the note is drawn: the backend's choice (``view_backend``), but while a regular volume is
        shown the 2/3/4-pass modes by the CPU overlay, which splits the volume at the surfaces
        (``volviz.render.iso_volume_split``; the GPU passes are blended before VTK's volume pass, so the whole volume
        would lie over them), and exact mode on the GPU only where the renderer can peel the surfaces with the volume
        (no render pass of its own: ``volviz.render.gl_iso``)."""
        backend = view_backend(self.plotter, self.session, "iso")
        if regular_volumes(_vtk_props(self.shown_props())):
            peels = self.iso_mode == "exact" and self.plotter.renderer.GetPass() is None
            return "gpu" if backend == "gpu" and peels else "cpu"
        return backend

    def _show_iso_mode(self, update: bool) -> None:
        mode = self.iso_mode
        backend = self._iso_backend()
        view = self.iso_view
        if view is not None and (mode == "vtk" or not self._iso_props() or view.backend != backend):
            view.remove()
            view = self.iso_view = None
        if view is None and mode != "vtk" and self._iso_props():
            view = self.iso_view = view_class("iso", backend)(self.plotter, mode=mode)
        if view is not None:
            view.mode = mode
        self._sync_iso_overlay()
        if update and self.iso_overlay is not None:
            self.iso_overlay.update()
        elif update:
            self.plotter.render()

    def _iso_props(self) -> dict[str, Any]:
        return {comp_id: view.prop for comp_id, view in self._views_of("isosurfaces").items()}

    def _sync_iso_overlay(self) -> None:
        """In a mode of the note the iso view (either backend) draws the visible components' translucent surfaces;
        opaque surfaces stay VTK actors, so they are the modes' opaque pass in the depth buffer (for PT volumes too).
        In "vtk" mode VTK draws everything. A view on the wrong backend (a regular volume shown or hidden:
        ``_iso_backend``) is made again."""
        overlay = self.iso_view
        if overlay is not None and overlay.backend != self._iso_backend():
            self._show_iso_mode(update=False)
            return
        meshes, lod, shading = [], [], "spectrum"
        for comp_id, prop in self._iso_props().items():
            visible = self.component(comp_id).visible
            prop.SetVisibility(visible)
            for actor in prop.volviz_translucent:
                actor.SetVisibility(overlay is None)
            if visible:
                levels = prop.volviz_lod or [None] * len(prop.volviz_shown)
                for mesh, level in zip(prop.volviz_shown, levels):
                    if mesh.style.opacity < 1.0:
                        meshes.append(mesh)
                        lod.append(level)
                shading = prop.volviz_shading
        if overlay is not None:
            overlay.set_surfaces(meshes, lod, shading)
        self._peel_volumes()

    def _peel_volumes(self) -> None:
        """In "vtk" mode (and the GPU's exact mode) translucent isosurfaces inside a regular volume are depth-peeled
        with it, so the volume behind a surface, the surface and the volume in front composite in that order
        (``volviz.render.volume_peeling``); the app's window, ``volviz render`` and exports alike."""
        shown = self.shown_props()
        translucent = self.iso_view is None and any(
            prop.GetVisibility() and any(a.GetVisibility() for a in prop.volviz_translucent)
            for comp_id, prop in self._iso_props().items() if comp_id in shown)
        translucent = translucent or bool(getattr(self.iso_view, "peels_volumes", False))   # the GPU's exact mode
        peel_volumes(self.plotter, _vtk_props(shown), translucent)
