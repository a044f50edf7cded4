"""1-D motion profiles with first-degree (piecewise-linear) acceleration: the FAST paper's Figure 6.

Paper: Yao et al. 2020, "A motion planning algorithm for the feed support system of FAST"
(REFERENCE.md "Papers"), section 3: "all the acceleration
curves adopted in this paper are first degree curves, so that the velocity planning curves are
quadratic" (Figure 6). Every segment of a FAST plan uses them: start/termination (section 3.1),
the source switching straight line and focal segments with their times T_line, T_focal
(section 3.2, eq. 10), and the transition segments of an observation (section 3.3, A_max,
A_t-max of Table 1). The same profile serves a position along a path (m) or an angle (rad); the
docstrings say m, m/s, m/s^2, m/s^3, read rad, rad/s, ... for an angle.

Reading of Figure 6
-------------------
The figure itself is not in the text; the sentence above and the paper's use of "a maximum
velocity and acceleration" (section 3.2) are read as follows. Acceleration is a continuous,
piecewise-linear function of time (first degree on each piece, constant jerk), so velocity is
piecewise quadratic and position piecewise cubic. A change of speed from v0 to v1 is one
triangular acceleration *pulse*: the acceleration rises linearly from 0 to a peak a and falls
linearly back to 0, so it is zero (and continuous) at both ends of every change. A pulse of peak
a and duration T changes the speed by a T / 2 (its area), so with peak a_max

    T = 2 |v1 - v0| / a_max,        distance = (v0 + v1) / 2 * T            (``velocity_change``)

(the pulse is point-symmetric about its midpoint, so its mean speed is (v0 + v1) / 2). A move is
a pulse from v0 to a cruise speed v_c, a cruise at v_c for tau >= 0, and a pulse from v_c to v1,
with |peak acceleration| <= a_max and |v| <= v_max.

Minimum time (``move_min_time``, ``min_move_time``)
---------------------------------------------------
Work in the direction of motion s = sign(distance): d = |distance|, u0 = s v0, u1 = s v1, both
in [0, v_max] (a profile never reverses: s v(t) >= 0 throughout). With both pulses at a_max the
pulses alone (tau = 0) cover

    f(v) = (sgn(v - u0) (v^2 - u0^2) + sgn(v - u1) (v^2 - u1^2)) / a_max

which is smallest, d_min = |u1^2 - u0^2| / a_max, for v between u0 and u1: a shorter distance
cannot be covered without reversing (``LimitError``). For v >= max(u0, u1) the move time is
T(v) = 2 (2 v - u0 - u1) / a_max + (d - f(v)) / v, and dT/dv = 2 / a_max - (d + (u0^2 + u1^2) /
a_max) / v^2 < 0 up to the speed where the cruise vanishes (f(v) = d); a weaker pulse only
lengthens the move. So the fastest profile of the family peaks at

    v_p = sqrt((a_max d + u0^2 + u1^2) / 2):
    v_p <= v_max:  v_c = v_p, no cruise,       T = 2 (2 v_p - u0 - u1) / a_max
    v_p >  v_max:  v_c = v_max, cruise tau = (d - f(v_max)) / v_max,
                   T = 2 (2 v_max - u0 - u1) / a_max + tau.

Rest to rest (u0 = u1 = 0): reaching v_c takes 2 v_c / a_max over v_c^2 / a_max, so the move is
T = 2 sqrt(2 d / a_max) when d <= 2 v_max^2 / a_max, else T = d / v_max + 2 v_max / a_max.

Prescribed time (``move_in_time``)
----------------------------------
When several mechanisms must finish together (the paper's eq. (10): T_line is the largest of
the mechanisms' times and the others are re-planned for it) a move must take exactly T >= T_min.
Rule: both pulses keep the full peak a_max (the shortest speed changes) and the cruise takes the
rest of the time; the cruise speed v is then the unique solution of

    h(v) = v T - (phi(v - u0) + phi(v - u1)) / a_max = d,     phi(x) = x |x|,

(h is the distance covered in time T, h'(v) = tau >= 0, so h is increasing on the admissible
speeds) solved exactly on each of its three quadratic/linear pieces (v above, between or below
u0 and u1). For a rest-to-rest move this is v = (a T - sqrt(a^2 T^2 - 8 a d)) / 4, the lowest
cruise speed (hence the lowest peak speed, the gentlest on the speed limit) of any profile of
the family with that duration and distance: a weaker pulse leaves less time to cruise and needs
a faster cruise. The other natural choice, the lowest peak acceleration (the Rubin hexapod's
rule, planbench.planners.hexapod), gives the opposite, the highest cruise speed; it is not used here.
A move with nonzero boundary speeds can also be too slow: slowing down (to rest at the most) and
speeding up again covers at least h(v_lowest) (``LimitError``; the profiles never reverse).

Sampling outside the profile (``Profile.evaluate``): before t = 0 the start velocity is held
(position p0 + v0 t, zero acceleration and jerk: at rest for a profile that starts at rest);
after the end the final velocity is held (position p_end + v_end (t - T), zero acceleration).

API
---
* ``Profile(durations, accel, p0=0, v0=0, label="s")``: piece durations (s) and the
  acceleration at every break (m/s^2), linear in between; ``Profile.from_breaks``. ``duration``,
  ``evaluate(t, side)`` -> ``ProfileSample`` (position, velocity, acceleration, jerk, shaped as
  t), ``sample(t)`` -> ``planbench.planners.trajectory.TrajectorySample`` with (n, 1) arrays (a
  single-channel ``Trajectory``), ``then``/``concatenate`` (end to end), ``with_start``.
* ``velocity_change(v0, v1, a_max)``, ``cruise(velocity, duration)``,
  ``min_move_time(distance, v_max, a_max, v0=0, v1=0)`` (s),
  ``move_min_time(distance, v_max, a_max, v0=0, v1=0)``,
  ``move_in_time(distance, duration, v_max, a_max, v0=0, v1=0)``.
Requests that sit on a limit within round-off (d = d_min, T = T_min, to 1e-12 relative) are
planned on the limit. A pulse shorter than the resolution of the absolute break times
(h < 8 eps T) is widened to that length with a lower peak and the same speed change.
``move_in_time``'s duration is exact to the last bit where the sum of the pieces allows it (the
round-off of the sum is moved into the longest piece).
Every number given (distances, speeds, limits, durations, accelerations, sample times) must be
finite and within +/-``planbench.planners.trajectory.MAX_MAGNITUDE``, and so must a profile's break
times, positions, velocities and jerks (a ``PlanningError`` names the value and the limit).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from planbench.planners.errors import LimitError, PlanningError
from planbench.planners.trajectory import TrajectorySample, check_values, fmt_number, sample_times

__all__ = [
    "Profile",
    "ProfileSample",
    "concatenate",
    "cruise",
    "min_move_time",
    "move_in_time",
    "move_min_time",
    "velocity_change",
]

# Relative round-off allowed when a request sits exactly on a limit (d == d_min, T == T_min).
_RTOL = 1e-12


# --------------------------------------------------------------------------- the profile


@dataclass(frozen=True, eq=False)
class ProfileSample:
    """A profile at the times ``t`` (arrays of t's shape): m, m/s, m/s^2, m/s^3."""

    t: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray


@dataclass(frozen=True, eq=False)
class Profile:
    """A piecewise-cubic 1-D motion whose acceleration is continuous and piecewise linear.

    Attributes:
      durations: (k,) piece durations, s, each > 0 (k == 0: a profile of zero duration).
      accel: (k+1,) acceleration at each break, m/s^2; linear in between (constant jerk
        (accel[i+1] - accel[i]) / durations[i] on piece i). accel[0] is the start acceleration.
      p0, v0: start position (m) and velocity (m/s).
      label: the channel's name (the Trajectory protocol's ``labels``).

    Derived: ``breaks`` (k+1,) = 0, cumsum(durations) (s); ``positions``, ``velocities`` (k+1,)
    at the breaks, integrated exactly piece by piece from the durations (so a short pulse after
    a long cruise keeps its exact area; absolute break times carry the round-off of t); ``jerk``
    (k,). Sampling is exact at the breaks (it returns these values). Position and velocity are
    continuous by construction, and so is acceleration. ``Profile.from_breaks`` builds one from
    break times.
    """

    durations: np.ndarray
    accel: np.ndarray
    p0: float = 0.0
    v0: float = 0.0
    label: str = "s"

    def __post_init__(self):
        dt = np.array(self.durations, dtype=float).reshape(-1)
        accel = np.array(self.accel, dtype=float).reshape(-1)
        if accel.size != dt.size + 1:
            raise PlanningError(f"a profile of {dt.size} pieces needs {dt.size + 1} accelerations, got {accel.size}")
        check_values(dt, "profile durations", "s")
        check_values(accel, "profile accel", "m/s^2")
        if np.any(dt <= 0):
            i = int(np.argmax(dt <= 0))
            raise PlanningError(f"profile piece durations must be > 0: durations[{i}] = {_fmt(dt[i])} s")
        p0, v0 = _finite("p0", self.p0, "m"), _finite("v0", self.v0, "m/s")
        a0, a1 = accel[:-1], accel[1:]
        velocities = v0 + np.concatenate(([0.0], np.cumsum(0.5 * (a0 + a1) * dt)))
        dp = velocities[:-1] * dt + (2.0 * a0 + a1) * dt * dt / 6.0
        positions = p0 + np.concatenate(([0.0], np.cumsum(dp)))
        jerk = np.diff(accel) / dt
        breaks = np.concatenate(([0.0], np.cumsum(dt)))
        # Derived values: within the same magnitude, so sampling (t * v ...) stays finite.
        for name, value, unit in (
            ("break time", breaks, "s"),
            ("position", positions, "m"),
            ("velocity", velocities, "m/s"),
            ("jerk", jerk, "m/s^3"),
        ):
            check_values(value, lambda i, name=name: f"profile {name} at break {i[0]}", unit)
        for name, value in (
            ("durations", dt),
            ("accel", accel),
            ("breaks", breaks),
            ("positions", positions),
            ("velocities", velocities),
            ("jerk", jerk),
        ):
            value.setflags(write=False)
            object.__setattr__(self, name, value)
        object.__setattr__(self, "p0", p0)
        object.__setattr__(self, "v0", v0)

    @classmethod
    def from_breaks(cls, breaks, accel, p0: float = 0.0, v0: float = 0.0, label: str = "s") -> Profile:
        """From break times (k+1,) s: breaks[0] == 0, strictly increasing."""
        breaks = np.array(breaks, dtype=float).reshape(-1)
        if breaks.size < 1 or not np.all(np.isfinite(breaks)):
            raise PlanningError(f"profile breaks {breaks} s must be >= 1 finite times")
        if breaks[0] != 0.0:
            raise PlanningError(f"a profile starts at t = 0 s, got breaks[0] = {_fmt(breaks[0])} s")
        dt = np.diff(breaks)
        if np.any(dt <= 0):
            i = int(np.argmax(dt <= 0))
            raise PlanningError(
                f"profile breaks must increase strictly: breaks[{i + 1}] = "
                f"{_fmt(breaks[i + 1])} s <= breaks[{i}] = {_fmt(breaks[i])} s"
            )
        return cls(dt, accel, p0, v0, label)

    # ----------------------------------------------------------------- properties

    @property
    def duration(self) -> float:
        """s."""
        return float(self.breaks[-1])

    @property
    def labels(self) -> tuple[str, ...]:
        return (self.label,)

    @property
    def a0(self) -> float:
        """Start acceleration, m/s^2."""
        return float(self.accel[0])

    @property
    def end_position(self) -> float:
        return float(self.positions[-1])

    @property
    def end_velocity(self) -> float:
        return float(self.velocities[-1])

    @property
    def end_acceleration(self) -> float:
        return float(self.accel[-1])

    @property
    def distance(self) -> float:
        """end_position - p0, m (signed)."""
        return float(self.positions[-1] - self.positions[0])

    @property
    def peak_acceleration(self) -> float:
        """max |a|, m/s^2 (at a break: a is linear on each piece)."""
        return float(np.max(np.abs(self.accel)))

    @property
    def peak_speed(self) -> float:
        """max |v| over the profile, m/s: at a break or where a piece's acceleration crosses 0."""
        a0, a1 = self.accel[:-1], self.accel[1:]
        cross = a0 * a1 < 0
        tau = np.where(cross, -a0 / np.where(self.jerk != 0, self.jerk, 1.0), 0.0)
        inner = self.velocities[:-1] + a0 * tau + 0.5 * self.jerk * tau * tau
        return float(max(np.max(np.abs(self.velocities)), np.max(np.abs(inner), initial=0.0)))

    # ----------------------------------------------------------------- sampling

    def evaluate(self, t, side: str = "right") -> ProfileSample:
        """Position, velocity, acceleration and jerk at the times ``t`` (s, any shape).

        Inside [0, duration] the piece containing t is evaluated; exactly at a break the values
        stored for that break are returned (``side="right"``, the default) or the previous
        piece's polynomial is evaluated at its end (``side="left"``: the left limits, e.g. to
        check continuity); ``side`` also picks which piece's jerk a break gets. Before 0: the
        start velocity held, p0 + v0 t, zero acceleration and jerk. After the end: the final
        velocity held, p_end + v_end (t - T), zero acceleration and jerk.
        """
        if side not in ("left", "right"):
            raise PlanningError(f"side {side!r} is not 'left' or 'right'")
        t = check_values(t, "sample time", "s")
        k = self.breaks.size - 1
        idx = np.searchsorted(self.breaks, t, side=side) - 1
        idx = np.clip(idx, 0, k)
        # One extra zero-jerk "piece" after the last break, for t >= T.
        jerk = np.append(self.jerk, 0.0)
        outside = (t < 0.0) | (t > self.breaks[-1])
        tau = t - self.breaks[idx]
        a = np.where(outside, 0.0, self.accel[idx])
        j = np.where(outside, 0.0, jerk[idx])
        v = self.velocities[idx]
        p = self.positions[idx] + tau * (v + tau * (a / 2.0 + tau * j / 6.0))
        return ProfileSample(
            t=t,
            position=p,
            velocity=v + tau * (a + tau * j / 2.0),
            acceleration=a + j * tau,
            jerk=j,
        )

    def sample(self, t) -> TrajectorySample:
        """The Trajectory protocol: t (n,) s -> (n, 1) position, velocity, acceleration.

        ``t``: a number or a 1-D array of finite times (``planbench.planners.trajectory.sample_times``).
        """
        t = sample_times(t)
        s = self.evaluate(t)
        return TrajectorySample(
            t=t, position=s.position[:, None], velocity=s.velocity[:, None], acceleration=s.acceleration[:, None]
        )

    # ----------------------------------------------------------------- composition

    def with_start(self, position: float) -> Profile:
        """The same motion started at ``position`` (m)."""
        return Profile(self.durations, self.accel, _finite("position", position, "m"), self.v0, self.label)

    def then(self, *others: Profile) -> Profile:
        """``concatenate([self, *others])``."""
        return concatenate([self, *others])


def concatenate(profiles: Sequence[Profile], rtol: float = 1e-9) -> Profile:
    """Profiles end to end: each starts where (position, time) the one before it ended.

    Each profile's start velocity and acceleration must equal the previous end's to ``rtol``
    relative to the largest speed / acceleration of the two (else ``PlanningError``), so the
    result is continuous in position, velocity and acceleration (every planned move here starts
    and ends at zero acceleration). Positions are relative: a later profile's own p0 is
    replaced by the previous end position. The result keeps the first profile's label and p0.
    """
    profiles = list(profiles)
    if not profiles:
        raise PlanningError("concatenate needs at least one profile, got none")
    first = profiles[0]
    durations, accel = [first.durations], [first.accel]
    v_end, a_end = first.end_velocity, first.end_acceleration
    v_scale = np.max(np.abs(first.velocities))
    a_scale = np.max(np.abs(first.accel))
    for i, nxt in enumerate(profiles[1:], start=1):
        v_scale_i = max(v_scale, np.max(np.abs(nxt.velocities)))
        a_scale_i = max(a_scale, np.max(np.abs(nxt.accel)))
        if abs(nxt.v0 - v_end) > rtol * v_scale_i:
            raise PlanningError(
                f"profile {i} starts at v0 = {_fmt(nxt.v0)} m/s but the one "
                f"before it ends at {_fmt(v_end)} m/s (tolerance "
                f"{rtol * v_scale_i:.3g} m/s)"
            )
        if abs(nxt.a0 - a_end) > rtol * a_scale_i:
            raise PlanningError(
                f"profile {i} starts at a0 = {_fmt(nxt.a0)} m/s^2 but the one "
                f"before it ends at {_fmt(a_end)} m/s^2 (tolerance "
                f"{rtol * a_scale_i:.3g} m/s^2)"
            )
        durations.append(nxt.durations)
        accel.append(nxt.accel[1:])
        v_scale, a_scale = v_scale_i, a_scale_i
        if nxt.durations.size:
            v_end += nxt.end_velocity - nxt.v0
            a_end = nxt.end_acceleration
    return Profile(np.concatenate(durations), np.concatenate(accel), first.p0, first.v0, first.label)


def cruise(velocity: float, duration: float, start: float = 0.0, label: str = "s") -> Profile:
    """Constant ``velocity`` (m/s; 0 holds still) for ``duration`` s from ``start`` m."""
    velocity = _finite("velocity", velocity, "m/s")
    duration = _duration(duration)
    durations = [duration] if duration > 0 else []
    return Profile(durations, np.zeros(len(durations) + 1), start, velocity, label)


# --------------------------------------------------------------------------- planning


def velocity_change(v0: float, v1: float, a_max: float) -> Profile:
    """The minimum-time pulse from v0 to v1 (m/s): peak a_max (m/s^2), from position 0.

    Duration 2 |v1 - v0| / a_max, distance (v0 + v1) / 2 * duration (FAST paper, Figure 6).
    v0 == v1 gives a profile of zero duration.
    """
    v0 = _finite("v0", v0, "m/s")
    v1 = _finite("v1", v1, "m/s")
    a_max = _positive("a_max", a_max, "m/s^2")
    dv = v1 - v0
    half = abs(dv) / a_max
    if half == 0.0:
        return Profile([], [0.0], 0.0, v0)
    return Profile([half, half], [0.0, np.sign(dv) * a_max, 0.0], 0.0, v0)


def min_move_time(distance: float, v_max: float, a_max: float, v0: float = 0.0, v1: float = 0.0) -> float:
    """The minimum time (s) of ``move_min_time`` (same arguments), without building it.

    For the paper's eq. (10): the largest of the mechanisms' minimum times sets T_line.
    """
    return _plan_min(distance, v_max, a_max, v0, v1)[-1]


def move_min_time(distance: float, v_max: float, a_max: float, v0: float = 0.0, v1: float = 0.0) -> Profile:
    """The fastest profile of the family that moves ``distance`` m (signed) from v0 to v1.

    Args:
      distance: m (or rad), signed; the profile starts at position 0.
      v_max: speed limit, m/s, > 0; a_max: peak-acceleration limit, m/s^2, > 0.
      v0, v1: boundary velocities, m/s, |v| <= v_max, in the direction of the distance (or 0).

    Cruise speed min(v_max, sqrt((a_max |d| + v0^2 + v1^2) / 2)), both pulses at a_max (module
    docstring). Raises ``LimitError`` when a boundary speed exceeds v_max or points against the
    distance, or when |distance| < |v1^2 - v0^2| / a_max (it cannot be covered without
    reversing); ``PlanningError`` on NaN/inf or non-positive limits.
    """
    s, u0, _, a, _, up, down, tau, _ = _plan_min(distance, v_max, a_max, v0, v1)
    return _build(s, u0, up, tau, down, a)


def move_in_time(
    distance: float, duration: float, v_max: float, a_max: float, v0: float = 0.0, v1: float = 0.0
) -> Profile:
    """A profile of the family that moves ``distance`` m from v0 to v1 in exactly ``duration`` s.

    Both pulses at the full peak a_max, the cruise takes the rest of the time, the cruise speed
    solves h(v) = d exactly (module docstring): for a rest-to-rest move, the lowest cruise speed
    of any profile of the family with this duration. ``duration`` == ``min_move_time(...)``
    gives ``move_min_time``'s profile. Raises ``LimitError`` when the duration is shorter than
    the minimum time, or (nonzero boundary speeds only) so long that even slowing down as far as
    the family allows covers more than the distance; otherwise as ``move_min_time``.
    """
    T = _duration(duration)
    s, u0, u1, a, _, up_fast, down_fast, tau_fast, t_min = _plan_min(distance, v_max, a_max, v0, v1)
    d = abs(float(distance))
    v_max = float(v_max)
    if T < t_min:
        if T < t_min * (1.0 - _RTOL):
            raise LimitError(
                f"duration {_fmt(T)} s is shorter than the minimum time "
                f"{_fmt(t_min)} s to move {_fmt(distance)} m from v0 = {_fmt(v0)} "
                f"to v1 = {_fmt(v1)} m/s under v_max = {_fmt(v_max)} m/s, "
                f"a_max = {_fmt(a_max)} m/s^2"
            )
        T_plan = t_min
    else:
        T_plan = T
    lo, hi = min(u0, u1), max(u0, u1)
    mid, reach = 0.5 * (u0 + u1), 0.25 * a * T_plan
    v_bot = min(max(0.0, mid - reach), lo)
    v_top = max(min(v_max, mid + reach), hi)

    def h(v):
        x0, x1 = v - u0, v - u1
        return v * T_plan - (x0 * abs(x0) + x1 * abs(x1)) / a

    d_low = h(v_bot)
    if d < d_low * (1.0 - _RTOL):
        raise LimitError(
            f"duration {_fmt(T)} s is too long to move {_fmt(distance)} m from "
            f"v0 = {_fmt(v0)} to v1 = {_fmt(v1)} m/s: slowing down (to "
            f"{_fmt(s * v_bot)} m/s at the most, a_max = {_fmt(a_max)} m/s^2) and "
            f"back still covers {_fmt(s * d_low)} m, and the profiles never reverse"
        )
    if d >= h(hi):  # cruise above both boundary speeds: 2 v^2 - B v + C = 0, lower root
        B = 2.0 * (u0 + u1) + a * T_plan
        C = u0 * u0 + u1 * u1 + a * d
        den = B + np.sqrt(max(B * B - 8.0 * C, 0.0))
        v = 2.0 * C / den if den > 0 else 0.0
    elif d >= h(lo):  # between them: h is linear with slope T - 2 (hi - lo) / a > 0
        slope = T_plan - 2.0 * (hi - lo) / a  # 0 only for the bare pulse, T = 2 |u1 - u0| / a
        v = lo + (d - h(lo)) / slope if slope > 0 else hi
    else:  # below both: 2 v^2 + B v + C = 0, upper root
        B = a * T_plan - 2.0 * (u0 + u1)
        C = u0 * u0 + u1 * u1 - a * d
        root = np.sqrt(max(B * B - 8.0 * C, 0.0))
        v = -2.0 * C / (B + root) if B > 0 else 0.25 * (root - B)
    v = min(max(v, v_bot), v_top)
    up, down = v - u0, u1 - v
    tau = max(T_plan - 2.0 * (abs(up) + abs(down)) / a, 0.0)
    if T_plan <= t_min * (1.0 + 16.0 * np.finfo(float).eps):
        # The minimum-time profile: at T = t_min the quadratic has a double root, which the
        # formula finds only to ~sqrt(eps); the few ulps T - t_min go to the exact-duration
        # correction.
        up, down, tau = up_fast, down_fast, tau_fast
    return _build(s, u0, up, tau, down, a, total=T)


# --------------------------------------------------------------------------- helpers


_fmt = fmt_number  # a number as Python writes a float (no ``np.float64(...)``)


def _finite(name: str, value, unit: str) -> float:
    """One finite number within +/-MAX_MAGNITUDE (``planbench.planners.trajectory.check_values``)."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise PlanningError(f"{name} = {_fmt(value)} {unit} is not a number") from None
    return float(check_values(x, name, unit))


def _positive(name: str, value, unit: str) -> float:
    x = _finite(name, value, unit)
    if x <= 0:
        raise PlanningError(f"{name} = {_fmt(value)} {unit} must be > 0")
    return x


def _duration(value) -> float:
    x = _finite("duration", value, "s")
    if x < 0:
        raise PlanningError(f"duration = {_fmt(value)} s must be >= 0")
    return x


def _plan_min(distance, v_max, a_max, v0, v1):
    """Validate and plan the minimum-time move, in the direction s of motion.

    Returns (s, u0, u1, a, v_c, up, down, tau, T): speeds u0 = s v0, u1 = s v1, cruise speed
    v_c, the pulses' speed changes up = v_c - u0 and down = u1 - v_c (computed without
    cancellation), cruise time tau and the minimum time T.
    """
    dist = _finite("distance", distance, "m")
    v_max = _positive("v_max", v_max, "m/s")
    a = _positive("a_max", a_max, "m/s^2")
    v0 = _finite("v0", v0, "m/s")
    v1 = _finite("v1", v1, "m/s")
    for name, value in (("v0", v0), ("v1", v1)):
        if abs(value) > v_max:
            raise LimitError(f"|{name}| = {_fmt(abs(value))} m/s exceeds v_max = {_fmt(v_max)} m/s")
    s = np.sign(dist) or np.sign(v0) or np.sign(v1) or 1.0
    s = float(s)
    for name, value in (("v0", v0), ("v1", v1)):
        if s * value < 0:
            raise LimitError(
                f"{name} = {_fmt(value)} m/s points against the distance {_fmt(dist)} m; the profiles never reverse"
            )
    d, u0, u1 = abs(dist), s * v0 + 0.0, s * v1 + 0.0
    d_min = abs(u1 * u1 - u0 * u0) / a
    if d < d_min * (1.0 - _RTOL):
        raise LimitError(
            f"distance {_fmt(dist)} m is too short to change speed from v0 = "
            f"{_fmt(v0)} to v1 = {_fmt(v1)} m/s at a_max = {_fmt(a)} m/s^2 without "
            f"reversing: it needs at least {_fmt(s * d_min)} m"
        )
    lo, hi = min(u0, u1), max(u0, u1)
    # v_p^2 - hi^2 = (a d - (hi^2 - lo^2)) / 2 = a (d - d_min) / 2: the peak's excess over the
    # higher boundary speed without the cancellation of sqrt((a d + u0^2 + u1^2) / 2) - hi
    # when a d << u^2 (the pulse widths, hence the time and distance, keep full precision).
    excess2 = max(0.5 * (a * d - (hi - lo) * (hi + lo)), 0.0)
    v_peak = float(np.sqrt(hi * hi + excess2))
    if v_peak <= v_max:
        v, tau = v_peak, 0.0
        above = excess2 / (v_peak + hi) if v_peak > 0 else 0.0  # v_p - hi
        up, down = above + (hi - u0), -(above + (hi - u1))  # v - u0, u1 - v
    else:
        v = v_max
        up, down = v - u0, u1 - v
        pulses = (up * (v + u0) - down * (v + u1)) / a  # f(v_max)
        tau = max((d - pulses) / v, 0.0)
    T = 2.0 * (abs(up) + abs(down)) / a + tau
    return s, u0, u1, a, v, up, down, tau, T


def _exact_total(durations: np.ndarray, total: float) -> np.ndarray:
    """Durations whose sum, as Profile sums them (cumsum), is ``total`` to the last bit.

    Only round-off is moved, first to the longest piece (the cruise where there is one), then,
    if the sum still jumps over ``total``, to the last piece (whose last-bit changes always reach
    it): one correction, then steps of one ulp (the sum is monotone in each piece). The closest
    sum found is kept.
    """
    best, best_err = durations, abs(np.cumsum(durations)[-1] - total)
    for i in (int(np.argmax(durations)), durations.size - 1):
        trial = best.copy()
        if i == durations.size - 1 and durations.size > 1:
            guess = total - np.cumsum(trial[:-1])[-1]
        else:
            guess = trial[i] - (np.cumsum(trial)[-1] - total)
        if guess > 0:
            trial[i] = guess
        direction = 0.0
        for _ in range(64):
            err = np.cumsum(trial)[-1] - total
            if abs(err) < best_err:
                best, best_err = trial.copy(), abs(err)
            step = -np.inf if err > 0 else np.inf
            if err == 0 or (direction and step != direction):
                break
            direction = step
            trial[i] = np.nextafter(trial[i], step)
            if trial[i] <= 0:
                break
        if best_err == 0:
            break
    return best


def _build(s, u0, up, tau, down, a, total=None) -> Profile:
    """From speed u0: a pulse changing it by ``up`` (peak a), a cruise of tau s, a pulse
    changing it by ``down``; all velocities times s, from position 0. ``total``: the exact
    duration (its round-off moved by ``_exact_total``)."""
    h1, h2 = abs(up) / a, abs(down) / a
    # A pulse shorter than the resolution of the absolute break times would put a jump of
    # a_max between two equal break times. Such a pulse is widened to h_min = 8 eps T with a
    # lower peak |dv| / h_min (the same speed change); its extra time comes out of the cruise
    # (moving it changes the distance by (extra time) * |dv| / 2: round-off).
    h_min = 8.0 * np.finfo(float).eps * (2.0 * (h1 + h2) + tau)
    peak1 = peak2 = a
    if 0 < h1 < h_min:
        tau -= 2.0 * (h_min - h1)
        h1, peak1 = h_min, abs(up) / h_min
    if 0 < h2 < h_min:
        tau -= 2.0 * (h_min - h2)
        h2, peak2 = h_min, abs(down) / h_min
    tau = max(tau, 0.0)  # no cruise to take it from: the move is longer by < 32 eps T
    pieces = [(h1, np.sign(up) * peak1), (h1, 0.0), (tau, 0.0), (h2, np.sign(down) * peak2), (h2, 0.0)]
    pieces = [(dt, acc) for dt, acc in pieces if dt > 0]
    if total is not None and not pieces and total > 0:
        pieces = [(total, 0.0)]  # nothing to change: only wait (safety; tau carries it)
    durations = np.array([dt for dt, _ in pieces])
    accel = s * np.array([0.0] + [acc for _, acc in pieces]) + 0.0
    if total is not None and durations.size:
        durations = _exact_total(durations, total)
    return Profile(durations, accel, 0.0, s * u0 + 0.0)
