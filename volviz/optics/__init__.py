"""Optics: transfer functions, the exact ray-segment integral (Roettger Eq. 8.1), pre-integration tables, metrics."""
from volviz.optics.integrate import integrate_segment
from volviz.optics.table3d import Table3D, build_table3d
from volviz.optics.table_error import TableError
from volviz.optics.transfer_function import TransferFunction

__all__ = ["TransferFunction", "integrate_segment", "Table3D", "build_table3d", "TableError"]
