"""FAST's measurement system: inertial units, total stations and GPS/RTK fused by Kalman filters.

FAST measures the feed cabin and the Stewart platform by fusing a strapdown inertial system
(SINS), GPS/RTK and total stations with a Kalman filter (Li M.-H. et al., RAA 20, 140, 2020;
REFERENCE.md). Its fused errors are 14.56 mm and 0.095 deg RMS for the cabin and 2.99 mm and
0.093 deg for the Stewart platform. The total stations lag 150-240 ms and sample at about
8 Hz; the inertial part alone diverges. This module simulates such a system for the task (a
user's controller gets the same observation as ours):

* an IMU on the cabin and one on the feed platform, read every control tick: the specific
  force of the tick from the velocity increment of MuJoCo's ``velocimeter`` at the IMU's site
  (a strapdown unit integrates its accelerometers internally; fast.xml says why not a sampled
  ``accelerometer``) and the rate of its ``gyro`` (models/fast/fast.xml: ``cabin_imu_*``,
  ``platform_imu_*``), with white noise, a turn-on bias and a bias random walk of a
  tactical-grade fibre-optic SINS (``SensorOptions``; the telescope's own is not public);
* GPS/RTK antennas on the cabin roof (sites ``rtk1..3``) and total-station prisms on the feed
  platform (sites ``prism1..3``), each fix the three points' world positions with white noise
  and a slowly varying (first-order Gauss-Markov) error per coordinate: multipath for RTK,
  refraction for the total stations. The slow part is what no filter can remove, so it sets
  the fused error;
* per body, a Kalman filter at the control rate: the IMU propagates position, velocity and
  attitude (strapdown), every fix corrects them and the biases with the steady-state gains of
  the per-axis error model (``scipy.linalg.solve_discrete_are``), at the fix's own time: the
  correction is carried to the present through the error model's transition (exact for the
  linear filter), so a 200 ms old fix corrects without lag.

The defaults are set so that the estimates' errors against the truth match the published
fused ones, positions and attitudes (tests/test_fast_measurement.py measures them on 60 s
runs). The attitudes need an IMU whose accelerometers wander enough that gravity does not pin
the tilt, and fix errors that stay correlated for 15 s (models/fast/README.md).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from planbench.fast.physics import CONTROL_DT, PHYSICS_DT, FastPhysics, index_view, moment_sum
from planbench.logfile import temporary_writer
from planbench.params import ParamError, Params, param
from planbench.planners.rotations import skew
from planbench.task import Sensors, SensorSpec


@dataclass(frozen=True)
class SensorOptions(Params):
    """FAST's measurement system (the task's, not the controller's: a user's controller gets
    the same readings). Typed and ranged as the scenarios' parameters (planbench.params).

    ``system = "fused"`` (default): the measurement system of the module doc, whose defaults
    give the published fused errors (positions and attitudes). ``system = "ideal"``: the earlier, idealized pair of
    cabin-pose measurements (``IdealSensors``: ``pose_*`` and ``stewart_*``), kept to compare.
    """

    system: str = param(
        "fused",
        "the measurement system: fused (IMUs, total stations and GPS/RTK through Kalman "
        "filters, FAST's published errors) or ideal (the idealized cabin-pose measurements pose_* "
        "and stewart_*)",
        choices=("fused", "ideal"),
    )
    imu_gyro_noise: float = param(
        4.4e-5,
        "the SINS gyros' angle random walk, per axis (0.15 deg/sqrt(h), a "
        "tactical-grade fibre-optic gyro; FAST's own is not public: assumed, with the "
        "fix errors below, so that the fused attitudes are the published ones)",
        "rad/sqrt(s)",
        low=0.0,
        high=1e-3,
        reason="up to a consumer MEMS gyro's",
    )
    imu_gyro_bias: float = param(
        4.85e-6,
        "their turn-on bias, 1 sigma per axis (1 deg/h; assumed as above)",
        "rad/s",
        low=0.0,
        high=1e-3,
        reason="up to a consumer MEMS gyro's",
    )
    imu_gyro_bias_walk: float = param(
        1e-6, "their bias random walk (assumed)", "rad/s/sqrt(s)", low=0.0, high=1e-5, reason="an assumed bound"
    )
    imu_accel_noise: float = param(
        1e-3,
        "the SINS accelerometers' white noise density, per axis (100 ug/sqrt(Hz), tactical grade; assumed)",
        "m/s^2/sqrt(Hz)",
        low=0.0,
        high=0.1,
        reason="up to a consumer MEMS accelerometer's",
    )
    imu_accel_bias: float = param(
        1e-2,
        "their turn-on bias, 1 sigma per axis (1 mg; assumed)",
        "m/s^2",
        low=0.0,
        high=0.5,
        reason="up to a consumer MEMS accelerometer's",
    )
    imu_accel_bias_walk: float = param(
        1e-3,
        "their bias random walk (assumed: large enough that gravity does not pin "
        "the tilt, as FAST's 'the inertial part alone diverges')",
        "m/s^2/sqrt(s)",
        low=0.0,
        high=1e-2,
        reason="an assumed bound",
    )
    ts_rate_hz: float = param(
        8.0,
        "the total stations' fixes of the feed platform's three prisms",
        "Hz",
        low=0.1,
        high=1.0 / PHYSICS_DT,
        reason="a fix at least every 10 s, at most one per control "
        "tick (checked against control_rate_hz; about 8 Hz at 500 m: REFERENCE.md)",
    )
    ts_latency_s: float = param(
        0.2,
        "their latency (150-240 ms measured: REFERENCE.md)",
        "s",
        low=0.0,
        high=1.0,
        reason="the filter keeps a second of its past for late fixes",
    )
    ts_noise_m: float = param(
        1e-3,
        "their white noise per prism and coordinate, 1 sigma (about 2 mm uncertainty at 150-300 m: SPIE 6280)",
        "m",
        low=0.0,
        high=0.1,
        reason="an assumed bound",
    )
    ts_common_m: float = param(
        0.8e-3,
        "their slowly varying error common to the three prisms (refraction, the "
        "stations' orientation), 1 sigma per coordinate (set so that the fused platform "
        "error is the published 2.99 mm)",
        "m",
        low=0.0,
        high=0.1,
        reason="an assumed bound",
    )
    ts_point_m: float = param(
        2.2e-3,
        "their slowly varying error of each prism alone, 1 sigma per coordinate "
        "(set, with the SINS above, so that the fused platform attitude is the published "
        "0.093 deg)",
        "m",
        low=0.0,
        high=0.1,
        reason="an assumed bound",
    )
    ts_drift_time_s: float = param(
        15.0,
        "the correlation time of those slow errors (first-order Gauss-Markov; assumed)",
        "s",
        low=0.01,
        high=3600.0,
        reason="10 ms to an hour",
    )
    rtk_rate_hz: float = param(
        10.0,
        "GPS/RTK fixes of the cabin's three roof antennas (a common RTK output rate; assumed)",
        "Hz",
        low=0.1,
        high=1.0 / PHYSICS_DT,
        reason="a fix at least every 10 s, at most one per control tick (checked against control_rate_hz)",
    )
    rtk_latency_s: float = param(
        0.05,
        "their latency (assumed)",
        "s",
        low=0.0,
        high=1.0,
        reason="the filter keeps a second of its past for late fixes",
    )
    rtk_noise_m: float = param(
        5e-3,
        "their white noise per antenna and coordinate, 1 sigma (assumed)",
        "m",
        low=0.0,
        high=0.5,
        reason="an assumed bound",
    )
    rtk_common_m: float = param(
        6.5e-3,
        "their slowly varying error common to the three antennas (base station, "
        "atmosphere), 1 sigma per coordinate (set so that the fused cabin error is the "
        "published 14.56 mm)",
        "m",
        low=0.0,
        high=0.5,
        reason="an assumed bound",
    )
    rtk_point_m: float = param(
        8.5e-3,
        "their slowly varying error of each antenna alone (multipath), 1 sigma per "
        "coordinate (set, with the SINS above, so that the fused cabin attitude is the "
        "published 0.095 deg)",
        "m",
        low=0.0,
        high=0.5,
        reason="an assumed bound",
    )
    rtk_drift_time_s: float = param(
        15.0,
        "the correlation time of those slow errors (first-order Gauss-Markov; assumed)",
        "s",
        low=0.01,
        high=3600.0,
        reason="10 ms to an hour",
    )

    pose_rate_hz: float = param(
        10.0,
        "ideal system: rate of the cable loop's cabin pose fixes (total stations; 10 Hz assumed)",
        "Hz",
        low=0.1,
        high=1.0 / PHYSICS_DT,
        reason="a fix at least every 10 s (assumed), at most one per control tick (checked against control_rate_hz)",
    )
    pose_latency_s: float = param(
        0.15,
        "their latency (150 ms, the low end measured)",
        "s",
        low=0.0,
        high=10.0,
        reason="total stations lag 150-240 ms (REFERENCE.md); 10 s is an assumed bound",
    )
    pose_noise_m: float = param(
        1e-3,
        "their white position noise per axis, 1 sigma (assumed: a total station's class at 150-300 m)",
        "m",
        low=0.0,
        high=1.0,
        reason="an assumed bound",
    )
    pose_noise_rad: float = param(
        20e-6,
        "their white attitude noise per axis, 1 sigma (assumed)",
        "rad",
        low=0.0,
        high=0.1,
        reason="an assumed bound",
    )
    stewart_latency_s: float = param(
        0.01,
        "ideal system: latency of the 100 Hz pose measurement the stabilizer corrects with (assumed: IMU-aided)",
        "s",
        low=0.0,
        high=10.0,
        reason="an assumed bound",
    )
    stewart_noise_m: float = param(
        0.5e-3,
        "its white position noise per axis, 1 sigma (assumed)",
        "m",
        low=0.0,
        high=1.0,
        reason="an assumed bound",
    )
    stewart_noise_rad: float = param(
        10e-6,
        "its white attitude noise per axis, 1 sigma (assumed)",
        "rad",
        low=0.0,
        high=0.1,
        reason="an assumed bound",
    )

    def check_rates(self, control_rate_hz: float) -> None:
        """A ParamError naming the first fix rate of this system above the control rate (a
        fix needs a tick of its own)."""
        names = ("rtk_rate_hz", "ts_rate_hz") if self.system == "fused" else ("pose_rate_hz",)
        for name in names:
            if getattr(self, name) > control_rate_hz * (1.0 + 1e-9):
                raise ParamError(
                    f"sensors.{name} = {getattr(self, name):g} Hz is above the control rate "
                    f"control_rate_hz = {control_rate_hz:g} Hz: at most one fix per tick"
                )


def encoder_specs(rate_hz: float) -> list[SensorSpec]:
    """The encoders both measurement systems read every tick, exactly."""
    return [
        SensorSpec("ab_angles", "A-B rotator encoders (and the rotation they give)", "rad", rate_hz),
        SensorSpec("leg_positions", "Stewart leg encoders (length change from nominal)", "m", rate_hz),
        SensorSpec("leg_setpoints", "Stewart leg drives' set-points", "m", rate_hz),
    ]


class Encoders:
    """The encoders' readings (``encoder_specs``) in an observation every tick: the A-B angles
    and the B frame's rotation in the cabin frame that they give, the legs' lengths and
    set-points. Exact readings whose indices step evenly (``index_view``) are read-only views
    of the live buffers, put in ``obs`` (no cost per tick, as ``planbench.task.JointEncoders``');
    the others are copied every tick."""

    def __init__(self, physics, obs: dict):
        data = self._data = physics.data.ptr
        reads = []
        for key, buffer, ids in (
            ("ab_angles", "qpos", physics.ab_qpos),
            ("leg_positions", "qpos", physics.leg_qpos),
            ("leg_setpoints", "act", physics.leg_act),
        ):
            index = index_view(ids)
            if isinstance(index, slice):
                view = getattr(data, buffer)[index]
                view.flags.writeable = False
                obs[key] = view
            else:
                reads.append((obs[key], buffer, index))
        self._reads = tuple(reads)
        # The B frame in the cabin frame, R_cabin^T R_B, from views of the live rotations.
        self._ab_rotation_of = (
            data.xmat[physics.cabin_body].reshape(3, 3).T,
            data.xmat[physics.ab_b_body].reshape(3, 3),
            obs["ab_rotation"],
        )

    def __call__(self) -> None:
        data = self._data
        for out, buffer, index in self._reads:
            out[:] = getattr(data, buffer)[index]
        cabin_transposed, ab_b, out = self._ab_rotation_of
        np.matmul(cabin_transposed, ab_b, out=out)


class IdealSensors(Sensors):
    """The idealized sensors (``SensorOptions(system="ideal")``): two measurements of the cabin
    pose, and encoders.

    The true cabin pose is recorded every tick; a measurement reports the pose of ``latency``
    ticks ago with its own white noise (position, and a small rotation I + [w]x), seeded from
    the run's seed.

    Observation keys:
      cabin_pose_ts_position (3,) m, cabin_pose_ts_rotation (3, 3), cabin_pose_ts_time (1,) s,
        cabin_pose_ts_count (1,): the total stations' fix (every 1 / pose_rate_hz, a new one
        when the count changes), for the cable loop.
      cabin_pose_position (3,), cabin_pose_rotation (3, 3), cabin_pose_time (1,): the
        every-tick measurement (IMU-aided), for the stabilizer.
      ab_angles (2,) rad and ab_rotation (3, 3): the A-B rotator's encoders and the B frame's
        orientation in the cabin frame that they give (exact).
      leg_positions (6,) m and leg_setpoints (6,) m: the Stewart legs' encoders (exact) and
        their drives' set-points.
    """

    def __init__(self, physics: FastPhysics, options: SensorOptions = SensorOptions(), control_dt: float = CONTROL_DT):
        super().__init__()
        o = self.options = options
        self.dt = control_dt
        self.every = _ticks(1.0 / o.pose_rate_hz, control_dt, 1)
        self.pose_lag = _latency_ticks(o.pose_latency_s, control_dt)
        self.stewart_lag = _latency_ticks(o.stewart_latency_s, control_dt)
        rate = 1.0 / control_dt
        # The rates and latencies as simulated: whole numbers of ticks (as FusedSensors').
        self.specs = [
            SensorSpec(
                "cabin_pose_ts",
                "cabin pose by the total stations (position and attitude)",
                "m|rad",
                rate / self.every,
                self.pose_lag * control_dt,
                f"white, {1e3 * o.pose_noise_m:g} mm and {1e6 * o.pose_noise_rad:g} urad 1-sigma per axis",
            ),
            SensorSpec(
                "cabin_pose",
                "cabin pose for the stabilizer (IMU-aided)",
                "m|rad",
                rate,
                self.stewart_lag * control_dt,
                f"white, {1e3 * o.stewart_noise_m:g} mm and {1e6 * o.stewart_noise_rad:g} urad 1-sigma per axis",
            ),
            *encoder_specs(rate),
        ]

    def reset(self, physics, times: np.ndarray, seed: int) -> dict:
        o = self.options
        n = times.size
        self._data = physics.data.ptr
        self._cabin = physics.cabin_body
        rng = np.random.default_rng([seed, 0xFA57])
        self.true_pos = np.empty((n, 3))
        self.true_rot = np.empty((n, 3, 3))
        # Noise of each measurement: position (n, 3) and a small rotation I + [w]x (n, 3, 3).
        self.pose_noise = (
            rng.normal(0.0, o.pose_noise_m, (n, 3)),
            np.eye(3) + skew(rng.normal(0.0, o.pose_noise_rad, (n, 3))),
        )
        self.stewart_noise = (
            rng.normal(0.0, o.stewart_noise_m, (n, 3)),
            np.eye(3) + skew(rng.normal(0.0, o.stewart_noise_rad, (n, 3))),
        )
        self.observation = obs = {
            "cabin_pose_ts_position": np.zeros(3),
            "cabin_pose_ts_rotation": np.eye(3),
            "cabin_pose_ts_time": np.zeros(1),
            "cabin_pose_ts_count": np.zeros(1, dtype=int),
            "cabin_pose_position": np.zeros(3),
            "cabin_pose_rotation": np.eye(3),
            "cabin_pose_time": np.zeros(1),
            "ab_angles": np.zeros(2),
            "ab_rotation": np.eye(3),
            "leg_positions": np.zeros(6),
            "leg_setpoints": np.zeros(6),
        }
        self._encoders = Encoders(physics, obs)
        self(0, physics)
        return obs

    def _measured(self, tick: int, lag: int, noise, position: np.ndarray, rotation: np.ndarray) -> int:
        j = max(0, tick - lag)
        np.add(self.true_pos[j], noise[0][j], out=position)
        np.matmul(noise[1][j], self.true_rot[j], out=rotation)
        return j

    def __call__(self, tick: int, physics) -> None:
        data, obs = self._data, self.observation
        self.true_pos[tick] = data.xpos[self._cabin]
        cabin = data.xmat[self._cabin].reshape(3, 3)
        self.true_rot[tick] = cabin
        if tick % self.every == 0:
            j = self._measured(
                tick, self.pose_lag, self.pose_noise, obs["cabin_pose_ts_position"], obs["cabin_pose_ts_rotation"]
            )
            obs["cabin_pose_ts_time"][0] = j * self.dt
            obs["cabin_pose_ts_count"][0] += 1
        j = self._measured(
            tick, self.stewart_lag, self.stewart_noise, obs["cabin_pose_position"], obs["cabin_pose_rotation"]
        )
        obs["cabin_pose_time"][0] = j * self.dt
        self._encoders()


#: The Kalman filters' error state (true less estimated), world frame: position, velocity,
#: accelerometer bias, attitude (the small rotation from the estimate to the truth) and gyro
#: bias, 3 each. The biases are estimated in the world frame, which the slow tilts of the
#: cabin (14 deg over minutes) make a good approximation; they are carried to the IMU's frame
#: when applied. The specific force is about g up (the feed support's accelerations are
#: millimetres per second squared), so an attitude error theta turns into an acceleration
#: error theta x (0, 0, g): the model couples each horizontal position with its tilt, and
#: the filter has one steady state (the model is time-invariant).
P, V, BA, TH, BG = (slice(3 * k, 3 * k + 3) for k in range(5))


def error_model(dt: float, gravity: float):
    """(Phi (15, 15), G (15, 6)) of the error state per tick: x' = Phi x + G w, w the
    accelerometers' and the gyros' white noise per tick (3 each)."""
    phi = np.eye(15)
    up = np.array([0.0, 0.0, gravity])
    tilt = -skew(up)  # theta x up = -[up]x theta
    phi[P, V] = dt * np.eye(3)
    phi[P, BA] = -0.5 * dt * dt * np.eye(3)
    phi[P, TH] = 0.5 * dt * dt * tilt
    phi[V, BA] = -dt * np.eye(3)
    phi[V, TH] = dt * tilt
    phi[TH, BG] = -dt * np.eye(3)
    g = np.zeros((15, 6))
    g[P, :3] = 0.5 * dt * dt * np.eye(3)
    g[V, :3] = dt * np.eye(3)
    g[TH, 3:] = dt * np.eye(3)
    return phi, g


#: The filters' variances are at least this (m^2, rad^2, ...), so that an ideal sensor (a zero
#: noise) still gives a well-posed Riccati equation.
VARIANCE_FLOOR = 1e-18


def steady_state_gain(
    phi: np.ndarray, g: np.ndarray, white: np.ndarray, walk: np.ndarray, every: int, measurement_var: np.ndarray
) -> np.ndarray:
    """The steady-state Kalman gain (15, 6) of the error model (``error_model``) measured in
    position and attitude every ``every`` ticks.

    ``white`` (6,): 1 sigma per tick of the accelerometers' and gyros' white noise; ``walk``
    (6,): of their biases' random walk per tick; ``measurement_var`` (6,): the fix's variance
    of position and attitude per axis. The fix-to-fix model is Phi^m with the process noise
    summed over the m ticks; the a-priori covariance P solves the discrete algebraic Riccati
    equation (scipy.linalg.solve_discrete_are), and K = P H^T (H P H^T + R)^-1.
    """
    q = g @ np.diag(np.square(white)) @ g.T + VARIANCE_FLOOR * np.eye(15)
    q[BA, BA] += np.diag(np.square(walk[:3]))
    q[BG, BG] += np.diag(np.square(walk[3:]))
    phi_m, q_m = np.eye(15), np.zeros((15, 15))
    for _ in range(every):
        q_m = phi @ q_m @ phi.T + q
        phi_m = phi @ phi_m
    h = np.zeros((6, 15))
    h[:3, P] = np.eye(3)
    h[3:, TH] = np.eye(3)
    r = np.diag(np.maximum(measurement_var, VARIANCE_FLOOR))
    p = scipy.linalg.solve_discrete_are(phi_m.T, h.T, q_m, r)
    return p @ h.T @ np.linalg.inv(h @ p @ h.T + r)


class ImuErrors:
    """The two IMUs' errors at each of a run's ``n`` ticks, (2, 3) a tick: white noise
    (``white`` 1 sigma), plus a turn-on bias (``bias``), plus a random walk (steps of ``walk``
    1 sigma), drawn from ``rng`` as ``normal(0, white, (n, 2, 3)) + normal(0, bias, (1, 2, 3))
    + cumsum(normal(0, walk, (n, 2, 3)), axis=0)`` draws them (the same numbers, ``rng`` left
    where those draws leave it), made IMU_BLOCK_TICKS ticks at a time as the ticks are read in
    order (``errors[tick]``): a run holds one block, whatever its length."""

    def __init__(self, rng: np.random.Generator, n: int, white: float, bias: float, walk: float):
        self.n, self.white, self.walk = n, white, walk
        self._white_rng = self._skip(rng, n, white)  # a copy at the white noise's first draw
        self.bias = rng.normal(0.0, bias, (1, 2, 3))
        self._walk_rng = self._skip(rng, n, walk)
        self._walk_sum = np.zeros((1, 2, 3))  # the walk at the last tick made
        self.start, self._rows = 0, np.zeros((0, 2, 3))

    @staticmethod
    def _skip(rng: np.random.Generator, n: int, sigma: float) -> np.random.Generator:
        """A copy of ``rng`` as it is, and ``rng`` moved past n ticks' draws (a block at a time)."""
        copy = np.random.Generator(type(rng.bit_generator)())
        copy.bit_generator.state = rng.bit_generator.state
        for start in range(0, n, IMU_BLOCK_TICKS):
            rng.normal(0.0, sigma, (min(IMU_BLOCK_TICKS, n - start), 2, 3))
        return copy

    def __getitem__(self, tick: int) -> np.ndarray:
        row = tick - self.start
        if row < 0 or row >= self._rows.shape[0]:
            self._advance(tick)
            row = tick - self.start
        return self._rows[row]

    def _advance(self, tick: int) -> None:
        end = self.start + self._rows.shape[0]
        if not end <= tick < self.n:
            raise IndexError(f"IMU errors are made in tick order: tick {tick} after ticks up to {end - 1} of {self.n}")
        while True:  # (ticks skipped are made and dropped: the draws stay in order)
            m = min(IMU_BLOCK_TICKS, self.n - end)
            steps = self._walk_rng.normal(0.0, self.walk, (m, 2, 3))
            walk = np.cumsum(np.concatenate([self._walk_sum, steps]), axis=0)[1:]
            self._walk_sum = walk[-1:]
            self._rows = (self._white_rng.normal(0.0, self.white, (m, 2, 3)) + self.bias) + walk
            self.start, end = end, end + m
            if tick < end:
                return


