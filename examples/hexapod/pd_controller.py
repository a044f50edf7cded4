"""A user's controller for the hexapod: the strut drives' plain PD, no static feed-forward and
no integral action.

Run it:  planbench run hexapod-sync-move --controller examples/hexapod/pd_controller.py:PlainPD

The drives' set-point follows the planned strut positions. The 3 t camera's weight is then
held by the position error alone, kp (s - q) = F: each strut sags by F / kp below its plan.
The reference controller (planbench.hexapod.HexapodController) adds the static drive forces and an
integral action.
"""

from __future__ import annotations


class PlainPD:
    def reset(self, context) -> None:
        self.reference = context.reference.position  # (n, 6) strut length changes, m
        self.dt = context.control_dt
        self.command = context.command
        context.setpoint[:6] = self.reference[0]

    def __call__(self, tick: int, observation) -> None:
        target = self.reference[min(tick + 1, len(self.reference) - 1)]
        self.command[:6] = (target - observation["setpoints"]) / self.dt
