"""The trajectory contract shared by every planner.

A planner returns an object with a ``duration`` (s), ``labels`` (one name per channel, e.g. a
joint or strut) and a vectorized ``sample(t)`` that returns positions, velocities and
accelerations at an array of times. The runner samples the whole run once, at the control
rate, so no Python runs per physics step.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, Sequence, runtime_checkable

import numpy as np


@dataclass(frozen=True)
class TrajectorySample:
    """Planned motion at the times ``t``.

    Attributes:
      t: (n,) times in s.
      position: (n, m) positions, SI (m or rad) per channel.
      velocity: (n, m) first time derivatives.
      acceleration: (n, m) second time derivatives.
    """

    t: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray


@runtime_checkable
class Trajectory(Protocol):
    """What the runner needs from a planner's output."""

    @property
    def duration(self) -> float: ...

    @property
    def labels(self) -> Sequence[str]: ...

    def sample(self, t: np.ndarray | float) -> TrajectorySample: ...


def control_ticks(duration: float, control_dt: float) -> np.ndarray:
    """Tick times 0, dt, 2 dt, ... covering ``duration`` (s) inclusive of its end (to 1e-9 s)."""
    if not np.isfinite(duration) or duration < 0:
        raise ValueError(f"duration {duration!r} s must be finite and >= 0")
    if not np.isfinite(control_dt) or control_dt <= 0:
        raise ValueError(f"control period {control_dt!r} s must be finite and > 0")
    n = int(np.floor(duration / control_dt + 1e-9))
    return np.arange(n + 1) * control_dt
