"""The parent's side of a reader child process: start it, send one request, wait for its answer within a time limit,
and say what happened when it dies.

A child is ``python -m volviz.io.isolated`` with requests as JSON lines on its stdin and answers as JSON lines on its
stdout (the child moves its own stdout to stderr first, so nothing a library prints can break the protocol). Its
stderr is drained by a thread into a short tail, kept to explain an abort (``std::bad_alloc`` is an out-of-memory).
Idle children are kept warm in a small pool: starting Python and importing VTK costs most of a second, a warm request
a few milliseconds.
"""
from __future__ import annotations

import atexit
import json
import os
import select
import signal
import subprocess
import sys
import threading
import time
from collections import deque
from typing import Any

STARTUP_SECONDS = 120.0  # a cold start on a loaded machine; not counted in a read's time limit
MAX_IDLE = 2
MAX_REQUESTS = 200  # a child is replaced after this many reads (what a reader leaks goes with it)
TAIL_BYTES = 8192
SIGNAL_WHAT = {
    signal.SIGSEGV: "crashed (segmentation fault)",
    signal.SIGBUS: "crashed (bus error)",
    signal.SIGFPE: "crashed (arithmetic fault)",
    signal.SIGILL: "crashed (illegal instruction)",
    signal.SIGABRT: "aborted",
    signal.SIGKILL: "was killed (SIGKILL, usually the system running out of memory)",
}


class ChildDied(Exception):
    """The child ended without answering: ``what`` says how (a signal, an exit status), ``tail`` its last stderr."""

    def __init__(self, what: str, tail: str) -> None:
        super().__init__(what)
        self.what, self.tail = what, tail


class ChildTimedOut(Exception):
    """The child did not answer within the time limit and was killed."""


#: the child's argument for a child started for the read at hand (``volviz render FILE``): waiting for that read, it
#: loads none of the readers' VTK modules it may not use (issue #30: 0.1 s of the child's CPU while the parent
#: imported the render layer)
AT_HAND = "--read-at-hand"


