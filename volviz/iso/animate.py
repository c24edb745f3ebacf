"""4D isosurfaces of a time series (libMini note, "4D Visualization"): display time is continuous, the volume is the
linear blend of its two neighbouring steps (``volviz.model.timeseries.frame_at``), and extraction runs on a
background worker (``volviz.jobs.JobRunner``) so playback never waits for it: each display frame asks for the
surfaces at its time; the newest request supersedes a stale one (key ``"iso-anim"``), and the frame shows the newest
finished surfaces meanwhile.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import Any, Callable, Optional, Sequence

import numpy as np

from volviz.iso.extract import IsoMesh, IsoStyle, extract
from volviz.jobs import JobOutcome, JobRunner
from volviz.model.datasets import TimeSeries
from volviz.model.timeseries import frame_at

__all__ = ["IsoFrame", "extract_at", "IsoAnimator", "playback_times"]


@dataclass
class IsoFrame:
    """Surfaces extracted for display time ``time`` (``interpolated``: from the 4D blend, not the nearest step)."""

    time: float
    meshes: list[IsoMesh]
    interpolated: bool


def extract_at(series: TimeSeries, t: float, styles: Sequence[IsoStyle | float], interpolate: bool = True,
               scalars: Optional[str] = None, transform: Optional[Callable[[list[IsoMesh]], list[IsoMesh]]] = None,
               progress: Optional[Callable[[float, str], None]] = None) -> IsoFrame:
    """Surfaces of the series at display time ``t`` (the blend of its neighbouring steps, or the earlier step).

    ``transform`` post-processes the meshes on the worker (clipping, LOD) so the display thread gets them ready.
    """
    vol = frame_at(series, float(t), interpolate=interpolate)
    if progress is not None:
        progress(0.2, f"t = {t:.3f} interpolated")
    meshes = extract(vol, styles, scalars=scalars)
    if transform is not None:
        meshes = transform(meshes)
    return IsoFrame(float(t), meshes, bool(interpolate))


def playback_times(series: TimeSeries, frames_per_step: int) -> np.ndarray:
    """Display times from the first to the last step, ``frames_per_step`` frames between two steps."""
    times = np.asarray(series.times, dtype=np.float64)
    if frames_per_step < 1:
        raise ValueError("frames_per_step must be >= 1")
    return np.interp(np.arange((len(times) - 1) * frames_per_step + 1) / frames_per_step,
                     np.arange(len(times)), times)


class IsoAnimator:
    """Non-blocking 4D isosurfaces: ``frame(t)`` requests time ``t`` in the background, returns the newest result.

    ``extractor`` defaults to :func:`extract_at`; it is called as ``extractor(series, t, styles, interpolate=...,
    scalars=..., transform=..., progress=...)`` on a worker thread.
    """

    def __init__(self, series: TimeSeries, styles: Sequence[IsoStyle | float], runner: Optional[JobRunner] = None,
                 interpolate: bool = True, scalars: Optional[str] = None,
                 transform: Optional[Callable[[list[IsoMesh]], list[IsoMesh]]] = None,
                 extractor: Callable[..., IsoFrame] = extract_at, key: str = "iso-anim"):
        if len(series) < 1:
            raise ValueError("the time series is empty")
        self.series, self.styles = series, list(styles)
        self.interpolate, self.scalars, self.transform = interpolate, scalars, transform
        self._own_runner = runner is None
        self.runner = runner or JobRunner(max_workers=1)
        self._extractor, self._key = extractor, key
        self._lock = threading.Lock()
        self._latest: Optional[IsoFrame] = None
        self._ready = threading.Condition(self._lock)
        self.requested: Optional[float] = None
        self.delivered = 0

    def _done(self, outcome: JobOutcome) -> None:
        if outcome.ok and outcome.result is not None:
            with self._ready:
                self._latest = outcome.result
                self.delivered += 1
                self._ready.notify_all()

    def request(self, t: float) -> Any:
        """Ask for the surfaces at display time ``t`` (supersedes an older pending request); returns the Job."""
        with self._lock:
            self.requested = float(t)
        return self.runner.submit(self._extractor, self.series, float(t), self.styles, interpolate=self.interpolate,
                                  scalars=self.scalars, transform=self.transform, name="iso-extract",
                                  key=self._key, on_done=self._done)

    def latest(self) -> Optional[IsoFrame]:
        with self._lock:
            return self._latest

    def frame(self, t: float) -> Optional[IsoFrame]:
        """Request ``t`` and return at once with the newest finished surfaces (None before the first one)."""
        self.request(t)
        return self.latest()

    def wait_for(self, t: float, timeout: float = 30.0) -> IsoFrame:
        """Block until the surfaces of time ``t`` are delivered (for export and tests, not for playback)."""
        with self._ready:
            ok = self._ready.wait_for(lambda: self._latest is not None and self._latest.time == float(t), timeout)
            if not ok:
                raise TimeoutError(f"isosurfaces for t = {t} were not delivered within {timeout} s")
            return self._latest  # type: ignore[return-value]

    def close(self) -> None:
        if self._own_runner:
            self.runner.shutdown(wait=True)