#: Ticks of IMU errors made at a time (ImuErrors).
IMU_BLOCK_TICKS = 4096


def gauss_markov(rng: np.random.Generator, shape: tuple, sigma: float, correlation_s: float, dt: float) -> np.ndarray:
    """A first-order Gauss-Markov process along axis 0 (stationary, ``sigma`` 1 sigma, time
    constant ``correlation_s``) sampled every ``dt`` s: e_k+1 = phi e_k + sqrt(1 - phi^2)
    sigma n_k (scipy.signal.lfilter), started in its stationary distribution."""
    n = rng.standard_normal(shape)
    if sigma == 0.0:
        return np.zeros(shape)
    phi = math.exp(-dt / correlation_s)
    n[1:] *= math.sqrt(1.0 - phi * phi)
    import scipy.signal  # (here: importing it costs every command line ~0.4 s, scipy.stats included)

    return sigma * scipy.signal.lfilter([1.0], [1.0, -phi], n, axis=0)


def inverse_point_inertia(points: np.ndarray) -> np.ndarray:
    """(sum |q|^2 I - q q^T)^-1 (3, 3) of ``points`` (k, 3), q about their centroid: the
    normal matrix of a small rotation fitted to them (``small_rotation_fit``)."""
    q = points - points.mean(axis=0)
    return np.linalg.inv(np.einsum("ki,ki->", q, q) * np.eye(3) - q.T @ q)


