"""Compressed multiresolution and animated regular volumes (Guthe Ch. 2).

- ``codec``: ``compress`` / ``decompress`` / ``info`` of ``.vvz`` wavelet-octree files (§2.2.1-2.2.2, §2.3.1).
- ``lod``: ``LodTree`` (per-node statistics, on-demand node decoding, LRU cache), ``Camera``, ``LodTree.select``
  (P = E/z or the Eq. 2.7 TF bound, block budget, transparent-block skipping) and ``LodTree.blocks`` (§2.3.3-2.3.7).
- ``animation``: ``compress_series`` / ``decompress_series`` / ``SeriesPlayer`` (I/P/B with windowed motion
  compensation, one decode per displayed frame, 4D interpolation; §2.2.3).

Import the submodules directly (``from volviz.regular.lod import LodTree``); this package imports nothing eagerly
so that the Numba kernels compile only when used.
"""
