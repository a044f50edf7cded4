"""The ship antenna's task: the sea (``ShipMotionDrive``, the disturbance that moves the deck),
the evaluation (``AntennaEvaluation``: checks, metrics, timeseries), the ideal joint path and
the start angles, ``build`` (a ``Setup`` of planbench.runner around a ``Task`` of planbench.task),
``plan``, the paper's comparison of methods, the scenarios and the environment reward.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from planbench import run_limits
from planbench.antenna.controller import AntennaController
from planbench.antenna.params import (
    CONTROL_DT,
    DECK_JOINTS,
    JOINTS,
    PAPER_DURATION_S,
    REFERENCE_DT,
    AntennaPaperParams,
    AntennaParams,
    AntennaPlant,
    AntennaSeaParams,
    ImuModel,
    _exp_so3,
    log_bytes_per_tick,
    satellite_of,
)
from planbench.antenna.physics import AntennaPhysics
from planbench.antenna.sensors import AntennaImu
from planbench.antenna.ship_motion import PaperShipMotion, SeaStateMotion
from planbench.checks import Check
from planbench.controllers import ServoFeedforwardController, demanded_force
from planbench.planners import antenna as ant
from planbench.planners.trajectory import TrajectorySample
from planbench.runner import RunLog, Setup
from planbench.scenarios import BENCHMARK, DEMO, Scenario
from planbench.task import (
    Components,
    ControlContext,
    JointEncoders,
    Output,
    Provenance,
    RecordingPlanner,
    Task,
    check_planner,
    nominal_copy,
)

#: Check limits (REFERENCE.md, "Ship antenna"; FCC ESV: transmit off within 100 ms above
#: 0.5 deg; industry 0.2 deg peak, ~0.1 deg RMS; polarization within 1 deg).
POINTING_MAX_SEA_DEG = 0.2
POINTING_MAX_PAPER_DEG = 0.5
POINTING_RMS_DEG = 0.1
POLARIZATION_MAX_DEG = 1.0
ATTITUDE_FRO_LIMIT = 1e-6


# ----------------------------------------------------------------------------- the sea


class ShipMotionTrajectory:
    """A ship motion (planbench.antenna.ship_motion) as a Trajectory of the deck joints."""

    labels = DECK_JOINTS

    def __init__(self, motion, duration: float):
        self.motion = motion
        self._duration = float(duration)

    @property
    def duration(self) -> float:
        return self._duration

    def sample(self, t) -> TrajectorySample:
        state = self.motion.sample(np.atleast_1d(np.asarray(t, dtype=float)))
        return TrajectorySample(state.t, *state.joint_arrays())


class ShipMotionDrive:
    """The disturbance: the deck follows the ship motion through its stiff drives.

    A servo controller with the model's inverse dynamics as feed-forward, so the deck tracks
    the prescribed motion to a few thousandths of a degree whatever the antenna does.

    Args:
      motion: the ship motion the task was built with (``planbench.antenna.ship_motion``).
      seed: the seed ``motion`` was drawn from.
      sea_start: for a random sea, draws another sea and its start for another episode seed
        (``draw_start``); None: every episode has ``motion``.
    """

    def __init__(self, physics: AntennaPhysics, motion, seed: int | None = None, sea_start: SeaStart | None = None):
        kp, kv = physics.drive_gains(DECK_JOINTS)
        self.motion = self.built_motion = motion
        self.seed, self.sea_start = seed, sea_start
        self.servo = ServoFeedforwardController(kp, kv)
        self.qpos_adr = physics.deck_qpos
        self.reference = None

    def draw_start(self, physics, seed: int) -> None:
        """A random sea (``sea_start``) is drawn afresh for each seed but the one it was built
        with; the physics is put at that sea's start (``planbench.task.Disturbance``)."""
        if self.sea_start is None or seed == self.seed:
            self.motion = self.built_motion
        else:
            self.motion = self.sea_start(physics, seed)

    def reset(self, physics, times, rng) -> None:
        # The sea's servo reads the deck joints exactly (it is the plant, not a controller
        # under test).
        self.reference = ShipMotionTrajectory(self.motion, times[-1]).sample(times)
        model, data = physics.model.ptr, physics.data.ptr
        encoders = JointEncoders(
            physics.deck_qpos,
            physics.deck_dofs,
            model.actuator_actadr[physics.deck_actuators],
            "deck joints",
            "m|rad",
            CONTROL_DT,
        )
        self.observation = encoders.reset(physics, times, 0)
        self.encoders = encoders
        dt = times[1] - times[0] if times.size > 1 else CONTROL_DT
        # Views of the deck drives' commands and set-points (each a contiguous run), written
        # in place by the servo.
        ids, adr = physics.deck_actuators, model.actuator_actadr[physics.deck_actuators]
        assert np.all(np.diff(ids) == 1) and np.all(np.diff(adr) == 1), "the deck drives are one contiguous run"
        self.servo.reset(
            ControlContext(
                model=model,
                nominal_physics=nominal_copy(physics),
                problem=None,
                trajectory=None,
                reference=self.reference,
                control_dt=dt,
                command=data.ctrl[ids[0] : ids[-1] + 1],
                setpoint=data.act[adr[0] : adr[-1] + 1],
                actuators=DECK_JOINTS,
                observation=self.observation,
            )
        )

    def __call__(self, tick: int, physics) -> None:
        self.encoders(tick, physics)
        self.servo(tick, self.observation)

    def tracking_error(self, log: RunLog) -> np.ndarray:
        """(4,) largest |deck joint - ship motion| over the run (m, rad)."""
        n = log.t.size
        deck = log.qpos[:, self.qpos_adr]
        return np.abs(deck - self.reference.position[:n]).max(axis=0)


