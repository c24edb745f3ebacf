"""Visibility sorting (Roettger §8.1, Guthe §4.3): MPVO, image-space boundary relations, cycles, approximate sorts.

Correctness is checked against exact ray casting: along every pixel ray, consecutive cells must appear back to front.
"""
from __future__ import annotations

import numpy as np
import pytest

from volviz.unstructured import synthetic as syn
from volviz.model.camera import Camera
from volviz.unstructured.reference import order_violations
from volviz.unstructured.sort import is_convex, visibility_order
from volviz.unstructured.topology import topology

SIZE = (48, 40)


def _cameras(mesh):
    return [Camera.orbit(mesh.points, 30, 20, 2.5), Camera.orbit(mesh.points, 200, -35, 2.2),
            Camera.orbit(mesh.points, 10, 5, 3.0, parallel=True)]


def test_mpvo_exact_on_convex_mesh_all_methods_are_permutations():
    m = syn.box_tets(5, jitter=0.3)
    assert is_convex(topology(m))
    for cam in _cameras(m):
        for method in ("mpvo", "centroid", "power"):
            res = visibility_order(m, cam, SIZE, method)
            assert np.array_equal(np.sort(res.order), np.arange(m.n_cells))
        res = visibility_order(m, cam, SIZE, "mpvo")
        assert res.cycles == 0 and res.boundary_relations == 0
        assert order_violations(m, cam, SIZE, res.order, 1e-9) == 0


@pytest.mark.parametrize("make", [syn.cavity_box, syn.holed_box], ids=["cavity", "hole"])
def test_nonconvex_needs_and_gets_boundary_relations(make):
    m = make(7)
    assert not is_convex(topology(m))
    plain_wrong = 0
    for cam in _cameras(m):
        plain = visibility_order(m, cam, SIZE, "mpvo", nonconvex="none")
        plain_wrong += order_violations(m, cam, SIZE, plain.order, 1e-9)
        res = visibility_order(m, cam, SIZE, "mpvo")
        assert res.boundary_relations > 0 and res.cycles == 0
        assert order_violations(m, cam, SIZE, res.order, 1e-9) == 0
    assert plain_wrong > 0                                          # plain MPVO is wrong on these meshes


def test_disconnected_pieces():
    m = syn.merge(syn.box_tets(3), syn.box_tets(4, jitter=0.2), syn.box_tets(3),
                  offsets=[(0, 0, 0), (0.4, 0.5, 1.3), (-0.3, 0.2, -1.2)])
    for cam in _cameras(m) + [Camera((0.5, 0.5, 6.0), (0.5, 0.5, 0.0), (0, 1, 0), 40.0, clipping_range=(0.1, 20))]:
        res = visibility_order(m, cam, SIZE, "mpvo")
        assert order_violations(m, cam, SIZE, res.order, 1e-9) == 0


@pytest.mark.parametrize("parallel", [False, True])
def test_visibility_cycle_detected_and_broken(parallel):
    m = syn.pencil_cycle(w=0.3)
    cam = Camera((0, 0, 8), (0, 0, 0), (0, 1, 0), 30, parallel=parallel, parallel_scale=2.0, clipping_range=(1, 20))
    res = visibility_order(m, cam, (128, 128), "mpvo")
    assert res.boundary_relations == 3                              # 0 over 1, 1 over 2, 2 over 0
    assert res.cycles == 1
    assert np.array_equal(np.sort(res.order), np.arange(3))
    # from the side there is no cycle
    side = Camera((0, -8, 0.3), (0, 0, 0), (0, 0, 1), 30, clipping_range=(1, 20))
    res = visibility_order(m, side, (128, 128), "mpvo")
    assert res.cycles == 0 and order_violations(m, side, (128, 128), res.order, 1e-9) == 0


def test_camera_inside_mesh_order_correct():
    m = syn.box_tets(5, jitter=0.2)
    cam = Camera((0.45, 0.55, 0.5), (1.0, 0.8, 0.6), (0, 0, 1), 70.0, clipping_range=(0.01, 10.0))
    res = visibility_order(m, cam, SIZE, "mpvo")
    assert order_violations(m, cam, SIZE, res.order, 1e-9) == 0


def test_unknown_method_rejected():
    m = syn.box_tets(3)
    with pytest.raises(ValueError, match="unknown sort method"):
        visibility_order(m, Camera.orbit(m.points), SIZE, "bogus")


def test_camera_inside_nonconvex_mesh_samples_only_what_is_in_front():
    """A camera inside a non-convex mesh: boundary faces behind it, or crossing the near plane, get the pixel box of
    their part in front of the near plane (before: the whole screen, 768 M candidate pixels for one Blunt Fin view,
    a 2.2 s sort). The boundary relations equal those sampled with whole-screen boxes, and the order is correct."""
    import volviz.unstructured.sort as sort_mod
    from volviz.unstructured.reference import screen_bboxes

    m = syn.cavity_box(8)
    cam = Camera((0.5, 0.12, 0.5), (0.5, 1.0, 0.5), (0, 0, 1), 60.0, clipping_range=(0.01, 10.0))
    topo = topology(m)
    box = sort_mod._boundary_box(cam, topo, SIZE)
    area = np.maximum(box[:, 1] - box[:, 0] + 1, 0) * np.maximum(box[:, 3] - box[:, 2] + 1, 0)
    assert (area == 0).sum() > 100 and area.sum() < 0.05 * len(box) * SIZE[0] * SIZE[1]
    src, dst = sort_mod.boundary_relations(topo, cam, SIZE)
    whole = np.tile([0, SIZE[0] - 1, 0, SIZE[1] - 1], (len(box), 1)).astype(np.int64)
    saved = sort_mod._boundary_box
    sort_mod._boundary_box = lambda *args: whole          # the exhaustive sampling the boxes must agree with
    try:
        src_all, dst_all = sort_mod.boundary_relations(topo, cam, SIZE)
    finally:
        sort_mod._boundary_box = saved
    assert len(src) > 0 and set(zip(src, dst)) == set(zip(src_all, dst_all))
    res = visibility_order(m, cam, SIZE, "mpvo", nonconvex="sample")
    assert res.boundary_relations == len(src) and order_violations(m, cam, SIZE, res.order, 1e-9) == 0
    res = visibility_order(m, cam, SIZE, "mpvo")                     # object space: the default
    assert res.boundary_relations > 0 and order_violations(m, cam, SIZE, res.order, 1e-9) == 0
    # one tetrahedron wholly behind the eye: empty; one crossing the near plane: the box of its front part
    pts = np.array([[0.4, 0.0, 0.4], [0.6, 0.0, 0.4], [0.5, -0.1, 0.6], [0.5, 0.05, 0.5],
                    [0.45, 0.62, 0.45], [0.55, 0.62, 0.45], [0.5, 0.62, 0.55], [0.5, 0.11, 0.5]])
    b = screen_bboxes(cam, pts, np.array([[0, 1, 2, 3], [4, 5, 6, 7]]), SIZE)
    assert b[0, 0] > b[0, 1] and b[0, 2] > b[0, 3]
    front = cam.project(pts[4:7], SIZE)
    assert (b[1, 0] <= front[:, 0]).all() and (front[:, 0] <= b[1, 1]).all()
    assert (b[1, 2] <= front[:, 1]).all() and (front[:, 1] <= b[1, 3]).all()
    assert (b[1, 1] - b[1, 0] + 1) * (b[1, 3] - b[1, 2] + 1) < SIZE[0] * SIZE[1] // 4
