"""Uniform cubic B-spline through key points, zero velocity at both ends.

This is the joint-space planner of the ammunition loading robot paper
(Li, Xu, Luo, "Trajectory Planning of Ammunition Loading Robot Based on Cubic-B Spline",
``shared/papers/loader-cubic-bspline.txt``), written from its definitions:

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
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
from scipy import linalg

from planners.errors import LimitError, PlanningError
from planners.trajectory import TrajectorySample

# Eq. (10): power-basis coefficients of the uniform cubic B-spline, rows for u^3, u^2, u, 1.
BASIS = np.array(
    [
        [-1.0, 3.0, -3.0, 1.0],
        [3.0, -6.0, 3.0, 0.0],
        [-3.0, 0.0, 3.0, 0.0],
        [1.0, 4.0, 1.0, 0.0],
    ]
) / 6.0

_UNIFORM_RTOL = 1e-9


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


class CubicBSplineTrajectory:
    """Joint trajectory through key points at uniform times (loader paper, eq. 1-10).

    Args:
      times: (n+1,) key times in s, strictly increasing and uniformly spaced.
      key_points: (n+1, m) joint values at those times, SI units (m or rad).
      labels: m joint names, used in error messages and outputs.
      lower, upper: optional (m,) joint limits. Key points outside them are rejected, and so
        is a spline that overshoots them between key points.

    Before ``times[0]`` and after ``times[-1]`` the trajectory holds its end points at rest.
    """

    def __init__(
        self,
        times: Sequence[float],
        key_points: np.ndarray,
        labels: Sequence[str] | None = None,
        lower: Sequence[float] | None = None,
        upper: Sequence[float] | None = None,
    ):
        times = np.asarray(times, dtype=float)
        key_points = np.asarray(key_points, dtype=float)
        if key_points.ndim == 1:
            key_points = key_points[:, None]
        if times.ndim != 1:
            raise PlanningError(f"key times must be a 1-D array, got shape {times.shape}")
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
        if not np.all(np.isfinite(times)):
            raise PlanningError(f"key times contain NaN or inf: {times.tolist()}")
        bad = np.argwhere(~np.isfinite(key_points))
        if bad.size:
            k, j = bad[0]
            raise PlanningError(f"key point {k} of joint {labels[j]} is {key_points[k, j]}")
        steps = np.diff(times)
        if np.any(steps <= 0):
            k = int(np.argmax(steps <= 0))
            raise PlanningError(
                f"key times must increase strictly: t[{k + 1}] = {times[k + 1]} s "
                f"<= t[{k}] = {times[k]} s"
            )
        h = (times[-1] - times[0]) / (times.size - 1)
        worst = int(np.argmax(np.abs(steps - h)))
        if abs(steps[worst] - h) > _UNIFORM_RTOL * h:
            raise PlanningError(
                f"key times must be uniformly spaced (the paper's uniform B-spline, eq. 6): "
                f"step {worst} is {steps[worst]} s, the mean step is {h} s"
            )
        self._lower = None if lower is None else np.asarray(lower, dtype=float)
        self._upper = None if upper is None else np.asarray(upper, dtype=float)
        for name, lim in (("lower", self._lower), ("upper", self._upper)):
            if lim is not None and lim.shape != (m,):
                raise PlanningError(f"{name} limits have shape {lim.shape}, expected ({m},)")
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

    def sample(self, t: np.ndarray | float) -> TrajectorySample:
        """Positions, velocities and accelerations at times ``t`` (s), vectorized (eq. 10)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
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
    def _check_limits(self, values, labels, times, what):
        for name, lim, breaks in (
            ("lower", self._lower, lambda v, l: v < l),
            ("upper", self._upper, lambda v, l: v > l),
        ):
            if lim is None:
                continue
            bad = np.argwhere(breaks(values, lim[None, :]))
            if bad.size:
                k, j = bad[0]
                raise LimitError(
                    f"{what} at t = {times[k]:.4g} s: joint {labels[j]} = {values[k, j]:.6g} "
                    f"is beyond its {name} limit {lim[j]:.6g}"
                )

    def _check_overshoot(self):
        """Reject a spline that leaves the joint limits between key points.

        Each segment is a cubic in u; its extrema are the roots of the derivative quadratic.
        """
        if self._lower is None and self._upper is None:
            return
        a3, a2, a1 = self._coef_u[:, 0], self._coef_u[:, 1], self._coef_u[:, 2]
        candidates = [np.zeros_like(a3), np.ones_like(a3)]
        qa, qb, qc = 3.0 * a3, 2.0 * a2, a1
        disc = qb**2 - 4.0 * qa * qc
        with np.errstate(divide="ignore", invalid="ignore"):
            root = np.sqrt(np.where(disc >= 0, disc, np.nan))
            linear = np.abs(qa) < 1e-14
            r1 = np.where(linear, -qc / qb, (-qb + root) / (2.0 * qa))
            r2 = np.where(linear, np.nan, (-qb - root) / (2.0 * qa))
        for r in (r1, r2):
            candidates.append(np.where(np.isfinite(r) & (r > 0) & (r < 1), r, 0.0))
        for u in candidates:
            values = ((a3 * u + a2) * u + a1) * u + self._coef_u[:, 3]  # (segments, m)
            times = self._t0 + (np.arange(values.shape[0])[:, None] + u) * self._h
            for name, lim, sign in (("lower", self._lower, -1.0), ("upper", self._upper, 1.0)):
                if lim is None:
                    continue
                bad = np.argwhere(sign * (values - lim[None, :]) > 0)
                if bad.size:
                    k, j = bad[0]
                    raise LimitError(
                        f"spline between key points at t = {times[k, j]:.4g} s: joint "
                        f"{self._labels[j]} = {values[k, j]:.6g} overshoots its {name} limit "
                        f"{lim[j]:.6g}"
                    )
