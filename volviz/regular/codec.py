"""Wavelet codec for regular volumes: ``compress``, ``decompress``, ``info`` (Guthe §2.2.1-2.2.2, §2.3.1).

Pipeline: integer 5/3 wavelet octree over 32^3 tiles (:mod:`.wavelet`; in lossless files each node may use the
integer S-transform instead, chosen by coded size and recorded per brick), optional dead-zone quantisation
(:mod:`.kernels`), significance map + rANS or adaptive arithmetic coding (:mod:`.entropy`), one checksummed brick
per octree node in a ``.vvz`` file (:mod:`.container`).

Modes
- ``lossless``: threshold 0, bit-exact for 8/16-bit integer input (and for the quantised integers of float input).
- ``quality=Q`` (0..100): image-domain quantiser step ``delta = 2 ** ((90 - Q) / 10)`` voxel units (each -10
  halves the rate roughly); subband steps ``delta / sqrt(weight)`` with the 5/3 synthesis energy weights
  (``wavelet.subband_weights``), so the error spreads evenly over subbands, rounded to integers (>= 1; 1 = that
  subband is lossless). Integer steps on the integer coefficients give bins of equal integer counts; fractional
  steps in (1, 2) cost rate for almost no error reduction (on embryo integer steps gave a higher PSNR at a lower
  rate; Q >= 95 is lossless there: docs/bench/docstring-figures.md). The quality knob therefore moves in discrete
  steps near lossless.
- ``psnr=DB``: bisection over log(delta) until the PSNR (peak = the dtype's maximum, 255 for 8-bit, 65535 for
  16-bit and quantised float) is at least DB; the search measures the true reconstruction (quantise + inverse
  wavelet) of the whole volume, or of a central 256^3 crop for volumes above 2^25 voxels (then stated in ``info``).

Float input is quantised to 16 bits: ``q = round((x - lo) / (hi - lo) * 65535)`` with lo, hi the finite min/max
(stored in the metadata); the decoder returns float32 ``lo + q * (hi - lo) / 65535``, so the lossless mode has a
maximum error of ``(hi - lo) / 131070``. Non-finite samples are refused.

Out of core: level 0 is read in z-slabs of 32 planes (a ``numpy.memmap`` in VTK/Fortran order reads contiguous
slabs; processed pages are released with madvise), only the 1/8-size lowpass pyramid stays in memory, and bricks
stream to the file.
"""
from __future__ import annotations

import math
import mmap
import warnings
from pathlib import Path
from typing import Any, Callable

import numpy as np

from volviz.model.datasets import RegularVolume

from . import kernels as K
from .container import KIND_NODE, KIND_ROOT, CorruptBrickError, CorruptBrickWarning, Reader, VVZError, Writer
from .entropy import CODER_VERSION, CODERS, capacity
from .wavelet import TILE, TRANSFORM_53, TRANSFORM_HAAR, level_shapes, n_tiles, subband_weights

Progress = Callable[[float, str], None]
_INT_TYPES = {"uint8": 255, "int8": 255, "uint16": 65535, "int16": 65535}
_SLAB_PLANES = 2 * TILE
_PSNR_FULL_LIMIT = 1 << 25
TRANSFORM_CHOICES = {"auto": -1, "5/3": TRANSFORM_53, "haar": TRANSFORM_HAAR}


def quality_to_delta(quality: float) -> float:
    """``--quality Q`` (0..100) to the image-domain quantiser step (see module docstring)."""
    if not 0 <= quality <= 100:
        raise ValueError(f"quality must lie in 0..100, got {quality}")
    return float(2.0 ** ((90.0 - quality) / 10.0))


def level_steps(delta: float, levels: int) -> np.ndarray:
    """Quantiser steps ``steps[l, b]`` for level l = 1..levels and detail subband b = 1..7; all zero for lossless.
    ``steps[:, 0]`` is 1 for lossless files (the decoder's lowpass is exact: a context of the arithmetic coder),
    else 0."""
    steps = np.zeros((levels + 1, 8))
    if delta > 0:
        steps[1:] = np.maximum(np.rint(delta / np.sqrt(subband_weights(levels)[1:])), 1.0)
    steps[:, 0] = 0.0 if delta > 0 else 1.0
    return steps


def _peak(kind: str) -> float:
    return float(_INT_TYPES.get(kind, 65535))


