"""``volviz bench compression``: rate-distortion and decode speed of the wavelet codec against zfp, blosc2-zstd
and a plain wavelet + zstd baseline (Guthe §2.2.2, §2.3.8).

For each volume (embryo 256^3 8-bit, headsq 64x64x93 16-bit, neghip 66^3 8-bit, and ``field512``: a generated
512^3 8-bit field of band-limited noise, see :func:`field512`): our codec with the fast rANS coder
and the adaptive arithmetic coder, lossless and over a quality sweep; zfp (``zfpy``, fixed-rate mode on float32, the
reconstruction rounded and clipped to the integer type) at several rates; blosc2 with zstd (clevel 9, shuffle,
lossless); the same tiled 5/3 transform and quantiser followed by zstd (level 19) over the sign-mapped 16-bit
coefficients. PSNR peak: 255 for 8-bit data, the data maximum for the 16-bit CT (stated in the table). Decode speed:
median of ``--reps`` runs after a warm-up, in MB/s of the decoded volume (one byte per 8-bit voxel), including file
reading, checksums and the inverse wavelet.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from volviz.argtypes import UsageParser, int_in

DATA = Path(os.environ.get("VOLVIZ_DATA", Path(__file__).resolve().parents[3] / "shared" / "data"))
QUALITIES = (90, 86, 84, 82, 80, 75, 70, 65, 60, 55, 50)  # integer steps: Q >= 95 is lossless
BIG_QUALITIES = (90, 80, 70, 60, 50)  # field512: fewer settings, each compress takes seconds
ZFP_RATES = (0.25, 0.5, 1.0, 2.0, 4.0)
BIG = 1 << 25  # volumes above this many voxels skip the slow wavelet + zstd baseline


def field512(n: int = 512, seed: int = 6) -> np.ndarray:
    """Deterministic 8-bit test field: 12 plane waves with random directions, wavelengths n/24..n/2 and phases,
    amplitude ~ 1/sqrt(frequency), scaled to 127.5 +- 120 and rounded (generated in z-slabs, never stored)."""
    rng = np.random.default_rng(seed)
    k = rng.normal(size=(12, 3))
    k /= np.linalg.norm(k, axis=1, keepdims=True)
    freq = rng.uniform(2, 24, 12)[:, None] * k * (2 * np.pi / n)
    amp = 1.0 / np.sqrt(np.linalg.norm(freq, axis=1) * n / (2 * np.pi))
    amp /= amp.sum()
    phase = rng.uniform(0, 2 * np.pi, 12)
    out = np.empty((n, n, n), np.uint8)
    x = np.arange(n, dtype=np.float32)
    for z0 in range(0, n, 32):
        z = x[z0:z0 + 32]
        acc = np.zeros((n, n, len(z)), np.float32)
        for f, a, p in zip(freq, amp, phase):
            ex = np.exp(1j * (f[0] * x + p)).astype(np.complex64)
            ey = np.exp(1j * f[1] * x).astype(np.complex64)
            ez = np.exp(1j * f[2] * z).astype(np.complex64)
            acc += a * (ex[:, None, None] * ey[None, :, None] * ez[None, None, :]).imag
        out[:, :, z0:z0 + 32] = np.clip(np.rint(127.5 + 120 * acc), 0, 255).astype(np.uint8)
    return out


def _load(name: str) -> tuple[np.ndarray, float]:
    # the readers (registry and plugins): loaded when a case first reads a file
    from volviz.io import read, read_slice_stack

    if name == "embryo":
        return np.asarray(read(DATA / "volumes" / "embryo.slc").data), 255.0
    if name == "neghip":
        return np.asarray(read(DATA / "volumes" / "neghip.slc").data), 255.0
    if name == "field512":
        return field512(), 255.0
    if name == "headsq":
        v = read_slice_stack(str(DATA / "headsq" / "quarter.%d"), dims=(64, 64, 93), dtype="<u2").data
        return np.asarray(v), float(v.max())
    raise SystemExit(f"unknown volume {name!r}")


def _timed(fn: Callable[[], Any], reps: int) -> tuple[float | None, Any]:
    out = fn()  # warm-up (and JIT)
    times = []
    for _ in range(reps):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return (statistics.median(times) if times else None), out


def _psnr(a: np.ndarray, b: np.ndarray, peak: float) -> float:
    se = 0.0
    for z0 in range(0, a.shape[-1], 32):  # z-slabs: no float64 copy of a 512^3 volume
        se += float(np.sum((a[..., z0:z0 + 32].astype(np.float64) - b[..., z0:z0 + 32]) ** 2))
    mse = se / a.size
    return math.inf if mse == 0 else 10 * math.log10(peak * peak / mse)


def _row(method: str, setting: str, nbytes: int, vol: np.ndarray, rec: np.ndarray, peak: float,
         dec_s: float | None) -> dict[str, Any]:
    return {"method": method, "setting": setting, "bytes": int(nbytes), "bpv": 8.0 * nbytes / vol.size,
            "ratio": vol.nbytes / nbytes, "psnr": _psnr(vol, rec, peak), "exact": bool(np.array_equal(vol, rec)),
            "decode_mb_s": None if dec_s is None else vol.nbytes / dec_s / 1e6}


def _ours(vol: np.ndarray, peak: float, tmp: Path, reps: int, speed_at: set[str]) -> list[dict[str, Any]]:
    # the kernels (Numba) of this case only: a bench loads what its cases run
    from volviz.model.datasets import RegularVolume
    from volviz.regular.codec import compress, decompress

    rows = []
    rv = RegularVolume(np.asfortranarray(vol))
    for coder in ("rans", "arith"):
        for q in (None,) + (BIG_QUALITIES if vol.size > BIG else QUALITIES):
            path = tmp / f"{coder}_{q}.vvz"
            compress(rv, path, coder=coder, quality=q)
            setting = "lossless" if q is None else f"Q{q}"
            if setting in speed_at:
                dec, rec = _timed(lambda: decompress(path).data, reps)
            else:
                dec, rec = None, decompress(path).data
            rows.append(_row(f"vvz-{coder}", setting, path.stat().st_size, vol, rec, peak, dec))
        path = tmp / f"{coder}_53.vvz"  # the same without the per-node S-transform choice, for comparison
        compress(rv, path, coder=coder, transform="5/3")
        rows.append(_row(f"vvz-{coder}", "lossless, 5/3 only", path.stat().st_size, vol, decompress(path).data,
                         peak, None))
    return rows


def _zfp(vol: np.ndarray, peak: float, reps: int) -> list[dict[str, Any]]:
    # optional: zfpy (volviz[bench]), a peer measured beside volviz's codec
    import zfpy

    info = np.iinfo(vol.dtype)
    f = np.ascontiguousarray(vol, dtype=np.float32)
    rows = []
    for rate in ZFP_RATES:
        buf = zfpy.compress_numpy(f, rate=rate)
        dec, out = _timed(lambda: np.clip(np.rint(zfpy.decompress_numpy(buf)), info.min, info.max).astype(vol.dtype),
                          reps if rate == 1.0 else 0)
        rows.append(_row("zfp", f"rate {rate}", len(buf), vol, out, peak, dec if rate == 1.0 else None))
    return rows


def _blosc(vol: np.ndarray, peak: float, reps: int) -> list[dict[str, Any]]:
    # optional: blosc2 (volviz[bench]), a peer measured beside volviz's codec
    import blosc2

    c = np.ascontiguousarray(vol)
    buf = blosc2.compress(c, typesize=c.itemsize, clevel=9, filter=blosc2.Filter.SHUFFLE, codec=blosc2.Codec.ZSTD)
    dec, out = _timed(lambda: np.frombuffer(blosc2.decompress(buf), vol.dtype).reshape(vol.shape), reps)
    return [_row("blosc2-zstd", "clevel 9 shuffle", len(buf), vol, out, peak, dec)]


def _wavelet_zstd(vol: np.ndarray, peak: float, reps: int) -> list[dict[str, Any]]:
    """Baseline: the same tiled 5/3 pyramid and quantiser, sign-mapped 16-bit coefficients, zstd level 19."""
    # optional: zstandard (volviz[bench]), a peer measured beside volviz's codec
    import zstandard

    from volviz.regular import kernels as K
    from volviz.regular.codec import forward_pyramid, inverse_pyramid, level_steps, quality_to_delta

    info = np.iinfo(vol.dtype)
    rows = []
    for q in (None, 90, 80, 70, 60):
        pyr, root = forward_pyramid(vol)
        steps = level_steps(0.0 if q is None else quality_to_delta(q), len(pyr))
        parts = [root.astype("<i4").tobytes()]
        for lev, (shape, det) in enumerate(pyr, start=1):
            K.run_tiles(K.quantise_level, det, np.array(shape, np.int64), steps[lev])
            v = det.astype(np.int64)
            zz = np.where(v >= 0, 2 * v, -2 * v - 1)
            parts.append(zz.astype("<u2" if zz.max() < 65536 else "<u4").tobytes())
        blob = zstandard.ZstdCompressor(level=19).compress(b"".join(parts))
        shapes_dt = [(shape, det.dtype) for shape, det in pyr]

        def decode() -> np.ndarray:
            raw = zstandard.ZstdDecompressor().decompress(blob)
            pos = root.nbytes
            rec_root = np.frombuffer(raw[:pos], "<i4").reshape(root.shape)
            levels = []
            for (shape, _), (_, det0) in zip(shapes_dt, pyr):
                n = det0.size
                width = 2 if len(raw) - pos >= 2 * n else 4
                zz = np.frombuffer(raw[pos:pos + width * n], f"<u{width}").astype(np.int32).reshape(det0.shape)
                pos += width * n
                levels.append((shape, np.where(zz & 1, -((zz + 1) >> 1), zz >> 1).astype(np.int32)))
            return np.clip(inverse_pyramid(levels, rec_root, steps, False), info.min, info.max).astype(vol.dtype)

        dec, rec = _timed(decode, reps if q in (None, 80) else 0)
        rows.append(_row("wavelet+zstd", "lossless" if q is None else f"Q{q}", len(blob), vol, rec, peak,
                         dec if q in (None, 80) else None))
    return rows


def _interp_psnr(rows: list[dict[str, Any]], method: str, bpv: float) -> float | None:
    pts = sorted((r["bpv"], r["psnr"]) for r in rows if r["method"] == method and math.isfinite(r["psnr"]))
    for (b0, p0), (b1, p1) in zip(pts, pts[1:]):
        if b0 <= bpv <= b1:
            t = (math.log(bpv) - math.log(b0)) / (math.log(b1) - math.log(b0))
            return p0 + t * (p1 - p0)
    return None


def _plot(results: dict[str, list[dict[str, Any]]], out: Path) -> None:
    # optional: matplotlib (volviz[bench]), only for the figures
    from volviz.bench import pyplot

    plt = pyplot()

    fig, axes = plt.subplots(1, len(results), figsize=(5.5 * len(results), 4.5))
    axes = np.atleast_1d(axes)
    style = {"vvz-rans": "o-", "vvz-arith": "s-", "zfp": "^--", "wavelet+zstd": "d:"}
    for ax, (name, rows) in zip(axes, results.items()):
        for method, st in style.items():
            pts = sorted((r["bpv"], r["psnr"]) for r in rows if r["method"] == method and math.isfinite(r["psnr"]))
            if pts:
                ax.plot(*zip(*pts), st, label=method, ms=4)
        for r in rows:
            if r["exact"] and r["setting"] != "lossless, 5/3 only":
                ax.axvline(r["bpv"], lw=0.6, color="grey", ls="--")
                ax.annotate(f"{r['method']} lossless", (r["bpv"], ax.get_ylim()[0]), rotation=90, fontsize=6,
                            va="bottom", ha="right")
        ax.set_xscale("log")
        ax.set_xlabel("bits per voxel")
        ax.set_ylabel("PSNR (dB)")
        ax.set_title(name)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def _targets(results: dict[str, list[dict[str, Any]]]) -> str:
    """The issue's targets on embryo, measured in this run."""
    rows = results.get("embryo")
    if not rows:
        return ""

    def get(method: str, setting: str, key: str) -> Any:
        return next((r[key] for r in rows if r["method"] == method and r["setting"] == setting), None)

    ours = max((get(m, "lossless", "ratio") or 0.0) for m in ("vvz-rans", "vvz-arith"))
    blosc = get("blosc2-zstd", "clevel 9 shuffle", "ratio") or math.inf
    p1 = [x for x in (_interp_psnr(rows, m, 1.0) for m in ("vvz-rans", "vvz-arith")) if x is not None]
    p025 = [x for x in (_interp_psnr(rows, m, 0.25) for m in ("vvz-rans", "vvz-arith")) if x is not None]
    speeds = {s: get("vvz-rans", s, "decode_mb_s") for s in ("lossless", "Q90", "Q80", "Q70")}
    speeds = {k: v for k, v in speeds.items() if v is not None}
    best1, best025 = max(p1, default=math.nan), max(p025, default=math.nan)
    lines = ["", "## Targets (embryo)", "", "| target | measured | met? |", "|---|---|---|",
             f"| lossless ratio >= blosc2-zstd ({blosc:.2f}) | {ours:.2f} (best of rANS / arith) | "
             f"{'yes' if ours >= blosc else 'no'} |",
             f"| >= 57 dB at 1 bit/voxel | {best1:.2f} dB | {'yes' if best1 >= 57 else 'no'} |",
             f"| >= 44 dB at 0.25 bit/voxel | {best025:.2f} dB | {'yes' if best025 >= 44 else 'no'} |",
             "| decode >= 200 MB/s incl. inverse wavelet (rANS; median) | " + ", ".join(
                 f"{k} {v:.0f}" for k, v in speeds.items()) + f" MB/s | "
             f"{'yes' if speeds and min(speeds.values()) >= 200 else 'no (see load)'} |", ""]
    return "\n".join(lines)


