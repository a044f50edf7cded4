"""The loader's scenario parameters (``LoaderParams``) and plant uncertainty (``LoaderPlant``),
with the control tick, the settle time and the log size per tick their checks need."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from planbench import models, run_limits
from planbench.drives import DRIVES, torque_constant_error
from planbench.params import PlantParams, ScenarioParams, param
from planbench.planners import loader as loader_planner

CONTROL_DT = 0.005  # s: 200 Hz motion controller; the drives run at the 0.5 ms physics step
SETTLE_S = 0.5  # s simulated after the plan ends, so the arrival is seen at rest


@functools.lru_cache(maxsize=2)
def log_bytes_per_tick(drives: str = "ideal") -> float:
    """Bytes a loader run preallocates per control tick: the runner's log of the compiled
    model with ``drives`` (6 planned joints) and the servo controller's set-points and
    feed-forward torques (6 + 6 doubles). The contact list of loader-direct (a few hundred
    ticks) is left out."""
    from planbench.loader.physics import LoaderPhysics  # the physics module imports this one

    model = LoaderPhysics.load(drives=drives).model.ptr
    return run_limits.floats(run_limits.runlog_floats_per_tick(model, 6) + 2 * 6)


_JOINTS = models.loader_spec()
#: Each key point column's range in Table 1's units (mm, deg): the model's joint ranges.
_KEY_LOW = tuple(float(v) for v in loader_planner.si_to_table1(_JOINTS.lower))
_KEY_HIGH = tuple(float(v) for v in loader_planner.si_to_table1(_JOINTS.upper))


@dataclass(frozen=True)
class LoaderParams(ScenarioParams):
    """A loader run: key points through the cubic B-spline, the payload, the run's length."""

    key_points: tuple[tuple[float, ...], ...] = param(
        tuple(tuple(float(v) for v in row) for row in loader_planner.TABLE1),
        "key points, one row per point: theta1 (mm), theta2 ... theta6 (deg), as Table 1; the first is the start pose",
        unit=("mm", "deg", "deg", "deg", "deg", "deg"),
        low=_KEY_LOW,
        high=_KEY_HIGH,
        reason="the joint ranges of models/loader/loader.xml",
        length=6,
        min_items=2,
        max_items=200,
    )
    key_interval: float = param(
        0.5,
        "time from one key point to the next (uniform, as Table 1)",
        "s",
        low=CONTROL_DT,
        high=60.0,
        reason="at least one control tick; a minute is longer than any loading stroke",
    )
    settle: float = param(
        SETTLE_S,
        "time simulated after the last key point, so the arrival is seen at rest",
        "s",
        low=0.0,
        high=60.0,
        reason="the drives settle in well under a second",
    )
    payload_mass: float = param(
        45.0,
        "mass of the shell in the gripper (its inertia scales with it)",
        "kg",
        low=0.0,
        high=90.0,
        reason="none to twice the 45 kg 155 mm shell the drives are sized for (models/loader/README.md)",
    )
    drives: str = param(
        "as-built",
        "the arm's drives: as-built (motors, a ball screw, RV and strain-wave reducers "
        "with their stiffness and backlash, friction, the motors' encoders; models/loader/README.md) "
        "or ideal (one stiff servo per joint)",
        choices=DRIVES,
    )
    duration: float | None = param(
        None,
        "simulated time; none: the key points' span plus the settle time",
        "s",
        low=CONTROL_DT,
        reason="at least one control tick (5 ms)",
    )

    def check(self) -> None:
        duration = (
            self.duration if self.duration is not None else (len(self.key_points) - 1) * self.key_interval + self.settle
        )
        run_limits.check_duration(duration, CONTROL_DT, self.log_bytes_per_tick())

    def log_bytes_per_tick(self) -> float:
        return log_bytes_per_tick(self.drives)


#: Each encoder's zero offset range, in Table 1's units (mm, deg).
_BIAS_UNITS = ("mm", "deg", "deg", "deg", "deg", "deg")
_BIAS_LIMIT = (1.0, 0.1, 0.1, 0.1, 0.1, 0.1)