# ----------------------------------------------------------------------------- evaluation


def pointing_errors(dish: np.ndarray, satellite: np.ndarray):
    """(pointing, polarization) errors in rad of world-from-antenna rotations (n, 3, 3).

    Pointing: the angle between the boresight Z_a and the satellite direction Z_s.
    Polarization: the twist about the boresight of eTs^T R (swing-twist decomposition).
    """
    z = dish[:, :, 2]
    target = satellite[:, 2]
    pointing = np.arctan2(np.linalg.norm(np.cross(z, target), axis=1), z @ target)
    relative = satellite.T @ dish
    twist = np.arctan2(relative[:, 1, 0] - relative[:, 0, 1], relative[:, 0, 0] + relative[:, 1, 1])
    return pointing, twist


class AntennaEvaluation:
    """Checks and outputs of an antenna run."""

    def __init__(
        self,
        physics: AntennaPhysics,
        satellite,
        planner: RecordingPlanner,
        drive: ShipMotionDrive,
        pointing_max_deg: float,
        rms_limit_deg: float | None,
        description: dict,
    ):
        self.physics = physics
        self.drive = drive
        self.satellite = satellite
        self.planner = planner  # the task's record of every update the planner returned
        self.pointing_max_deg = pointing_max_deg
        self.rms_limit_deg = rms_limit_deg
        self.description = description

    def _joint_log(self, log: RunLog):
        p = self.physics
        return log.qpos[:, p.antenna_qpos], log.qvel[:, p.antenna_dofs]

    def updates(self) -> dict:
        """The planner's updates as the task recorded them, with ||f(Theta) - N||_F of each:
        the returned angles against the attitude they were asked for."""
        records = self.planner.records()
        # One matrix at a time: the same arithmetic as the planner's own residual, to the bit.
        records["error_fro"] = np.array(
            [
                float(ant.frobenius_error(ant.forward_kinematics(theta), n))
                for theta, n in zip(records["theta"], records["attitude"], strict=True)
            ]
        )
        return records

    def errors_deg(self, log: RunLog):
        pointing, twist = pointing_errors(self.physics.dish_rotation(log.qpos), self.satellite)
        return np.degrees(pointing), np.degrees(twist)

    def _demanded(self, log: RunLog) -> np.ndarray:
        """(n, 4) the drives' demanded torques, N m: their loops on the coordinate they read
        (the motor's as built), before the torque clamp."""
        p = self.physics
        kp, kv = p.drive_gains()
        return demanded_force(
            kp, kv, log.act[:, p.antenna_actuators], log.qpos[:, p.drive_qpos], log.qvel[:, p.drive_dofs]
        )

    def evaluate(self, log: RunLog):
        p = self.physics
        pointing, polarization = self.errors_deg(log)
        q, qd = self._joint_log(log)
        kp, kv = p.drive_gains()
        torque = self._demanded(log)
        torque_ratio = np.abs(torque).max(0) / p.torque_limit()
        rate_ratio = np.abs(qd).max(0) / p.rate_limit()
        ctrl_ratio = np.abs(log.ctrl[:, p.antenna_actuators]).max(0) / p.rate_limit()
        updates = self.updates()
        deck_error = self.drive.tracking_error(log)
        checks = [
            Check(
                "pointing_error_max",
                float(pointing.max()),
                self.pointing_max_deg,
                "deg",
                note=f"at t = {log.t[int(np.argmax(pointing))]:.2f} s",
            ),
        ]
        if self.rms_limit_deg is not None:
            checks.append(Check("pointing_error_rms", float(np.sqrt(np.mean(pointing**2))), self.rms_limit_deg, "deg"))
        sigma = ant.weighted_singular_value(ant.jacobian(q))
        damped_t = updates["t"][updates["damped"]]
        limited_t = updates["t"][updates["rate_limited"]]
        checks += [
            Check("polarization_error_max", float(np.abs(polarization).max()), POLARIZATION_MAX_DEG, "deg"),
            Check(
                "attitude_error_fro_max",
                float(np.max(updates["error_fro"], initial=0.0)),
                ATTITUDE_FRO_LIMIT,
                "1",  # a norm of rotation matrices: dimensionless
                note=f"||f(Theta) - N||_F of the angles the planner returned, over {updates['t'].size} updates",
            ),
            Check(
                "joint_rate",
                float(rate_ratio.max()),
                1.0,
                "of limit",
                note=f"measured joint speed / rated speed, worst {JOINTS[int(np.argmax(rate_ratio))]}",
            ),
            Check(
                "joint_torque",
                float(torque_ratio.max()),
                1.0,
                "of limit",
                note=f"demanded / drive limit, worst {JOINTS[int(np.argmax(torque_ratio))]}",
            ),
        ]
        metrics = dict(self.description)
        metrics.update(
            {
                "pointing_error_rms_deg": float(np.sqrt(np.mean(pointing**2))),
                "pointing_error_p99_deg": float(np.percentile(pointing, 99)),
                "polarization_error_rms_deg": float(np.sqrt(np.mean(polarization**2))),
                "peak_joint_rate_deg_s": dict(
                    zip(JOINTS, np.degrees(np.abs(qd).max(0)).round(3).tolist(), strict=True)
                ),
                "commanded_rate_of_limit": dict(zip(JOINTS, ctrl_ratio.round(4).tolist(), strict=True)),
                "peak_torque_N_m": dict(zip(JOINTS, np.abs(torque).max(0).round(3).tolist(), strict=True)),
                "joint_range_deg": {
                    n: [float(np.degrees(q[:, j].min()).round(3)), float(np.degrees(q[:, j].max()).round(3))]
                    for j, n in enumerate(JOINTS)
                },
                "planner_updates": int(updates["t"].size),
                "planner_wall_s": self.planner.wall_s,
                "newton_iterations_mean": float(np.mean(updates["iterations"])) if updates["t"].size else 0.0,
                "newton_iterations_max": int(np.max(updates["iterations"], initial=0)),
                # Distance to a singularity along the run: sigma_min of J W^-1/2 (0 = singular;
                # damping starts below AntennaLimits.singular_threshold).
                "weighted_singular_value_min": float(sigma.min()),
                "weighted_singular_value_min_t_s": float(log.t[int(np.argmin(sigma))]),
                "singularity_damping_updates": int(updates["damped"].sum()),
                "singularity_damping_first_t_s": float(damped_t[0]) if damped_t.size else None,
                "singularity_damping_last_t_s": float(damped_t[-1]) if damped_t.size else None,
                "rate_limited_updates": int(updates["rate_limited"].sum()),
                "rate_limited_first_t_s": float(limited_t[0]) if limited_t.size else None,
                "deck_tracking_error_deg": float(np.degrees(deck_error[1:].max())),
                "deck_heave_error_mm": float(1e3 * deck_error[0]),
            }
        )
        return checks, metrics

    def timeseries(self, log: RunLog) -> dict:
        p = self.physics
        q, qd = self._joint_log(log)
        kp, kv = p.drive_gains()
        pointing, polarization = self.errors_deg(log)
        updates = self.updates()
        deck = log.qpos[:, p.deck_qpos]
        return {
            "joint_names": np.array(JOINTS),
            "ship_heave": deck[:, 0],
            "ship_heading": deck[:, 1],
            "ship_pitch": deck[:, 2],
            "ship_roll": deck[:, 3],
            "theta_planned": log.reference.position,
            "theta_actual": q,
            "theta_rate": qd,
            "setpoint": log.act[:, p.antenna_actuators],
            "torque_demanded": self._demanded(log),
            "torque_limit": p.torque_limit(),
            "rate_limit": p.rate_limit(),
            "pointing_error_deg": pointing,
            "polarization_error_deg": polarization,
            "update_t": updates["t"],
            "update_theta": updates["theta"],
            "update_error_fro": updates["error_fro"],
            "update_iterations": updates["iterations"],
            "update_damped": updates["damped"],
            "update_rate_limited": updates["rate_limited"],
        }

    def report(self, log: RunLog, checks, path) -> None:
        from planbench.antenna.report import antenna_report

        antenna_report(self.timeseries(log), log.t, checks, path, self.pointing_max_deg)


