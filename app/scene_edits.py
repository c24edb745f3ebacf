"""Edits of the shown scene in the main window: what the docks' signals do. Each edit is made in the session
(``volviz.session.Session.set_transfer_function`` ...), which announces it; the window hears it once the
controller's views show it (``scene_changed``) and the view scheduler refreshes the camera views for it
(``volviz_app.view_scheduler.ViewScheduler.views_follow``): no edit here refreshes a view itself (issue #31). The
scene dock selects a component (its transfer function and histogram, computed in the background when missing, go to
the TF editor), shows or hides it (a component hidden at load is prepared in the background, a natural-scene
component rebuilds the natural scene in the background), and sets its opacity and settings; the TF editor's edits are
throttled to one edit of the session per ``PREVIEW_MS`` (previews while dragging, full size with an error estimate
once an edit is finished); the clipping dock's clipping cuts every view (what is cut on the CPU, isosurfaces and PT
meshes, in the background: ``cut_in_background``); the render settings dock changes the renderer (the scene rebuilt
with the same camera), the isosurface mode or the error budget.

Held by the window as ``window.scene_edits``; its collaborators are the shown scene (``shown_scene``), the parent of
its preview timer, the views' refreshes (``ViewRefreshes``: the window's view scheduler), the window's ``jobs``, the
status label, the TF editor, the scene tree and the array choice, and as callbacks ``render_scene()``,
``set_dirty(dirty)``, ``show_error(title, text)``, ``show_session(...)`` (``volviz_app.scene_loading``: a rebuild
with the same camera) and ``enforce_error_budget(rmse)``. The window subscribes ``scene_changed`` to each installed
scene's changes and calls ``scene_installed()``; it connects the docks' signals to its forwarders of
``select_component``, ``tf_changed``, ``tf_committed``, ``set_visibility``, ``set_opacity``, ``settings_changed`` and
``set_clip``."""
from __future__ import annotations

import threading
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Optional, Protocol

from PySide6.QtCore import QObject, QTimer
from PySide6.QtWidgets import QLabel

from volviz.jobs import Job, JobOutcome
from volviz.session import Session, SessionError
from .docks.render_settings import RENDERER_DEFAULTS
from .shown_scene import ShownScene
from .volume_setup_job import set_up_volumes

if TYPE_CHECKING:
    from volviz.model.clip import ClipSettings
    from volviz.model.events import SceneChange
    from volviz.render.controller import SceneController
    from .array_choice import ArrayChoice
    from .docks.scene_tree import SceneTree
    from .docks.tf_editor import TransferFunctionEditor
    from .workers import JobBridge

#: ``volviz_app.scene_loading.SceneLoading.show_session``: a session shown (session, its file, title, dirty, the
#: datasets already read), prepared in the background while the current scene stays
ShowSession = Callable[[Session, Optional[Path], str, bool, dict[str, Any]], None]

PREVIEW_MS = 40          # live transfer-function preview: at most one re-render per 40 ms while dragging


def _histogram_range(hist: Any) -> Optional[tuple[float, float]]:
    """The data range a (counts, edges) histogram spans (None without one)."""
    return None if hist is None else (float(hist[1][0]), float(hist[1][-1]))


class ViewRefreshes(Protocol):
    """What the edits ask of the views' refreshes (``volviz_app.view_scheduler.ViewScheduler``): to follow an edit
    the views hold, to refresh some camera views or the natural scene after a background cut or show, to draw once
    control returns to the event loop, and the last measured error (None: none measured)."""

    last_error_rmse: Optional[float]

    def views_follow(self, change: SceneChange) -> None: ...
    def refresh_views(self, keys: Optional[list[str]] = None, settled: Optional[Callable[[], None]] = None,
                      scale: int = 1, estimate: bool = True, moving: bool = False) -> int: ...
    def refresh_nature(self, settled: Optional[Callable[[], None]] = None, scale: int = 1) -> None: ...
    def schedule_render(self) -> None: ...


