"""A user's controller for the loader: the drives' plain PD on the reference, no feed-forward.

Run it:  planbench run loader-supply --controller examples/loader/pd_controller.py:PlainPD

The loader's drives are position servos (MJCF ``general`` actuators with an integrator): the
command is the rate of the drive's set-point s, and the drive pushes kp (s - q) - kv qdot.
Holding s on the planned position q_ref makes that a PD on the tracking error, with nothing
for gravity or the arm's inertia; the reference controller adds both (inverse dynamics).
"""

from __future__ import annotations


class PlainPD:
    """Set-point = the planned joint positions, ramped over each tick."""

    def reset(self, context) -> None:
        self.reference = context.reference.position  # (n, 6) planned joints at every tick
        self.nu = self.reference.shape[1]
        self.dt = context.control_dt
        self.command = context.command
        context.setpoint[: self.nu] = self.reference[0]  # enable the drives at the start pose

    def __call__(self, tick: int, observation) -> None:
        target = self.reference[min(tick + 1, len(self.reference) - 1)]
        # ctrl is the set-point rate: reach the next tick's target by the end of this one.
        self.command[: self.nu] = (target - observation["setpoints"]) / self.dt


def make() -> PlainPD:
    return PlainPD()


if __name__ == "__main__":  # the same from Python
    from planbench import api

    result = api.run("loader-supply", controller=make())
    print("passed" if result.passed else "failed", {c.name: round(float(c.value), 4) for c in result.checks})
