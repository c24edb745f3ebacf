"""The benchmarks of ``volviz bench NAME`` (one module each). Those that draw figures need matplotlib, an optional
dependency (``pip install 'volviz[bench]'``)."""
from __future__ import annotations

import importlib.util
from typing import Any

from volviz.argtypes import UsageError

#: the benchmarks whose reports include matplotlib figures
PLOTTING = ("tables", "unstructured", "compression", "nature", "iso", "lod_frames")


def require_plotting(name: str) -> None:
    """A UsageError before a plotting benchmark starts when matplotlib is missing (not after minutes of work)."""
    if name in PLOTTING and importlib.util.find_spec("matplotlib") is None:
        raise UsageError(f"volviz bench {name} draws its figures with matplotlib, which is not installed: "
                         "pip install 'volviz[bench]'")


def pyplot() -> Any:
    """matplotlib's pyplot on the Agg (file) backend."""
    import matplotlib  # optional (volviz[bench]): only the benches that draw figures

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # after use("Agg"), which must come first

    return plt
