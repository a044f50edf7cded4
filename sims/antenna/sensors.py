"""The ship antenna's sensors: ``AntennaImu``, the pedestal IMU (sampled, noisy, late, with the
plant's unknown bias) and the antenna's joint encoders.
"""

from __future__ import annotations

import dataclasses
import math
from collections import deque

import mujoco
import numpy as np

from planbench.antenna.params import AXIS_ENCODER, AntennaPlant, ImuModel, _exp_so3
from planbench.antenna.physics import AntennaPhysics
from planbench.task import JointEncoders, Sensors, SensorSpec


class AntennaImu(Sensors):
    """The antenna's sensors: the IMU on the pedestal base, and the antenna's encoders.

    The IMU is sampled every ``imu.ticks`` control ticks from MuJoCo's ``imu_quat`` and
    ``imu_gyro`` sensors; its attitude error is a first-order Gauss-Markov process, its gyro
    noise white (``ImuModel``); a sample reaches the controller ``latency`` ticks later (the
    newest that has arrived by a tick is the one it sees), the first one too: it is taken at
    t = 0 and arrives at t = latency (with no latency, at once). Until then ``imu_count`` is 0
    and the other IMU keys hold placeholders (identity, zeros) that describe no measurement.

    Each sample's time stamp is when MuJoCo's sensors saw the state it reports: a tick's
    ``imu_quat`` and ``imu_gyro`` after ``mj_step`` describe the start of the tick's last
    physics step, so the samples after t = 0 are stamped one physics step (1 ms) before their
    tick (0.019, 0.039, ... s at 50 Hz). The stamp is the sample's true time, not a clock's
    error; its age on arrival is the latency plus that step.

    ``errors`` (an ``AntennaPlant``; None: none) are the true IMU's errors that its datasheet
    (``imu``, the published SensorSpecs) does not state, so the controller does not know them:
    a constant attitude error B = exp([imu_bias]x) in the IMU frame (measured = true B, before
    the Gauss-Markov error).

    Observation keys:
      imu_attitude (3, 3): the measured deck attitude, world from IMU frame.
      imu_gyro (3,): the measured angular rate, rad/s, in the IMU frame.
      imu_time (1,): when that sample was taken, s (MuJoCo's sensors after a step describe
        the start of its last physics step).
      imu_count (1,): samples delivered so far (a new one arrived when it changes; 0 before
        the first arrives).
      joint_positions, joint_velocities, setpoints (4,): the antenna's encoders (exact) and
        its drives' set-points, rad and rad/s.
    """

    def __init__(self, physics: AntennaPhysics, imu: ImuModel, control_dt: float, errors: AntennaPlant | None = None):
        super().__init__()
        self.imu = imu
        self.dt = control_dt
        self.period, self.latency = imu.ticks(control_dt)
        # The true sensor's error (None: the datasheet's sensor): the attitude bias, a
        # rotation in the IMU frame.
        self.bias_rotation = None if errors is None else errors.bias_rotation()
        self.encoders = JointEncoders(
            physics.antenna_qpos,
            physics.antenna_dofs,
            physics.model.ptr.actuator_actadr[physics.antenna_actuators],
            "antenna joint encoders theta1 ... theta4",
            "rad",
            control_dt,
            resolution=AXIS_ENCODER if physics.drives == "as-built" else 0.0,
        )
        self.specs = [
            SensorSpec(
                "imu_attitude",
                "deck attitude of the pedestal IMU (world from IMU)",
                "rotation matrix",
                imu.rate_hz,
                imu.latency_s,
                f"Gauss-Markov, {imu.attitude_noise_deg:g} deg 1-sigma per axis, correlation time "
                f"{imu.attitude_noise_time_s:g} s",
            ),
            SensorSpec(
                "imu_gyro",
                "angular rate of the pedestal IMU, IMU frame",
                "rad/s",
                imu.rate_hz,
                imu.latency_s,
                f"white, {imu.gyro_noise_deg_s:g} deg/s 1-sigma per axis",
            ),
        ] + self.encoders.specs
        if errors is not None and any(errors.imu_bias):
            # summary.json says the sensor has an error; the controller is not told its value.
            self.specs[0] = dataclasses.replace(
                self.specs[0], bias="unknown constant attitude error (plant uncertainty)"
            )

    def reset(self, physics, times: np.ndarray, seed: int) -> dict:
        imu = self.imu
        self.rng = np.random.default_rng([seed, 0x1A7E])
        self.att_sigma = math.radians(imu.attitude_noise_deg)
        h, corr = self.period * self.dt, imu.attitude_noise_time_s
        self.att_decay = math.exp(-h / corr) if corr > 0 else 0.0
        self.att_error = self.rng.normal(0.0, self.att_sigma, 3)  # stationary start
        self.gyro_sigma = math.radians(imu.gyro_noise_deg_s)
        self.att_drive = self.att_sigma * math.sqrt(1.0 - self.att_decay**2)
        # The samples' noise for the whole run, drawn at once: the same standard normals in
        # the same order (per sample the attitude's drive, then the gyro's; the first sample
        # has no drive) and scaled as Generator.normal(0, sigma) scales them (0 + sigma z).
        self._noise_rows = 0
        self._draw_noise((times.size - 1) // self.period + 1)
        self.physics_dt = physics.model.ptr.opt.timestep
        self.quat_slice = physics.sensor_slice("imu_quat")
        self.gyro_slice = physics.sensor_slice("imu_gyro")
        self._data = physics.data.ptr
        self.queue = deque()
        obs = dict(self.encoders.reset(physics, times, seed))
        obs.update(imu_attitude=np.eye(3), imu_gyro=np.zeros(3), imu_time=np.zeros(1), imu_count=np.zeros(1, dtype=int))
        self.observation = obs
        self._measure(0, lag=0.0)  # mj_forward just evaluated the sensors at t = 0
        if self.queue[0][0] <= 0:  # no latency: it has arrived
            self._deliver(self.queue.popleft()[1])
        return obs

    def _draw_noise(self, samples: int) -> None:
        """Noise rows (attitude drive, gyro) for the next ``samples`` samples, drawn in order
        (when the rows of the last draw are used up)."""
        att, gyro = self.att_sigma > 0, self.gyro_sigma > 0
        noise = np.zeros((samples, 6))
        first = self._noise_rows == 0  # the sample at t = 0 has no drive
        self._noise_rows += samples
        if first and gyro:
            noise[0, 3:] = 0.0 + self.gyro_sigma * self.rng.standard_normal(3)
        rest = noise[1:] if first else noise
        width = 3 * (att + gyro)
        if width and rest.shape[0]:
            z = self.rng.standard_normal((rest.shape[0], width))  # row by row, as drawn per sample
            if att:
                rest[:, :3] = 0.0 + self.att_drive * z[:, :3]
            if gyro:
                rest[:, 3:] = 0.0 + self.gyro_sigma * z[:, width - 3 :]
        self._noise, self._next_noise = noise, 0

    def _measure(self, tick: int, lag: float | None = None) -> None:
        sd = self._data.sensordata
        rotation = np.empty(9)
        mujoco.mju_quat2Mat(rotation, sd[self.quat_slice])
        rotation = rotation.reshape(3, 3)
        if self.bias_rotation is not None:
            rotation = rotation @ self.bias_rotation
        if self._next_noise == self._noise.shape[0]:  # a longer run than reset prepared
            self._draw_noise(64)
        noise = self._noise[self._next_noise]
        self._next_noise += 1
        if self.att_sigma > 0:
            if tick > 0:
                self.att_error = self.att_decay * self.att_error + noise[:3]
            rotation = rotation @ _exp_so3(self.att_error)
        gyro = sd[self.gyro_slice].copy()
        if self.gyro_sigma > 0:
            gyro = gyro + noise[3:]
        # After mj_step the sensors hold the state at the start of its last physics step.
        lag = self.physics_dt if lag is None else lag
        self.queue.append((tick + self.latency, (tick * self.dt - lag, rotation, gyro)))

    def _deliver(self, sample) -> None:
        obs = self.observation
        obs["imu_time"][0], obs["imu_attitude"][:], obs["imu_gyro"][:] = sample
        obs["imu_count"][0] += 1

    def __call__(self, tick: int, physics) -> None:
        self.encoders(tick, physics)
        if tick > 0 and tick % self.period == 0:
            self._measure(tick)
        sample = None
        while self.queue and self.queue[0][0] <= tick:  # the newest sample that has arrived
            sample = self.queue.popleft()[1]
        if sample is not None:
            self._deliver(sample)