def point_pose_noise(points: np.ndarray, sigma: float) -> float:
    """1 sigma per axis of the attitude that the least-squares fit of ``points`` (k, 3) (body
    frame) gives when each coordinate has ``sigma`` of white noise: sqrt of the largest
    eigenvalue of sigma^2 ``inverse_point_inertia`` (the tilt axes for points in a plane)."""
    return float(sigma * math.sqrt(np.linalg.eigvalsh(inverse_point_inertia(points)).max()))


def _as_array(name: str, doc: str, shape: tuple = (3,)) -> property:
    """A read-only property: the per-body float lists ``name`` as an array (B, *shape)."""
    return property(lambda self: np.array(getattr(self, name)).reshape(-1, *shape), doc=doc)


class FusedPoses:
    """Kalman filters of several bodies' poses (one each, batched), IMU-propagated and
    corrected by delayed point fixes.

    Args:
      points: per body, (k, 3) its fix's points in its frame, m.
      imu_offsets: per body, (3,) the IMU's position in its frame (the IMU's frame is the
        body's), m.
      noises: per body, its filter's noise model: accel_white, accel_walk, gyro_white,
        gyro_walk (per tick), every (ticks between fixes), fix_white and fix_drift (1 sigma
        per point and coordinate, m; the drift is common to the points).
      dt: the control tick, s; gravity: (3,) m/s^2; history: ticks of state kept for late fixes.
    """

    def __init__(self, points, imu_offsets, noises, dt: float, gravity: np.ndarray, history: int):
        self.points = [np.asarray(p, float) for p in points]
        self.centroids = [p.mean(axis=0) for p in self.points]
        self.imu_offsets = np.array(imu_offsets, float)
        self.dt, self.gravity = dt, np.asarray(gravity, float)
        self.history = history
        phi, g = error_model(dt, float(np.linalg.norm(self.gravity)))
        self.gains, self._inverse_inertia = [], []
        for pts, noise in zip(self.points, noises, strict=True):
            position_var = noise["fix_white"] ** 2 / len(pts) + noise["fix_drift"] ** 2
            attitude_var = point_pose_noise(pts, noise["fix_white"]) ** 2
            self.gains.append(
                steady_state_gain(
                    phi,
                    g,
                    np.repeat([noise["accel_white"], noise["gyro_white"]], 3),
                    np.repeat([noise["accel_walk"], noise["gyro_walk"]], 3),
                    noise["every"],
                    np.repeat([position_var, attitude_var], 3),
                )
            )
            self._inverse_inertia.append(inverse_point_inertia(pts))
        # Per body, its points and its IMU about their centroid, body frame (per fix, else).
        self._local_points = [p - c for p, c in zip(self.points, self.centroids, strict=True)]
        self._local_imu = [o - c for o, c in zip(self.imu_offsets, self.centroids, strict=True)]
        # Phi^k for k = 0 .. history - 1, to carry a correction at a past tick to the present.
        powers = [np.eye(15)]
        for _ in range(history - 1):
            powers.append(phi @ powers[-1])
        self._powers = np.stack(powers)
        # Per body, Phi^k K (history, 15, 6): a fix's innovation to the correction k ticks
        # after it, in one product; and the fix's constants as Python floats (``correct``).
        self._carry = [self._powers @ gain for gain in self.gains]
        self._fit_constants = [
            (q.tolist(), j.ravel().tolist(), o.tolist())
            for q, j, o in zip(self._local_points, self._inverse_inertia, self._local_imu, strict=True)
        ]

    def reset(self, positions, rotations) -> None:
        """Start every body at a known pose (the operator's survey of the parked machine),
        at rest: ``positions`` (B, 3), ``rotations`` (B, 3, 3) of the bodies' frames."""
        rotation = np.array(rotations, float)
        position = np.array(positions, float) + np.einsum("bij,bj->bi", rotation, self.imu_offsets)
        # The state per body in Python floats (the IMU's position and velocity, world; its
        # rotation's rows, 9; the biases, IMU frame): the tick's arithmetic on them costs a
        # fraction of numpy's calls on (B, 3) arrays (``propagate``).
        self._position = position.tolist()
        self._velocity = np.zeros_like(position).tolist()
        self._rotation = rotation.reshape(-1, 9).tolist()
        self._accel_bias = np.zeros_like(position).tolist()
        self._gyro_bias = np.zeros_like(position).tolist()
        self._gravity = self.gravity.tolist()
        self._offsets = self.imu_offsets.tolist()
        # Per body, the estimates at the ticks of the fixes still on their way: (tick,
        # position, velocity, rotation), oldest first.
        self._samples = [deque() for _ in self.points]
        self.tick = 0

    # The estimates as arrays, from the per-body lists the filters keep (module doc).
    position = _as_array("_position", "(B, 3) the IMUs' estimated positions, world, m.")
    velocity = _as_array("_velocity", "(B, 3) their velocities, world, m/s.")
    rotation = _as_array("_rotation", "(B, 3, 3) the bodies' estimated rotations, world.", (3, 3))
    accel_bias = _as_array("_accel_bias", "(B, 3) the accelerometers' estimated biases, IMU frame, m/s^2.")
    gyro_bias = _as_array("_gyro_bias", "(B, 3) the gyros' estimated biases, IMU frame, rad/s.")

    def propagate(self, specific_force, rate) -> None:
        """One tick of strapdown navigation of every body from its IMU's readings (B, 3), its
        frame, of the tick that ends: attitude by the rate (first order; re-orthonormalized at
        each fix), acceleration = R (f - b_a) + g.

        In Python floats (a fraction of numpy's cost on (B, 3) arrays), each element's
        arithmetic that of the vectorized form, R (f - b_a) by einsum and R - R_ik eps_kjl w_l
        dt (tests/test_fast_measurement.py compares them): R v sums its products as numpy's
        einsum does for (B, 3, 3) by (B, 3), (R_i0 v_0 + R_i2 v_2) + R_i1 v_1,
        and each element of R [w dt]x is a difference of two products."""
        if isinstance(specific_force, np.ndarray):
            specific_force = specific_force.tolist()
        if isinstance(rate, np.ndarray):
            rate = rate.tolist()
        dt = self.dt
        half = 0.5 * dt
        gx, gy, gz = self._gravity
        positions, velocities, rotations = self._position, self._velocity, self._rotation
        for b, ((fx, fy, fz), (cx, cy, cz), (wx, wy, wz), (bx, by, bz)) in enumerate(
            zip(specific_force, self._accel_bias, rate, self._gyro_bias, strict=True)
        ):
            r0, r1, r2, r3, r4, r5, r6, r7, r8 = rotations[b]
            ux, uy, uz = fx - cx, fy - cy, fz - cz
            ax = (r0 * ux + r2 * uz) + r1 * uy + gx
            ay = (r3 * ux + r5 * uz) + r4 * uy + gy
            az = (r6 * ux + r8 * uz) + r7 * uy + gz
            px, py, pz = positions[b]
            vx, vy, vz = velocities[b]
            positions[b] = [px + (vx + half * ax) * dt, py + (vy + half * ay) * dt, pz + (vz + half * az) * dt]
            velocities[b] = [vx + ax * dt, vy + ay * dt, vz + az * dt]
            w0, w1, w2 = (wx - bx) * dt, (wy - by) * dt, (wz - bz) * dt
            rotations[b] = [
                r0 - (r2 * w1 - r1 * w2),
                r1 - (r0 * w2 - r2 * w0),
                r2 - (r1 * w0 - r0 * w1),
                r3 - (r5 * w1 - r4 * w2),
                r4 - (r3 * w2 - r5 * w0),
                r5 - (r4 * w0 - r3 * w1),
                r6 - (r8 * w1 - r7 * w2),
                r7 - (r6 * w2 - r8 * w0),
                r8 - (r7 * w0 - r6 * w1),
            ]
        self.tick += 1

    def sample(self, body: int) -> None:
        """Keep ``body``'s estimate of the present tick: a fix taken now will be compared with it."""
        self._samples[body].append((self.tick, list(self._position[body]), list(self._rotation[body])))

    def correct(self, body: int, measured_points: np.ndarray, at_tick: int) -> None:
        """A fix of body ``body``'s points (k, 3) world, m, taken at tick ``at_tick`` (at most
        ``history - 1`` ticks ago, where ``sample`` kept the estimate): the innovation against
        that estimate (position of the IMU and the small rotation theta that best turns the
        predicted points onto the measured ones), the steady-state correction carried to the
        estimates kept for later fixes and to the present (x_k = Phi^k K y, exact for the
        linear error model).

        The fit in Python floats (a fraction of numpy's calls on 3-vectors): theta =
        R J R^T sum p x (m - c - p), p = R q the predicted points about their centroid, c the
        measured centroid, J the points' inverse inertia (``small_rotation_fit``'s normal
        equations); tests/test_fast_tick.py compares it with the vectorized form."""
        age = self.tick - at_tick
        if not 0 <= age < self.history:
            raise ValueError(f"a fix {age} ticks old: the filter keeps {self.history}")
        samples = self._samples[body]
        sampled, (sx, sy, sz), rotation = samples.popleft()
        if sampled != at_tick:  # fixes arrive in the order they were taken, each sampled once
            raise ValueError(f"a fix of tick {at_tick} where the filter kept tick {sampled}")
        local, inverse_inertia, (ox, oy, oz) = self._fit_constants[body]
        r0, r1, r2, r3, r4, r5, r6, r7, r8 = rotation
        measured = measured_points.tolist()
        cx = cy = cz = 0.0
        for mx, my, mz in measured:
            cx, cy, cz = cx + mx, cy + my, cz + mz
        count = len(measured)
        cx, cy, cz = cx / count, cy / count, cz / count
        ux = uy = uz = 0.0
        for (mx, my, mz), (qx, qy, qz) in zip(measured, local, strict=True):
            px, py, pz = r0 * qx + r1 * qy + r2 * qz, r3 * qx + r4 * qy + r5 * qz, r6 * qx + r7 * qy + r8 * qz
            dx, dy, dz = mx - cx - px, my - cy - py, mz - cz - pz
            ux, uy, uz = ux + (py * dz - pz * dy), uy + (pz * dx - px * dz), uz + (px * dy - py * dx)
        ux, uy, uz = r0 * ux + r3 * uy + r6 * uz, r1 * ux + r4 * uy + r7 * uz, r2 * ux + r5 * uy + r8 * uz
        j0, j1, j2, j3, j4, j5, j6, j7, j8 = inverse_inertia
        vx, vy, vz = j0 * ux + j1 * uy + j2 * uz, j3 * ux + j4 * uy + j5 * uz, j6 * ux + j7 * uy + j8 * uz
        tx, ty, tz = r0 * vx + r1 * vy + r2 * vz, r3 * vx + r4 * vy + r5 * vz, r6 * vx + r7 * vy + r8 * vz
        # The IMU where the fix puts it: c + (I + [theta]x) R o, o the IMU about the centroid.
        ax, ay, az = r0 * ox + r1 * oy + r2 * oz, r3 * ox + r4 * oy + r5 * oz, r6 * ox + r7 * oy + r8 * oz
        innovation = np.array(
            [
                cx + ax + (ty * az - tz * ay) - sx,
                cy + ay + (tz * ax - tx * az) - sy,
                cz + az + (tx * ay - ty * ax) - sz,
                tx,
                ty,
                tz,
            ]
        )
        carry = self._carry[body]
        for k, (tick, (px, py, pz), later_rotation) in enumerate(samples):
            later = (carry[tick - at_tick] @ innovation).tolist()
            samples[k] = (tick, [px + later[0], py + later[1], pz + later[2]], _turned(later[9:12], later_rotation))
        now = (carry[age] @ innovation).tolist()
        px, py, pz = self._position[body]
        self._position[body] = [px + now[0], py + now[1], pz + now[2]]
        vx, vy, vz = self._velocity[body]
        self._velocity[body] = [vx + now[3], vy + now[4], vz + now[5]]
        rotation = _orthonormal(np.array(_turned(now[9:12], self._rotation[body])).reshape(3, 3)).ravel().tolist()
        self._rotation[body] = rotation
        # The biases' corrections (world frame) in the IMU's frame (R^T b): the error is the
        # true bias less the estimate, so the estimate grows by it.
        r0, r1, r2, r3, r4, r5, r6, r7, r8 = rotation
        for biases, (bx, by, bz) in ((self._accel_bias, now[6:9]), (self._gyro_bias, now[12:15])):
            ex, ey, ez = biases[body]
            biases[body] = [
                ex + (r0 * bx + r3 * by + r6 * bz),
                ey + (r1 * bx + r4 * by + r7 * bz),
                ez + (r2 * bx + r5 * by + r8 * bz),
            ]

    def body_poses(self):
        """(origins (B, 3), rotations (B, 3, 3), velocities (B, 3)) of the bodies' frames, world."""
        return np.array(self.body_origins()), self.rotation, self.velocity

    def body_origins(self) -> list:
        """Per body, its frame's origin [x, y, z] (world, m): the IMU's position less its
        offset turned by the rotation (R o summed as ``propagate`` sums R v)."""
        out = []
        for (px, py, pz), (r0, r1, r2, r3, r4, r5, r6, r7, r8), (ox, oy, oz) in zip(
            self._position, self._rotation, self._offsets, strict=True
        ):
            out.append(
                [
                    px - ((r0 * ox + r2 * oz) + r1 * oy),
                    py - ((r3 * ox + r5 * oz) + r4 * oy),
                    pz - ((r6 * ox + r8 * oz) + r7 * oy),
                ]
            )
        return out


