"""dm_control Physics of the loader's scene (``LoaderPhysics``): its accessors, the model's load
with the payload's mass, and the plant's edits of its MjSpec (``apply_plant``, ``plant_chain``)."""

from __future__ import annotations

import copy
import dataclasses
import functools
import math
from dataclasses import dataclass

import mujoco
import numpy as np
from dm_control import mujoco as dm_mujoco

from planbench import models
from planbench.drives import (
    DriveTrain,
    add_drive_train,
    check_option,
    drive_coordinates,
    keyframe_with_motors,
    transmission_deflection,
)
from planbench.loader.collision import geoms_by_contype
from planbench.loader.params import LoaderPlant
from planbench.plant import set_inertial

#: Robot collision geoms have contype 1, obstacles (breechblock, seat ring, floor) contype 2.
ROBOT_CONTYPE = 1
OBSTACLE_CONTYPE = 2


#: The lightest shell the model carries, kg; lighter is none.
MIN_PAYLOAD_KG = 1e-6


@dataclass(frozen=True)
class Transmission:
    """One axis's transmission as built (models/loader/README.md "Drives as built").

    Attributes:
      kind: what it is, in words.
      ratio: motor rad per joint unit (rad/m for the slide's screw).
      stiffness: torsional (N m/rad) or axial (N/m) at the joint; inf: rigid.
      backlash: lost motion at the joint, rad or m.
      efficiency: of the reducer or screw.
      torque_constant: of the motor, N m/A.
    """

    kind: str
    ratio: float
    stiffness: float
    backlash: float
    efficiency: float
    torque_constant: float


_ARCMIN = math.radians(1.0 / 60.0)
#: Each axis's transmission: a preloaded ball screw on the rail (its axial mode, about 500 Hz
#: against the reflected rotor, lies far above the 10 Hz loop: rigid); RV cycloidal reducers on
#: the shoulder and elbow, Harmonic Drive strain-wave gears (no backlash) on the wrist.
TRANSMISSIONS = {
    "slide": Transmission(
        "ball screw 32 x 10 mm, preloaded, direct drive", 2.0 * math.pi / 0.010, math.inf, 0.0, 0.90, 1.0
    ),
    "shoulder": Transmission("RV cycloidal reducer (RV-320E class)", 120.0, 3.0e6, _ARCMIN, 0.85, 1.9),
    "elbow": Transmission("RV cycloidal reducer (RV-160E class)", 120.0, 1.5e6, _ARCMIN, 0.85, 1.9),
    "wrist_pitch": Transmission("strain-wave gear, size 50, ratio 50", 50.0, 2.8e5, 0.0, 0.75, 1.2),
    "wrist_yaw": Transmission("strain-wave gear, size 32, ratio 50", 50.0, 7.8e4, 0.0, 0.75, 0.6),
    "wrist_roll": Transmission("strain-wave gear, size 20, ratio 50", 50.0, 1.6e4, 0.0, 0.75, 0.3),
}
#: Coulomb friction and viscous friction at rated speed, each as a fraction of the axis's
#: peak torque (reducer, bearings, seals; assumption, models/loader/README.md).
COULOMB_FRACTION = 0.03
VISCOUS_FRACTION = 0.03
#: The motors' encoders (the arm has no joint-side encoders): counts per motor turn.
MOTOR_ENCODER_COUNTS = 2**20