@dataclass(frozen=True)
class LoaderPlant(PlantParams):
    """The loader as built, against its model (plant uncertainty, for campaigns).

    The paper gives no masses, dimensions or drive data: the nominal model's numbers are all
    assumptions (models/loader/README.md), and so are these ranges; each states its reasoning.
    The defaults are the nominal plant. The planner and the controller keep the nominal
    model; ``apply_plant`` edits the plant's MjSpec, the encoders take the bias.
    """

    payload_mass_error: float = param(
        0.0,
        "true shell mass relative to payload_mass (which the controller is told): m = payload_mass (1 + error); "
        "its inertia scales with it",
        "fraction",
        low=-0.1,
        high=0.1,
        reason="155 mm HE projectiles weigh 43-47 kg (+-4.4 % of 45 kg, models/loader/README.md); +-10 % "
        "also covers a fuze or projectile lot the loader was not told of (assumption)",
    )
    arm_mass_error: float = param(
        0.0,
        "mass (and inertia) of every arm link, carriage to gripper, relative to the model's",
        "fraction",
        low=-0.05,
        high=0.05,
        reason="welded beams and castings come within a few % of their drawing mass; +-5 % assumed (the "
        "link masses are themselves assumptions, models/loader/README.md)",
    )
    upper_arm_length_error: float = param(
        0.0,
        "error of the upper arm's shoulder-to-elbow axis distance (1.0 m in the model)",
        "m",
        low=-0.002,
        high=0.002,
        reason="a welded arm whose bores are machined after welding holds +-0.5 mm; +-2 mm allows an "
        "unmachined weldment (assumption)",
    )
    joint_viscous_friction: float = param(
        0.0,
        "viscous friction of every joint (reducer, bearings, seals): its force/torque at the drive's rated "
        "speed as a fraction of the drive's rated force/torque; the model has none",
        "fraction",
        low=0.0,
        high=0.1,
        reason="friction only takes energy (>= 0); servo gearboxes lose 5-10 % at rated speed (efficiency "
        "90-95 %): up to 10 %, all of it taken as viscous (assumption: no drive data are published)",
    )
    drive_force_scale: float = param(
        1.0,
        "every drive's force/torque limit relative to its rating (models/loader/README.md)",
        "fraction",
        low=0.5,
        high=1.0,
        reason="a drive delivers at most its rated force; down to half of it when derated (heat, a low DC bus, "
        "an aged motor); assumption",
    )
    AS_BUILT_FIELDS = ("friction_error", "reducer_stiffness_error", "backlash_error", "torque_constant_error")

    friction_error: float = param(
        0.0,
        "as-built drives: every axis's Coulomb and viscous friction relative to the model's",
        "fraction",
        low=-0.5,
        high=1.0,
        reason="reducer and seal friction varies with temperature, lubrication and load: half to twice the "
        "model's (assumption; a cold robot joint's friction is several times a warm one's, "
        "models/loader/README.md)",
    )
    reducer_stiffness_error: float = param(
        0.0,
        "as-built drives: every reducer's torsional stiffness relative to the model's",
        "fraction",
        low=-0.3,
        high=0.3,
        reason="catalogue rigidity figures are typical values; unit-to-unit and mounting spread +-30 % (assumption)",
    )
    backlash_error: float = param(
        0.0,
        "as-built drives: the RV reducers' lost motion relative to the model's 1 arcmin",
        "fraction",
        low=-1.0,
        high=2.0,
        reason="none (a preloaded reducer) to three times the catalogue's 1 arcmin (a worn one; assumption)",
    )
    torque_constant_error: float = torque_constant_error("the joint motors")
    encoder_bias: tuple[float, ...] = param(
        (0.0,) * 6,
        "zero offset of each drive's encoder, theta1 (mm), theta2 ... theta6 (deg): the drive and "
        "the controller read q + bias",
        unit=_BIAS_UNITS,
        low=tuple(-b for b in _BIAS_LIMIT),
        high=_BIAS_LIMIT,
        length=6,
        reason="the joints' zero (mastering) offsets of a calibrated arm, assumed within the 0.1 deg key-point "
        "limit and 1 mm of the slide's homing; no encoder data are published",
    )

    def encoder_bias_si(self) -> np.ndarray:
        """(6,) the encoder biases in joint units, m and rad."""
        return loader_planner.table1_to_si(np.array(self.encoder_bias))