#: A constant of the per-fix arithmetic (an allocation, otherwise).
_EYE3_15 = 1.5 * np.eye(3)


def _turned(w, r) -> list:
    """(I + [w]x) R as 9 floats (rows), for w (3 floats) and R (9 floats, rows)."""
    wx, wy, wz = w
    r0, r1, r2, r3, r4, r5, r6, r7, r8 = r
    return [
        r0 + (wy * r6 - wz * r3),
        r1 + (wy * r7 - wz * r4),
        r2 + (wy * r8 - wz * r5),
        r3 + (wz * r0 - wx * r6),
        r4 + (wz * r1 - wx * r7),
        r5 + (wz * r2 - wx * r8),
        r6 + (wx * r3 - wy * r0),
        r7 + (wx * r4 - wy * r1),
        r8 + (wx * r5 - wy * r2),
    ]


def small_rotation_fit(measured: np.ndarray, predicted: np.ndarray, inverse_inertia: np.ndarray) -> np.ndarray:
    """The small rotation theta (3,) that best turns the centred points ``predicted`` (k, 3)
    onto the centred ``measured`` (k, 3): min sum |m - (I + [theta]x) q|^2, whose normal
    equations give theta = (sum |q|^2 I - q q^T)^-1 sum q x (m - q) (``inverse_inertia``: that
    inverse, in the same frame). First order in theta: a fix's innovation is a fraction of a
    milliradian, where it equals the exact fit (Kabsch; scipy's Rotation.align_vectors,
    tested) to its square, and costs a tenth of it."""
    return inverse_inertia @ moment_sum(predicted, measured - predicted)


