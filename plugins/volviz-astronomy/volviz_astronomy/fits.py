"""FITS image cubes (``.fits``, ``.fit``, ``.fts``; gzip- or tile-compressed) through astropy: the spectral cubes of
radio astronomy (RA, Dec, frequency or velocity), integral-field optical cubes, simulation snapshots.

- The image shown: the first HDU whose data has three axes of more than one element (``hdu=`` picks one by number
  or name); a 2D image when the file has no cube. A fourth axis (Stokes, most often of one element) shows its first
  plane, with a warning when it has more.
- Values through BSCALE / BZERO (astropy's scaling); integer samples equal to BLANK become NaN (drawn transparent).
- Axes: FITS lists NAXIS1 (x, fastest) first; the volume is laid out x, y, z in that order, one unit per pixel and
  per channel (a cube's spectral axis shares no unit with its sky axes), the sky pixel's aspect kept from
  |CDELT2 / CDELT1|. The array is named after BUNIT when the header has it.
- astropy checks each header; a data unit shorter than its header says is refused before it is read, and so is a
  file holding a slice or more beyond its last HDU (fewer extra bytes: a ``ReadWarning``, ``volviz.io.trailing``).
"""
from __future__ import annotations

import math
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from volviz.io._checks import check_file, check_finite, describe_bytes, read_bytes
from volviz.io.errors import PathLike, ReadError, ReadWarning
from volviz.io.trailing import check_trailing
from volviz.model import Image2D, RegularVolume

from volviz_astronomy.specs import is_fits


def _open(path: PathLike) -> tuple[Any, Any]:
    """The file's HDU list, read whole, and the file handle it reads from (the caller closes both). astropy is given
    a handle of ours: a file it opens itself stays open when its parsing fails."""
    from astropy.io import fits
    from astropy.utils.exceptions import AstropyUserWarning

    handle = open(path, "rb")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", category=AstropyUserWarning)   # "may have been truncated": checked below
            warnings.simplefilter("error", category=fits.verify.VerifyWarning)
            hdus = fits.open(handle, memmap=False, lazy_load_hdus=False)
            try:
                hdus.verify("exception")
            except BaseException:
                hdus.close()
                raise
        return hdus, handle
    except (OSError, ValueError, TypeError, IndexError, KeyError, fits.verify.VerifyError,
            fits.verify.VerifyWarning) as exc:
        handle.close()
        _not_an_extension(path)
        raise ReadError(path, f"astropy cannot read it as FITS ({str(exc).strip()[:200]})") from None
    except BaseException:
        handle.close()
        raise


def _fields(hdu: Any) -> str:
    """The header fields that give an HDU's data size, as "NAXIS1 16, NAXIS2 14, NAXIS3 8 of BITPIX -32"."""
    axes = ", ".join(f"NAXIS{i} {n}" for i, n in enumerate(_shape(hdu)[::-1], 1))
    return f"{axes} of BITPIX {hdu.header.get('BITPIX')}"


def _slice_bytes(hdu: Any) -> int:
    shape = _shape(hdu)
    return abs(int(hdu.header.get("BITPIX", 8))) // 8 * math.prod(shape[1:]) if shape else 2880


def _check_after_last_hdu(path: Path, hdus: Any) -> None:
    """Bytes after the last HDU's data unit: refused when they make a slice or more, else a ReadWarning."""
    from astropy.io import fits

    last = hdus[-1]
    info = hdus.fileinfo(len(hdus) - 1)
    start, span = int(info["datLoc"]), int(info["datSpan"])
    if type(last) in (fits.PrimaryHDU, fits.ImageHDU):  # plain images: the padding after the samples is zeros
        data_bytes = _expected_bytes(last)
        check_trailing(path, _fields(last), data_bytes, _extra_bytes(path, start + data_bytes), _slice_bytes(last))
    else:  # tables, tile-compressed images: their data unit as astropy measured it
        check_trailing(path, f"a {type(last).__name__} data unit of {span} bytes", span,
                       path.stat().st_size - start - span, 2880)


def _extra_bytes(path: Path, data_end: int) -> int:
    """The bytes after the last HDU's data (ending at ``data_end``) that are not its zero padding to the 2880-byte
    block: a data unit that a wrong NAXISn cut short leaves its rest there."""
    pad = -data_end % 2880
    with open(path, "rb") as handle:
        handle.seek(data_end)
        padding = np.frombuffer(handle.read(pad), np.uint8)
    after = path.stat().st_size - data_end - pad
    if after > 0:
        return after + pad
    nonzero = np.flatnonzero(padding)
    return int(nonzero[-1]) + 1 if nonzero.size else 0