# ----------------------------------------------------------------------------- scenarios


def ideal_path(motion, satellite: np.ndarray, duration: float, theta0) -> ant.JointPathTrajectory:
    """Joint angles for the true ship motion, CRR with full correction every REFERENCE_DT."""
    n = int(math.ceil(duration / REFERENCE_DT)) + 1
    t = np.arange(n) * REFERENCE_DT
    ship = motion.sample(t)
    attitudes = ant.ship_attitude(ship.heading, ship.pitch, ship.roll) @ satellite
    return ant.JointPathTrajectory(ant.solve_joint_path(attitudes, REFERENCE_DT, theta0, "crr-full"))


def start_angles(motion, satellite: np.ndarray, azimuth: float, elevation: float, polarization: float) -> np.ndarray:
    """Joint angles for the attitude at t = 0: from the level-ship solution (eq. 15),
    corrected to the ship's attitude at 0 by weighted Newton steps (planbench.planners.antenna)."""
    theta = ant.joint_angles_at_rest(azimuth, elevation, polarization)
    ship = motion.sample(0.0)
    target = ant.ship_attitude(ship.heading[0], ship.pitch[0], ship.roll[0]) @ satellite
    level = ant.forward_kinematics(theta)
    # Turn from the level attitude to the target in small steps (the path stays on the
    # weighted minimum-norm branch).
    path = ant.solve_joint_path(_slerp(level, target, 50), 1.0, theta, "crr-full")
    return path.theta[-1]


