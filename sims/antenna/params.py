"""The ship antenna's parameters: the scenarios' (``AntennaParams``, ``AntennaPaperParams``,
``AntennaSeaParams``), the pedestal IMU's datasheet (``ImuModel``) and the plant's uncertainty
(``AntennaPlant``), with the constants they need: the control tick, the joints, the IMU's
defaults and ranges, the scenario defaults, and the memory a run's log needs
(``log_bytes_per_tick``), which the parameters' checks refuse beyond the limit.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import mujoco
import numpy as np

import models
from planners import antenna as ant
from planners.errors import PlanningError
from planners.antenna.geostationary import look_angles
from sims import run_limits
from sims.drives import DRIVES, torque_constant_error
from sims.antenna.ship_motion import SEA_HS_MAX_M, SEA_TP_RANGE_S, check_sea_state
from sims.params import ParamError, Params, PlantParams, ScenarioParams, override, param
from sims.plant import set_inertial


CONTROL_DT = 0.005  # s: the runner's tick; the IMU rate is a whole number of ticks
DECK_JOINTS = ("heave", "yaw", "pitch", "roll")
JOINTS = ant.JOINT_LABELS

#: The IMU (REFERENCE.md and the paper, section 4.1: attitude updates 20-50 times a second).
#: Noise and latency are assumptions for a marine MEMS/FOG attitude and heading reference
#: (datasheets give 0.01-0.05 deg RMS dynamic attitude accuracy; a few to tens of ms from
#: sampling to the controller). The attitude an AHRS outputs is a filtered estimate: its
#: error wanders slowly (a first-order Gauss-Markov process here), it is not white per
#: sample; the gyro's rate noise is white.
IMU_RATE_HZ = 50.0
IMU_LATENCY_S = 0.020
IMU_ATTITUDE_NOISE_DEG = 0.02  # 1 sigma per axis of the attitude error
IMU_ATTITUDE_NOISE_TIME_S = 1.0  # correlation time of the attitude error
IMU_GYRO_NOISE_DEG_S = 0.02  # 1 sigma per axis, white per sample
#: Range of the IMU options the model means something for (assumptions, not data): at least
#: 1 Hz (the paper's IMU updates 20-50 times a second; below 1 Hz the controller would hold
#: each attitude for longer than an eighth of the paper's 8 s pitch period, no stabilizer),
#: at most the 200 Hz control rate (one sample per tick); a latency of at most 1 s (a few to
#: tens of ms for a marine AHRS; a second-old attitude is no longer a measurement of the
#: motion, and the prediction extrapolates the gyro over the latency).
IMU_RATE_MIN_HZ = 1.0
IMU_LATENCY_MAX_S = 1.0

#: Scenario defaults.
PAPER_DURATION_S = 60.0
SEA_DURATION_S = 300.0
SEA_HS_M = 5.0
SEA_TP_S = 10.0
SEA_HEADING_DEG = 135.0  # waves 45 deg off the starboard bow: both roll and pitch
SHIP_LAT_DEG, SHIP_LON_DEG = 40.0, -20.0  # North Atlantic
SATELLITE_LON_DEG = -15.0  # a geostationary slot at 15 deg W

#: Interval of the ideal joint path (the reference for plots and the initial state), s.
REFERENCE_DT = 0.05


@dataclass(frozen=True)
class ImuModel(Params):
    """The pedestal IMU's datasheet, as the controller sees it: the scenarios' ``imu`` table
    (typed and ranged as every parameter, sims.params), declared here once.

    The attitude error is first-order Gauss-Markov, e_k+1 = e_k exp(-h / T) +
    sigma sqrt(1 - exp(-2 h / T)) n_k (T = attitude_noise_time_s; 0 for white noise).
    """

    rate_hz: float = param(IMU_RATE_HZ, "samples per second (200 / a whole number; the paper: 20-50)", "Hz",
                           low=IMU_RATE_MIN_HZ, high=1.0 / CONTROL_DT,
                           reason="1 Hz is the slowest the controller models; at most one per control tick")
    latency_s: float = param(IMU_LATENCY_S, "time from sampling to the controller (a whole number of 5 ms ticks)",
                             "s", low=0.0, high=IMU_LATENCY_MAX_S,
                             reason="a marine AHRS: a few to tens of ms; 1 s at most")
    attitude_noise_deg: float = param(IMU_ATTITUDE_NOISE_DEG, "attitude error per axis (1 sigma, Gauss-Markov)",
                                      "deg", low=0.0, high=5.0, reason="a marine AHRS: 0.01-1 deg")
    attitude_noise_time_s: float = param(IMU_ATTITUDE_NOISE_TIME_S, "correlation time of the attitude error, 0 "
                                         "for white", "s", low=0.0, high=3600.0, reason="up to an hour's drift")
    gyro_noise_deg_s: float = param(IMU_GYRO_NOISE_DEG_S, "gyro white noise per axis and sample (1 sigma)",
                                    "deg/s", low=0.0, high=1.0, reason="MEMS to fibre-optic gyros: 0.001-0.1 deg/s")

    def check(self) -> None:
        try:
            self.ticks(CONTROL_DT)
        except PlanningError as e:
            raise ParamError(f"rate_hz / latency_s: {e}") from None

    def ticks(self, control_dt: float) -> tuple[int, int]:
        """(ticks per sample, latency in ticks); raises PlanningError if not whole numbers."""
        if not np.isfinite(self.rate_hz) or self.rate_hz <= 0:
            raise PlanningError(f"IMU rate {self.rate_hz!r} Hz must be > 0")
        if self.rate_hz < IMU_RATE_MIN_HZ:
            raise PlanningError(f"IMU rate {self.rate_hz:g} Hz is below {IMU_RATE_MIN_HZ:g} Hz, the "
                                "slowest the controller models (the paper's IMU: 20-50 Hz)")
        if not np.isfinite(self.latency_s):
            raise PlanningError(f"IMU latency {self.latency_s!r} s must be finite")
        if self.latency_s > IMU_LATENCY_MAX_S:
            raise PlanningError(f"IMU latency {self.latency_s:g} s is above {IMU_LATENCY_MAX_S:g} s, "
                                "the longest the controller models (a marine AHRS: a few to tens of ms)")
        period = 1.0 / (self.rate_hz * control_dt)
        latency = self.latency_s / control_dt
        if abs(period - round(period)) > 1e-9 or round(period) < 1:
            raise PlanningError(f"IMU rate {self.rate_hz:g} Hz is not the control rate "
                                f"{1 / control_dt:g} Hz divided by a whole number")
        if self.latency_s < 0 or abs(latency - round(latency)) > 1e-9:
            raise PlanningError(f"IMU latency {self.latency_s:g} s is not a whole number of "
                                f"{control_dt * 1e3:g} ms control ticks >= 0")
        return int(round(period)), int(round(latency))


def _exp_so3(rotvec) -> np.ndarray:
    """Rotation matrix of a rotation vector (3,) (MuJoCo's quaternion functions). Its angle
    sqrt((x^2 + y^2) + z^2) in floats: np.linalg.norm's sum of squares at a fifth of its cost."""
    quat = np.empty(4)
    x, y, z = np.asarray(rotvec, dtype=float).tolist()
    angle = math.sqrt(x * x + y * y + z * z)
    if angle < 1e-300:
        return np.eye(3)
    mujoco.mju_axisAngle2Quat(quat, np.array([x / angle, y / angle, z / angle]), angle)
    mat = np.empty(9)
    mujoco.mju_quat2Mat(mat, quat)
    return mat.reshape(3, 3)


def log_bytes_per_tick(imu: ImuModel = ImuModel(), drives: str = "ideal") -> float:
    """Bytes an antenna run keeps per control tick, in memory or on disk: the runner's log of
    the compiled model (4 planned joints); the deck drive's ship-motion reference (3 x 4, at
    the run's ticks) and its servo's set-points and feed-forward (4 + 4); once per IMU sample
    the task's record of the planner's updates (t, the 3 x 3 attitude, 4 angles, iterations,
    two flags) and the sample's noise (3 + 3, drawn for the whole run: sims.antenna.sensors);
    the ideal joint path every REFERENCE_DT (t, 4 angles, error, iterations, two flags, and its
    spline's 16 coefficients and breakpoint)."""
    period, _ = imu.ticks(CONTROL_DT)
    floats = (run_limits.runlog_floats_per_tick(_model(drives), 4) + 12 + 8 + (15 + 2 / 8 + 6) / period
              + (7 + 2 / 8 + 16 + 1) * CONTROL_DT / REFERENCE_DT)
    return run_limits.floats(floats)


#: The as-built pedestal (models/antenna/README.md "Drives as built"): each axis's reduction,
#: its transmission's stiffness at the axis (N m/rad), the gears' backlash (rad), bearing and
#: seal friction (N m), the axis encoders' count (rad), and the mast's bending mode (Hz, damping).
AXIS_RATIO = 100.0
BELT_STIFFNESS = 6.0e4
GEAR_STIFFNESS = 7.9e4
GEAR_BACKLASH = math.radians(3.0 / 60.0)
AXIS_FRICTION = 1.0
AXIS_ENCODER = 2.0 * math.pi / 2**17
MAST_MODE_HZ, MAST_DAMPING_RATIO = 30.0, 0.02
MAST_JOINTS = ("mast_x", "mast_y")


def axis_drive(nominal: mujoco.MjModel, name: str, friction: float = AXIS_FRICTION,
               plant: "AntennaPlant | None" = None):
    """The drive train of the antenna axis ``name`` as built (``sims.drives.DriveTrain``): its
    motor's rotor is the model's armature (J N^2), its loop gains and torque limit the model's
    drive's; azimuth through a belt, the others through gears with backlash. ``plant`` (None:
    nominal): its errors of the transmissions' stiffness, the gears' backlash and the motors'
    torque constant (which scales every force the drive makes, its loops' too)."""
    from sims.drives import DriveTrain

    joint, actuator = nominal.joint(name), nominal.actuator(name)
    belt = name == "azimuth"
    peak = float(actuator.forcerange[1])
    torque_constant = 0.1  # N m/A, a 100-200 W servo motor (assumption)
    drive = DriveTrain(
        ratio=AXIS_RATIO, rotor_inertia=float(nominal.dof_armature[joint.dofadr[0]]) / AXIS_RATIO**2,
        torque_constant=torque_constant, peak_current=peak / (torque_constant * AXIS_RATIO),
        continuous_current=0.5 * peak / (torque_constant * AXIS_RATIO), max_motor_speed=3000 * 2 * math.pi / 60,
        kp=float(actuator.gainprm[0]), kv=float(-actuator.biasprm[2]),
        stiffness=BELT_STIFFNESS if belt else GEAR_STIFFNESS, backlash=0.0 if belt else GEAR_BACKLASH,
        coulomb_friction=friction, encoder_resolution=AXIS_ENCODER)
    if plant is None:
        return drive
    return drive.with_errors(stiffness=plant.transmission_stiffness_error, backlash=plant.gear_backlash_error,
                             torque_constant=plant.torque_constant_error)


def as_built(spec: mujoco.MjSpec, nominal: mujoco.MjModel, friction: float = AXIS_FRICTION,
             plant: "AntennaPlant | None" = None) -> None:
    """Edit the antenna's MjSpec into the pedestal as built: the mast's bending at the pedestal
    (two hinges, ``MAST_JOINTS``, whose stiffness puts the mode at MAST_MODE_HZ against the
    antenna's inertia about them) and each axis's drive train (``axis_drive``); the home
    keyframe rebuilt for the joints added (the motors with their axes, the mast straight)."""
    from sims.drives import add_drive_train, keyframe_with_motors

    pedestal = spec.body("pedestal")
    for name, axis in zip(MAST_JOINTS, ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0])):
        pedestal.add_joint(name=name, type=mujoco.mjtJoint.mjJNT_HINGE, axis=axis)
    for name in JOINTS:
        add_drive_train(spec, name, name, axis_drive(nominal, name, friction, plant))
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    inertia = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, inertia)
    omega = 2.0 * math.pi * MAST_MODE_HZ
    for name in MAST_JOINTS:
        i = model.joint(name).dofadr[0]
        spec.joint(name).stiffness = [inertia[i, i] * omega**2, 0.0, 0.0]
        spec.joint(name).damping = [2.0 * MAST_DAMPING_RATIO * inertia[i, i] * omega, 0.0, 0.0]
    keyframe_with_motors(spec, nominal)  # the motors with their axes, the mast straight


