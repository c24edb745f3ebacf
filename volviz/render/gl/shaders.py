"""The GLSL sources of volviz's GL passes (``resources/shaders``, package ``volviz_resources``), with the
``//VOLVIZ::include <file>`` lines resolved (the pixel ray and opaque depth the ray-segment shaders share,
``ray_pixel.glsl``) and compile-time variants made by ``#define`` lines (a pass's kind compiled in, not switched on
a uniform: llvmpipe runs every branch under a lane mask; ``volviz.render.gl_pt``'s docstring has the measurement)."""
from __future__ import annotations

from importlib import resources

__all__ = ["shader_source", "with_defines"]


def shader_source(name: str) -> str:
    """The text of ``resources/shaders/<name>``, its ``//VOLVIZ::include <file>`` lines replaced by those files."""
    text = (resources.files("volviz_resources") / "shaders" / name).read_text(encoding="utf-8")
    lines = []
    for line in text.splitlines():
        head, _, rest = line.partition("//VOLVIZ::include ")
        lines.append(shader_source(rest.strip()) if not head.strip() and rest else line)
    return "\n".join(lines) + "\n"


def with_defines(source: str, head: str) -> str:
    """``source`` with the ``#define`` lines ``head`` right after VTK's system declarations."""
    return source.replace("//VTK::System::Dec\n", "//VTK::System::Dec\n" + head, 1)