def _not_an_extension(path: PathLike) -> None:
    """When the HDUs after the primary one do not parse: if the primary header parses and the bytes after its data
    unit do not start an extension (``XTENSION=``), its header claims less data than the file holds; say so."""
    from astropy.io import fits

    try:
        with warnings.catch_warnings(), open(path, "rb") as handle:   # (a handle of ours: see ``_open``)
            warnings.simplefilter("ignore")
            with fits.open(handle, memmap=False, lazy_load_hdus=True) as hdus:
                first = hdus[0]  # hdus.fileinfo(0) would parse the HDUs after it
                start, span = int(first._data_offset), int(first._data_size)
                fields, data_bytes, end = _fields(first), _expected_bytes(first), start + span
    except Exception:  # noqa: BLE001 - the primary HDU does not parse either: astropy's message stands
        return
    size = Path(path).stat().st_size
    with open(path, "rb") as handle:
        handle.seek(end)
        following = handle.read(8)
    if end < size and following != b"XTENSION":
        raise ReadError(path, f"its header gives {fields}: {data_bytes} bytes of data, but {size - start - data_bytes} "
                              "bytes follow them that are no FITS extension (no XTENSION header): the header claims "
                              "less data than the file holds")


def _shape(hdu: Any) -> tuple[int, ...]:
    """The data's shape (slowest axis first) from the header, without reading the data."""
    naxis = int(hdu.header.get("ZNAXIS", hdu.header.get("NAXIS", 0)))
    prefix = "ZNAXIS" if "ZNAXIS" in hdu.header else "NAXIS"
    return tuple(int(hdu.header.get(f"{prefix}{i}", 0)) for i in range(naxis, 0, -1))


def _pick(path: PathLike, hdus: Any, hdu: int | str | None) -> Any:
    images = [h for h in hdus if h.is_image and _shape(h) and math.prod(_shape(h)) > 0]
    if hdu is not None:
        try:
            chosen = hdus[hdu]
        except (KeyError, IndexError):
            names = ", ".join(f"{i} ({h.name})" for i, h in enumerate(hdus))
            raise ReadError(path, f"has no HDU {hdu!r}; its HDUs are {names}") from None
        if chosen not in images:
            raise ReadError(path, f"HDU {hdu!r} holds no image data")
        return chosen
    cubes = [h for h in images if sum(n > 1 for n in _shape(h)) >= 3]
    if cubes:
        return cubes[0]
    if images:
        return images[0]
    raise ReadError(path, "holds no image data (no HDU with NAXIS > 0)")


def _expected_bytes(hdu: Any) -> int:
    """The bytes the data unit must hold: |BITPIX| / 8 per sample (uncompressed HDUs)."""
    return abs(int(hdu.header.get("BITPIX", 8))) // 8 * math.prod(_shape(hdu))


def read_fits(path: PathLike, hdu: int | str | None = None,
              allow_nonfinite: bool = True) -> RegularVolume | Image2D:
    """A FITS image cube as a volume (or an image as an Image2D); see the module."""
    p = check_file(path)
    head = read_bytes(p, 2880)
    if not is_fits(head):
        raise ReadError(p, f"is not a FITS file (it does not start with SIMPLE =; its content is "
                           f"{describe_bytes(head)})")
    hdus, handle = _open(p)
    try:
        chosen = _pick(p, hdus, hdu)
        header = chosen.header
        start = hdus.fileinfo(hdus.index(chosen))["datLoc"]
        if "ZNAXIS" not in header and p.suffix.lower() != ".gz" and start + _expected_bytes(chosen) > p.stat().st_size:
            raise ReadError(p, f"its data unit ({' x '.join(map(str, _shape(chosen)[::-1]))} samples of BITPIX "
                               f"{header.get('BITPIX')}) runs past the end of the file: it is truncated")
        if p.suffix.lower() != ".gz":  # bytes after the last HDU: a header that claims less than the file holds
            _check_after_last_hdu(p, hdus)
        try:
            data = np.array(chosen.data)
        except (OSError, ValueError, TypeError, IndexError) as exc:
            raise ReadError(p, f"its data could not be read ({exc})") from None
        blank = header.get("BLANK")
        raw_ints = data.dtype.kind in "iu"
    finally:
        hdus.close()
        handle.close()
    data = np.squeeze(data)
    if blank is not None and raw_ints:
        data = np.where(data == blank, np.nan, data.astype(np.float32))
    if data.ndim == 4:
        warnings.warn(f"{p}: the cube has {data.shape[0]} planes along its fourth axis (Stokes); the first is shown",
                      ReadWarning, stacklevel=2)
        data = data[0]
    if data.ndim not in (2, 3):
        raise ReadError(p, f"its image has {data.ndim} axes of more than one element; volviz shows 2 or 3")
    if not data.dtype.isnative:
        data = data.astype(data.dtype.newbyteorder("="))
    check_finite(p, data, allow_nonfinite)
    aspect = _aspect(header)
    if data.ndim == 2:
        return Image2D(data[::-1], spacing=(1.0, aspect), source=str(p))    # row 0 of an Image2D is its top
    name = str(header.get("BUNIT", "") or "intensity").strip() or "intensity"
    return RegularVolume(np.ascontiguousarray(np.transpose(data, (2, 1, 0))), spacing=(1.0, aspect, 1.0), name=name,
                         source=str(p))


def _aspect(header: Any) -> float:
    """|CDELT2 / CDELT1| when both are finite and non-zero, else 1."""
    try:
        ratio = abs(float(header["CDELT2"]) / float(header["CDELT1"]))
    except (KeyError, TypeError, ValueError, ZeroDivisionError):
        return 1.0
    return ratio if math.isfinite(ratio) and ratio > 0 else 1.0
