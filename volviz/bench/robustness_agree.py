"""What a read holds, in terms both sides of the robustness campaign share, and the campaign's "valid as damaged"
judgment (``volviz bench robustness``, issue #32).

A file cut short can still be a valid file of its format: an EnSight case file cut right after its ``GEOMETRY``
section is a case without variables. The campaign's own judgment (``robustness._judge``) compares a read with the
read of the undamaged file and calls any difference after a truncation *garbage*: it cannot tell such a file from
silently wrong data. A second, independent reader can: when VTK's reader of the format reads the cut file to the same
content as volviz (``content`` of each frame: point count, bounds, and every data array's size, sum, minimum and
maximum, compared without names or order, as the two readers name and order arrays differently), the case is *valid
as damaged*. Only truncations are judged so: a cut file holds nothing that contradicts what it still says, while a
changed header field that both readers follow alike (VTK checks few counts) is still an inconsistent file.
"""
from __future__ import annotations

import math
from typing import Any, Optional

import numpy as np

#: fields of the volviz model holding data arrays (codec schema names): one array, or a mapping of named arrays
DATA_FIELDS = ("data", "scalars", "arrays", "point_data", "cell_data")
RTOL = 1e-5


def array_summary(values: Any) -> list[float]:
    """``[count, sum, min, max, non-finite count]`` of an array's values (as float64; sums of the finite ones)."""
    flat = np.asarray(values).real.astype(np.float64, copy=False).ravel()
    finite = flat[np.isfinite(flat)]
    if not finite.size:
        return [float(flat.size), 0.0, 0.0, 0.0, float(flat.size)]
    return [float(flat.size), float(finite.sum()), float(finite.min()), float(finite.max()),
            float(flat.size - finite.size)]


def content_volviz(frame: Any) -> dict:
    """A volviz dataset's ``content``: its point count, bounds (of its points, or of its grid) and the summaries of
    its data arrays (each array object once)."""
    seen: dict[int, Any] = {}
    for name in DATA_FIELDS:
        value = getattr(frame, name, None)
        for a in (value.values() if isinstance(value, dict) else [value]):
            if isinstance(a, np.ndarray):
                seen.setdefault(id(a), a)
    bounds: Optional[list[float]] = None
    points = getattr(frame, "points", None)
    if isinstance(points, np.ndarray) and points.ndim >= 2 and points.size:
        points = points.reshape(-1, points.shape[-1])          # a curvilinear grid's (nx, ny, nz, 3)
        padded = np.zeros((len(points), 3))
        padded[:, :min(3, points.shape[1])] = points[:, :3]
        bounds = [float(v) for lo, hi in zip(padded.min(axis=0), padded.max(axis=0)) for v in (lo, hi)]
    elif type(frame).__name__ == "RegularVolume":
        dims = np.asarray(frame.data.shape[:3]) - 1
        lo, hi = np.asarray(frame.origin, float), np.asarray(frame.origin, float) + np.asarray(frame.spacing) * dims
        bounds = [float(v) for a, b in zip(lo, hi) for v in (min(a, b), max(a, b))]
    return {"n": int(getattr(frame, "n_points", 0)), "bounds": bounds,
            "arrays": sorted(array_summary(a) for a in seen.values())}


def content_vtk(leaves: list[Any]) -> dict:
    """The ``content`` of VTK's output (its data set leaves): point count and bounds over the leaves, each point or
    cell array's summary over the leaves that hold it (by name: a multiblock's parts are one mesh in volviz)."""
    # VTK's NumPy bridge: only for a dataset VTK read
    from vtkmodules.util.numpy_support import vtk_to_numpy

    n, bounds = 0, None
    parts: dict[tuple[str, str], list[np.ndarray]] = {}
    for leaf in leaves:
        n += leaf.GetNumberOfPoints()
        if leaf.GetNumberOfPoints():
            b = list(leaf.GetBounds())
            bounds = b if bounds is None else [min(bounds[i], b[i]) if i % 2 == 0 else max(bounds[i], b[i])
                                               for i in range(6)]
        for where, data in (("point", leaf.GetPointData()), ("cell", leaf.GetCellData())):
            for i in range(data.GetNumberOfArrays()):
                a = data.GetArray(i)
                if a is not None:
                    parts.setdefault((where, a.GetName() or str(i)), []).append(vtk_to_numpy(a))
    return {"n": int(n), "bounds": bounds,
            "arrays": sorted(array_summary(np.concatenate([np.ravel(p) for p in ps])) for ps in parts.values())}


def _close(a: float, b: float, scale: float) -> bool:
    return math.isclose(a, b, rel_tol=RTOL, abs_tol=RTOL * max(scale, 1e-30))


def same_content(a: list[dict], b: list[dict]) -> bool:
    """Whether two reads (lists of frame ``content``) hold the same: frame for frame the same point count, bounds
    and multiset of array summaries (sums, minima and maxima within ``RTOL`` of the array's magnitude)."""
    if len(a) != len(b) or not a:
        return False
    for fa, fb in zip(a, b):
        if fa["n"] != fb["n"] or len(fa["arrays"]) != len(fb["arrays"]):
            return False
        if (fa["bounds"] is None) != (fb["bounds"] is None):
            return False
        if fa["bounds"] is not None:
            scale = max(abs(v) for v in fa["bounds"] + fb["bounds"])
            if not all(_close(x, y, scale) for x, y in zip(fa["bounds"], fb["bounds"])):
                return False
        for sa, sb in zip(fa["arrays"], fb["arrays"]):
            scale = max(abs(sa[2]), abs(sa[3]), abs(sb[2]), abs(sb[3])) * max(sa[0], 1.0)
            if sa[0] != sb[0] or sa[4] != sb[4] or not all(_close(x, y, scale) for x, y in zip(sa[1:4], sb[1:4])):
                return False
    return True


def valid_as_damaged(kind: str, answers: dict[str, dict]) -> bool:
    """A truncated file that volviz and VTK's reader both read, without a doubt stated, to the same content: a
    valid file of the format as it was cut (see the module)."""
    if kind != "truncate" or set(answers) != {"volviz", "vtk"}:
        return False
    ours, theirs = answers["volviz"], answers["vtk"]
    if ours.get("status") != "ok" or theirs.get("status") != "ok" or ours.get("warned") or ours.get("problem"):
        return False
    return same_content(ours.get("content") or [], theirs.get("content") or [])
