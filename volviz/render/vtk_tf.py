"""A ``volviz.optics.TransferFunction`` to and from VTK's transfer functions (``vtkColorTransferFunction`` for the
color κ, ``vtkPiecewiseFunction`` for the opacity a = ρ · unit distance, the convention for VTK's volume mappers in
docs/design.md "Opacity conventions differ"): what VTK's own mappers, the scalar bar and ParaView-style imports need.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from volviz.optics.transfer_function import TransferFunction

if TYPE_CHECKING:   # type-only: VTK's classes, reached through the facade at run time
    from volviz.render.vtk_facade import vtkColorTransferFunction, vtkPiecewiseFunction

__all__ = ["tf_from_vtk", "tf_to_vtk"]

#: the opacity function's last node is repeated this share of the span above the top (see ``tf_to_vtk``); closer,
#: VTK's GPU ray caster asks for an opacity texture fine enough to resolve it (a million texels at 1e-6) and warns
TOP_GUARD = 1e-3


def tf_from_vtk(ctf: vtkColorTransferFunction, otf: vtkPiecewiseFunction, unit_distance: float, name: str = "",
                samples: int = 256) -> TransferFunction:
    """From a ``vtkColorTransferFunction`` (κ) and a ``vtkPiecewiseFunction`` (opacity a): ρ = a / unit_distance.

    Control points are the union of both functions' nodes, which is exact when both interpolate linearly in RGB
    (color space RGB, every node midpoint 0.5 and sharpness 0). Otherwise (HSV/Lab/diverging color space or
    non-default midpoints) the functions are additionally sampled at ``samples`` evenly spaced scalars: the result
    is then a piecewise-linear approximation of VTK's curve. VTK clamps outside its range; volviz is transparent
    there (the range is the union of both functions' ranges). The guard node ``tf_to_vtk`` adds above the top (the
    last opacity node, ``TOP_GUARD`` of the span above the color function's last node, repeating its opacity) is
    left out.
    """
    unit_distance = float(unit_distance)
    if not (np.isfinite(unit_distance) and unit_distance > 0):
        raise ValueError(f"unit_distance must be finite and > 0, got {unit_distance}")
    n_c = int(ctf.GetSize())
    n_o = int(otf.GetSize())
    if n_c < 1 or n_o < 1:
        raise ValueError(f"VTK transfer functions must have nodes (color: {n_c}, opacity: {n_o})")
    cnodes = np.zeros((n_c, 6))
    onodes = np.zeros((n_o, 4))
    for i in range(n_c):
        val = [0.0] * 6
        ctf.GetNodeValue(i, val)
        cnodes[i] = val
    for i in range(n_o):
        val4 = [0.0] * 4
        otf.GetNodeValue(i, val4)
        onodes[i] = val4
    if n_o > 2 and _is_top_guard(onodes, cnodes[-1, 0]):
        onodes = onodes[:-1]
    exact = (
        int(ctf.GetColorSpace()) == 0  # VTK_CTF_RGB
        and np.allclose(cnodes[:, 4], 0.5, atol=1e-12, rtol=0) and np.allclose(cnodes[:, 5], 0.0, atol=1e-12)
        and np.allclose(onodes[:, 2], 0.5, atol=1e-12, rtol=0) and np.allclose(onodes[:, 3], 0.0, atol=1e-12)
    )
    s = np.unique(np.concatenate([cnodes[:, 0], onodes[:, 0]]))
    if s.size == 1:
        raise ValueError("VTK transfer functions span a single scalar; need a range")
    if exact:
        colors = np.stack([np.interp(s, cnodes[:, 0], cnodes[:, 1 + ch]) for ch in range(3)], axis=1)
        opacity = np.interp(s, onodes[:, 0], onodes[:, 1])
    else:
        s = np.unique(np.concatenate([s, np.linspace(s[0], s[-1], int(samples))]))
        c2, o2 = type(ctf)(), type(otf)()
        c2.DeepCopy(ctf)
        o2.DeepCopy(otf)
        c2.ClampingOn()
        o2.ClampingOn()
        colors = np.array([c2.GetColor(float(x)) for x in s], dtype=np.float64)
        opacity = np.array([o2.GetValue(float(x)) for x in s], dtype=np.float64)
    return TransferFunction(s, np.clip(colors, 0.0, None), np.clip(opacity, 0.0, None) / unit_distance, name=name)


def tf_to_vtk(tf: TransferFunction, unit_distance: float) -> tuple[vtkColorTransferFunction, vtkPiecewiseFunction]:
    """``tf`` as ``(vtkColorTransferFunction, vtkPiecewiseFunction)`` with opacity a = ρ · unit_distance.

    Set the same ``unit_distance`` as the volume property's ``ScalarOpacityUnitDistance``. Clamping is turned off
    on both, so VTK is transparent outside the range like volviz. Without clamping VTK's piecewise function counts
    its last node's own scalar as outside (``GetValue`` and the mappers' tables give 0 there), so a region of the
    data exactly at the function's top value drew transparent (a made sphere of the data's maximum came out hollow
    and blotchy): the last opacity is repeated ``TOP_GUARD`` of the span above the top, which VTK then counts as
    outside instead. Opacity values above 1 are kept as they are (VTK clamps them when it uses them), so round-trips
    (``tf_from_vtk``, which leaves the guard out) are exact.
    """
    unit_distance = float(unit_distance)
    if not (np.isfinite(unit_distance) and unit_distance > 0):
        raise ValueError(f"unit_distance must be finite and > 0, got {unit_distance}")
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    ctf = vtk.vtkColorTransferFunction()
    ctf.SetColorSpaceToRGB()
    ctf.ClampingOff()
    otf = vtk.vtkPiecewiseFunction()
    otf.ClampingOff()
    for s, (r, g, b), rho in zip(tf.scalars, tf.colors, tf.extinction):
        ctf.AddRGBPoint(float(s), float(r), float(g), float(b))
        otf.AddPoint(float(s), float(rho) * unit_distance)
    top = float(tf.scalars[-1])
    guard = max(top + TOP_GUARD * (top - float(tf.scalars[0])), float(np.nextafter(top, np.inf)))
    otf.AddPoint(guard, float(tf.extinction[-1]) * unit_distance)
    return ctf, otf


def _is_top_guard(onodes: np.ndarray, color_top: float) -> bool:
    """Whether the last of the opacity nodes (x, value, midpoint, sharpness) is ``tf_to_vtk``'s guard above the
    color function's top ``color_top``: just above it, repeating the opacity of the node at it."""
    (x0, a0), (x1, a1) = onodes[-2, :2], onodes[-1, :2]
    span = x0 - float(onodes[0, 0])
    reach = max(x0 + TOP_GUARD * span, float(np.nextafter(x0, np.inf)))
    return bool(x0 == color_top and a1 == a0 and x0 < x1 <= reach)
