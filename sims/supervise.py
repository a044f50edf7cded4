"""Plug-in code runs supervised: in a child process that the parent watches.

A user's planner or controller is untrusted code: it may raise, call ``sys.exit`` or
``os._exit``, hang, or kill its own process. ``planbench run`` therefore validates its input
and takes its output's lock in the parent, then builds, simulates and writes in a forked
child (``run_supervised``). The child sends its outcome back over a pipe; a child that ends
without sending one (``os._exit``, a signal, a crash) or that outlives its wall-time limit is
a fault of the code it was running, never a pass. Where it was is kept in a small shared
memory page (``phase``), written at each boundary between planbench's code and the plug-ins'
(importing a plug-in, its factory, ``plan``, ``sample``, ``reset``, the control loop), so the
parent's verdict names the plug-in and the call.

Forking is cheap (no imports repeated) and safe here: nothing has started a thread or made an
OpenGL context before it. The child dies with its parent (``PR_SET_PDEATHSIG``).
"""

from __future__ import annotations

import contextlib
import ctypes
import mmap
import os
import pickle
import select
import signal
import struct
import sys
import time
import traceback
from dataclasses import dataclass

#: Default wall-time limit of a run, s: this plus the simulated duration (a run slower than
#: real time by ten minutes has hung; the longest default scenario takes about a minute).
DEFAULT_TIMEOUT_BASE_S = 600.0

#: After SIGTERM, how long a timed-out or orphaned child may clean up before SIGKILL, s.
KILL_GRACE_S = 2.0

#: How the phases from the first physics step on begin: a run that ends there has simulated.
AFTER_FIRST_STEP = ("the control loop", "evaluating", "writing")

_PAGE = 4096
_TEXT = 2048  # bytes of the phase text; a float (the simulated duration) follows


class _Board:
    """The shared page: the phase text and the simulated duration once the run knows it."""

    def __init__(self):
        self.map = mmap.mmap(-1, _PAGE)

    def write_phase(self, text: str) -> None:
        data = text.encode("utf-8", "replace")[: _TEXT - 1]
        self.map[:_TEXT] = data + b"\0" * (_TEXT - len(data))

    def read_phase(self) -> str:
        return self.map[:_TEXT].split(b"\0", 1)[0].decode("utf-8", "replace")

    def write_duration(self, seconds: float) -> None:
        self.map[_TEXT : _TEXT + 8] = struct.pack("d", float(seconds))

    def read_duration(self) -> float:
        return struct.unpack("d", self.map[_TEXT : _TEXT + 8])[0]


_board: _Board | None = None  # set in a supervised child only


def phase(text: str) -> None:
    """Say where the supervised run is now (a no-op outside a supervised child)."""
    if _board is not None:
        _board.write_phase(text)


def in_worker() -> _Board:
    """Phases recorded in this process (a campaign's worker), for its own timeout messages."""
    global _board
    if _board is None:
        _board = _Board()
    _board.write_phase("planbench's own code, before any plug-in")
    return _board


def report_duration(seconds: float) -> None:
    """Tell the parent the run's simulated duration, s (its default time limit follows it)."""
    if _board is not None:
        _board.write_duration(seconds)


@dataclass
class Ended:
    """How a supervised child ended without completing. ``phase``: where it was;
    ``how``: its exit status or signal, or the time limit it passed; ``timed_out``."""

    phase: str
    how: str
    timed_out: bool
    elapsed_s: float
    limit_s: float | None


class Fault(Exception):
    """The supervised child ended without completing (``ended`` says how)."""

    def __init__(self, ended: Ended):
        super().__init__(f"the run ended in {ended.phase} without completing: {ended.how}")
        self.ended = ended


def _die_with_parent(parent: int) -> None:
    with contextlib.suppress(Exception):
        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL))  # PR_SET_PDEATHSIG
    if os.getppid() != parent:  # the parent died before prctl took hold
        os._exit(1)


