"""The exact reference ray caster against an independent dense-sampling integral (point location + a fine midpoint
Riemann sum along the ray, Guthe Eqs. 1.17-1.19) on conforming 5-tetrahedra grids, with rays exactly through
vertices, along edges and inside shared faces, and with data reaching the ends of the transfer function's range (the
round-off case that made the reference drop whole segments)."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.model.datasets import TetMesh
from volviz.optics import TransferFunction
from volviz.unstructured import synthetic as syn
from volviz.model.camera import Camera
from volviz.unstructured.render import render

N = 5                                          # 5^3 points, spacing 1/4, 320 tetrahedra
H = 1.0 / (N - 1)


def _plateau(p: np.ndarray) -> np.ndarray:
    """A field clipped to [0.2, 0.8]: whole cells sit exactly at the TF's first and last control points."""
    r = np.sqrt(((p - np.array([0.3, 0.6, 0.45])) ** 2).sum(axis=-1))
    return np.clip(1.4 * r, 0.2, 0.8)


#: rho > 0 at both ends of the range (0.2 and 0.8): a scalar 1e-15 outside the range would be transparent
TF = TransferFunction([0.2, 0.5, 0.8], [[1.0, 0.6, 0.2], [0.2, 1.0, 0.4], [0.3, 0.4, 1.0]], [1.5, 0.6, 2.5])


class DenseSampler:
    """Scalar field of a tetrahedralised unit-cube grid by point location (cube index, then the cube's five tets by
    barycentric coordinates; numpy, independent of the renderer's kernels)."""

    def __init__(self, mesh: TetMesh) -> None:
        self.mesh = mesh
        p = mesh.points[mesh.tets]                                        # (m, 4, 3)
        mat = np.concatenate([np.transpose(p, (0, 2, 1)), np.ones((len(p), 1, 4))], axis=1)
        self.inv = np.linalg.inv(mat)
        cube = np.floor(p.mean(axis=1) / H).astype(np.int64)
        key = (cube[:, 0] * (N - 1) + cube[:, 1]) * (N - 1) + cube[:, 2]
        order = np.argsort(key, kind="stable")
        assert np.all(np.bincount(key, minlength=(N - 1) ** 3) == 5)
        self.by_cube = order.reshape(-1, 5)                               # (cubes, 5) tet ids

    def scalar(self, x: np.ndarray) -> np.ndarray:
        c = np.clip(np.floor(x / H).astype(np.int64), 0, N - 2)
        cand = self.by_cube[(c[:, 0] * (N - 1) + c[:, 1]) * (N - 1) + c[:, 2]]          # (k, 5)
        xh = np.concatenate([x, np.ones((len(x), 1))], axis=1)
        lam = np.einsum("kcij,kj->kci", self.inv[cand], xh)                 # (k, 5, 4)
        best = lam.min(axis=2).argmax(axis=1)
        lam = np.clip(lam[np.arange(len(x)), best], 0.0, None)
        assert lam.sum(axis=1).min() > 0.999
        lam /= lam.sum(axis=1, keepdims=True)
        sv = self.mesh.scalars[self.mesh.tets[cand[np.arange(len(x)), best]]]
        # a convex combination lies in [min, max] of the vertex scalars: keep round-off inside the TF's range
        return np.clip((lam * sv).sum(axis=1), sv.min(axis=1), sv.max(axis=1))


def dense_integral(sampler: DenseSampler, tf: TransferFunction, cam: Camera, size: tuple[int, int],
                   pixels: list[tuple[int, int]], steps: int = 4000) -> np.ndarray:
    """Premultiplied RGBA (k, 4) of the given (row, col) pixels by a midpoint Riemann sum inside the unit cube."""
    rb = cam.rays(size)
    near, far = cam.clipping_range
    out = np.zeros((len(pixels), 4))
    for n, (row, col) in enumerate(pixels):
        o = rb.o0 + col * rb.ox + row * rb.oy
        d = rb.d0 + col * rb.dx + row * rb.dy
        t0, t1 = near, far
        for a in range(3):                                                # slab test against [0, 1]^3
            if d[a] == 0.0:
                if not 0.0 <= o[a] <= 1.0:
                    t1 = -1.0
                continue
            ta, tb = sorted(((0.0 - o[a]) / d[a], (1.0 - o[a]) / d[a]))
            t0, t1 = max(t0, ta), min(t1, tb)
        if t1 <= t0:
            continue
        t = t0 + (np.arange(steps) + 0.5) * (t1 - t0) / steps
        rgb, rho = tf.evaluate(sampler.scalar(o + t[:, None] * d))
        tau = rho * (t1 - t0) * np.linalg.norm(d) / steps
        alpha = -np.expm1(-tau)
        before = np.exp(-(np.cumsum(tau) - tau))
        out[n, :3] = (rgb * (alpha * before)[:, None]).sum(axis=0)
        out[n, 3] = -np.expm1(-tau.sum())
    return out


