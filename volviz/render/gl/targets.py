"""Textures and framebuffer objects of the GL passes: a pass's own color or depth target (a texture attached to a
framebuffer object of its own), the float32 lookup tables (3D, or a 2D array of layers), texel arrays (VTK's 2D
emulation of a texture buffer), the depth format of a framebuffer's depth attachment (a depth blit needs equal
formats), and releasing them. ``ren_win`` is the render window whose context they live in."""
from __future__ import annotations

from typing import TYPE_CHECKING, Callable, Iterable, Optional, Union

import numpy as np

if TYPE_CHECKING:   # type-only: VTK's classes, reached through the facade at run time
    from volviz.render.vtk_facade import vtkOpenGLFramebufferObject, vtkOpenGLRenderWindow, vtkTextureObject

    #: a texture with the framebuffer object it is attached to
    Target = tuple[vtkTextureObject, vtkOpenGLFramebufferObject]

__all__ = ["color_target", "depth_format", "depth_target", "release", "table_texture", "texel_array"]

_DEPTH_FORMATS = {0x81A5: "Fixed16", 0x81A6: "Fixed24", 0x81A7: "Fixed32", 0x8CAC: "Float32"}  # GL internal formats


def _attached(ren_win: vtkOpenGLRenderWindow, tex: vtkTextureObject,
              attach: Callable[[vtkOpenGLFramebufferObject, vtkTextureObject], None]) -> Target:
    """(``tex``, a new framebuffer object with ``tex`` attached by ``attach(fbo, tex)``), the caller's binding kept."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    fbo = vtk.vtkOpenGLFramebufferObject()
    fbo.SetContext(ren_win)
    fbo.SaveCurrentBindingsAndBuffers()
    fbo.Bind()
    attach(fbo, tex)
    fbo.RestorePreviousBindingsAndBuffers()
    return tex, fbo


def color_target(ren_win: vtkOpenGLRenderWindow, width: int, height: int, components: int, linear: bool) -> Target:
    """(texture, framebuffer object): a float32 color target of ``components`` channels; ``linear``: filtered
    linearly and clamped to its edges (a target sampled between texels), else nearest."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    tex = vtk.vtkTextureObject()
    tex.SetContext(ren_win)
    tex.Create2D(width, height, components, vtk.VTK_FLOAT, False)
    mode = vtk.vtkTextureObject.Linear if linear else vtk.vtkTextureObject.Nearest
    tex.SetMinificationFilter(mode)
    tex.SetMagnificationFilter(mode)
    if linear:
        tex.SetWrapS(vtk.vtkTextureObject.ClampToEdge)
        tex.SetWrapT(vtk.vtkTextureObject.ClampToEdge)
    return _attached(ren_win, tex, lambda fbo, t: fbo.AddColorAttachment(0, t))


def depth_target(ren_win: vtkOpenGLRenderWindow, width: int, height: int, fmt: int) -> Target:
    """(texture, framebuffer object): a depth target of the vtkTextureObject depth format ``fmt`` (read by
    texelFetch: no filtering)."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    tex = vtk.vtkTextureObject()
    tex.SetContext(ren_win)
    tex.AllocateDepth(width, height, fmt)
    return _attached(ren_win, tex, lambda fbo, t: fbo.AddDepthAttachment(t))


def depth_format(depth_texture: Optional[vtkTextureObject]) -> int:
    """The vtkTextureObject depth format of ``depth_texture`` (a framebuffer's depth attachment; None: Fixed32)."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    internal = depth_texture.GetInternalFormat(vtk.VTK_FLOAT, 1, False) if depth_texture is not None else 0
    return int(getattr(vtk.vtkTextureObject, _DEPTH_FORMATS.get(internal, "Fixed32")))


def table_texture(ren_win: vtkOpenGLRenderWindow, data: np.ndarray, layered: bool) -> vtkTextureObject:
    """A float32 RGBA lookup table, linear and clamped to its edges: ``data`` (nz, ny, nx, 4) as a 3D texture, or
    (``layered``) as a 2D array of nz layers (bilinear within a layer: 4 taps instead of 8)."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    nz, ny, nx = data.shape[:3]
    tex = vtk.vtkTextureObject()
    tex.SetContext(ren_win)
    if layered:
        tex.Create2DArrayFromRaw(nx, ny, 4, vtk.VTK_FLOAT, nz, data)
    else:
        tex.Create3DFromRaw(nx, ny, nz, 4, vtk.VTK_FLOAT, data)
    tex.SetMinificationFilter(vtk.vtkTextureObject.Linear)
    tex.SetMagnificationFilter(vtk.vtkTextureObject.Linear)
    tex.SetWrapS(vtk.vtkTextureObject.ClampToEdge)
    tex.SetWrapT(vtk.vtkTextureObject.ClampToEdge)
    tex.SetWrapR(vtk.vtkTextureObject.ClampToEdge)
    return tex


def texel_array(ren_win: vtkOpenGLRenderWindow, texels: np.ndarray, what: str,
                into: Optional[vtkTextureObject] = None) -> vtkTextureObject:
    """``texels`` (n, components) as float32 texels in VTK's 2D emulation of a texture buffer (read by index in the
    shader with the texture's width); ``what`` names it in the error when OpenGL refuses it. ``into``: a texture
    made here before, whose storage is replaced (a per-frame upload keeps one texture object)."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    tex = into
    if tex is None:
        tex = vtk.vtkTextureObject()
        tex.SetContext(ren_win)
    data = np.ascontiguousarray(texels, np.float32)
    if not tex.EmulateTextureBufferWith2DTexturesFromRaw(len(data), data.shape[1], vtk.VTK_FLOAT, data):
        raise RuntimeError(f"OpenGL refused the {what} texture of {len(data)} texels")
    return tex


def release(ren_win: Optional[vtkOpenGLRenderWindow],
            objects: Iterable[Union[vtkTextureObject, vtkOpenGLFramebufferObject, None]]) -> None:
    """Free the GL resources of ``objects`` (textures, framebuffer objects; None skipped) in ``ren_win``'s context
    (none without a window: nothing to free)."""
    if ren_win is None:
        return
    for obj in objects:
        if obj is not None:
            obj.ReleaseGraphicsResources(ren_win)