class Worker:
    """One child process; not thread-safe (the pool hands each worker to one caller at a time)."""

    def __init__(self, idle_load: bool = True) -> None:
        """``idle_load``: the child loads every reader's VTK modules while it waits for its first request (a child
        kept warm for reads to come); without, it loads only what its reads use (``AT_HAND``)."""
        env = dict(os.environ)
        env["MALLOC_ARENA_MAX"] = "2"  # glibc reserves 64 MB of address space per thread arena otherwise (RLIMIT_AS)
        env["PYTHONUNBUFFERED"] = "1"
        env.pop("VOLVIZ_ISOLATE", None)
        argv = [sys.executable, "-m", "volviz.io.isolated", *(() if idle_load else (AT_HAND,))]
        self.proc = subprocess.Popen(argv, stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, close_fds=True)
        assert self.proc.stdin is not None and self.proc.stdout is not None  # pipes, as asked
        self._stdin, self._stdout = self.proc.stdin, self.proc.stdout
        self._buffer = b""
        self._tail: deque[bytes] = deque()
        self._tail_size = 0
        self._ready = False
        self.requests = 0
        threading.Thread(target=self._drain, args=(self.proc.stderr,), daemon=True,
                         name=f"volviz-reader-{self.proc.pid}-stderr").start()

    def _drain(self, stream) -> None:
        while True:
            chunk = stream.read1(4096)
            if not chunk:
                stream.close()      # the child has gone: its stderr pipe is closed here, not left to the collector
                return
            self._tail.append(chunk)
            self._tail_size += len(chunk)
            while self._tail_size > TAIL_BYTES and len(self._tail) > 1:
                self._tail_size -= len(self._tail.popleft())

    def tail(self) -> str:
        return b"".join(self._tail).decode("utf-8", "replace")

    @property
    def alive(self) -> bool:
        return self.proc.poll() is None

    def _line(self, deadline: float) -> bytes:
        """The next line of the child's stdout, waiting until ``deadline`` (monotonic)."""
        fd = self._stdout.fileno()
        while b"\n" not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0:
                raise ChildTimedOut()
            ready, _, _ = select.select([fd], [], [], min(left, 1.0))
            if not ready:
                continue
            chunk = os.read(fd, 1 << 16)
            if not chunk:
                raise self._died()
            self._buffer += chunk
        line, _, self._buffer = self._buffer.partition(b"\n")
        return line

    def _died(self) -> ChildDied:
        try:
            code = self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.kill()
            code = self.proc.returncode
        time.sleep(0.05)  # let the drain thread take the last of stderr
        if code is not None and code < 0:
            try:
                name = signal.Signals(-code)
                what = SIGNAL_WHAT.get(name, f"was killed by signal {name.name}")
            except ValueError:
                what = f"was killed by signal {-code}"
        else:
            what = f"exited unexpectedly (status {code})"
        return ChildDied(what, self.tail())

    def wait_ready(self) -> None:
        """Wait for the child's start-up line (its imports done); ChildDied if it could not start."""
        if not self._ready:
            try:
                hello = json.loads(self._line(time.monotonic() + STARTUP_SECONDS))
            except ChildTimedOut:
                self.kill()
                raise ChildDied(f"did not start within {STARTUP_SECONDS:.0f} s", self.tail()) from None
            if not (isinstance(hello, dict) and hello.get("ready")):
                self.kill()
                raise ChildDied(f"started with an unexpected line {str(hello)[:80]!r}", self.tail())
            self._ready = True

    def request(self, message: dict, seconds: float) -> Any:
        """Send one request and return the decoded answer; ChildTimedOut (the child is killed) or ChildDied."""
        self.wait_ready()
        self.requests += 1
        self._tail.clear()  # what this request makes the child print explains its death, not an earlier request's
        self._tail_size = 0
        try:
            self._stdin.write(json.dumps(message).encode() + b"\n")
            self._stdin.flush()
        except (BrokenPipeError, OSError):
            raise self._died() from None
        try:
            line = self._line(time.monotonic() + seconds)
        except ChildTimedOut:
            self.kill()
            raise
        return json.loads(line)

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:  # pragma: no cover - SIGKILL is not refused
            pass
        self._close_pipes()

    def close(self) -> None:
        """Ask an idle child to leave (end of its stdin), and make sure it has."""
        try:
            self._stdin.close()
            self.proc.wait(timeout=2)
        except (OSError, subprocess.TimeoutExpired):
            pass
        self.kill()

    def _close_pipes(self) -> None:
        for stream in (self._stdin, self._stdout):
            try:
                stream.close()
            except OSError:
                pass


class Pool:
    """Warm children waiting for requests: ``take`` hands one out (starting one if none waits), ``give`` takes it
    back."""

    def __init__(self, max_idle: int = MAX_IDLE) -> None:
        self.max_idle = max_idle
        self._idle: list[Worker] = []
        self._lock = threading.Lock()
        atexit.register(self.shutdown)

    def take(self) -> Worker:
        with self._lock:
            while self._idle:
                worker = self._idle.pop()
                if worker.alive:
                    return worker
                worker.kill()
        return Worker()

    def give(self, worker: Worker) -> None:
        if not worker.alive or worker.requests >= MAX_REQUESTS:
            self.prewarm()  # its successor starts now, not when the next read waits for it
            # the old child leaves in the background: the read that retired it does not wait for its exit
            threading.Thread(target=worker.close, name="volviz-reader-close", daemon=True).start()
            return
        with self._lock:
            if len(self._idle) < self.max_idle:
                self._idle.append(worker)
                return
        worker.close()

    def prewarm(self, idle_load: bool = True) -> None:
        """Start a child now (without waiting for it) so the first read finds it ready (``idle_load``: ``Worker``)."""
        with self._lock:
            if any(w.alive for w in self._idle):
                return
            self._idle.append(Worker(idle_load))

    def shutdown(self) -> None:
        with self._lock:
            idle, self._idle = self._idle, []
        for worker in idle:
            worker.close()

    def idle_pids(self) -> list[int]:
        with self._lock:
            return [w.proc.pid for w in self._idle if w.alive]