def tracked_start(motion, satellite: np.ndarray, theta: np.ndarray, plant: AntennaPlant) -> np.ndarray:
    """The joint angles an antenna holds at t = 0 when it has been tracking with ``plant``'s
    biased IMU, from ``theta`` (those for the true attitude at 0): the attitude B^T bTe(0) eTs
    that the biased deck attitude eTb B asks for (eq. 1 with the measurement), reached by
    weighted Newton steps; ``theta`` itself without a bias."""
    if not any(plant.imu_bias):
        return theta
    ship = motion.sample(0.0)
    target = plant.bias_rotation().T @ ant.ship_attitude(ship.heading[0], ship.pitch[0], ship.roll[0]) @ satellite
    path = ant.solve_joint_path(_slerp(ant.forward_kinematics(theta), target, 10), 1.0, theta, "crr-full")
    return path.theta[-1]


def _slerp(a: np.ndarray, b: np.ndarray, n: int) -> np.ndarray:
    """n + 1 attitudes turning from ``a`` to ``b`` (3, 3) about one fixed axis."""
    relative = b @ a.T
    if (np.trace(relative) - 1.0) / 2.0 < math.cos(math.pi - 1e-6):
        # A half turn (ship heading 180 deg with no motion, found by hypothesis): the matrix
        # log of planbench.planners.antenna refuses it; scipy's Slerp picks one of its two axes.
        return Slerp([0.0, 1.0], Rotation.from_matrix(np.stack([a, b])))(np.linspace(0.0, 1.0, n + 1)).as_matrix()
    rotvec = ant.rotation_log(relative)
    s = np.linspace(0.0, 1.0, n + 1)
    return np.stack([_exp_so3(f * rotvec) @ a for f in s])


@dataclass(frozen=True)
class AntennaOptions:
    """How the antenna's sensors, controller and planner are set up (tests and users vary it;
    the CLI sets the IMU's rate and latency and the prediction)."""

    imu: ImuModel = ImuModel()
    predict: bool = True
    method: str = "crr"
    omega_method: str = "log"


