"""The hexapod's physics: the scene compiled at a telescope elevation, the plant edits, and
the dm_control Physics of the hexapod with its accessors.

The hexapod frame is the model's body ``top_end`` (models/hexapod/hexapod.xml); the model is
recompiled per elevation with the top end tilted (MjSpec, ``_spec``), so gravity stays the
world's -z. ``apply_plant`` edits the MjSpec into a perturbed plant (``HexapodPlant``,
sims/hexapod/params.py); ``HexapodPhysics.load`` loads either at its home keyframe.
"""

from __future__ import annotations

import copy
import functools
import math
from typing import TYPE_CHECKING

import mujoco
import numpy as np
from dm_control import mujoco as dm_mujoco
from scipy.spatial.transform import Rotation

from planbench import models, run_limits
from planbench.drives import (
    DriveTrain,
    add_drive_train,
    check_option,
    drive_coordinates,
    servo_gains,
    transmission_deflection,
)
from planbench.planners import hexapod as hexapod_planner
from planbench.planners.errors import LimitError
from planbench.planners.hexapod import RUBIN_CAMERA, STRUT_LABELS
from planbench.planners.rotations import wxyz
from planbench.plant import set_inertial
from planbench.runner import RunLog

if TYPE_CHECKING:  # annotations only: sims/hexapod/params.py imports this module
    from planbench.hexapod.params import HexapodPlant

ELEVATION_RANGE_DEG = (15.0, 90.0)
DEFAULT_ELEVATION_DEG = 45.0


def top_end_rotation(elevation_deg: float) -> np.ndarray:
    """Orientation of the hexapod frame in the world at a telescope elevation (deg).

    +z (base to mirror side, toward the primary) points along (0, cos El, -sin El): down at the
    zenith, horizontal at El = 0; +y = (0, sin El, cos El); +x = y x z = (-1, 0, 0).
    """
    el = np.radians(elevation_deg)
    x = np.array([-1.0, 0.0, 0.0])
    y = np.array([0.0, np.sin(el), np.cos(el)])
    z = np.array([0.0, np.cos(el), -np.sin(el)])
    return np.column_stack([x, y, z])


def check_elevation(elevation_deg: float) -> float:
    """The elevation (deg) if the telescope can point there, else a LimitError (bad input)."""
    lo, hi = ELEVATION_RANGE_DEG
    if not np.isfinite(elevation_deg) or not lo <= elevation_deg <= hi:
        raise LimitError(f"elevation {elevation_deg!r} deg is outside the telescope's range [{lo:g}, {hi:g}] deg")
    return float(elevation_deg)


#: One strut's drive train as built (models/hexapod/README.md "Drives as built" gives each
#: number's source or assumption): a brushless servo motor through a 10:1 precision planetary
#: gearbox on a 40 x 10 mm ball screw, N = 2 pi 10 / 0.01 m = 6283 rad/m; the nut, the screw
#: shaft and the support bearings in series as one axial stiffness; the drive's position and
#: velocity loops (a 20 Hz, zeta 0.7 position loop against the reflected rotor and a strut's
#: share of the payload).
STRUT_RATIO = 2.0 * math.pi * 10.0 / 0.010
STRUT_ROTOR_INERTIA = 4e-4  # kg m^2
STRUT_EFFICIENCY = 0.97 * 0.9  # the planetary stage's and the ball screw's
STRUT_TORQUE_CONSTANT = 0.9  # N m/A
STRUT_LOOP_INERTIA = STRUT_ROTOR_INERTIA * STRUT_RATIO**2 + 1000.0  # kg: rotor + a strut's share
STRUT_KP, STRUT_KV = servo_gains(STRUT_LOOP_INERTIA, 20.0, 0.7)
#: The drive's current limits, set to the strut's 50 kN rating and a 40 kN continuous load, A.
_AMPS_PER_NEWTON = 1.0 / (STRUT_TORQUE_CONSTANT * STRUT_RATIO * STRUT_EFFICIENCY)
STRUT_DRIVE = DriveTrain(
    ratio=STRUT_RATIO,
    rotor_inertia=STRUT_ROTOR_INERTIA,
    torque_constant=STRUT_TORQUE_CONSTANT,
    peak_current=50e3 * _AMPS_PER_NEWTON,
    continuous_current=40e3 * _AMPS_PER_NEWTON,
    max_motor_speed=6000 * 2 * math.pi / 60,
    efficiency=STRUT_EFFICIENCY,
    stiffness=2.8e8,
    coulomb_friction=1300.0,
    viscous_friction=2.0e4,
    kp=STRUT_KP,
    kv=STRUT_KV,
    encoder_resolution=50e-9,
)
#: Bending stiffness of each end flexure about each axis, N m/rad (the universal joints'
#: stiffness, zero moment at the zero pose).
FLEXURE_STIFFNESS = 2.6e4