@functools.lru_cache(maxsize=2)
def _model(drives: str = "ideal") -> mujoco.MjModel:
    """The nominal antenna with ``drives`` (``DRIVES``), compiled."""
    if drives == "ideal":
        return models.load("antenna")
    spec = mujoco.MjSpec.from_file(str(models.scene_path("antenna")))
    as_built(spec, models.load("antenna"))
    return spec.compile()


def satellite_of(params: "AntennaParams") -> tuple[float, float, float]:
    """(azimuth, elevation, polarization), rad: given, or from the satellite's orbital
    longitude and the ship's position (``look_angles``)."""
    if params.satellite_look is not None:
        return tuple(np.radians(params.satellite_look))
    return look_angles(np.radians(params.satellite_lon), np.radians(params.ship_lat), np.radians(params.ship_lon),
                       polarization=params.satellite_polarization)


#: Elevation of the satellite above the horizon, deg, below which no run is set up: a
#: ship's dish does not track lower (the sea, the superstructure and the atmosphere; an
#: assumption of a typical maritime VSAT terminal's 5 deg).
MIN_SATELLITE_ELEVATION_DEG = 5.0
#: How far the ship may sail during a run, m: the look angles are those of the start position,
#: and 5 km turn the local vertical by 0.045 deg (d / R_earth), under a quarter of the 0.2 deg
#: pointing limit.
MAX_SAILED_M = 5000.0
_ANGLE = run_limits.ANGLE