class SeaStart:
    """The random start of a sea-state episode (``ShipMotionDrive.draw_start``): a fresh
    JONSWAP sea drawn from the episode's seed, the deck at its state at t = 0 and the antenna at
    the joint angles and rates that hold the satellite there (``start_angles``; with a biased
    IMU, ``tracked_start``), its set-points with them."""

    #: s of ideal path solved for the start's joint rates (the same as the whole run's to
    #: round-off: the path's first samples do not depend on its length).
    RATE_SPAN_S = 1.0

    def __init__(self, params: AntennaSeaParams, satellite: np.ndarray, plant: AntennaPlant | None):
        self.params, self.satellite, self.plant = params, satellite, plant

    def __call__(self, physics: AntennaPhysics, seed: int):
        """Puts ``physics`` at the start of the sea drawn from ``seed``; returns that sea."""
        motion = motion_of(self.params, seed)
        az, el, pol = satellite_of(self.params)
        theta = start_angles(motion, self.satellite, az, el, pol)
        start = ideal_path(motion, self.satellite, self.RATE_SPAN_S, theta).sample(0.0)
        theta = start.position[0]
        if self.plant is not None:
            theta = tracked_start(motion, self.satellite, theta, self.plant)
        deck_pos, deck_vel, _ = motion.sample(0.0).joint_arrays()
        physics.set_state(deck_pos[0], deck_vel[0], theta, start.velocity[0])
        return motion


def _setup(
    motion,
    azimuth,
    elevation,
    polarization,
    duration,
    seed,
    pointing_max_deg,
    rms_limit_deg,
    description,
    antenna_options: AntennaOptions,
    video_length_s: float = 60.0,
    planner=None,
    controller=None,
    params=None,
    plant=None,
) -> Setup:
    perturbed = plant is not None and not plant.is_nominal
    # The plant (perturbed or not) and the model the planner and the controller know, both
    # at the same initial state; the deck's drive is the sea's, so it drives the plant.
    drives = params.drives if params is not None else "ideal"
    physics = AntennaPhysics.load(plant if perturbed else None, drives)
    nominal = AntennaPhysics.load(drives=drives) if perturbed else physics
    satellite = ant.satellite_attitude(azimuth, elevation, polarization)
    theta0 = start_angles(motion, satellite, azimuth, elevation, polarization)
    reference = ideal_path(motion, satellite, duration, theta0)
    start = reference.sample(0.0)
    theta_start = tracked_start(motion, satellite, start.position[0], plant) if perturbed else start.position[0]
    ship0 = motion.sample(0.0)
    deck_pos, deck_vel, _ = ship0.joint_arrays()
    for p in {id(physics): physics, id(nominal): nominal}.values():
        p.set_state(deck_pos[0], deck_vel[0], theta_start, start.velocity[0])
    sea_start = (
        SeaStart(params, satellite, plant if perturbed else None) if isinstance(params, AntennaSeaParams) else None
    )
    drive = ShipMotionDrive(physics, motion, seed, sea_start)
    imu = antenna_options.imu
    problem = ant.AntennaProblem(
        satellite,
        float(azimuth),
        float(elevation),
        float(polarization),
        theta_start.copy(),
        ant.AntennaLimits(rate=nominal.rate_limit()),
        update_dt=1.0 / imu.rate_hz,
    )
    if planner is None:
        planner = ant.CrrPlanner(antenna_options.method, antenna_options.omega_method)
    check_planner(planner, online=True)
    period, _ = imu.ticks(CONTROL_DT)
    recorder = RecordingPlanner(planner, int(math.ceil(duration / (period * CONTROL_DT))) + 2)
    if controller is None:
        controller = AntennaController(antenna_options.predict)
    description = dict(description)
    description.update(
        {
            "imu_rate_hz": antenna_options.imu.rate_hz,
            "imu_latency_s": antenna_options.imu.latency_s,
            "imu_attitude_noise_deg": antenna_options.imu.attitude_noise_deg,
            "imu_attitude_noise_time_s": antenna_options.imu.attitude_noise_time_s,
            "imu_gyro_noise_deg_s": antenna_options.imu.gyro_noise_deg_s,
            "prediction": antenna_options.predict,
        }
    )
    if isinstance(planner, ant.CrrPlanner):
        description.update({"planner": planner.method, "planner_angular_velocity": planner.omega_method})
    evaluation = AntennaEvaluation(physics, satellite, recorder, drive, pointing_max_deg, rms_limit_deg, description)
    task = Task(
        problem=problem,
        sensors=AntennaImu(physics, imu, CONTROL_DT, plant if perturbed else None),
        evaluation=evaluation,
        control_dt=CONTROL_DT,
        duration=duration,
        disturbance=drive,
        controlled=physics.antenna_actuators,
        reference_visible=False,  # the ideal path knows the true sea: plots only
        nominal_physics=nominal_copy(nominal) if perturbed else None,
    )  # None: a copy of physics
    return Setup(
        physics,
        task,
        Components(planner=recorder, trajectory=reference, controller=controller),
        # Time-lapse so the video lasts at most video_length_s.
        Output(video_speed=max(1.0, duration / video_length_s)),
        Provenance(seed=seed, params=params, plant=plant if plant is not None else AntennaPlant()),
    )


