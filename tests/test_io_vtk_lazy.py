"""The readers reach VTK through ``volviz.io.vtk_lazy`` (issue #30, time to the first image): a read imports only the
VTK modules its classes live in, never the whole ``vtk`` module (1.2-2 s of a reader child's cold start), and every
name still resolves to VTK's own object."""
from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pyvista as pv
import vtk

from volviz.io.vtk_lazy import MODULE_OF, LazyVTK


def test_every_listed_class_is_vtks_own():
    lazy = LazyVTK()
    for name, module in MODULE_OF.items():
        assert getattr(lazy, name) is getattr(vtk, name), name
        assert getattr(vtk, name).__module__ == f"vtkmodules.{module}", name
    assert lazy.VTK_DOUBLE == vtk.VTK_DOUBLE == 11
    assert lazy.vtkSphereSource is vtk.vtkSphereSource             # not listed: from the whole of VTK


def test_a_read_does_not_load_the_whole_of_vtk(tmp_path):
    """A fresh process reads a VTK XML image and mesh, isolation off so the reader runs there: the values are the
    file's and the ``vtk`` module was never imported."""
    grid = pv.ImageData(dimensions=(4, 5, 6))
    grid.point_data["f"] = np.arange(grid.n_points, dtype=np.float32)
    grid.save(tmp_path / "cube.vti")
    mesh = pv.Sphere().cast_to_unstructured_grid().delaunay_3d()
    mesh.point_data["h"] = mesh.points[:, 2]
    mesh.save(tmp_path / "ball.vtu")
    script = ("import sys\nimport numpy as np\nimport volviz.io as vio\n"
              "cube, ball = vio.read(sys.argv[1]), vio.read(sys.argv[2])\n"
              "print(cube.dimensions, float(np.asarray(cube.data).sum()), ball.n_points, 'vtk' in sys.modules)\n")
    done = subprocess.run([sys.executable, "-c", script, str(tmp_path / "cube.vti"), str(tmp_path / "ball.vtu")],
                          capture_output=True, text=True, timeout=300, env={**os.environ, "VOLVIZ_ISOLATE": "0"})
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["(4,", "5,", "6)", f"{float(np.arange(120).sum())}", str(mesh.n_points), "False"]
