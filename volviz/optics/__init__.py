"""Optics: transfer functions, the exact ray-segment integral (Roettger Eq. 8.1), pre-integration tables, metrics."""
from volviz.optics.integrate import integrate_segment
from volviz.optics.transfer_function import TransferFunction

__all__ = ["TransferFunction", "integrate_segment"]
