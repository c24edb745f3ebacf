"""``ObjectCache``: values derived from an object (a mesh's topology, a dataset's first-look representation), kept
for as long as that object lives, beside it rather than in it (issue #31: no cache written into another object's
``__dict__``). The datasets are dataclasses that compare by value, so they are not hashable and a
``weakref.WeakKeyDictionary`` cannot hold them: the values are kept by the object's identity, and a
``weakref.finalize`` drops them when it is collected (before its ``id`` can be reused). An object that takes no weak
reference is not cached (the caller recomputes)."""
from __future__ import annotations

import threading
import weakref
from typing import Callable, Generic, Optional, TypeVar

V = TypeVar("V")


class ObjectCache(Generic[V]):
    """One value per live object, by identity (see the module's docstring)."""

    def __init__(self) -> None:
        self._values: dict[int, V] = {}
        self._lock = threading.Lock()   # first puts from two threads register one finalizer

    def get(self, obj: object) -> Optional[V]:
        """The value kept for ``obj`` (None: none)."""
        return self._values.get(id(obj))

    def put(self, obj: object, value: V) -> V:
        """Keep ``value`` for ``obj`` until ``obj`` is collected (not kept when ``obj`` takes no weak reference);
        returns ``value``."""
        key = id(obj)
        with self._lock:
            if key not in self._values:
                try:
                    weakref.finalize(obj, self._values.pop, key, None)
                except TypeError:   # no weak reference to it: nothing would tell when its id is free again
                    return value
            self._values[key] = value
        return value

    def setdefault(self, obj: object, make: Callable[[], V]) -> V:
        """The value kept for ``obj``, made by ``make()`` and kept when there is none."""
        value = self.get(obj)
        return self.put(obj, make()) if value is None else value

    def __len__(self) -> int:
        return len(self._values)
