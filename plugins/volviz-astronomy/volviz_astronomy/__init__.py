"""volviz reader plugin: the data cubes of astronomy, read by the field's own library.

Registered through the ``volviz.readers`` entry point (``volviz_astronomy.specs:SPECS``); ``volviz.io.read``
dispatches to the loaders here, each run in volviz's isolated reader process (``volviz.io.isolated``):

- FITS (.fits, .fit, .fts, gzip-compressed or tile-compressed): image cubes through astropy
  (``volviz_astronomy.fits``): spectral cubes of radio and optical astronomy, simulation outputs.
"""
from volviz_astronomy.specs import SPECS

__all__ = ["SPECS"]
