"""PLOT3D whole-grid binary files (3D): a grid file (xyz) and an optional solution file (q).

Layouts, all detected from the file sizes (``vtkMultiBlockPLOT3DReader``'s auto-detection does the same):

- byte order little or big endian (the Blunt Fin in shared/data is big-endian, whatever its README says);
- with or without Fortran record markers (a 4-byte length before and after each record);
- single-grid (``ni nj nk``) or multi-grid (``nblocks`` then ``ni nj nk`` per block);
- single or double precision; with or without an IBLANK integer per point.

xyz: ``ni nj nk`` then X(ni,nj,nk), Y, Z [, IBLANK] with i fastest.
q:   ``ni nj nk``, then ``fsmach alpha re time``, then Q(ni,nj,nk,5) = density, momentum (3), stagnation energy.

Trailing padding of less than 512 bytes is accepted (the Blunt Fin q file is padded to a 512-byte block).

Derived functions follow vtkMultiBlockPLOT3DReader's definitions (checked numerically against it in
tests/test_io_plot3d.py), with gas constant R = 1, gamma = 1.4, free stream rho_inf = 1, c_inf = 1,
p_inf = 1/gamma, V_inf = fsmach. Where the density is 0 it is replaced by 1 for the derived quantities (as VTK).
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import product
from pathlib import Path

import numpy as np

from volviz.io._checks import check_finite, describe_dims, file_size, read_at, read_bytes
from volviz.io.errors import PathLike, ReadError, bytes_and_size
from volviz.model import CurvilinearGrid

PADDING_LIMIT = 512  # bytes of trailing padding accepted after the last record
DERIVED = ("Velocity", "VelocityMagnitude", "KineticEnergy", "Pressure", "Temperature", "Enthalpy", "SoundSpeed",
           "MachNumber", "PressureCoefficient", "Entropy")


@dataclass(frozen=True)
class Plot3DLayout:
    """One concrete binary layout of a PLOT3D file, as detected (or forced) for reading."""

    byteorder: str          # "<" or ">"
    record_markers: bool
    multigrid: bool
    precision: int          # 4 or 8 bytes per real
    iblanking: bool
    dims: tuple[tuple[int, int, int], ...]
    header_end: int         # offset of the first data record (its marker, if any)


@dataclass(frozen=True)
class FlowConditions:
    """The four free-stream values of a q file (``fsmach alpha re time``) and the gamma used."""

    fsmach: float
    alpha: float
    re: float
    time: float
    gamma: float = 1.4


def _ints(buf: bytes, offset: int, count: int, bo: str) -> list[int] | None:
    if offset + 4 * count > len(buf):
        return None
    return [int(v) for v in np.frombuffer(buf, dtype=bo + "i4", count=count, offset=offset)]


def _header(buf: bytes, bo: str, markers: bool, multigrid: bool):
    """Parse the dimension header; returns (dims per block, offset after header) or None if implausible."""
    pos = 0
    nblocks = 1
    if multigrid:
        if markers:
            m = _ints(buf, 0, 1, bo)
            if m != [4] or _ints(buf, 8, 1, bo) != [4]:
                return None
            nblocks = _ints(buf, 4, 1, bo)[0]  # type: ignore[index]
            pos = 12
        else:
            got = _ints(buf, 0, 1, bo)
            if got is None:
                return None
            nblocks, pos = got[0], 4
        if not 1 <= nblocks <= 100_000:
            return None
    nbytes = 12 * nblocks
    if markers:
        if _ints(buf, pos, 1, bo) != [nbytes]:
            return None
        pos += 4
    values = _ints(buf, pos, 3 * nblocks, bo)
    if values is None:
        return None
    pos += nbytes
    if markers:
        if _ints(buf, pos, 1, bo) != [nbytes]:
            return None
        pos += 4
    dims = tuple(tuple(values[3 * b:3 * b + 3]) for b in range(nblocks))
    if any(d <= 0 for block in dims for d in block):
        return None
    return dims, pos


def _xyz_block_bytes(dims, precision: int, iblank: bool) -> int:
    n = dims[0] * dims[1] * dims[2]
    return n * (3 * precision + (4 if iblank else 0))


def _q_block_bytes(dims, precision: int) -> tuple[int, int]:
    n = dims[0] * dims[1] * dims[2]
    return 4 * precision, 5 * n * precision


def _expected_size(kind: str, layout_dims, header_end: int, markers: bool, precision: int, iblank: bool) -> int:
    total = header_end
    for dims in layout_dims:
        if kind == "xyz":
            total += _xyz_block_bytes(dims, precision, iblank) + (8 if markers else 0)
        else:
            cond, q = _q_block_bytes(dims, precision)
            total += cond + q + (16 if markers else 0)
    return total


def detect_layout(path: PathLike, kind: str, head: bytes, size: int, *, byteorder: str | None = None,
                  record_markers: bool | None = None, multigrid: bool | None = None,
                  precision: int | None = None, iblanking: bool | None = None) -> Plot3DLayout:
    """Find the layout whose sizes match the file (``kind`` is "xyz" or "q"); ReadError if none does."""
    bos = [byteorder] if byteorder else ["<", ">"]
    if any(b not in ("<", ">") for b in bos):
        raise ValueError(f"byteorder must be '<' or '>', got {byteorder!r}")
    exact, padded, tried = [], [], []
    for bo, mk, mg in product(bos, [record_markers] if record_markers is not None else [False, True],
                              [multigrid] if multigrid is not None else [False, True]):
        parsed = _header(head, bo, mk, mg)
        if parsed is None:
            continue
        dims, header_end = parsed
        for prec, ib in product([precision] if precision else [4, 8],
                                ([iblanking] if iblanking is not None else [False, True]) if kind == "xyz"
                                else [False]):
            need = _expected_size(kind, dims, header_end, mk, prec, ib)
            layout = Plot3DLayout(bo, mk, mg, prec, ib, dims, header_end)
            tried.append((need, layout))
            if need == size:
                exact.append(layout)
            elif need < size < need + PADDING_LIMIT:
                padded.append((size - need, layout))
    if exact:
        return _check_markers(path, kind, head, exact[0])
    if padded:
        return _check_markers(path, kind, head, min(padded, key=lambda t: t[0])[1])
    if not tried:
        raise ReadError(path, f"not a PLOT3D {kind} file: no byte order or record layout gives a plausible "
                              f"dimension header (first bytes {head[:16].hex()})")
    need, best = min(tried, key=lambda t: abs(t[0] - size))
    desc = ", ".join(describe_dims(d) for d in best.dims[:3]) + (" ..." if len(best.dims) > 3 else "")
    raise ReadError(path, f"PLOT3D {kind} header claims {len(best.dims)} block(s) of {desc} points, which needs "
                          f"{bytes_and_size(need)} in the closest layout "
                          f"({'big' if best.byteorder == '>' else 'little'}-endian, "
                          f"{'with' if best.record_markers else 'no'} record markers, "
                          f"{'double' if best.precision == 8 else 'single'} precision), "
                          f"but the file holds {bytes_and_size(size)}")


def is_plot3d_grid(head: bytes, size: int | None = None) -> bool:
    """Whether ``head`` starts a PLOT3D grid (xyz) file of ``size`` bytes: a layout whose dimension header gives
    exactly that size (or up to ``PADDING_LIMIT`` less), as ``detect_layout`` reads it. The registry's sniffer for
    the names PLOT3D shares with text point clouds (``*.xyz``): a text table read as integers claims far more
    bytes than it holds (issue #32: a point cloud with a damaged first row was taken for PLOT3D by its name).
    ``size`` None (not known): a plausible header in some layout and zero bytes in the head (binary integers)."""
    if size is None:
        return b"\0" in head[:16] and any(_header(head, bo, mk, mg) is not None
                                          for bo, mk, mg in product("<>", (False, True), (False, True)))
    try:
        detect_layout("<sniff>", "xyz", head, size)
    except ReadError:
        return False
    return True


def _check_markers(path: PathLike, kind: str, head: bytes, layout: Plot3DLayout) -> Plot3DLayout:
    if layout.record_markers:
        expect = (_xyz_block_bytes(layout.dims[0], layout.precision, layout.iblanking) if kind == "xyz"
                  else 4 * layout.precision)
        got = _ints(head, layout.header_end, 1, layout.byteorder)
        if got is not None and got != [expect]:
            raise ReadError(path, f"first PLOT3D data record marker is {got[0]}, expected {expect}")
    return layout


def _block_offset(kind: str, layout: Plot3DLayout, block: int) -> int:
    pos = layout.header_end
    for dims in layout.dims[:block]:
        if kind == "xyz":
            pos += _xyz_block_bytes(dims, layout.precision, layout.iblanking)
        else:
            pos += sum(_q_block_bytes(dims, layout.precision))
        pos += (8 if kind == "xyz" else 16) if layout.record_markers else 0
    return pos


def _choose_block(path: PathLike, layout: Plot3DLayout, block: int | None) -> int:
    n = len(layout.dims)
    if block is None:
        if n > 1:
            raise ReadError(path, f"multi-block PLOT3D file with {n} blocks: pass block=0..{n - 1} to pick one")
        return 0
    if not 0 <= block < n:
        raise ReadError(path, f"block {block} requested but the file has {n} block(s)")
    return block


def read_plot3d_xyz(path: PathLike, block: int | None = None,
                    **layout_options) -> tuple[np.ndarray, np.ndarray | None, Plot3DLayout]:
    """Grid points (ni, nj, nk, 3) float64, IBLANK (ni, nj, nk) int32 or None, and the detected layout."""
    size = file_size(path)
    head = read_bytes(path, 65536)
    layout = detect_layout(path, "xyz", head, size, **layout_options)
    b = _choose_block(path, layout, block)
    dims = layout.dims[b]
    n = dims[0] * dims[1] * dims[2]
    pos = _block_offset("xyz", layout, b) + (4 if layout.record_markers else 0)
    raw = read_at(path, pos, _xyz_block_bytes(dims, layout.precision, layout.iblanking))
    real = f"{layout.byteorder}f{layout.precision}"
    coords = np.frombuffer(raw, dtype=real, count=3 * n).astype(np.float64)
    check_finite(path, coords, False, "grid coordinates")
    points = np.stack([coords[k * n:(k + 1) * n].reshape(dims, order="F") for k in range(3)], axis=-1)
    iblank = None
    if layout.iblanking:
        iblank = np.frombuffer(raw, dtype=layout.byteorder + "i4", count=n, offset=3 * n * layout.precision)
        iblank = iblank.astype(np.int32).reshape(dims, order="F")
    return points, iblank, layout


def read_plot3d_q(path: PathLike, block: int | None = None, allow_nonfinite: bool = True, gamma: float = 1.4,
                  **layout_options) -> tuple[np.ndarray, FlowConditions, Plot3DLayout]:
    """Solution Q (ni, nj, nk, 5) in the file's precision, the flow conditions and the detected layout."""
    size = file_size(path)
    head = read_bytes(path, 65536)
    layout = detect_layout(path, "q", head, size, **layout_options)
    b = _choose_block(path, layout, block)
    dims = layout.dims[b]
    mk = 4 if layout.record_markers else 0
    pos = _block_offset("q", layout, b)
    real = f"{layout.byteorder}f{layout.precision}"
    cond_bytes, q_bytes = _q_block_bytes(dims, layout.precision)
    cond = np.frombuffer(read_at(path, pos + mk, cond_bytes), dtype=real).astype(np.float64)
    check_finite(path, cond, False, "q header (fsmach, alpha, re, time)")
    q = np.frombuffer(read_at(path, pos + cond_bytes + 3 * mk, q_bytes), dtype=real)
    q = q.astype(q.dtype.newbyteorder("="))
    check_finite(path, q, allow_nonfinite, "q solution")
    q = q.reshape(dims + (5,), order="F")
    fsmach, alpha, re, time = (float(v) for v in cond)
    return q, FlowConditions(fsmach, alpha, re, time, gamma=gamma), layout


def derived_functions(q: np.ndarray, cond: FlowConditions, r_gas: float = 1.0) -> dict[str, np.ndarray]:
    """VTK's standard PLOT3D functions computable pointwise from Q, in float64.

    rho, m, e = Q[...,0], Q[...,1:4], Q[...,4]; v = m / rho; p = (gamma - 1)(e - rho |v|^2 / 2);
    T = p / (rho R); h = gamma p / ((gamma - 1) rho); c = sqrt(gamma p / rho); Mach = |v| / c;
    Cp = (p - p_inf) / (rho_inf V_inf^2 / 2); s = R/(gamma-1) ln((p / p_inf) / (rho / rho_inf)^gamma).
    """
    with np.errstate(all="ignore"):  # non-finite results are reported by the caller's finite check
        return _derived(q, cond, r_gas)


def _derived(q: np.ndarray, cond: FlowConditions, r_gas: float) -> dict[str, np.ndarray]:
    g = cond.gamma
    q64 = q.astype(np.float64)
    rho = q64[..., 0].copy()
    rho[rho == 0.0] = 1.0
    mom = q64[..., 1:4]
    e = q64[..., 4]
    vel = mom / rho[..., None]
    v2 = np.einsum("...i,...i->...", vel, vel)
    p = (g - 1.0) * (e - 0.5 * rho * v2)
    c = np.sqrt(g * p / rho)
    rho_inf, c_inf = 1.0, 1.0
    p_inf = rho_inf * c_inf * c_inf / g
    v_inf = cond.fsmach * c_inf
    out = {
        "Velocity": vel,
        "VelocityMagnitude": np.sqrt(v2),
        "KineticEnergy": 0.5 * v2,
        "Pressure": p,
        "Temperature": p / (rho * r_gas),
        "Enthalpy": g * p / ((g - 1.0) * rho),
        "SoundSpeed": c,
        "MachNumber": np.sqrt(v2) / c,
        "PressureCoefficient": (p - p_inf) / (0.5 * rho_inf * v_inf * v_inf) if v_inf != 0 else None,
        "Entropy": r_gas / (g - 1.0) * np.log((p / p_inf) / (rho / rho_inf) ** g),
    }
    return {k: v for k, v in out.items() if v is not None}


def read_plot3d(xyz_path: PathLike, q_path: PathLike | None = None, *, block: int | None = None,
                functions: tuple[str, ...] | None = DERIVED, gamma: float = 1.4, r_gas: float = 1.0,
                allow_nonfinite: bool = True, **layout_options) -> CurvilinearGrid:
    """Read a PLOT3D grid (and solution) into a CurvilinearGrid.

    With a q file the point data holds ``Density``, ``Momentum`` (vector), ``StagnationEnergy`` (file precision)
    and the requested derived ``functions`` (float64; names as vtkMultiBlockPLOT3DReader). ``Density`` is active.
    Layout options (``byteorder``, ``record_markers``, ``multigrid``, ``precision``, ``iblanking``) restrict the
    auto-detection. Derived values that come out NaN/Inf (negative pressure, ...) raise ReadError unless
    ``allow_nonfinite``.
    """
    unknown = set(functions or ()) - set(DERIVED)
    if unknown:
        raise ValueError(f"unknown PLOT3D functions {sorted(unknown)}; available: {', '.join(DERIVED)}")
    points, iblank, layout = read_plot3d_xyz(xyz_path, block, **layout_options)
    point_data: dict[str, np.ndarray] = {}
    if q_path is not None:
        q_options = {k: v for k, v in layout_options.items() if k != "iblanking"}
        q_options.setdefault("byteorder", layout.byteorder)
        q, cond, _ = read_plot3d_q(q_path, block, allow_nonfinite, gamma, **q_options)
        if q.shape[:3] != points.shape[:3]:
            raise ReadError(q_path, f"q dimensions {describe_dims(q.shape[:3])} differ from the grid's "
                                    f"{describe_dims(points.shape[:3])} in {xyz_path}")
        point_data["Density"] = np.ascontiguousarray(q[..., 0])
        point_data["Momentum"] = np.ascontiguousarray(q[..., 1:4])
        point_data["StagnationEnergy"] = np.ascontiguousarray(q[..., 4])
        derived = derived_functions(q, cond, r_gas)
        for name in functions or ():
            if name in derived:
                check_finite(q_path, derived[name], allow_nonfinite, f"derived function {name}")
                point_data[name] = derived[name]
    if iblank is not None:
        point_data["IBlank"] = iblank
    return CurvilinearGrid(points, point_data, active="Density" if q_path is not None else None,
                           source=str(xyz_path))


def read_flow_conditions(q_path: PathLike, block: int | None = None, gamma: float = 1.4,
                         **layout_options) -> FlowConditions:
    """Only the free-stream values of a q file (VTK puts them in the field array ``Properties``)."""
    return read_plot3d_q(q_path, block, True, gamma, **layout_options)[1]


def companion_q_file(xyz_path: PathLike):
    """The q file next to an xyz file by the usual naming (``bluntfinxyz.bin`` -> ``bluntfinq.bin``), or None."""
    p = Path(xyz_path)
    name = p.name
    for a, b in (("xyz", "q"), ("XYZ", "Q"), (".x", ".q"), (".X", ".Q")):
        if a in name:
            cand = p.with_name(name[::-1].replace(a[::-1], b[::-1], 1)[::-1])
            if cand != p and cand.is_file():
                return cand
    return None
