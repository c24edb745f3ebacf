"""The views of volviz's own images in a plotter, one registry by view kind and backend (``volviz.render.backend``
chooses the backend): PT volumes (Roettger Ch. 8-9), the natural scene (Ch. 10-11), the isosurfaces' transparency
modes (libMini note §4) and volumes at a level of detail (Guthe §2.3).

Every view offers the calls of ``View``: ``backend`` ("gpu" or "cpu"); ``begin(scale=1)`` on the GUI thread (what
to make for the plotter's camera now; ``scale`` > 1 asks for a preview while the camera moves), ``compute(request)``
on any thread (the CPU work: an image, a mesh, a visibility order, blocks), ``finish(request, *result)`` on the GUI
thread (hand it to VTK; the caller renders once), and ``remove()``. A GPU view's ``compute`` does only the part the
CPU must do (the GL PT pass: the visibility order; the GL natural scene: LOD selection and vertex buffers); VTK draws
it at every render. ``SceneController`` updates all of them through these calls (``begin_views``, ``compute_views``,
``finish_views``), and the app runs ``compute`` in its background jobs.
"""
from __future__ import annotations

import importlib
from typing import Any, Protocol, runtime_checkable

__all__ = ["VIEWS", "View", "view_class"]

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
class View(Protocol):
    """What every registered view offers (module docstring)."""

    backend: str

    def begin(self, scale: int = 1) -> Any: ...

    def compute(self, request: Any, progress: Any = None) -> tuple[Any, ...]: ...

    def finish(self, request: Any, *result: Any) -> Any: ...

    def remove(self) -> None: ...


def view_class(kind: str, backend: str) -> type:
    """The view class drawing ``kind`` on ``backend``; ValueError naming what exists otherwise."""
    try:
        module, name = VIEWS[(kind, backend)].split(":")
    except KeyError:
        raise ValueError(f"no {backend!r} view for {kind!r}; views: "
                         f"{', '.join(f'{k}/{b}' for k, b in VIEWS)}") from None
    cls: type = getattr(importlib.import_module(module), name)
    return cls
