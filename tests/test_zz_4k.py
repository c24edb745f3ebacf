import pytest
from conftest import data_file
from flows import wait_loaded, wait_settled, drag_viewport
from loop_latency import LoopGaps

@pytest.mark.parametrize("rel", ["bluntfin/bluntfinxyz.bin", ])
def test_zz(qtbot, make_window, rel):
    window = make_window(); window.resize(3800, 2100); window.show()
    gaps = LoopGaps()
    window.open_path(data_file(rel))
    wait_loaded(qtbot, window); wait_settled(qtbot, window)
    print(rel, window.plotter.ren_win.GetSize(), "open:", gaps.summary(), sorted(round(b*1000) for b in gaps.blocked)[-6:])
    gaps.restart()
    drag_viewport(qtbot, window, 300, 0); wait_settled(qtbot, window)
    print(rel, "drag:", gaps.summary(), sorted(round(b*1000) for b in gaps.blocked)[-6:])
    gaps.stop()