def motion_of(params: AntennaParams, seed: int | None = None):
    """The ship's motion: the paper's eq. (15)-(16) with the run's amplitudes and periods, or
    a JONSWAP sea drawn from ``seed`` (default the run's seed)."""
    if isinstance(params, AntennaPaperParams):
        # At the defaults this is eq. (15)-(16) to the bit (radians(1 deg/s) equals the
        # paper's 0.01 deg per 0.01 s sample).
        return PaperShipMotion(
            amplitudes_deg={
                "heading": params.heading_amplitude,
                "pitch": params.pitch_amplitude,
                "roll": params.roll_amplitude,
            },
            periods_s={"heading": params.heading_period, "pitch": params.pitch_period, "roll": params.roll_period},
            turn_rate_deg_s=params.turn_rate,
            course_deg=-params.ship_heading,
        )
    seed = params.seed if seed is None else seed
    return SeaStateMotion(
        params.hs,
        params.tp,
        params.wave_heading,
        np.random.default_rng([seed, 0x5EA]),
        gamma=params.gamma,
        speed=params.ship_speed,
        course_deg=-params.ship_heading,
    )


def build(
    params: AntennaParams,
    planner=None,
    controller=None,
    antenna_options: AntennaOptions | None = None,
    plant: AntennaPlant | None = None,
) -> Setup:
    """An antenna run: the ship's motion, the satellite, the IMU; ``planner`` (default the
    paper's CRR) solves the joint angles online from the IMU's attitude, ``controller``
    (default ``AntennaController``) drives the axes. ``antenna_options``: the planner's
    method and the controller's prediction for tests (default: from the parameters).
    ``plant``: the plant's uncertainty (``AntennaPlant``; None or nominal: the model as it
    is); the planner and the controller keep the nominal model and the IMU's datasheet."""
    if plant is not None:
        plant.check_drives(params.drives)
    if antenna_options is None:
        antenna_options = AntennaOptions(imu=params.imu, predict=params.prediction)
    run_limits.check_duration(params.duration, CONTROL_DT, log_bytes_per_tick(antenna_options.imu, params.drives))
    az, el, pol = satellite_of(params)
    motion = motion_of(params)
    duration = params.duration
    if isinstance(params, AntennaPaperParams):
        description = {
            "ship_motion": f"paper eq. (15)-(16): heading {params.heading_amplitude:g} deg / "
            f"{params.heading_period:g} s and {params.turn_rate:g} deg/s, pitch "
            f"{params.pitch_amplitude:g} deg / {params.pitch_period:g} s, roll "
            f"{params.roll_amplitude:g} deg / {params.roll_period:g} s",
            "satellite_az_el_pol_deg": np.degrees([az, el, pol]).round(4).tolist(),
        }
        # A 30 s video: the 8 s and 10 s periods shown at 4 s and 5 s.
        return _setup(
            motion,
            az,
            el,
            pol,
            duration,
            params.seed,
            POINTING_MAX_PAPER_DEG,
            None,
            description,
            antenna_options,
            video_length_s=30.0,
            planner=planner,
            controller=controller,
            params=params,
            plant=plant,
        )
    sd = motion.standard_deviation()
    description = {
        "ship_motion": f"JONSWAP Hs {params.hs:g} m, Tp {params.tp:g} s, gamma {motion.gamma:g}, "
        f"waves {params.wave_heading:g} deg off the bow",
        "ship_motion_std": {
            "heave_m": float(sd[0]),
            "yaw_deg": float(np.degrees(sd[1])),
            "pitch_deg": float(np.degrees(sd[2])),
            "roll_deg": float(np.degrees(sd[3])),
        },
        "ship_position_deg": [params.ship_lat, params.ship_lon],
        "satellite_lon_deg": params.satellite_lon,
        "satellite_az_el_pol_deg": np.degrees([az, el, pol]).round(4).tolist(),
    }
    return _setup(
        motion,
        az,
        el,
        pol,
        duration,
        params.seed,
        POINTING_MAX_SEA_DEG,
        POINTING_RMS_DEG,
        description,
        antenna_options,
        planner=planner,
        controller=controller,
        params=params,
        plant=plant,
    )


