"""The interface of a projected-tetrahedra volume in a plotter (Roettger Ch. 8-9), whichever renderer draws it
(``volviz.render.backend``): ``volviz.render.gl_pt.GLPTVolume`` on the GPU (VTK draws it at every render) or
``volviz.render.pt_prop.PTVolume`` on the CPU (an image re-made by ``update``, or by ``begin`` / ``compute`` /
``finish`` in the app's background jobs, and pasted over VTK's scene). ``SceneController`` talks to both through it.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Literal, Optional, TypeGuard

from volviz.render.framing import Bounds, points_bounds

if TYPE_CHECKING:   # type-only imports for the signatures
    from volviz.jobs import ProgressCallback
    from volviz.model.clip import ClipSettings
    from volviz.model.datasets import TetMesh
    from volviz.optics.transfer_function import TransferFunction

__all__ = ["PTView", "is_pt_view"]


class PTView:
    """What both PT volumes offer (the calls of ``volviz.render.views.View`` and ``ComponentView``). Attributes:
    ``backend`` ("gpu" or "cpu"), ``mesh`` (the TetMesh drawn), ``whole_mesh`` (uncut), ``tf``, ``stats`` (the last
    frame's: ``method``, ``sort_s``, ...), ``visible``."""

    kind: Literal["pt"] = "pt"
    camera_dependent = True
    backend = ""
    mesh: Any
    whole_mesh: Any
    stats: dict[str, Any]
    visible: bool

    @property
    def prop(self) -> PTView:
        return self

    @property
    def drawn_by(self) -> str:
        """Whose raster makes the picture, "gpu" or "cpu" (the statistics' backend): the ``backend``, unless a CPU
        view's image is drawn by the GPU pass in a thread (``pt_prop``'s method "pt-gl")."""
        return self.backend

    def set_tf(self, tf: TransferFunction, opacity: float = 1.0) -> None:
        """Draw with a new transfer function from the next frame on; ``opacity`` scales its extinction."""
        self._use_tf(tf.scaled_extinction(opacity) if opacity != 1.0 else tf)

    def _use_tf(self, tf: Any) -> None:
        raise NotImplementedError

    def set_clip(self, clip: ClipSettings) -> bool:
        """Clip by ``volviz.model.clip.ClipSettings``. True: done; False: this view clips only by drawing a cut mesh,
        which the caller makes (``cut`` on any thread) and shows (``show_cut``)."""
        raise NotImplementedError

    def cut(self, clip: ClipSettings, progress: Optional[ProgressCallback] = None) -> Optional[TetMesh]:
        """Any thread: the uncut mesh cut by ``clip`` exactly (``volviz.iso.clip.clip_tetmesh``), with its topology
        built; None when the clipping removes all of it."""
        # heavy: the cut's Numba kernels and SciPy, loaded only when a mesh is cut
        from volviz.scene.tetra import cut_tetmesh

        return cut_tetmesh(self.whole_mesh, clip)

    def show_cut(self, mesh: Optional[TetMesh], visible: bool = True) -> None:
        """Draw a ``cut`` from the next frame on (None: nothing left, the volume is hidden); re-render it after."""
        if mesh is None:
            self.visible = False
            return
        self.mesh = mesh
        self.visible = visible

    def update(self) -> object:
        """Make the view current for the plotter's camera and scene now."""
        raise NotImplementedError

    def remove(self) -> None:
        """Take the volume out of the plotter."""
        raise NotImplementedError

    def bounds(self) -> Bounds:
        """(xmin, xmax, ymin, ymax, zmin, zmax) of the uncut mesh."""
        return points_bounds(self.whole_mesh.points)


def is_pt_view(prop: object) -> TypeGuard[PTView]:
    return isinstance(prop, PTView)
