"""What a run may ask for: its duration against the control tick and the disk space its log
needs, and the range of angle options. Checked before anything is built (README.md,
"Scenario parameters, scenario files and reruns"), by the parameters' ``check`` (which
``planbench run`` calls while it reads its options) and again by every mechanism's ``build``
(the Python API).

Duration:
  * at least one control tick of the scenario: a shorter run takes no physics step and its
    checks would pass on the initial state alone;
  * its log must fit on disk. The runner streams the log to a file as the run goes
    (``sims.logfile``: t, qpos, qvel, act, ctrl, actuator_force, sensordata, mocap, in
    chunks), in the output directory's staging directory (``planbench run``) or the temporary
    directory (a run that writes nothing). Each mechanism states its bytes per tick (its
    package's ``log_bytes_per_tick``, e.g. ``sims.loader.log_bytes_per_tick``: the log's
    columns and the reference, controller and disturbance arrays kept per tick, an upper
    bound of the file's size; tests/test_run_options.py measures them). A run whose estimate
    exceeds the free space where its log goes (``log_space_limit``) is refused: by the
    parameters' check against the current directory's file system (``planbench run``'s
    default ``results/``), and again by ``sims.pipeline.execute`` against the output's
    (or the temporary directory's) before the first physics step.

Angles (wave heading, wind direction, a wind file's directions): refused beyond
+-ANGLE_LIMIT_DEG (``ANGLE``, the one declaration of their range), used as given inside (every
use is periodic: -90 and 270 deg are the same direction). A larger value is no direction
anyone means: at 1e308 deg a double cannot even tell 1 deg apart.
"""

from __future__ import annotations

import math
import os
import shutil
from pathlib import Path

from sims.params import ParamError

#: Angle options are refused beyond +- this, deg (one turn either way).
ANGLE_LIMIT_DEG = 360.0
#: The range of an angle parameter (``sims.params.param`` keywords).
ANGLE = dict(unit="deg", low=-ANGLE_LIMIT_DEG, high=ANGLE_LIMIT_DEG,
             reason="one turn either way; angles are not wrapped")

_BYTES_PER_FLOAT = 8


class RunLimitError(ParamError):
    """A run option that is a valid number but not a run (too short, too long for the disk)."""


def _existing(path: Path) -> Path:
    """``path``, or the nearest folder above it that exists (an output not yet created)."""
    path = Path(os.path.abspath(path))
    while not path.exists() and path != path.parent:
        path = path.parent
    return path


def free_bytes(directory) -> int:
    """Free space (bytes, for this user) on the file system that holds ``directory``."""
    return shutil.disk_usage(_existing(Path(directory))).free


def log_space_limit(directory=None) -> tuple[float, str]:
    """(bytes, why): the largest log a run writing at ``directory`` may stream, the free space
    on its file system, and the rule in words. None: the current directory (where
    ``planbench run`` writes ``results/`` unless told otherwise)."""
    where = _existing(Path.cwd() if directory is None else Path(directory))
    return float(free_bytes(where)), f"the free space on the file system of {where}"


def format_bytes(n: float) -> str:
    """1.4 PiB, 12 GiB, 300 MiB, 512 B: two significant digits, binary prefixes (above
    1024 EiB in bytes, 2e+21 B)."""
    n = float(n)
    if not math.isfinite(n):
        return "more than 1e308 B"
    if n >= 2**70:
        return f"{n:.2g} B"
    for unit, scale in (("EiB", 2**60), ("PiB", 2**50), ("TiB", 2**40), ("GiB", 2**30),
                        ("MiB", 2**20), ("KiB", 2**10)):
        if n >= scale:
            v = n / scale
            return f"{v:.0f} {unit}" if v >= 10 else f"{v:.2g} {unit}"
    return f"{n:.0f} B"


def runlog_floats_per_tick(model, channels: int) -> int:
    """Doubles per tick of ``sims.runner.RunLog`` for a compiled model: t, qpos (nq), qvel
    (nv), act (na), ctrl and actuator_force (nu each), sensordata, mocap_pos and mocap_quat
    (3 + 4 per mocap body), streamed to the log file; the reference's t, position, velocity
    and acceleration (``channels`` each), in a temporary log of its own
    (``sims.runner.stored_reference``; a reference read whole holds its arrays in memory
    instead, the ticks' times as its t); the ticks' times, in memory."""
    return (3 + model.nq + model.nv + model.na + 2 * model.nu + model.nsensordata
            + 7 * model.nmocap + 3 * channels)


def floats(n: float) -> float:
    """Bytes of ``n`` doubles."""
    return _BYTES_PER_FLOAT * n


def check_duration(duration: float | None, control_dt: float, bytes_per_tick: float,
                   limit: tuple[float, str] | None = None) -> float | None:
    """The duration (s) if it is at least one control tick and its log fits the disk-space limit;
    a RunLimitError naming the value and the limit otherwise.

    Args:
      duration: simulated time asked for, s; None (nothing asked, no default known) passes.
      control_dt: the scenario's control period, s.
      bytes_per_tick: the log's bytes per control tick (``log_bytes_per_tick`` of the
        mechanism).
      limit: (bytes, why), default ``log_space_limit()``.
    """
    if duration is None:
        return None
    duration = float(duration)
    if not math.isfinite(duration):
        raise RunLimitError(f"duration {duration!r} s is not finite")
    if duration < control_dt * (1.0 - 1e-9):
        raise RunLimitError(f"duration {duration:g} s is shorter than one control tick "
                            f"({control_dt * 1e3:g} ms): nothing would be simulated")
    limit_bytes, why = log_space_limit() if limit is None else limit
    need = (duration / control_dt + 1.0) * bytes_per_tick  # ticks, to within one
    if need > limit_bytes:
        raise RunLimitError(f"duration {duration:g} s needs {'' if math.isinf(need) else '~'}"
                            f"{format_bytes(need)} of log, more "
                            f"than the limit of {format_bytes(limit_bytes)} ({why})")
    return duration