def _markdown(results: dict[str, Any], peaks: dict[str, float], cmd: str, png: str, env: str) -> str:
    lines = ["# Compression benchmark (wavelet octree codec)", "", f"Command: `{cmd}`", "", env, "",
             "Decode speed = MB of decoded volume per second (median of repeated runs after a warm-up), including "
             "file reading, CRC checks, entropy decoding and the inverse wavelet; zfp/blosc2/zstd decode from memory.",
             "", f"![rate-distortion]({png})", ""]
    for name, rows in results.items():
        lines += [f"## {name} (PSNR peak {peaks[name]:g})", "",
                  "| method | setting | bits/voxel | ratio | PSNR (dB) | exact | decode MB/s |",
                  "|---|---|---|---|---|---|---|"]
        for r in rows:
            ps = "inf" if not math.isfinite(r["psnr"]) else f"{r['psnr']:.2f}"
            sp = "" if r["decode_mb_s"] is None else f"{r['decode_mb_s']:.0f}"
            lines.append(f"| {r['method']} | {r['setting']} | {r['bpv']:.3f} | {r['ratio']:.2f} | {ps} | "
                         f"{'yes' if r['exact'] else ''} | {sp} |")
        lines.append("")
    return "\n".join(lines)


ANIM_PATTERNS = ("I", "IPP", "IBB", "IBBPBBPPB")


