"""A user's planner for the antenna: the paper's baseline of section 5.2, pseudo-inverse
integration, as an online planner.

Run it:  planbench run antenna-paper-motion --planner examples/antenna/pinv_planner.py:PinvIntegration

Per attitude sample N(t) it takes the antenna's angular velocity from the last sample (eq. 6)
and integrates the joint rates of the weighted pseudo-inverse (eq. 7) over the interval:
Theta <- Theta + J^+ omega dt. Nothing pulls Theta back onto f(Theta) = N, so the attitude
error of each step adds up: the drift that the paper's Figure 4 shows and that CRR removes.
"""

from __future__ import annotations

import numpy as np

from planbench.planners import antenna as ant


class PinvIntegration:
    def reset(self, problem) -> None:
        self.weights = problem.weights
        self.theta = np.array(problem.theta0, dtype=float)
        self.attitude = ant.forward_kinematics(self.theta)
        self.t = 0.0

    def step(self, t: float, attitude: np.ndarray) -> np.ndarray:
        self.theta, _ = ant.pinv_integration_step(self.theta, self.attitude, attitude, t - self.t, self.weights)
        self.attitude, self.t = attitude, t
        return self.theta