def _orthonormal(r: np.ndarray) -> np.ndarray:
    """``r`` (3, 3), within 1e-6 of a rotation, made orthonormal to round-off: one Newton
    step of the polar decomposition, R (3 I - R^T R) / 2 (its error squares)."""
    return r @ (_EYE3_15 - 0.5 * (r.T @ r))


class FusedSensors(Sensors):
    """FAST's measurement system (module doc; ``SensorOptions(system="fused")``).

    Observation keys (SI; world frame unless stated):
      cabin_estimate_position (3,), cabin_estimate_rotation (3, 3), cabin_estimate_velocity
        (3,), cabin_estimate_time (1,): the cabin frame's fused pose (origin at the anchor
        plane's centre) for the present tick, from the cabin's SINS and GPS/RTK.
      platform_estimate_position, _rotation, _velocity, _time: the feed platform's, from its
        SINS and the total stations.
      cabin_imu_accel, cabin_imu_gyro, platform_imu_accel, platform_imu_gyro (3,): the IMUs'
        readings of the tick (specific force m/s^2 and rate rad/s, the IMU's frame = the
        body's), for a user's own fusion.
      cabin_rtk_points (3, 3) and platform_ts_points (3, 3): the last fix delivered (rows:
        antennas rtk1..3 / prisms prism1..3, world, m), with _time (when it was taken) and
        _count (a new one when it changes).
      ab_angles, ab_rotation, leg_positions, leg_setpoints: the encoders, as IdealSensors.
    """

    BODIES = ("cabin", "platform")

    def __init__(self, physics, options: SensorOptions = SensorOptions(), control_dt: float = CONTROL_DT):
        super().__init__()
        o = self.options = options
        self.dt = control_dt
        model = physics.model.ptr
        self.gravity = model.opt.gravity.copy()
        self.fix_every = {
            "cabin": _ticks(1.0 / o.rtk_rate_hz, control_dt, 1),
            "platform": _ticks(1.0 / o.ts_rate_hz, control_dt, 1),
        }
        self.fix_lag = {
            "cabin": _latency_ticks(o.rtk_latency_s, control_dt),
            "platform": _latency_ticks(o.ts_latency_s, control_dt),
        }
        self.body_ids = {"cabin": physics.cabin_body, "platform": int(model.body("feed_platform").id)}
        self.point_sites = {
            "cabin": [model.site(f"rtk{i}").id for i in (1, 2, 3)],
            "platform": [model.site(f"prism{i}").id for i in (1, 2, 3)],
        }
        self.imu_site = {b: model.site(f"{b}_imu").id for b in self.BODIES}
        self.noise = {
            "cabin": (o.rtk_noise_m, o.rtk_common_m, o.rtk_point_m, o.rtk_drift_time_s),
            "platform": (o.ts_noise_m, o.ts_common_m, o.ts_point_m, o.ts_drift_time_s),
        }
        history = max(self.fix_lag.values()) + 2
        imu = dict(
            accel_white=o.imu_accel_noise / math.sqrt(control_dt),
            accel_walk=o.imu_accel_bias_walk * math.sqrt(control_dt),
            gyro_white=o.imu_gyro_noise / math.sqrt(control_dt),
            gyro_walk=o.imu_gyro_bias_walk * math.sqrt(control_dt),
        )
        noises = []
        for b in self.BODIES:
            white, common, point, _ = self.noise[b]
            noises.append(dict(imu, every=self.fix_every[b], fix_white=math.hypot(white, point), fix_drift=common))
        self.filters = FusedPoses(
            [model.site_pos[self.point_sites[b]] for b in self.BODIES],
            [model.site_pos[self.imu_site[b]] for b in self.BODIES],
            noises,
            control_dt,
            self.gravity,
            history,
        )
        self._imu_sites = np.array([self.imu_site[b] for b in self.BODIES])
        columns = np.arange(model.nsensordata)  # (2, 3) sensordata columns of each body's reading
        self._vel_columns = np.array([columns[physics.sensor_block(f"{b}_imu_vel")] for b in self.BODIES])
        self._gyro_columns = np.array([columns[physics.sensor_block(f"{b}_imu_gyro")] for b in self.BODIES])
        rate = 1.0 / control_dt
        imu_noise = f"white {o.imu_accel_noise:g} m/s^2/sqrt(Hz) and {o.imu_gyro_noise:g} rad/sqrt(s)"
        imu_bias = (
            f"turn-on {o.imu_accel_bias:g} m/s^2 and {o.imu_gyro_bias:g} rad/s 1-sigma, random walk "
            f"{o.imu_accel_bias_walk:g} m/s^2/sqrt(s) and {o.imu_gyro_bias_walk:g} rad/s/sqrt(s)"
        )

        def fix_noise(b):
            white, common, point, tau = self.noise[b]
            return (
                f"white {1e3 * white:g} mm; Gauss-Markov ({tau:g} s) {1e3 * common:g} mm common and "
                f"{1e3 * point:g} mm per point, 1-sigma per coordinate"
            )

        self.specs = [
            SensorSpec(
                "cabin_estimate",
                "cabin pose fused from its SINS and GPS/RTK (Kalman filter)",
                "m|rad|m/s",
                rate,
                0.0,
                "the filter's error (about 15 mm and 0.1 deg RMS)",
            ),
            SensorSpec(
                "platform_estimate",
                "feed platform pose fused from its SINS and the total stations (Kalman filter)",
                "m|rad|m/s",
                rate,
                0.0,
                "the filter's error (about 3 mm and 0.1 deg RMS)",
            ),
            SensorSpec(
                "cabin_imu",
                "cabin SINS: specific force and angular rate, IMU frame",
                "m/s^2|rad/s",
                rate,
                0.0,
                imu_noise,
                imu_bias,
            ),
            SensorSpec(
                "platform_imu",
                "feed platform SINS: specific force and angular rate, IMU frame",
                "m/s^2|rad/s",
                rate,
                0.0,
                imu_noise,
                imu_bias,
            ),
            # The rates and latencies as simulated: whole numbers of ticks.
            SensorSpec(
                "cabin_rtk",
                "GPS/RTK positions of the cabin's three roof antennas",
                "m",
                rate / self.fix_every["cabin"],
                self.fix_lag["cabin"] * control_dt,
                fix_noise("cabin"),
            ),
            SensorSpec(
                "platform_ts",
                "total-station positions of the feed platform's three prisms",
                "m",
                rate / self.fix_every["platform"],
                self.fix_lag["platform"] * control_dt,
                fix_noise("platform"),
            ),
            *encoder_specs(rate),
        ]

    def reset(self, physics, times: np.ndarray, seed: int) -> dict:
        o = self.options
        n = times.size
        self._data = data = physics.data.ptr
        rng = np.random.default_rng([seed, 0xFA58])
        # IMU errors per tick: white noise, and a bias = turn-on + random walk.
        dt = self.dt
        self.accel_error = ImuErrors(
            rng, n, o.imu_accel_noise / math.sqrt(dt), o.imu_accel_bias, o.imu_accel_bias_walk * math.sqrt(dt)
        )
        self.gyro_error = ImuErrors(
            rng, n, o.imu_gyro_noise / math.sqrt(dt), o.imu_gyro_bias, o.imu_gyro_bias_walk * math.sqrt(dt)
        )
        # Fix errors per fix (rows: fixes; points; coordinates): white, common slow, per-point slow.
        self.fix_error = {}
        for b in self.BODIES:
            white, common, point, tau = self.noise[b]
            every = self.fix_every[b]
            m = n // every + 1
            fix_dt = every * dt
            self.fix_error[b] = (
                rng.normal(0.0, white, (m, 3, 3))
                + gauss_markov(rng, (m, 1, 3), common, tau, fix_dt)
                + gauss_markov(rng, (m, 3, 3), point, tau, fix_dt)
            )
        self._last_velocity = np.zeros((2, 3))
        self.pending = {b: deque() for b in self.BODIES}  # (arrival tick, points (3, 3), taken at tick)
        # Per tick: position (3) and rotation (9) of each body, streamed to a file of its own.
        self.estimates = temporary_writer({"estimate": (2, 12)}, times, prefix="planbench-estimates-")
        obs = {}
        # The readings of both bodies in (2, ...) arrays; the observation's arrays are views.
        self._accel, self._gyro = np.zeros((2, 3)), np.zeros((2, 3))
        # The estimates' position and rotation of both bodies side by side (2, 12), the
        # estimate log's row: one write a tick.
        self._estimate = np.zeros((2, 12))
        self._position, self._rotation = self._estimate[:, :3], self._estimate[:, 3:]
        self._rotation.shape = (2, 3, 3)  # in place: a view
        self._velocity = np.zeros((2, 3))
        self._time = np.zeros(1)
        bodies = [self.body_ids[b] for b in self.BODIES]
        self.filters.reset(data.xpos[bodies], data.xmat[bodies].reshape(-1, 3, 3))
        for k, b in enumerate(self.BODIES):
            obs.update(
                {
                    f"{b}_estimate_position": self._position[k],
                    f"{b}_estimate_rotation": self._rotation[k],
                    f"{b}_estimate_velocity": self._velocity[k],
                    f"{b}_estimate_time": self._time,
                    f"{b}_imu_accel": self._accel[k],
                    f"{b}_imu_gyro": self._gyro[k],
                }
            )
        for key in ("cabin_rtk", "platform_ts"):
            obs.update(
                {f"{key}_points": np.zeros((3, 3)), f"{key}_time": np.zeros(1), f"{key}_count": np.zeros(1, dtype=int)}
            )
        obs.update(ab_angles=np.zeros(2), ab_rotation=np.eye(3), leg_positions=np.zeros(6), leg_setpoints=np.zeros(6))
        self.observation = obs
        self._fix_key = {"cabin": "cabin_rtk", "platform": "platform_ts"}
        # What the tick reads, looked up once: the IMUs' sites and their readings' places in
        # one block of sensordata; per body its fix's period, latency, points, errors, queue
        # and observation arrays; the encoders' views.
        self._imu_rotations = [data.site_xmat[int(i)] for i in self._imu_sites]  # views of the live rows
        columns = np.concatenate([self._vel_columns.ravel(), self._gyro_columns.ravel()])
        low = int(columns.min())
        self._imu_readings = data.sensordata[low : int(columns.max()) + 1]  # a view
        self._imu_places = [
            (int(v[0]) - low, int(g[0]) - low) for v, g in zip(self._vel_columns, self._gyro_columns, strict=True)
        ]
        if not all(np.array_equal(c, c[0] + np.arange(3)) for c in (*self._vel_columns, *self._gyro_columns)):
            raise ValueError("the IMUs' readings must be 3 consecutive sensordata columns each")
        self._gravity_list = self.gravity.tolist()
        self._fixes = []
        for b in self.BODIES:
            key = self._fix_key[b]
            self._fixes.append(
                (
                    self.fix_every[b],
                    self.fix_lag[b],
                    index_view(self.point_sites[b]),
                    self.fix_error[b],
                    self.pending[b],
                    obs[f"{key}_points"],
                    obs[f"{key}_time"],
                    obs[f"{key}_count"],
                )
            )
        self._encoders = Encoders(physics, obs)
        self._estimate_flat = self._estimate.reshape(24)
        self._accel_flat, self._gyro_flat = self._accel.reshape(6), self._gyro.reshape(6)
        self._velocity_flat = self._velocity.reshape(6)
        self(0, physics)
        return obs

    def estimate_log(self, rows: int):
        """The estimates of the run's first ``rows`` ticks (a ``planbench.logfile.LogFile`` whose
        array ``estimate`` is (rows, 2, 12): per tick the position (3) and rotation (9) of each
        body), their file closed the first time."""
        return self.estimates.read_back(rows)

    def __call__(self, tick: int, physics) -> None:
        data, dt = self._data, self.dt
        # The IMUs: the tick's specific force from the velocity increment, and the rate, in
        # their frames, with their errors. In Python floats, each element's arithmetic that
        # of the vectorized form (tests/test_fast_measurement.py): the world velocity R v
        # summed as numpy's einsum sums it (FusedPoses.propagate), R^T f in order.
        block = self._imu_readings.tolist()
        accel_error, gyro_error = self.accel_error[tick].tolist(), self.gyro_error[tick].tolist()
        gx, gy, gz = self._gravity_list
        velocities, accels, gyros = [], [], []
        for k, site_rotation in enumerate(self._imu_rotations):
            r0, r1, r2, r3, r4, r5, r6, r7, r8 = site_rotation.tolist()
            at, gt = self._imu_places[k]
            v0, v1, v2 = block[at : at + 3]
            w0, w1, w2 = (r0 * v0 + r2 * v2) + r1 * v1, (r3 * v0 + r5 * v2) + r4 * v1, (r6 * v0 + r8 * v2) + r7 * v1
            if tick > 0:
                l0, l1, l2 = self._last_velocity[k]
                f0, f1, f2 = (w0 - l0) / dt - gx, (w1 - l1) / dt - gy, (w2 - l2) / dt - gz
            else:
                f0, f1, f2 = -gx, -gy, -gz
            e0, e1, e2 = accel_error[k]
            accels.append(
                [
                    ((r0 * f0 + r3 * f1) + r6 * f2) + e0,
                    ((r1 * f0 + r4 * f1) + r7 * f2) + e1,
                    ((r2 * f0 + r5 * f1) + r8 * f2) + e2,
                ]
            )
            e0, e1, e2 = gyro_error[k]
            gyros.append([block[gt] + e0, block[gt + 1] + e1, block[gt + 2] + e2])
            velocities.append([w0, w1, w2])
        self._last_velocity = velocities
        self._accel_flat[:] = accels[0] + accels[1]  # (flat lists: a third cheaper to write)
        self._gyro_flat[:] = gyros[0] + gyros[1]
        f = self.filters
        if tick > 0:
            f.propagate(accels, gyros)
        for k, (every, lag, sites, errors, queue, points_obs, time_obs, count_obs) in enumerate(self._fixes):
            if tick % every == 0:  # a fix taken now, delivered after its latency
                f.sample(k)
                queue.append((tick + lag, data.site_xpos[sites] + errors[tick // every], tick))
            while queue and queue[0][0] <= tick:
                _, points, taken = queue.popleft()
                f.correct(k, points, taken)
                points_obs[:] = points
                time_obs[0] = taken * dt
                count_obs[0] += 1
        (cabin, platform), (cabin_rotation, platform_rotation) = f.body_origins(), f._rotation
        self._estimate_flat[:] = cabin + cabin_rotation + platform + platform_rotation
        self.estimates.row("estimate", tick)[:] = self._estimate
        cabin, platform = f._velocity
        self._velocity_flat[:] = cabin + platform
        self._time[0] = tick * dt
        self._encoders()


def _ticks(seconds: float, dt: float, least: int) -> int:
    """A sensor's period in control ticks: the nearest whole number, at least ``least``."""
    return max(least, int(round(seconds / dt)))


def _latency_ticks(seconds: float, dt: float) -> int:
    """A latency in control ticks, rounded up (to 1e-9 of a tick): a reading never reaches the
    controller sooner than its datasheet says (50 ms at 50 Hz: 3 ticks, 60 ms)."""
    return int(math.ceil(seconds / dt - 1e-9))


def make_sensors(physics, options: SensorOptions, control_dt: float = CONTROL_DT) -> Sensors:
    """The task's sensors of ``options.system``."""
    return (FusedSensors if options.system == "fused" else IdealSensors)(physics, options, control_dt)


def floats_per_tick(options: SensorOptions, control_dt: float = CONTROL_DT) -> float:
    """Doubles per control tick that the sensors of ``options`` keep, in memory or in a file.
    Ideal: the true cabin pose (3 + 9) and the noise of their two measurements (2 x (3 + 9)).
    Fused: the fixes' errors (9 a fix, and one fix more per body: a run has n // every + 1) and
    the estimates' log (the tick's time and 2 x 12), streamed to a file of its own
    (``FusedSensors.estimates``); the IMUs' errors are made a block of ticks at a time
    (``ImuErrors``)."""
    if options.system == "ideal":
        return 36.0
    fixes = sum(1.0 / _ticks(1.0 / rate, control_dt, 1) for rate in (options.rtk_rate_hz, options.ts_rate_hz))
    return 24.0 + 9.0 * fixes + 1.0


def estimate_errors(sensors: FusedSensors, physics, log) -> dict:
    """The fused estimates' RMS errors against the true bodies over a run's log (a
    ``planbench.runner.RunLog``; all rows but the last, where no sensor read), read a chunk at a
    time: {"cabin_mm", "cabin_deg", "platform_mm", "platform_deg"}; position of the body
    frame's origin, attitude the angle of the estimated rotation times the true one's
    inverse. None each when the run ended before its first tick's estimate (a controller
    that faulted at tick 0): there is no error to average."""
    from scipy.spatial.transform import Rotation

    model = physics.model.ptr
    n = log.n - 1
    estimates = sensors.estimate_log(n)
    bodies = (("cabin", "cabin"), ("platform", "feed_platform"))
    adrs = [model.jnt_qposadr[model.body_jntadr[model.body(name).id]] for _, name in bodies]
    if n <= 0:
        return {f"{body}_{unit}": None for body, _ in bodies for unit in ("mm", "deg")}
    position, attitude = np.empty((2, n)), np.empty((2, n))  # per body, per tick: the errors, m and rad
    for start, rows in log.chunks(["qpos"]):
        qpos = rows["qpos"][: max(n - start, 0)]
        stop = start + qpos.shape[0]
        estimate = estimates.span("estimate", start, stop)
        for k, adr in enumerate(adrs):
            position[k, start:stop] = np.linalg.norm(estimate[:, k, :3] - qpos[:, adr : adr + 3], axis=1)
            attitude[k, start:stop] = (
                Rotation.from_matrix(estimate[:, k, 3:].reshape(-1, 3, 3))
                * Rotation.from_quat(qpos[:, adr + 3 : adr + 7], scalar_first=True).inv()
            ).magnitude()
    out = {}
    for k, (body, _) in enumerate(bodies):
        out[f"{body}_mm"] = 1e3 * float(np.sqrt(np.mean(position[k] ** 2)))
        out[f"{body}_deg"] = float(np.degrees(np.sqrt(np.mean(attitude[k] ** 2))))
    return out
