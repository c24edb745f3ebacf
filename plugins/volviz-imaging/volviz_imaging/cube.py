"""Gaussian cube files (``.cube``, ``.cub``): electron densities, orbitals, electrostatic potentials and spin
densities from Gaussian's cubegen, ORCA, Psi4, PySCF, CP2K, Quantum ESPRESSO's pp.x and VASP tools.

The layout (Gaussian's cubegen documentation): two comment lines; the atom count and the grid's origin (a negative
count: an orbital cube, whose atom list is followed by the count and indices of its orbitals); three lines of a
point count and the step vector of each grid axis (a positive first count: Bohr, negative: Angstrom); one line per
atom; then the values, the third axis fastest, each orbital's value in turn at every point.

- Shown in Angstrom, as molecular viewers show cubes (1 Bohr = 0.529177210903 Angstrom).
- Placement: origin + i v1 + j v2 + k v3 through ``placement.aligned_volume`` (skewed cells, e.g. a periodic
  crystal's, are put on their nearest axes with a warning).
- An orbital cube shows its first orbital (``orbital=N`` picks orbital N by its number in the file, the others are
  named in a warning).
- The header's counts are held against the file's length before the values are parsed: each value takes at least
  two characters (a digit and a separator).

VTK's own reader (vtkGaussianCubeReader2) puts the grid at the origin with unit spacing, away from the molecule,
so the file is read here.
"""
from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

from volviz.io._checks import check_file, parse_float, parse_int, read_bytes
from volviz.io.errors import ChoiceWarning, PathLike, ReadError, human_bytes
from volviz.model import RegularVolume

from volviz_imaging.placement import aligned_volume

BOHR_IN_ANGSTROM = 0.529177210903
MAX_HEADER_LINES = 10_000_000   # atoms plus the orbital line: a header longer than this is not a cube file's


def _fields(p: Path, line: bytes, count: int, what: str) -> list[bytes]:
    fields = line.split()
    if len(fields) < count:
        raise ReadError(p, f"its {what} line has {len(fields)} fields, needs {count}")
    return fields


def _header(p: Path, lines: list[bytes]) -> tuple[np.ndarray, np.ndarray, bool, int]:
    """The voxel-to-world affine (in the file's unit), the grid's point counts, whether the unit is Angstrom, and the
    number of atoms (negative for an orbital cube)."""
    if len(lines) < 6:
        raise ReadError(p, "is shorter than a cube file's header (2 comment lines, the origin, 3 axis lines)")
    first = _fields(p, lines[2], 4, "atom count and origin")
    n_atoms = parse_int(p, first[0], "atom count")
    affine = np.eye(4)
    affine[:3, 3] = [parse_float(p, v, "origin") for v in first[1:4]]
    counts = []
    for axis in range(3):
        fields = _fields(p, lines[3 + axis], 4, f"axis {axis + 1}")
        counts.append(parse_int(p, fields[0], f"point count of axis {axis + 1}"))
        affine[:3, axis] = [parse_float(p, v, f"step of axis {axis + 1}") for v in fields[1:4]]
    angstrom = counts[0] < 0
    shape = np.abs(np.asarray(counts, dtype=np.int64))
    if np.any(shape < 1):
        raise ReadError(p, f"its grid has {' x '.join(map(str, counts))} points")
    if abs(n_atoms) > MAX_HEADER_LINES:
        raise ReadError(p, f"its atom count {n_atoms} is not one a cube file holds")
    return affine, shape, angstrom, n_atoms


def read_cube(path: PathLike, orbital: int | None = None, allow_nonfinite: bool = True) -> RegularVolume:
    """A Gaussian cube file as a volume in Angstrom (see the module)."""
    p = check_file(path)
    content = read_bytes(p)
    affine, shape, angstrom, n_atoms = _header(p, content.split(b"\n", 6))
    header_lines = 6 + abs(n_atoms) + (1 if n_atoms < 0 else 0)
    rows = content.split(b"\n", header_lines)
    if len(rows) <= header_lines:
        raise ReadError(p, f"ends inside its header ({abs(n_atoms)} atom lines announced)")
    orbitals = [1]
    if n_atoms < 0:
        listed = rows[header_lines - 1].split()
        n_orbitals = parse_int(p, listed[0], "orbital count") if listed else 0
        if n_orbitals < 1 or len(listed) < n_orbitals + 1:
            raise ReadError(p, "its orbital line does not list the orbitals it announces")
        orbitals = [parse_int(p, v, "orbital number") for v in listed[1:n_orbitals + 1]]
    n_values = int(np.prod(shape)) * len(orbitals)
    text = rows[header_lines]
    if 2 * n_values > len(text) + 1:
        raise ReadError(p, f"its header announces {' x '.join(map(str, shape))} points x {len(orbitals)} value(s) "
                           f"({n_values} numbers), more than its {human_bytes(len(text))} of values can hold")
    try:
        values = np.fromstring(text.replace(b"D", b"E").replace(b"d", b"e"), dtype=np.float64, sep=" ")
    except ValueError:                  # NumPy stops at a token that is not a number
        raise ReadError(p, "holds text that is not a number among its values") from None
    if values.size != n_values:
        raise ReadError(p, f"holds {values.size} readable values where its header announces {n_values} "
                           f"({' x '.join(map(str, shape))} points x {len(orbitals)})")
    chosen = _chosen_orbital(p, orbitals, orbital)
    data = values.reshape(tuple(shape) + (len(orbitals),))[..., chosen].astype(np.float32)
    if not angstrom:
        affine[:3, :] *= BOHR_IN_ANGSTROM
    name = f"orbital {orbitals[chosen]}" if n_atoms < 0 else "density"
    if not math.isfinite(float(np.abs(affine).sum())):
        raise ReadError(p, "its origin or axis steps are not finite")
    return aligned_volume(p, data, affine, name, allow_nonfinite=allow_nonfinite)


def _chosen_orbital(p: Path, orbitals: list[int], orbital: int | None) -> int:
    """The index (in the file's list) of the orbital to show; a warning names the others."""
    if orbital is not None and orbital not in orbitals:
        raise ReadError(p, f"holds no orbital {orbital}; its orbitals are {', '.join(map(str, orbitals))}")
    chosen = orbitals.index(orbital) if orbital is not None else 0
    if len(orbitals) > 1:
        how = "as asked" if orbital is not None else "the first"
        warnings.warn(ChoiceWarning(f"{p}: holds {len(orbitals)} orbitals; showing {how}, orbital "
                                    f"{orbitals[chosen]}. Others: "
                                    f"{', '.join(str(n) for n in orbitals if n != orbitals[chosen])} (orbital=N "
                                    "picks one)", p, "orbital", orbitals[chosen], orbitals,
                                    [f"orbital {n}" for n in orbitals]), stacklevel=3)
    return chosen