class _Source:
    """Slab access to a volume as int32, with float quantisation and memmap page release."""

    def __init__(self, data: np.ndarray) -> None:
        self.data = data
        self.dtype = np.dtype(data.dtype)
        self.lo = self.hi = 0.0
        if self.dtype.name in _INT_TYPES:
            self.kind = self.dtype.name
        elif self.dtype.kind in "fiub":
            self.kind = "float" if self.dtype.kind == "f" else "int-quantised"
            lo, hi = math.inf, -math.inf
            for z0 in range(0, data.shape[2], _SLAB_PLANES):
                s = np.asarray(data[:, :, z0:z0 + _SLAB_PLANES])
                if s.dtype.kind == "f" and not np.isfinite(s).all():
                    raise ValueError("volume contains NaN or Inf samples; the codec needs finite values")
                lo, hi = min(lo, float(s.min())), max(hi, float(s.max()))
                self.release(z0, z0 + _SLAB_PLANES)
            self.lo, self.hi = lo, hi
        else:
            raise ValueError(f"unsupported volume dtype {self.dtype}")

    def slab(self, z0: int, z1: int) -> np.ndarray:
        s = np.asarray(self.data[:, :, z0:z1])
        if self.kind in _INT_TYPES:
            return np.ascontiguousarray(s, dtype=np.int32)
        scale = 65535.0 / (self.hi - self.lo) if self.hi > self.lo else 0.0
        return np.ascontiguousarray(np.rint((s.astype(np.float64) - self.lo) * scale), dtype=np.int32)

    def release(self, z0: int, z1: int) -> None:
        """Drop the page-cache pages of a processed memmap slab from this process's resident set."""
        mm = getattr(self.data, "_mmap", None)
        if mm is None or not hasattr(mm, "madvise"):
            return
        d = self.data
        if not d.flags.f_contiguous:
            return
        plane = d.shape[0] * d.shape[1] * d.itemsize
        start = getattr(d, "offset", 0) + z0 * plane
        stop = getattr(d, "offset", 0) + min(z1, d.shape[2]) * plane
        start -= start % mmap.PAGESIZE
        try:
            mm.madvise(mmap.MADV_DONTNEED, start, max(0, stop - start))
        except (OSError, ValueError):
            pass


def _encode_array(a: np.ndarray, steps: np.ndarray, coder: int, level: int, writer: Writer, tile_base: int,
                  low: np.ndarray, choice: int = -1) -> None:
    """Encode every tile of ``a`` (a whole level or a z-slab of it) and stream the bricks."""
    ntiles = n_tiles(a.shape[0]) * n_tiles(a.shape[1]) * n_tiles(a.shape[2])
    cap = capacity(TILE ** 3)
    out = np.zeros(ntiles * cap, np.uint8)
    sizes = np.zeros(ntiles, np.int64)
    tfs = np.zeros(ntiles, np.int64)
    K.run_tiles(K.encode_level, a, steps, coder, out, cap, sizes, low, tfs, choice)
    for t in range(ntiles):
        writer.add(level, KIND_NODE, tile_base + t, out[t * cap:t * cap + int(sizes[t])], int(tfs[t]))


def _root_dpcm(root: np.ndarray) -> np.ndarray:
    d = root.astype(np.int64)
    for ax in range(3):
        d = np.diff(d, axis=ax, prepend=0)
    return d.astype(np.int32)


def _root_undpcm(d: np.ndarray) -> np.ndarray:
    r = d.astype(np.int64)
    for ax in (2, 1, 0):
        r = np.cumsum(r, axis=ax)
    return r.astype(np.int32)


def forward_pyramid(vol: np.ndarray) -> tuple[list[tuple[tuple[int, int, int], np.ndarray]], np.ndarray]:
    """Whole-volume forward wavelet octree in memory: per level (shape, tile buffers (ntiles, 32, 32, 32)) and
    the root lowpass. Used by the PSNR search and the wavelet + zstd baseline."""
    shapes = level_shapes(vol.shape)
    cur = np.ascontiguousarray(vol, dtype=np.int32)
    pyr = []
    for lev in range(1, len(shapes)):
        low = np.zeros(shapes[lev], np.int32)
        nt = n_tiles(cur.shape[0]) * n_tiles(cur.shape[1]) * n_tiles(cur.shape[2])
        det = np.zeros((nt, TILE, TILE, TILE), np.int32)
        K.run_tiles(K.transform_level, cur, low, det, np.zeros(nt, np.int64))
        pyr.append((cur.shape, det))
        cur = low
    return pyr, cur


