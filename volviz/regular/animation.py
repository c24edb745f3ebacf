"""Animated regular volumes: motion-compensated I/P/B wavelet coding and one-decode-per-frame playback
(Guthe §2.2.3 and §2.2.5; 4D interpolation after the libMini note).

Encoder
- **Motion estimation** (§2.2.3): 8^3 blocks; for each block the vector ``v`` (|v_a| <= 15) minimising the squared
  error ``sum (cur(x) - ref(x + v))^2`` (reference samples clamped at the volume border). ``search="local"`` is the
  thesis's local search from the zero vector (move to the best of the 26 neighbouring vectors while the error drops;
  the axis-only 6-neighbourhood stalled in diagonal error valleys on a test field), starting from the best of
  the zero vector and the vectors of the three causal neighbour blocks (a standard video-coding predictor);
  ``search="full"`` tries all 31^3 vectors (ties keep the earlier, zero-first candidate).
- **Windowed motion compensation** (Watanabe and Singhal, §2.2.3, Fig. 2.15): each block predicts a 12^3 window (its
  8^3 core plus a 2-voxel apron) weighted by the separable cosine window ``w(o)`` (offset ``o`` from the core start):
  ``1/2 (1 - cos(pi (o + 2.5) / 4))`` for ``o`` in [-2, 2), 1 in [2, 6), ``1/2 (1 + cos(pi (o - 5.5) / 4))`` in
  [6, 10); neighbouring windows sum to one; at the volume border the weights are renormalised. The prediction is
  rounded to integers.
- **Frame types** (§2.2.3): I = wavelet-coded alone; P = windowed MC from the previous anchor (I/P) + wavelet-coded
  residual; B = average of the windowed MCs from the previous and next anchors, *MC only* (no residual, as in the
  thesis) in lossy modes and with a residual in lossless mode (so the whole series is bit-exact). The encoder is
  closed-loop: references are the decoded anchors, so lossy errors do not drift.
- A GOP ``pattern`` (``"I"``, ``"IPP"``, ``"IBB"``, ``"IBBPBBPPB"``, any string of I/P/B starting with I) repeats
  over the display frames; a trailing B without a following anchor becomes P. Volumes are **stored in the order of
  first use** ("MPEG order"): each anchor precedes the B volumes that need it.
- Residuals and intra volumes use the regular codec (:func:`volviz.regular.codec.compress`: lossless, or
  ``quality`` Q as there); motion vectors are int8 (x, y, z) per block, zlib-compressed (a deviation: the thesis
  codes them with an adaptive arithmetic model).

Store: a directory ``NAME.vvs/`` with ``series.json`` (format ``volviz-series`` v1: dims, dtype, pattern, mode,
per-volume type / references / files / CRC32 of the vector files, storage order) and one ``vNNNN.vvz`` per coded
volume plus ``mNNNN_r.bin`` vector files. Input: 8-bit volumes (residuals of 8-bit data fit the codec's int16).

Playback (§2.2.3): :func:`schedule` gives the setup decodes and, for every displayed frame, exactly one volume to
decode while that frame is shown; :class:`SeriesPlayer` follows it and offers 4D interpolation between steps.
"""
from __future__ import annotations

import json
import math
import tempfile
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np
from numba import njit

from volviz.io.atomic import new_temp_dir, recover_directory, replace_directory
from volviz.io.errors import ReadError
from volviz.model.datasets import RegularVolume, TimeSeries

from .backends import compression_backend
from .codec import compress, decompress

BLOCK = 8
APRON = 2
SEARCH = 15
FORMAT = "volviz-series"
VERSION = 1


class SeriesError(ReadError):
    """A ``.vvs`` series store that cannot be read; the message names the file and the problem."""


