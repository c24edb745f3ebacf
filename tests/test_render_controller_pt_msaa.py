"""PT volumes over opaque geometry in a plotter with multisampling on (PyVista's default): no one-pixel edges around
opaque silhouettes (volviz.render.pt_prop switches MSAA off while a PT volume is in the plotter, and back on after).
Real offscreen VTK rendering; the composite equals the exact reference with the read-back depth limit blended over
the same opaque image (RMSE <= 1, max <= 4 of 255; with MSAA on the silhouettes were off by up to 18)."""
from __future__ import annotations

import numpy as np
import pytest

pv = pytest.importorskip("pyvista")

from volviz.optics import TransferFunction  # noqa: E402
from volviz.render.pt_prop import add_pt_volume  # noqa: E402
from volviz.unstructured import synthetic as syn  # noqa: E402
from volviz.unstructured.render import render  # noqa: E402

TF = TransferFunction([0.0, 0.3, 0.6, 0.9], [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]], [0.0, 3.0, 6.0, 1.0])
SIZE = (256, 192)


def test_pt_volume_over_multisampled_opaque_geometry_has_no_edge_artifacts() -> None:
    mesh = syn.box_tets(6)
    pl = pv.Plotter(off_screen=True, window_size=list(SIZE))
    pl.ren_win.SetMultiSamples(4)
    pl.set_background("black")
    # an opaque plane through the left half of the cube, a sphere in front of its right part: many silhouettes
    pl.add_mesh(pv.Plane(center=(0.25, 0.5, 0.5), direction=(0, 1, 0), i_size=1.2, j_size=0.5),
                color=(0.8, 0.6, 0.2), lighting=False)
    pl.add_mesh(pv.Sphere(radius=0.12, center=(0.75, -0.4, 0.75)), color=(0.2, 0.6, 0.9), lighting=False)
    pl.camera_position = [(0.6, -2.5, 0.9), (0.5, 0.5, 0.5), (0, 0, 1)]
    try:
        handle = add_pt_volume(pl, mesh, TF)
        assert pl.ren_win.GetMultiSamples() == 0
        handle.visible = False
        opaque = pl.screenshot(return_img=True).astype(np.float64) / 255.0
        handle.visible = True
        shot = pl.screenshot(return_img=True).astype(np.float64) / 255.0
        ref = render(mesh, TF, handle.camera, SIZE, "reference", depth=handle.depth)
        expected = ref[..., :3] + (1.0 - ref[..., 3:]) * opaque
        d = (shot - expected) * 255.0
        assert np.sqrt((d ** 2).mean()) <= 1.0 and np.abs(d).max() <= 4.0
        assert np.abs(shot - opaque).max() > 0.5  # the volume is on screen
        handle.remove()
        assert pl.ren_win.GetMultiSamples() == 4  # antialiasing is back once no PT volume is left
    finally:
        pl.close()
