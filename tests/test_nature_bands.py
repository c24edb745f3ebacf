"""Row bands dealt out to threads (volviz.nature.raster.dealt_band): every band exactly once, each thread's
contiguous share of iterations spread over the whole image."""
from __future__ import annotations

from volviz.nature.raster import dealt_band, dealt_count


def test_every_band_is_drawn_exactly_once():
    for nb in range(1, 40):
        for threads in range(1, 9):
            got = [dealt_band(ii, nb, threads) for ii in range(dealt_count(nb, threads))]
            assert sorted(b for b in got if b >= 0) == list(range(nb)), (nb, threads)


def test_each_thread_gets_bands_from_top_to_bottom():
    per = dealt_count(16, 2) // 2
    first = [dealt_band(ii, 16, 2) for ii in range(per)]               # what thread 0 gets
    second = [dealt_band(ii, 16, 2) for ii in range(per, 2 * per)]
    assert first == list(range(0, 16, 2)) and second == list(range(1, 16, 2))