def strut_drive(plant: HexapodPlant | None = None) -> DriveTrain:
    """A strut's drive train as built (``STRUT_DRIVE``), with ``plant``'s errors of its friction,
    screw stiffness and torque constant."""
    if plant is None:
        return STRUT_DRIVE
    return STRUT_DRIVE.with_errors(
        friction=plant.friction_error,
        stiffness=plant.screw_stiffness_error,
        torque_constant=plant.torque_constant_error,
    )


@functools.lru_cache(maxsize=16)
def _compiled(elevation_deg: float, drives: str = "ideal") -> mujoco.MjModel:
    """The nominal scene at ``elevation_deg`` (deg) with ``drives`` (``DRIVES``), compiled."""
    return _spec(elevation_deg, drives).compile()


@functools.lru_cache(maxsize=16)
def _compiled_plant(elevation_deg: float, plant: HexapodPlant, drives: str = "ideal") -> mujoco.MjModel:
    """The scene at ``elevation_deg`` (deg) with ``drives`` perturbed into the plant ``plant``,
    compiled."""
    spec = _spec(elevation_deg, drives, plant)
    apply_plant(spec, plant, _compiled(elevation_deg, drives))
    return spec.compile()


#: Where the platform's free joint sits in the keyframe's qpos: it is the model's last joint
#: (models/hexapod/hexapod.xml; tests/test_hexapod_physics.py checks it), so its 7 values end qpos.
PLATFORM_KEY_QPOS = -7


def _spec(elevation_deg: float, drives: str = "ideal", plant: HexapodPlant | None = None) -> mujoco.MjSpec:
    """The scene's MjSpec with the top end tilted to ``elevation_deg`` (deg) and its struts'
    drives (``DRIVES``; as built: ``STRUT_DRIVE``, with ``plant``'s errors of its elements)."""
    check_option(drives)
    spec = mujoco.MjSpec.from_file(str(models.scene_path("hexapod")))
    if drives == "as-built":
        drive = strut_drive(plant)
        for name in STRUT_LABELS:
            add_drive_train(spec, name, name, drive)
            for axis in ("u1", "u2"):
                spec.joint(f"{name}_{axis}").stiffness = [FLEXURE_STIFFNESS, 0.0, 0.0]
        # 30 dofs and 24 constraint rows: the dense constraint Jacobian is the faster one
        # (0.8 us a step less than MuJoCo's automatic choice, sparse, measured).
        spec.option.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
    top_end = spec.body("top_end")
    rotation = top_end_rotation(elevation_deg)
    origin = np.array(top_end.pos)
    quat = wxyz(rotation)
    top_end.quat = quat
    platform_pos = origin + rotation @ RUBIN_CAMERA.rotation_pivot
    platform = spec.body("platform")
    platform.pos = platform_pos
    platform.quat = quat
    key = spec.key("home")
    # Every joint but the platform's is at 0 at home (the model's zero pose), the motors'
    # too: the key's qpos is rebuilt for the joints the drives added.
    hinges = sum(1 for j in spec.joints if j.type != mujoco.mjtJoint.mjJNT_FREE)
    qpos = np.zeros(hinges + 7)
    free = PLATFORM_KEY_QPOS
    qpos[free : free + 3] = platform_pos
    qpos[free + 3 :] = quat
    key.qpos = qpos
    return spec


