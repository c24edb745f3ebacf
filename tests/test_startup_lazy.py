"""Issue #30, time to the first image: the imports a fresh process defers to their first use. ``volviz.optics``
resolves its public names on first use (``import volviz.optics`` and its ``TransferFunction`` load no Numba, a
table's name loads the kernels it needs), and the render layer runs matplotlib's pyplot, which pyvista imports for
nothing a render uses, only when a name of it is used (``volviz.render.lazy_pyplot``)."""
from __future__ import annotations

import json
import os
import subprocess
import sys

from conftest import REPO, data_file


def _child(code: str) -> dict:
    """The JSON object the last line of ``code``'s output holds, run in a fresh interpreter (matplotlib on its file
    backend: no window of its own under the tests' display)."""
    done = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=300,
                          env={**os.environ, "MPLBACKEND": "Agg"})
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_optics_loads_no_numba_until_a_kernel_is_named() -> None:
    report = _child("""
import json, sys
import volviz.optics as optics
from volviz.optics import TransferFunction
tf = TransferFunction.ramp(0.0, 1.0)
before = "numba" in sys.modules or "scipy" in sys.modules
build = optics.build_table3d
from volviz.optics.table3d import build_table3d
names = {}
exec("from volviz.optics import *", names)
print(json.dumps({"before": before, "after": "numba" in sys.modules, "same": build is build_table3d,
                  "star": sorted(n for n in names if not n.startswith("__")), "all": sorted(optics.__all__),
                  "tf": TransferFunction is sys.modules["volviz.optics.transfer_function"].TransferFunction}))
""")
    assert report["before"] is False
    assert report["after"] is True and report["same"] is True and report["tf"] is True
    assert report["star"] == report["all"] and len(report["all"]) == 23


def test_optics_refuses_an_unknown_name() -> None:
    import pytest

    import volviz.optics

    with pytest.raises(AttributeError, match="no attribute 'build_table4d'"):
        getattr(volviz.optics, "build_table4d")


def test_a_render_runs_no_pyplot_and_pyplot_still_works(tmp_path) -> None:
    out = tmp_path / "v.png"
    report = _child(f"""
import json, sys
from volviz.cli import main
code = main(["render", {str(data_file("volumes/HeadMRVolume.mhd"))!r}, "-o", {str(out)!r}, "--size", "64x48"])
from volviz.render.lazy_pyplot import pyplot_ran
imported, ran, figure = "matplotlib.pyplot" in sys.modules, pyplot_ran(), "matplotlib.figure" in sys.modules
import matplotlib.pyplot as plt                      # a second import binds the same module, still not run
again = pyplot_ran()
fig = plt.figure(figsize=(2, 1))                     # the first use runs it in place
names = {{}}
exec("from matplotlib.pyplot import *", names)
print(json.dumps({{"code": code, "imported": imported, "ran": ran, "figure": figure, "again": again,
                  "now": pyplot_ran(), "same": sys.modules["matplotlib.pyplot"] is plt,
                  "fig": type(fig).__name__, "inches": [float(v) for v in fig.get_size_inches()],
                  "star": "subplots" in names}}))
""")
    assert out.stat().st_size > 0 and report["code"] == 0
    assert report["imported"] is True and report["ran"] is False and report["figure"] is False
    assert report["again"] is False and report["now"] is True and report["same"] is True
    assert report["fig"] == "Figure" and report["inches"] == [2.0, 1.0] and report["star"] is True


def test_a_render_of_a_regular_volume_loads_no_numba_scipy_or_lod_codec(tmp_path) -> None:
    """``scene.lod.is_lod`` asks whether a dataset is a LodTree without importing the LOD codec (a LodTree exists only
    once its module was imported), so drawing a plain regular volume loads neither the codec nor Numba nor SciPy;
    a LodTree is still recognised."""
    out = tmp_path / "h.png"
    report = _child(f"""
import json, sys
from volviz.cli import main
code = main(["render", {str(data_file("volumes/hydrogen.vti"))!r}, "-o", {str(out)!r}, "--size", "64x48"])
loaded = {{name: name in sys.modules for name in ("numba", "scipy", "volviz.regular.lod")}}
from volviz.scene.lod import is_lod
from volviz.regular.lod import LodTree
tree = LodTree.__new__(LodTree)
print(json.dumps({{"code": code, "loaded": loaded, "tree": is_lod(tree), "other": is_lod(object())}}))
""")
    assert out.stat().st_size > 0 and report["code"] == 0
    assert report["loaded"] == {"numba": False, "scipy": False, "volviz.regular.lod": False}
    assert report["tree"] is True and report["other"] is False


def test_a_render_runs_no_agg_backend_and_pyvistas_matplotlib_chart_still_draws(tmp_path) -> None:
    """pyvista's charts import the Agg backend's canvas for ``ChartMPL``: a render does not run the backend
    (``matplotlib.backend_bases``: text, fonts, mathtext), and a ``ChartMPL`` made afterwards runs it at its first
    canvas and is drawn."""
    out = tmp_path / "v.png"
    report = _child(f"""
import json, sys
import numpy as np
from volviz.cli import main
code = main(["render", {str(data_file("volumes/HeadMRVolume.mhd"))!r}, "-o", {str(out)!r}, "--size", "64x48"])
from volviz.render.lazy_pyplot import AGG, ran
before = {{"ran": ran(AGG), "bases": "matplotlib.backend_bases" in sys.modules}}
import matplotlib.pyplot as plt
import pyvista as pv
fig, ax = plt.subplots(figsize=(2, 2))
ax.plot([0, 1], [0, 1], color="red", linewidth=8)
chart = pv.ChartMPL(fig)
real = sys.modules[AGG].FigureCanvasAgg
plotter = pv.Plotter(off_screen=True, window_size=(120, 120))
plotter.set_background("white")
plotter.add_chart(chart)
image = np.asarray(plotter.screenshot(None, return_img=True))[..., :3].astype(int)
plotter.close()
red = int(((image[..., 0] > 200) & (image[..., 1] < 80) & (image[..., 2] < 80)).sum())
print(json.dumps({{"code": code, "before": before, "after": ran(AGG), "real": isinstance(chart._canvas, real),
                  "red": red}}))
""")
    assert report["code"] == 0 and report["before"] == {"ran": False, "bases": False}
    assert report["after"] is True and report["real"] is True and report["red"] > 50


def test_any_other_importer_of_the_agg_canvas_gets_the_class_itself(tmp_path) -> None:
    """The stand-in is pyvista's charts' alone: another ``from`` import of the canvas (matplotlib's Qt backend
    subclasses it) gets the real class, and the backend has run."""
    out = tmp_path / "v.png"
    report = _child(f"""
import json
from volviz.cli import main
code = main(["render", {str(data_file("volumes/HeadMRVolume.mhd"))!r}, "-o", {str(out)!r}, "--size", "64x48"])
from matplotlib.backends.backend_agg import FigureCanvasAgg
from volviz.render.lazy_pyplot import AGG, ran
class Canvas(FigureCanvasAgg):
    pass
from matplotlib.figure import Figure
canvas = Canvas(Figure(figsize=(1, 1), dpi=50))
canvas.draw()
print(json.dumps({{"code": code, "class": isinstance(FigureCanvasAgg, type), "ran": ran(AGG),
                  "size": list(canvas.buffer_rgba().shape)}}))
""")
    assert report == {"code": 0, "class": True, "ran": True, "size": [50, 50, 4]}
