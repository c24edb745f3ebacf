"""Compression backends found through the ``volviz.compression_backends`` entry points (a real dist-info folder on
sys.path), and the message when the one asked for is not installed."""
from __future__ import annotations

import numpy as np
import pytest

from dist_info import install_dist
from volviz.regular import animation as A
from volviz.regular.backends import BackendMissing, backend_names, compression_backend
from volviz.regular.cli import compress_main

BACKEND_MODULE = '''
CALLS = []


def run(address, func, tasks):
    """Run every task here, last first (results may come back in any order)."""
    CALLS.append(address)
    for task in reversed(list(tasks)):
        yield func(*task)
'''


@pytest.fixture
def reversed_backend(tmp_path, monkeypatch):
    site = install_dist(tmp_path / "site", "reversed-backend",
                        {"volviz.compression_backends": {"reversed": "reversed_backend:run"}},
                        {"reversed_backend": BACKEND_MODULE})
    monkeypatch.syspath_prepend(str(site))
    yield site


def _series(n=12, shape=(10, 8, 9)):
    rng = np.random.default_rng(3)
    base = rng.integers(0, 200, shape, dtype=np.uint8)
    return [np.roll(base, t, axis=0) for t in range(n)]


def test_backend_from_an_entry_point_gives_the_sequential_bytes(reversed_backend, tmp_path):
    import reversed_backend as module

    assert "reversed" in backend_names() and "dask" in backend_names()
    vols = _series()
    A.compress_series(vols, tmp_path / "seq.vvs", pattern="IPB")
    A.compress_series(vols, tmp_path / "rev.vvs", pattern="IPB", scheduler="here", backend="reversed")
    assert module.CALLS == ["here"]
    seq = {p.name: p.read_bytes() for p in sorted((tmp_path / "seq.vvs").iterdir())}
    rev = {p.name: p.read_bytes() for p in sorted((tmp_path / "rev.vvs").iterdir())}
    assert len(seq) > 12 and seq == rev


def test_missing_backend_names_the_package_to_install(monkeypatch, tmp_path):
    with pytest.raises(BackendMissing, match=r"the 'ray' compression backend is not installed \(installed: dask\); "
                                             r"install a package registering 'ray' in the entry-point group "
                                             r"volviz.compression_backends"):
        compression_backend("ray")
    # as if the volviz-dask plugin were not installed: the lookup reads a group no package registers in
    from volviz.regular import backends

    monkeypatch.setattr(backends, "ENTRY_POINT_GROUP", "volviz.no_backends_here")
    with pytest.raises(BackendMissing, match=r"'dask' compression backend is not installed \(installed: none\); "
                                             r"install volviz-dask \(pip install -e plugins/volviz-dask"):
        compression_backend("dask")
    with pytest.raises(SystemExit, match=r"--scheduler: the 'dask' compression backend is not installed .*volviz-dask"):
        compress_main([str(tmp_path / "s%02d.pvm"), "--series", "-o", str(tmp_path / "o.vvs"), "--scheduler",
                       "tcp://127.0.0.1:1"])
