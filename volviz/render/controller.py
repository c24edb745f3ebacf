"""A live scene in one plotter: what the app's docks change and what export renders, through one code path.

``SceneController`` owns the mapping from session components to VTK props. Transfer-function edits, visibility,
opacity and display time update the props in place (no rebuild), so live previews stay cheap. The scene-wide clipping
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
from typing import TYPE_CHECKING, Any, Iterator, Optional, TypeGuard

from volviz.model import TimeSeries
from volviz.session import CameraState, Component, Session

if TYPE_CHECKING:
    from volviz.render.lod_volume import LodVolume
    from volviz.render.pt_view import PTView


ISO_MODES = ("vtk", "2pass", "3pass", "4pass", "exact")


def iso_summary(stats: dict[str, Any]) -> str:
    """One line of an isosurface view's statistics (``SceneController.iso_stats``: ``volviz.render.iso_overlay.
    IsoOverlay`` or ``volviz.render.gl_iso.GLIsoView``): the mode, the triangles, those a GPU draws per frame where
    known, and the seconds of the last image (CPU) or frame (GPU)."""
    drawn = stats.get("triangles_drawn")
    drawn_text = "" if drawn is None else f", {drawn:,} drawn"
    return f"{stats['method']}: {stats['triangles']:,} triangles{drawn_text}, {stats['volume_s'] * 1000:.0f} ms"


def _is_lod(prop: Any) -> TypeGuard[LodVolume]:
    from volviz.render.lod_volume import LodVolume

    return isinstance(prop, LodVolume)


def _is_pt(prop: Any) -> TypeGuard[PTView]:
    """A PT volume on either backend (``volviz.render.pt_view``)."""
    from volviz.render.pt_view import is_pt_view

    return is_pt_view(prop)


def _is_cpu_pt(prop: Any) -> bool:
    """A PT volume whose images volviz renders (``begin`` / ``compute`` / ``finish``); the GPU's VTK draws."""
    return _is_pt(prop) and prop.backend == "cpu"


@contextmanager
def no_render(plotter: Any) -> Iterator[None]:
    """PyVista renders after every added actor or mesh (``render=True``); inside this block it does not, and the
    caller draws once afterwards (each render of a big scene on llvmpipe is 50-600 ms of a blocked GUI thread)."""
    suppressed = getattr(plotter, "suppress_rendering", False)
    plotter.suppress_rendering = True
    try:
        yield
    finally:
        plotter.suppress_rendering = suppressed


def ensure_lights(plotter: Any) -> None:
    """Give a renderer without lights PyVista's default light kit again (``Plotter.clear`` removes all lights; unlit,
    VTK compiles shaders without normals, and the iso-spectrum shader cannot compile)."""
    if plotter.renderer.GetLights().GetNumberOfItems() == 0:
        plotter.enable_lightkit()