def _radial(xyz, error: float) -> np.ndarray:
    """``xyz`` (3,) with its (x, y) moved radially by ``error`` (m): a pivot on a circle about
    the hexapod axis whose radius is ``error`` larger."""
    xyz = np.array(xyz, dtype=float)
    xyz[:2] *= 1.0 + error / math.hypot(xyz[0], xyz[1])
    return xyz


def apply_plant(spec: mujoco.MjSpec, plant: HexapodPlant, nominal: mujoco.MjModel) -> None:
    """Edit the hexapod's MjSpec into the plant ``plant`` (``nominal``: the same spec
    compiled unperturbed). Each edit touches only its own elements:

    * camera_mass_error, camera_com_offset: the camera body's mass and central inertia times
      (1 + error), its centre of mass moved by the offset (m, hexapod frame = the camera body's
      frame), its principal axes kept (``planbench.plant.set_inertial``; the geoms stay);
    * base_pivot_radius_error, platform_pivot_radius_error: the six base pivot sites and the
      strut housings on them, or the six mirror-side pivot sites, moved radially (m). The
      struts keep their built lengths (the rods' zero), so the loops close elsewhere;
    * drive_stiffness_error: every strut drive's kp (gain and bias term) times (1 + error);
    * drive_force_scale: every drive's force range times the scale;
    * encoder_bias_um: the drives close their loop on the biased encoder, so the drive force
      is kp (set-point - (q + b)) - kv qdot: affine bias term biasprm[0] = -kp b.
    """
    if plant.camera_mass_error or any(plant.camera_com_offset):
        set_inertial(spec, nominal, "camera", 1.0 + plant.camera_mass_error, plant.camera_com_offset)
    for i, name in enumerate(STRUT_LABELS):
        if plant.base_pivot_radius_error:
            site, housing = spec.site(f"base_pivot{i + 1}"), spec.body(f"{name}_housing")
            site.pos = _radial(site.pos, plant.base_pivot_radius_error)
            housing.pos = _radial(housing.pos, plant.base_pivot_radius_error)
        if plant.platform_pivot_radius_error:
            site = spec.site(f"platform_pivot{i + 1}")
            site.pos = _radial(site.pos, plant.platform_pivot_radius_error)
    bias = plant.encoder_bias_si()
    for j, name in enumerate(STRUT_LABELS):
        actuator = spec.actuator(name)
        gain, biasprm = np.array(actuator.gainprm), np.array(actuator.biasprm)
        if plant.drive_stiffness_error:
            gain[0] *= 1.0 + plant.drive_stiffness_error
            biasprm[1] = -gain[0]
        if bias[j]:
            biasprm[0] = -gain[0] * bias[j]
        actuator.gainprm, actuator.biasprm = gain, biasprm
        if plant.drive_force_scale != 1.0:
            actuator.forcerange = plant.drive_force_scale * np.asarray(actuator.forcerange)


