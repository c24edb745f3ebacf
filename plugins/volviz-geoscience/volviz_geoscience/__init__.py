"""volviz reader plugin: the data of geoscience, read by the field's own libraries.

Registered through the ``volviz.readers`` entry point (``volviz_geoscience.specs:SPECS``); ``volviz.io.read``
dispatches to the loaders here, each run in volviz's isolated reader process (``volviz.io.isolated``):

- SEG-Y (.sgy, .segy): post-stack seismic cubes and 2D sections through segyio (``volviz_geoscience.segy``), placed
  in the survey's own frame in metres with time (or depth) downwards.
- LAS / LAZ (.las, .laz): lidar point clouds through laspy (``volviz_geoscience.las``), at their own coordinates,
  coloured by elevation first, with intensity, classification, returns, GPS time and colours as arrays.
"""
from volviz_geoscience.specs import SPECS

__all__ = ["SPECS"]
