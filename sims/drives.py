"""Drive trains as built, in MuJoCo's own terms: motor, transmission, friction, the drive's
position and velocity loops, and its encoder.

A driven joint q (m or rad; the *load* side) gets a motor coordinate q_m on a dof of its own,
in the joint's units: the motor's angle divided by the transmission ratio N (motor rad per
joint unit; 2 pi / lead for a ball screw, the gear ratio for a reducer). On that dof:

* the rotor's inertia reflected through the transmission, ``armature`` = J_m N^2
  (kg or kg m^2): the kinetic energy J_m (N qdot_m)^2 / 2 written in the joint's units;
* the friction of the motor, screw or gears, referred to the joint: ``frictionloss`` (Coulomb,
  N or N m; MuJoCo's dry friction, a constraint) and ``damping`` (viscous, N s/m or N m s/rad);
* the drive's force: the actuator moves from q to q_m, its force (motor torque x N x
  efficiency) clamped to the motor's peak (``forcerange``).

A fixed tendon q - q_m with the transmission's stiffness and damping carries the force to the
joint (MuJoCo's passive tendon spring, integrated with the rest of the physics); its
``springlength`` is the dead band [-b/2, b/2] of a backlash b: no force while the teeth are
apart. A rigid transmission (``stiffness`` = inf) has no tendon: then the motor's inertia and
friction go on q itself and the actuator stays there.

The drive's loops. The actuator keeps the position set-point s in its activation (the
integrator the controller's set-point rate feeds, as with the ideal drives) and applies
kp (s - q_m) - kv qdot_m: the position loop's proportional gain and the velocity loop's, on the
motor's encoder, at every physics step. ``servo_gains`` sets them from the loop's closed-loop
bandwidth and damping against the inertia it moves. Each MuJoCo step is one sample of the
drive's loops; the current loop, kilohertz-fast in every drive here, is taken as ideal (a
torque that follows its demand within the step).

The encoder the controller reads (``planbench.task.JointEncoders``' ``resolution``) counts in
steps of ``encoder_resolution``: the load's position where the machine has an encoder on the
load (the hexapod's struts, the antenna's axes), the motor's over N where it has motor encoders
only (the loader).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import mujoco
import numpy as np

from planbench.params import param
from planbench.planners.errors import LimitError

#: Mass and inertia of a motor body (kg, kg m^2): the rotor's inertia is the dof's armature;
#: MuJoCo needs a moving body to have some mass of its own.
ROTOR_BODY_MASS = 1e-3
ROTOR_BODY_INERTIA = 1e-6

#: Name suffixes of the elements a drive train adds for a joint NAME: its motor's joint and body,
#: and the transmission's tendon.
MOTOR_SUFFIX = "_motor"
TRANSMISSION_SUFFIX = "_transmission"

#: A mechanism's ``drives`` option: its drive trains as built, or the MJCF's ideal servos.
DRIVES = ("as-built", "ideal")


def check_option(drives: str) -> str:
    """``drives`` if it is one of ``DRIVES``, else a LimitError naming it."""
    if drives not in DRIVES:
        raise LimitError(f"drives = {drives!r} is not one of {', '.join(DRIVES)}")
    return drives


@dataclass(frozen=True)
class DriveTrain:
    """One axis's drive train, in the driven joint's units (m or rad, N or N m).

    Attributes:
      ratio: N, motor rad per joint unit (2 pi / lead for a ball screw, rad/m).
      rotor_inertia: J_m, the motor's rotor with what turns at its speed (brake, encoder,
        screw or gear input), kg m^2.
      torque_constant: K_t, N m/A.
      peak_current, continuous_current: the drive's and motor's current limits, A.
      max_motor_speed: rad/s.
      efficiency: of the transmission (the motor's torque that reaches the joint).
      stiffness: of the transmission at the joint, N/m or N m/rad; inf: rigid.
      transmission_damping: its structural damping at the joint, N s/m or N m s/rad.
      backlash: the total dead band at the joint, m or rad.
      coulomb_friction: at the joint, N or N m.
      viscous_friction: at the joint, N s/m or N m s/rad.
      kp, kv: the drive's position and velocity loop gains as stiffness and damping at the
        joint (N/m, N s/m or N m/rad, N m s/rad).
      encoder_resolution: the load encoder's count, m or rad; 0: exact.
    """

    ratio: float
    rotor_inertia: float
    torque_constant: float
    peak_current: float
    continuous_current: float
    max_motor_speed: float
    kp: float
    kv: float
    efficiency: float = 1.0
    stiffness: float = math.inf
    transmission_damping: float = 0.0
    backlash: float = 0.0
    coulomb_friction: float = 0.0
    viscous_friction: float = 0.0
    encoder_resolution: float = 0.0

    @property
    def reflected_inertia(self) -> float:
        """J_m N^2: the rotor's inertia seen at the joint, kg or kg m^2."""
        return self.rotor_inertia * self.ratio**2

    @property
    def peak_force(self) -> float:
        """K_t I_peak N eta: the largest force at the joint, N or N m."""
        return self.torque_constant * self.peak_current * self.ratio * self.efficiency

    @property
    def continuous_force(self) -> float:
        """K_t I_cont N eta, N or N m."""
        return self.torque_constant * self.continuous_current * self.ratio * self.efficiency

    @property
    def max_speed(self) -> float:
        """The joint's speed at the motor's limit, m/s or rad/s."""
        return self.max_motor_speed / self.ratio

    @property
    def rigid(self) -> bool:
        return math.isinf(self.stiffness)

    def with_errors(
        self, friction: float = 0.0, stiffness: float = 0.0, backlash: float = 0.0, torque_constant: float = 0.0
    ) -> DriveTrain:
        """This drive train as a plant off its datasheet: its Coulomb and viscous friction, its
        transmission's stiffness, its backlash and its motor's torque constant each times
        (1 + error). A torque constant off by e scales every force the drive makes: its loops'
        gains and its peak (the drive's current limit stays)."""
        torque = 1.0 + torque_constant
        return dataclasses.replace(
            self,
            coulomb_friction=self.coulomb_friction * (1.0 + friction),
            viscous_friction=self.viscous_friction * (1.0 + friction),
            stiffness=self.stiffness * (1.0 + stiffness),
            backlash=self.backlash * (1.0 + backlash),
            torque_constant=self.torque_constant * torque,
            kp=self.kp * torque,
            kv=self.kv * torque,
        )


def torque_constant_error(motors: str):
    """The plant-uncertainty field (``planbench.params.param``) of the torque constant of
    ``motors`` (in words) against their datasheet's, for ``DriveTrain.with_errors``."""
    return param(
        0.0,
        f"as-built drives: {motors}' torque constant relative to the datasheet's (every force the "
        "drive makes scales with it)",
        "fraction",
        low=-0.1,
        high=0.1,
        reason="motor datasheets give K_t to +-10 % (assumption; magnet temperature and tolerance)",
    )


def servo_gains(inertia: float, bandwidth_hz: float, damping_ratio: float) -> tuple[float, float]:
    """(kp, kv) of a position loop that makes ``inertia`` (kg or kg m^2) a second-order system
    of natural frequency ``bandwidth_hz`` and damping ratio ``damping_ratio``:
    kp = m w^2, kv = 2 zeta m w (m qddot + kv qdot + kp q = kp s)."""
    omega = 2.0 * math.pi * bandwidth_hz
    return inertia * omega**2, 2.0 * damping_ratio * inertia * omega


def add_drive_train(spec: mujoco.MjSpec, joint: str, actuator: str, drive: DriveTrain) -> None:
    """Edit ``spec`` so that ``actuator`` drives ``joint`` through ``drive`` (module doc).

    The motor's body is a sibling of the joint's body (same parent, same frame: the motor
    sits on the link before the joint), its joint of the same type along the same axis,
    named ``joint + MOTOR_SUFFIX``; the tendon ``joint + TRANSMISSION_SUFFIX``. The
    actuator's gains become the drive's kp, kv (its affine bias: kp (s - q_m) - kv qdot_m)
    and its force range the motor's peak force.
    """
    load = spec.joint(joint)
    act = spec.actuator(actuator)
    target = load
    if not drive.rigid:
        body = load.parent
        rotor = body.parent.add_body(
            name=joint + MOTOR_SUFFIX,
            pos=body.pos,
            quat=body.quat,
            mass=ROTOR_BODY_MASS,
            inertia=[ROTOR_BODY_INERTIA] * 3,
        )
        target = rotor.add_joint(name=joint + MOTOR_SUFFIX, type=load.type, axis=load.axis, pos=load.pos)
        load.armature = 0.0
        load.frictionloss = 0.0
        load.damping = [0.0, 0.0, 0.0]
        # MjSpec's stiffness and damping are polynomials (linear, quadratic, cubic terms).
        tendon = spec.add_tendon(
            name=joint + TRANSMISSION_SUFFIX,
            stiffness=[drive.stiffness, 0.0, 0.0],
            damping=[drive.transmission_damping, 0.0, 0.0],
            springlength=[-0.5 * drive.backlash, 0.5 * drive.backlash],
        )
        tendon.wrap_joint(joint, 1.0)
        tendon.wrap_joint(joint + MOTOR_SUFFIX, -1.0)
        act.target = target.name
    target.armature = drive.reflected_inertia
    target.frictionloss = drive.coulomb_friction
    target.damping = [drive.viscous_friction, 0.0, 0.0]
    gain, bias = np.array(act.gainprm), np.array(act.biasprm)
    gain[0], bias[1], bias[2] = drive.kp, -drive.kp, -drive.kv
    act.gainprm, act.biasprm = gain, bias
    act.forcerange = [-drive.peak_force, drive.peak_force]


def motor_joint(model: mujoco.MjModel, joint: str) -> int:
    """The id of the joint whose dof the drive of ``joint`` acts on: its motor's joint with a
    compliant transmission, else the joint itself."""
    try:
        return model.joint(joint + MOTOR_SUFFIX).id
    except KeyError:
        return model.joint(joint).id


def load_joint(model: mujoco.MjModel, actuator_id: int) -> int:
    """The id of the joint an actuator finally moves: the load joint of a motor's joint (name
    ``JOINT + MOTOR_SUFFIX``), else the actuator's own joint."""
    joint = int(model.actuator_trnid[actuator_id, 0])
    name = model.joint(joint).name
    if name.endswith(MOTOR_SUFFIX):
        return model.joint(name[: -len(MOTOR_SUFFIX)]).id
    return joint


def drive_coordinates(model: mujoco.MjModel, joints) -> tuple[np.ndarray, np.ndarray]:
    """(qpos addresses, dof addresses) of the coordinates the drives of ``joints`` (names) act
    on and their loops read: each one's motor (``motor_joint``)."""
    ids = [motor_joint(model, name) for name in joints]
    return model.jnt_qposadr[ids].copy(), model.jnt_dofadr[ids].copy()


def _transmission(model: mujoco.MjModel, joint: str) -> int | None:
    try:
        return model.tendon(joint + TRANSMISSION_SUFFIX).id
    except KeyError:
        return None


def transmission_stiffness(model: mujoco.MjModel, joint: str) -> float:
    """The stiffness of the tendon between ``joint`` and its motor, N/m or N m/rad (inf: none)."""
    tendon = _transmission(model, joint)
    return math.inf if tendon is None else float(model.tendon_stiffness[tendon])


def transmission_deflection(model: mujoco.MjModel, joints, force: np.ndarray) -> np.ndarray:
    """(..., n) how far each motor stands off its load (q_m - q, m or rad) when its transmission
    carries ``force`` (..., n) to the load (N or N m; the load's qfrc): f / k, plus half the
    backlash in the direction of f (the teeth in contact); 0 through a rigid transmission."""
    tendons = [_transmission(model, name) for name in joints]
    stiffness = np.array([math.inf if t is None else model.tendon_stiffness[t] for t in tendons])
    half_band = np.array([0.0 if t is None else model.tendon_lengthspring[t, 1] for t in tendons])
    return force / stiffness + np.sign(force) * half_band


def keyframe_with_motors(spec: mujoco.MjSpec, nominal: mujoco.MjModel) -> None:
    """Rebuild ``spec``'s ``home`` keyframe for the joints its drive trains (and any other
    edit) added: every joint of ``nominal`` at its value in ``nominal``'s first keyframe, each
    motor at its load's, the added joints otherwise at their qpos0. Compiles ``spec``."""
    model = spec.compile()
    qpos = model.qpos0.copy()
    for j in range(nominal.njnt):
        name = nominal.joint(j).name
        value = nominal.key_qpos[0][nominal.jnt_qposadr[j] : nominal.jnt_qposadr[j] + _QPOS_SIZE[nominal.jnt_type[j]]]
        for target in {model.joint(name).id, motor_joint(model, name)}:
            adr = model.jnt_qposadr[target]
            qpos[adr : adr + value.size] = value
    spec.key("home").qpos = qpos


#: qpos values per joint type (free, ball, slide, hinge).
_QPOS_SIZE = {
    int(mujoco.mjtJoint.mjJNT_FREE): 7,
    int(mujoco.mjtJoint.mjJNT_BALL): 4,
    int(mujoco.mjtJoint.mjJNT_SLIDE): 1,
    int(mujoco.mjtJoint.mjJNT_HINGE): 1,
}
