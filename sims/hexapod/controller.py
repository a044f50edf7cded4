"""The hexapod's reference controller: the strut servo with static-load feed-forward and
integral action (``HexapodController``)."""

from __future__ import annotations

import numpy as np

from planbench.controllers import ServoFeedforwardController
from planbench.hexapod.physics import static_drive_forces

INTEGRAL_TIME_S = 0.1  # integral action's time constant; the lowest mode is ~12 Hz


class HexapodController(ServoFeedforwardController):
    """Strut servo: reference tracking with static-load feed-forward and integral action.

    ``planbench.controllers.ServoFeedforwardController`` (set-point interpolation, feed-forward in
    the set-point, integral action on the encoder error) with its feed-forward replaced:
    inverse dynamics does not apply to the closed loops, so f_ff is the set of drive forces
    that hold the payload in static equilibrium at the reference pose, what a real hexapod's
    gravity table supplies (``planbench.hexapod.physics.static_drive_forces``). The integral action takes what the
    model leaves out (wind, the constraint compliance, the payload's tiny inertial forces).
    Gains and force limits are read from the nominal model in ``reset``; the statics use the
    nominal model at the start pose (``ControlContext.nominal_physics``).

    Args:
      feedforward: include f_ff (False: PD + integral only).
      integral_time: T_i in s; None for no integral action.
    """

    def __init__(self, feedforward: bool = True, integral_time: float | None = INTEGRAL_TIME_S):
        super().__init__(None, None, feedforward, integral_time)

    @property
    def f_ff(self) -> np.ndarray:
        """(n, 6) the static drive forces along the reference, N (push positive)."""
        return self.tau_ff

    def feedforward_forces(self, context) -> np.ndarray:
        return static_drive_forces(context.nominal_physics(), context.reference.position)
