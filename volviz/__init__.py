"""volviz: accurate, fast volume rendering of scientific data and natural scenes (Qt-free core library)."""
import os as _os
import sys as _sys

__version__ = "0.1.0"

# Parallel Numba kernels run from several threads at once (the UI thread and the background job runner). Numba's
# default "workqueue" threading layer aborts the process when that happens; the "threadsafe" choice picks OpenMP
# (libgomp) or TBB, which allow it.
_os.environ.setdefault("NUMBA_THREADING_LAYER", "threadsafe")
if "numba" in _sys.modules:  # imported before volviz: still early enough while no parallel kernel has run
    _sys.modules["numba"].config.THREADING_LAYER = _os.environ["NUMBA_THREADING_LAYER"]
