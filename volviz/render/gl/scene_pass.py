"""The float32 scene target that the GL passes of one renderer share: a ``vtkFramebufferPass`` around VTK's
standard render steps, whose depth texture holds the opaque scene while the translucent props draw (the GL PT
volume blits its depth from it, the fog layers read it). Translucent props are drawn in order (no OIT, no depth
peeling: the passes' actors rely on it). The passes acquire it (``ScenePass.acquire``) and release it when removed;
the last user to leave takes it off the renderer (VTK complains when a framebuffer pass outlives its context's
resources). The shared passes are kept here by renderer, not on the renderer."""
from __future__ import annotations

import weakref
from typing import TYPE_CHECKING

if TYPE_CHECKING:   # type-only: VTK's classes, reached through the facade at run time
    from volviz.render.vtk_facade import vtkRenderer, vtkTextureObject

__all__ = ["ScenePass"]


class ScenePass:
    """The float scene target installed on ``renderer`` (``framebuffer``: the ``vtkFramebufferPass``) and the
    objects using it (``users``). Made by ``acquire``; found by ``of``."""

    _installed: weakref.WeakKeyDictionary[vtkRenderer, ScenePass] = weakref.WeakKeyDictionary()

    def __init__(self, renderer: vtkRenderer) -> None:
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk

        self.renderer = renderer
        self.users: list[object] = []
        self.framebuffer = vtk.vtkFramebufferPass()
        self.framebuffer.SetColorFormat(vtk.vtkTextureObject.Float32)
        self.framebuffer.SetDelegatePass(vtk.vtkRenderStepsPass())

    @classmethod
    def of(cls, renderer: vtkRenderer) -> ScenePass | None:
        """The scene target installed on ``renderer``, or None."""
        return cls._installed.get(renderer)

    @classmethod
    def acquire(cls, renderer: vtkRenderer, user: object) -> ScenePass:
        """The renderer's scene target (installed now if it has none), with ``user`` counted as one of its users;
        the renderer's depth peeling and OIT are switched off (translucent props drawn in order)."""
        renderer.SetUseDepthPeeling(False)
        renderer.SetUseOIT(False)
        scene = cls._installed.get(renderer)
        if scene is None:
            scene = cls._installed[renderer] = cls(renderer)
            renderer.SetPass(scene.framebuffer)
        scene.users.append(user)
        return scene

    def release(self, user: object) -> None:
        """``user`` no longer draws in the renderer; the last one takes the target off (its GL resources freed)."""
        if user in self.users:
            self.users.remove(user)
        if self.users or self._installed.get(self.renderer) is not self:
            return
        ren_win = self.renderer.GetRenderWindow()
        if ren_win is not None:
            self.framebuffer.ReleaseGraphicsResources(ren_win)
        self.renderer.SetPass(None)  # type: ignore[arg-type]  # VTK takes None (no pass); its stubs do not say so
        del self._installed[self.renderer]

    def depth_texture(self) -> vtkTextureObject:
        """The depth texture of the scene target (the opaque scene's depth while the translucent props draw)."""
        return self.framebuffer.GetDepthTexture()
