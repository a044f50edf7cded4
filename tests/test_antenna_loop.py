"""The antenna's control loop, computed ahead: the IMU's noise drawn once per run
(sims/antenna/sensors.py) and the controller's set-point ramps tabulated once per update
(sims/antenna/controller.py) give the very numbers of a sample-by-sample and tick-by-tick
evaluation (references kept here): whole runs are compared bit for bit."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from planbench import runner
from planbench.antenna import sensors as antenna_sensors
from planbench.antenna import task as antenna_task
from planbench.antenna.controller import AntennaController
from planbench.antenna.params import AntennaSeaParams, ImuModel, _exp_so3

LOGGED = ("qpos", "qvel", "act", "ctrl", "actuator_force", "sensordata")


class PerSampleImu(antenna_sensors.AntennaImu):
    """The IMU drawing each sample's noise when it is taken (Generator.normal per sample)."""

    def reset(self, physics, times, seed):
        self._reference_rng = None
        return super().reset(physics, times, seed)

    def _measure(self, tick, lag=None):
        if self._reference_rng is None:  # the stream from its start, as reset drew it
            self._reference_rng = np.random.default_rng([self._seed, 0x1A7E])
            self.att_error = self._reference_rng.normal(0.0, self.att_sigma, 3)
        rng = self._reference_rng
        sd = self._data.sensordata
        rotation = np.empty(9)
        antenna_sensors.mujoco.mju_quat2Mat(rotation, sd[self.quat_slice])
        rotation = rotation.reshape(3, 3)
        if self.bias_rotation is not None:
            rotation = rotation @ self.bias_rotation
        if self.att_sigma > 0:
            if tick > 0:
                drive = self.att_sigma * math.sqrt(1.0 - self.att_decay**2)
                self.att_error = self.att_decay * self.att_error + rng.normal(0.0, drive, 3)
            rotation = rotation @ _exp_so3(self.att_error)
        gyro = sd[self.gyro_slice].copy()
        if self.gyro_sigma > 0:
            gyro = gyro + rng.normal(0.0, self.gyro_sigma, 3)
        lag = self.physics_dt if lag is None else lag
        self.queue.append((tick + self.latency, (tick * self.dt - lag, rotation, gyro)))


class PerTickController(AntennaController):
    """The controller evaluating its ramps at every tick."""

    def _fraction(self, tick):
        span = self.tick_to - self.tick_from
        return 1.0 if span <= 0 else min(max((tick - self.tick_from) / span, 0.0), 1.0)

    def _feedforward(self, tick):
        return self.ff_from + self._fraction(tick) * (self.ff_to - self.ff_from)

    def _ramp(self, tick):
        return self.theta_from + self._fraction(tick) * (self.theta_to - self.theta_from)

    def __call__(self, tick, observation):
        count = int(observation["imu_count"][0])
        if count != self.seen:
            self.seen = count
            self._update(tick, observation)
        target = self._ramp(tick + 1) + self.lead * self._feedforward(tick + 1)
        self.command[self.actuators] = (target - observation["setpoints"]) / self.dt


def _run(imu: ImuModel, controller=None, duration: float = 1.5):
    params = AntennaSeaParams().replace(duration=duration)
    options = antenna_task.AntennaOptions(imu=imu)
    return runner.simulate(antenna_task.build(params, controller=controller, antenna_options=options))


IMUS = [
    ImuModel(),
    ImuModel(attitude_noise_deg=0.0),
    ImuModel(gyro_noise_deg_s=0.0),
    ImuModel(attitude_noise_deg=0.0, gyro_noise_deg_s=0.0),
    ImuModel(latency_s=0.0, rate_hz=100.0),
    ImuModel(attitude_noise_time_s=0.0),
]


