"""The GPU PT pass's own framebuffers (``volviz.render.gl_pt``, "Compositing" and "Opaque geometry" there): the
float32 RGBA target the cells are composited into (cleared each frame: ~95 cells overlap per pixel on the Blunt Fin,
which an 8-bit target does not accumulate accurately), the copy of the opaque scene's depth the fragments end their
segments at (blitted from the framebuffer being drawn), and for a frame drawn smaller while the camera moves that
depth at the smaller size; binding them around the cells' draw and giving the scene its framebuffer back."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from volviz.render.gl import ScenePass, color_target, depth_format, depth_target, glenum, release

if TYPE_CHECKING:   # type-only: VTK's classes, reached through the facade at run time
    from volviz.render.vtk_facade import vtkTextureObject

__all__ = ["PTTargets"]


class PTTargets:
    """The targets of one volume in ``renderer`` (made again when a size or the scene's depth format changes)."""

    def __init__(self, renderer: Any) -> None:
        self.renderer = renderer
        self._targets: tuple[Any, ...] | None = None  # color, its FBO, depth, its FBO, format, drawn-size depth, FBO
        self._viewport: list[int] | None = None       # the scene's viewport while the cells draw smaller
        self._bound = False                           # the color target is bound (cells drawn, no resolve yet)

    @property
    def color(self) -> vtkTextureObject | None:
        """The color texture the cells were last drawn into (None before the first draw)."""
        return self._targets[0] if self._targets is not None else None

    @property
    def size(self) -> tuple[int, int] | None:
        """The size of the color target (None before the first draw)."""
        if self._targets is None:
            return None
        return int(self._targets[0].GetWidth()), int(self._targets[0].GetHeight())

    def _make(self, size: tuple[int, int], drawn: tuple[int, int], fmt: int) -> tuple[Any, ...]:
        """The float32 RGBA target of the ``drawn`` size (linear filtering, for the upsampling resolve), its copy of
        the opaque depth at the window's ``size`` (``fmt``: the scene's depth attachment's, as a depth blit needs)
        and, when ``drawn`` is smaller, that depth again at the ``drawn`` size (else None), each attached to a
        framebuffer object of its own."""
        t = self._targets
        if (t is not None and (t[0].GetWidth(), t[0].GetHeight()) == drawn
                and (t[2].GetWidth(), t[2].GetHeight()) == size and t[4] == fmt):
            return t
        self.release()
        ren_win = self.renderer.GetRenderWindow()
        small = depth_target(ren_win, *drawn, fmt) if drawn != size else (None, None)
        self._targets = (*color_target(ren_win, *drawn, 4, True), *depth_target(ren_win, *size, fmt), fmt, *small)
        return self._targets

    def release(self) -> None:
        """Free the targets' GL resources."""
        if self._targets is not None:
            release(self.renderer.GetRenderWindow(), self._targets[:4] + self._targets[5:])
        self._targets = None

    def _scene_depth_format(self) -> int:
        """The depth format of the framebuffer being drawn (the scene target's or the window's): GL blits depth only
        between equal formats."""
        scene = ScenePass.of(self.renderer)
        if scene is not None:
            return depth_format(scene.depth_texture())
        fb = self.renderer.GetRenderWindow().GetRenderFramebuffer()
        return depth_format(fb.GetDepthAttachmentAsTextureObject())

    def bind(self, size: tuple[int, int], drawn: tuple[int, int]) -> vtkTextureObject:
        """Copy the scene's depth at this point of the frame (after the opaque pass: the opaque geometry's; one sample
        of each pixel when the window is multisampled) into the volume's depth texture (then, for a frame drawn
        smaller, the nearest sample of it into the ``drawn``-size one), then bind and clear the color target for the
        cells (and set the viewport to ``drawn``). Returns the depth texture the cells read."""
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk

        state = self.renderer.GetRenderWindow().GetState()
        scene = [0]
        state.vtkglGetIntegerv(glenum.DRAW_FRAMEBUFFER_BINDING, scene)
        color, color_fbo, depth, depth_fbo, _, small, small_fbo = self._make(size, drawn, self._scene_depth_format())
        color_fbo.SaveCurrentBindingsAndBuffers()
        self._bound = True
        w, h = size
        mask = [1]
        state.vtkglGetBooleanv(glenum.DEPTH_WRITEMASK, mask)
        state.vtkglDepthMask(True)                  # a depth blit writes through the depth write mask
        state.vtkglBindFramebuffer(glenum.READ_FRAMEBUFFER, scene[0])
        state.vtkglBindFramebuffer(glenum.DRAW_FRAMEBUFFER, depth_fbo.GetFBOIndex())
        blit = vtk.vtkOpenGLFramebufferObject.Blit
        blit((0, w, 0, h), (0, w, 0, h), glenum.DEPTH_BUFFER_BIT, glenum.NEAREST)
        if small is not None:                       # single-sampled to single-sampled: a scaling blit is allowed
            state.vtkglBindFramebuffer(glenum.READ_FRAMEBUFFER, depth_fbo.GetFBOIndex())
            state.vtkglBindFramebuffer(glenum.DRAW_FRAMEBUFFER, small_fbo.GetFBOIndex())
            blit((0, w, 0, h), (0, drawn[0], 0, drawn[1]), glenum.DEPTH_BUFFER_BIT, glenum.NEAREST)
            depth = small
        state.vtkglDepthMask(bool(mask[0]))
        color_fbo.Bind()
        color_fbo.ActivateDrawBuffer(0)
        state.vtkglClearColor(0.0, 0.0, 0.0, 0.0)
        state.vtkglClear(glenum.COLOR_BUFFER_BIT)
        if drawn != size:
            self._viewport = [0, 0, 0, 0]
            state.vtkglGetIntegerv(glenum.VIEWPORT, self._viewport)
            state.vtkglViewport(0, 0, drawn[0], drawn[1])
        return depth

    def restore(self) -> None:
        """The scene's framebuffer (and viewport) again, if the cells' target is still bound."""
        if self._bound:
            assert self._targets is not None  # bound to them
            self._targets[1].RestorePreviousBindingsAndBuffers()
            self._bound = False
        if self._viewport is not None:
            self.renderer.GetRenderWindow().GetState().vtkglViewport(*self._viewport)
            self._viewport = None

    def deactivate(self) -> None:
        """The color and depth textures off their texture units (the frame's end)."""
        t = self._targets
        for tex in (t[0], t[2], t[5]) if t is not None else ():
            if tex is not None:
                tex.Deactivate()
