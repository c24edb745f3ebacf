"""The scalar axis shared by the pre-integration tables (Roettger §8.4–§9.1): ``n_s`` samples s_lo + i·ds spanning
[s_lo, s_hi] along the first axis of the table array."""
from __future__ import annotations

import numpy as np


class ScalarAxis:
    """Mixin for a table dataclass with fields ``s_lo``, ``s_hi`` and an array named by ``_axis_field``."""

    _axis_field = "rgba"
    s_lo: float
    s_hi: float

    @property
    def n_s(self) -> int:
        return int(getattr(self, self._axis_field).shape[0])

    @property
    def ds(self) -> float:
        return (self.s_hi - self.s_lo) / (self.n_s - 1)

    @property
    def scalars(self) -> np.ndarray:
        """The table's scalar sample positions s_lo + i·ds."""
        return np.linspace(self.s_lo, self.s_hi, self.n_s)