# -- motion estimation and compensation ------------------------------------------------------------------------------
@njit(cache=True, nogil=True)
def _sse(cur, ref, s0, s1, s2, e0, e1, e2, v0, v1, v2):
    n0, n1, n2 = ref.shape
    acc = 0.0
    for i in range(s0, e0):
        ri = min(max(i + v0, 0), n0 - 1)
        for j in range(s1, e1):
            rj = min(max(j + v1, 0), n1 - 1)
            for k in range(s2, e2):
                rk = min(max(k + v2, 0), n2 - 1)
                d = float(cur[i, j, k]) - float(ref[ri, rj, rk])
                acc += d * d
    return acc


@njit(cache=True, nogil=True)
def _estimate(cur, ref, full, out):
    c0, c1, c2 = out.shape[:3]
    n0, n1, n2 = cur.shape
    for b0 in range(c0):
        for b1 in range(c1):
            for b2 in range(c2):
                s0, s1, s2 = b0 * BLOCK, b1 * BLOCK, b2 * BLOCK
                e0, e1, e2 = min(s0 + BLOCK, n0), min(s1 + BLOCK, n1), min(s2 + BLOCK, n2)
                best = _sse(cur, ref, s0, s1, s2, e0, e1, e2, 0, 0, 0)
                v0 = v1 = v2 = 0
                if full:
                    for a in range(-SEARCH, SEARCH + 1):
                        for b in range(-SEARCH, SEARCH + 1):
                            for c in range(-SEARCH, SEARCH + 1):
                                if best == 0.0:
                                    break
                                e = _sse(cur, ref, s0, s1, s2, e0, e1, e2, a, b, c)
                                if e < best or (e == best and abs(a) + abs(b) + abs(c) < abs(v0) + abs(v1) + abs(v2)):
                                    best, v0, v1, v2 = e, a, b, c
                else:
                    for nb in range(3):  # predictors: the vectors of the causal neighbour blocks
                        p0, p1, p2 = b0 - (nb == 0), b1 - (nb == 1), b2 - (nb == 2)
                        if p0 < 0 or p1 < 0 or p2 < 0:
                            continue
                        a, b, c = int(out[p0, p1, p2, 0]), int(out[p0, p1, p2, 1]), int(out[p0, p1, p2, 2])
                        e = _sse(cur, ref, s0, s1, s2, e0, e1, e2, a, b, c)
                        if e < best:
                            best, v0, v1, v2 = e, a, b, c
                    for _ in range(3 * SEARCH):
                        moved = False
                        bb, w0, w1, w2 = best, v0, v1, v2
                        for nb in range(27):
                            if nb != 13:
                                a = v0 + nb // 9 - 1
                                b = v1 + (nb // 3) % 3 - 1
                                c = v2 + nb % 3 - 1
                                if abs(a) > SEARCH or abs(b) > SEARCH or abs(c) > SEARCH:
                                    continue
                                e = _sse(cur, ref, s0, s1, s2, e0, e1, e2, a, b, c)
                                if e < bb:
                                    bb, w0, w1, w2 = e, a, b, c
                                    moved = True
                        if not moved:
                            break
                        best, v0, v1, v2 = bb, w0, w1, w2
                out[b0, b1, b2, 0] = v0
                out[b0, b1, b2, 1] = v1
                out[b0, b1, b2, 2] = v2


def n_blocks(shape: Sequence[int]) -> tuple[int, int, int]:
    return tuple((int(s) + BLOCK - 1) // BLOCK for s in shape)  # type: ignore[return-value]


def estimate_motion(cur: np.ndarray, ref: np.ndarray, search: str = "local") -> np.ndarray:
    """Motion vectors (c0, c1, c2, 3) int8 of the 8^3 blocks of ``cur`` against ``ref``: ``cur(x) ~ ref(x + v)``."""
    if cur.shape != ref.shape or cur.ndim != 3:
        raise ValueError(f"motion estimation needs two 3D volumes of one shape, got {cur.shape} and {ref.shape}")
    if search not in ("local", "full"):
        raise ValueError(f"unknown search {search!r} (local, full)")
    out = np.zeros(n_blocks(cur.shape) + (3,), np.int8)
    _estimate(np.ascontiguousarray(cur), np.ascontiguousarray(ref), search == "full", out)
    return out


def window_weights() -> np.ndarray:
    """The 1D cosine window over the 12 offsets -2..9 of a block (partition of unity with its neighbours)."""
    o = np.arange(-APRON, BLOCK + APRON, dtype=np.float64)
    w = np.ones_like(o)
    rise = o < APRON
    fall = o >= BLOCK - APRON
    w[rise] = 0.5 * (1 - np.cos(np.pi * (o[rise] + APRON + 0.5) / (2 * APRON)))
    w[fall] = 0.5 * (1 + np.cos(np.pi * (o[fall] - (BLOCK - APRON) + 0.5) / (2 * APRON)))
    return w


@njit(cache=True, nogil=True)
def _compensate(ref, mv, win, acc, wsum):
    n0, n1, n2 = ref.shape
    c0, c1, c2 = mv.shape[:3]
    for b0 in range(c0):
        for b1 in range(c1):
            for b2 in range(c2):
                v0, v1, v2 = int(mv[b0, b1, b2, 0]), int(mv[b0, b1, b2, 1]), int(mv[b0, b1, b2, 2])
                for o0 in range(-APRON, BLOCK + APRON):
                    i = b0 * BLOCK + o0
                    if i < 0 or i >= n0:
                        continue
                    ri = min(max(i + v0, 0), n0 - 1)
                    w0 = win[o0 + APRON]
                    for o1 in range(-APRON, BLOCK + APRON):
                        j = b1 * BLOCK + o1
                        if j < 0 or j >= n1:
                            continue
                        rj = min(max(j + v1, 0), n1 - 1)
                        w01 = w0 * win[o1 + APRON]
                        for o2 in range(-APRON, BLOCK + APRON):
                            k = b2 * BLOCK + o2
                            if k < 0 or k >= n2:
                                continue
                            rk = min(max(k + v2, 0), n2 - 1)
                            w = w01 * win[o2 + APRON]
                            acc[i, j, k] += w * ref[ri, rj, rk]
                            wsum[i, j, k] += w


def compensate(ref: np.ndarray, mv: np.ndarray) -> np.ndarray:
    """Windowed motion compensation (12^3 cosine windows): the float64 prediction of the current volume."""
    acc = np.zeros(ref.shape)
    wsum = np.zeros(ref.shape)
    _compensate(np.ascontiguousarray(ref), np.ascontiguousarray(mv), window_weights(), acc, wsum)
    return acc / wsum


# -- GOP structure and playback schedule -----------------------------------------------------------------------------
@dataclass(frozen=True)
class FrameInfo:
    display: int
    kind: str                 # "I", "P" or "B"
    refs: tuple[int, ...]     # display indices of the reference anchors (P: previous; B: previous, next)


def frame_types(n: int, pattern: str) -> list[FrameInfo]:
    """Types and references of ``n`` display frames under a repeating GOP ``pattern``."""
    pattern = pattern.upper()
    if not pattern or pattern[0] != "I" or set(pattern) - set("IPB"):
        raise ValueError(f"GOP pattern must start with I and contain only I, P, B: {pattern!r}")
    if n < 1:
        raise ValueError("a series needs at least one volume")
    kinds = [pattern[t % len(pattern)] for t in range(n)]
    for t in range(n - 1, -1, -1):  # trailing B without a next anchor -> P
        if kinds[t] != "B":
            break
        kinds[t] = "P"
    out, prev = [], -1
    nxt = [0] * n
    following = -1
    for t in range(n - 1, -1, -1):
        nxt[t] = following
        if kinds[t] != "B":
            following = t
    for t, k in enumerate(kinds):
        refs: tuple[int, ...] = () if k == "I" else (prev,) if k == "P" else (prev, nxt[t])
        out.append(FrameInfo(t, k, refs))
        if k != "B":
            prev = t
    return out


def storage_order(frames: list[FrameInfo]) -> list[int]:
    """Display indices in the order of first use ("MPEG order"): each anchor right before the B volumes that
    reference it as their next anchor."""
    order: list[int] = []
    done: set[int] = set()
    for f in frames:
        for r in f.refs:
            if r not in done:
                order.append(r)
                done.add(r)
        if f.display not in done:
            order.append(f.display)
            done.add(f.display)
    return order


def schedule(order: Sequence[int]) -> tuple[list[int], list[int | None]]:
    """Playback schedule: (setup decodes, decode per displayed frame). While frame ``t`` is shown, exactly one
    stored volume is decoded (``None`` only at the end); every frame is decoded before it is shown."""
    n = len(order)
    pos = {d: i for i, d in enumerate(order)}
    k = max(pos[t] - t for t in range(n)) + 1  # volumes stored before frame 0 is shown
    setup = list(order[:k])
    per_frame: list[int | None] = [order[t + k] if t + k < n else None for t in range(n)]
    return setup, per_frame


# -- encoder ---------------------------------------------------------------------------------------------------------
def _frames_of(series: TimeSeries | Sequence[np.ndarray | RegularVolume]) -> Callable[[int], np.ndarray]:
    if isinstance(series, TimeSeries):
        return lambda i: np.asarray(series.frame(i).data)  # type: ignore[union-attr]
    return lambda i: np.asarray(series[i].data if isinstance(series[i], RegularVolume) else series[i])


def _predict(f: FrameInfo, mvs: list[np.ndarray], refs: dict[int, np.ndarray]) -> np.ndarray:
    preds = [compensate(refs[r], mv) for r, mv in zip(f.refs, mvs)]
    return np.floor(sum(preds) / len(preds) + 0.5).astype(np.int32)


def _segments(frames: list[FrameInfo]) -> list[list[int]]:
    """Display indices grouped from each I volume to the next: the units of distributed encoding."""
    parts: list[list[int]] = []
    for f in frames:
        if f.kind == "I" or not parts:
            parts.append([])
        parts[-1].append(f.display)
    return parts


def _encode_part(get: Callable[[int], np.ndarray] | dict[int, np.ndarray], frames: list[FrameInfo],
                 order: list[int], targets: Sequence[int], kw: dict[str, Any], b_res: bool,
                 search: str) -> list[tuple[int, dict[str, Any], dict[str, bytes]]]:
    """Encode the display volumes ``targets``: walk the storage order from the first of them to the last, coding
    every anchor on the way (an anchor outside ``targets`` -- the next I volume that trailing B volumes reference --
    is coded only for its reconstruction) and skipping B volumes outside ``targets``. Returns (storage index,
    record, {file name: bytes}) per target. Deterministic, so any split of the series gives the same bytes as one
    sequential pass."""
    fetch = get.__getitem__ if isinstance(get, dict) else get
    pos = {d: i for i, d in enumerate(order)}
    tset = set(targets)
    first, last = min(pos[d] for d in tset), max(pos[d] for d in tset)
    todo = [i for i in range(first, last + 1) if order[i] in tset or frames[order[i]].kind != "B"]
    last_use: dict[int, int] = {}
    for i in todo:
        for r in frames[order[i]].refs:
            last_use[r] = i
    decoded: dict[int, np.ndarray] = {}
    out = []
    with tempfile.TemporaryDirectory(prefix="vvs-part") as td:
        tmp = Path(td)
        for i in todo:
            d = order[i]
            f = frames[d]
            cur = fetch(d)
            dtype = cur.dtype
            lo, hi = int(np.iinfo(dtype).min), int(np.iinfo(dtype).max)
            rec: dict[str, Any] = {"display": d, "type": f.kind, "refs": list(f.refs), "mv": [], "file": None}
            files: dict[str, bytes] = {}
            if f.kind == "I":
                pred = None
                residual = cur.astype(np.int32)
            else:
                mvs = [estimate_motion(cur, decoded[r], search) for r in f.refs]
                for j, mv in enumerate(mvs):
                    blob = zlib.compress(mv.tobytes(), 9)
                    name = f"m{i:04d}_{j}.bin"
                    files[name] = blob
                    rec["mv"].append({"file": name, "crc": zlib.crc32(blob)})
                pred = _predict(f, mvs, decoded)
                residual = cur.astype(np.int32) - pred
            if f.kind != "B" or b_res:
                name = f"v{i:04d}.vvz"
                vol = residual.astype(dtype) if pred is None else residual.astype(np.int16)
                compress(RegularVolume(vol), tmp / name, **kw)
                rec["file"] = name
                files[name] = (tmp / name).read_bytes()
                back = decompress(tmp / name).data.astype(np.int32)
                (tmp / name).unlink()
                rec_vol = back if pred is None else pred + back
            else:
                rec_vol = pred  # type: ignore[assignment]
            if f.kind != "B":
                decoded[d] = np.clip(rec_vol, lo, hi).astype(dtype)
            for r in list(decoded):
                if last_use.get(r, -1) <= i and r != d:
                    del decoded[r]
            if d in tset:
                out.append((i, rec, files))
    return out


def compress_series(series: TimeSeries | Sequence[np.ndarray | RegularVolume], path: str | Path,
                    pattern: str = "IBBPBBPPB", mode: str = "lossless", quality: float | None = None,
                    search: str = "local", b_residual: bool | None = None,
                    progress: Callable[[float, str], None] | None = None,
                    scheduler: str | None = None, backend: str = "dask") -> dict[str, Any]:
    """Encode a series of 8-bit volumes into the store directory ``path`` (replaced if it exists); returns
    :func:`series_info`. ``b_residual`` defaults to True for lossless and False (MC only) otherwise.

    ``scheduler``: address of a cluster for the compression ``backend`` (entry-point group
    ``volviz.compression_backends``; ``"dask"``, from plugins/volviz-dask, takes a dask.distributed scheduler's
    address such as ``tcp://host:8786``). The series is then split at its I volumes into independent parts (each
    part also codes the next I volume for the reconstruction its trailing B volumes need), one task per part; the
    client reads the volumes, sends each task its volumes, and writes the returned files. The store is
    bit-identical to the sequential one."""
    if mode not in ("lossless", "quality"):
        raise ValueError(f"unknown mode {mode!r} (lossless, quality)")
    if mode == "quality" and quality is None:
        raise ValueError("quality mode needs quality=Q")
    get = _frames_of(series)
    n = len(series)
    frames = frame_types(n, pattern)
    order = storage_order(frames)
    first = get(0)
    if first.ndim != 3 or first.dtype not in (np.uint8, np.int8):
        raise ValueError(f"series volumes must be 3D 8-bit arrays, got {first.dtype} {first.shape}")
    dtype, dims = first.dtype, first.shape

    def checked(d: int) -> np.ndarray:
        cur = get(d)
        if cur.shape != dims or cur.dtype != dtype:
            raise ValueError(f"volume {d} has {cur.dtype} {cur.shape}, the series {dtype} {dims}")
        return cur

    b_res = (mode == "lossless") if b_residual is None else bool(b_residual)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = new_temp_dir(path)  # the new store is written beside the old one, which stays until it is complete
    kw: dict[str, Any] = {"mode": mode} if mode == "lossless" else {"quality": quality}
    records: dict[int, dict[str, Any]] = {}

    def store(results: list[tuple[int, dict[str, Any], dict[str, bytes]]]) -> None:
        for i, rec, files in results:
            for name, blob in files.items():
                (tmp / name).write_bytes(blob)
            records[i] = rec
            if progress:
                progress(len(records) / n, f"volume {rec['display']} ({rec['type']})")

    if scheduler is None:
        store(_encode_part(checked, frames, order, list(range(n)), kw, b_res, search))
    else:
        pos = {d: i for i, d in enumerate(order)}

        def tasks():
            for part in _segments(frames):
                lo_i, hi_i = min(pos[d] for d in part), max(pos[d] for d in part)
                need = {order[i] for i in range(lo_i, hi_i + 1) if order[i] in part or frames[order[i]].kind != "B"}
                yield ({d: checked(d) for d in sorted(need)}, frames, order, part, kw, b_res, search)

        for result in compression_backend(backend)(scheduler, _encode_part, tasks()):
            store(result)
    if sorted(records) != list(range(n)):
        raise RuntimeError(f"series encoding produced storage records {sorted(records)}, expected 0..{n - 1}")
    meta = {"format": FORMAT, "version": VERSION, "dims": list(dims), "dtype": np.dtype(dtype).name, "n": n,
            "pattern": pattern.upper(), "mode": mode, "quality": quality, "b_residual": b_res, "search": search,
            "storage": [records[i] for i in range(n)]}
    (tmp / "series.json").write_text(json.dumps(meta, indent=1))
    replace_directory(tmp, path)  # a kill at any moment leaves one complete store (recovered on the next open)
    return series_info(path)


# -- decoder and player ----------------------------------------------------------------------------------------------
def _read_meta(path: Path) -> dict[str, Any]:
    name = str(path)
    recover_directory(path)  # a replacement interrupted by a kill: put the old store back or finish the swap
    try:
        meta = json.loads((path / "series.json").read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise SeriesError(name, f"cannot read series.json ({exc})") from exc
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise SeriesError(name, "not a volviz-series store")
    if int(meta.get("version", 0)) > VERSION:
        raise SeriesError(name, f"series version {meta.get('version')} is newer than this reader ({VERSION})")
    try:
        n = int(meta["n"])
        dims = tuple(int(d) for d in meta["dims"])
        recs = meta["storage"]
        if len(recs) != n or sorted(int(r["display"]) for r in recs) != list(range(n)) or len(dims) != 3:
            raise ValueError("storage records do not cover the display frames")
        for r in recs:
            if r["type"] not in ("I", "P", "B"):
                raise ValueError(f"bad volume type {r['type']!r}")
    except (KeyError, TypeError, ValueError) as exc:
        raise SeriesError(name, f"series.json field missing or invalid ({exc})") from exc
    return meta


class SeriesDecoder:
    """Decodes the stored volumes of a series store in storage order (or any order that has its references)."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.meta = _read_meta(self.path)
        self.dims = tuple(self.meta["dims"])
        self.dtype = np.dtype(self.meta["dtype"])
        self.records = {int(r["display"]): r for r in self.meta["storage"]}
        self.order = [int(r["display"]) for r in self.meta["storage"]]
        self.decodes = 0

    def decode(self, display: int, refs: dict[int, np.ndarray]) -> np.ndarray:
        """Decode display frame ``display``; ``refs`` must hold its decoded reference anchors."""
        rec = self.records[display]
        info_ = np.iinfo(self.dtype)
        pred = None
        if rec["type"] != "I":
            mvs = []
            for m in rec["mv"]:
                try:
                    blob = (self.path / m["file"]).read_bytes()
                except OSError as exc:
                    raise SeriesError(str(self.path / m["file"]), f"cannot read motion vectors ({exc})") from exc
                if zlib.crc32(blob) != int(m["crc"]):
                    raise SeriesError(str(self.path / m["file"]), "motion-vector checksum mismatch")
                mvs.append(np.frombuffer(zlib.decompress(blob), np.int8).reshape(n_blocks(self.dims) + (3,)))
            missing = [r for r in rec["refs"] if r not in refs]
            if missing:
                raise ValueError(f"frame {display} needs reference frames {missing} decoded first")
            pred = _predict(FrameInfo(display, rec["type"], tuple(rec["refs"])), mvs, refs)
        if rec["file"] is not None:
            if not (self.path / rec["file"]).is_file():
                raise SeriesError(str(self.path / rec["file"]), f"volume file of frame {display} is missing")
            res = decompress(self.path / rec["file"], strict=True).data.astype(np.int32)
            pred = res if pred is None else pred + res
        self.decodes += 1
        return np.clip(pred, info_.min, info_.max).astype(self.dtype)  # type: ignore[arg-type]


class SeriesPlayer:
    """Sequential playback following :func:`schedule`: :meth:`frame` shows frame ``t`` and performs exactly one
    scheduled decode; :meth:`at` returns the 4D-interpolated volume at a continuous display time."""

    def __init__(self, path: str | Path) -> None:
        self.decoder = SeriesDecoder(path)
        self.n = len(self.decoder.order)
        self.setup_list, self.per_frame = schedule(self.decoder.order)
        self._have: dict[int, np.ndarray] = {}
        self._next = 0
        self.decodes_per_frame: list[int] = []
        for d in self.setup_list:
            self._decode(d)

    def _decode(self, d: int) -> None:
        self._have[d] = self.decoder.decode(d, self._have)

    def frame(self, t: int) -> np.ndarray:
        """Frame ``t`` (must be the next frame in display order), then the one decode scheduled for it."""
        if t != self._next:
            raise ValueError(f"sequential playback expects frame {self._next}, got {t}")
        if t not in self._have:
            raise RuntimeError(f"frame {t} was not decoded in time (schedule broken)")
        vol = self._have[t]
        before = self.decoder.decodes
        nxt = self.per_frame[t]
        if nxt is not None:
            self._decode(nxt)
        self.decodes_per_frame.append(self.decoder.decodes - before)
        self._next = t + 1
        # release what no later frame needs: shown B volumes and anchors no longer referenced
        needed = {r for d in self.decoder.order[self.decoder.order.index(nxt) if nxt is not None else self.n:]
                  for r in self.decoder.records[d]["refs"]}
        for d in list(self._have):
            if d <= t and d not in needed and d != t:
                del self._have[d]
        return vol

    def at(self, time: float) -> np.ndarray:
        """4D interpolation (libMini note): linear in time between the two decoded frames around ``time``, for
        ``time`` in [t, t + 1] where ``t`` is the last frame returned by :meth:`frame`."""
        t = self._next - 1
        if not (t >= 0 and t <= time <= t + 1):
            raise ValueError(f"time {time} outside the playable interval [{t}, {t + 1}]")
        a = self._have.get(t)
        if a is None:
            raise RuntimeError(f"frame {t} no longer held")
        b = self._have.get(min(t + 1, self.n - 1), a)
        w = time - t
        return (1 - w) * a.astype(np.float32) + w * b.astype(np.float32)


def series_info(path: str | Path) -> dict[str, Any]:
    """Summary: dims, count, pattern, bytes per type, ratio."""
    p = Path(path)
    meta = _read_meta(p)
    total = sum(f.stat().st_size for f in p.iterdir())
    by_type: dict[str, int] = {"I": 0, "P": 0, "B": 0}
    for r in meta["storage"]:
        size = sum((p / m["file"]).stat().st_size for m in r["mv"])
        if r["file"]:
            size += (p / r["file"]).stat().st_size
        by_type[r["type"]] += size
    original = int(np.prod(meta["dims"])) * np.dtype(meta["dtype"]).itemsize * int(meta["n"])
    return {"dims": meta["dims"], "n": meta["n"], "pattern": meta["pattern"], "mode": meta["mode"],
            "quality": meta["quality"], "bytes": total, "bytes_by_type": by_type, "ratio": original / total,
            "bits_per_voxel": 8.0 * total / (original / np.dtype(meta["dtype"]).itemsize),
            "storage_order": [r["display"] for r in meta["storage"]]}


def decompress_series(path: str | Path) -> list[np.ndarray]:
    """All frames in display order (decoded in storage order)."""
    dec = SeriesDecoder(path)
    have: dict[int, np.ndarray] = {}
    for d in dec.order:
        have[d] = dec.decode(d, have)
    return [have[t] for t in range(len(dec.order))]


def psnr(a: np.ndarray, b: np.ndarray, peak: float = 255.0) -> float:
    mse = float(np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2))
    return math.inf if mse == 0 else 10 * math.log10(peak * peak / mse)
