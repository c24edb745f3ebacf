"""Safe writes: only regular files are replaced; interrupted saves (really killed child processes) leave one
complete file or store, and the next save removes their temporaries."""
from __future__ import annotations

import json
import os
import random
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from volviz import session as S
from volviz.io.atomic import (OutputPathError, atomic_write_bytes, check_output_path, new_temp_dir, recover_directory,
                              replace_directory, temp_name)
from volviz.regular.animation import compress_series, decompress_series

REPO = Path(__file__).resolve().parent.parent


def dead_pid() -> int:
    """The id of a process that has ended."""
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def device_node(tmp_path: Path) -> Path:
    """A character device to write at: a null device made in tmp_path as root (so a failure of the check cannot
    damage the machine's /dev/null), else /dev/null itself (which a non-root process cannot replace anyway)."""
    node = tmp_path / "null"
    try:
        os.mknod(node, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    except PermissionError:
        return Path("/dev/null")
    return node


def test_a_device_node_is_not_replaced(tmp_path: Path) -> None:
    node = device_node(tmp_path)
    with pytest.raises(OutputPathError, match="character device; volviz replaces only regular files"):
        atomic_write_bytes(node, b"data")
    assert stat.S_ISCHR(os.lstat(node).st_mode)
    with pytest.raises(S.SessionError, match="character device"):
        S.save(S.Session(), node)
    assert stat.S_ISCHR(os.lstat(node).st_mode)


def test_fifo_folder_and_symlink_targets_are_refused(tmp_path: Path) -> None:
    fifo = tmp_path / "out.png"
    os.mkfifo(fifo)
    real = tmp_path / "real.json"
    real.write_text("keep")
    link = tmp_path / "link.json"
    link.symlink_to(real)
    (tmp_path / "folder.json").mkdir()
    for target, words in ((fifo, "FIFO"), (link, "symbolic link"), (tmp_path / "folder.json", "folder")):
        with pytest.raises(OutputPathError, match=words) as info:
            check_output_path(target)
        assert str(target) in str(info.value)
        with pytest.raises(OutputPathError):
            atomic_write_bytes(target, b"x")
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode) and link.is_symlink() and real.read_text() == "keep"
    with pytest.raises(OutputPathError, match="does not exist"):
        check_output_path(tmp_path / "no" / "such" / "file.png")


def test_regular_files_are_replaced_with_the_umask_permissions(tmp_path: Path) -> None:
    target = tmp_path / "a.bin"
    atomic_write_bytes(target, b"one")
    atomic_write_bytes(target, b"two")
    assert target.read_bytes() == b"two"
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~umask
    assert [p.name for p in tmp_path.iterdir()] == ["a.bin"]


def test_the_next_save_removes_stale_temporaries_only(tmp_path: Path) -> None:
    gone = dead_pid()
    stale = [tmp_path / f".a.json.volviz-tmp-{gone}-0badc0de", tmp_path / f".other.png.volviz-tmp-{gone}-1"]
    live = [tmp_path / f".a.json.volviz-tmp-{os.getpid()}-2", tmp_path / ".a.json.volviz-tmp-1-3"]  # us; init
    for path in stale + live:
        path.write_bytes(b"partial")
    (tmp_path / f".s.vvs.volviz-tmp-{gone}-4").mkdir()  # a store folder being written when its process died
    (tmp_path / f".s.vvs.volviz-tmp-{gone}-4" / "v0000.vvz").write_bytes(b"partial")
    S.save(S.Session(), tmp_path / "a.json")
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == sorted(["a.json"] + [p.name for p in live])


# -- kills at random moments ------------------------------------------------------------------------------------------
FILE_WRITER = r"""
import sys
import numpy as np
from volviz.io.atomic import atomic_write_bytes
target, size = sys.argv[1], int(sys.argv[2])
print("ready", flush=True)
generation = 0
while True:
    generation = (generation + 1) % 250
    atomic_write_bytes(target, np.full(size, generation, np.uint8).tobytes())
"""

STORE_WRITER = r"""
import json, sys
from pathlib import Path
from volviz.io.atomic import new_temp_dir, replace_directory
target, files, size = Path(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
print("ready", flush=True)
generation = 0
while True:
    generation += 1
    tmp = new_temp_dir(target)
    for i in range(files):
        (tmp / f"v{i:04d}.vvz").write_bytes(bytes([generation % 256]) * size)
    (tmp / "series.json").write_text(json.dumps({"generation": generation, "files": files}))
    replace_directory(tmp, target)
"""