def _child(work, board: _Board, write_fd: int, parent: int) -> None:
    """Run ``work`` and send its outcome: ("ok", value), ("raised", exception) or
    ("interrupted", None). Never returns."""
    global _board
    code = 0
    signalled = []

    def interrupted(signum, frame):
        # The first signal interrupts; what is raised while cleaning up after it (ffmpeg
        # killed by the same Ctrl-C: a broken pipe) is its consequence, not a fault.
        if not signalled:
            signalled.append(signum)
            # SIGTERM: the parent's time limit (``_stop``); the log so far is kept.
            raise RunStopped if signum == signal.SIGTERM else KeyboardInterrupt

    try:
        from planbench.outputs import INTERRUPT_SIGNALS, RunStopped

        for s in INTERRUPT_SIGNALS:
            signal.signal(s, interrupted)
        _die_with_parent(parent)
        _board = board
        try:
            payload = ("ok", work())
        except KeyboardInterrupt:
            payload = ("interrupted", None)
        except BaseException as e:  # noqa: BLE001  (sent to the parent, which decides)
            if signalled:
                payload = ("interrupted", None)
            else:
                if not _one_line(e):
                    traceback.print_exc()
                payload = ("raised", e)
        try:
            data = pickle.dumps(payload)
        except Exception:  # noqa: BLE001  (an exception that does not pickle)
            data = pickle.dumps(("raised", RuntimeError(f"{type(payload[1]).__name__}: {payload[1]}")))
        with os.fdopen(write_fd, "wb") as pipe:
            pipe.write(data)
    except BaseException:  # noqa: BLE001
        code = 70
    finally:
        with contextlib.suppress(Exception):
            sys.stdout.flush()
            sys.stderr.flush()
        os._exit(code)


def _one_line(e: BaseException) -> bool:
    """Errors the CLI prints as one line (bad input, plug-in faults), not as a traceback."""
    from planbench.outputs import OutputError
    from planbench.planners.errors import PlanningError
    from planbench.task import PluginError

    return isinstance(e, (PlanningError, OutputError, PluginError, ValueError, SystemExit))


def _status(status: int) -> str:
    if os.WIFSIGNALED(status):
        sig = os.WTERMSIG(status)
        with contextlib.suppress(ValueError):
            return f"its process was killed by {signal.Signals(sig).name}"
        return f"its process was killed by signal {sig}"
    code = os.waitstatus_to_exitcode(status)
    return f"its process exited with status {code} before the run finished (os._exit or a crash)"


def _stop(pid: int) -> int:
    """SIGTERM, a short grace, SIGKILL; the wait status."""
    with contextlib.suppress(ProcessLookupError):
        os.kill(pid, signal.SIGTERM)
    deadline = time.monotonic() + KILL_GRACE_S
    while time.monotonic() < deadline:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            return status
        time.sleep(0.02)
    with contextlib.suppress(ProcessLookupError):
        os.kill(pid, signal.SIGKILL)
    return os.waitpid(pid, 0)[1]


def run_supervised(work, timeout_s: float | None = None):
    """``work()`` in a forked child; its return value, or its exception raised again here.

    ``timeout_s``: the wall-time limit, s; None: ``DEFAULT_TIMEOUT_BASE_S`` plus the simulated
    duration the child reports (``report_duration``). Raises ``Fault`` when the child ends
    without completing or passes the limit (it is killed), KeyboardInterrupt when it was
    interrupted. An interrupt of the parent stops the child before it propagates."""
    board = _Board()
    board.write_phase("planbench's own code, before any plug-in")
    board.write_duration(float("nan"))
    sys.stdout.flush()
    sys.stderr.flush()
    read_fd, write_fd = os.pipe()
    parent = os.getpid()
    pid = os.fork()
    if pid == 0:
        os.close(read_fd)
        _child(work, board, write_fd, parent)
    os.close(write_fd)
    start = time.monotonic()
    chunks = []
    reaped = None
    try:
        with os.fdopen(read_fd, "rb") as pipe:
            fd = pipe.fileno()
            while True:
                duration = board.read_duration()
                limit = (
                    timeout_s
                    if timeout_s is not None
                    else DEFAULT_TIMEOUT_BASE_S + (0.0 if duration != duration else duration)
                )
                left = limit - (time.monotonic() - start)
                if left <= 0:
                    where = board.read_phase()
                    reaped = _stop(pid)
                    raise Fault(
                        Ended(where, f"it passed the time limit of {limit:g} s", True, time.monotonic() - start, limit)
                    )
                ready, _, _ = select.select([fd], [], [], min(left, 1.0))
                if ready:
                    data = os.read(fd, 1 << 20)
                    if not data:
                        break
                    chunks.append(data)
        reaped = os.waitpid(pid, 0)[1]
    except BaseException:
        if reaped is None:
            reaped = _stop(pid)
        raise
    if not chunks:
        raise Fault(Ended(board.read_phase(), _status(reaped), False, time.monotonic() - start, timeout_s))
    kind, value = pickle.loads(b"".join(chunks))
    if kind == "ok":
        return value
    if kind == "interrupted":
        raise KeyboardInterrupt
    raise value
