"""What a run may ask for: its duration against the control tick and the memory its log
needs, and the range of angle options. Checked before anything is built (README.md,
"Scenario parameters, scenario files and reruns"), by the parameters' ``check`` (which
``planbench run`` calls while it reads its options) and again by every mechanism's ``build``
(the Python API).

Duration:
  * at least one control tick of the scenario: a shorter run takes no physics step and its
    checks would pass on the initial state alone;
  * its log must fit in memory. The runner preallocates the log (``sims.runner.RunLog``:
    t, qpos, qvel, act, ctrl, actuator_force, sensordata, mocap, the reference sampled at
    every tick) and the controllers and disturbances preallocate their own per-tick arrays;
    each mechanism states those per tick (its package's ``log_bytes_per_tick``, e.g.
    ``sims.loader.log_bytes_per_tick``; tests/test_run_options.py measures them). A run whose
    estimate exceeds ``log_memory_limit()``, a quarter of the machine's physical memory, is
    refused: evaluating the checks and writing the outputs needs about as much again as the
    log (measured peaks of 1.2-2.5 times the log), so a quarter leaves the rest of the machine
    its memory.

Angles (wave heading, wind direction, a wind file's directions): refused beyond
+-ANGLE_LIMIT_DEG (``ANGLE``, the one declaration of their range), used as given inside (every
use is periodic: -90 and 270 deg are the same direction). A larger value is no direction
anyone means: at 1e308 deg a double cannot even tell 1 deg apart.
"""

from __future__ import annotations

import math
import os

from sims.params import ParamError

#: The log may take this fraction of physical memory (see the module doc).
LOG_MEMORY_FRACTION = 0.25
#: The limit where the system does not report its memory (os.sysconf): 4 GiB, a quarter of a
#: 16 GiB machine.
FALLBACK_LOG_LIMIT_BYTES = 4 * 2**30
#: Angle options are refused beyond +- this, deg (one turn either way).
ANGLE_LIMIT_DEG = 360.0
#: The range of an angle parameter (``sims.params.param`` keywords).
ANGLE = dict(unit="deg", low=-ANGLE_LIMIT_DEG, high=ANGLE_LIMIT_DEG,
             reason="one turn either way; angles are not wrapped")

_BYTES_PER_FLOAT = 8


class RunLimitError(ParamError):
    """A run option that is a valid number but not a run (too short, too long for memory)."""


def physical_memory_bytes() -> int | None:
    """This machine's physical memory (os.sysconf), None where the system does not say."""
    try:
        pages, size = os.sysconf("SC_PHYS_PAGES"), os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        return None
    return pages * size if pages > 0 and size > 0 else None


def log_memory_limit() -> tuple[float, str]:
    """(bytes, why): the largest log a run may preallocate, and the rule in words."""
    total = physical_memory_bytes()
    if total is None:
        return float(FALLBACK_LOG_LIMIT_BYTES), "this system does not report its memory"
    return LOG_MEMORY_FRACTION * total, f"a quarter of this machine's {format_bytes(total)} of memory"


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
    (3 + 4 per mocap body), and the reference's position, velocity and acceleration
    (``channels`` each; its t is the log's)."""
    return (1 + model.nq + model.nv + model.na + 2 * model.nu + model.nsensordata
            + 7 * model.nmocap + 3 * channels)


def floats(n: float) -> float:
    """Bytes of ``n`` doubles."""
    return _BYTES_PER_FLOAT * n


def check_duration(duration: float | None, control_dt: float, bytes_per_tick: float,
                   limit: tuple[float, str] | None = None) -> float | None:
    """The duration (s) if it is at least one control tick and its log fits the memory limit;
    a RunLimitError naming the value and the limit otherwise.

    Args:
      duration: simulated time asked for, s; None (nothing asked, no default known) passes.
      control_dt: the scenario's control period, s.
      bytes_per_tick: the log's bytes per control tick (``log_bytes_per_tick`` of the
        mechanism).
      limit: (bytes, why), default ``log_memory_limit()``.
    """
    if duration is None:
        return None
    duration = float(duration)
    if not math.isfinite(duration):
        raise RunLimitError(f"duration {duration!r} s is not finite")
    if duration < control_dt * (1.0 - 1e-9):
        raise RunLimitError(f"duration {duration:g} s is shorter than one control tick "
                            f"({control_dt * 1e3:g} ms): nothing would be simulated")
    limit_bytes, why = log_memory_limit() if limit is None else limit
    need = (duration / control_dt + 1.0) * bytes_per_tick  # ticks, to within one
    if need > limit_bytes:
        raise RunLimitError(f"duration {duration:g} s needs {'' if math.isinf(need) else '~'}"
                            f"{format_bytes(need)} of log, more "
                            f"than the limit of {format_bytes(limit_bytes)} ({why})")
    return duration


