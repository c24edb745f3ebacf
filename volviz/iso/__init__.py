"""Multiple semi-transparent isosurfaces from several, possibly overlapping, time-varying volumes (the libMini note,
Roettger 2007): extraction, order-independent compositing modes, 4D animation, clipping and view-dependent LOD."""
