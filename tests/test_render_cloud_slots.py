"""The C-LOD cloud leaves' slots on the GPU (``volviz.render.cloud_slots``): a frame uploads only the leaves its mesh
gained, into one contiguous region; leaves that stay keep their slots; a compaction re-sends the whole array. The
slot array the GPU would hold is replayed here from the updates alone, and every frame's draw order must read each
leaf's own address from it. Along a camera path over a real ``CloudLOD``: the added leaves are exactly those new to
the mesh. The images drawn from the slots are compared with the CPU clouds in ``tests/test_render_gl_nature.py``."""
from __future__ import annotations

import numpy as np

from volviz.model.camera import Camera
from volviz.nature import noise
from volviz.nature.clouds import CloudLOD, CloudShading, CloudVolume
from volviz.render.cloud_slots import RESERVED, TEXEL_BYTES, LeafSlots, leaf_keys


def _replay(gpu: np.ndarray | None, update) -> np.ndarray:
    """What the GPU's slot array holds after ``update`` (a region written, or the whole array replaced)."""
    if update.whole:
        return update.texels.copy()
    assert gpu is not None
    gpu[update.start:update.start + len(update.texels)] = update.texels
    return gpu


def _rows(leaves: np.ndarray) -> np.ndarray:
    return np.concatenate([leaves[:, 1:], leaves[:, :1]], axis=1).astype(np.float32)


def test_leaf_keys_are_the_octree_dense_index():
    roots = np.array([2, 3, 1])
    levels = 3
    leaves = np.array([(lv, a, b, c) for lv in range(levels + 1) for a in range(2 << lv >> 1)
                       for b in range(3 << lv) for c in range(1 << lv)], np.int64)
    keys = leaf_keys(leaves, roots)
    assert len(np.unique(keys)) == len(keys)
    # within CloudLOD's stored levels the key is its dense node index (off[lv] + (a nb + b) nc + c)
    off = np.concatenate([[0], np.cumsum([int(np.prod(roots << lv)) for lv in range(levels + 1)])])
    lv, a, b, c = leaves.T
    np.testing.assert_array_equal(keys, off[lv] + (a * (roots[1] << lv) + b) * (roots[2] << lv) + c)


def test_slots_keep_leaves_and_upload_only_the_new_ones():
    rng = np.random.default_rng(3)
    pool = np.array([(lv, a, b, c) for lv in range(3) for a in range(4) for b in range(4) for c in range(2)], np.int64)
    keys = leaf_keys(pool, np.array([1, 1, 1]) * 4)
    slots = LeafSlots(min_capacity=64)
    gpu = None
    shown = rng.choice(len(pool), 20, replace=False)
    held: dict[int, int] = {}
    for step in range(40):
        update = slots.place(pool[shown], keys[shown])
        gpu = _replay(gpu, update)
        order = update.order
        assert order.dtype == np.int32 and list(order[:RESERVED]) == list(range(RESERVED))
        assert np.all(gpu[:RESERVED, 3] == -1.0)                         # reserved: no leaf
        np.testing.assert_array_equal(gpu[order[RESERVED:]], _rows(pool[shown]))
        assert len(np.unique(order)) == len(order)
        now = dict(zip(shown.tolist(), order[RESERVED:].tolist()))
        new = [i for i in now if i not in held]
        assert update.added == len(new)
        if not update.whole:
            # the kept leaves kept their slots; the new ones fill one region, uploaded alone
            assert all(now[i] == held[i] for i in now if i in held)
            assert sorted(now[i] for i in new) == list(range(update.start, update.start + len(new)))
            assert update.upload_bytes == len(new) * TEXEL_BYTES + 4 * len(order)
        else:
            assert update.start == 0 and len(update.texels) == update.capacity >= 2 * (len(shown) + RESERVED)
        held = now
        assert slots.n_leaves == len(shown)
        # the next frame: about a quarter of the leaves replaced, the rest in a new order
        keep = rng.permutation(shown)[: 15 + step % 5]
        rest = np.setdiff1d(np.arange(len(pool)), keep)
        shown = rng.permutation(np.concatenate([keep, rng.choice(rest, 5, replace=False)]))


def test_compaction_when_the_region_runs_past_the_end():
    pool = np.array([(2, a, b, c) for a in range(8) for b in range(8) for c in range(4)], np.int64)
    keys = leaf_keys(pool, np.array([2, 2, 1]))
    slots = LeafSlots(min_capacity=16)
    first = slots.place(pool[:10], keys[:10])
    assert first.whole and first.capacity == 32 and first.added == 10
    wholes = 0
    gpu = first.texels.copy()
    for k in range(1, 12):                        # each frame swaps in 5 new leaves: 32 slots last 3-4 frames
        pick = np.arange(5 * k, 5 * k + 10)
        update = slots.place(pool[pick], keys[pick])
        gpu = _replay(gpu, update)
        np.testing.assert_array_equal(gpu[update.order[RESERVED:]], _rows(pool[pick]))
        wholes += update.whole
        assert update.whole or update.upload_bytes == 5 * TEXEL_BYTES + 4 * 12
    assert 2 <= wholes <= 4


def test_along_a_camera_path_the_added_leaves_are_those_new_to_the_mesh():
    shape = (33, 33, 17)
    f = noise.cloud_density(shape, seed=2, coverage=0.4)
    vol = CloudVolume(f, noise.cloud_light(f, (1.0, 1.0, 1.0)), (2.0, 2.0, 2.0))
    lod = CloudLOD(vol, big_c=2.5, small_c=6.0, cutoff=CloudShading.npr().cutoff)
    slots = LeafSlots()
    gpu = None
    prev: set[int] = set()
    added, total = [], []
    for t in np.linspace(0.0, 1.0, 12):
        eye = np.array([-20.0 + 60.0 * t, -30.0 + 20.0 * t, 50.0 - 20.0 * t])
        cam = Camera(eye, (32.0, 32.0, 16.0), (0, 0, 1), 50, clipping_range=(0.5, 500))
        frame = lod.update(cam, (64, 48), morph=False)
        keys = leaf_keys(frame.leaves, lod.roots)
        update = slots.place(frame.leaves, keys)
        gpu = _replay(gpu, update)
        np.testing.assert_array_equal(gpu[update.order[RESERVED:]], _rows(frame.leaves))
        assert update.added == len(set(keys.tolist()) - prev)
        if prev:
            added.append(update.added)
            total.append(len(keys))
        prev = set(keys.tolist())
    assert 0 < sum(added) < 0.5 * sum(total)      # the mesh changes, most leaves stay