@dataclass(frozen=True)
class AntennaParams(ScenarioParams):
    """What both antenna runs share: the satellite, the ship's position and course, the IMU."""

    RENAMED = {"imu_rate": "imu.rate_hz", "imu_latency": "imu.latency_s",
               "imu_attitude_noise": "imu.attitude_noise_deg", "imu_attitude_noise_time": "imu.attitude_noise_time_s",
               "imu_gyro_noise": "imu.gyro_noise_deg_s"}

    satellite_lon: float | None = param(
        None, "the geostationary satellite's orbital longitude (east positive); none: satellite_look",
        "deg", low=-180.0, high=180.0, reason="a longitude", excludes=("satellite_look",))
    satellite_look: tuple[float, ...] | None = param(
        None, "the satellite's azimuth (from north, clockwise), elevation and polarization seen from "
        "the level ship; none: from satellite_lon", unit=("deg", "deg", "deg"), low=(-360.0, 0.0, -90.0),
        high=(360.0, 90.0, 90.0), reason="a direction above the horizon, a polarization angle", length=3,
        excludes=("satellite_lon",))
    satellite_polarization: str = param("horizontal", "the satellite's linear polarization (with satellite_lon)",
                                        choices=("horizontal", "vertical"))
    ship_lat: float = param(SHIP_LAT_DEG, "the ship's latitude (WGS84)", "deg", low=-90.0, high=90.0, reason="a latitude")
    ship_lon: float = param(SHIP_LON_DEG, "the ship's longitude (east positive)", "deg", low=-180.0, high=180.0,
                            reason="a longitude")
    ship_heading: float = param(0.0, "the ship's mean course, clockwise from north (compass)", **_ANGLE)
    imu: ImuModel = param(ImuModel(), "the pedestal IMU (sims.antenna.ImuModel: rate_hz, latency_s, "
                          "attitude_noise_deg, attitude_noise_time_s, gyro_noise_deg_s)")
    prediction: bool = param(True, "the controller predicts the IMU's latency away with its gyro")
    drives: str = param("as-built", "the pedestal's drives: as-built (motors, an azimuth belt, geared axes with backlash, "
                        "friction, the mast's 30 Hz bending, 17-bit axis encoders; models/antenna/README.md) or ideal "
                        "(one stiff servo per axis on a rigid mast)", choices=DRIVES)
    duration: float = param(SEA_DURATION_S, "simulated time", "s", low=CONTROL_DT, reason="at least one control tick (5 ms)")

    def check(self) -> None:
        if self.satellite_lon is None and self.satellite_look is None:
            raise ParamError("satellite_lon or satellite_look must be given")
        if self.satellite_lon is not None and self.satellite_look is not None:
            raise ParamError("give satellite_lon or satellite_look, not both")
        if self.satellite_lon is not None:
            try:
                _, el, _ = satellite_of(self)
            except PlanningError as e:
                raise ParamError(f"satellite_lon = {self.satellite_lon:g} deg: {e}") from None
            if np.degrees(el) < MIN_SATELLITE_ELEVATION_DEG:
                raise ParamError(
                    f"satellite_lon = {self.satellite_lon:g} deg is {np.degrees(el):.2f} deg above the horizon of "
                    f"a ship at ({self.ship_lat:g}, {self.ship_lon:g}) deg, below the {MIN_SATELLITE_ELEVATION_DEG:g} deg "
                    "a ship's dish tracks down to")
        elif self.satellite_look[1] < MIN_SATELLITE_ELEVATION_DEG:
            raise ParamError(f"satellite_look elevation = {self.satellite_look[1]:g} deg is below the "
                             f"{MIN_SATELLITE_ELEVATION_DEG:g} deg a ship's dish tracks down to")
        run_limits.check_duration(self.duration, CONTROL_DT, self.log_bytes_per_tick())

    def log_bytes_per_tick(self) -> float:
        return log_bytes_per_tick(self.imu, self.drives)


