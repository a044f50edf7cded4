"""The ship antenna's reference controller: ``AntennaController`` reads the IMU, predicts the deck
attitude over its latency, asks the online planner for the joint angles and ramps the servo
set-points to them with the servo's velocity feed-forward.
"""

from __future__ import annotations

import numpy as np

from planbench.antenna.params import JOINTS, _exp_so3
from planbench.planners import antenna as ant


class AntennaController:
    """Reads the IMU, asks the online planner for the joint solution, drives the antenna servos.

    On each IMU sample (a new ``imu_count``) the deck attitude is predicted to the next
    sample's arrival (``predict``: from the gyro rate and its change over the last sample,
    R(t) = R_m exp([w tau + a tau^2 / 2]x); without: the last sample is used as is), N = R^T eTs
    (eq. 1) and the planner (``ControlContext.planner``, the paper's CRR by default) gives the
    joint angles for that time. The set-points ramp to them linearly, plus kv/kp times the
    joint rates that hold the attitude against the (predicted) gyro rate, ramped between
    updates (the servo's velocity feed-forward), so the drive force is a PD on the error to the
    ramp. The IMU's rate and latency are the sensor's published ones (``ControlContext``'s
    sensor specs), as a real controller is configured with its IMU's datasheet.

    Args:
      predict: False to use each IMU sample as it is (its age becomes lag).
    """

    def __init__(self, predict: bool = True):
        self.predict = predict

    def reset(self, context) -> None:
        problem = context.problem
        self.planner = context.planner
        self.satellite = problem.satellite
        self.weights = problem.weights
        self.limits = problem.limits
        self.dt = context.control_dt
        imu = next(s for s in context.sensors if s.name == "imu_attitude")
        self.period = int(round(1.0 / (imu.rate_hz * self.dt)))
        self.latency = int(round(imu.latency_s / self.dt))
        model = context.model
        ids = np.array([model.actuator(n).id for n in JOINTS])
        self.actuators = np.array([context.actuators.index(n) for n in JOINTS])  # in the command
        kp = model.actuator_gainprm[ids, 0]
        kv = -model.actuator_biasprm[ids, 2]
        self.lead = kv / kp  # s: velocity feed-forward through the set-point
        obs = context.observation
        theta = obs["joint_positions"].copy()
        rate = obs["joint_velocities"].copy()
        # Until the first IMU sample arrives (at its latency), the joints go on at the rates
        # their encoders show at the start (the run starts in steady tracking).
        first = self.latency
        self.theta_from, self.theta_to = theta, theta + rate * first * self.dt
        self.ff_from, self.ff_to = rate, rate.copy()
        self.tick_from, self.tick_to = 0, first
        self._fractions = {}  # span -> (span + 1, 1) fractions of the ramp
        self._tables()
        self.last_gyro = None
        self.command = context.command
        # The command's channels in the controller's order: written in place when they are
        # the command itself, in order.
        self._in_place = bool(np.array_equal(self.actuators, np.arange(self.command.size)))
        self._difference = np.empty(len(JOINTS))
        self.seen = int(obs["imu_count"][0])
        if self.seen:  # no latency: the first sample is here, the first update is planned now
            self._update(0, obs)

    def _update(self, tick: int, obs) -> None:
        measured_t, rotation, gyro = float(obs["imu_time"][0]), obs["imu_attitude"], obs["imu_gyro"].copy()
        target_tick = tick + self.period
        rate = gyro
        if self.predict:
            tau = target_tick * self.dt - measured_t
            accel = np.zeros(3) if self.last_gyro is None else (gyro - self.last_gyro) / (self.period * self.dt)
            rotation = rotation @ _exp_so3(gyro * tau + 0.5 * accel * tau * tau)
            rate = gyro + accel * tau
        self.last_gyro = gyro
        attitude = rotation.T @ self.satellite
        theta = self.planner.step(target_tick * self.dt, attitude)
        # N = R^T eTs turns at -w_body in the ship frame: the joint rates that hold it, from
        # the gyro (its noise is far smaller than that of differenced attitudes); eq. (7/9)
        # for one pose in plain floats.
        feedforward = ant.joint_rates_scalar(theta, -rate, self.weights, self.limits)[0]
        self.theta_from, self.ff_from = self._ramp(tick), self._feedforward(tick)
        self.tick_from, self.tick_to = tick, target_tick
        self.theta_to, self.ff_to = theta, feedforward
        self._tables()

    def _tables(self) -> None:
        """The ramps at every tick from tick_from to tick_to (row k: tick_from + k; after
        tick_to they stay at the last row) and the set-point targets from them, computed
        once per update with the same arithmetic as a tick-by-tick evaluation."""
        span = self.tick_to - self.tick_from
        fraction = self._fractions.get(span)
        if fraction is None:  # the span is the IMU's period but for the first
            if span <= 0:
                fraction = np.ones((1, 1))
            else:
                fraction = np.minimum(np.maximum(np.arange(span + 1) / span, 0.0), 1.0)[:, None]
            self._fractions[span] = fraction
        self._ramps = self.theta_from + fraction * (self.theta_to - self.theta_from)
        self._feedforwards = self.ff_from + fraction * (self.ff_to - self.ff_from)
        self._targets = self._ramps + self.lead * self._feedforwards
        self._last_row = self._targets.shape[0] - 1

    def _row(self, tick: int) -> int:
        return min(max(tick - self.tick_from, 0), self._last_row)

    def _feedforward(self, tick: int) -> np.ndarray:
        return self._feedforwards[self._row(tick)]

    def _ramp(self, tick: int) -> np.ndarray:
        return self._ramps[self._row(tick)]

    def __call__(self, tick: int, observation) -> None:
        count = int(observation["imu_count"][0])
        if count != self.seen:
            self.seen = count
            self._update(tick, observation)
        # The set-point for the end of the tick: the ramp plus kv/kp times the feed-forward.
        target = self._targets[min(max(tick + 1 - self.tick_from, 0), self._last_row)]
        if self._in_place:
            np.divide(np.subtract(target, observation["setpoints"], out=self._difference), self.dt, out=self.command)
        else:
            self.command[self.actuators] = (target - observation["setpoints"]) / self.dt