class SceneController:
    def __init__(self, plotter: Any, session: Session, datasets: dict[str, Any], on_screen: bool = False):
        self.plotter = plotter
        self.on_screen = on_screen  # the Qt viewport (kept for callers; both draw the iso-spectrum shader)
        self.session = session
        self.datasets = datasets
        self.props: dict[str, Any] = {}
        self.iso_view: Any = None         # GLIsoView or IsoOverlay while a mode of the note is on
        self._vtk_inputs: dict[str, Any] = {}  # uncut inputs of clipped VTK tetrahedral volumes
        self.histograms: dict[str, Any] = {}   # comp id -> (counts, edges) of its data, from ``prepare``
        self.time = 0.0
        self.interpolate_time = True

    # -- building ---------------------------------------------------------------------------------------------------
    def build(self) -> None:
        """Build the scene now (``prepare`` then ``install``, both on this thread)."""
        self.install(self.prepare())

    def prepare(self, progress: Any = None, t: Optional[float] = None) -> Any:
        """Any thread, before ``install``: the heavy part of building (``volviz.render.scene_builder.prepare_scene``) at
        display time ``t`` of a time series (default: the session's display time). Touches no plotter, so the app
        runs it in the background."""
        from volviz.render.scene_builder import prepare_scene

        span = self.time_span()
        if t is None or not span:
            t = span[0] if span else None
            start = self.session.render.options.get("time")
            if span and isinstance(start, (int, float)):
                t = float(start)  # the session's display time
        return prepare_scene(self.session, self.datasets, t, self.interpolate_time, progress)

    def install(self, prepared: Any, views: bool = True) -> None:
        """GUI thread: add the props of a ``prepare`` result to the plotter without rendering. The view-dependent
        parts (PT images, LOD blocks, terrain and overlay) are drawn now when ``views``; the app instead updates them
        in the background (``pt_volume``, ``lod_volumes``, ``nature``: ``begin`` / ``compute`` / ``finish``)."""
        from volviz.render.scene_builder import install_scene

        ensure_lights(self.plotter)
        with no_render(self.plotter):  # the caller draws once afterwards
            self.props = install_scene(self.plotter, self.session, self.datasets, prepared, spectrum=True,
                                       views=views)
            self.plotter.camera_set = True  # install_scene chose the view; PyVista must not re-frame the props
            self.installed_bounds = self.bounds()  # (what the clipping dock starts from)
            self.decorate()
            if any(_is_pt(p) for p in self.props.values()):
                # VTK fits the clipping range to its own props only: a previous scene's near plane cut through a PT
                # mesh (a 700k-tetrahedron first frame took minutes instead of 0.3 s)
                self.plotter.renderer.ResetCameraClippingRange(self.installed_bounds)
            self._vtk_inputs = {}
            self.histograms = dict(prepared.histograms)
            self.time = prepared.time if prepared.time is not None else 0.0
            for comp_id, cut in prepared.cut.items():  # PT meshes were cut in ``prepare`` (the GPU clips itself)
                if _is_cpu_pt(self.props.get(comp_id)):
                    self.set_pt_mesh(comp_id, cut)
            if self.clip.all_planes():
                self.apply_clip(update_pt=False, cut_pt=False, isosurfaces=False)
            self.set_iso_mode(self.iso_mode, update=views)

    def clear(self) -> None:
        """Remove everything this controller added, including PT overlay renderers, which ``plotter.clear()`` keeps."""
        for comp_id, prop in self.props.items():
            if _is_pt(prop) or comp_id == "nature":
                prop.remove()
        if self.iso_view is not None:
            self.iso_view.remove()
            self.iso_view = None
        self.props = {}
        self.plotter.clear()

    def decorate(self) -> None:
        """(Re)draw the scalar bar, orientation axes and outline box as the session's render options say
        (``volviz.render.decorations``); call after a transfer function, visibility or option changed."""
        from volviz.render.decorations import apply_decorations

        apply_decorations(self.plotter, self.session, self.shown_props(), self.datasets)

    def shown_props(self) -> dict[str, Any]:
        """The props of the visible components (the natural scene's view under ``"nature"``)."""
        visible = {c.id for c in self.session.components if c.visible}
        return {k: p for k, p in self.props.items() if k == "nature" or k in visible}

    def component(self, comp_id: str) -> Component:
        for comp in self.session.components:
            if comp.id == comp_id:
                return comp
        raise KeyError(comp_id)

    def dataset_of(self, comp_id: str) -> Any:
        from volviz.render.scene_builder import component_dataset

        return component_dataset(self.component(comp_id), self.datasets)

    # -- transfer functions, visibility, opacity --------------------------------------------------------------------
    def transfer_function(self, comp_id: str) -> Any:
        from volviz.render.scene_builder import component_transfer_function

        return component_transfer_function(self.session, self.component(comp_id))

    def set_transfer_function(self, comp_id: str, tf: Any, update: bool = True) -> None:
        """Store ``tf`` in the session and apply it; a PT volume re-renders only when ``update`` (the app instead
        renders it in the background: ``pt_volume(comp_id)``, then ``begin`` / ``compute`` / ``finish``)."""
        from volviz.render.vtk_scene import update_volume_property

        comp = self.component(comp_id)
        name = comp.transfer_function or comp.id
        self.session.transfer_functions[name] = tf.to_dict()
        comp.transfer_function = name
        prop = self.props.get(comp_id)
        if _is_pt(prop):
            prop.set_tf(tf.scaled_extinction(comp.opacity) if comp.opacity != 1.0 else tf)
            if update:
                prop.update()
        elif _is_lod(prop):
            prop.set_transfer_function(tf)
            if update:
                prop.update()             # the selection depends on the TF (transparent blocks, Eq. 2.7)
        elif prop is not None and prop.IsA("vtkVolume"):
            update_volume_property(prop.GetProperty(), tf, comp.opacity)
        from volviz.render.decorations import update_legend

        update_legend(self.plotter, self.session, self.datasets)   # the scalar bar shows the new colors and range

    def set_visible(self, comp_id: str, visible: bool, nature: bool = True, build: bool = True) -> None:
        """Show or hide a component. A terrain / fog / clouds / sky component rebuilds the natural scene now unless
        ``nature`` is false (the app rebuilds it in the background: ``prepare_nature``, ``install_nature``). Another
        component hidden at build time is built now unless ``build`` is false (the app prepares it in the
        background: ``prepare_component``, ``install_component``)."""
        try:
            self._set_visible(comp_id, visible, nature, build)
        finally:
            self.decorate()        # the outline and the scalar bar follow what is shown

    def _set_visible(self, comp_id: str, visible: bool, nature: bool, build: bool) -> None:
        from volviz.render.scene_builder import NATURE_TYPES

        comp = self.component(comp_id)
        comp.visible = bool(visible)
        if comp.type in NATURE_TYPES:
            if nature:
                self.rebuild_nature()
            return
        prop = self.props.get(comp_id)
        if prop is None and visible:  # hidden at build time: add it now
            if build:
                self.install_component(comp_id, self.prepare_component(comp_id), views=True)
            return
        if comp.type == "isosurface":
            self._sync_iso_overlay()
            return
        if _is_pt(prop):
            prop.visible = bool(visible)
        elif _is_lod(prop):
            prop.volume.SetVisibility(bool(visible))
        elif prop is not None:
            prop.SetVisibility(bool(visible))

    def needs_build(self, comp_id: str) -> bool:
        """Whether showing the component needs ``prepare_component`` / ``install_component`` (it has no prop yet)."""
        from volviz.render.scene_builder import NATURE_TYPES

        return self.component(comp_id).type not in NATURE_TYPES and self.props.get(comp_id) is None

    def prepare_component(self, comp_id: str, progress: Any = None) -> Any:
        """Any thread: the heavy part of showing a non-nature component that was hidden at build time
        (``volviz.render.scene_builder.prepare_component`` at the display time). Touches no plotter."""
        from volviz.jobs import report
        from volviz.render.scene_builder import PreparedScene, ensure_transfer_functions, prepare_component

        ensure_transfer_functions(self.session, self.datasets)
        prepared = PreparedScene(time=self.time if self.time_series() else None)
        report(progress, 0.0, f"preparing {comp_id}")
        prepare_component(self.session, self.component(comp_id), self.datasets, prepared, prepared.time,
                          self.interpolate_time)
        report(progress, 1.0, f"{comp_id} prepared")
        return prepared

    def install_component(self, comp_id: str, prepared: Any, views: bool = True) -> Any:
        """GUI thread: add the prop of a ``prepare_component`` result without rendering (a PT volume's image and a
        LOD volume's blocks are drawn now when ``views``; the app updates them in the background)."""
        from volviz.render.scene_builder import install_component

        comp = self.component(comp_id)
        with no_render(self.plotter):
            prop = install_component(self.plotter, self.session, comp, self.datasets, prepared, spectrum=True,
                                     views=views)
            self.props[comp_id] = prop
            self.histograms.update(prepared.histograms)
            if comp_id in prepared.cut:
                self.set_pt_mesh(comp_id, prepared.cut[comp_id])
            if comp.type != "isosurface" and self.clip.all_planes():
                self.apply_clip(update_pt=False, cut_pt=False, isosurfaces=False)
            if comp.type == "isosurface":
                self._sync_iso_overlay()
            elif self.iso_view is not None:
                self.set_iso_mode(self.iso_mode, update=views)  # a GPU PT volume's pass may rule out exact GL
        return prop

    def set_opacity(self, comp_id: str, opacity: float, isosurfaces: bool = True) -> None:
        """Set a component's opacity. An isosurface component's surfaces are re-made here when ``isosurfaces`` (the
        app re-makes them in the background: ``isosurface_meshes``, ``isosurface_parts``, ``show_isosurfaces``)."""
        comp = self.component(comp_id)
        comp.opacity = float(min(max(opacity, 0.0), 1.0))
        prop = self.props.get(comp_id)
        if prop is None:
            return
        if comp.type == "isosurface":
            if isosurfaces:
                self._readd_isosurfaces(comp_id)
        elif _is_pt(prop):
            tf = self.transfer_function(comp_id)
            prop.set_tf(tf.scaled_extinction(comp.opacity) if comp.opacity != 1.0 else tf)
            prop.update()
        elif _is_lod(prop):
            prop.opacity = comp.opacity
            prop.set_transfer_function(self.transfer_function(comp_id))
        elif prop.IsA("vtkVolume"):
            from volviz.render.vtk_scene import update_volume_property

            update_volume_property(prop.GetProperty(), self.transfer_function(comp_id), comp.opacity)
        else:
            prop.GetProperty().SetOpacity(comp.opacity)

    # -- time -------------------------------------------------------------------------------------------------------
    def time_series(self) -> dict[str, TimeSeries]:
        out = {}
        for comp in self.session.components:
            if comp.dataset is not None and isinstance(self.datasets.get(comp.dataset), TimeSeries):
                out[comp.id] = self.dataset_of(comp.id)
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
        self.time = float(t)
        for comp_id, series in self.time_series().items():
            prop = self.props.get(comp_id)
            if prop is None:
                continue
            comp = self.component(comp_id)
            if comp.type == "isosurface":  # re-extract at the new time (the 4D blend happens in prepare)
                comp.settings = {**comp.settings, "interpolate": self.interpolate_time}
                if isosurfaces:
                    self.show_isosurfaces({comp_id: self.extract_isosurfaces(comp_id, self.time)})
            elif prop.IsA("vtkVolume") and volumes:
                self.show_volumes({comp_id: self.blend_volume(comp_id, self.time)})
        self._sync_iso_overlay()
        if update and self.iso_overlay is not None:
            self.iso_overlay.update()

    def time_volumes(self) -> list[str]:
        """The VTK volumes shown from a time series (what a display-time change re-blends)."""
        return [comp_id for comp_id in self.time_series()
                if self.component(comp_id).type != "isosurface" and self.props.get(comp_id) is not None
                and self.props[comp_id].IsA("vtkVolume")]

    def blend_volume(self, comp_id: str, t: float, interpolate: Optional[bool] = None, progress: Any = None) -> Any:
        """Any thread: the VTK input of a time-series volume at display time ``t`` (the 4D blend of the neighbouring
        steps when interpolating, libMini note "4D Visualization"); ``show_volumes`` puts it on screen."""
        from volviz.render.scene_builder import prepared_volume_input

        interpolate = self.interpolate_time if interpolate is None else bool(interpolate)
        return prepared_volume_input(self.time_series()[comp_id], float(t), interpolate)

    def show_volumes(self, inputs: dict[str, Any]) -> None:
        """GUI thread: give time-series volumes new inputs (``comp_id → blend_volume(...)``), cut by the clipping."""
        from volviz.render.clipping import clip_vtk_prop

        for comp_id, data in inputs.items():
            prop = self.props.get(comp_id)
            if prop is None or data is None:
                continue
            self._vtk_inputs.pop(comp_id, None)
            prop.GetMapper().SetInputData(data)
            if self.clip.all_planes():
                self._vtk_inputs[comp_id] = clip_vtk_prop(prop, self.clip)

    def time_isosurfaces(self) -> list[str]:
        """The isosurface components shown from a time series (what a display-time change re-extracts)."""
        series = self.time_series()
        return [comp_id for comp_id in series
                if self.props.get(comp_id) is not None and self.component(comp_id).type == "isosurface"]

    def extract_isosurfaces(self, comp_id: str, t: float, interpolate: Optional[bool] = None,
                            progress: Any = None) -> list[Any]:
        """Any thread: the surfaces of an isosurface component at display time ``t`` (the 4D blend of the
        neighbouring steps when interpolating, libMini note "4D Visualization"), cut by the component's own
        clipping (``volviz.iso.prepare``); ``show_isosurfaces`` puts them on screen."""
        from volviz.iso import IsoSettings, prepare
        from volviz.render.scene_builder import SceneError

        comp = self.component(comp_id)
        settings_doc = dict(comp.settings)  # a snapshot: the GUI thread replaces (never mutates) comp.settings
        settings_doc["interpolate"] = self.interpolate_time if interpolate is None else bool(interpolate)
        try:
            settings = IsoSettings.from_dict(settings_doc)
        except ValueError as exc:
            raise SceneError(f"component {comp_id!r}: {exc}") from None
        return list(prepare(self.dataset_of(comp_id), settings, float(t), progress=progress).meshes)

    def isosurface_parts(self, comp_id: str, t: float, interpolate: Optional[bool] = None,
                         progress: Any = None) -> Any:
        """Any thread: ``extract_isosurfaces`` cut by the scene's clipping, with their LOD chains
        (``volviz.render.scene_builder.IsoParts``), so that ``show_isosurfaces`` only makes actors."""
        from volviz.render.scene_builder import isosurface_parts

        meshes = self.extract_isosurfaces(comp_id, t, interpolate, progress)
        return isosurface_parts(self.component(comp_id), meshes=meshes, clip=self.session.clip)

    def show_isosurfaces(self, meshes: dict[str, Any]) -> None:
        """GUI thread: replace the actors of isosurface components by new surfaces (``comp_id →`` the meshes of
        ``extract_isosurfaces``, or better the ``isosurface_parts``, whose clipping and LOD chains were made off this
        thread and are redone here only when the clipping or opacity changed since); the overlay's meshes follow
        (not re-rendered)."""
        from volviz.render.scene_builder import IsoParts, add_isosurface_actors, isosurface_parts

        with no_render(self.plotter):  # no render per added actor: the caller draws once afterwards
            for comp_id, surfaces in meshes.items():
                prop = self.props.get(comp_id)
                if prop is None:
                    continue
                comp = self.component(comp_id)
                parts = surfaces if isinstance(surfaces, IsoParts) else None
                if parts is None or parts.clip != self.clip.to_dict() or parts.opacity != comp.opacity:
                    parts = isosurface_parts(comp, meshes=list(parts.meshes if parts else surfaces),
                                             clip=self.session.clip)
                self.plotter.remove_actor(prop, render=False)
                self.props[comp_id] = add_isosurface_actors(self.plotter, comp_id, parts)
        self._sync_iso_overlay()

    # -- camera -----------------------------------------------------------------------------------------------------
    def camera(self) -> CameraState:
        from volviz.render.vtk_scene import camera_state

        return camera_state(self.plotter)

    def set_camera(self, camera: Optional[CameraState], update: bool = True) -> None:
        """Apply ``camera`` (None: frame the scene); re-run the view-dependent parts when ``update`` (the app runs
        them in the background instead)."""
        from volviz.render.vtk_scene import apply_camera

        if camera is None:
            from volviz.render.decorations import legend_margin
            from volviz.render.framing import frame_scene

            frame_scene(self.plotter, self.shown_props(), right_margin=legend_margin(self.session))
        else:
            apply_camera(self.plotter, camera)
        if update:
            self.update_views()

    # -- view-dependent parts (terrain LOD, fog and cloud images) ---------------------------------------------------
    @property
    def nature(self) -> Any:
        return self.props.get("nature")

    def update_views(self, pt: bool = True, nature: bool = True, lod: bool = True) -> dict[str, Any]:
        """Re-run what depends on the camera (C-LOD terrain, fog and clouds unless ``nature`` is false, PT volumes
        unless ``pt`` is false, volumes at a level of detail unless ``lod`` is false, for callers that do those in
        the background: ``nature.begin`` / ``compute`` / ``finish``, ``lod_volumes`` ``select`` / ``decode`` /
        ``show``); returns their statistics."""
        stats: dict[str, Any] = {}
        if nature and self.nature is not None:
            stats.update(self.nature.update())
        for comp_id, prop in self.props.items():
            if pt and _is_pt(prop) and prop.visible:
                prop.update()
                stats[comp_id] = dict(prop.stats)
            elif lod and _is_lod(prop) and prop.volume.GetVisibility():
                stats[comp_id] = dict(prop.update())
        if pt and self.iso_view is not None:
            self.iso_view.update()
            stats["iso"] = dict(self.iso_view.stats)
        return stats

    def begin_views(self, stage: int) -> list[tuple[str, Any, Any]]:
        """GUI thread: the requests of the view-dependent parts for the current camera, in two stages because the
        PT volumes and the isosurfaces' CPU mode read the opaque scene's depth: stage 0 the natural scene and the
        volumes at a level of detail, stage 1 (after stage 0 is finished) the PT volumes and the iso overlay. Then
        ``compute_views`` (any thread) and ``finish_views`` (GUI thread); ``update_views`` does all three here."""
        requests: list[tuple[str, Any, Any]] = []
        if stage == 0:
            if self.nature is not None:
                requests.append(("nature", self.nature, self.nature.begin()))
            for volume in self.lod_volumes().values():
                requests.append(("lod", volume, volume.begin()))
            return requests
        for prop in self.props.values():
            if _is_cpu_pt(prop) and prop.visible:
                requests.append(("overlay", prop, prop.begin()))
        if self.iso_overlay is not None:
            requests.append(("overlay", self.iso_overlay, self.iso_overlay.begin()))
        return requests

    @staticmethod
    def compute_views(requests: list[tuple[str, Any, Any]], progress: Any = None) -> list[Any]:
        """Any thread: the CPU images and meshes of ``begin_views`` requests (pure NumPy/Numba, no VTK calls): each
        view's ``compute`` (``volviz.render.views.View``)."""
        from volviz.jobs import report

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

    def lod_volumes(self) -> dict[str, Any]:
        """The visible volumes drawn at a level of detail (``volviz.render.lod_volume.LodVolume``) by component."""
        return {comp_id: prop for comp_id, prop in self.props.items()
                if _is_lod(prop) and prop.volume.GetVisibility()}

    def pt_volume(self, comp_id: str) -> Any:
        """The PT volume of a component whose images volviz renders (the CPU backend: ``begin`` / ``compute`` /
        ``finish``), or None when VTK draws it (the GPU backend, or VTK's own mappers)."""
        prop = self.props.get(comp_id)
        return prop if _is_cpu_pt(prop) else None

    def gl_pt_volume(self, comp_id: str) -> Any:
        """The GPU PT volume of a component (VTK draws it; its visibility order can be made on a worker:
        ``begin`` / ``compute`` / ``finish``), or None."""
        prop = self.props.get(comp_id)
        return prop if _is_pt(prop) and prop.backend == "gpu" else None

    def pt_stats(self) -> dict[str, Any]:
        """The last frame statistics of every PT volume (sort / project / raster seconds, fragments, method)."""
        return {comp_id: dict(prop.stats) for comp_id, prop in self.props.items() if _is_pt(prop)}

    def pt_backends(self) -> dict[str, str]:
        """The backend ("gpu" or "cpu") of every PT volume (``volviz.render.backend``)."""
        return {comp_id: prop.backend for comp_id, prop in self.props.items() if _is_pt(prop)}

    def rebuild_nature(self) -> None:
        """Rebuild the natural scene for the visible nature components now (``prepare_nature``, ``install_nature``)."""
        self.install_nature(self.prepare_nature())

    def prepare_nature(self, progress: Any = None) -> Any:
        """Any thread: the NatureScene of the visible terrain / fog / clouds / sky components (None: none)."""
        from volviz.render.scene_builder import prepare_nature

        return prepare_nature(self.session, self.datasets)

    def install_nature(self, scene: Any, views: bool = True) -> Any:
        """GUI thread: show a ``prepare_nature`` result. With ``views`` its first view is computed now; otherwise
        the old terrain and overlay stay on screen until the new view's first ``finish_nature`` replaces them."""
        from volviz.render.scene_builder import install_nature, view_backend

        old = self.props.pop("nature", None)
        backend = view_backend(self.plotter, self.session, "nature")
        if old is not None and "gpu" in (old.backend, backend):
            old.remove()   # the GL layers go with their view (float targets, observers)
        names = ("nature-sky", "nature-terrain", "nature-overlay") if views or scene is None else ()
        for name in names:
            self.plotter.remove_actor(name, render=False)
        view = install_nature(self.plotter, scene, views, backend)  # adds its actors with ``render=False``
        if view is not None:
            self.props["nature"] = view
        if self.iso_view is not None:
            with no_render(self.plotter):
                self.set_iso_mode(self.iso_mode, update=views)  # the GPU scene's pass may rule out exact GL
        return view

    def finish_nature(self, view: Any, request: Any, result: tuple[Any, ...]) -> dict[str, Any]:
        """GUI thread: show a computed view of the natural scene (``view.compute``; a scene without terrain drops
        the terrain of the view it replaced)."""
        stats: dict[str, Any] = view.finish(request, *result)  # adds its actors with ``render=False``
        return stats

    def bounds(self) -> tuple[float, float, float, float, float, float]:
        """(xmin, xmax, ymin, ymax, zmin, zmax) of everything the visible components show, including what VTK does
        not see (PT volumes, isosurfaces drawn by a CPU mode, the natural scene's terrain and clouds; not the sky
        dome around the eye); uncut extents."""
        from volviz.render.framing import points_bounds, prop_bounds, union

        boxes = []
        for comp_id, prop in self.shown_props().items():
            if _is_pt(prop):
                boxes.append(prop.bounds())
            elif comp_id in self._iso_props():
                boxes += [points_bounds(m.points) for m in prop.volviz_meshes if len(m.points)]
            else:
                box = prop_bounds(prop)
                if box is not None:
                    boxes.append(box)
        return union(boxes) or (-1.0, 1.0, -1.0, 1.0, -1.0, 1.0)

    # -- clipping (scene-wide) --------------------------------------------------------------------------------------
    @property
    def clip(self) -> Any:
        from volviz.render.clipping import clip_settings

        return clip_settings(self.session.clip)

    def set_clip(self, clip: Any, update_pt: bool = True, cut_pt: bool = True,
                 isosurfaces: bool = True) -> list[str]:
        """Store new clipping (``session.clip`` JSON or ClipSettings) and cut every prop; returns the ids of the PT
        volumes drawn from a cut mesh (CPU backend; a GPU volume clips per fragment, at once). Their meshes are cut here
        when ``cut_pt`` and re-rendered when ``update_pt``; the app instead cuts them in the background (``cut_pt_mesh``
        on a worker, then ``set_pt_mesh``) and re-renders.
        Isosurfaces are re-cut here when ``isosurfaces``; the app instead cuts them in the background
        (``isosurface_meshes``, ``volviz.render.scene_builder.isosurface_parts`` on a worker, ``show_isosurfaces``)."""
        from volviz.iso.clip import ClipSettings

        self.session.clip = clip.to_dict() if isinstance(clip, ClipSettings) else self.clip.from_dict(clip).to_dict()
        return self.apply_clip(update_pt, cut_pt, isosurfaces)

    def isosurface_meshes(self) -> dict[str, list[Any]]:
        """The extracted (uncut) surfaces of every shown isosurface component, for re-cutting them elsewhere."""
        return {comp_id: list(prop.volviz_meshes) for comp_id, prop in self._iso_props().items()}

    def apply_clip(self, update_pt: bool = True, cut_pt: bool = True, isosurfaces: bool = True) -> list[str]:
        """Cut every prop by the session's clipping (isosurfaces only when ``isosurfaces``: ``install`` gets them
        cut by ``prepare``); returns the ids of the PT volumes drawn from a cut mesh (the CPU backend; see
        ``set_clip``)."""
        from volviz.render.clipping import clip_vtk_prop

        clip = self.clip
        pt_ids = []
        for comp_id, prop in list(self.props.items()):
            if comp_id == "nature":
                continue
            comp = self.component(comp_id)
            if comp.type == "isosurface":
                if isosurfaces:
                    self._readd_isosurfaces(comp_id)
            elif _is_pt(prop):
                if prop.set_clip(clip):        # the GPU clips per fragment; the CPU draws a cut mesh
                    continue
                pt_ids.append(comp_id)
                if cut_pt:
                    self.set_pt_mesh(comp_id, self.cut_pt_mesh(comp_id))
                    if update_pt and prop.visible:
                        prop.update()
            elif _is_lod(prop):
                clip_vtk_prop(prop.volume, clip)       # mapper clipping planes, blocks untouched
            elif hasattr(prop, "GetMapper"):
                self._vtk_inputs[comp_id] = clip_vtk_prop(prop, clip, self._vtk_inputs.get(comp_id))
        self._sync_iso_overlay()
        self.plotter.render()
        return pt_ids

    def cut_pt_mesh(self, comp_id: str, clip: Any = None, progress: Any = None) -> Any:
        """Any thread: the PT volume's uncut mesh cut by ``clip`` (default: the session's), exactly
        (``volviz.iso.clip.clip_tetmesh``), with its topology built; None when the clipping removes all of it."""
        from volviz.render.scene_builder import cut_tetmesh

        return cut_tetmesh(self.props[comp_id].whole_mesh, self.clip if clip is None else clip)

    def set_pt_mesh(self, comp_id: str, mesh: Any) -> None:
        """Show a cut mesh of ``cut_pt_mesh`` (None: nothing left, the volume is hidden); re-render it afterwards."""
        prop = self.props[comp_id]
        if mesh is None:
            prop.visible = False
            return
        prop.mesh = mesh
        prop.visible = self.component(comp_id).visible

    def _readd_isosurfaces(self, comp_id: str) -> None:
        """New actors for an isosurface component's already extracted surfaces (after a clip or opacity change)."""
        from volviz.render.scene_builder import add_isosurfaces

        prop = self.props[comp_id]
        self.plotter.remove_actor(prop, render=False)
        self.props[comp_id] = add_isosurfaces(self.plotter, self.component(comp_id), None, clip=self.session.clip,
                                              meshes=prop.volviz_meshes)
        self._sync_iso_overlay()

    # -- isosurface transparency mode (per scene) -------------------------------------------------------------------
    @property
    def iso_overlay(self) -> Any:
        """The isosurfaces' CPU overlay (``IsoOverlay``: ``begin`` / ``compute`` / ``finish``) while a mode of the note
        is drawn on the CPU backend; None otherwise (VTK draws the GPU's ``GLIsoView`` at every render)."""
        view = self.iso_view
        return view if view is not None and view.backend == "cpu" else None

    def iso_stats(self) -> dict[str, Any]:
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
        ``compute`` / ``finish``). The exact mode is VTK's depth peeling, which does not run under the float scene
        target of a GPU PT volume or GPU natural scene in the same renderer (``volviz.render.gl_pt``): there the
        exact mode is drawn by the CPU backend's overlay."""
        from volviz.render.gl_pt import _PASS_MARK
        from volviz.render.scene_builder import view_backend

        if mode not in ISO_MODES:
            raise ValueError(f"unknown isosurface mode {mode!r}; choose from {ISO_MODES}")
        if mode != "vtk" or "iso_mode" in self.session.render.options:
            self.session.render.options["iso_mode"] = mode
        backend = view_backend(self.plotter, self.session, "iso")
        if backend == "gpu" and mode == "exact" and getattr(self.plotter.renderer, _PASS_MARK, None) is not None:
            backend = "cpu"
        view = self.iso_view
        if view is not None and (mode == "vtk" or not self._iso_props() or view.backend != backend):
            view.remove()
            view = self.iso_view = None
        if view is None and mode != "vtk" and self._iso_props():
            from volviz.render.views import view_class

            view = self.iso_view = view_class("iso", backend)(self.plotter, mode=mode)
        if view is not None:
            view.mode = mode
        self._sync_iso_overlay()
        if update and self.iso_overlay is not None:
            self.iso_overlay.update()
        else:
            self.plotter.render()

    def _iso_props(self) -> dict[str, Any]:
        return {comp_id: prop for comp_id, prop in self.props.items()
                if comp_id != "nature" and self.component(comp_id).type == "isosurface"}

    def _sync_iso_overlay(self) -> None:
        """In a mode of the note the iso view (either backend) draws the visible components' translucent surfaces;
        opaque surfaces stay VTK actors, so they are the modes' opaque pass in the depth buffer (for PT volumes too).
        In "vtk" mode VTK draws everything."""
        overlay = self.iso_view
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