@dataclass(frozen=True)
class AntennaPaperParams(AntennaParams):
    """The paper's ship motion, eq. (15)-(16): sinusoidal heading, pitch and roll and a turn."""

    satellite_look: tuple[float, ...] | None = override(AntennaParams, "satellite_look", tuple(ant.PAPER_SATELLITE_DEG))
    heading_amplitude: float = param(40.0, "heading oscillation's amplitude", "deg", low=0.0, high=180.0,
                                     reason="half a turn either way")
    heading_period: float = param(300.0, "heading oscillation's period", "s", low=1.0, high=3600.0,
                                  reason="1 s to an hour")
    turn_rate: float = param(1.0, "the ship's steady turn", "deg/s", low=-10.0, high=10.0,
                             reason="a ship turns at most a few deg/s")
    pitch_amplitude: float = param(40.0, "pitch amplitude", "deg", low=0.0, high=60.0,
                                   reason="the paper's 40 deg is already beyond any ship; 60 deg is capsizing")
    pitch_period: float = param(8.0, "pitch period", "s", low=1.0, high=60.0, reason="ship motion periods")
    roll_amplitude: float = param(45.0, "roll amplitude", "deg", low=0.0, high=60.0,
                                  reason="the paper's 45 deg is already extreme; 60 deg is capsizing")
    roll_period: float = param(10.0, "roll period", "s", low=1.0, high=60.0, reason="ship motion periods")
    duration: float = param(PAPER_DURATION_S, "simulated time", "s", low=CONTROL_DT, reason="at least one control tick (5 ms)")