class HexapodPhysics(dm_mujoco.Physics):
    """dm_control Physics of models/hexapod/scene.xml at one telescope elevation."""

    #: The pivots of the machine simulated (a perturbed plant's instance has its own) and its
    #: encoders' biases (m; None: none).
    geometry = RUBIN_CAMERA
    encoder_bias = None
    drives = "ideal"

    @classmethod
    def load(
        cls, elevation_deg: float = 90.0, plant: HexapodPlant | None = None, drives: str = "ideal"
    ) -> HexapodPhysics:
        """The scene at ``elevation_deg`` (deg) at its home keyframe with the struts' ``drives``
        (``DRIVES``); ``plant`` (None: the nominal plant) the true machine, perturbed as
        ``HexapodPlant`` says (``apply_plant``)."""
        elevation_deg = check_elevation(elevation_deg)
        nominal = plant is None or plant.is_nominal
        model = _compiled(elevation_deg, drives) if nominal else _compiled_plant(elevation_deg, plant, drives)
        physics = cls.from_model(dm_mujoco.wrapper.MjModel(copy.copy(model)))
        physics.elevation_deg = elevation_deg
        physics.drives = drives
        if not nominal:
            physics.geometry = plant.geometry()
            physics.encoder_bias = plant.encoder_bias_si()
        physics.reset(keyframe_id=0)
        return physics

    # ---- indices
    @functools.cached_property
    def strut_qpos(self) -> np.ndarray:
        """qpos index of each strut's slide (the encoders)."""
        model = self.model.ptr
        return np.array([model.joint(n).qposadr[0] for n in STRUT_LABELS])

    @functools.cached_property
    def strut_dofs(self) -> np.ndarray:
        """dof index of each strut's slide."""
        model = self.model.ptr
        return np.array([model.joint(n).dofadr[0] for n in STRUT_LABELS])

    @functools.cached_property
    def drive_qpos(self) -> np.ndarray:
        """qpos index of the coordinate each strut's drive acts on and its loops read: the
        motor's (as built), the strut's slide (ideal)."""
        return drive_coordinates(self.model.ptr, STRUT_LABELS)[0]

    @functools.cached_property
    def drive_dofs(self) -> np.ndarray:
        return drive_coordinates(self.model.ptr, STRUT_LABELS)[1]

    @functools.cached_property
    def strut_actuators(self) -> np.ndarray:
        """actuator index of each strut's drive."""
        model = self.model.ptr
        return np.array([model.actuator(n).id for n in STRUT_LABELS])

    @functools.cached_property
    def strut_act(self) -> np.ndarray:
        """activation index of each strut drive's set-point."""
        return self.model.ptr.actuator_actadr[self.strut_actuators].copy()

    @functools.cached_property
    def strut_tendons(self) -> np.ndarray:
        """tendon index of each strut's pivot-to-pivot length."""
        model = self.model.ptr
        return np.array([model.tendon(f"{n}_length").id for n in STRUT_LABELS])

    @functools.cached_property
    def _free_qpos(self) -> int:
        return int(self.model.ptr.joint("platform").qposadr[0])

    @property
    def top_end_frame(self):
        """(origin (3,), rotation (3, 3)) of the hexapod frame in the world (a fixed body)."""
        model = self.model.ptr
        body = model.body("top_end")
        return np.array(body.pos), Rotation.from_quat(np.roll(body.quat, -1)).as_matrix()

    # ---- drive constants (from the compiled model: one source of truth)
    @property
    def kp(self) -> np.ndarray:
        return self.model.ptr.actuator_gainprm[self.strut_actuators, 0].copy()

    @property
    def kv(self) -> np.ndarray:
        return -self.model.ptr.actuator_biasprm[self.strut_actuators, 2].copy()

    @property
    def force_limit(self) -> np.ndarray:
        return self.model.ptr.actuator_forcerange[self.strut_actuators, 1].copy()

    # ---- state
    def strut_positions(self) -> np.ndarray:
        """Encoder readings: strut length changes from the zero pose, m."""
        return self.data.qpos[self.strut_qpos].copy()

    def drive_positions(self, strut_positions: np.ndarray) -> np.ndarray:
        """What the drives' encoders read for true strut positions (m, (..., 6)): plus their
        bias."""
        return strut_positions if self.encoder_bias is None else strut_positions + self.encoder_bias

    def strut_velocities(self) -> np.ndarray:
        return self.data.qvel[self.strut_dofs].copy()

    def strut_drive_forces(self) -> np.ndarray:
        """Drive forces along each strut, N; positive pushes (compression)."""
        return self.data.actuator_force[self.strut_actuators].copy()

    def strut_lengths(self) -> np.ndarray:
        """Pivot-to-pivot lengths (MuJoCo's spatial tendons), m."""
        return self.data.ten_length[self.strut_tendons].copy()

    def gravity_in_hexapod_frame(self) -> np.ndarray:
        _, rotation = self.top_end_frame
        return rotation.T @ self.model.opt.gravity

    def poses_from_qpos(self, qpos: np.ndarray) -> np.ndarray:
        """(n, 6) hexapod poses (x, y, z, rx, ry, rz) of logged qpos rows (n, nq)."""
        qpos = np.atleast_2d(qpos)
        origin, rotation = self.top_end_frame
        pos_world = qpos[:, self._free_qpos : self._free_qpos + 3]
        quat_world = qpos[:, self._free_qpos + 3 : self._free_qpos + 7]
        position = (pos_world - origin) @ rotation - RUBIN_CAMERA.rotation_pivot
        r_world = Rotation.from_quat(np.roll(quat_world, -1, axis=1))
        angles = (Rotation.from_matrix(rotation.T) * r_world).as_euler("XYZ")
        return np.hstack([position, angles])

    def platform_pose(self) -> np.ndarray:
        return self.poses_from_qpos(self.data.qpos)[0]

    def payload_mass_properties(self):
        """(mass kg, centre of mass (3,) in the platform frame) of the platform and camera."""
        model, data = self.model.ptr, self.data.ptr
        platform = model.body("platform").id
        mass = float(model.body_subtreemass[platform])
        com_world = data.subtree_com[platform]
        local = data.xmat[platform].reshape(3, 3).T @ (com_world - data.xpos[platform])
        return mass, local

    def strut_rod_masses(self) -> np.ndarray:
        model = self.model.ptr
        return np.array([model.body_mass[model.body(f"{n}_rod").id] for n in STRUT_LABELS])

    def set_pose(self, pose) -> None:
        """Put the hexapod at rest at ``pose``: platform, universal joints and slides.

        Each strut's universal joint turns its housing's z axis onto the new pivot-to-pivot
        direction (hinge about x by a, then about the new y by b: z' = Rx(a) Ry(b) e_z) and
        the slide takes up the length change; the loops close to round-off.
        """
        pose = np.asarray(pose, dtype=float)
        model, data = self.model.ptr, self.data.ptr
        origin, rotation = self.top_end_frame
        position, r_pose = hexapod_planner.platform_frame(pose, self.geometry)
        data.qpos[self._free_qpos : self._free_qpos + 3] = origin + rotation @ position
        data.qpos[self._free_qpos + 3 : self._free_qpos + 7] = wxyz(rotation @ r_pose)
        pivots = hexapod_planner.pivot_positions(pose, self.geometry)
        for i, name in enumerate(STRUT_LABELS):
            housing = model.body(f"{name}_housing")
            r0 = Rotation.from_quat(np.roll(housing.quat, -1)).as_matrix()
            leg = pivots[i] - self.geometry.base_pivots[i]
            length = np.linalg.norm(leg)
            u = r0.T @ leg / length
            b = np.arcsin(np.clip(u[0], -1.0, 1.0))
            a = np.arctan2(-u[1], u[2])
            data.qpos[model.joint(f"{name}_u1").qposadr[0]] = a
            data.qpos[model.joint(f"{name}_u2").qposadr[0]] = b
            data.qpos[self.strut_qpos[i]] = length - model.body(f"{name}_rod").pos[2]
        data.qvel[:] = 0.0
        data.act[:] = data.qpos[self.strut_qpos]
        if self.drives != "ideal":
            # As built: each motor stands off its rod by the screw's deflection under the
            # static load, F / k, so that the machine starts at rest.
            force = static_drive_forces(self, data.qpos[self.strut_qpos][None, :])[0]
            data.qpos[self.drive_qpos] = data.qpos[self.strut_qpos] + transmission_deflection(
                model, STRUT_LABELS, force
            )
            data.act[:] = data.qpos[self.drive_qpos]
        mujoco.mj_forward(model, data)

    def set_struts(self, strut_positions, guess=None) -> None:
        """Put the hexapod at rest with its struts at ``strut_positions`` (6,) m, length changes
        from their built length (the rods' zero): the platform where the plant's pivots
        (``geometry``) put it (forward kinematics from ``guess``, a pose), then ``set_pose``."""
        model = self.model.ptr
        built = np.array([model.body(f"{n}_rod").pos[2] for n in STRUT_LABELS])
        pose, _ = hexapod_planner.forward_kinematics(
            np.asarray(strut_positions, dtype=float) + built, self.geometry, initial=guess
        )
        self.set_pose(pose)

    def loop_closure_error(self) -> float:
        """Largest violation of the six ball constraints, m."""
        data = self.data.ptr
        rows = data.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        return float(np.abs(data.efc_pos[rows]).max()) if rows.any() else 0.0