def inverse_pyramid(pyr: list[tuple[tuple[int, int, int], np.ndarray]], root: np.ndarray, steps: np.ndarray,
                    quantise: bool) -> np.ndarray:
    """Inverse of :func:`forward_pyramid` with (quantisation and) dequantisation by ``steps[level]``."""
    cur = root
    for lev in range(len(pyr), 0, -1):
        shape, det = pyr[lev - 1]
        a = np.empty(shape, np.int32)
        K.run_tiles(K.reconstruct_level, cur, det, steps[lev], a, quantise)
        cur = a
    return cur


def _reconstruct_psnr(vol: np.ndarray, delta: float, peak: float, cache: dict[str, Any],
                      clip: tuple[float, float] = (0.0, 65535.0)) -> float:
    """PSNR of quantise + inverse wavelet at step ``delta`` (no entropy coding; same arithmetic as the decoder)."""
    if "pyr" not in cache:
        cache["pyr"], cache["root"] = forward_pyramid(vol)
    cur = inverse_pyramid(cache["pyr"], cache["root"], level_steps(delta, len(cache["pyr"])), True)
    mse = float(np.mean((np.clip(cur, clip[0], clip[1]).astype(np.float64) - vol) ** 2))
    return math.inf if mse == 0 else 10.0 * math.log10(peak * peak / mse)