@dataclass(frozen=True)
class AntennaSeaParams(AntennaParams):
    """A JONSWAP sea through the ship's RAOs; the satellite by its orbital slot."""

    satellite_lon: float | None = override(AntennaParams, "satellite_lon", SATELLITE_LON_DEG)
    hs: float = param(SEA_HS_M, "significant wave height", "m", low=0.0, low_open=True, high=SEA_HS_MAX_M,
                      reason="WMO's record is 19.0 m; also no steeper than DNV-RP-C205 allows (checked with tp)")
    tp: float = param(SEA_TP_S, "spectral peak period", "s", low=SEA_TP_RANGE_S[0], high=SEA_TP_RANGE_S[1],
                      reason="wind seas and swell (Munk 1950)")
    gamma: float = param(3.3, "JONSWAP peak enhancement (1: Pierson-Moskowitz)", "", low=1.0, high=7.0,
                         reason="DNV-RP-C205's range of gamma")
    wave_heading: float = param(SEA_HEADING_DEG, "wave heading off the bow: 180 head seas, 90 beam seas from "
                                "starboard", **_ANGLE)
    ship_speed: float = param(0.0, "the ship's speed through the water (the sea is met at encounter frequencies)",
                              "m/s", low=0.0, high=15.0, reason="a fast container ship, 29 kn")

    def check(self) -> None:
        super().check()
        try:
            check_sea_state(self.hs, self.tp)
        except ValueError as e:
            raise ParamError(f"hs, tp: {e}") from None
        if self.ship_speed * self.duration > MAX_SAILED_M:
            raise ParamError(f"ship_speed = {self.ship_speed:g} m/s for {self.duration:g} s sails "
                             f"{self.ship_speed * self.duration / 1e3:.3g} km, more than the {MAX_SAILED_M / 1e3:g} km "
                             "over which the start position's look angles hold (0.045 deg)")


