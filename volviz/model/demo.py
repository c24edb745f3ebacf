"""The built-in procedural demo data: generated, never read from disk (docs/design.md "Model only what a scene
needs")."""
from __future__ import annotations

import numpy as np

from volviz.model.datasets import TetMesh


def demo_scalar_field(points: np.ndarray) -> np.ndarray:
    """An analytic field on [-1, 1]^3: two soft blobs and a spherical shell (Roettger Fig. 8.3's sphere distance)."""
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    blob_a = np.exp(-((x - 0.35) ** 2 + (y - 0.2) ** 2 + (z + 0.1) ** 2) / 0.08)
    blob_b = 0.8 * np.exp(-((x + 0.4) ** 2 + (y + 0.3) ** 2 + (z - 0.25) ** 2) / 0.05)
    shell = 0.6 * np.exp(-((np.sqrt(x * x + y * y + z * z) - 0.75) ** 2) / 0.004)
    return blob_a + blob_b + shell


def demo_tet_mesh(n: int = 16) -> TetMesh:
    """A tetrahedralised cube [-1, 1]^3 with ``n`` cells per edge carrying ``demo_scalar_field`` (5 tets per cube)."""
    # PyVista (VTK, heavy): the model stays VTK-free until the demo mesh is made
    import pyvista as pv

    if n < 1:
        raise ValueError(f"demo mesh needs at least one cell per edge, got {n}")
    grid = pv.ImageData(dimensions=(n + 1, n + 1, n + 1), spacing=(2.0 / n,) * 3, origin=(-1.0, -1.0, -1.0))
    tets = grid.triangulate()
    points = np.asarray(tets.points, dtype=np.float64)
    connectivity = tets.cells_dict[10]
    return TetMesh(points, connectivity, demo_scalar_field(points), name="demo field", source="procedural demo")