def plan(params: AntennaParams) -> ant.JointPathTrajectory:
    """The run's case without physics: joint angles for the true ship motion (CRR with full
    correction every REFERENCE_DT), from the start angles."""
    az, el, pol = satellite_of(params)
    satellite = ant.satellite_attitude(az, el, pol)
    motion = motion_of(params)
    return ideal_path(motion, satellite, params.duration, start_angles(motion, satellite, az, el, pol))


def compare_methods(duration: float = PAPER_DURATION_S) -> dict:
    """The paper's section 5 experiment: pinv integration, CRR (eq. 6 and exact angular
    velocity) and CRR with full correction over eq. (15)-(16) at dT = 0.01 s."""
    t = np.arange(int(round(duration / ant.PAPER_DT)) + 1) * ant.PAPER_DT
    ship = PaperShipMotion().sample(t)
    az, el, pol = np.radians(ant.PAPER_SATELLITE_DEG)
    attitudes = ant.desired_attitude(ship.heading, ship.pitch, ship.roll, az, el, pol)
    theta0 = np.radians(ant.PAPER_THETA0_DEG)
    runs = {"pinv": ("pinv", "eq6"), "crr": ("crr", "eq6"), "crr_log": ("crr", "log"), "crr_full": ("crr-full", "eq6")}
    return {
        key: ant.solve_joint_path(attitudes, ant.PAPER_DT, theta0, method, omega_method=omega)
        for key, (method, omega) in runs.items()
    }


def write_method_comparison(plan, out_dir) -> None:
    """methods.npz and methods.png: the paper's Figures 2-8 for the three methods (the
    scenario's own plan is not needed: the comparison runs the paper's conditions)."""
    from planbench.antenna.report import antenna_methods_plot

    paths = compare_methods()
    arrays = {"t": paths["pinv"].t}
    for key, path in paths.items():
        arrays[f"theta_{key}"] = path.theta
        arrays[f"error_fro_{key}"] = path.error_fro
        arrays[f"iterations_{key}"] = path.iterations
    np.savez_compressed(Path(out_dir) / "methods.npz", **arrays)
    antenna_methods_plot(paths, Path(out_dir) / "methods.png")


def joint_kinds() -> list[str]:
    return ["hinge"] * 4


# ----------------------------------------------------------------------------- registry


SCENARIOS = (
    Scenario(
        "antenna-paper-motion",
        "ship antenna, 4 axes: the paper's extreme ship motion (pitch 40 deg/8 s, roll 45 deg/10 s, "
        "1 deg/s turn), IMU at 50 Hz, CRR planner, 60 s",
        AntennaPaperParams(),
        build,
        plan,
        kinds=joint_kinds,
        plan_extras=write_method_comparison,
        control_dt=CONTROL_DT,
        online_planner=True,
        plant=AntennaPlant(),
    ),
    Scenario(
        "antenna-sea-state",
        "ship antenna, 4 axes: JONSWAP sea Hs 5 m, Tp 10 s, waves 135 deg off the bow, holding a GEO "
        "satellite at 15 W from 40 N 20 W, 300 s",
        AntennaSeaParams(),
        build,
        plan,
        kinds=joint_kinds,
        control_dt=CONTROL_DT,
        online_planner=True,
        plant=AntennaPlant(),
        tags=(DEMO, BENCHMARK),
    ),
)


def environment_reward(setup: Setup):
    """The dm_control reward: exp(-pointing error / 0.1 deg)."""
    satellite, scale = setup.task.problem.satellite, np.deg2rad(0.1)

    def reward(physics, tick, adapter):
        pointing, _ = pointing_errors(physics.dish_rotation(physics.data.qpos), satellite)
        return float(np.exp(-pointing[0] / scale))

    return reward
