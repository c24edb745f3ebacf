"""A medical volume placed in volviz's world: voxel array + 4x4 voxel-to-world affine -> an axis-aligned
``RegularVolume`` in RAS+ millimetres (x to the patient's right, y anterior, z superior), the space NIfTI's and
FreeSurfer's affines use and 3D Slicer shows; NRRD and DICOM files in LPS (DICOM's patient space) are turned into
RAS first (``lps_to_ras``).

volviz volumes are axis-aligned grids, so the array is permuted and flipped onto the world axes nearest to its own
(nibabel's ``io_orientation`` / ``apply_orientation``, what ``nibabel.as_closest_canonical`` does): spacing and origin
then follow from the reoriented affine. A scan taken obliquely keeps the rotation that remains; it is dropped, and a
``ReadWarning`` names the angle. The same head read from NIfTI, NRRD or DICOM lands at the same place.
"""
from __future__ import annotations

import math
import warnings
import numpy as np

from volviz.io._checks import check_finite
from volviz.io.errors import PathLike, ReadError, ReadWarning
from volviz.model import RegularVolume
from volviz.model.arrays import volume_of

__all__ = ["LPS_TO_RAS", "aligned_volume", "lps_to_ras", "oblique_degrees"]

#: world LPS -> RAS: x and y change sign
LPS_TO_RAS = np.diag([-1.0, -1.0, 1.0, 1.0])


def lps_to_ras(affine: np.ndarray) -> np.ndarray:
    """A voxel-to-LPS affine as a voxel-to-RAS one."""
    return LPS_TO_RAS @ np.asarray(affine, dtype=np.float64)


def oblique_degrees(affine: np.ndarray) -> float:
    """The angle (degrees) of the rotation between an affine's voxel axes (columns, normalised) and the world axes
    they are nearest to (0 for an axis-aligned affine, whatever its flips and permutation)."""
    m = np.asarray(affine, dtype=np.float64)[:3, :3]
    cols = m / np.linalg.norm(m, axis=0)
    nearest = np.zeros((3, 3))
    for j in range(3):
        i = int(np.argmax(np.abs(cols[:, j])))
        nearest[i, j] = math.copysign(1.0, cols[i, j])
    rot = nearest.T @ cols  # the rotation left once the axes are on their nearest world axes
    return float(np.degrees(np.arccos(np.clip((np.trace(rot) - 1.0) / 2.0, -1.0, 1.0))))


def aligned_volume(path: PathLike, data: np.ndarray, affine: np.ndarray, name: str,
                   allow_nonfinite: bool = True, warn: bool = True) -> RegularVolume:
    """``data`` (nx, ny, nz) or (nx, ny, nz, c) with its voxel-to-RAS ``affine`` as an axis-aligned volume named
    ``name`` (its components one array, by magnitude or component in the array selector). ``warn``: whether an
    oblique scan is reported (once per file: the later steps of a time series pass False)."""
    from nibabel.orientations import OrientationError, apply_orientation, inv_ornt_aff, io_orientation

    affine = np.asarray(affine, dtype=np.float64)
    if affine.shape != (4, 4) or not np.all(np.isfinite(affine)):
        raise ReadError(path, "the voxel-to-world transform is not a finite 4x4 matrix")
    if abs(np.linalg.det(affine[:3, :3])) < 1e-12:
        raise ReadError(path, "the voxel-to-world transform is singular (a voxel size or direction is zero)")
    if data.ndim not in (3, 4) or min(data.shape[:3]) < 1:
        raise ReadError(path, f"{data.ndim}-dimensional voxel data of shape {data.shape} is not a volume")
    try:
        ornt = io_orientation(affine)
        if np.isnan(ornt).any():  # an axis nibabel could not assign
            raise OrientationError("an axis has no world axis")
    except OrientationError:  # columns of wildly different lengths: no axis assignment is unambiguous
        sizes = ", ".join(f"{v:.3g}" for v in np.linalg.norm(affine[:3, :3], axis=0))
        raise ReadError(path, f"the voxel-to-world transform has no nearest world axes (voxel sizes {sizes}): "
                              "a voxel size or direction is damaged") from None
    placed = affine @ inv_ornt_aff(ornt, data.shape[:3])  # the shape before the axes move
    data = apply_orientation(data, ornt)
    angle = oblique_degrees(placed)
    if angle > 0.1 and warn:
        warnings.warn(f"{path}: the volume was scanned obliquely ({angle:.1f} degrees from the nearest world axes); "
                      "it is shown on those axes (volviz volumes are axis-aligned)", ReadWarning, stacklevel=3)
    sx, sy, sz = (float(s) for s in np.linalg.norm(placed[:3, :3], axis=0))
    ox, oy, oz = (float(v) for v in placed[:3, 3])
    spacing, origin = (sx, sy, sz), (ox, oy, oz)
    if not data.dtype.isnative:
        data = data.astype(data.dtype.newbyteorder("="))
    check_finite(path, data, allow_nonfinite)
    return volume_of(data, name, spacing, origin, source=str(path))
