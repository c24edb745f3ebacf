"""The benchmarks of ``volviz bench NAME`` (one module each). Those that draw figures need matplotlib, an optional
dependency (``pip install 'volviz[bench]'``)."""
from __future__ import annotations

from typing import Any

from volviz.argtypes import UsageError

#: the benchmarks whose reports include matplotlib figures
PLOTTING = ("tables", "unstructured", "compression", "nature", "iso", "lod_frames")


def require_plotting(name: str) -> None:
    """A UsageError before a plotting benchmark starts when matplotlib is missing (not after minutes of work)."""
    import importlib.util

    if name in PLOTTING and importlib.util.find_spec("matplotlib") is None:
        raise UsageError(f"volviz bench {name} draws its figures with matplotlib, which is not installed: "
                         "pip install 'volviz[bench]'")


def pyplot() -> Any:
    """matplotlib's pyplot on the Agg (file) backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt
