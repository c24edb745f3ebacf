"""``volviz compress`` checks every argument that reaches a computation first (issue #32): --raw sizes against the
file, the input a regular file (a FIFO never blocks it), a --scheduler that answers; each a one-line usage error that
leaves nothing behind in the output folder."""
from __future__ import annotations

import os
import socket
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from conftest import data_file

from volviz.cli import main
from volviz.regular.cli import _check_scheduler

VOLVIZ = Path(sys.executable).with_name("volviz")


def _usage_error(capsys: pytest.CaptureFixture[str], args: list[str]) -> str:
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("volviz: error: "), err
    return err[0].removeprefix("volviz: error: ")


def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if "volviz-tmp" in p.name or p.suffix in (".vvz", ".vvs"))


def test_raw_sizes_are_checked_against_the_file(tmp_path, capsys):
    raw = tmp_path / "small.raw"
    raw.write_bytes(bytes(1000))
    out = tmp_path / "o.vvz"
    line = _usage_error(capsys, ["compress", str(raw), "-o", str(out), "--raw", "100000", "100000", "100000"])
    assert line == (f"--raw 100000 100000 100000 --dtype uint8 needs 1000000000000000 bytes, but {raw} holds 1000 "
                    "bytes (fewer): give its dimensions and --dtype")
    line = _usage_error(capsys, ["compress", str(raw), "-o", str(out), "--raw", "10", "10", "4", "--dtype", "uint16"])
    assert line.endswith(f"needs 800 bytes, but {raw} holds 1000 bytes (more): give its dimensions and --dtype")
    assert _leftovers(tmp_path) == []
    data = (np.arange(1000) % 7).astype(np.uint8)  # the right sizes still compress, losslessly
    raw.write_bytes(data.tobytes())
    assert main(["compress", str(raw), "-o", str(out), "--raw", "10", "10", "10", "--quiet"]) == 0
    from volviz.regular.codec import decompress

    assert np.array_equal(decompress(out).data, data.reshape((10, 10, 10), order="F"))


def test_a_fifo_input_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "fifo.pvm"
    os.mkfifo(fifo)
    for extra in (["--raw", "10", "10", "10"], []):
        # a guard, not a timing: a blocked open would hang here until the timeout kills it
        done = subprocess.run([str(VOLVIZ), "compress", str(fifo), "-o", str(tmp_path / "out.vvz"), *extra],
                              capture_output=True, text=True, timeout=120)
        assert done.returncode == 2
        assert done.stderr.strip() == f"volviz: error: {fifo}: is a FIFO (named pipe), not a regular file"
    assert _leftovers(tmp_path) == []


def _closed_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_an_unreachable_scheduler_is_a_usage_error(tmp_path, capsys):
    port = _closed_port()
    pattern = str(data_file("storm/Storm.pvm-t01")).replace("t01", "t%02d")
    out = tmp_path / "s.vvs"
    line = _usage_error(capsys, ["compress", pattern, "-o", str(out), "--series", "--scheduler",
                                 f"tcp://127.0.0.1:{port}"])
    assert line == (f"--scheduler tcp://127.0.0.1:{port}: no scheduler reachable at 127.0.0.1:{port} "
                    "(Connection refused)")
    assert _leftovers(tmp_path) == []  # nothing read, no temporary store folder
    line = _usage_error(capsys, ["compress", pattern, "-o", str(out), "--series", "--scheduler", "somewhere"])
    assert line == "--scheduler 'somewhere': not an address of the form tcp://HOST:PORT"


@pytest.mark.parametrize("reply, message", [
    (b"", "accepted the connection but sent no scheduler handshake within 0.5 s (got 0 bytes)"),
    (b"HTTP/1.1 400 Bad Request\r\n", "answers, but not as a dask scheduler (its first message claims "
                                      f"{int.from_bytes(b'HTTP/1.1', 'little')} bytes)"),
])
def test_a_listener_that_is_no_scheduler_is_refused(reply, message):
    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]
    conns: list[socket.socket] = []

    def serve() -> None:
        conn, _ = server.accept()
        conns.append(conn)
        if reply:
            conn.sendall(reply)

    thread = threading.Thread(target=serve, daemon=True)
    thread.start()
    try:
        with pytest.raises(SystemExit) as caught:
            _check_scheduler(f"tcp://127.0.0.1:{port}", timeout=0.5)
        assert str(caught.value.code) == f"--scheduler tcp://127.0.0.1:{port}: 127.0.0.1:{port} {message}"
    finally:
        thread.join()
        for c in conns:
            c.close()
        server.close()
