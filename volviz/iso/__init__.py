"""Multiple semi-transparent isosurfaces from several, possibly overlapping, time-varying volumes (the libMini note,
Roettger 2007): extraction, order-independent compositing modes, iso-spectrum shading, 4D animation, clipping and
view-dependent LOD. Entry points for a scene builder: ``IsoSettings``, ``prepare`` (background) and ``render_iso``
(per view). The VTK actors of the surfaces are made in ``volviz.render`` (``iso_spectrum.iso_actor``)."""
from volviz.iso.animate import IsoAnimator, IsoFrame, extract_at, playback_times
from volviz.iso.clip import clip_isosurface, clip_isosurfaces, clip_tetmesh, clip_volume
from volviz.iso.composite import MODES, composite, fragments, render, render_modes
from volviz.iso.extract import IsoMesh, IsoStyle, extract, extract_many
from volviz.iso.lod import LodChain, build_lod, lod_mesh, lod_meshes, select_level
from volviz.iso.component import IsoSettings, PreparedIso, prepare, render_iso
from volviz.iso.spectrum import SpectrumFit, fit_spectrum, spectrum_alpha

__all__ = ["IsoAnimator", "IsoFrame", "extract_at", "playback_times", "clip_isosurface", "clip_isosurfaces",
           "clip_tetmesh", "clip_volume", "MODES", "composite", "fragments",
           "render", "render_modes", "IsoMesh", "IsoStyle", "extract", "extract_many", "LodChain", "build_lod",
           "lod_mesh", "lod_meshes", "select_level", "IsoSettings", "PreparedIso", "prepare", "render_iso",
           "SpectrumFit", "fit_spectrum", "spectrum_alpha"]
