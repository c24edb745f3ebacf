"""The note's transparency modes (2-pass, 3-pass, 4-pass, exact) with a regular volume in the scene (issue #28,
``volviz.render.iso_volume_split``): the volume in front of a translucent surface lies over it and the volume behind
under it, against the exact composite of the scene's own renders (``iso_volume_scene``: a plane through a ball, one
surface layer per ray, where every mode is the exact "over").

The surface image I (premultiplied, alpha α) is the CPU compositor's for the mode (``volviz.iso.composite.render``,
the overlay's own optics), V_f, a_f and F come from renders of VTK's actors (the surface made opaque black and white):
the expected frame is V_f + (1 − a_f)·I + (1 − α)·(F − V_f). Before the split the frames were far off on the
surface's pixels: the CPU overlay drew the surfaces over the finished scene, the whole volume under them (RMSE 26.9
levels); the GPU's 2/3/4 passes are blended before VTK's volume pass, the whole volume over them (RMSE 9.4); the
GPU's exact mode peels the surfaces over the finished scene (RMSE 28.0)."""
from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv

from iso_volume_scene import (STYLE, close_plotters, one_layer_composite, scene, shot,  # noqa: F401 (a fixture)
                              surface_image, two_layer_composite, volume_cut)
from volviz.iso.composite import MODES
from volviz.render.volume_peeling import peeling_volumes


def errors(c, p: pv.Plotter, mode: str) -> dict[str, float]:
    """The frame against the exact composite over the surface's pixels (α > 0.2), 8-bit units: rmse, max; and the
    same for the surface over the whole volume (``old_rmse``), the share of those pixels the frame changes from the
    volume alone by more than 3 levels (``changed``) and the surface's share of the frame (``share``)."""
    frame = shot(p)
    full, v_f, one_minus_a_f = volume_cut(c, p)
    surf = surface_image(c, p, mode)
    a_s = surf[..., 3]
    expected = one_layer_composite(full, v_f, one_minus_a_f, surf[..., :3], a_s)
    over_all = surf[..., :3] + (1.0 - a_s[..., None]) * full          # the surface over the whole volume
    on = a_s > 0.2
    err = np.abs(frame - expected)[on] * 255.0
    old = np.abs(over_all - expected)[on] * 255.0
    change = np.abs(frame - full).max(axis=-1)[on] * 255.0
    return {"rmse": float(np.sqrt((err ** 2).mean())), "max": float(err.max()),
            "over3": int((err.max(axis=-1) > 3.0).sum()), "pixels": int(on.sum()),
            "old_rmse": float(np.sqrt((old ** 2).mean())), "changed": float((change > 3.0).mean()),
            "share": float(on.mean())}


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("backend", ["cpu", "gpu"])
def test_every_mode_puts_the_surface_between_the_volume_in_front_and_behind(backend, mode):
    """Measured at 200 x 150 on llvmpipe over the surface's pixels (α > 0.2, 53 % of the frame), every mode with
    either backend's setting: RMSE 0.42, max 1.4 levels against the exact composite (made of 8-bit renders, and the
    overlay is 8-bit straight alpha: about one level each, hence the bounds 1 and 3); the surface over the whole
    volume RMSE 27. The frame differs from the volume alone by more than 3 levels on every such pixel."""
    c, p = scene(backend, iso_mode=mode)
    e = errors(c, p, mode)
    print(backend, mode, e)
    assert e["share"] > 0.3                                          # the surface fills much of the view
    assert e["rmse"] < 1.0 and e["max"] <= 3.0
    assert e["old_rmse"] > 5.0                                       # the order replaced is far off
    assert e["changed"] > 0.9


def test_a_regular_volume_draws_the_passes_by_the_cpu_overlay_and_exact_mode_peeled_with_it():
    """With a regular volume shown the 2/3/4-pass modes are drawn by the CPU overlay, whose volume is split at the
    surfaces (the GPU passes cannot be: VTK draws its volumes after them), on the GPU backend too; hidden, the GPU's
    passes again. Exact mode stays on the GPU, peeled by the renderer together with the volume (VTK's dual depth
    peeling, the volume by the GPU ray caster meanwhile), and by its own layer over the scene without the volume."""
    c, p = scene("gpu", iso_mode="3pass")
    assert c.iso_view.backend == "cpu" and c.iso_overlay is not None
    c.set_visible("vol", False)
    assert c.iso_view.backend == "gpu" and c.iso_overlay is None
    c.set_visible("vol", True)
    assert c.iso_view.backend == "cpu" and c.iso_view.mode == "3pass"
    assert len(c.iso_view.meshes) == 1
    c.set_iso_mode("exact")
    ren, mapper = p.renderer, c.props["vol"].GetMapper()
    assert c.iso_view.backend == "gpu" and c.iso_view.peels_volumes and peeling_volumes(p)
    assert ren.GetUseDepthPeeling() and ren.GetUseDepthPeelingForVolumes()
    assert mapper.GetRequestedRenderMode() == mapper.GPURenderMode
    c.set_visible("vol", False)                     # peeled by its own layer; the renderer's settings restored
    assert c.iso_view.backend == "gpu" and not c.iso_view.peels_volumes and not peeling_volumes(p)
    assert not ren.GetUseDepthPeelingForVolumes()
    c.set_visible("vol", True)
    assert c.iso_view.peels_volumes and peeling_volumes(p)
    c.set_iso_mode("2pass")
    assert c.iso_view.backend == "cpu" and not peeling_volumes(p) and not ren.GetUseDepthPeeling()


def test_exact_mode_on_the_gpu_composites_the_volume_between_two_layers():
    """Two parallel translucent planes through the ball's dense middle, each ray crossing both: the exact composite
    of the scene's own renders (the volume cut at each plane) against the frames. Measured at 200 x 150: the GPU's
    exact mode, peeled with the volume, RMSE 0.57 levels (bound 1.5: seven 8-bit pieces of about half a level each);
    the CPU overlay's split at the nearest layer RMSE 8.0 (the volume between the planes composited behind both); the
    surfaces over the whole volume 24-25."""
    styles = [dict(STYLE, value=10.0), dict(STYLE, value=21.0, color=[0.9, 0.2, 0.1])]
    errs = {}
    for backend in ("gpu", "cpu"):
        c, p = scene(backend, iso_mode="exact", styles=styles)
        assert c.iso_view.backend == backend
        frame = shot(p)
        exact, over_all, on = two_layer_composite(c, p)
        errs[backend] = rmse = float(np.sqrt(((frame - exact)[on] ** 2).mean()) * 255.0)
        old = float(np.sqrt(((over_all - exact)[on] ** 2).mean()) * 255.0)
        print(backend, "two layers: rmse", rmse, "| surfaces over the whole volume:", old, "| pixels", on.sum())
        assert on.sum() > 5000 and old > 15.0
    assert errs["gpu"] < 1.5 and errs["cpu"] > 2.0 * errs["gpu"]
