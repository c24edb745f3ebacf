"""``volviz.model.object_cache.ObjectCache`` keeps a value per live object beside it, not in its ``__dict__`` (issue
#31), and drops it when the object is collected; the unstructured caches that use it keep their values per mesh."""
from __future__ import annotations

import gc

import numpy as np
import pytest

from volviz.model import RegularVolume
from volviz.model.object_cache import ObjectCache
from volviz.model.representation import representation
from volviz.unstructured import synthetic as syn
from volviz.unstructured.topology import cell_ranges, topology


def test_a_value_is_kept_per_object_while_it_lives() -> None:
    cache: ObjectCache[str] = ObjectCache()
    a, b = RegularVolume(np.zeros((2, 2, 2), np.float32)), RegularVolume(np.zeros((2, 2, 2), np.float32))
    with pytest.raises(TypeError):                        # a dataset compares by value: no hash, no WeakKeyDictionary
        hash(a)
    assert cache.get(a) is None
    assert cache.put(a, "a") == "a" and cache.setdefault(b, lambda: "b") == "b"
    assert cache.setdefault(a, lambda: "not made") == "a" and (cache.get(a), cache.get(b)) == ("a", "b")
    assert set(vars(a)) == {"data", "spacing", "origin", "name", "source", "arrays"} and len(cache) == 2
    del a
    gc.collect()
    assert len(cache) == 1 and cache.get(b) == "b"


def test_an_object_without_weak_references_is_not_kept() -> None:
    cache: ObjectCache[int] = ObjectCache()
    key = (1, 2)   # a tuple takes no weak reference: nothing would say when its id is free again
    assert cache.put(key, 3) == 3 and cache.get(key) is None and len(cache) == 0


def test_the_datasets_caches_hold_nothing_in_the_dataset() -> None:
    mesh = syn.cavity_box(9)
    before = set(vars(mesh))
    topo = topology(mesh)
    assert topology(mesh) is topo and cell_ranges(mesh) is cell_ranges(mesh)
    assert topo.planes32.dtype == np.float32 and np.array_equal(topo.planes32[:, :, 3], topo.face_d.astype(np.float32))
    volume = RegularVolume(np.arange(27, dtype=np.float32).reshape(3, 3, 3))
    assert representation(volume) is representation(volume) and representation(volume).kind == "volume"
    assert set(vars(mesh)) == before and set(vars(volume)) == {"data", "spacing", "origin", "name", "source", "arrays"}
    mesh.points = mesh.points + 1.0    # replaced arrays: a new topology
    assert topology(mesh) is not topo
