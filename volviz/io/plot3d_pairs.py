"""PLOT3D files come in pairs, a grid (xyz) and a solution (q): which file of a pair is which, and the grid that a
solution file opened alone belongs to (found by name, as ``companion_q_file`` finds a grid's solution)."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Optional, Sequence

from volviz.io.plot3d import read_flow_conditions

#: (solution, grid) name parts: ``bluntfinq.bin`` -> ``bluntfinxyz.bin``, ``wing.q`` -> ``wing.x`` / ``wing.xyz``
_NAME_PAIRS = (("q", "xyz"), ("Q", "XYZ"), (".q", ".x"), (".q", ".xyz"))


def is_plot3d_solution(path: str | os.PathLike) -> bool:
    """Whether ``path`` reads as a PLOT3D solution file (its flow-conditions header parses)."""
    try:
        read_flow_conditions(Path(path))
    except Exception:  # noqa: BLE001 -- any failure means: not a solution file
        return False
    return True


def grid_of_solution(path: str | os.PathLike) -> Optional[Path]:
    """The grid file next to the solution file ``path`` whose name matches it (None when there is none)."""
    p = Path(path)
    name = p.name
    for q, g in _NAME_PAIRS:
        if q in name:
            grid = p.with_name(name[::-1].replace(q[::-1], g[::-1], 1)[::-1])
            if grid != p and grid.is_file():
                return grid
    return None


def grid_and_solution(paths: Sequence[str | os.PathLike]) -> Optional[tuple[Path, Path]]:
    """``(grid, solution)`` when ``paths`` are the two files of a PLOT3D pair in either order, else None."""
    if len(paths) != 2:
        return None
    a, b = (Path(p) for p in paths)
    solution_a, solution_b = is_plot3d_solution(a), is_plot3d_solution(b)
    if solution_a == solution_b:
        return None
    return (b, a) if solution_a else (a, b)
