"""Natural scenes (Roettger Ch. 3, 5, 10, 11): terrain C-LOD with geomorphing, sky dome, PCP ground fog and cloud
layers, volumetric C-LOD clouds with morphing, Perlin-noise generators and CPU frames.

Modules: ``heightfield`` (2^n + 1 grids), ``terrain`` (quadtree C-LOD), ``noise`` (Perlin / fBm generators),
``raster`` (terrain z-buffer, sky), ``fog`` (PCP prisms), ``clouds`` (octree C-LOD + renderer), ``sky`` (dome mesh),
``nature_scene`` (``NatureScene``, ``scene_from_components``, ``demo_scene``). The views that put a scene in a plotter
are in ``volviz.render`` (``nature_view``, ``gl_nature``).
"""