def _series_psnr(ref: Sequence[np.ndarray], rec: Sequence[np.ndarray], idx: Sequence[int]) -> float:
    if not idx:
        return math.nan
    mse = float(np.mean([np.mean((ref[i].astype(np.float64) - rec[i]) ** 2) for i in idx]))
    return math.inf if mse == 0 else 10 * math.log10(255.0 ** 2 / mse)


def _generated_series(n: int, size: int) -> list[np.ndarray]:
    """A smooth random 8-bit field (Gaussian-filtered noise) drifting by (0.8, 0.45, 0.3) voxels per step
    (sub-voxel motion, trilinear resampling) whose contrast slowly changes."""
    # heavy: SciPy, only for this case
    from scipy import ndimage

    rng = np.random.default_rng(1)
    pad = int(math.ceil(0.8 * n)) + 8
    base = ndimage.gaussian_filter(rng.standard_normal((size + pad,) * 3), 4)
    base = (base - base.mean()) / base.std()
    grid = np.indices((size,) * 3).reshape(3, -1).astype(np.float64)
    out = []
    for t in range(n):
        s = np.array([4 + 0.8 * t, 4 + 0.45 * t, 4 + 0.3 * t])[:, None]
        f = ndimage.map_coordinates(base, grid + s, order=1).reshape((size,) * 3)
        out.append(np.clip(128 + (36 + 8 * math.sin(t / 9)) * f, 0, 255).astype(np.uint8))
    return out


