"""Temporaries of interrupted writes and concurrent writers (issue #32): a killed write's temporary is removed by the
next write; one of the same target unchanged for STALE_AGE_S goes even when a process of its id runs (ids are
reused); two processes writing one target leave one complete file of one of them, never a mix, and no temporary."""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np

from volviz.io.atomic import STALE_AGE_S, atomic_write_bytes, temp_name
from volviz.model.datasets import RegularVolume
from volviz.regular.codec import compress, decompress


def _temporaries(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if ".volviz-tmp-" in p.name)


def _live_temp(target: Path, age_s: float) -> Path:
    """A temporary of ``target`` named for a running process (the parent of this one), last changed ``age_s`` ago."""
    tmp = temp_name(target).with_name(f".{target.name}.volviz-tmp-{os.getppid()}-{os.urandom(4).hex()}")
    tmp.write_bytes(b"half")
    then = time.time() - age_s
    os.utime(tmp, (then, then))
    return tmp


def test_a_killed_write_leaves_nothing_after_the_next_write(tmp_path):
    target = tmp_path / "s.json"
    code = textwrap.dedent(f"""
        import os
        from volviz.io.atomic import temp_name
        tmp = temp_name({str(target)!r})
        with open(tmp, "wb") as f:
            f.write(b"x" * 100000)
        os._exit(9)  # killed between write and rename
    """)
    assert subprocess.run([sys.executable, "-c", code]).returncode == 9
    assert len(_temporaries(tmp_path)) == 1
    atomic_write_bytes(target, b"complete")
    assert target.read_bytes() == b"complete" and _temporaries(tmp_path) == []


def test_abandoned_temporaries_of_the_target_go_whatever_their_process_id(tmp_path):
    target, other = tmp_path / "a.vvz", tmp_path / "b.vvz"
    old = _live_temp(target, STALE_AGE_S + 60)
    fresh = _live_temp(target, 5)                   # perhaps a write in progress: kept
    old_other = _live_temp(other, STALE_AGE_S + 60)  # another target's: left to that target's writes
    compress(RegularVolume(np.arange(1000, dtype=np.uint8).reshape(10, 10, 10)), target)  # the container Writer
    assert _temporaries(tmp_path) == sorted([fresh.name, old_other.name])
    assert not old.exists()
    assert np.array_equal(decompress(target).data, np.arange(1000, dtype=np.uint8).reshape(10, 10, 10))
    atomic_write_bytes(other, b"b")
    assert _temporaries(tmp_path) == [fresh.name]


def test_two_processes_writing_one_target_never_mix(tmp_path):
    target = tmp_path / "shared.bin"
    size, rounds = 1 << 18, 60
    code = textwrap.dedent(f"""
        import sys
        from volviz.io.atomic import atomic_write_bytes
        value = int(sys.argv[1])
        for _ in range({rounds}):
            atomic_write_bytes({str(target)!r}, bytes([value]) * {size})
    """)
    writers = [subprocess.Popen([sys.executable, "-c", code, str(v)]) for v in (1, 2)]
    seen = set()
    while any(w.poll() is None for w in writers):
        try:
            data = target.read_bytes()
        except FileNotFoundError:  # not written yet
            continue
        values = set(np.unique(np.frombuffer(data, np.uint8)).tolist())
        assert len(data) == size and len(values) == 1 and values <= {1, 2}
        seen |= values
    assert [w.returncode for w in writers] == [0, 0]
    final = np.unique(np.frombuffer(target.read_bytes(), np.uint8)).tolist()
    assert len(target.read_bytes()) == size and final in ([1], [2])
    assert seen and _temporaries(tmp_path) == []
