"""A user's controller for the antenna: each IMU sample as it comes, no prediction and no rate
feed-forward.

Run it:  planbench run antenna-paper-motion --controller examples/antenna/hold_controller.py:SampleAndHold

On every new IMU sample (``imu_count`` changes) it forms the wanted attitude in the ship
frame, N = R^T eTs (paper, eq. 1), asks the planner (``context.planner``) for the joint angles
and ramps the drives' set-points to them over one IMU period. The sample is already
``latency`` old when it arrives and the ramp takes another period, so the antenna lags the
ship's motion; the reference controller predicts the attitude from the gyro instead.
"""

from __future__ import annotations

from planbench.planners.antenna import JOINT_LABELS


class SampleAndHold:
    def reset(self, context) -> None:
        self.planner = context.planner
        self.satellite = context.problem.satellite
        self.dt = context.control_dt
        imu = next(s for s in context.sensors if s.name == "imu_attitude")
        self.period = max(1, round(1.0 / (imu.rate_hz * self.dt)))  # ticks per IMU sample
        self.antenna = [context.actuators.index(name) for name in JOINT_LABELS]  # the four drives
        self.command = context.command
        self.target = context.observation["joint_positions"].copy()
        self.seen = 0  # imu_count: no sample has arrived yet

    def __call__(self, tick: int, observation) -> None:
        count = int(observation["imu_count"][0])
        if count != self.seen:
            self.seen = count
            attitude = observation["imu_attitude"].T @ self.satellite
            self.target = self.planner.step((tick + self.period) * self.dt, attitude)
        error = self.target - observation["setpoints"]
        self.command[self.antenna] = error / (self.period * self.dt)