def static_drive_forces(physics: HexapodPhysics, strut_positions: np.ndarray) -> np.ndarray:
    """(n, 6) drive forces (N, push positive) that hold the hexapod statically with its struts
    at ``strut_positions`` (n, 6) m (the nominal pivots' kinematics).

    Exact statics of the model: the payload's weight, and each strut's own weight. A strut's
    housing and rod hang on its base universal joint; the moment of their weights about it,
    M = sum_k r_k x m_k g (r_k along the strut), is held by a transverse force at the top pivot,
    F_t = (l x M) / |l|^2, whose reaction loads the platform. The rod's weight along the strut
    is the drive's own. Tensions from ``planbench.planners.hexapod.static_strut_forces`` of the total
    wrench on the platform.
    """
    model = physics.model.ptr
    lengths = strut_positions + RUBIN_CAMERA.nominal_lengths
    poses, _ = hexapod_planner.forward_kinematics(lengths)
    mass, com_local = physics.payload_mass_properties()
    gravity = physics.gravity_in_hexapod_frame()
    origin, rotation = hexapod_planner.platform_frame(poses)
    force = np.broadcast_to(mass * gravity, poses[:, :3].shape).copy()
    moment = np.cross(rotation @ com_local, force)
    pivots = hexapod_planner.pivot_positions(poses)
    legs = pivots - RUBIN_CAMERA.base_pivots
    leg_length = np.linalg.norm(legs, axis=-1, keepdims=True)
    units = legs / leg_length
    housing = np.array([model.body(f"{n}_housing").id for n in STRUT_LABELS])
    rod = np.array([model.body(f"{n}_rod").id for n in STRUT_LABELS])
    # Centres of mass along the strut from its base pivot, m (rod frame origin = tip).
    housing_arm = model.body_ipos[housing, 2]
    rod_arm = leg_length[..., 0] + model.body_ipos[rod, 2]
    weight_moment = model.body_mass[housing] * housing_arm + model.body_mass[rod] * rod_arm
    strut_moment = np.cross(units * weight_moment[..., None], gravity)
    tip_force = np.cross(legs, strut_moment) / leg_length**2
    force -= tip_force.sum(axis=1)
    moment -= np.cross(pivots - origin[:, None, :], tip_force).sum(axis=1)
    tension = hexapod_planner.static_strut_forces(poses, np.hstack([force, moment]))
    rod_weight = model.body_mass[rod] * (units @ gravity)
    return -tension - rod_weight


