"""Natural scenes (Roettger Ch. 3, 5, 10, 11): terrain C-LOD with geomorphing, sky dome, PCP ground fog and cloud
layers, volumetric C-LOD clouds with morphing, Perlin-noise generators, CPU frames and a PyVista view.

Modules: ``heightfield`` (2^n + 1 grids), ``terrain`` (quadtree C-LOD), ``noise`` (Perlin / fBm generators),
``raster`` (terrain z-buffer, sky), ``fog`` (PCP prisms), ``clouds`` (octree C-LOD + renderer), ``sky`` (dome mesh),
``scene`` (``NatureScene``, ``NatureView``, ``build_nature_components``, ``demo_scene``).
"""
