"""The probe's numerics (issue #28): the first visible sample along a ray in a tetrahedral mesh (value interpolated
in its cell) and in a compressed multiresolution volume (at full resolution), checked against values known by hand,
pyvista's own interpolation and the regular-volume probe of the decoded volume."""
from __future__ import annotations

import numpy as np
import pytest

from conftest import blob_vvz
from volviz.model.probe import VISIBLE_OPACITY, probe_regular
from volviz.optics import TransferFunction
from volviz.unstructured.probe import barycentric, probe_tetmesh
from volviz.unstructured.synthetic import box_tets


def _linear(p: np.ndarray) -> np.ndarray:
    return p[..., 0] + 2.0 * p[..., 1] + 3.0 * p[..., 2]


def _flat_tf(rho: float, lo: float = -10.0, hi: float = 10.0) -> TransferFunction:
    return TransferFunction([lo, hi], [[1, 1, 1], [1, 1, 1]], [rho, rho])


@pytest.fixture(scope="module")
def cube():
    """The unit cube in 5 x 5 x 5 hexahedra split into tetrahedra, the linear field x + 2y + 3z at its points (which
    linear interpolation in any tetrahedron reproduces exactly)."""
    return box_tets(6, field=_linear)


def _inside(mesh, result) -> bool:
    return bool(barycentric(mesh.points, mesh.tets[result.cell], np.array(result.position)).min() > -1e-9)


def test_without_a_tf_the_probe_stops_where_the_ray_enters_the_mesh(cube) -> None:
    hit = probe_tetmesh(cube, (0.3, 0.4, -1.0), (0.0, 0.0, 1.0))
    assert np.allclose(hit.position, (0.3, 0.4, 0.0), atol=1e-12)
    assert hit.value == pytest.approx(1.1, abs=1e-12)
    assert _inside(cube, hit)
    assert hit.point in cube.tets[hit.cell]
    assert np.linalg.norm(cube.points[hit.point] - hit.position) == pytest.approx(
        np.linalg.norm(cube.points[cube.tets[hit.cell]] - hit.position, axis=1).min())
    assert probe_tetmesh(cube, (2.0, 0.4, -1.0), (0.0, 0.0, 1.0)) is None     # beside the cube


def test_a_constant_extinction_reaches_one_percent_after_its_optical_depth(cube) -> None:
    """ρ constant: 1 - exp(-ρ L) = 1 % at L = -ln(0.99) / ρ; ρ chosen so that L = 0.25 along an oblique ray."""
    d = np.array([0.2, 0.1, 1.0]) / np.linalg.norm([0.2, 0.1, 1.0])
    rho = -np.log1p(-VISIBLE_OPACITY) / 0.25
    origin = np.array([0.3, 0.4, 0.0]) - 2.0 * d
    hit = probe_tetmesh(cube, origin, d, _flat_tf(rho))
    expected = np.array([0.3, 0.4, 0.0]) + 0.25 * d
    assert np.allclose(hit.position, expected, atol=1e-9), (hit.position, expected)
    assert hit.value == pytest.approx(float(_linear(expected)), abs=1e-9)
    assert _inside(cube, hit)
    assert probe_tetmesh(cube, origin, d, _flat_tf(rho * 1e-3)) is None        # never reaches 1 % in the cube


def test_the_value_is_pyvista_s_interpolation_at_the_hit_of_a_transparent_front(cube) -> None:
    """A nonlinear field (distance from the centre), transparent below 0.3: the ray along -x through the middle
    passes the opaque rim first; the value at the hit equals VTK's probe of the mesh there."""
    mesh = box_tets(6)
    tf = TransferFunction([0.0, 0.3, 0.31, 1.0], np.ones((4, 3)), [0.0, 0.0, 50.0, 50.0])
    hit = probe_tetmesh(mesh, (3.0, 0.45, 0.52), (-1.0, 0.0, 0.0), tf)
    assert hit is not None and 0.0 < hit.position[0] < 1.0
    import pyvista as pv

    sampled = pv.PolyData(np.array([hit.position])).sample(mesh.to_pyvista())
    assert hit.value == pytest.approx(float(sampled.point_data[mesh.name][0]), rel=1e-9)
    assert hit.value >= 0.3
    assert _inside(mesh, hit)


@pytest.fixture(scope="module")
def blob(tmp_path_factory):
    from volviz.regular.codec import decompress
    from volviz.regular.lod import LodTree

    path = blob_vvz(tmp_path_factory.mktemp("lod") / "blob.vvz", 40)
    return LodTree(path, sidecar=False), decompress(path)


@pytest.mark.parametrize("ray", [((-5.0, 19.3, 21.6), (1.0, 0.0, 0.0)),
                                 ((50.0, 60.0, -20.0), (-27.0, -41.0, 37.0)),
                                 ((17.2, -9.0, 30.4), (5.8, 28.0, -13.4))])
def test_the_lod_probe_is_the_regular_probe_of_the_decoded_volume(blob, ray) -> None:
    """Along rays that cross several 16^3 nodes: the same voxel and value as ``probe_regular`` on the decoded
    volume, with a TF transparent below 150 (the blob's core) and without one."""
    from volviz.regular.probe_lod import probe_lod

    tree, volume = blob
    origin, direction = np.array(ray[0]), np.array(ray[1]) / np.linalg.norm(ray[1])
    tf = TransferFunction([0.0, 149.0, 150.0, 255.0], np.ones((4, 3)), [0.0, 0.0, 0.5, 0.5])
    for f in (tf, None):
        got = probe_lod(tree, origin, direction, f, "blob")
        want = probe_regular(volume, origin, direction, f, "blob")
        assert want is not None and got == want, (got, want)
        assert got.value == float(volume.data[got.voxel])
    assert got.voxel != probe_lod(tree, origin, direction, tf, "blob").voxel     # the TF moved the hit inwards


def test_the_probes_skip_what_the_clipping_cuts_away(cube, blob) -> None:
    """A clip plane keeping z >= 0.6 (the mesh) or x >= 20.6 (the volumes): the mesh probe enters at the plane; the
    regular and LOD probes start behind it and still agree on the voxel and value."""
    from volviz.model.clip import ClipPlane, ClipSettings
    from volviz.regular.probe_lod import probe_lod

    hit = probe_tetmesh(cube, (0.3, 0.4, -1.0), (0.0, 0.0, 1.0),
                        clip=ClipSettings(planes=(ClipPlane((0.0, 0.0, 0.6), (0.0, 0.0, 1.0)),)))
    assert np.allclose(hit.position, (0.3, 0.4, 0.6)) and hit.value == pytest.approx(0.3 + 0.8 + 1.8)
    assert probe_tetmesh(cube, (0.3, 0.4, -1.0), (0.0, 0.0, 1.0),
                         clip=ClipSettings(planes=(ClipPlane((0.0, 0.0, 0.6), (0.0, 0.0, -1.0)),
                                                   ClipPlane((0.0, 0.0, 0.7), (0.0, 0.0, 1.0))))) is None
    tree, volume = blob
    clip = ClipSettings(planes=(ClipPlane((20.6, 0.0, 0.0), (1.0, 0.0, 0.0)),))
    origin, direction = np.array([-5.0, 19.3, 21.6]), np.array([1.0, 0.0, 0.0])
    want = probe_regular(volume, origin, direction, None, "blob", clip=clip)
    assert want.voxel[0] == 21 and want == probe_lod(tree, origin, direction, None, "blob", clip=clip)
    assert want.value == float(volume.data[want.voxel])
