"""The transfer-function editor's histogram of a component selected later (issue #5, TF editor "over the data
histogram" and "Background work"): a component hidden at load has none yet; its data is read and the histogram
computed on a worker while the editor shows a placeholder, and a newer selection supersedes it. Under Xvfb with real
widgets and real rendering."""
from __future__ import annotations

import json
import threading
from pathlib import Path

import numpy as np

from conftest import data_file
from loop_latency import LoopGaps
from test_app_workflows import wait_loaded  # a helper shared with it (the make_window fixture is in conftest.py)


def test_histogram_of_a_later_selected_component_is_computed_in_the_background(qtbot, make_window,
                                                                               tmp_path: Path) -> None:
    session = tmp_path / "two.json"
    session.write_text(json.dumps({
        "format": "volviz-session", "version": 1,
        "datasets": [{"id": "neghip", "path": str(data_file("volumes/neghip.slc"))},
                     {"id": "embryo", "path": str(data_file("volumes/embryo.slc"))}],
        "transfer_functions": {"embryo-tf": {"format": "volviz-transfer-function", "version": 1, "scalars": [0.0, 80.0, 255.0], "colors": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
                                             "extinction": [0.0, 0.5, 1.0]}},
        "components": [{"id": "small", "type": "volume", "dataset": "neghip"},
                       {"id": "big", "type": "volume", "dataset": "embryo", "visible": False,
                        "transfer_function": "embryo-tf"}]}))
    window = make_window()
    window.resize(1000, 600)
    qtbot.wait(300)  # the viewport's resize handling is over
    window.open_path(session)
    wait_loaded(qtbot, window)
    assert "big" not in window.controller.histograms
    canvas = window.tf_editor.canvas
    gaps = LoopGaps()
    window.scene_tree.tree.setCurrentItem(window.scene_tree.item("big"))  # what a click on it does
    assert canvas.histogram_pending and canvas.histogram is None, "the histogram was computed on the GUI thread"
    qtbot.waitUntil(lambda: window.histograms_computed == 1, timeout=120000)
    gaps.stop()
    assert not canvas.histogram_pending
    assert threading.main_thread().ident not in window.histogram_threads
    from volviz.model.stats import histogram

    counts, edges = histogram(window.controller.dataset_of("big"))
    assert np.array_equal(canvas.histogram, counts) and np.array_equal(canvas.histogram_edges, edges)
    assert window.tf_editor._data_range == (float(edges[0]), float(edges[-1]))
    print(gaps.summary())
    gaps.assert_responsive("for a histogram", 5)
    # a newer selection supersedes: the small volume's (precomputed) histogram shows at once and stays
    window.controller.histograms.pop("big")
    window.scene_tree.tree.setCurrentItem(window.scene_tree.item("big"))
    window.scene_tree.tree.setCurrentItem(window.scene_tree.item("small"))
    small = window.controller.histograms["small"]
    assert not canvas.histogram_pending and np.array_equal(canvas.histogram, small[0])
    qtbot.waitUntil(lambda: "big" in window.controller.histograms or not window.jobs.runner.active, timeout=60000)
    qtbot.wait(200)
    assert np.array_equal(canvas.histogram, small[0]) and window.histograms_computed == 1
