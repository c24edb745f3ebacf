"""Checks of an OpenFOAM case's field files before ``vtkOpenFOAMReader`` reads a time step.

VTK's reader lists the fields of a time folder by their ``FoamFile`` headers and drops, without a word, a file whose
header is damaged or a field file cut short after its ``internalField``: the case then opens without that field
(the user sees ``U`` missing, or values made up for a cut boundary). Here every file of the time folder being read
is checked, in the terms of the OpenFOAM file format (a ``FoamFile { ... }`` dictionary first, then for a field
class ``internalField`` and a ``boundaryField`` dictionary that closes):

- the file starts, after comments, with a complete ``FoamFile`` dictionary naming its ``class``;
- a field file (class ``vol...Field``, ``surface...Field``, ``point...Field``) holds ``internalField`` and a
  ``boundaryField`` whose braces balance (ASCII files) or which ends with ``}`` (binary files, whose lists may hold
  brace bytes).

Files that are not OpenFOAM data by their name (hidden files, editor backups ``~``, ``.orig``, ``.bak``) and
compressed fields (``.gz``, which VTK decompresses) are left to VTK; so are folders (``uniform/``). A file is read
whole up to 16 MB; of a larger one only its first and last 64 KB (the header and the end of ``boundaryField``).
"""
from __future__ import annotations

import re
from pathlib import Path

from volviz.io.errors import PathLike, ReadError

_SKIPPED_SUFFIXES = ("~", ".orig", ".bak", ".gz", ".swp")
_WHOLE_LIMIT = 16 << 20
_PART = 64 << 10
_COMMENTS = re.compile(rb"/\*.*?\*/|//[^\n]*", re.S)
_HEADER = re.compile(rb"\s*FoamFile\s*\{([^{}]*)\}")
_CLASS = re.compile(rb"\bclass\s+([A-Za-z0-9_<>:]+)\s*;")
_FORMAT = re.compile(rb"\bformat\s+(\w+)\s*;")
_FIELD_CLASS = re.compile(rb"(vol|surface|point)\w*Field$")


def _text(path: Path) -> bytes:
    size = path.stat().st_size
    with open(path, "rb") as f:
        if size <= _WHOLE_LIMIT:
            return f.read()
        head = f.read(_PART)
        f.seek(size - _PART)
        return head + b"\n" + f.read()


def check_field_file(case: PathLike, path: Path) -> None:
    """Refuse ``path`` (a file of a time folder of ``case``) when its header or its field is incomplete."""
    name = path.relative_to(case) if path.is_relative_to(case) else path
    data = _text(path)
    header = _HEADER.match(_COMMENTS.sub(b" ", data[:_PART]))
    if header is None:
        raise ReadError(case, f"the OpenFOAM file {name} has no complete FoamFile header: it is damaged or not an "
                              "OpenFOAM file", advice="repair it, or move it out of the case folder to read the rest")
    klass = _CLASS.search(header.group(1))
    if klass is None:
        raise ReadError(case, f"the OpenFOAM file {name} names no class in its FoamFile header: it is damaged")
    if not _FIELD_CLASS.search(klass.group(1)):
        return
    binary = (m := _FORMAT.search(header.group(1))) is not None and m.group(1) == b"binary"
    body = data[header.end():]
    at = body.find(b"boundaryField")
    if body.find(b"internalField") < 0 or at < 0:
        raise ReadError(case, f"the OpenFOAM field file {name} ends before its "
                              f"{'boundaryField' if b'internalField' in body else 'internalField'}: it is truncated")
    tail = _COMMENTS.sub(b" ", body[at:]) if not binary else body[at:]
    complete = tail.rstrip().endswith(b"}") if binary or len(data) > _WHOLE_LIMIT \
        else tail.count(b"{") == tail.count(b"}") > 0
    if not complete:
        raise ReadError(case, f"the OpenFOAM field file {name} ends inside its boundaryField: it is truncated")


def check_time_folder(case: PathLike, folder: Path) -> None:
    """Check every data file of one time folder of the case (see the module docstring)."""
    if not folder.is_dir():
        return
    for path in sorted(folder.iterdir()):
        if path.is_file() and not path.name.startswith(".") and not path.name.endswith(_SKIPPED_SUFFIXES):
            check_field_file(case, path)
