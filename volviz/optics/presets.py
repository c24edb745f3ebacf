"""ParaView color-map JSON presets: import, export, and the presets shipped in ``resources/presets``.

ParaView's preset files hold a list (or one) of objects with ``"Name"``, ``"ColorSpace"``, ``"RGBPoints"``
(flat x, r, g, b, …) and optionally ``"Points"`` (flat x, opacity, midpoint, sharpness, …). volviz reads them as:

- κ from ``RGBPoints``, linearly interpolated in RGB. Other color spaces (``"Diverging"``, ``"Lab"``, ``"HSV"``) are
  read as linear RGB between the given points: an approximation that is close when the points are dense (the
  shipped presets are RGB with 33 points).
- ρ = opacity / unit_distance from ``Points`` (the VTK convention of docs/design.md "Opacity conventions differ";
  midpoint and sharpness are ignored, i.e. read as 0.5 and 0). Without ``Points`` the opacity is a linear ramp from 0
  to 1 over the color range (ParaView's default for volumes).
- Both are combined on the union of their control points, which is exact for piecewise-linear inputs.

Export writes ``"ColorSpace": "RGB"``, both point lists (opacity = ρ · unit_distance, midpoint 0.5, sharpness 0) and
``"VolvizUnitDistance"``, which import uses when present, so a round trip returns the same function.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import volviz_resources

from volviz.io.atomic import atomic_write_text
from volviz.optics.transfer_function import TransferFunction

__all__ = ["list_presets", "load_preset", "preset_path", "tf_from_paraview", "tf_to_paraview",
           "read_paraview_presets", "write_paraview_presets"]


def _presets_dir() -> Path:
    return volviz_resources.path("presets")


def list_presets() -> list[str]:
    """Names (file stems) of the presets shipped in ``resources/presets``, sorted."""
    return sorted(p.stem for p in _presets_dir().glob("*.json"))


def preset_path(name: str) -> Path:
    """Path of a shipped preset by name (with or without ``.json``); ValueError naming the known presets."""
    stem = name[:-5] if name.endswith(".json") else name
    path = _presets_dir() / f"{stem}.json"
    if not path.is_file():
        raise ValueError(f"unknown preset {name!r}; available: {', '.join(list_presets())}")
    return path


def load_preset(name: str, unit_distance: float | None = None) -> TransferFunction:
    """The first transfer function of a shipped preset (see ``list_presets``) or of a ParaView JSON file path."""
    path = Path(name)
    if not (path.suffix == ".json" and path.is_file()):
        path = preset_path(name)
    tfs = read_paraview_presets(path, unit_distance=unit_distance)
    return tfs[0]


def _flat(obj: dict, key: str, width: int, where: str) -> np.ndarray:
    raw = obj[key]
    try:
        arr = np.asarray(raw, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{where}: {key!r} must be a flat list of numbers") from exc
    if arr.ndim != 1 or arr.size == 0 or arr.size % width:
        raise ValueError(f"{where}: {key!r} must be a flat list with a multiple of {width} numbers, got {arr.size}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{where}: {key!r} contains NaN or Inf")
    pts = arr.reshape(-1, width)
    if np.any(np.diff(pts[:, 0]) < 0):
        raise ValueError(f"{where}: {key!r} x values must be non-decreasing")
    return pts


def _dedupe(x: np.ndarray, vals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Drop repeated x (keep the last, ParaView's behaviour for a jump is not representable in a continuous TF)."""
    keep = np.append(np.diff(x) > 0, True)
    return x[keep], vals[keep]


def tf_from_paraview(obj: Any, unit_distance: float | None = None) -> TransferFunction:
    """One ParaView preset object → TransferFunction (see module docstring)."""
    if not isinstance(obj, dict):
        raise ValueError(f"a ParaView preset must be a JSON object, got {type(obj).__name__}")
    name = obj.get("Name", "")
    where = f"preset {name!r}"
    if "RGBPoints" not in obj:
        raise ValueError(f"{where}: missing 'RGBPoints'")
    rgb = _flat(obj, "RGBPoints", 4, where)
    if unit_distance is None:
        unit_distance = float(obj.get("VolvizUnitDistance", 1.0))
    if not (np.isfinite(unit_distance) and unit_distance > 0):
        raise ValueError(f"{where}: unit distance must be finite and > 0, got {unit_distance}")
    cx, cv = _dedupe(rgb[:, 0], rgb[:, 1:4])
    if "Points" in obj:
        op = _flat(obj, "Points", 4, where)
        ox, ov = _dedupe(op[:, 0], op[:, 1])
    else:
        ox, ov = np.array([cx[0], cx[-1]]), np.array([0.0, 1.0])
    s = np.union1d(cx, ox)
    if s.size < 2:
        raise ValueError(f"{where}: needs at least two distinct scalars")
    colors = np.stack([np.interp(s, cx, cv[:, ch]) for ch in range(3)], axis=1)
    opacity = np.interp(s, ox, ov)
    if np.any(colors < 0) or np.any(opacity < 0):
        raise ValueError(f"{where}: colors and opacities must be >= 0")
    return TransferFunction(s, colors, opacity / unit_distance, name=str(name))


def tf_to_paraview(tf: TransferFunction, unit_distance: float = 1.0) -> dict:
    """TransferFunction → one ParaView preset object (JSON-safe)."""
    if not (np.isfinite(unit_distance) and unit_distance > 0):
        raise ValueError(f"unit_distance must be finite and > 0, got {unit_distance}")
    rgb_points: list[float] = []
    points: list[float] = []
    for s, (r, g, b), rho in zip(tf.scalars, tf.colors, tf.extinction):
        rgb_points += [float(s), float(r), float(g), float(b)]
        points += [float(s), float(rho) * unit_distance, 0.5, 0.0]
    return {"Name": tf.name, "ColorSpace": "RGB", "Creator": "volviz", "RGBPoints": rgb_points, "Points": points,
            "VolvizUnitDistance": float(unit_distance)}


def read_paraview_presets(path: str | Path, unit_distance: float | None = None) -> list[TransferFunction]:
    """All presets of a ParaView JSON file (a list of objects or one object). Errors name the file."""
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"{path}: cannot read ParaView preset JSON: {exc}") from exc
    items = data if isinstance(data, list) else [data]
    if not items:
        raise ValueError(f"{path}: no presets in file")
    try:
        return [tf_from_paraview(obj, unit_distance) for obj in items]
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from exc


def write_paraview_presets(path: str | Path, tfs: TransferFunction | list[TransferFunction],
                           unit_distance: float = 1.0) -> None:
    """Write one or more transfer functions as a ParaView preset list (atomically: the old file survives a failure)."""
    items = [tfs] if isinstance(tfs, TransferFunction) else list(tfs)
    text = "[\n" + ",\n".join(_format(tf_to_paraview(t, unit_distance)) for t in items) + "\n]\n"
    atomic_write_text(path, text)


def _format(obj: dict) -> str:
    """One preset object as JSON with one control point (4 numbers) per line."""
    fields = []
    for key, value in obj.items():
        if isinstance(value, list):
            rows = [", ".join(json.dumps(v) for v in value[i:i + 4]) for i in range(0, len(value), 4)]
            text = "[\n      " + ",\n      ".join(rows) + "\n    ]"
        else:
            text = json.dumps(value)
        fields.append(f"    {json.dumps(key)}: {text}")
    return "  {\n" + ",\n".join(fields) + "\n  }"
