"""Rest-to-rest swing of a one-joint pendulum: the quintic blend s(tau) = 10 tau^3 - 15 tau^4
+ 6 tau^5 (tau = t / T), which starts and ends with zero velocity and acceleration.

Pure numpy; ``QuinticPlanner().plan(problem)`` returns a ``planbench.planners.trajectory.Trajectory``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from planbench.planners.trajectory import TrajectorySample, sample_times


@dataclass(frozen=True)
class SwingProblem:
    """Swing from ``start`` to ``goal`` (rad) in ``move_time`` (s); ``labels`` the channel."""

    start: float
    goal: float
    move_time: float
    labels: tuple = ("swing",)


@dataclass(frozen=True)
class QuinticSwing:
    """The planned swing of ``problem`` (a Trajectory): held at the goal after ``duration``."""

    problem: SwingProblem

    @property
    def duration(self) -> float:
        return float(self.problem.move_time)

    @property
    def labels(self) -> tuple:
        return tuple(self.problem.labels)

    def sample(self, t) -> TrajectorySample:
        t = sample_times(t)
        T, start = self.duration, float(self.problem.start)
        span = float(self.problem.goal) - start
        tau = np.clip(t / T, 0.0, 1.0)
        inside = (t > 0.0) & (t < T)
        s = tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2)
        ds = np.where(inside, 30.0 * tau**2 * (1.0 - tau) ** 2 / T, 0.0)
        dds = np.where(inside, 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau) / T**2, 0.0)

        def column(x):
            return np.asarray(x, dtype=float).reshape(-1, 1)

        return TrajectorySample(t, column(start + span * s), column(span * ds), column(span * dds))


class QuinticPlanner:
    """plan(problem) -> the quintic rest-to-rest swing of ``problem``."""

    def plan(self, problem: SwingProblem) -> QuinticSwing:
        return QuinticSwing(problem)
