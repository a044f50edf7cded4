"""A user's planner for the loader: scipy's quintic interpolating spline through the key points.

Run it:  planbench run loader-supply --planner examples/loader/quintic_planner.py:QuinticPlanner

The paper joins Table 1's key points with a cubic B-spline; here scipy's
``make_interp_spline`` of degree 5 passes through the same points at the same times, with
zero velocity and acceleration at both ends.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import make_interp_spline

from planbench.planners.trajectory import TrajectorySample


class SplineTrajectory:
    """A scipy spline as a planbench Trajectory: at rest at its end after ``duration``."""

    def __init__(self, spline, labels, duration: float):
        self.spline = spline
        self.labels = tuple(labels)
        self.duration = float(duration)

    def sample(self, t) -> TrajectorySample:
        t = np.atleast_1d(np.asarray(t, dtype=float))
        tau = np.clip(t, 0.0, self.duration)
        moving = ((t >= 0.0) & (t <= self.duration))[:, None]
        return TrajectorySample(t, self.spline(tau), self.spline(tau, 1) * moving, self.spline(tau, 2) * moving)


class QuinticPlanner:
    """Degree-5 interpolation of ``problem.key_points`` at ``problem.key_times``."""

    def plan(self, problem) -> SplineTrajectory:
        zero = np.zeros(problem.key_points.shape[1])
        ends = [(1, zero), (2, zero)]
        spline = make_interp_spline(problem.key_times, problem.key_points, k=5, bc_type=(ends, ends))
        return SplineTrajectory(spline, problem.labels, problem.key_times[-1])