def _cameras() -> dict[str, tuple[Camera, tuple[int, int]]]:
    # parallel along z, pixel centres at x, y = k/8 (k = 1..7): rays along interior edges and in shared faces
    along_z = Camera((0.5, 0.5, 3.0), (0.5, 0.5, 0.0), (0, 1, 0), parallel=True, parallel_scale=7 / 16,
                     clipping_range=(0.5, 5.0))
    # parallel along the main diagonal: the centre ray runs through the vertices (k/4, k/4, k/4)
    diag = Camera((2.0, 2.0, 2.0), (0.5, 0.5, 0.5), (0, 0, 1), parallel=True, parallel_scale=0.9,
                  clipping_range=(0.5, 6.0))
    # perspective with the eye in the grid plane z = 1/2: the middle row's rays lie in faces between cube layers
    in_plane = Camera((2.2, -1.3, 0.5), (0.5, 0.5, 0.5), (0, 0, 1), 40.0, clipping_range=(0.5, 6.0))
    # perspective from a generic direction (the cloud-bug camera, scaled to the unit cube)
    generic = Camera((-0.5, -0.77, 0.89), (0.5, 0.5, 0.25), (0, 0, 1), 50.0, clipping_range=(0.05, 6.0))
    return {"along_z": (along_z, (7, 7)), "diagonal": (diag, (9, 9)), "in_plane": (in_plane, (15, 15)),
            "generic": (generic, (16, 12))}


@pytest.fixture(scope="module")
def grid() -> tuple[TetMesh, DenseSampler]:
    mesh = syn.box_tets(N, field=_plateau)
    assert mesh.n_cells == 5 * (N - 1) ** 3
    return mesh, DenseSampler(mesh)


@pytest.mark.parametrize("name", list(_cameras()))
def test_reference_matches_dense_sampling(grid, name):
    mesh, sampler = grid
    cam, size = _cameras()[name]
    ref = render(mesh, TF, cam, size, "reference")
    w, h = size
    rng = np.random.default_rng(7)
    pixels = [(h // 2, w // 2), (h // 2, 0), (0, w // 2), (h // 2, w // 2 + 1)]
    pixels += [tuple(v) for v in np.stack([rng.integers(0, h, 8), rng.integers(0, w, 8)], 1)]
    dense = dense_integral(sampler, TF, cam, size, pixels)
    got = np.array([ref[r, c] for r, c in pixels])
    assert dense[:, 3].max() > 0.3                                        # the rays see a lot of medium
    # midpoint rule with 4000 steps: O(h^2) error ~1e-7 for this continuous TF; 5e-5 is 0.013 of 255
    assert np.abs(got - dense).max() < 5e-5, np.abs(got - dense).max(axis=1)


def test_constant_scalar_at_tf_end_is_not_dropped(grid):
    """Every vertex at the TF's last control point: alpha = 1 - exp(-rho_hi L) with L the chord through the cube."""
    mesh, _ = grid
    m = TetMesh(mesh.points, mesh.tets, np.full(mesh.n_points, 0.8))
    cam = _cameras()["generic"][0]
    w, h = 16, 12
    img = render(m, TF, cam, (w, h), "reference")
    pixels = [(r, c) for r in range(h) for c in range(w)]
    dense = dense_integral(DenseSampler(m), TF, cam, (w, h), pixels, steps=8)   # exact for a constant field
    assert np.abs(img.reshape(-1, 4) - dense).max() < 1e-12
    assert (dense[:, 3] > 0).sum() > 100


def test_rays_in_shared_faces_are_counted_once(grid):
    """Parallel rays along z exactly on the grid planes x = k/4 or y = k/4 (inside faces shared by two cells, and
    along edges shared by up to six): each ray's segments tile its chord with no overlap or gap."""
    from volviz.unstructured.reference import iter_ray_segments

    mesh, _ = grid
    cam, size = _cameras()["along_z"]
    seen = 0
    for pix, seg in iter_ray_segments(mesh, cam, size):
        for p in np.unique(pix):
            s = seg[pix == p]
            assert abs(s[:, 3].sum() - 1.0) < 1e-9, (divmod(int(p), size[0]), s[:, 3].sum())
            end = s[:, 0] + s[:, 3]                                        # |D| = 1 for parallel rays
            assert np.all(np.abs(s[1:, 0] - end[:-1]) < 1e-9)
            seen += 1
    assert seen == size[0] * size[1]


@pytest.mark.parametrize("name", list(_cameras()))
def test_pt_draws_rays_in_shared_faces_once(grid, name):
    """"pt" uses the same tie-break for rays lying in face planes (before: 79/255 off along z, 63 in_plane)."""
    mesh, _ = grid
    cam, size = _cameras()[name]
    ref = render(mesh, TF, cam, size, "reference")
    img = render(mesh, TF, cam, size, "pt", n_s=256, n_l=128)
    d = np.abs(img - ref) * 255.0
    assert d.max() < 1.0 and np.sqrt((d ** 2).mean()) < 0.3, (d.max(), np.sqrt((d ** 2).mean()))