def _psnr_sample(src: _Source) -> np.ndarray:
    shape = src.data.shape
    if int(np.prod(shape)) <= _PSNR_FULL_LIMIT:
        return src.slab(0, shape[2])
    lo = [max(0, (s - 256) // 2) for s in shape]
    sub = np.asarray(src.data[lo[0]:lo[0] + 256, lo[1]:lo[1] + 256, lo[2]:lo[2] + 256])
    return _Source(sub).slab(0, sub.shape[2]) if src.kind in _INT_TYPES else np.ascontiguousarray(
        np.rint((sub.astype(np.float64) - src.lo) * (65535.0 / max(src.hi - src.lo, 1e-300))), dtype=np.int32)


def compress(volume: RegularVolume, path: str | Path, mode: str = "lossless", quality: float | None = None,
             psnr: float | None = None, coder: str = "rans", progress: Progress | None = None,
             transform: str = "auto") -> dict[str, Any]:
    """Compress ``volume`` to the ``.vvz`` file ``path`` (atomic write); returns :func:`info` of the result.

    ``mode`` is ``"lossless"``, ``"quality"`` (needs ``quality``) or ``"psnr"`` (needs ``psnr``); passing
    ``quality`` or ``psnr`` alone selects the mode. ``coder``: ``"rans"`` (fast) or ``"arith"`` (higher ratio).
    ``progress(fraction, message)`` is called as levels/slabs finish. ``volume.data`` may be a ``numpy.memmap``
    (processed out of core). ``transform`` (lossless files; lossy files always use the 5/3): ``"auto"`` codes each
    node with the 5/3 and the S-transform and keeps the smaller, ``"5/3"`` or ``"haar"`` forces one.
    """
    if quality is not None and mode == "lossless":
        mode = "quality"
    if psnr is not None and mode == "lossless":
        mode = "psnr"
    if mode not in ("lossless", "quality", "psnr"):
        raise ValueError(f"unknown mode {mode!r} (lossless, quality, psnr)")
    if coder not in CODERS:
        raise ValueError(f"unknown coder {coder!r} ({', '.join(CODERS)})")
    if transform not in TRANSFORM_CHOICES:
        raise ValueError(f"unknown transform {transform!r} ({', '.join(TRANSFORM_CHOICES)})")
    choice = TRANSFORM_CHOICES[transform]
    report = progress or (lambda f, m: None)
    data = volume.data
    nx, ny, nz = (int(s) for s in data.shape)
    shape = (nx, ny, nz)
    src = _Source(data)
    peak = _peak(src.kind)
    clip = (float(np.iinfo(src.dtype).min), float(np.iinfo(src.dtype).max)) if src.kind in _INT_TYPES else (
        0.0, 65535.0)
    shapes = level_shapes(shape)
    levels = len(shapes) - 1
    delta, measured, psnr_scope = 0.0, None, "volume"
    if mode == "quality":
        delta = quality_to_delta(float(quality))  # type: ignore[arg-type]
    elif mode == "psnr":
        if psnr is None or not psnr > 0:
            raise ValueError("psnr mode needs a positive target in dB")
        report(0.0, "searching the quantiser step")
        sample = _psnr_sample(src)
        psnr_scope = "volume" if sample.shape == shape else "central 256^3 crop"
        cache: dict[str, Any] = {}
        lo_d, hi_d = 0.0, 1.0
        if _reconstruct_psnr(sample, 1.0, peak, cache, clip) >= psnr:
            while hi_d < 1e6 and _reconstruct_psnr(sample, hi_d * 2, peak, cache, clip) >= psnr:
                hi_d *= 2
            lo_d, hi_d = hi_d, hi_d * 2
            for _ in range(8):
                mid = math.sqrt(lo_d * hi_d)
                if _reconstruct_psnr(sample, mid, peak, cache, clip) >= psnr:
                    lo_d = mid
                else:
                    hi_d = mid
            delta = lo_d
        else:
            delta = 0.0  # even the finest lossy step misses the target: store losslessly
        measured = math.inf if delta == 0 else _reconstruct_psnr(sample, delta, peak, cache, clip)
        del cache, sample
    if mode == "quality" and int(np.prod(shape)) <= _PSNR_FULL_LIMIT:
        measured = _reconstruct_psnr(src.slab(0, shape[2]), delta, peak, {}, clip)
    steps = level_steps(delta, levels)
    ci = CODERS[coder]
    with Writer(path) as writer:
        total_work = sum(int(np.prod(s)) for s in shapes[:-1]) or 1
        done = 0
        if levels == 0:
            cur = src.slab(0, shape[2])
        else:
            cur = np.zeros(shapes[1], np.int32)
            for z0 in range(0, shape[2], _SLAB_PLANES):
                z1 = min(shape[2], z0 + _SLAB_PLANES)
                slab = src.slab(z0, z1)
                low = np.zeros(tuple((s + 1) // 2 for s in slab.shape), np.int32)
                tile_base = n_tiles(shape[0]) * n_tiles(shape[1]) * (z0 // TILE)
                _encode_array(slab, steps[1], ci, 1, writer, tile_base, low, choice)
                cur[:, :, z0 // 2:z0 // 2 + low.shape[2]] = low
                src.release(z0, z1)
                done += slab.size
                report(done / total_work, f"level 1: planes {z1}/{shape[2]}")
                del slab, low
            for lev in range(2, levels + 1):
                low = np.zeros(shapes[lev], np.int32)
                _encode_array(cur, steps[lev], ci, lev, writer, 0, low, choice)
                done += cur.size
                report(done / total_work, f"level {lev}")
                cur = low
        rbuf = np.zeros(capacity(cur.size), np.uint8)
        n = K.encode_root(_root_dpcm(cur), ci, rbuf)
        writer.add(levels, KIND_ROOT, 0, rbuf[:n])
        payload = writer.payload_bytes
        meta = {
            "format": "volviz-vvz", "dims": list(shape), "dtype": src.dtype.name, "kind": src.kind,
            "levels": levels, "tile": TILE, "coder": coder, "coder_version": CODER_VERSION[coder], "mode": mode,
            "delta": delta,
            "quality": None if quality is None else float(quality), "psnr_target": psnr,
            "psnr": None if measured is None or math.isinf(measured) else round(measured, 4),
            "psnr_scope": psnr_scope, "lossless": delta == 0.0, "peak": peak,
            "transform": transform if delta == 0.0 else "5/3",
            "float_lo": src.lo, "float_hi": src.hi, "spacing": list(volume.spacing), "origin": list(volume.origin),
            "name": volume.name, "original_bytes": int(np.prod(shape)) * src.dtype.itemsize,
            "payload_bytes": payload,
        }
        writer.close(meta)
    report(1.0, "done")
    return info(path)


def _check_meta(meta: dict[str, Any], name: str) -> tuple[tuple[int, int, int], int, str]:
    try:
        dims = tuple(int(d) for d in meta["dims"])
        levels = int(meta["levels"])
        coder = str(meta["coder"])
        kind = str(meta["kind"])
        float(meta["delta"]), np.dtype(str(meta["dtype"]))
        int(meta["tile"])
    except (KeyError, TypeError, ValueError) as exc:
        raise VVZError(name, f"metadata field missing or invalid ({exc})") from exc
    if len(dims) != 3 or min(dims) < 1 or max(dims) > 1 << 20:
        raise VVZError(name, f"bad dims {dims}")
    if int(meta["tile"]) != TILE:
        raise VVZError(name, f"tile size {meta['tile']} not supported (this build uses {TILE})")
    if coder not in CODERS:
        raise VVZError(name, f"unknown coder {coder!r}")
    if int(meta.get("coder_version", 1)) != CODER_VERSION[coder]:
        raise VVZError(name, f"{coder} coder version {meta.get('coder_version', 1)} is not supported (this build "
                       f"reads version {CODER_VERSION[coder]}); compress the volume again")
    if kind not in _INT_TYPES and kind not in ("float", "int-quantised"):
        raise VVZError(name, f"unknown sample kind {kind!r}")
    if levels != len(level_shapes(dims)) - 1:
        raise VVZError(name, f"{levels} levels do not match dims {dims}")
    return dims, levels, coder


def transforms(table: np.ndarray, idx: Any, lossless: bool, name: str) -> np.ndarray:
    """The per-brick transforms of the records ``table[idx]`` as int64, checked: 5/3 or S-transform, and the
    S-transform only in lossless files (:class:`VVZError` naming the brick otherwise)."""
    tfs = np.atleast_1d(table["transform"][idx]).astype(np.int64)
    allowed = (TRANSFORM_53, TRANSFORM_HAAR) if lossless else (TRANSFORM_53,)
    bad = np.nonzero(~np.isin(tfs, allowed))[0]
    if bad.size:
        i = int(np.atleast_1d(np.arange(len(table))[idx])[bad[0]])
        raise VVZError(name, f"brick {i} (level {int(table[i]['level'])}, tile {int(table[i]['tile'])}) names "
                       f"transform {int(tfs[bad[0]])}, not valid in a {'lossless' if lossless else 'lossy'} file")
    return tfs


def _tile_region(level: int, tile: int, shapes: list[tuple[int, int, int]]) -> tuple[tuple[int, int], ...]:
    """Voxel region (full resolution, half-open per axis) covered by a tile of ``level``."""
    shp = shapes[level - 1]
    c0, c1 = n_tiles(shp[0]), n_tiles(shp[1])
    t = (tile % c0, (tile // c0) % c1, tile // (c0 * c1))
    scale = 1 << (level - 1)
    return tuple((t[a] * TILE * scale, min(shapes[0][a], (t[a] + 1) * TILE * scale)) for a in range(3))


def decompress(path: str | Path, strict: bool = False, report: list[dict[str, Any]] | None = None,
               progress: Progress | None = None) -> RegularVolume:
    """Decode a ``.vvz`` file. A brick whose CRC32 fails (or whose stream is inconsistent) is named in a
    :class:`CorruptBrickWarning` (or raises :class:`CorruptBrickError` when ``strict``), appended to ``report``
    (level, tile, table index, voxel region), and its region is filled from the coarser level (details zero:
    the trilinear-like 5/3 interpolation of the parent); the rest of the volume decodes normally."""
    rd = Reader(path)
    name = str(path)
    try:
        meta = rd.meta
        dims, levels, coder = _check_meta(meta, name)
        shapes = level_shapes(dims)
        table = rd.table
        index: dict[tuple[int, int, int], int] = {}
        for i, rec in enumerate(table):
            index[(int(rec["kind"]), int(rec["level"]), int(rec["tile"]))] = i
        expected = 1 + sum(n_tiles(s[0]) * n_tiles(s[1]) * n_tiles(s[2]) for s in shapes[:-1])
        if len(index) != expected or len(table) != expected:
            raise VVZError(name, f"brick table has {len(table)} records, dims {dims} need {expected}")
        damaged: list[dict[str, Any]] = []
        payload = rd.payload
        ci = CODERS[coder]
        steps = level_steps(float(meta["delta"]), levels)

        def fail(i: int, level: int, tile: int, why: str) -> None:
            region = _tile_region(level, tile, shapes) if table[i]["kind"] == KIND_NODE else tuple(
                (0, d) for d in dims)
            entry = {"index": i, "level": level, "tile": tile, "kind": "root" if table[i]["kind"] == KIND_ROOT
                     else "node", "region": [list(r) for r in region], "reason": why}
            damaged.append(entry)

        ri = index.get((KIND_ROOT, levels, 0))
        if ri is None:
            raise VVZError(name, "root brick missing")
        root = np.zeros(shapes[-1], np.int32)
        rec = table[ri]
        if rd.brick_ok(ri):
            if K.decode_root(payload, int(rec["offset"]), int(rec["size"]), ci, root) != 0:
                root[:] = 0
                fail(ri, levels, 0, "inconsistent stream")
            else:
                root = _root_undpcm(root)
        else:
            fail(ri, levels, 0, "checksum mismatch")
        cur = root
        for lev in range(levels, 0, -1):
            shp = shapes[lev - 1]
            nt = n_tiles(shp[0]) * n_tiles(shp[1]) * n_tiles(shp[2])
            idx = np.array([index.get((KIND_NODE, lev, t), -1) for t in range(nt)], np.int64)
            if (idx < 0).any():
                raise VVZError(name, f"level {lev} tile {int(np.argmin(idx))} missing from the brick table")
            offs = table["offset"][idx].astype(np.int64)
            sizes = table["size"][idx].astype(np.int64)
            tfs = transforms(table, idx, float(meta["delta"]) == 0.0, name)
            valid = np.ones(nt, np.uint8)
            for t in range(nt):
                if not rd.brick_ok(int(idx[t])):
                    valid[t] = 0
                    fail(int(idx[t]), lev, t, "checksum mismatch")
            status = np.zeros(nt, np.int64)
            if lev == 1 and meta["kind"] in _INT_TYPES:  # the finest level writes the output type directly
                dt = np.dtype(meta["dtype"])
                a = np.empty(shp, dt)
                lo, hi = int(np.iinfo(dt).min), int(np.iinfo(dt).max)
            else:
                a = np.empty(shp, np.int32)
                lo, hi = -(1 << 31), (1 << 31) - 1
            K.run_tiles(K.decode_level, cur, payload, offs, sizes, tfs, valid, steps[lev], ci, a, lo, hi, status)
            for bad in np.nonzero(status != 0)[0]:
                fail(int(idx[bad]), lev, int(bad), "inconsistent stream")
            cur = a
            if progress:
                progress((levels - lev + 1) / max(levels, 1), f"level {lev}")
        if damaged:
            msg = "; ".join(f"brick {d['index']} ({d['kind']}, level {d['level']}, tile {d['tile']}, voxels "
                            f"{d['region']}): {d['reason']}" for d in damaged)
            if strict:
                raise CorruptBrickError(name, f"corrupt bricks: {msg}")
            warnings.warn(f"{name}: {len(damaged)} corrupt brick(s) filled from the coarser level: {msg}",
                          CorruptBrickWarning, stacklevel=2)
            if report is not None:
                report.extend(damaged)
        data = _to_dtype(cur, meta)
    finally:
        rd.close()
    return RegularVolume(data=data, spacing=tuple(meta.get("spacing", (1, 1, 1))),
                         origin=tuple(meta.get("origin", (0, 0, 0))),
                         name=str(meta.get("name", "scalars")), source=str(path))


def _to_dtype(a: np.ndarray, meta: dict[str, Any]) -> np.ndarray:
    kind = meta["kind"]
    dtype = np.dtype(meta["dtype"])
    if kind in _INT_TYPES:
        if a.dtype == dtype:  # already clipped and cast by the finest level's decode
            return a
        info_ = np.iinfo(dtype)
        out = np.empty(a.shape, dtype)
        K.run_tiles(K.clip_cast, a, info_.min, info_.max, out)
        return out
    lo, hi = float(meta["float_lo"]), float(meta["float_hi"])
    q = np.clip(a, 0, 65535).astype(np.float64)
    out = lo + q * ((hi - lo) / 65535.0)
    return out.astype(dtype) if kind == "float" else np.rint(out).astype(dtype)


def info(path: str | Path) -> dict[str, Any]:
    """Summary of a ``.vvz`` file: dims, dtype, levels, bricks (and stripped all-zero nodes, and nodes coded with the
    S-transform), ratio, PSNR, coder."""
    rd = Reader(path)
    try:
        meta = dict(rd.meta)
        dims, levels, coder = _check_meta(meta, str(path))
        table = rd.table
        meta.update(
            file_bytes=rd.file_size, bricks=int(len(table)), stripped_bricks=int(np.sum(table["size"] == 0)),
            haar_bricks=int(np.sum(table["transform"] == TRANSFORM_HAAR)),
            ratio=float(meta["original_bytes"]) / rd.file_size,
            bits_per_voxel=8.0 * rd.file_size / float(np.prod(dims)),
        )
    finally:
        rd.close()
    return meta
