"""Optics: transfer functions, the exact ray-segment integral (Roettger Eq. 8.1), pre-integration tables, metrics."""
from volviz.optics.transfer_function import TransferFunction

__all__ = ["TransferFunction"]