#: The bodies the antenna drives move (their masses are the README's assumptions); the
#: pedestal base is welded to the deck and the motors' armature is a separate, known value.
MOVING_BODIES = ("azimuth", "elevation", "cross_elevation", "polarization", "reflector")


@dataclass(frozen=True)
class AntennaPlant(PlantParams):
    """The antenna's plant uncertainty: how the real terminal differs from models/antenna and
    its IMU from the datasheet the controller is set up with (models/antenna/README.md,
    "Plant uncertainty").

    Where each one acts: ``mass_error``, ``imbalance_offset``, ``joint_friction`` and
    ``torque_limit_scale`` edit the MJCF (MjSpec) before compiling (``model``); ``imu_bias``
    is the IMU's true error in the task's sensor (``AntennaImu``), which the published
    SensorSpecs (the datasheet the controller reads) leave out. A run with a bias starts in
    steady tracking of what that IMU reports (``tracked_start``), as an antenna that has been
    tracking with it would; the checks still judge the true pointing.
    """

    AS_BUILT_FIELDS = ("transmission_stiffness_error", "gear_backlash_error", "torque_constant_error")

    mass_error: float = param(
        0.0, "error of the moving antenna parts' masses and inertias (azimuth, elevation, cross-elevation, "
        "polarization and reflector bodies, 98 kg) as a fraction; centres of mass unchanged", "fraction",
        low=-0.2, high=0.2, reason="the masses are assumptions for a 1 m class terminal (models/antenna/README.md); "
        "vendors' 100-150 kg span +/-20 % about 125 kg")
    imbalance_offset: tuple[float, ...] = param(
        (0.0, 0.0, 0.0), "shift of the polarization assembly's centre of mass (the polarization and reflector "
        "bodies, 33 kg), antenna frame (x_a, y_a, z_a = boresight); the model's residual is (2, 0, 3) mm", "mm",
        low=-10.0, high=10.0, length=3, reason="real pedestals are balanced to a few mm (models/antenna/README.md); "
        "10 mm is 3.2 N m of static torque, a third of the polarization drive's 10 N m")
    joint_friction: float = param(
        0.0, "Coulomb friction of each antenna axis' bearings, seals and cable wrap (the model has none)", "N m",
        low=0.0, high=5.0, reason="a few N m on real pedestals (models/antenna/README.md); at most half the smallest "
        "drive limit (polarization, 10 N m)")
    torque_limit_scale: float = param(
        1.0, "the antenna drives' torque limits as a fraction of their ratings (40, 15, 12, 10 N m)", "fraction",
        low=0.5, high=1.0, reason="the rating is what a drive guarantees; derating (heat, low supply voltage) only "
        "lowers it; half the rating is still 5-10 times the torque the CRR path needs (README)")
    transmission_stiffness_error: float = param(
        0.0, "as-built drives: every axis's belt or gear stiffness relative to the model's", "fraction",
        low=-0.3, high=0.3,
        reason="belt tension and catalogue rigidity figures spread by tens of %: +-30 % (assumption)")
    gear_backlash_error: float = param(
        0.0, "as-built drives: the geared axes' backlash relative to the model's 3 arcmin", "fraction",
        low=-1.0, high=2.0,
        reason="none (anti-backlash gears) to 9 arcmin (economy planetaries have up to 8-10 arcmin, "
               "models/antenna/README.md)")
    torque_constant_error: float = torque_constant_error("the axis motors")
    imu_bias: tuple[float, ...] = param(
        (0.0, 0.0, 0.0), "constant attitude error of the IMU (its AHRS's bias and its mounting misalignment), "
        "a rotation vector about the IMU axes (x starboard, y bow, z up)", "deg", low=-2.0, high=2.0, length=3,
        reason="marine AHRS: 0.01-0.1 deg in tilt, up to ~1 deg in heading (datasheets, assumed); 2 deg is a "
        "badly aligned installation")

    def bias_rotation(self) -> np.ndarray:
        """B = exp([imu_bias]x), (3, 3): measured attitude = true attitude B (world from IMU)."""
        return _exp_so3(np.radians(self.imu_bias))

    def model(self, drives: str = "ideal") -> mujoco.MjModel:
        """models/antenna/scene.xml with this plant's masses, balance, friction and torque
        limits (MjSpec): body_mass and body_inertia of MOVING_BODIES times (1 + mass_error)
        (explicit inertials with the same principal axes), body_ipos of the polarization and
        reflector bodies moved by imbalance_offset, dof_frictionloss of the four antenna joints
        = joint_friction, their drives' actuator_forcerange times torque_limit_scale. MuJoCo
        derives the rest (subtree masses, qM at qpos0) from them. With the as-built ``drives``
        the pedestal is then built (``as_built``), its axes' friction the model's plus
        joint_friction, on the motors, with this plant's errors of its transmissions' stiffness,
        the gears' backlash and the motors' torque constant."""
        nominal = _model()
        spec = mujoco.MjSpec.from_file(str(models.scene_path("antenna")))
        shift = np.asarray(self.imbalance_offset) * 1e-3  # m; the reflector's axes are the antenna frame's
        for body in MOVING_BODIES:
            set_inertial(spec, nominal, body, 1.0 + self.mass_error,
                         shift if body in ("polarization", "reflector") else None)
        for name in JOINTS:
            spec.joint(name).frictionloss = self.joint_friction
            actuator = spec.actuator(name)
            actuator.forcerange = nominal.actuator_forcerange[nominal.actuator(name).id] * self.torque_limit_scale
        if drives == "as-built":
            edited = spec.compile()
            as_built(spec, edited, AXIS_FRICTION + self.joint_friction, self)
        return spec.compile()