def magnified_qpos(physics: HexapodPhysics, magnification: float):
    """Setup.video_qpos: states whose pose change from the first logged pose is magnified."""

    def frames(log: RunLog, ticks: np.ndarray) -> np.ndarray:
        scratch = HexapodPhysics.from_model(dm_mujoco.wrapper.MjModel(copy.copy(physics.model.ptr)))
        scratch.elevation_deg = physics.elevation_deg
        scratch.geometry = physics.geometry
        poses = physics.poses_from_qpos(log.qpos[ticks])
        start = physics.poses_from_qpos(log.qpos[0])[0]
        out = np.empty((ticks.size, physics.model.nq))
        for k, pose in enumerate(start + magnification * (poses - start)):
            scratch.set_pose(pose)
            out[k] = scratch.data.qpos
        return out

    return frames


def log_bytes_per_tick(wind: bool = True, drives: str = "ideal") -> float:
    """Bytes a hexapod run preallocates per control tick: the runner's log of the compiled
    model (6 planned struts), the controller's set-points and feed-forward forces (6 + 6
    doubles) and, with wind, its speed and force (1 + 3)."""
    model = _compiled(DEFAULT_ELEVATION_DEG, drives)  # every elevation has the same sizes
    return run_limits.floats(run_limits.runlog_floats_per_tick(model, 6) + 2 * 6 + (4 if wind else 0))
