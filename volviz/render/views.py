"""The views of volviz's own images in a plotter, one registry by view kind and backend (``volviz.render.backend``
chooses the backend): PT volumes (Roettger Ch. 8-9), the natural scene (Ch. 10-11), the isosurfaces' transparency
modes (libMini note §4) and volumes at a level of detail (Guthe §2.3).

Every view offers the calls of ``View``: ``backend`` ("gpu" or "cpu"); ``begin(scale=1)`` on the GUI thread (what
to make for the plotter's camera now; ``scale`` > 1 asks for a preview while the camera moves), ``compute(request)``
on any thread (the CPU work: an image, a mesh, a visibility order, blocks), ``finish(request, *result)`` on the GUI
thread (hand it to VTK; the caller renders once), and ``remove()``. A GPU view's ``compute`` does only the part the
CPU must do (the GL PT pass: the visibility order; the GL natural scene: LOD selection and vertex buffers); VTK draws
it at every render. ``SceneController`` updates all of them through these calls (``camera_views``, ``begin_views``,
``compute_views``, ``finish_views``), and the app runs ``compute`` in its background jobs. ``job`` is the key of a
view's updates and what its worker makes ("visibility order", "volume", ...); a view may ask for a coarse update
first (``coarse_first``) or for none while the camera moves (``while_moving = False``).

Every shown component has a view (``ComponentView``) the controller talks to through the same calls, whatever its
kind: ``set_tf(tf, opacity)``, ``visible``, ``set_clip(clip)`` (True: clipped at once; False: drawn from a cut the
caller makes, ``cut(clip)`` on any thread and ``show_cut(cut, visible)`` on the GUI thread), ``update()``,
``bounds()``, ``stats`` and ``remove()``; ``prop`` is what it adds to VTK. The PT and LOD views are also camera
views (``camera_dependent``); a component that VTK draws with its own props has a view of
``volviz.render.component_views``.
"""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any, Optional, Protocol, TypeVar, runtime_checkable

from typing_extensions import TypeVarTuple, Unpack   # (typing's own from Python 3.11; pydantic needs it too)

if TYPE_CHECKING:   # type-only: the views' argument types, without importing the optics and VTK at run time
    from volviz.jobs import ProgressCallback
    from volviz.model.clip import ClipSettings
    from volviz.optics.transfer_function import TransferFunction
    from volviz.render.framing import Bounds

__all__ = ["COMPONENT_VIEWS", "ComponentView", "RequestT", "VIEWS", "View", "component_view_classes", "view_class"]

#: what a view's ``begin`` makes and its ``compute`` and ``finish`` take back (each view has its own: a dict of the
#: camera and image size, the natural scene's (camera, size, scale), None for a view with nothing to compute)
RequestT = TypeVar("RequestT")
ResultTs = TypeVarTuple("ResultTs")

#: (view kind, backend) -> "module:class"
VIEWS: dict[tuple[str, str], str] = {
    ("pt", "gpu"): "volviz.render.gl_pt:GLPTVolume",
    ("pt", "cpu"): "volviz.render.pt_prop:PTVolume",
    ("nature", "gpu"): "volviz.render.gl_nature:GLNatureView",
    ("nature", "cpu"): "volviz.render.nature_view:NatureView",
    ("iso", "gpu"): "volviz.render.gl_iso:GLIsoView",
    ("iso", "cpu"): "volviz.render.iso_overlay:IsoOverlay",
    ("lod", "cpu"): "volviz.render.lod_volume:LodVolume",
}


@runtime_checkable
class View(Protocol[RequestT, Unpack[ResultTs]]):
    """What every registered view offers (module docstring), generic in its request type and in the tuple its
    ``compute`` returns (``View[Request, *Results]``), which ``finish`` takes back unpacked: each view chooses its
    shape. ``begin`` is called with ``scale`` by keyword (the natural scene's ``begin`` takes a camera first)."""

    backend: str

    def begin(self, *, scale: int = 1) -> RequestT: ...

    def compute(self, request: RequestT, progress: Optional[ProgressCallback] = None) -> tuple[Unpack[ResultTs]]: ...

    def finish(self, request: RequestT, *result: Unpack[ResultTs]) -> object: ...

    def remove(self) -> None: ...


#: the classes of the views of components, by kind ("module:class"; PT by backend)
COMPONENT_VIEWS: dict[str, tuple[str, ...]] = {
    "pt": (VIEWS[("pt", "gpu")], VIEWS[("pt", "cpu")]),
    "lod": (VIEWS[("lod", "cpu")],),
    "vtk": ("volviz.render.component_views:VtkPropView",),
    "isosurfaces": ("volviz.render.component_views:IsoSurfacesView",),
    "slices": ("volviz.render.slices:SlicesView",),
}


@runtime_checkable
class ComponentView(Protocol):
    """What the view of every shown component offers (module docstring)."""

    camera_dependent: bool
    visible: bool
    stats: dict[str, Any]

    @property
    def kind(self) -> str: ...   # read-only: a view's class may narrow it to a Literal (the controller's CameraView)

    @property
    def prop(self) -> object: ...

    def set_tf(self, tf: TransferFunction, opacity: float = 1.0) -> None: ...

    def set_clip(self, clip: ClipSettings) -> bool: ...

    def update(self) -> object: ...

    def bounds(self) -> Optional[Bounds]: ...

    def remove(self) -> None: ...


def _load(spec: str) -> type:
    module, name = spec.split(":")
    cls: type = getattr(importlib.import_module(module), name)
    return cls


def view_class(kind: str, backend: str) -> type:
    """The view class drawing ``kind`` on ``backend``; ValueError naming what exists otherwise."""
    try:
        spec = VIEWS[(kind, backend)]
    except KeyError:
        raise ValueError(f"no {backend!r} view for {kind!r}; views: "
                         f"{', '.join(f'{k}/{b}' for k, b in VIEWS)}") from None
    return _load(spec)


def component_view_classes(kind: str) -> list[type]:
    """The view classes of components of ``kind`` (``COMPONENT_VIEWS``)."""
    return [_load(spec) for spec in COMPONENT_VIEWS[kind]]
