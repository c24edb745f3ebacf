"""Shared fixtures: where the real datasets are, and the rule for when they are missing.

Data comes from ``$VOLVIZ_DATA`` or ``../shared/data`` beside the repository. A test that needs it calls
``data_file("bluntfin/bluntfinxyz.bin")``: when the data is missing it skips with a clear reason, unless
``VOLVIZ_REQUIRE_DATA=1``, where a missing file is a failure.
"""
from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent


def data_root() -> Path:
    env = os.environ.get("VOLVIZ_DATA")
    return Path(env).resolve() if env else (REPO.parent / "shared" / "data").resolve()


# the app and the CLI find the shipped sessions' data where the tests do (CI sets it; a plain local run did not, and
# the Yukon flows then waited on the missing-data dialog)
os.environ.setdefault("VOLVIZ_DATA", str(data_root()))


def data_file(relative: str) -> Path:
    """Path of a shared dataset; skip (or fail under VOLVIZ_REQUIRE_DATA=1) when it is missing."""
    path = data_root() / relative
    if not path.exists():
        message = f"dataset {relative} not found under {data_root()} (set VOLVIZ_DATA)"
        if os.environ.get("VOLVIZ_REQUIRE_DATA") == "1":
            pytest.fail(message)
        pytest.skip(message)
    return path


@pytest.fixture
def data() -> "type[data_file]":
    """The ``data_file`` function as a fixture: ``data("headsq/quarter.1")``."""
    return data_file


def blob_vvz(path: Path, n: int) -> Path:
    """A lossless ``.vvz`` of an n^3 8-bit test field (a Gaussian blob on a wavy background, values 5-245) at
    ``path``: the volume of the LOD, ray-casting and app LOD tests."""
    import numpy as np

    from volviz.model.datasets import RegularVolume
    from volviz.regular.codec import compress

    x, y, z = np.meshgrid(*(np.linspace(-1, 1, n),) * 3, indexing="ij")
    field = 200 * np.exp(-3 * ((x - 0.2) ** 2 + y ** 2 + (z + 0.1) ** 2)) + 40 * np.sin(4 * x) * np.cos(3 * y) + 45
    compress(RegularVolume(np.asfortranarray(np.clip(field, 0, 255).astype(np.uint8))), path, mode="lossless")
    return path


@pytest.fixture
def make_window(qtbot, tmp_path: Path):
    """``make_window()`` opens another app window (settings and recovery folder in tmp_path); all are closed at
    teardown."""
    import gc

    from PySide6.QtCore import QSettings

    from volviz_app.window import MainWindow

    created = []

    def make() -> MainWindow:
        settings = QSettings(str(tmp_path / "settings.ini"), QSettings.Format.IniFormat)
        win = MainWindow(settings=settings, recovery_dir=tmp_path / "recovery")  # closed below, not by qtbot:
        win.resize(1400, 900)
        win.show()
        qtbot.waitExposed(win)
        created.append(win)
        return win

    yield make
    for win in created:
        win.dirty = False  # no "save changes?" prompt at teardown
        win.close()
    gc.collect()  # free the closed windows here, on the GUI thread


def read_mutations(path: Path, mutations, truncated_reads_same: bool) -> int:
    """Write each mutation (``volviz.bench.robustness.Mutation``) of a file to ``path`` and read it with
    ``volviz.io.read``; assert the fuzz property: a ReadError naming the file, or a dataset of the original's size
    with finite spacing and origin. A truncated file is refused, or (``truncated_reads_same``) read with exactly the
    original's data. Returns how many were refused."""
    import warnings

    import volviz.io as vio
    from volviz.bench import robustness as rb

    original = rb.fingerprint_volviz(vio.read(path))
    refused = 0
    for mutation in mutations:
        path.write_bytes(mutation.data)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                found = rb.fingerprint_volviz(vio.read(path))
        except vio.ReadError as exc:
            assert str(path) in str(exc), f"{mutation.detail}: {exc}"
            refused += 1
            continue
        assert found["problem"] == "", f"{mutation.detail}: {found['problem']}"
        assert found["n_points"] == original["n_points"], f"{mutation.detail}: another size was accepted"
        if mutation.kind == "truncate":
            assert truncated_reads_same, f"{mutation.detail}: read although truncated"
            assert found["crc"] == original["crc"], f"{mutation.detail}: a truncated file read with other data"
    return refused


def xml_mutations(data: bytes, seed: str, flips: int, cuts: int, per_kind: int) -> list:
    """Bit flips, truncations and XML attribute mutations (``volviz.bench.robustness``) of a text file's bytes."""
    import random

    from volviz.bench import robustness as rb

    rng = random.Random(seed)
    mutations = [rb.flip_bits(data, rng, len(data)) for _ in range(flips)]
    mutations += [rb.truncate(data, at) for at in sorted(rng.sample(range(1, len(data)), cuts))]
    return mutations + [m for kind in ("xml-swap", "xml-flip", "xml-enlarge") for _ in range(per_kind)
                        if (m := rb.xml_mutation(data, rng, kind)) is not None]


def read_every_frame(path: Path, mutations, names: tuple[str, ...]) -> tuple[int, list]:
    """Write each mutation to ``path`` and read it with every frame of a time series; a ReadError must name one of
    ``names``. Returns how many were refused and ``(mutation, dataset, frames)`` of those read."""
    import volviz.io as vio
    from volviz.model import TimeSeries

    refused, read = 0, []
    for mutation in mutations:
        path.write_bytes(mutation.data)
        try:
            found = vio.read(path)
            frames = [found.frame(i) for i in range(len(found))] if isinstance(found, TimeSeries) else [found]
        except vio.ReadError as exc:
            assert any(name in str(exc) for name in names), f"{mutation.detail}: {exc}"
            refused += 1
            continue
        read.append((mutation, found, frames))
    return refused, read


def pytest_xdist_auto_num_workers(config) -> int:
    """``-n auto`` (pyproject's addopts): one worker per core, at most four. Much of the suite waits on Xvfb, reader
    processes and real-time flows, so two workers on CI's two cores nearly halve its time; more than four only
    multiply the memory of VTK, Qt and Numba per worker."""
    return max(1, min(4, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1))


def _measures_latency(function: object) -> bool:
    """Whether a test measures the app's event-loop latency (it makes a ``loop_latency.LoopGaps``)."""
    import inspect

    try:
        return "LoopGaps(" in inspect.getsource(function)
    except (OSError, TypeError):
        return False


@pytest.fixture(autouse=True)
def _latency_tests_run_alone(request: pytest.FixtureRequest):
    """Under pytest-xdist, a test that measures the app's event-loop latency runs while no other test of the run
    does: it holds a lock file exclusively, every other test holds it shared. Its bound (100 ms of blocking that is
    the app's, ``loop_latency``) is about the app on this machine, not beside a second app of the suite: with two
    busy processes on the 2 cores, the isosurface playback's worst blocked gap reached 94-103 ms on HEAD and 50-96 ms
    on 352aca7 (a quiet frame: 13 ms of render and 3 ms of showing the surfaces), and it failed CI in 4 of 5 runs
    beside the other worker."""
    run = os.environ.get("PYTEST_XDIST_TESTRUNUID")
    if run is None:     # one process: nothing runs beside it
        yield
        return
    import fcntl
    import tempfile

    with open(Path(tempfile.gettempdir()) / f"volviz-tests-{run}.lock", "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX if _measures_latency(request.function) else fcntl.LOCK_SH)
        yield
