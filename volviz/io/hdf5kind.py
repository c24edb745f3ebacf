"""What an HDF5 file is, before the generic HDF5-arrays reader takes it: many formats are HDF5 underneath, and read
as a plain list of arrays they show as something else (a Fluent case as a 4565 x 2 image of its node coordinates).

``hdf5_kind`` looks at the file's structure (root groups, datasets and attributes, through h5py, with no data read)
and names the format by the signs its own library writes:

- ``vtkhdf``: a ``/VTKHDF`` group (VTK's HDF5 format);
- ``fluent-cff``: Fluent's Common Fluid Format, a case (``/meshes`` and ``/settings``) or its data (``/results`` and
  ``/settings``);
- ``cgns``: CGNS/HDF5, whose root holds the `` format`` and `` hdf5version`` datasets (CGNS SIDS-to-HDF5 mapping);
- ``exodus``: Exodus II on netCDF-4: netCDF's marks (below) with Exodus's ``api_version`` / ``coord`` / ``connect1``;
- ``netcdf``: netCDF-4: the ``_NCProperties`` root attribute, or the ``_Netcdf4Dimid`` / ``_Netcdf4Coordinates``
  attributes netCDF-C puts on its dimension scales and variables;
- ``matlab``: a MAT-file v7.3 (its 512-byte text header before the HDF5 signature).

``None`` means plain arrays. ``KINDS`` maps each kind to the reader spec that reads it and the words used in
messages.
"""
from __future__ import annotations

from typing import Any

from volviz.io._checks import HDF5_SIGNATURE, read_bytes
from volviz.io.errors import PathLike, ReadError
from volviz.io.loaders import loader_call
from volviz.io.registry import get_reader

#: kind -> (reader spec name, what the file is, in words)
KINDS: dict[str, tuple[str, str]] = {
    "vtkhdf": ("vtkhdf", "a VTKHDF file"),
    "fluent-cff": ("fluent-cff", "a Fluent case or data file in the Common Fluid Format (CFF)"),
    "cgns": ("cgns", "a CGNS/HDF5 file"),
    "exodus": ("exodus", "an Exodus II file (netCDF-4/HDF5)"),
    "netcdf": ("netcdf-cf", "a netCDF-4 file"),
    "matlab": ("matlab", "a MATLAB v7.3 MAT-file"),
}
_NETCDF_ATTRS = ("_Netcdf4Dimid", "_Netcdf4Coordinates")
_EXODUS_NAMES = ("coord", "coordx", "connect1", "eb_prop1", "eb_status")
_NETCDF_MAX_LOOKED_AT = 64  # root members whose attributes are looked at for netCDF-4's marks


def _is_netcdf4(f: Any) -> bool:
    if "_NCProperties" in f.attrs:
        return True
    for i, name in enumerate(f):
        if i >= _NETCDF_MAX_LOOKED_AT:
            break
        member = f.get(name)
        if member is not None and any(a in member.attrs for a in _NETCDF_ATTRS):
            return True
    return False


def kind_of_open(f: Any) -> str | None:
    """The kind (see the module) of an open ``h5py.File``, None for plain arrays."""
    # heavy: h5py (about 45 modules), loaded only when an HDF5 file is looked into
    import h5py

    if isinstance(f.get("VTKHDF"), h5py.Group):
        return "vtkhdf"
    groups = {name for name in ("meshes", "results", "settings") if isinstance(f.get(name), h5py.Group)}
    if "settings" in groups and groups & {"meshes", "results"}:
        return "fluent-cff"
    if " hdf5version" in f or " format" in f:
        return "cgns"
    if _is_netcdf4(f):
        exodus = "api_version" in f.attrs or "floating_point_word_size" in f.attrs or any(n in f for n in _EXODUS_NAMES)
        return "exodus" if exodus else "netcdf"
    return None


def hdf5_kind(path: PathLike) -> str | None:
    """The kind of the HDF5 file at ``path`` (see the module); None for plain arrays or a file h5py cannot open
    (the reader then says what is wrong)."""
    # heavy: h5py (about 45 modules), loaded only when an HDF5 file is looked into
    import h5py

    head = read_bytes(path, 128)
    if head.startswith(b"MATLAB 7.3 MAT-file"):
        return "matlab"
    if not head.startswith(HDF5_SIGNATURE):
        return None
    try:
        with h5py.File(path, "r") as f:
            return kind_of_open(f)
    except (OSError, RuntimeError, ValueError, KeyError, TypeError):
        return None


#: names Fluent gives its CFF files (``vtkFLUENTCFFReader`` reads the pair)
_FLUENT_ENDINGS = (".cas.h5", ".dat.h5")


def check_named_kind(path: PathLike, f: Any) -> None:
    """A file named like Fluent CFF (``.cas.h5``, ``.dat.h5``) whose root lacks Fluent's groups is refused, naming
    them and what the root holds: read as plain arrays, a Fluent case with one renamed group (a flipped bit:
    ``settings`` -> ``setdings``) showed as a 4565 x 2 image of its node coordinates (issue #32). ``dataset=``
    still reads one of its arrays."""
    name = str(path).lower()
    if name.endswith(_FLUENT_ENDINGS):
        held = ", ".join(sorted(f)[:12]) or "nothing"
        raise ReadError(path, f"is named like a Fluent CFF file but its root lacks the /settings group with /meshes "
                              f"(case) or /results (data) (it holds: {held}): the file is damaged or not Fluent CFF",
                        "pass dataset= to read one of its arrays")


def read_as_kind(path: PathLike, kind: str, allow_nonfinite: bool = True) -> Any:
    """Read an HDF5 file of ``kind`` with the reader registered for it; a ReadError saying what the file is and what
    to do when no such reader is installed (the plugin's formats: Fluent CFF, CGNS, Exodus, netCDF)."""
    spec_name, words = KINDS[kind]
    try:
        spec = get_reader(spec_name)
    except KeyError:
        raise ReadError(path, f"is {words}, not a file of plain arrays, and no installed reader reads it",
                        "install the volviz-vtk-readers plugin (pip install plugins/volviz-vtk-readers), or pass "
                        "dataset= to read one of its arrays as an array") from None
    load, options = loader_call(spec_name, spec.loader, {"allow_nonfinite": allow_nonfinite})
    return load(path, **options)
