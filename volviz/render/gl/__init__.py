"""The plumbing the GL passes (``gl_pt``, ``gl_fog``, ``gl_nature``, ``gl_iso``) share, as one public API: shader
sources and their variants (``shaders``), the float scene target a renderer's passes share (``scene_pass``), the
pixel ray's uniforms and the resolve triangle (``frame``), targets, tables and texel arrays (``targets``), and GL's
enumerants (``glenum``). It imports none of the passes (an import-linter contract in ``pyproject.toml``)."""
from __future__ import annotations

from volviz.render.gl import glenum
from volviz.render.gl.frame import resolve_polydata, set_ray_uniforms
from volviz.render.gl.scene_pass import ScenePass
from volviz.render.gl.shaders import shader_source, with_defines
from volviz.render.gl.targets import (color_target, depth_format, depth_target, release, table_texture,
                                      texel_array)

__all__ = ["ScenePass", "color_target", "depth_format", "depth_target", "glenum", "release", "resolve_polydata",
           "set_ray_uniforms", "shader_source", "table_texture", "texel_array", "with_defines"]
