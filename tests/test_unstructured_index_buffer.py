"""The order as the GPU pass's index buffer (``volviz.unstructured.index_buffer``): the visible cells of the order,
in order, and the 4 faces of each as int32 vertex ids 4 c + corner (``topology.FACES``), written into buffers kept
between fills."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.unstructured.index_buffer import IndexBuffer
from volviz.unstructured.topology import FACES


def test_fill_gives_the_visible_cells_in_order_and_their_faces():
    rng = np.random.default_rng(5)
    m = 1000
    order = rng.permutation(m).astype(np.int32)
    visible = rng.random(m) < 0.7
    buf = IndexBuffer(m)
    offsets, conn, cells = buf.fill(order, visible)
    expect = order[visible[order]]
    assert np.array_equal(cells, expect) and len(cells) == visible.sum()
    assert conn.dtype == np.int32 and offsets.dtype == np.int32
    assert np.array_equal(conn.reshape(-1, 4, 3), 4 * expect[:, None, None] + FACES[None])
    assert np.array_equal(offsets, np.arange(0, 3 * (4 * len(expect) + 1), 3))
    # the next fill reuses the same memory: its views start where the first's did
    offsets2, conn2, cells2 = buf.fill(order[::-1].copy(), np.ones(m, bool))
    assert np.shares_memory(conn, conn2) and np.shares_memory(cells, cells2)
    assert np.array_equal(cells2, order[::-1]) and len(conn2) == 12 * m and offsets2[-1] == 12 * m


def test_an_int64_order_and_nothing_visible():
    buf = IndexBuffer(4)
    offsets, conn, cells = buf.fill(np.array([3, 1, 2, 0], np.int64), np.zeros(4, bool))
    assert len(cells) == 0 and len(conn) == 0 and offsets.tolist() == [0]
    offsets, conn, cells = buf.fill(np.array([3, 1], np.int64), np.array([False, True, False, True]))
    assert cells.tolist() == [3, 1] and conn[:3].tolist() == [13, 14, 15] and conn[12:15].tolist() == [5, 6, 7]


def test_bad_sizes_are_refused():
    with pytest.raises(ValueError, match="order of 5 cells for an index buffer of 4"):
        IndexBuffer(4).fill(np.arange(5), np.ones(5, bool))
    with pytest.raises(ValueError, match="too many tetrahedra for 32-bit vertex indices: 536870912"):
        IndexBuffer(2 ** 29)
