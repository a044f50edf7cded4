"""The trajectory contract shared by every planner.

A planner returns an object with a ``duration`` (s), ``labels`` (one name per channel, e.g. a
joint or strut) and a vectorized ``sample(t)`` that returns positions, velocities and
accelerations at an array of times. The runner samples the whole run once, at the control
rate, so no Python runs per physics step.

Input checks shared by the planners
-----------------------------------
Every number a planner takes from its caller must be finite and within +/-``MAX_MAGNITUDE``
(1e150, in the value's SI unit). No joint, strut, pose, time or limit of a real machine comes
near it, and it keeps products and squares of inputs and of the quantities planned from them
representable: the largest double is 1.8e308, sqrt of it 1.3e154, so even a square of 1e4
times an input stays finite (the B-spline's overshoot check solves quadratics in its
coefficients). ``check_values`` raises a ``PlanningError`` naming the first entry that breaks
this and the limit; ``sample_times`` validates the times of every ``Trajectory.sample``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Protocol, Sequence, runtime_checkable

import numpy as np

from planners.errors import PlanningError

#: The largest magnitude a planner accepts for any input number (module docstring).
MAX_MAGNITUDE = 1e150


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

    def rows(self, start: int, stop: int) -> "TrajectorySample":
        """The sample at the times ``t[start:stop]``."""
        return TrajectorySample(self.t[start:stop], self.position[start:stop], self.velocity[start:stop],
                                self.acceleration[start:stop])

    def head(self, n: int) -> "TrajectorySample":
        """The sample at the first ``n`` times."""
        return self.rows(0, n)


class ChunkedSample:
    """A trajectory's sample at the times ``t`` (n,) s, made a chunk of rows at a time as they
    are asked for (``rows``): a long run's reference, which need not be held whole.
    ``position``, ``velocity`` and ``acceleration`` are TrajectorySample's whole arrays,
    sampled (a chunk at a time) when first read and kept.

    Args:
      sample: t -> TrajectorySample, the trajectory's ``sample`` (or a wrapper of it).
      t: (n,) the times, s.
      chunk: rows sampled at least at a time, so that a row-by-row reader samples once a chunk.
    """

    def __init__(self, sample: Callable, t: np.ndarray, chunk: int = 4096, stored=None):
        self.sample, self.t, self.chunk = sample, t, max(1, int(chunk))
        self._held = (0, None)  # (first row, TrajectorySample) of the rows sampled last
        self._whole = None
        # Rows sampled once and read back: an object with ``span(name, start, stop)`` (a
        # sims.logfile.LogFile of arrays position, velocity, acceleration), or None.
        self.stored = stored

    def rows(self, start: int, stop: int) -> TrajectorySample:
        """The sample at the times ``t[start:stop]`` (0 <= start <= stop <= n)."""
        first, held = self._held
        if self._whole is not None:
            return self._whole.rows(start, stop)
        if self.stored is not None:
            return TrajectorySample(self.t[start:stop], *(self.stored.span(name, start, stop)
                                                          for name in ("position", "velocity", "acceleration")))
        if held is None or start < first or stop > first + held.t.size:
            first, held = start, self.sample(self.t[start:max(stop, start + self.chunk)])
            self._held = (first, held)
        return held.rows(start - first, stop - first)

    def head(self, n: int) -> "ChunkedSample":
        """The sample at the first ``n`` times."""
        head = ChunkedSample(self.sample, self.t[:n], self.chunk, self.stored)
        if self._whole is not None:
            head._whole = self._whole.rows(0, n)
        return head

    def whole(self) -> TrajectorySample:
        """Every row, as one TrajectorySample (kept)."""
        if self._whole is None:
            n = self.t.size
            parts = [self.rows(start, min(start + self.chunk, n)) for start in range(0, n, self.chunk)]
            if not parts:
                self._whole = self.sample(self.t)
            else:
                self._whole = TrajectorySample(self.t, *(np.concatenate([getattr(p, name) for p in parts])
                                                         for name in ("position", "velocity", "acceleration")))
            self._held = (0, None)
            # Every row is now in memory: the stored log is let go (its file, a temporary
            # one already removed from the file system, frees its disk space once closed).
            self.stored = None
        return self._whole

    @property
    def position(self) -> np.ndarray:
        return self.whole().position

    @property
    def velocity(self) -> np.ndarray:
        return self.whole().velocity

    @property
    def acceleration(self) -> np.ndarray:
        return self.whole().acceleration


@runtime_checkable
class Trajectory(Protocol):
    """What the runner needs from a planner's output."""

    @property
    def duration(self) -> float: ...

    @property
    def labels(self) -> Sequence[str]: ...

    def sample(self, t: np.ndarray | float) -> TrajectorySample: ...


def fmt_number(x) -> str:
    """A number as Python writes a float (``nan``, ``inf``, ``1e+308``, no ``np.float64``)."""
    try:
        return repr(float(x))
    except (TypeError, ValueError):
        return repr(x)


def _as_float_array(values, what: str) -> np.ndarray:
    try:
        return np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        text = repr(values)
        text = text if len(text) <= 60 else text[:57] + "..."
        raise PlanningError(f"{what} must be numbers, got {text}") from None