def joint_drive(nominal: mujoco.MjModel, name: str, plant: LoaderPlant | None = None) -> DriveTrain:
    """The drive train of the loader's joint ``name`` as built (``TRANSMISSIONS``), with ``plant``'s
    errors of its friction, stiffness, backlash and torque constant. The motor's rotor is the
    model's armature (J N^2), the drive's loop gains, peak torque and rated speed the model's."""
    t = TRANSMISSIONS[name]
    joint, actuator = nominal.joint(name), nominal.actuator(name)
    peak = float(actuator.forcerange[1])
    rated_speed = float(actuator.ctrlrange[1])
    amps = 1.0 / (t.torque_constant * t.ratio * t.efficiency)  # A per N m (or N) at the joint
    drive = DriveTrain(
        ratio=t.ratio,
        rotor_inertia=float(nominal.dof_armature[joint.dofadr[0]]) / t.ratio**2,
        torque_constant=t.torque_constant,
        peak_current=peak * amps,
        continuous_current=0.5 * peak * amps,
        max_motor_speed=rated_speed * t.ratio,
        efficiency=t.efficiency,
        kp=float(actuator.gainprm[0]),
        kv=float(-actuator.biasprm[2]),
        stiffness=t.stiffness,
        backlash=t.backlash,
        coulomb_friction=COULOMB_FRACTION * peak,
        viscous_friction=VISCOUS_FRACTION * peak / rated_speed,
        encoder_resolution=2.0 * math.pi / MOTOR_ENCODER_COUNTS / t.ratio,
    )
    if plant is None:
        return drive
    return drive.with_errors(
        friction=plant.friction_error,
        stiffness=plant.reducer_stiffness_error,
        backlash=plant.backlash_error,
        torque_constant=plant.torque_constant_error,
    )


def as_built(spec: mujoco.MjSpec, nominal: mujoco.MjModel, plant: LoaderPlant | None = None) -> None:
    """Edit the loader's MjSpec into the arm as built: each joint's drive train (``joint_drive``),
    the home keyframe rebuilt for the motors' joints (each at its load's value)."""
    for name in models.loader_spec().names:
        add_drive_train(spec, name, name, joint_drive(nominal, name, plant))
    # The friction's constraint rows on 11 dofs: the dense Jacobian is the faster one (7.1 against
    # 7.7 us a step with MuJoCo's automatic choice, measured).
    spec.option.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
    keyframe_with_motors(spec, nominal)