def _animation(name: str, vols: list[np.ndarray], settings: Sequence[float | None], tmp: Path
               ) -> list[dict[str, Any]]:
    """Ratio and PSNR per sequence type (Guthe Table 2.11), playback rate through the one-decode schedule."""
    # the kernels (Numba) of this case only: a bench loads what its cases run
    from volviz.regular import animation as A

    rows = []
    for pattern in ANIM_PATTERNS:
        for q in settings:
            path = tmp / f"{name}_{pattern}_{q}.vvs"
            t0 = time.perf_counter()
            inf = A.compress_series(vols, path, pattern=pattern, mode="lossless" if q is None else "quality",
                                    quality=q)
            enc = time.perf_counter() - t0
            player = A.SeriesPlayer(path)
            t0 = time.perf_counter()
            rec = [player.frame(t).copy() for t in range(len(vols))]
            play = time.perf_counter() - t0
            kinds = A.frame_types(len(vols), pattern)
            by = {k: [f.display for f in kinds if f.kind == k] for k in "IPB"}
            rows.append({"series": name, "pattern": pattern, "setting": "lossless" if q is None else f"Q{q:g}",
                         "ratio": inf["ratio"], "bpv": inf["bits_per_voxel"],
                         "psnr": _series_psnr(vols, rec, range(len(vols))),
                         **{f"psnr_{k}": _series_psnr(vols, rec, by[k]) for k in "IPB"},
                         "exact": all(np.array_equal(a, b) for a, b in zip(vols, rec)),
                         "encode_s": enc, "play_fps": len(vols) / play,
                         "decodes_per_frame": max(player.decodes_per_frame)})
            print(f"{name} {pattern} {rows[-1]['setting']}: {inf['ratio']:.2f}:1 {rows[-1]['psnr']:.2f} dB",
                  file=sys.stderr)
    return rows