@pytest.mark.parametrize(
    "imu",
    IMUS,
    ids=lambda m: (
        f"{m.rate_hz:g}Hz-{m.latency_s:g}s-{m.attitude_noise_deg:g}deg-"
        f"{m.attitude_noise_time_s:g}s-{m.gyro_noise_deg_s:g}dps"
    ),
)
def test_the_imu_noise_drawn_once_is_the_per_sample_noise(imu, monkeypatch):
    original_reset = antenna_sensors.AntennaImu.reset

    def reset(self, physics, times, seed):
        self._seed = seed
        return original_reset(self, physics, times, seed)

    monkeypatch.setattr(antenna_sensors.AntennaImu, "reset", reset)
    ahead = _run(imu)
    monkeypatch.setattr(antenna_task, "AntennaImu", PerSampleImu)
    per_sample = _run(imu)
    for name in LOGGED:
        np.testing.assert_array_equal(getattr(ahead, name), getattr(per_sample, name), err_msg=name)


def test_the_imu_draws_more_noise_when_a_run_outlasts_its_times():
    """A sensor stepped past the ticks it was reset for (an environment's longer episode)
    goes on with the same stream."""
    imu = ImuModel()
    params = AntennaSeaParams().replace(duration=1.0)
    setup = antenna_task.build(params, antenna_options=antenna_task.AntennaOptions(imu=imu))
    sensor = setup.task.sensors
    physics = setup.physics
    times = setup.task.times()
    sensor.reset(physics, times[:9], 7)
    rows = [sensor._noise[i].copy() for i in range(sensor._noise.shape[0])]
    for _ in range(3):
        sensor._next_noise = sensor._noise.shape[0]
        sensor._draw_noise(4)
        rows += [sensor._noise[i].copy() for i in range(4)]
    rng = np.random.default_rng([7, 0x1A7E])
    rng.normal(0.0, sensor.att_sigma, 3)
    for k, row in enumerate(rows):
        expected = np.zeros(6)
        if k > 0:
            expected[:3] = rng.normal(0.0, sensor.att_drive, 3)
        expected[3:] = rng.normal(0.0, sensor.gyro_sigma, 3)
        np.testing.assert_array_equal(row, expected, err_msg=f"sample {k}")


@pytest.mark.parametrize(
    "imu",
    [ImuModel(), ImuModel(latency_s=0.0, rate_hz=100.0), ImuModel(rate_hz=20.0)],
    ids=["default", "no-latency", "20Hz"],
)
def test_the_tabulated_ramps_are_the_per_tick_ramps(imu):
    tabulated = _run(imu, AntennaController())
    per_tick = _run(imu, PerTickController())
    for name in LOGGED:
        np.testing.assert_array_equal(getattr(tabulated, name), getattr(per_tick, name), err_msg=name)


def _exp_so3_by_norm(rotvec) -> np.ndarray:
    """The rotation of a rotation vector with its angle by np.linalg.norm (the earlier form)."""
    import mujoco

    angle = float(np.linalg.norm(rotvec))
    if angle < 1e-300:
        return np.eye(3)
    quat, mat = np.empty(4), np.empty(9)
    mujoco.mju_axisAngle2Quat(quat, rotvec / angle, angle)
    mujoco.mju_quat2Mat(mat, quat)
    return mat.reshape(3, 3)


@settings(max_examples=200, deadline=None)
@given(arrays(float, 3, elements=st.floats(-4.0, 4.0)), st.integers(-12, 0))
def test_the_rotation_of_a_rotation_vector_is_the_norm_form_s(rotvec, exponent):
    """_exp_so3's angle in floats against np.linalg.norm's, for small and large rotations: the
    same matrix to round-off (bit for bit where numpy sums the three squares in order), and
    a rotation (scipy's Rotation.from_rotvec)."""
    from scipy.spatial.transform import Rotation

    rotvec = rotvec * 10.0**exponent
    np.testing.assert_allclose(_exp_so3(rotvec), _exp_so3_by_norm(rotvec), rtol=0.0, atol=1e-15)
    np.testing.assert_allclose(_exp_so3(rotvec), Rotation.from_rotvec(rotvec).as_matrix(), rtol=0.0, atol=1e-14)
