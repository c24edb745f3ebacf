"""MPVO per view (``volviz.unstructured.mpvo``, issue #29): a shared face is decided by its lower-numbered cell's
plane, found through ``Topology.back_face``; the face sides split over the cores (large meshes) give the same bits
and the same order as the serial pass; the order stays exact (checked by ray casting); Kahn resumes after a stall."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.model.camera import Camera
from volviz.model.datasets import TetMesh
from volviz.unstructured import mpvo
from volviz.unstructured import synthetic as syn
from volviz.unstructured.reference import order_violations
from volviz.unstructured.sort import visibility_order
from volviz.unstructured.topology import topology


def _offset(m: TetMesh) -> TetMesh:
    return TetMesh(m.points + 1e6, m.tets, m.scalars)


@pytest.mark.parametrize("make", [lambda: syn.box_tets(6, jitter=0.3), lambda: _offset(syn.cavity_box(7))],
                         ids=["jittered", "cavity-offset-1e6"])
def test_back_face_names_the_neighbours_shared_face(make):
    topo = topology(make())
    nb = topo.neighbor
    t, f = np.nonzero(nb >= 0)
    g = (topo.back_face[t] >> (2 * f)) & 3
    assert len(t) > 1000 and np.array_equal(nb[nb[t, f], g], t)


@pytest.mark.parametrize("parallel", [False, True])
def test_face_sides_on_all_cores_equal_the_serial_pass(parallel):
    m = syn.cavity_box(9)
    topo = topology(m)
    cam = Camera.orbit(m.points, 30, 20, 2.5, parallel=parallel)
    eye = np.ascontiguousarray(cam.position - topo.origin)
    fwd = np.ascontiguousarray(cam.frame()[2])
    serial = mpvo.face_sides(topo.neighbor, topo.back_face, topo.face_n, topo.face_d, eye, fwd, parallel, cores=False)
    split = mpvo.face_sides(topo.neighbor, topo.back_face, topo.face_n, topo.face_d, eye, fwd, parallel, cores=True)
    assert np.array_equal(serial[0], split[0]) and np.array_equal(serial[1], split[1])
    # every interior face is in front of exactly one of its cells (none lies in a plane through the eye here)
    nb = topo.neighbor
    front = (serial[0][:, None] >> np.arange(4)) & 1
    t, f = np.nonzero(nb >= 0)
    assert front[t, f].sum() == len(t) // 2
    assert np.array_equal(serial[1], ((nb >= 0) & (front == 0)).sum(axis=1))


def test_large_mesh_path_gives_the_same_exact_order(monkeypatch):
    """The face sides on all cores (taken from ``PARALLEL_CELLS`` cells on): the order equals the serial one and
    has no violation along any pixel ray (a non-convex mesh, perspective and orthographic)."""
    m = syn.cavity_box(8)
    cams = [Camera.orbit(m.points, 30, 20, 2.5), Camera.orbit(m.points, 200, -35, 2.2, parallel=True)]
    serial = [visibility_order(m, cam, (96, 80)).order for cam in cams]
    monkeypatch.setattr(mpvo, "PARALLEL_CELLS", 0)
    for cam, ref in zip(cams, serial):
        res = visibility_order(m, cam, (96, 80))
        assert np.array_equal(res.order, ref) and res.cycles == 0 and res.boundary_relations > 0
        assert order_violations(m, cam, (96, 80), res.order, 1e-9) == 0


def test_kahn_resumes_after_a_stall_with_the_fallback():
    """A cycle stalls the first run, which returns with its state; the second run carries on from there, emitting
    the first cell of the fallback order not yet emitted (3 pencils: 0 over 1, 1 over 2, 2 over 0)."""
    nb = np.full((3, 4), -1, np.int32)
    front = np.zeros(3, np.uint8)
    indeg = np.zeros(3, np.int32)
    src, dst = np.array([1, 2, 0], np.int32), np.array([0, 1, 2], np.int32)    # sorted by source
    by = np.argsort(src, kind="stable")
    mpvo.add_extra(src[by], dst[by], front, indeg)
    order = np.full(3, -1, np.int32)
    n, cycles = mpvo.kahn(nb, front, indeg, src[by], dst[by], order, 0, np.empty(0, np.int32))
    assert (n, cycles) == (0, -1)
    n, cycles = mpvo.kahn(nb, front, indeg, src[by], dst[by], order, n, np.array([2, 0, 1], np.int32))
    assert (n, cycles) == (3, 1)
    assert order.tolist() == [2, 1, 0]         # 2 forced; then 1 (freed by 2), then 0 (freed by 1)


def test_relations_run_in_line_when_no_thread_can_start(monkeypatch):
    """A background sort during interpreter shutdown: the sort's worker thread cannot take the boundary relations
    (its executor refuses new work), so the calling thread computes them; the order is the same."""
    from concurrent.futures import ThreadPoolExecutor

    from volviz.unstructured import sort

    m = syn.cavity_box(7)
    cam = Camera.orbit(m.points, 30, 20, 2.5)
    ref = visibility_order(m, cam, (96, 80))
    monkeypatch.setattr(mpvo, "PARALLEL_CELLS", 0)
    closed = ThreadPoolExecutor(1)
    closed.shutdown()
    monkeypatch.setattr(sort, "_SECOND_CORE", closed)
    res = visibility_order(m, cam, (96, 80))
    assert np.array_equal(res.order, ref.order) and res.boundary_relations == ref.boundary_relations > 0


@pytest.mark.parametrize("parallel", [False, True])
def test_float32_planes_decide_as_the_float64_planes_near_every_plane(parallel):
    """The serial pass takes a side from the float32 planes only when it is clearly away from 0: eyes (and view
    directions) on face planes and 1e-9 to 1e-5 off them, on a jittered mesh offset by 1e6, give the bits and
    in-degrees of the float64 planes (the pass on all cores reads only those)."""
    topo = topology(_offset(syn.box_tets(7, jitter=0.3)))
    planes = mpvo.planes32(topo)
    assert planes.dtype == np.float32 and planes.shape == (topo.n_tets, 4, 4)
    rng = np.random.default_rng(3)
    t, f = np.nonzero(topo.neighbor >= 0)
    pick = rng.choice(len(t), 12, replace=False)
    checked = 0
    for k, off in zip(pick, [0.0, 1e-9, -1e-9, 1e-7, -1e-7, 1e-5, -1e-5, 0.0, 3e-8, -3e-8, 1e-6, -1e-6]):
        n, d = topo.face_n[t[k], f[k]], topo.face_d[t[k], f[k]]
        if parallel:           # a view direction in (or nearly in) the face's plane
            fwd = np.cross(n, rng.normal(size=3))
            fwd = np.ascontiguousarray(fwd / np.linalg.norm(fwd) + off * n)
            eye = np.zeros(3)
        else:                  # an eye on (or nearly on) the face's plane, outside the mesh
            p = topo.centroid[t[k]] + 3.0 * np.cross(n, rng.normal(size=3))
            eye = np.ascontiguousarray(p - (n @ p - d - off) * n)
            fwd = np.array([0.0, 0.0, 1.0])
        args = (topo.neighbor, topo.back_face, topo.face_n, topo.face_d, eye, fwd, parallel)
        fast = mpvo.face_sides(*args, cores=False, planes=planes)
        exact = mpvo.face_sides(*args, cores=True)
        plain = mpvo.face_sides(*args, cores=False)
        assert np.array_equal(fast[0], exact[0]) and np.array_equal(fast[1], exact[1])
        assert np.array_equal(plain[0], exact[0]) and np.array_equal(plain[1], exact[1])
        checked += 1
    assert checked == 12


def test_sorts_at_once_on_two_threads_give_the_serial_orders():
    """A sort's work arrays come from a pool on the topology: two sorts running at once (the app's worker and its
    GUI thread) take different ones, and each order equals the one made alone."""
    from concurrent.futures import ThreadPoolExecutor

    m = syn.cavity_box(9)
    topo = topology(m)
    cams = [Camera.orbit(m.points, az, 20, 2.5) for az in (10, 100, 190, 280)]
    alone = [visibility_order(topo, cam, (96, 80)).order for cam in cams]
    with ThreadPoolExecutor(2) as pool:
        both = list(pool.map(lambda cam: visibility_order(topo, cam, (96, 80)).order, cams * 3))
    assert all(np.array_equal(o, alone[i % 4]) for i, o in enumerate(both))
    assert 1 <= len(topo.__dict__["_sort_work"]) <= 2
