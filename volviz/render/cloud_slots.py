"""Where the GPU keeps the C-LOD cloud leaves (Roettger §11.3-11.5), so that a frame uploads only the leaves it adds.

The GPU backend morphs the leaves itself (``resources/shaders/cloud_leaf_vs.glsl``: the weights of Eq. 11.6 and the
corrected Eq. 11.8 from the eye, per frame, on the GPU), so a leaf's texel never changes while the leaf stays in the
LOD mesh: its octree address (a, b, c, level) alone. ``LeafSlots`` keeps each leaf of the mesh in a slot of one
texel array that lives on the GPU; a frame's leaves that were already there keep their slots, the new ones get the
next free slots — one contiguous range, uploaded as one region — and the leaves that left free theirs for the next
compaction. When the range runs past the array's end, the live leaves are packed to its front and the array (twice
the live leaves, at least) is uploaded whole: a cost shared by the frames until the next compaction.

The draw order is the frame's back-to-front leaf order (§11.5) as slot numbers, preceded by the two reserved slots
0 and 1 (no leaf; their points are the volume's box corners, so that VTK's bounds of the points the draw uses are
always the whole box).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: slots 0 and 1: the volume's box corners for VTK's bounds, no leaf
RESERVED = 2
#: bytes per slot texel: a, b, c, level as RGBA float32 (exact integers below 2^24)
TEXEL_BYTES = 16
#: bytes per index of the draw order (32-bit)
INDEX_BYTES = 4


def leaf_keys(leaves: np.ndarray, roots: np.ndarray) -> np.ndarray:
    """A unique int64 per octree node (level, a, b, c) of a forest with ``roots`` (3,) root nodes per axis: the
    node's place in level-major dense order (every level's nodes, coarse to fine, C order within a level)."""
    leaves = np.asarray(leaves, np.int64)
    roots = np.asarray(roots, np.int64)
    lv = leaves[:, 0]
    top = int(lv.max()) + 1 if len(lv) else 1
    counts = np.array([int(np.prod(roots << level)) for level in range(top)], np.int64)
    base = np.concatenate([[0], np.cumsum(counts)])[lv]
    nb, nc = roots[1] << lv, roots[2] << lv
    return base + (leaves[:, 1] * nb + leaves[:, 2]) * nc + leaves[:, 3]


@dataclass
class SlotUpdate:
    """What a frame changes on the GPU: ``order`` (n + 2,) int32 the slots to draw, back to front after the two
    reserved ones; ``start`` and ``texels`` the region of the slot array to upload (``texels`` (k, 4) float32 from
    slot ``start``), or with ``whole`` the whole array (``texels`` is then all of it); ``added`` the leaves new to
    the mesh; ``capacity`` the array's slots."""

    order: np.ndarray
    start: int
    texels: np.ndarray
    whole: bool
    added: int
    capacity: int

    @property
    def upload_bytes(self) -> int:
        """Bytes sent to the GPU for this frame: the slot region and the draw order."""
        return int(self.texels.nbytes + len(self.order) * INDEX_BYTES)


class LeafSlots:
    """The slot array's contents on the CPU and the leaves' slots (module docstring). ``place`` runs on one thread
    at a time and its updates must reach the GPU in the order made (``CloudPTVolume`` applies them at the next
    render)."""

    def __init__(self, min_capacity: int = 1024) -> None:
        self.min_capacity = int(min_capacity)
        self.capacity = 0
        self.top = RESERVED                      # the next never-used slot since the last compaction
        self.texels = np.zeros((0, 4), np.float32)
        self._keys = np.zeros(0, np.int64)       # the mesh's leaves, sorted, and their slots
        self._slots = np.zeros(0, np.int32)

    @property
    def n_leaves(self) -> int:
        return int(len(self._keys))

    def place(self, leaves: np.ndarray, keys: np.ndarray) -> SlotUpdate:
        """The frame's ``leaves`` (n, 4: level, a, b, c; back to front) with their ``leaf_keys``: their slots in
        draw order and the region of the slot array to upload."""
        keys = np.asarray(keys, np.int64)
        n = len(keys)
        at = np.searchsorted(self._keys, keys)
        known = at < len(self._keys)
        known[known] = self._keys[at[known]] == keys[known]
        slots = np.full(n, -1, np.int32)
        slots[known] = self._slots[at[known]]
        new = np.flatnonzero(~known)
        rows = np.empty((n, 4), np.float32)
        rows[:, :3] = leaves[:, 1:]
        rows[:, 3] = leaves[:, 0]
        if self.top + len(new) > self.capacity:          # compaction: every leaf packed to the front
            self.capacity = max(self.min_capacity, 1 << int(np.ceil(np.log2(2 * (n + RESERVED)))))
            self.texels = np.zeros((self.capacity, 4), np.float32)
            self.texels[:RESERVED, 3] = -1.0              # no leaf
            slots = np.arange(RESERVED, RESERVED + n, dtype=np.int32)
            self.texels[RESERVED:RESERVED + n] = rows
            self.top = RESERVED + n
            start, texels, whole = 0, self.texels, True
        else:
            start = self.top
            slots[new] = np.arange(start, start + len(new), dtype=np.int32)
            self.texels[start:start + len(new)] = rows[new]
            self.top += len(new)
            texels, whole = self.texels[start:self.top], False
        by_key = np.argsort(keys, kind="stable")
        self._keys, self._slots = keys[by_key], slots[by_key]
        order = np.concatenate([np.arange(RESERVED, dtype=np.int32), slots])
        return SlotUpdate(order, start, texels.copy(), whole, len(new), self.capacity)
