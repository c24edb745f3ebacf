"""Optics: transfer functions, the exact ray-segment integral (Roettger Eq. 8.1), pre-integration tables, metrics.

- ``TransferFunction``: piecewise-linear κ(s), ρ(s); dict, VTK and ParaView-preset conversion.
- ``integrate_segment``: the exact float64 reference for a linear-scalar segment (Eq. 8.1).
- Tables, each with ``lookup(s_f, s_b, l)``, ``error(...)`` against the reference and ``rebuild(new_tf)``:
  ``build_table3d`` (§8.4; direct or incremental), ``build_table2d`` (§8.5, Eq. 8.2), ``build_separable``
  (Ch. 9: ρ̂ + color polynomial), ``build_iso_table`` (§8.8–8.13), ``build_zot`` (conservative zero-opacity test).
- ``volviz.optics.metrics``: RMSE / max abs in 8-bit units, PSNR, error heat map.

The names are imported on first use (PEP 562 ``__getattr__``): the tables and the integral are Numba kernels, and
importing Numba (with SciPy) costs up to a second of a fresh process's start (issue #30;
docs/bench/docstring-figures.md), which a render that only needs a ``TransferFunction`` (a regular volume drawn by VTK)
should not pay.
"""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from volviz.optics.integrate import integrate_preclassified, integrate_segment
    from volviz.optics.isosurface import IsoSurface, IsoTable, build_iso_table, heaviside_alpha, iso_peaks_tf
    from volviz.optics.presets import list_presets, load_preset, read_paraview_presets, write_paraview_presets
    from volviz.optics.separable import SeparableTable, build_separable, segment_averages
    from volviz.optics.table2d import Table2D, build_table2d
    from volviz.optics.table3d import Table3D, build_table3d
    from volviz.optics.table_error import TableError
    from volviz.optics.tf_change import changed_span
    from volviz.optics.transfer_function import TransferFunction
    from volviz.optics.zot import ZOTable, build_zot

#: module (under volviz.optics) of each public name
_HOME = {
    "integrate": ("integrate_preclassified", "integrate_segment"),
    "isosurface": ("IsoSurface", "IsoTable", "build_iso_table", "heaviside_alpha", "iso_peaks_tf"),
    "presets": ("list_presets", "load_preset", "read_paraview_presets", "write_paraview_presets"),
    "separable": ("SeparableTable", "build_separable", "segment_averages"),
    "table2d": ("Table2D", "build_table2d"),
    "table3d": ("Table3D", "build_table3d"),
    "table_error": ("TableError",),
    "tf_change": ("changed_span",),
    "transfer_function": ("TransferFunction",),
    "zot": ("ZOTable", "build_zot"),
}
_MODULE_OF = {name: module for module, names in _HOME.items() for name in names}

__all__ = [
    "TransferFunction", "integrate_segment", "integrate_preclassified",
    "Table3D", "build_table3d", "Table2D", "build_table2d", "SeparableTable", "build_separable", "segment_averages",
    "IsoSurface", "IsoTable", "build_iso_table", "heaviside_alpha", "iso_peaks_tf", "ZOTable", "build_zot",
    "TableError", "changed_span",
    "list_presets", "load_preset", "read_paraview_presets", "write_paraview_presets",
]


def __getattr__(name: str) -> Any:
    """A public name, imported from its module on first use (and kept in this module's namespace)."""
    module = _MODULE_OF.get(name)
    if module is None:
        raise AttributeError(f"module 'volviz.optics' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"volviz.optics.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