class LoaderPhysics(dm_mujoco.Physics):
    """dm_control Physics of models/loader/scene.xml with readable accessors."""

    drives = "ideal"

    @classmethod
    def load(cls, payload_mass: float = None, plant: LoaderPlant | None = None, drives: str = "ideal") -> LoaderPhysics:
        """The scene at its home keyframe; ``payload_mass`` (kg, None: the model's 45 kg) scales
        the shell's geoms' masses, so its inertia scales with them (same shape and density
        distribution), edited with MjSpec before compiling. ``plant`` (None: the nominal
        plant): the true machine, perturbed as ``LoaderPlant`` says (``apply_plant``); its
        ``payload_mass_error`` makes the shell's true mass payload_mass (1 + error).
        ``drives`` (``planbench.drives.DRIVES``): the arm's drive trains as built (``as_built``) or the MJCF's
        ideal servos."""
        check_option(drives)
        nominal = plant is None or plant.is_nominal
        mass = shell_mass() if payload_mass is None else float(payload_mass)
        if not nominal:
            mass = mass * (1.0 + plant.payload_mass_error)
        if mass < MIN_PAYLOAD_KG:
            # MuJoCo cannot find the principal axes of geoms this light (their inertia's
            # eigenvalues round to zero): a shell under a milligram is no shell.
            mass = 0.0
        if nominal and drives == "ideal" and mass == shell_mass():
            physics = cls.from_xml_path(str(models.scene_path("loader")))
        else:
            # A copy: the cached model is shared, a run's physics is its own.
            physics = cls.from_model(
                dm_mujoco.wrapper.MjModel(copy.copy(_compiled(mass, None if nominal else plant, drives)))
            )
        physics.drives = drives
        physics.reset(keyframe_id=0)
        return physics

    def set_start(self, q: np.ndarray) -> None:
        """Joints at ``q`` (theta1 m, theta2 ... theta6 rad), at rest, and the drives' set-points
        where they hold them there: with drive trains as built each motor stands off its load
        by the deflection (and half the backlash) that carries the joint's static load, and
        the set-point off its motor by that load / kp."""
        self.named.data.qpos[self.joint_names] = q
        self.data.qvel[:] = 0.0
        self.data.act[:] = q
        if self.drives != "ideal":
            model, data = self.model.ptr, self.data.ptr
            motors, motor_dofs = self.drive_qpos, self.drive_dofs
            data.qpos[motors] = q
            mujoco.mj_forward(model, data)
            dofs = _joint_dofs(self)
            load = data.qfrc_bias[dofs]  # the static load at rest: gravity
            data.qpos[motors] = q + transmission_deflection(model, self.joint_names, load)
            mujoco.mj_forward(model, data)
            # The drive holds its motor's own load and, through a compliant transmission, the
            # joint's (a rigid one's motor is the joint).
            drive = data.qfrc_bias[motor_dofs] + np.where(motor_dofs != dofs, load, 0.0)
            gains = model.actuator_gainprm[self.actuator_ids, 0]
            data.act[model.actuator_actadr[self.actuator_ids]] = data.qpos[motors] + drive / gains
        self.forward()

    @property
    def joint_names(self) -> list[str]:
        return models.loader_spec().names

    def joint_positions(self) -> np.ndarray:
        """theta1 ... theta6: slide (m) and five angles (rad)."""
        return self.named.data.qpos[self.joint_names].copy()

    def joint_velocities(self) -> np.ndarray:
        return self.named.data.qvel[self.joint_names].copy()

    @property
    def actuator_ids(self) -> np.ndarray:
        """The drives of theta1 ... theta6."""
        return np.array([self.model.ptr.actuator(n).id for n in self.joint_names])

    @property
    def drive_qpos(self) -> np.ndarray:
        """qpos addresses of the coordinates the drives act on and their encoders read: each
        joint's motor (as built; the slide's rigid screw: the slide itself), else the joint."""
        return drive_coordinates(self.model.ptr, self.joint_names)[0]

    @property
    def drive_dofs(self) -> np.ndarray:
        return drive_coordinates(self.model.ptr, self.joint_names)[1]

    def setpoints(self) -> np.ndarray:
        """The drives' position set-points (their activations), m and rad."""
        return self.data.act.copy()

    def actuator_forces(self) -> np.ndarray:
        """Drive force (N) and torques (N m) after the force-range clamp."""
        return self.named.data.actuator_force[self.joint_names].copy()

    def shell_tip(self) -> np.ndarray:
        """World position of the shell's nose, m."""
        return self.named.data.site_xpos["shell_tip"].copy()

    def shell_tip_log(self, sensordata: np.ndarray) -> np.ndarray:
        """The ``shell_tip_pos`` sensor's columns of a logged sensordata array, m.

        MuJoCo evaluates sensors before integrating, so after ``mj_step`` they describe the
        state one physics step (0.5 ms) before the logged qpos.
        """
        sensor = self.model.ptr.sensor("shell_tip_pos")
        return sensordata[:, sensor.adr[0] : sensor.adr[0] + sensor.dim[0]]

    def robot_geoms(self) -> np.ndarray:
        return geoms_by_contype(self.model.ptr, ROBOT_CONTYPE)

    def obstacle_geoms(self) -> np.ndarray:
        return geoms_by_contype(self.model.ptr, OBSTACLE_CONTYPE)


@functools.lru_cache(maxsize=8)
def _compiled(mass: float, plant: LoaderPlant | None, drives: str) -> mujoco.MjModel:
    """The scene with a shell of ``mass`` kg, perturbed into ``plant`` (None: nominal), with
    ``drives`` (``DRIVES``), compiled. The drive trains are built from the nominal model (their
    gains and ratings the drives'), then the plant's edits apply on top."""
    spec = mujoco.MjSpec.from_file(str(models.scene_path("loader")))
    factor = mass / shell_mass()
    if factor != 1.0:
        for geom in spec.body("shell").find_all(mujoco.mjtObj.mjOBJ_GEOM):
            geom.mass = geom.mass * factor
    if drives == "as-built":
        as_built(spec, models.load("loader"), plant)
    if plant is not None:
        apply_plant(spec, plant)
    return spec.compile()