def check_values(values, name: str | Callable[[tuple[int, ...]], str],
                 unit: str | Callable[[tuple[int, ...]], str] = "",
                 max_abs: float = MAX_MAGNITUDE) -> np.ndarray:
    """``values`` as a float array, after checking every entry is finite and |x| <= max_abs.

    Args:
      values: anything ``np.asarray(values, dtype=float)`` takes.
      name: what the values are; a string (the entry's index is appended as ``[i, j]``) or a
        function of the index tuple giving the entry's name (e.g. "key point 3 of joint q1").
      unit: the values' SI unit, for the message (or a function of the index, for arrays
        that mix units such as poses in m and rad).

    Raises:
      PlanningError naming the first offending entry, its value and the limit.
    """
    what = name if isinstance(name, str) else "values"
    arr = _as_float_array(values, what)
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(arr) | (np.abs(arr) > max_abs)
    if not bad.any():
        return arr
    index = tuple(int(i) for i in np.argwhere(bad)[0]) if arr.ndim else ()
    value = float(arr[index])
    if callable(name):
        label = name(index)
    else:
        label = name + (f"[{', '.join(map(str, index))}]" if index else "")
    unit = unit(index) if callable(unit) else unit
    u = f" {unit}" if unit else ""
    if not np.isfinite(value):
        raise PlanningError(f"{label} = {fmt_number(value)}{u} is non-finite (NaN or inf); "
                            f"planners take finite numbers within +/-{max_abs:g}{u}")
    raise PlanningError(f"{label} = {fmt_number(value)}{u} is beyond +/-{max_abs:g}{u}, the "
                        f"largest magnitude planners take")


def check_positive(value, name: str, unit: str = "") -> float:
    """``value`` as a float if it is a finite number > 0 within +/-MAX_MAGNITUDE; else a
    PlanningError ``{name} = {value} {unit} must be finite and > 0`` (or the magnitude's)."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = math.nan
    if not (math.isfinite(x) and x > 0):
        u = f" {unit}" if unit else ""
        raise PlanningError(f"{name} = {value!r}{u} must be finite and > 0")
    return float(check_values(x, name, unit))


def sample_times(t) -> np.ndarray:
    """The times ``t`` (s) of a ``Trajectory.sample`` as a (n,) float array, validated.

    A number or a 1-D array (empty allowed); every time finite and within +/-MAX_MAGNITUDE.
    Raises a PlanningError naming the offending time (``sample time t[i] = nan s ...``) or the
    shape, before anything is computed from them (a NaN time used to index a segment raised an
    IndexError deep in the sampling).
    """
    arr = np.atleast_1d(_as_float_array(t, "sample times"))
    if arr.ndim != 1:
        raise PlanningError(f"sample times must be a number or a 1-D array, got shape "
                            f"{arr.shape}")
    return check_values(arr, lambda i: f"sample time t[{i[0]}]", "s")


def control_ticks(duration: float, control_dt: float) -> np.ndarray:
    """Tick times 0, dt, 2 dt, ... covering ``duration`` (s) inclusive of its end (to 1e-9 s)."""
    if not np.isfinite(duration) or duration < 0:
        raise ValueError(f"duration {duration!r} s must be finite and >= 0")
    if not np.isfinite(control_dt) or control_dt <= 0:
        raise ValueError(f"control period {control_dt!r} s must be finite and > 0")
    n = int(np.floor(duration / control_dt + 1e-9))
    return np.arange(n + 1) * control_dt


class PiecewiseTrajectory:
    """Trajectories one after another: piece i runs from ``starts[i]`` for its duration, then
    holds its end (at rest) until the next starts; the last piece ends the whole.

    For a list of moves (the hexapod's): each piece must start where the one before ended
    (the pieces are planned that way); the channels are the first piece's.
    """

    def __init__(self, pieces, starts):
        self.pieces = list(pieces)
        self.starts = np.asarray(starts, dtype=float)
        if not self.pieces or self.starts.shape != (len(self.pieces),) or self.starts[0] != 0.0 \
                or np.any(np.diff(self.starts) < [p.duration for p in self.pieces[:-1]]):
            raise ValueError("pieces must start at 0 and each after the one before has ended")

    @property
    def duration(self) -> float:
        return float(self.starts[-1] + self.pieces[-1].duration)

    @property
    def labels(self):
        return self.pieces[0].labels

    def sample(self, t) -> TrajectorySample:
        t = sample_times(t)
        index = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, len(self.pieces) - 1)
        n = len(self.pieces[0].labels)
        position, velocity, acceleration = (np.zeros((t.size, n)) for _ in range(3))
        for i, piece in enumerate(self.pieces):
            rows = np.flatnonzero(index == i)
            if rows.size == 0:
                continue
            local = t[rows] - self.starts[i]
            moving = local <= piece.duration
            s = piece.sample(np.minimum(local, piece.duration))
            position[rows] = s.position
            velocity[rows] = np.where(moving[:, None], s.velocity, 0.0)
            acceleration[rows] = np.where(moving[:, None], s.acceleration, 0.0)
        return TrajectorySample(t, position, velocity, acceleration)
