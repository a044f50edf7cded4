"""The hexapod's parameters: a run's (``HexapodParams``: the start pose, the moves, each a
``HexapodMove``, the dwell, the elevation, the wind, the duration) and the plant's
(``HexapodPlant``: the machine as built against its model), with the constants they need and
the parameters' pose units (``pose_si``, ``pose_mm_deg``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from planbench import run_limits
from planbench.drives import DRIVES, torque_constant_error
from planbench.hexapod.physics import DEFAULT_ELEVATION_DEG, ELEVATION_RANGE_DEG, _radial, log_bytes_per_tick
from planbench.params import ParamError, Params, PlantParams, ScenarioParams, param
from planbench.planners import hexapod as hexapod_planner
from planbench.planners.errors import LimitError
from planbench.planners.hexapod import RUBIN_CAMERA, RUBIN_LIMITS
from planbench.wind import MEAN_SPEED

CONTROL_DT = hexapod_planner.CONTROL_DT  # s: the generator's and the controller's 200 Hz
SETTLE_S = 1.0  # s simulated after the move: the integral action settles in ~0.5 s

#: The moves: a few mm and ~0.1 deg, inside the pose limits and the stroke (m, rad).
#: In the parameters' units, x, y, z mm and rx, ry, rz deg.
SYNC_TARGET_MM_DEG = (1.5, -1.0, 0.8, 0.10, -0.05, 0.03)
ASYNC_TARGET_MM_DEG = (-2.0, 1.5, -1.0, -0.05, 0.10, -0.05)
#: Default mean wind on the camera, m/s: an assumption for the air inside a dome with its
#: wind screen up (a fraction of the 10-15 m/s outside at which telescopes still observe);
#: the tests also run 10 m/s.
DEFAULT_WIND_M_S = 5.0


def pose_si(pose_mm_deg) -> np.ndarray:
    """Poses (..., 6) in the parameters' units (x, y, z mm; rx, ry, rz deg) in m and rad."""
    pose = np.asarray(pose_mm_deg, dtype=float)
    return np.concatenate([pose[..., :3] / 1000.0, np.radians(pose[..., 3:])], axis=-1)


def pose_mm_deg(pose_si) -> tuple:
    pose = np.asarray(pose_si, dtype=float)
    return tuple(float(v) for v in np.concatenate([pose[:3] * 1000.0, np.degrees(pose[3:])]))


_POSE_UNITS = ("mm", "mm", "mm", "deg", "deg", "deg")
_POSE_LOW = pose_mm_deg(RUBIN_LIMITS.pose_lower)
_POSE_HIGH = pose_mm_deg(RUBIN_LIMITS.pose_upper)
_POSE_REASON = "Rubin's pose limits per axis (REFERENCE.md); the struts' stroke is checked too"


@dataclass(frozen=True)
class HexapodMove(Params):
    """One move of a hexapod run."""

    target: tuple[float, ...] = param(
        (0.0,) * 6,
        "target pose x, y, z (mm), rx, ry, rz (deg) of the mirror-side pivot frame",
        unit=_POSE_UNITS,
        low=_POSE_LOW,
        high=_POSE_HIGH,
        reason=_POSE_REASON,
        length=6,
    )
    synchronous: bool = param(True, "all six struts arrive on the same tick (false: each at its own minimum time)")

    def check(self) -> None:
        _check_pose(self.target, "target")


def _check_pose(pose, key: str) -> None:
    si = pose_si(pose)
    try:
        hexapod_planner.check_pose_limits(si, what=key)
        hexapod_planner.check_stroke(hexapod_planner.strut_positions(np.atleast_2d(si)), what=key)
    except LimitError as e:
        raise ParamError(str(e)) from None


@dataclass(frozen=True)
class HexapodParams(ScenarioParams):
    """A hexapod run: moves one after another from a start pose, at an elevation, in wind."""

    start_pose: tuple[float, ...] = param(
        (0.0,) * 6,
        "start pose x, y, z (mm), rx, ry, rz (deg); the hexapod starts there at rest",
        unit=_POSE_UNITS,
        low=_POSE_LOW,
        high=_POSE_HIGH,
        reason=_POSE_REASON,
        length=6,
    )
    moves: tuple[HexapodMove, ...] = param(
        (HexapodMove(),),
        "the moves, one after another: [[moves]] tables of target and synchronous",
        min_items=1,
        max_items=100,
        reason="at least one move; a hundred fill a night",
    )
    dwell: float = param(
        SETTLE_S,
        "time from the tick one move's trajectory ends on to the next move's start (on the first tick after it)",
        "s",
        low=SETTLE_S,
        high=600.0,
        reason="each arrival is judged after the integral action's 1 s of settling",
    )
    elevation: float = param(
        DEFAULT_ELEVATION_DEG,
        "telescope elevation: gravity's direction in the hexapod frame",
        "deg",
        low=ELEVATION_RANGE_DEG[0],
        high=ELEVATION_RANGE_DEG[1],
        reason="the telescope's elevation range",
    )
    wind: float = param(DEFAULT_WIND_M_S, "mean wind on the camera (Kaimal turbulence), 0 for none", **MEAN_SPEED)
    drives: str = param(
        "as-built",
        "the struts' drives: as-built (motor, gearbox, ball screw, friction, the drive's "
        "loops, a counting encoder; models/hexapod/README.md) or ideal (one stiff servo per strut)",
        choices=DRIVES,
    )
    duration: float | None = param(
        None,
        "simulated time; none: to the tick the last move's trajectory ends on, plus 1 s of settling",
        "s",
        low=CONTROL_DT,
        reason="at least one control tick (5 ms)",
    )

    def check(self) -> None:
        _check_pose(self.start_pose, "start_pose")
        previous = self.start_pose
        for i, move in enumerate(self.moves):
            # Compared in strut space, to the last bit: a pose change below the struts' round-off
            # (rz = 5e-222 deg, found by hypothesis) moves no strut, and a plan of it has no length.
            struts = hexapod_planner.strut_positions(np.array([pose_si(previous), pose_si(move.target)]))
            if np.array_equal(struts[0], struts[1]):
                raise ParamError(
                    f"moves[{i}].target equals the pose before it (no strut length changes): a move of zero length"
                )
            previous = move.target
        if self.duration is not None:
            run_limits.check_duration(self.duration, CONTROL_DT, self.log_bytes_per_tick())

    def log_bytes_per_tick(self) -> float:
        return log_bytes_per_tick(self.wind > 0, self.drives)