def joint_kinds() -> list[str]:
    return [j.kind for j in models.loader_spec().joints]


@functools.lru_cache(maxsize=1)
def shell_mass() -> float:
    """The model's shell (the payload body ``shell``), kg."""
    model = models.load("loader")
    return float(model.body_mass[model.body("shell").id])


def _joint_dofs(physics: LoaderPhysics) -> np.ndarray:
    model = physics.model.ptr
    return np.array([model.joint(n).dofadr[0] for n in physics.joint_names])


#: The arm's links, carriage to gripper: the bodies whose geoms' masses ``arm_mass_error``
#: scales (the shell is the payload, ``payload_mass_error``).
ARM_BODIES = ("carriage", "upper_arm", "forearm", "wrist_pitch_link", "wrist_yaw_link", "gripper")


def apply_plant(spec: mujoco.MjSpec, plant: LoaderPlant) -> None:
    """Edit the loader's MjSpec into the plant ``plant`` (all but the payload's mass, which
    ``LoaderPhysics.load`` scales). Each edit touches only its own elements:

    * arm_mass_error: the mass and inertia of every body of ``ARM_BODIES`` times (1 + error),
      its centre of mass and principal axes kept (``planbench.plant.set_inertial``);
    * upper_arm_length_error: the elbow axis (body ``forearm``) moved along the upper arm, m
      (the beam's geom and mass are left: a bore position error, not another beam);
    * joint_viscous_friction: each joint's damping (N s/m, N m s/rad) = fraction x its drive's
      rated force / rated speed, so the friction at rated speed is that fraction of the rating;
    * drive_force_scale: every drive's force range times the scale;
    * encoder_bias: the drives close their loop on the biased encoder, so the drive force is
      kp (set-point - (q + b)) - kv qdot: affine bias term biasprm[0] = -kp b.
    """
    chain = models.loader_spec()
    if plant.arm_mass_error:
        nominal = models.load("loader")  # the links' inertials as MuJoCo computes them from their geoms
        for name in ARM_BODIES:
            set_inertial(spec, nominal, name, 1.0 + plant.arm_mass_error)
    if plant.upper_arm_length_error:
        forearm = spec.body("forearm")
        forearm.pos = np.asarray(forearm.pos) + np.array([plant.upper_arm_length_error, 0.0, 0.0])
    bias = plant.encoder_bias_si()
    for j, name in enumerate(chain.names):
        if plant.joint_viscous_friction:
            joint = spec.joint(name)
            damping = np.array(joint.damping)
            damping[0] = plant.joint_viscous_friction * chain.force_limit[j] / chain.rate_limit[j]
            joint.damping = damping
        actuator = spec.actuator(name)
        if plant.drive_force_scale != 1.0:
            actuator.forcerange = plant.drive_force_scale * np.asarray(actuator.forcerange)
        if bias[j]:
            biasprm = np.array(actuator.biasprm)
            biasprm[0] = -actuator.gainprm[0] * bias[j]
            actuator.biasprm = biasprm


def plant_chain(plant: LoaderPlant | None = None) -> models.SerialChainSpec:
    """The plant's kinematic chain (``models.loader_spec()`` with its upper-arm length error),
    for the evaluation's shell tip: the checks judge the true machine."""
    chain = models.loader_spec()
    if plant is None or not plant.upper_arm_length_error:
        return chain
    bodies = tuple(
        dataclasses.replace(b, pos=b.pos + np.array([plant.upper_arm_length_error, 0.0, 0.0]))
        if b.name == "forearm"
        else b
        for b in chain.bodies
    )
    return dataclasses.replace(chain, bodies=bodies)
