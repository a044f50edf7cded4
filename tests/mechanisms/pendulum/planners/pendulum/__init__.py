"""Rest-to-rest swing of a one-joint pendulum: the quintic blend s(tau) = 10 tau^3 - 15 tau^4
+ 6 tau^5 (tau = t / T), which starts and ends with zero velocity and acceleration.

Pure numpy; ``QuinticPlanner().plan(problem)`` returns a ``planners.trajectory.Trajectory``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from planners.trajectory import TrajectorySample, sample_times


@dataclass(frozen=True)
class SwingProblem:
    """Swing from ``start`` to ``goal`` (rad) in ``move_time`` (s); ``labels`` the channel."""

    start: float
    goal: float
    move_time: float
    labels: tuple = ("swing",)


@dataclass(frozen=True)
class QuinticSwing:
    """The planned swing (a Trajectory): held at the goal after ``duration``."""

    start: float
    goal: float
    duration: float
    labels: tuple = ("swing",)

    def sample(self, t) -> TrajectorySample:
        t = sample_times(t)
        tau = np.clip(t / self.duration, 0.0, 1.0)
        inside = (t > 0.0) & (t < self.duration)
        span, T = self.goal - self.start, self.duration
        s = tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2)
        ds = np.where(inside, 30.0 * tau**2 * (1.0 - tau) ** 2 / T, 0.0)
        dds = np.where(inside, 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau) / T**2, 0.0)
        column = lambda x: np.asarray(x, dtype=float).reshape(-1, 1)
        return TrajectorySample(t, column(self.start + span * s), column(span * ds), column(span * dds))


class QuinticPlanner:
    """plan(problem) -> the quintic rest-to-rest swing of ``problem``."""

    def plan(self, problem: SwingProblem) -> QuinticSwing:
        return QuinticSwing(float(problem.start), float(problem.goal), float(problem.move_time), tuple(problem.labels))
