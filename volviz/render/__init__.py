"""The render layer: VTK scenes, offscreen export, the CPU and GPU volume views (``docs/architecture.md``).

Importing it defers matplotlib's pyplot to its first use (``lazy_pyplot``): pyvista imports pyplot for nothing a
render uses, and the render layer is imported before pyvista's plotting package on every path that draws."""
from volviz.render.lazy_pyplot import defer_pyplot

defer_pyplot()
