"""A user's planner for the hexapod: a jerk-limited synchronous move (a quintic in time).

Run it:  planbench run hexapod-sync-move --planner examples/hexapod/smooth_planner.py:QuinticMove

Every strut follows s(t) = d (10 u^3 - 15 u^4 + 6 u^5), u = t / T: zero velocity and
acceleration at both ends, so the jerk stays finite (the paper's generator steps its
acceleration). Its peaks are 15 d / (8 T) and 10 d / (sqrt(3) T^2); T is the shortest that
keeps every strut under the problem's v_max and a_max, rounded up to a whole tick, and the
same for all six (a synchronous move).
"""

from __future__ import annotations

import math

import numpy as np

from planbench.planners.hexapod import STRUT_LABELS, strut_positions
from planbench.planners.trajectory import TrajectorySample


class QuinticTrajectory:
    labels = STRUT_LABELS

    def __init__(self, start: np.ndarray, target: np.ndarray, duration: float):
        self.start, self.delta, self.duration = start, target - start, float(duration)

    def sample(self, t) -> TrajectorySample:
        t = np.atleast_1d(np.asarray(t, dtype=float))
        u = np.clip(t / self.duration, 0.0, 1.0)[:, None]
        T = self.duration
        position = self.start + self.delta * (10 * u**3 - 15 * u**4 + 6 * u**5)
        velocity = self.delta * (30 * u**2 - 60 * u**3 + 30 * u**4) / T
        acceleration = self.delta * (60 * u - 180 * u**2 + 120 * u**3) / T**2
        return TrajectorySample(t, position, velocity, acceleration)


class QuinticMove:
    def plan(self, problem) -> QuinticTrajectory:
        start = strut_positions(problem.start_pose, problem.geometry)
        target = strut_positions(problem.target_pose, problem.geometry)
        d = float(np.abs(target - start).max())
        limits = problem.limits
        shortest = max(15 * d / (8 * limits.strut_speed), math.sqrt(10 * d / (math.sqrt(3) * limits.strut_accel)))
        ticks = max(1, math.ceil(shortest / problem.dt - 1e-9))
        return QuinticTrajectory(start, target, ticks * problem.dt)
