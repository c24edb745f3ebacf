"""The iso-spectrum fits of an isosurface component's translucent surfaces are made with its surfaces
(``volviz.scene.isosurfaces.isosurface_parts``, any thread: the app runs it on a worker), so that the actors made on
the GUI thread find them in ``fit_spectrum``'s cache; the first fit imports SciPy's optimizer (issue #28: a 169 ms
stall of the GUI thread in test_first_hour_flow[isosurfaces]: docs/bench/flow-gaps.md, survey 12)."""
from __future__ import annotations

import numpy as np

from volviz.iso import fit_spectrum
from volviz.model.datasets import RegularVolume
from volviz.scene.isosurfaces import isosurface_parts
from volviz.session import Component


def _ball() -> RegularVolume:
    x = np.linspace(-1.0, 1.0, 24)
    x, y, z = np.meshgrid(x, x, x, indexing="ij")
    return RegularVolume((x * x + y * y + z * z).astype(np.float32))


def test_the_translucent_surfaces_spectrum_fits_are_cached_with_the_surfaces() -> None:
    styles = [{"value": 0.3, "color": [1.0, 0.3, 0.2], "opacity": 0.43},     # translucent: scaled to 0.3655
              {"value": 0.6, "color": [0.2, 0.4, 1.0], "opacity": 1.0}]      # opaque (1.0 * 0.85): translucent too
    comp = Component("iso", "isosurface", "b", settings={"styles": styles}, opacity=0.85)
    fit_spectrum.cache_clear()
    parts = isosurface_parts(comp, _ball())
    opacities = sorted(float(m.style.opacity) for m in parts.shown)
    assert np.allclose(opacities, [0.43 * 0.85, 0.85])
    info = fit_spectrum.cache_info()
    assert info.currsize == 2 and info.misses == 2
    for opacity in opacities:                     # what the actors ask for: found, not fitted again
        fit_spectrum(opacity)
    assert fit_spectrum.cache_info().hits == 2 and fit_spectrum.cache_info().misses == 2


def test_opaque_surfaces_ask_for_no_fit() -> None:
    comp = Component("iso", "isosurface", "b", settings={"styles": [{"value": 0.3, "color": [1, 1, 1], "opacity": 1}]})
    fit_spectrum.cache_clear()
    isosurface_parts(comp, _ball())
    assert fit_spectrum.cache_info().currsize == 0
