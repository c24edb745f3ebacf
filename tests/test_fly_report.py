"""``volviz-app --flight-report``'s flight (issue #28): W held over Yukon in the real window; the report gives the
frame rate and the event loop's gaps, each also less the time the GUI thread waited for a CPU (``blocked``), the size
the flight's frames were drawn at, and the time from the release to the full-resolution frame."""
from __future__ import annotations

from conftest import data_file


def test_a_short_flight_report(qtbot, qapp, make_window) -> None:
    from volviz_app.flight_report import fly, markdown

    data_file("yukon/Yukon.map.pgm")
    window = make_window()
    result = fly(qapp, window, None, 1.0)
    assert result["steps"] == window.fly.steps >= 2 and result["frames"] >= 1
    assert 0.0 <= result["blocked_max_ms"] <= result["gap_max_ms"] + 1e-9
    assert 0 <= result["blocked_over_100ms"] <= result["gaps_over_100ms"]
    w, h = (int(v) for v in result["viewport"].split("x"))
    assert result["reduced_size"] == f"{(w + 1) // 2}x{(h + 1) // 2}" and 1 <= result["reduced_frames"]
    assert 0.0 < result["stop_s"] < 180.0 and result["stop_render_ms"] > 0.0   # the full-resolution frame came
    assert result["stop_gap_max_ms"] >= result["stop_render_ms"] - 1.0        # its render held the loop
    text = markdown(result, "volviz-app --flight-report out.md --flight-seconds 1")
    assert f"{result['steps']} camera steps" in text and f"longest {result['blocked_max_ms']:.0f} ms" in text
    assert f"Frames drawn while flying at {result['reduced_size']}" in text
