"""All pre-integration tables in one place (Roettger §8.4–8.13, Ch. 9), plus one error report over every kind.

The implementations live in ``table3d``, ``table2d``, ``separable``, ``isosurface`` and ``zot``; this module
re-exports them and offers ``error_report`` for benchmarks and the app's statistics view.
"""
from __future__ import annotations

from typing import Any

from volviz.optics.isosurface import IsoSurface, IsoTable, build_iso_table
from volviz.optics.separable import SeparableTable, build_separable
from volviz.optics.table2d import Table2D, build_table2d
from volviz.optics.table3d import Table3D, build_table3d, build_table3d_job
from volviz.optics.zot import ZOTable, build_zot

__all__ = ["Table3D", "build_table3d", "build_table3d_job", "Table2D", "build_table2d", "SeparableTable",
           "build_separable",
           "IsoSurface", "IsoTable", "build_iso_table", "ZOTable", "build_zot", "error_report"]


def error_report(table: Any, **kw: Any) -> dict:
    """Max and RMS error of any table kind against ``integrate_segment`` at grid-cell centres and random points.

    Returns ``{"centers": {...}, "random": {...}}`` (``TableError.as_dict``), or the ZOT's conservativeness counts.
    """
    if isinstance(table, ZOTable):
        return table.error(**kw)
    return {where: table.error(where=where, **kw).as_dict() for where in ("centers", "random")}
