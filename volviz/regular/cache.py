"""LRU cache of decoded wavelet-octree nodes under a memory budget (Guthe §2.3.7, cache 1).

Decoding a node's brick yields all of its children (:meth:`NodeDecoder.children`), so a node's samples can only be
produced while its parent is available. The cache therefore evicts only *leaves of the decoded tree* -- cached nodes
none of whose children are cached -- choosing the least recently used one; every cached node keeps its parent chain.
Decoded detail coefficients are not cached, only the node samples they produce. The root is never evicted.
"""
from __future__ import annotations

from collections import OrderedDict
from typing import Callable

import numpy as np

from .nodes import Key


def _parent(key: Key) -> Key:
    level, p = key
    return (level + 1, (p[0] // 2, p[1] // 2, p[2] // 2))


class NodeCache:
    """Node samples keyed by ``(level, (p0, p1, p2))`` with an LRU policy and a byte budget."""

    def __init__(self, budget_bytes: int, root_level: int) -> None:
        if budget_bytes <= 0:
            raise ValueError(f"cache budget must be positive, got {budget_bytes}")
        self.budget = int(budget_bytes)
        self.root_level = root_level
        self._data: OrderedDict[Key, np.ndarray] = OrderedDict()
        self._children: dict[Key, int] = {}
        self.bytes = 0
        self.hits = self.misses = self.evictions = 0

    def __contains__(self, key: Key) -> bool:
        return key in self._data

    def __len__(self) -> int:
        return len(self._data)

    def get(self, key: Key) -> np.ndarray | None:
        """The node's samples (marked as recently used), or None."""
        a = self._data.get(key)
        if a is None:
            self.misses += 1
            return None
        self.hits += 1
        self._data.move_to_end(key)
        return a

    def touch(self, key: Key) -> None:
        """Mark ``key`` and its ancestors as used by the renderer (so the chain outlives unused siblings)."""
        while key in self._data:
            self._data.move_to_end(key)
            if key[0] >= self.root_level:
                break
            key = _parent(key)

    def put(self, key: Key, a: np.ndarray) -> None:
        if key in self._data:
            self._data.move_to_end(key)
            return
        self._data[key] = a
        self.bytes += a.nbytes
        self._children.setdefault(key, 0)
        if key[0] < self.root_level:
            par = _parent(key)
            self._children[par] = self._children.get(par, 0) + 1
        self._evict(protect=key)

    def _evict(self, protect: Key) -> None:
        if self.bytes <= self.budget:
            return
        for key in list(self._data.keys()):  # oldest first
            if self.bytes <= self.budget:
                break
            if key == protect or key[0] >= self.root_level or self._children.get(key, 0) > 0:
                continue
            a = self._data.pop(key)
            self.bytes -= a.nbytes
            self._children.pop(key, None)
            par = _parent(key)
            self._children[par] = self._children.get(par, 1) - 1
            self.evictions += 1

    def get_or_make(self, key: Key, make: Callable[[], np.ndarray]) -> np.ndarray:
        a = self.get(key)
        if a is None:
            a = make()
            self.put(key, a)
        return a