def _lod_walkthrough(vol: np.ndarray, tmp: Path, budgets: Sequence[int], frames: int,
                     render_frames: int = 0) -> list[dict[str, Any]]:
    """Per-frame LOD work along an orbit at 512^2: selection (Eq. 2.7 TF priority) + block decoding through the
    LRU cache; with ``render_frames`` also whole rendered frames (``volviz.bench.lod_frames``)."""
    # the kernels (Numba) of this case only: a bench loads what its cases run
    from volviz.model.datasets import RegularVolume
    from volviz.optics import TransferFunction
    from volviz.regular.codec import compress
    from volviz.regular.lod import LodCamera, LodTree

    path = tmp / "lod.vvz"
    compress(RegularVolume(np.asfortranarray(vol)), path, quality=80)
    t0 = time.perf_counter()
    tree = LodTree(path, cache_bytes=64 << 20, volume=RegularVolume(vol))
    stats_s = time.perf_counter() - t0
    tf = TransferFunction([40.0, 120.0, 255.0], [[1, 0.6, 0.3], [1, 1, 1], [1, 1, 1]], [0.0, 0.05, 0.2])
    c = np.array(vol.shape, float) / 2
    rows = []
    for budget in budgets:
        tree.cache = type(tree.cache)(64 << 20, tree.levels)
        times, decoded, nblocks, skipped = [], [], [], []
        for f in range(frames + 1):
            ang = 2 * math.pi * f / 24
            eye = c + 1.6 * float(vol.shape[0]) * np.array([math.cos(ang), math.sin(ang), 0.3])
            cam = LodCamera(eye=tuple(eye), target=tuple(c), fov_y=30, width=512, height=512)
            before = tree.decoder.decoded_bricks
            t0 = time.perf_counter()
            sel = tree.select(cam, budget, tf=tf, mode="tf")
            for _ in tree.blocks(sel):
                pass
            if f:  # frame 0 is the cold start
                times.append(time.perf_counter() - t0)
                decoded.append(tree.decoder.decoded_bricks - before)
                nblocks.append(len(sel.nodes))
                skipped.append(sel.skipped_transparent)
        rows.append({"budget": budget, "blocks": float(np.mean(nblocks)),
                     "ms_per_frame": 1e3 * statistics.median(times),
                     "bricks_decoded_per_frame": float(np.mean(decoded)),
                     "transparent_skipped": float(np.mean(skipped)),
                     "cache_hit_rate": tree.cache.hits / max(1, tree.cache.hits + tree.cache.misses),
                     "stats_s": stats_s})
    if render_frames > 0:        # the same budgets drawn offscreen (volviz.render.lod_volume) at 512^2
        # another bench's module (it loads VTK or its own dependencies): only for this case
        from volviz.bench.lod_frames import render_walkthrough

        for row, r in zip(rows, render_walkthrough(tree, vol, tf, budgets, frames=render_frames, size=512)):
            row.update({f"render_{k}": v for k, v in r.items() if k != "budget"})
    return rows