class SceneEdits:
    """The docks' edits of the shown scene (see the module's docstring)."""

    def __init__(self, scene: ShownScene, parent: QObject, views: ViewRefreshes, jobs: JobBridge, status: QLabel,
                 tf_editor: TransferFunctionEditor, scene_tree: SceneTree, array_choice: ArrayChoice, *,
                 render_scene: Callable[[], None], set_dirty: Callable[[], None],
                 show_error: Callable[[str, str], None],
                 show_session: ShowSession, enforce_error_budget: Callable[[float], None]) -> None:
        self.scene, self.views, self.jobs, self.status = scene, views, jobs, status
        self.tf_editor, self.scene_tree, self.array_choice = tf_editor, scene_tree, array_choice
        self.render_scene, self.set_dirty, self.show_error = render_scene, set_dirty, show_error
        self.show_session, self.enforce_error_budget = show_session, enforce_error_budget
        self.components_shown = 0          # components hidden at load, prepared in the background and added
        self._histogram_job: Optional[Job] = None
        self.histograms_computed = 0       # TF-editor histograms computed in the background and shown
        self.histogram_threads: set[int] = set()       # the threads they were computed on
        self._pending_tf: Optional[tuple[str, Any, bool]] = None  # (component, TF, a finished edit)
        self.nature_rebuilds = 0           # natural scenes rebuilt in the background (visibility toggles)
        self.cuts_pending: set[str] = set()  # components whose cut for the current clipping or opacity is not shown
        self.preview_timer = QTimer(parent, singleShot=True, interval=PREVIEW_MS)
        self.preview_timer.timeout.connect(self._apply_pending_tf)

    # the shown scene's, read at each edit: the window replaces them when it shows another scene
    @property
    def controller(self) -> Optional[SceneController]:
        return self.scene.controller

    @property
    def session(self) -> Session:
        return self.scene.session

    @property
    def session_path(self) -> Optional[Path]:
        return self.scene.session_path

    def scene_installed(self) -> None:
        """A new scene is shown: its cuts were made in its preparation."""
        self.cuts_pending = set()

    def stop(self) -> None:
        """The window closes: no TF preview waits."""
        self.preview_timer.stop()

    def select_component(self, comp_id: str) -> None:
        if self.controller is None:
            return
        self.array_choice.show_component(comp_id)
        tf = self.controller.transfer_function(comp_id)
        self.tf_editor.setEnabled(tf is not None)
        if tf is None:
            return
        if comp_id in self.controller.lod_volumes():  # too large to decode whole: the range from node statistics
            from volviz.scene.lod import is_lod, lod_scalar_range

            dataset = self.controller.dataset_of(comp_id)
            assert is_lod(dataset)   # what a LOD view draws
            self.tf_editor.set_transfer_function(tf, data_range=lod_scalar_range(dataset))
            return
        known = self.controller.histograms.get(comp_id)
        self.tf_editor.blockSignals(True)  # the scene already shows this TF: no preview re-render
        try:
            self.tf_editor.set_transfer_function(tf, data_range=_histogram_range(known), histogram=known)
        finally:
            self.tf_editor.blockSignals(False)
        if known is None:
            self._compute_histogram(comp_id)
        elif self._histogram_job is not None:
            self._histogram_job.cancel()  # an older selection's histogram is no longer wanted

    def _compute_histogram(self, comp_id: str) -> None:
        """The data histogram of a component that has none yet (hidden at load), for the TF editor: its dataset is
        read and the histogram computed on a worker (``volviz.model.stats.histogram``) while the editor shows a
        placeholder; a newer selection supersedes it. ``histograms_computed`` counts the ones shown."""
        from volviz.model.stats import histogram
        from volviz.scene.datasets import load_datasets
        from volviz.scene.lod import is_lod

        controller, session_path = self.controller, self.session_path
        if controller is None:
            return
        self.tf_editor.set_histogram_pending()

        def compute(progress: Any = None) -> Any:
            load_datasets(controller.session, session_path, loaded=controller.datasets, also=(comp_id,))  # hidden
            self.histogram_threads.add(threading.get_ident())
            dataset = controller.dataset_of(comp_id)
            if is_lod(dataset):   # never decoded whole (a hidden one comes here): scalar_values' own refusal
                raise TypeError(f"no scalar values for {type(dataset).__name__}")
            return histogram(dataset)

        def done(outcome: JobOutcome) -> None:
            if outcome.ok and self.controller is controller:
                controller.histograms[comp_id] = outcome.result
                self.scene_tree.dataset_read(comp_id)
                if self.scene_tree.current_component() == comp_id:
                    self.tf_editor.set_histogram(outcome.result, _histogram_range(outcome.result))
                    self.histograms_computed += 1
            elif outcome.error is not None:
                self.tf_editor.set_histogram(None, None)
                self.show_error(f"Cannot compute the histogram of {comp_id}", str(outcome.error))

        self._histogram_job = self.jobs.submit(compute, name=f"histogram {comp_id}", key="histogram", on_done=done)

    def tf_changed(self, tf: Any) -> None:
        comp_id = self.scene_tree.current_component()
        if comp_id is None or self.controller is None:
            return
        # a finished edit renders at full size; a drag under way (the editor's TF not yet committed) as a preview
        self._pending_tf = (comp_id, tf, tf is self.tf_editor.committed_transfer_function)
        if not self.preview_timer.isActive():
            self.preview_timer.start()

    def tf_committed(self, tf: Any) -> None:
        self.tf_changed(tf)

    def _apply_pending_tf(self) -> None:
        if self._pending_tf is None or self.controller is None:
            return
        comp_id, tf, finished = self._pending_tf
        self._pending_tf = None
        self.session.set_transfer_function(comp_id, tf, preview=not finished)   # the views follow (``views_follow``)

    def set_visibility(self, comp_id: str, visible: bool) -> None:
        from volviz.scene.datasets import NATURE_TYPES

        if self.controller is None:
            return
        controller = self.controller
        nature = controller.component(comp_id).type in NATURE_TYPES
        build = visible and controller.needs_build(comp_id)
        self.session.set_visible(comp_id, visible)   # a component with a view: refreshed by ``views_follow``
        if nature:
            self.rebuild_nature(comp_id, visible)
        elif build:
            self.show_component(comp_id)

    def show_component(self, comp_id: str) -> None:
        """A component hidden at load was shown: prepare it in the background (extraction, tetrahedralisation, VTK
        volume input, histogram; a newer request for it supersedes), set up its CPU ray-cast volume off the GUI thread
        (``volume_setup_job``), add its prop on this thread, then compute its view-dependent parts in the background.
        ``components_shown`` counts the ones installed."""
        from volviz.scene.datasets import load_datasets

        controller, session_path = self.controller, self.session_path
        if controller is None:
            return
        self.status.setText(f"Preparing {comp_id}…")

        def prepare(progress: Any = None) -> Any:
            load_datasets(controller.session, session_path, loaded=controller.datasets)  # a component shown anew
            return controller.prepare_component(comp_id, progress)

        def install(cancelled: bool, prepared: Any) -> None:
            if cancelled or self.controller is not controller:
                return
            if not controller.component(comp_id).visible or not controller.needs_build(comp_id):
                return  # hidden again meanwhile (or already shown)
            controller.install_component(comp_id, prepared, views=False)
            self.scene_tree.dataset_read(comp_id)
            self.components_shown += 1
            self.status.setText(f"Showing {comp_id}")
            self.views.schedule_render()
            self.views.refresh_views([comp_id, "iso-overlay"])

        def done(outcome: JobOutcome) -> None:
            if self.controller is not controller:
                return
            if outcome.ok:   # its CPU ray-cast volume set up off the GUI thread first, as a loaded scene's
                set_up_volumes(self.jobs, controller, outcome.result, comp_id,
                               lambda cancelled: install(cancelled, outcome.result))
            elif outcome.error is not None:
                self._revert_visibility(controller, comp_id, True)
                self.show_error(f"Cannot show {comp_id}", str(outcome.error))

        self.jobs.submit(prepare, name=f"show {comp_id}", key=f"show:{comp_id}", on_done=done)

    def _revert_visibility(self, controller: SceneController, comp_id: str, visible: bool) -> None:
        """Showing (``visible``) or hiding a component failed: it keeps its previous state (its box follows through
        ``scene_changed``)."""
        controller.set_visible(comp_id, not visible, nature=False, build=False)

    def scene_changed(self, change: SceneChange) -> None:
        """The session's state was edited and the shown scene's views hold the edit (``SceneController.changes``,
        wherever the edit came from: a dock, an undo step, a failed show reverted, a script): the session is marked
        edited, the scene dock shows a component's visibility and opacity as they now are, the TF editor the selected
        component's transfer function, and the camera views follow (``views_follow``)."""
        self.set_dirty()
        if change.what in ("visible", "opacity") and change.component is not None and self.controller is not None:
            comp = self.controller.component(change.component)
            self.scene_tree.show_state(comp.id, comp.visible, comp.opacity)
        if (change.what == "transfer_function" and not change.preview and self.controller is not None
                and change.component is not None and change.component == self.scene_tree.current_component()):
            tf = self.controller.transfer_function(change.component)
            if tf is not None:
                self.tf_editor.follow(tf)   # set by a script: the dock shows it (its own edits it holds already)
        self.views.views_follow(change)
        controller = self.controller
        if change.what in ("opacity", "clip") and controller is not None:  # stale cuts made in the background
            if change.what == "clip":
                self.cuts_pending.intersection_update(controller.pending)  # the others show it already (an undo)
            self.cut_in_background(controller, controller.clip, controller.pending)

    def rebuild_nature(self, comp_id: str, visible: bool) -> None:
        """A terrain / fog / clouds / sky component was shown or hidden: rebuild the natural scene in the background
        (maps, fog prisms, cloud volumes; a newer toggle supersedes an older one), put it in on this thread, then
        compute its first view in the background; the old one stays on screen meanwhile. A scene that cannot be
        built (fog without terrain) leaves the component as it was, with a message."""
        from volviz.scene.datasets import load_datasets

        controller, session_path = self.controller, self.session_path
        if controller is None:
            return

        def prepare(progress: Any = None) -> Any:
            load_datasets(controller.session, session_path, loaded=controller.datasets)  # a component shown anew
            return controller.prepare_nature(progress)

        def done(outcome: JobOutcome) -> None:
            if self.controller is not controller:
                return
            if outcome.ok:
                controller.install_nature(outcome.result, views=False)
                self.nature_rebuilds += 1
                if controller.nature is None:
                    self.views.schedule_render()
                self.views.refresh_nature()
            elif outcome.error is not None:
                self._revert_visibility(controller, comp_id, visible)
                self.show_error(f"Cannot {'show' if visible else 'hide'} {comp_id}", str(outcome.error))

        self.jobs.submit(prepare, name="natural scene", key="nature-build", on_done=done)

    def set_opacity(self, comp_id: str, opacity: float) -> None:
        if self.controller is not None:  # the views follow (``views_follow``)
            self.session.set_opacity(comp_id, opacity)

    def set_clip(self, clip: ClipSettings | dict[str, Any]) -> None:
        """New scene-wide clipping (from the clipping dock, an undo step included; a script may give its JSON): every
        view is given it and the views follow (``views_follow``: what is cut on the CPU is cut in the background);
        invalid clipping gives a message and changes nothing."""
        if self.controller is None:
            return
        try:
            self.session.set_clip(clip)
        except ValueError as exc:
            self.show_error("Invalid clipping", str(exc))

    def cut_in_background(self, controller: SceneController, settings: Any, comp_ids: list[str]) -> None:
        """Cut the views of ``comp_ids`` by ``settings`` (``SceneController.cut``: a PT volume's tetrahedra, an
        isosurface component's surfaces with their LOD chains) on a worker (a newer request for a component
        supersedes), then show each cut here and refresh its camera views; ``clipping_shown()`` tells when all
        are shown. A PT volume given a new whole mesh meanwhile (a time series' next step) is cut again."""
        self.cuts_pending.update(comp_ids)
        for comp_id in comp_ids:
            whole = getattr(controller.views.get(comp_id), "whole_mesh", None)   # what the cut is made of

            def done(outcome: JobOutcome, comp_id: str = comp_id, whole: Any = whole) -> None:
                current = outcome.ok and self.controller is controller and controller.clip == settings
                if current and getattr(controller.views.get(comp_id), "whole_mesh", None) is not whole:
                    self.cut_in_background(controller, settings, [comp_id])
                elif current:
                    controller.show_cut(comp_id, outcome.result)
                    self.cuts_pending.discard(comp_id)
                    self.render_scene()
                    self.views.refresh_views([comp_id, "iso-overlay"])
                elif outcome.error is not None:
                    self.show_error("Cannot clip", f"{comp_id}: {outcome.error}")

            self.jobs.submit(controller.cut, comp_id, settings, name=f"clip {comp_id}", key=f"clip:{comp_id}",
                             on_done=done)

    def clipping_shown(self) -> bool:
        """Whether every view on screen is cut by the current clipping and opacity (cuts run in the background)."""
        return self.controller is None or not self.cuts_pending

    def apply_component_settings(self, comp_id: str, settings: dict[str, Any]) -> bool:
        """New settings for a component (the scene tree's form, an undo step): validated through the session schema,
        then the scene is rebuilt with the same camera and marked dirty; a bad value gives a message naming the field
        and changes nothing. Undoable edits go through ``volviz_app.component_settings.edit_settings``."""
        from volviz.session import session_from_dict, session_to_dict

        if self.controller is None:
            return False
        try:
            doc = session_to_dict(self.session)
            for comp in doc["components"]:
                if comp["id"] == comp_id:
                    _refit_on_new_array(doc, comp, settings)
                    comp["settings"] = settings
            candidate = session_from_dict(doc, "scene tree")
        except (ValueError, SessionError) as exc:
            self.show_error("Invalid settings", f"{comp_id}: {exc}")
            return False
        candidate.camera = self.controller.camera()
        candidate.layout.pop("window_state", None)  # the docks stay where they are
        # prepared in the background; the current scene stays until the new one is ready (or shown on an error)
        self.show_session(candidate, self.session_path, self.scene.title, True, self.scene.datasets)
        return True

    def settings_changed(self, values: dict[str, Any]) -> None:
        current = {**RENDERER_DEFAULTS, **self.session.render.options}  # a missing option is its default
        rebuild = (values["method"] != self.session.render.method
                   or any(values["options"].get(k) != current[k] for k in RENDERER_DEFAULTS))
        budget_changed = values["options"].get("error_budget") != self.session.render.options.get("error_budget")
        iso_mode = values["options"].get("iso_mode", "vtk")
        iso_changed = iso_mode != self.session.render.options.get("iso_mode", "vtk")
        follow = iso_changed and not rebuild and self.controller is not None   # a new mode in the shown scene
        options = {k: v for k, v in values["options"].items() if not (follow and k == "iso_mode")}
        self.session.render.method = values["method"]
        self.session.render.size = values["size"]
        self.session.render.options.update(options)
        self.set_dirty()
        if follow:
            self.session.set_iso_mode(iso_mode)   # the views follow (``views_follow``)
        if budget_changed and not rebuild and self.views.last_error_rmse is not None:
            self.enforce_error_budget(self.views.last_error_rmse)
            return
        if rebuild and self.controller is not None:  # another renderer: rebuild the scene with the same camera
            self.session.camera = self.controller.camera()
            self.session.layout.pop("window_state", None)
            self.show_session(self.session, self.session_path, self.scene.title, True, self.scene.datasets)


def _refit_on_new_array(doc: dict[str, Any], comp: dict[str, Any], settings: dict[str, Any]) -> None:
    """A component that shows another array gets the first-look transfer function of that array (placed from its
    histogram when the scene is prepared), as on a first open: the old one's scalar range belongs to the old array
    (Blunt Fin: Density's 0.19 .. 4.98 kept over MachNumber's 0 .. 3.39). The old function is dropped from the
    session unless another component uses it."""
    from volviz.model.settings import array_key

    key = array_key(comp["type"])
    old_tf = comp.get("transfer_function")
    if settings.get(key) == comp.get("settings", {}).get(key) or old_tf is None:
        return
    comp["transfer_function"] = None
    if not any(c.get("transfer_function") == old_tf for c in doc["components"]):
        doc["transfer_functions"].pop(old_tf, None)
