"""Uniform cubic B-spline through key points, zero velocity at both ends.

This is the joint-space planner of the ammunition loading robot paper
(Li, Xu, Luo, "Trajectory Planning of Ammunition Loading Robot Based on Cubic-B Spline",
REFERENCE.md "Papers"), written from its definitions:

* eq. (10): segment i, local parameter u in [0, 1],
  theta_i(u) = 1/6 [u^3 u^2 u 1] B [P_i, P_i+1, P_i+2, P_i+3]^T with the basis matrix B below;
* eq. (7): a segment starts at (P_i + 4 P_i+1 + P_i+2) / 6, which must equal key point M_i;
* eq. (8): the start velocity (P_2 - P_0) / 2 (and the end velocity) are zero.

Eq. (9) collects these into a banded (n+3)x(n+3) system for n+1 key points. As printed, its
right-hand side is ``M_i`` while eq. (7) needs ``6 M_i`` (the 1/6 of the basis was dropped);
we solve the system from eq. (7) and (8) and test the result against eq. (11).

The paper places key points at uniform times (0, 0.5, ... 2.5 s) and the uniform basis of
eq. (6) only holds for uniform knots, so non-uniform key times are rejected with a
``PlanningError`` instead of being silently mis-timed.

With zero end velocities this is the clamped interpolating cubic spline (REFERENCE.md); the
tests check it against ``scipy.interpolate.CubicSpline(bc_type="clamped")``.

Joint limits and round-off
--------------------------
Key points are checked against the limits exactly: they are the caller's numbers, so one on a
limit is accepted and one beyond it by any amount is refused. Between key points the spline is
checked at its extrema, and there its values are the planner's own arithmetic: the control
points come from a linear solve, the power-basis coefficients from them, the values from
Horner's rule. A spline that touches a limit in exact arithmetic (a key point on the limit, the
spline at rest there) evaluates to the limit give or take a few ulps of the control points, so
a strict comparison refused, e.g., the move 1 -> 0 in [0, 1] for a value of -2.2e-16. The
check therefore allows, per joint,

    tolerance = 64 (eps max_k |P_k| + eta)    (eps = 2.2e-16, P the joint's control points,
                                               eta = 4.9e-324 the smallest subnormal)

(``limit_tolerance``), an a priori bound of the evaluation's error. The banded solve is
backward stable and its matrix well conditioned: its error in the values is a few eps max |P|
(at most 3 measured). Each coefficient a_r = sum_q B_rq P_q is four rounded products and
sums, error <= 4 eps sum_q |B_rq| max |P|; summed over the rows (sum |B| = 32/6) that is
<= 22 eps max |P| at u in [0, 1]. Horner's rule adds at most 6 eps sum_r |a_r| <=
32 eps max |P|. Together < 64 eps max |P|; measured against exact rational arithmetic the
error never exceeded 3 eps max |P|. Each operation may also underflow by up to eta (the
standard error model's absolute term), which matters only for values near 1e-308 (a key
point of 5e-324 on a limit of 0 evaluated to -5e-324). The tolerance scales with the magnitude of the values,
not with the limits' range: the round-off of a joint near 1000 rad is that of 1000, whatever
its range. A real overshoot, larger than this, is still refused, and the sampled trajectory
stays within the limits up to the same tolerance (both tested in
``tests/test_api_bad_input.py``).

A planner for a machine may also allow an absolute ``margin`` per joint (default 0): key
points may then lie up to ``margin`` beyond a limit, and the spline between them up to
``margin`` plus its round-off (``limit_tolerance``). The loader's planner allows its encoders'
``planbench.planners.loader.JOINT_LIMIT_TOLERANCE``, so that what it refuses is a departure from the
range the machine could measure, not one of 1e-92 m (round-off of values near 1e-88 is
1e-104, which no limit check at the range's scale can see).

Inputs are checked before anything is solved: key times, key points and limits must be finite
and within +/-``planbench.planners.trajectory.MAX_MAGNITUDE``, the limits ordered, and the key step long
enough that the spline's accelerations stay within that magnitude too (a step of 1e-200 s
would give infinite accelerations).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike
from scipy import linalg

from planbench.planners.errors import LimitError, PlanningError
from planbench.planners.trajectory import MAX_MAGNITUDE, TrajectorySample, check_values, fmt_number, sample_times

# Eq. (10): power-basis coefficients of the uniform cubic B-spline, rows for u^3, u^2, u, 1.
BASIS = (
    np.array(
        [
            [-1.0, 3.0, -3.0, 1.0],
            [3.0, -6.0, 3.0, 0.0],
            [-3.0, 0.0, 3.0, 0.0],
            [1.0, 4.0, 1.0, 0.0],
        ]
    )
    / 6.0
)

_UNIFORM_RTOL = 1e-9
# Round-off allowed between key points, in units of eps * max |control point| of the joint
# (module docstring, "Joint limits and round-off").
LIMIT_TOLERANCE_ULPS = 64


def solve_control_points(key_points: np.ndarray) -> np.ndarray:
    """Control points P_0 ... P_{n+2} of the clamped uniform cubic B-spline (eq. 7-9).

    Args:
      key_points: (n+1, m) key points M_0 ... M_n, n >= 1, one column per joint.

    Returns:
      (n+3, m) control points. Row 0 and row n+2 carry the zero-velocity conditions
      P_0 = P_2 and P_{n+2} = P_n (eq. 8); rows 1..n+1 the interpolation conditions
      P_{i-1} + 4 P_i + P_{i+1} = 6 M_{i-1} (eq. 7).
    """
    key_points = np.asarray(key_points, dtype=float)
    n_keys = key_points.shape[0]
    size = n_keys + 2
    # Banded storage for solve_banded with 2 sub- and 2 super-diagonals:
    # ab[2 + i - j, j] = A[i, j].
    ab = np.zeros((5, size))

    def put(i: int, j: int, value: float) -> None:
        ab[2 + i - j, j] = value

    put(0, 0, -3.0)
    put(0, 2, 3.0)
    for i in range(1, size - 1):
        put(i, i - 1, 1.0)
        put(i, i, 4.0)
        put(i, i + 1, 1.0)
    put(size - 1, size - 3, -3.0)
    put(size - 1, size - 1, 3.0)
    rhs = np.zeros((size, key_points.shape[1]))
    rhs[1:-1] = 6.0 * key_points
    return linalg.solve_banded((2, 2), ab, rhs)


def _distinct(value: float, limit: float) -> tuple[str, str]:
    """A value and its limit as 6 significant digits, or in full where those look equal."""
    a, b = f"{value:.6g}", f"{limit:.6g}"
    return (a, b) if a != b else (fmt_number(value), fmt_number(limit))


class CubicBSplineTrajectory:
    """Joint trajectory through key points at uniform times (loader paper, eq. 1-10).

    Args:
      times: (n+1,) key times in s, strictly increasing and uniformly spaced.
      key_points: (n+1, m) joint values at those times, SI units (m or rad).
      labels: m joint names, used in error messages and outputs.
      lower, upper: optional (m,) joint limits, finite, lower <= upper. Key points outside
        them (by more than ``margin``) are rejected, and so is a spline that overshoots them
        between key points by more than ``limit_tolerance`` (``margin`` plus its round-off;
        module docstring).
      margin: absolute tolerance beyond a limit, a number or (m,), >= 0, in the joints'
        units (default 0: key points exactly, the spline to its round-off).

    Before ``times[0]`` and after ``times[-1]`` the trajectory holds its end points at rest.
    """

    def __init__(
        self,
        times: ArrayLike,
        key_points: ArrayLike,
        labels: Sequence[str] | None = None,
        lower: ArrayLike | None = None,
        upper: ArrayLike | None = None,
        margin: ArrayLike = 0.0,
    ):
        try:
            times = np.asarray(times, dtype=float)
            key_points = np.asarray(key_points, dtype=float)
        except (TypeError, ValueError):
            raise PlanningError(f"key times {times!r} and key points {key_points!r} must be numbers") from None
        if key_points.ndim == 1:
            key_points = key_points[:, None]
        if times.ndim != 1:
            raise PlanningError(f"key times must be a 1-D array, got shape {times.shape}")
        check_values(times, lambda i: f"key time t[{i[0]}]", "s")
        if times.size < 2:
            raise PlanningError(f"need at least 2 key points, got {times.size}")
        if key_points.ndim != 2 or key_points.shape[0] != times.size:
            raise PlanningError(
                f"key points have shape {key_points.shape}, expected ({times.size}, n_joints) "
                f"for {times.size} key times"
            )
        m = key_points.shape[1]
        labels = list(labels) if labels is not None else [f"q{j + 1}" for j in range(m)]
        if len(labels) != m:
            raise PlanningError(f"{len(labels)} joint labels for {m} joint columns")
        check_values(key_points, lambda i: f"key point {i[0]} of joint {labels[i[1]]}")
        steps = np.diff(times)
        if np.any(steps <= 0):
            k = int(np.argmax(steps <= 0))
            raise PlanningError(
                f"key times must increase strictly: t[{k + 1}] = {times[k + 1]} s <= t[{k}] = {times[k]} s"
            )
        h = (times[-1] - times[0]) / (times.size - 1)
        worst = int(np.argmax(np.abs(steps - h)))
        if abs(steps[worst] - h) > _UNIFORM_RTOL * h:
            raise PlanningError(
                f"key times must be uniformly spaced (the paper's uniform B-spline, eq. 6): "
                f"step {worst} is {steps[worst]} s, the mean step is {h} s"
            )
        limits = {}
        for name, lim in (("lower", lower), ("upper", upper)):
            if lim is None:
                limits[name] = None
                continue
            try:
                arr = np.asarray(lim, dtype=float)
            except (TypeError, ValueError):
                raise PlanningError(f"{name} limits {lim!r} are not numbers") from None
            if arr.shape != (m,):
                raise PlanningError(f"{name} limits have shape {arr.shape}, expected ({m},)")
            limits[name] = check_values(arr, lambda i, name=name: f"{name} limit of joint {labels[i[0]]}")
        self._lower, self._upper = limits["lower"], limits["upper"]
        try:
            margin = np.broadcast_to(np.asarray(margin, dtype=float), (m,)).copy()
        except (TypeError, ValueError):
            raise PlanningError(f"margin {margin!r} must be a number >= 0 or {m} of them") from None
        bad = np.flatnonzero(~(margin >= 0) | ~np.isfinite(margin))
        if bad.size:
            raise PlanningError(f"margin of joint {labels[bad[0]]} = {margin[bad[0]]!r} must be finite and >= 0")
        self._margin = margin
        if self._lower is not None and self._upper is not None:
            crossed = np.flatnonzero(self._lower > self._upper)
            if crossed.size:
                j = int(crossed[0])
                raise PlanningError(
                    f"joint {labels[j]}: lower limit {self._lower[j]:.6g} is above its upper limit {self._upper[j]:.6g}"
                )
        self._check_limits(key_points, labels, times, what="key point")

        self._t0 = float(times[0])
        self._h = float(h)
        self._times = times
        self._key_points = key_points
        self._labels = labels
        self.control_points = solve_control_points(key_points)
        # Power-basis coefficients of every segment in the local parameter u, shape
        # (segments, 4, m), rows for u^3, u^2, u, 1 (eq. 10 expanded once).
        windows = np.stack([self.control_points[i : i + 4] for i in range(times.size - 1)])
        self._coef_u = np.einsum("rc,scm->srm", BASIS, windows)
        self._check_key_step()
        finfo = np.finfo(float)
        self._tolerance = self._margin + LIMIT_TOLERANCE_ULPS * (
            finfo.eps * np.max(np.abs(self.control_points), axis=0) + finfo.smallest_subnormal
        )
        self._check_overshoot()

    # -- the Trajectory contract -------------------------------------------------------------
    @property
    def duration(self) -> float:
        return float(self._times[-1])

    @property
    def labels(self) -> list[str]:
        return list(self._labels)

    @property
    def key_times(self) -> np.ndarray:
        return self._times.copy()

    @property
    def key_points(self) -> np.ndarray:
        return self._key_points.copy()

    @property
    def limit_tolerance(self) -> np.ndarray:
        """(m,) allowed beyond a limit between key points: ``margin`` + 64 (eps max |P| + eta)
        per joint (module docstring, "Joint limits and round-off"); in the joints' units."""
        return self._tolerance.copy()

    @property
    def margin(self) -> np.ndarray:
        """(m,) allowed beyond a limit at the key points (the constructor's ``margin``)."""
        return self._margin.copy()

    def sample(self, t: np.ndarray | float) -> TrajectorySample:
        """Positions, velocities and accelerations at times ``t`` (s), vectorized (eq. 10).

        ``t``: a number or a 1-D array of finite times (``planbench.planners.trajectory.sample_times``;
        a PlanningError names a NaN or infinite time).
        """
        t = sample_times(t)
        s = (np.clip(t, self._t0, self._times[-1]) - self._t0) / self._h
        seg = np.minimum(np.floor(s).astype(int), self._coef_u.shape[0] - 1)
        u = (s - seg)[:, None]
        c = self._coef_u[seg]  # (n, 4, m)
        pos = ((c[:, 0] * u + c[:, 1]) * u + c[:, 2]) * u + c[:, 3]
        vel = ((3.0 * c[:, 0] * u + 2.0 * c[:, 1]) * u + c[:, 2]) / self._h
        acc = (6.0 * c[:, 0] * u + 2.0 * c[:, 1]) / self._h**2
        outside = (t < self._t0) | (t > self._times[-1])
        vel[outside] = 0.0
        acc[outside] = 0.0
        return TrajectorySample(t=t, position=pos, velocity=vel, acceleration=acc)

    # -- the paper's piecewise-polynomial form -----------------------------------------------
    def segment_polynomials(self) -> np.ndarray:
        """Coefficients of theta(t) = a3 (t-t_i)^3 + a2 (t-t_i)^2 + a1 (t-t_i) + a0 per segment.

        The form of eq. (11)-(13). Returns shape (segments, 4, m), rows a3, a2, a1, a0, in
        the joint's units per power of seconds.
        """
        scale = np.array([self._h**-3, self._h**-2, self._h**-1, 1.0])
        return self._coef_u * scale[None, :, None]

    # -- validation ---------------------------------------------------------------------------
    def _check_key_step(self):
        """Refuse a key step so short that the spline's accelerations leave +/-MAX_MAGNITUDE.

        The acceleration in a segment is (6 a3 u + 2 a2) / h^2, at most 8 max |a| / h^2.
        """
        peak = float(np.max(np.abs(self._coef_u[:, :2]))) if self._coef_u.size else 0.0
        if peak == 0.0:
            return
        with np.errstate(over="ignore", divide="ignore"):
            accel = 8.0 * peak / np.float64(self._h) ** 2
        if not accel <= MAX_MAGNITUDE:
            shortest = np.sqrt(8.0 * peak / MAX_MAGNITUDE)
            raise PlanningError(
                f"key step {self._h:.6g} s is too short for these key points: the spline's "
                f"accelerations (up to {accel:.3g} per s^2) would exceed +/-{MAX_MAGNITUDE:g}; "
                f"the key step must be >= {shortest:.3g} s"
            )

    def _check_limits(self, values, labels, times, what):
        # sign (v - l) > margin: with margin 0 exactly v > l (a difference of two doubles is 0
        # only when they are equal).
        for name, lim, sign in (("lower", self._lower, -1.0), ("upper", self._upper, 1.0)):
            if lim is None:
                continue
            excess = sign * (values - lim[None, :])
            bad = np.argwhere(excess > self._margin[None, :])
            if bad.size:
                k, j = bad[0]
                value, limit = _distinct(values[k, j], lim[j])
                allowed = f" by {excess[k, j]:.3g} (tolerance {self._margin[j]:.3g})" if self._margin[j] else ""
                raise LimitError(
                    f"{what} at t = {times[k]:.4g} s: joint {labels[j]} = {value} "
                    f"is beyond its {name} limit {limit}{allowed}"
                )

    def extrema(self) -> tuple[np.ndarray, np.ndarray]:
        """The values the limit check judges between key points, as it computes them.

        Each segment is a cubic in u; its extrema are the roots of the derivative quadratic
        qa u^2 + qb u + qc, found without cancellation: q = -(qb + sign(qb) sqrt(disc)) / 2,
        roots q / qa and qc / q. (The textbook (-qb + sqrt(disc)) / (2 qa) with a cutoff
        |qa| < 1e-14 for "linear" lost the root of a segment whose a3 was round-off of 4e-14:
        the spline 360, 128.5, 128.5, 360 dips to 70.6 and passed a lower limit of 75.)

        Returns:
          ((4 segments, m) values at each segment's start, end and derivative roots inside it
           (the start where there is none), in the joints' units; (4 segments, m) their
           times, s). Each column's numbers depend on that column's key points only.
        """
        a3, a2, a1 = self._coef_u[:, 0], self._coef_u[:, 1], self._coef_u[:, 2]
        candidates = [np.zeros_like(a3), np.ones_like(a3)]
        qa, qb, qc = 3.0 * a3, 2.0 * a2, a1
        disc = qb**2 - 4.0 * qa * qc
        with np.errstate(divide="ignore", invalid="ignore"):
            root = np.sqrt(np.where(disc >= 0, disc, np.nan))
            q = -0.5 * (qb + np.where(qb >= 0, 1.0, -1.0) * root)
            r1 = np.where(q != 0, q / qa, np.nan)  # inf/nan where qa == 0: no second root
            r2 = np.where(q != 0, qc / q, np.nan)  # q == 0: qb == qa qc == 0, roots at 0 only
        for r in (r1, r2):
            candidates.append(np.where(np.isfinite(r) & (r > 0) & (r < 1), r, 0.0))
        values, times = [], []
        for u in candidates:
            values.append(((a3 * u + a2) * u + a1) * u + self._coef_u[:, 3])  # (segments, m)
            times.append(self._t0 + (np.arange(a3.shape[0])[:, None] + u) * self._h)
        return np.concatenate(values), np.concatenate(times)

    def _check_overshoot(self):
        """Reject a spline that leaves the joint limits between key points (at ``extrema``)
        by more than ``limit_tolerance``."""
        if self._lower is None and self._upper is None:
            return
        values, times = self.extrema()
        for name, lim, sign in (("lower", self._lower, -1.0), ("upper", self._upper, 1.0)):
            if lim is None:
                continue
            excess = sign * (values - lim[None, :])
            bad = np.argwhere(excess > self._tolerance[None, :])
            if bad.size:
                k, j = bad[0]
                value, limit = _distinct(values[k, j], lim[j])
                what = (
                    f"tolerance {self._margin[j]:.3g} and the spline's round-off "
                    f"{self._tolerance[j] - self._margin[j]:.2g}"
                    if self._margin[j]
                    else f"round-off tolerance {self._tolerance[j]:.3g}"
                )
                raise LimitError(
                    f"spline between key points at t = {times[k, j]:.4g} s: joint "
                    f"{self._labels[j]} = {value} overshoots its {name} limit "
                    f"{limit} by {excess[k, j]:.3g} ({what})"
                )
