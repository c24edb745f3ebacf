"""Piecewise-linear transfer functions: chromaticity κ(s) (RGB) and extinction ρ(s) per unit length.

Optical model (Roettger §7.1 and §8.4, Eq. 8.1; Guthe §1.2): the emitted color density is κ(s)·ρ(s) (Roettger's
pre-multiplied convention), the opacity of a segment is α = 1 − exp(−∫ρ). Both κ and ρ are linear between control
points. Scalars outside ``[scalars[0], scalars[-1]]`` and NaN scalars are transparent (κ = 0, ρ = 0).

VTK convention (docs/design.md "Opacity conventions differ"): a VTK scalar opacity value ``a`` with the volume
property's ``ScalarOpacityUnitDistance`` ``u`` is read as the extinction ρ = a / u (per unit length), and written back
as a = ρ · u. VTK's color transfer function supplies κ directly.
"""
from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["TransferFunction"]

_DICT_FORMAT = "volviz-transfer-function"
_DICT_VERSION = 1


def _as_float_array(value: Any, name: str, ndim: int) -> np.ndarray:
    try:
        arr = np.array(value, dtype=np.float64, copy=True)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"TransferFunction {name} must be numeric, got {type(value).__name__}") from exc
    if arr.ndim != ndim:
        raise ValueError(f"TransferFunction {name} must be {ndim}-D, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"TransferFunction {name} must be finite (no NaN or Inf)")
    return arr


class TransferFunction:
    """Piecewise-linear κ(s) (color, RGB ≥ 0) and ρ(s) (extinction per unit length ≥ 0) over control points.

    Parameters
    ----------
    scalars : (n,) strictly increasing, n ≥ 2.
    colors : (n, 3) chromaticity κ ≥ 0 at the control points (not premultiplied; emission is κ·ρ).
    extinction : (n,) ρ ≥ 0 at the control points, per unit length.
    name : free text, kept in dicts and presets.

    Arrays are copied and made read-only; a transfer function is immutable (make a new one to edit).
    """

    __slots__ = ("_scalars", "_colors", "_extinction", "name")

    def __init__(self, scalars: Any, colors: Any, extinction: Any, name: str = "") -> None:
        s = _as_float_array(scalars, "scalars", 1)
        c = _as_float_array(colors, "colors", 2)
        r = _as_float_array(extinction, "extinction", 1)
        n = s.shape[0]
        if n < 2:
            raise ValueError(f"TransferFunction needs at least 2 control points, got {n}")
        if c.shape != (n, 3):
            raise ValueError(f"TransferFunction colors must have shape ({n}, 3), got {c.shape}")
        if r.shape != (n,):
            raise ValueError(f"TransferFunction extinction must have shape ({n},), got {r.shape}")
        steps = np.diff(s)
        if np.any(steps <= 0):
            bad = int(np.argmax(steps <= 0))
            raise ValueError(
                f"TransferFunction scalars must be strictly increasing; scalars[{bad}]={s[bad]!r} >= "
                f"scalars[{bad + 1}]={s[bad + 1]!r}"
            )
        if np.any(c < 0):
            raise ValueError("TransferFunction colors must be >= 0")
        if np.any(r < 0):
            raise ValueError("TransferFunction extinction must be >= 0")
        if not isinstance(name, str):
            raise ValueError(f"TransferFunction name must be a string, got {type(name).__name__}")
        for arr in (s, c, r):
            arr.setflags(write=False)
        self._scalars, self._colors, self._extinction, self.name = s, c, r, name

    # -- data -------------------------------------------------------------------------------------------------------
    @property
    def scalars(self) -> np.ndarray:
        """Control-point scalars (n,), read-only."""
        return self._scalars

    @property
    def colors(self) -> np.ndarray:
        """Chromaticity κ at the control points (n, 3), read-only."""
        return self._colors

    @property
    def extinction(self) -> np.ndarray:
        """Extinction ρ at the control points (n,), read-only."""
        return self._extinction

    @property
    def range(self) -> tuple[float, float]:
        """(first, last) control-point scalar; outside it the medium is transparent."""
        return float(self._scalars[0]), float(self._scalars[-1])

    def __len__(self) -> int:
        return int(self._scalars.shape[0])

    def __repr__(self) -> str:
        lo, hi = self.range
        return (f"TransferFunction(name={self.name!r}, n={len(self)}, range=({lo:g}, {hi:g}), "
                f"max_rho={self.max_extinction:g})")

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, TransferFunction):
            return NotImplemented
        return (
            self.name == other.name
            and np.array_equal(self._scalars, other._scalars)
            and np.array_equal(self._colors, other._colors)
            and np.array_equal(self._extinction, other._extinction)
        )

    __hash__ = None  # type: ignore[assignment]

    def __copy__(self) -> "TransferFunction":
        return self  # immutable: a copy (of a session holding it, say) shares it, as it would share a string

    def __deepcopy__(self, memo: dict[int, Any]) -> "TransferFunction":
        return self

    @property
    def max_extinction(self) -> float:
        """max ρ over the range (the maximum is at a control point)."""
        return float(self._extinction.max())

    # -- evaluation -------------------------------------------------------------------------------------------------
    def evaluate(self, s: Any) -> tuple[np.ndarray, np.ndarray]:
        """κ and ρ at scalars ``s`` (any shape): returns ``(rgb (..., 3), rho (...))`` float64.

        Linear interpolation between control points; outside the range and at NaN: (0, 0, 0) and 0.
        """
        x = np.asarray(s, dtype=np.float64)
        lo, hi = self.range
        inside = (x >= lo) & (x <= hi)  # False for NaN
        xs = np.where(inside, x, lo)
        rho = np.where(inside, np.interp(xs, self._scalars, self._extinction), 0.0)
        rgb = np.empty(x.shape + (3,), dtype=np.float64)
        for ch in range(3):
            rgb[..., ch] = np.where(inside, np.interp(xs, self._scalars, self._colors[:, ch]), 0.0)
        return rgb, rho

    def emission(self, s: Any) -> np.ndarray:
        """Emitted color density κ(s)·ρ(s) (..., 3)."""
        rgb, rho = self.evaluate(s)
        return rgb * rho[..., None]

    # -- edits ------------------------------------------------------------------------------------------------------
    def rescaled(self, lo: float, hi: float) -> "TransferFunction":
        """The same shape mapped linearly onto the scalar range [lo, hi]."""
        lo, hi = float(lo), float(hi)
        if not (np.isfinite(lo) and np.isfinite(hi) and hi > lo):
            raise ValueError(f"rescaled range must be finite with hi > lo, got ({lo}, {hi})")
        a, b = self.range
        s = lo + (self._scalars - a) * ((hi - lo) / (b - a))
        s[0], s[-1] = lo, hi
        return TransferFunction(s, self._colors, self._extinction, self.name)

    def scaled_extinction(self, factor: float) -> "TransferFunction":
        """ρ multiplied by ``factor`` ≥ 0 (e.g. a density slider)."""
        factor = float(factor)
        if not (np.isfinite(factor) and factor >= 0):
            raise ValueError(f"extinction factor must be finite and >= 0, got {factor}")
        return TransferFunction(self._scalars, self._colors, self._extinction * factor, self.name)

    # -- serialisation ----------------------------------------------------------------------------------------------
    def to_dict(self) -> dict:
        """JSON-safe dict (plain lists of floats) for session files."""
        return {
            "format": _DICT_FORMAT,
            "version": _DICT_VERSION,
            "name": self.name,
            "scalars": [float(v) for v in self._scalars],
            "colors": [[float(v) for v in row] for row in self._colors],
            "extinction": [float(v) for v in self._extinction],
        }

    @classmethod
    def from_dict(cls, d: Any) -> "TransferFunction":
        """Inverse of :meth:`to_dict`; raises ValueError naming the offending field."""
        if not isinstance(d, dict):
            raise ValueError(f"transfer function must be a dict, got {type(d).__name__}")
        fmt = d.get("format", _DICT_FORMAT)
        if fmt != _DICT_FORMAT:
            raise ValueError(f"transfer function 'format' must be {_DICT_FORMAT!r}, got {fmt!r}")
        version = d.get("version", _DICT_VERSION)
        if not isinstance(version, int) or version > _DICT_VERSION or version < 1:
            raise ValueError(f"transfer function 'version' {version!r} is not supported (max {_DICT_VERSION})")
        for key in ("scalars", "colors", "extinction"):
            if key not in d:
                raise ValueError(f"transfer function dict is missing field {key!r}")
        name = d.get("name", "")
        if not isinstance(name, str):
            raise ValueError("transfer function field 'name' must be a string")
        for key in ("scalars", "colors", "extinction"):
            try:
                np.asarray(d[key], dtype=np.float64)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"transfer function field {key!r} is not a numeric array") from exc
        return cls(d["scalars"], d["colors"], d["extinction"], name=name)

    # -- common shapes ----------------------------------------------------------------------------------------------
    @classmethod
    def ramp(cls, lo: float = 0.0, hi: float = 1.0, rho_max: float = 1.0, color: Any = (1.0, 1.0, 1.0),
             name: str = "ramp") -> "TransferFunction":
        """ρ rising linearly from 0 at ``lo`` to ``rho_max`` at ``hi``, constant color."""
        c = np.asarray(color, dtype=np.float64)
        return cls([lo, hi], [c, c], [0.0, rho_max], name=name)