def _anim_markdown(anim: list[dict[str, Any]], lod: list[dict[str, Any]], cmd: str, env: str) -> str:
    def f(x: float) -> str:
        return "inf" if x == math.inf else ("-" if x != x else f"{x:.2f}")

    lines = ["# Compression benchmark: animated volumes and LOD walkthrough", "", f"Command: `{cmd}`", "", env, "",
             "Animation (Guthe §2.2.3, Table 2.11): windowed motion compensation (8^3 blocks, 12^3 cosine windows, "
             "+-15 local search), closed-loop I/P/B coding in MPEG storage order; lossy B volumes are MC only, "
             "lossless ones carry a residual. PSNR (peak 255) over all frames and per frame type; playback = "
             "frames/s of `SeriesPlayer.frame` (exactly one volume decode per displayed frame, incl. file reads).",
             "", "| series | sequence | setting | ratio | bits/voxel | PSNR | PSNR I | PSNR P | PSNR B | exact | "
             "encode s | playback fps | decodes/frame |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in anim:
        lines.append(f"| {r['series']} | {r['pattern']} | {r['setting']} | {r['ratio']:.2f} | {r['bpv']:.3f} | "
                     f"{f(r['psnr'])} | {f(r['psnr_I'])} | {f(r['psnr_P'])} | {f(r['psnr_B'])} | "
                     f"{'yes' if r['exact'] else ''} | {r['encode_s']:.1f} | {r['play_fps']:.1f} | "
                     f"{r['decodes_per_frame']} |")
    if lod:
        lines += ["", "## LOD walkthrough (embryo 256^3, Q80, 512^2 camera orbit, TF-dependent priority Eq. 2.7)", "",
                  "CPU work per frame only: greedy selection + block assembly (one-voxel overlap) through the LRU "
                  "node cache (64 MiB); median over the orbit after a cold first frame. Whole rendered frames follow "
                  "below.", "",
                  "| block budget | blocks drawn | ms/frame | bricks decoded/frame | transparent skipped | "
                  "cache hit rate |", "|---|---|---|---|---|---|"]
        for r in lod:
            lines.append(f"| {r['budget']} | {r['blocks']:.0f} | {r['ms_per_frame']:.1f} | "
                         f"{r['bricks_decoded_per_frame']:.1f} | {r['transparent_skipped']:.0f} | "
                         f"{r['cache_hit_rate']:.2f} |")
        lines += ["", f"Node statistics (exact L2 errors, deviation histograms) took {lod[0]['stats_s']:.1f} s."]
        if "render_render_s_per_frame" in lod[0]:
            # optional: matplotlib (volviz[bench]), only for the figures
            from volviz.bench import lod_frames

            lines += [""] + lod_frames.markdown(lod)
    return "\n".join(lines) + "\n"


def _load_avg() -> str:
    try:
        return "load average " + " ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "load average unknown"


def main_animation(args: argparse.Namespace, argv: Sequence[str] | None) -> int:
    # the readers (registry and plugins): loaded when a case first reads a file
    from volviz.io import read

    env0 = _load_avg()
    with tempfile.TemporaryDirectory(prefix="vvsbench") as td:
        storm = read(str(DATA / "storm" / "Storm.pvm-t%02d"))
        vols = [np.asarray(storm.frame(i).data) for i in range(len(storm))]
        anim = _animation("storm 28x28x23 x21", vols, (None, 80.0, 60.0), Path(td))
        if args.anim_steps > 0:
            gen = _generated_series(args.anim_steps, args.anim_size)
            anim += _animation(f"generated {args.anim_size}^3 x{args.anim_steps}", gen, (70.0,), Path(td))
            del gen
        lod = []
        if args.lod_budgets:
            emb = np.asarray(read(DATA / "volumes" / "embryo.slc").data)
            lod = _lod_walkthrough(emb, Path(td), args.lod_budgets, args.lod_frames, args.lod_render_frames)
    cmd = "volviz bench compression " + " ".join(argv if argv is not None else sys.argv[1:])
    env = (f"Machine: {platform.machine()}, {os.cpu_count()} cores shared with other engineers' jobs; "
           f"{env0} at the start, {_load_avg()} at the end. Python {platform.python_version()}.")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "compression-animation.md").write_text(_anim_markdown(anim, lod, cmd.strip(), env))
    if args.json:
        Path(args.json).write_text(json.dumps({"animation": anim, "lod": lod}, indent=1, default=str))
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    p = UsageParser(prog="volviz bench compression", description=__doc__.splitlines()[0])
    p.add_argument("--volumes", nargs="+", choices=("embryo", "headsq", "neghip", "field512"),
                   default=["embryo", "headsq", "neghip", "field512"])
    p.add_argument("--reps", type=int_in(1, 1000), default=3)
    p.add_argument("--json", help="write all rows as JSON")
    p.add_argument("--out", default=str(Path(__file__).resolve().parents[2] / "docs" / "bench"),
                   help="directory of compression.md and compression.png")
    p.add_argument("--animation", action="store_true",
                   help="run the animation + LOD section instead (writes compression-animation.md)")
    p.add_argument("--anim-steps", type=int_in(0, 10_000), default=64, help="generated series length (0: Storm only)")
    p.add_argument("--anim-size", type=int_in(2, 1024), default=128, help="generated series edge length")
    p.add_argument("--lod-budgets", type=int_in(1, 1_000_000), nargs="*", default=[128, 256, 512])
    p.add_argument("--lod-frames", type=int_in(1, 10_000), default=12)
    p.add_argument("--lod-render-frames", type=int_in(0, 10_000), default=3,
                   help="rendered walkthrough frames per budget (0: CPU side only)")
    args = p.parse_args(list(argv) if argv is not None else None)
    if args.animation:
        return main_animation(args, argv)
    results: dict[str, list[dict[str, Any]]] = {}
    peaks: dict[str, float] = {}
    env0 = _load_avg()
    with tempfile.TemporaryDirectory(prefix="vvzbench") as td:
        for name in args.volumes:
            vol, peak = _load(name)
            peaks[name] = peak
            rows = _ours(vol, peak, Path(td), args.reps, {"lossless", "Q90", "Q80", "Q70"})
            rows += _blosc(vol, peak, args.reps) + _zfp(vol, peak, args.reps)
            if vol.size <= BIG:
                rows += _wavelet_zstd(vol, peak, args.reps)
            del vol
            results[name] = rows
            print(f"{name}: done", file=sys.stderr)
    summary = {}
    for name, rows in results.items():
        s = {f"psnr_at_{b}bpv_{m}": _interp_psnr(rows, m, b) for b in (1.0, 0.25)
             for m in ("vvz-rans", "vvz-arith", "zfp", "wavelet+zstd")}
        s.update({f"lossless_ratio_{r['method']}" + ("_5/3_only" if r["setting"] == "lossless, 5/3 only" else ""):
                  r["ratio"] for r in rows if r["exact"]})
        summary[name] = s
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    cmd = "volviz bench compression " + " ".join(argv if argv is not None else sys.argv[1:])
    env = (f"Machine: {platform.machine()}, {os.cpu_count()} cores shared with other engineers' jobs; {env0} at the "
           f"start, {_load_avg()} at the end. Python {platform.python_version()}.")
    md = _markdown(results, peaks, cmd.strip(), "compression.png", env)
    md += _targets(results)
    md += "\n## Summary (PSNR interpolated in log bits/voxel between measured points)\n\n```\n" + json.dumps(
        summary, indent=1) + "\n```\n"
    (out / "compression.md").write_text(md)
    _plot(results, out / "compression.png")
    if args.json:
        Path(args.json).write_text(json.dumps({"results": results, "summary": summary}, indent=1, default=str))
    print(json.dumps(summary, indent=1))
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