@dataclass(frozen=True)
class HexapodPlant(PlantParams):
    """The camera hexapod as built, against its model (plant uncertainty, for campaigns).

    The defaults are the nominal plant (models/hexapod/README.md). The planner and the
    controller keep the nominal model; ``apply_plant`` edits the plant's MjSpec, the encoders
    take the bias, ``geometry`` gives the plant's pivots (for its start and the video).
    """

    AS_BUILT_FIELDS = ("friction_error", "screw_stiffness_error", "torque_constant_error")

    camera_mass_error: float = param(
        0.0,
        "true camera mass relative to the model's 3000 kg (its inertia scales with it)",
        "fraction",
        low=-0.1,
        high=0.1,
        reason="LSSTCam is 'about 3 t' (REFERENCE.md): +-10 % bounds that rounded figure (assumption)",
    )
    camera_com_offset: tuple[float, ...] = param(
        (0.0, 0.0, 0.0),
        "offset of the camera's centre of mass from its axis and mid-length, x, y, z in the "
        "hexapod frame (its mass and central inertia kept)",
        "m",
        low=-0.05,
        high=0.05,
        length=3,
        reason="the camera's uniform density is an assumption (models/hexapod/README.md); its mass centre is "
        "taken as known to +-50 mm per axis (cabling, cryostat, filter exchanger; assumption)",
    )
    base_pivot_radius_error: float = param(
        0.0,
        "radial error of the six base pivots (their circle's radius, 0.692 m, is this much larger)",
        "m",
        low=-0.001,
        high=0.001,
        reason="machining and assembly of the pivot circles before a kinematic calibration, assumed +-1 mm; "
        "ts_mthexapod's constants.py gives the calibrated pivots to 1 um",
    )
    platform_pivot_radius_error: float = param(
        0.0,
        "radial error of the six mirror-side pivots (their circle's radius, 0.697 m, is this much larger)",
        "m",
        low=-0.001,
        high=0.001,
        reason="machining and assembly of the pivot circles before a kinematic calibration, assumed +-1 mm; "
        "ts_mthexapod's constants.py gives the calibrated pivots to 1 um",
    )
    drive_stiffness_error: float = param(
        0.0,
        "every strut drive's servo stiffness kp relative to the model's (ideal drives: servo and axial, "
        "100 N/um; as built: the position loop's 96.8 N/um)",
        "fraction",
        low=-0.3,
        high=0.3,
        reason="the 100 N/um is an order-of-magnitude assumption (models/hexapod/README.md); ball-screw "
        "preload, bearings and the flexures spread it by tens of %: +-30 % assumed",
    )
    drive_force_scale: float = param(
        1.0,
        "every strut drive's force limit relative to its 50 kN rating",
        "fraction",
        low=0.5,
        high=1.0,
        reason="a drive delivers at most its rated force; down to half of it when derated (heat, a low DC "
        "bus); assumption",
    )
    friction_error: float = param(
        0.0,
        "as-built drives: every strut's Coulomb and viscous friction relative to the model's",
        "fraction",
        low=-0.5,
        high=1.0,
        reason="ball-screw preload drag and gearbox losses vary with preload, lubrication and temperature: "
        "half to twice the model's (assumption; models/hexapod/README.md)",
    )
    screw_stiffness_error: float = param(
        0.0,
        "as-built drives: every strut's axial stiffness (screw, nut, bearings, gearbox) relative to the model's",
        "fraction",
        low=-0.3,
        high=0.3,
        reason="preload and bearing spread of catalogue rigidity figures, +-30 % (assumption)",
    )
    torque_constant_error: float = torque_constant_error("the strut motors")
    encoder_bias_um: tuple[float, ...] = param(
        (0.0,) * 6,
        "zero offset of each strut's encoder, strut1 ... strut6: the drive and the controller read q + bias",
        "um",
        low=-10.0,
        high=10.0,
        length=6,
        reason="a strut's length calibration, assumed within 10 um (ten times the 1 um end-of-move error); "
        "the encoders resolve 0.1 um (REFERENCE.md: 10 counts/um)",
    )

    def encoder_bias_si(self) -> np.ndarray:
        """(6,) the encoder biases, m."""
        return 1e-6 * np.array(self.encoder_bias_um)

    def geometry(self) -> hexapod_planner.HexapodGeometry:
        """The plant's pivots: RUBIN_CAMERA's with the radial errors (hexapod frame, zero pose;
        the mirror-side pivots' x, y there are those in the platform frame, which the rotation
        pivot on the axis leaves)."""
        if not (self.base_pivot_radius_error or self.platform_pivot_radius_error):
            return RUBIN_CAMERA
        base = np.array([_radial(p, self.base_pivot_radius_error) for p in RUBIN_CAMERA.base_pivots])
        platform = np.array([_radial(p, self.platform_pivot_radius_error) for p in RUBIN_CAMERA.platform_pivots])
        return hexapod_planner.HexapodGeometry(base, platform, RUBIN_CAMERA.rotation_pivot)