def kill_at_random(script: str, args: list[str], kills: int, seconds: float, seed: int) -> int:
    """Start ``script`` again and again and SIGKILL it at a random moment of its write loop; returns the kills."""
    rng = random.Random(seed)
    done = 0
    deadline = time.monotonic() + seconds
    env = dict(os.environ, PYTHONPATH=str(REPO))
    while done < kills and time.monotonic() < deadline:
        child = subprocess.Popen([sys.executable, "-c", script, *args], stdout=subprocess.PIPE, env=env)
        assert child.stdout is not None and child.stdout.readline().strip() == b"ready"
        time.sleep(rng.uniform(0.0, 0.25))
        child.send_signal(signal.SIGKILL)
        child.wait()
        done += 1
    return done


def test_killed_file_saves_leave_one_complete_file(tmp_path: Path) -> None:
    target = tmp_path / "big.bin"
    size = 8 << 20
    atomic_write_bytes(target, np.zeros(size, np.uint8).tobytes())
    leftovers = 0
    for round_ in range(20):
        assert kill_at_random(FILE_WRITER, [str(target), str(size)], 1, 30, seed=round_) == 1
        data = np.fromfile(target, np.uint8)
        assert data.size == size and (data == data[0]).all()  # one whole generation, never a mix or a truncation
        leftovers += sum(1 for p in tmp_path.iterdir() if ".volviz-tmp-" in p.name)
    atomic_write_bytes(target, b"final")  # the next save cleans up after every killed one
    assert [p.name for p in tmp_path.iterdir()] == ["big.bin"] and target.read_bytes() == b"final"
    print(f"temporaries seen after kills: {leftovers}")


def test_killed_store_replacements_leave_one_complete_store(tmp_path: Path) -> None:
    target = tmp_path / "s.vvs"
    files, size = 8, 256 << 10
    for round_ in range(20):
        assert kill_at_random(STORE_WRITER, [str(target), str(files), str(size)], 1, 30, seed=100 + round_) == 1
        recover_directory(target)  # what opening the store does first
        if not target.exists():
            assert round_ == 0 and not any(p.name.startswith(".s.vvs.volviz-old-") for p in tmp_path.iterdir())
            continue  # killed before the very first store was complete: there was never a store to lose
        meta = json.loads((target / "series.json").read_text())
        blobs = [(target / f"v{i:04d}.vvz").read_bytes() for i in range(files)]
        assert meta["files"] == files
        assert all(blob == bytes([meta["generation"] % 256]) * size for blob in blobs)
    new_temp_dir(target).rmdir()  # the next write cleans up what the killed ones left
    assert [p.name for p in tmp_path.iterdir()] == ["s.vvs"]


def test_a_store_moved_aside_by_a_killed_write_is_put_back_on_open(tmp_path: Path) -> None:
    frames = [np.full((8, 8, 8), v, np.uint8) for v in (10, 20, 30)]
    target = tmp_path / "s.vvs"
    compress_series(frames, target, pattern="IPP")
    # the state a kill between "old store aside" and "new store in" leaves, with a dead process's names
    gone = dead_pid()
    aside = tmp_path / f".s.vvs.volviz-old-{gone}-1"
    partial = tmp_path / f".s.vvs.volviz-tmp-{gone}-2"
    os.rename(target, aside)
    partial.mkdir()
    assert [f.tolist() for f in decompress_series(target)] == [f.tolist() for f in frames]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.vvs"]


def test_replacing_a_store_keeps_the_old_one_until_the_new_one_is_in(tmp_path: Path) -> None:
    target = tmp_path / "s.vvs"
    frames = [np.full((8, 8, 8), v, np.uint8) for v in (1, 2)]
    compress_series(frames, target, pattern="I")
    tmp = new_temp_dir(target)
    (tmp / "series.json").write_text("{}")
    assert target.is_dir() and (target / "series.json").read_text() != "{}"  # untouched while the new one is written
    replace_directory(tmp, target)
    assert (target / "series.json").read_text() == "{}"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.vvs"]
    link = tmp_path / "link.vvs"
    link.symlink_to(target)
    with pytest.raises(OutputPathError, match="symbolic link"):
        compress_series(frames, link, pattern="I")
    assert temp_name(target).name.startswith(f".s.vvs.volviz-tmp-{os.getpid()}-")


def test_compressed_volume_writes_refuse_a_fifo_and_clean_up_after_killed_ones(tmp_path: Path) -> None:
    from volviz.model.datasets import RegularVolume
    from volviz.regular.codec import compress

    volume = RegularVolume(np.arange(512, dtype=np.uint8).reshape(8, 8, 8) % 7)
    fifo = tmp_path / "pipe.vvz"
    os.mkfifo(fifo)
    with pytest.raises(OutputPathError, match="FIFO"):
        compress(volume, fifo, mode="lossless")
    fifo.unlink()
    stale = tmp_path / f".v.vvz.volviz-tmp-{dead_pid()}-5"
    stale.write_bytes(b"half a file")
    compress(volume, tmp_path / "v.vvz", mode="lossless")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["v.vvz"]
