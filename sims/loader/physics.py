"""dm_control Physics of the loader's scene (``LoaderPhysics``): its accessors, the model's load
with the payload's mass, and the plant's edits of its MjSpec (``apply_plant``, ``plant_chain``)."""

from __future__ import annotations

import dataclasses
import functools

import mujoco
import numpy as np
from dm_control import mujoco as dm_mujoco

import models
from sims.loader.collision import geoms_by_contype
from sims.loader.params import LoaderPlant
from sims.plant import set_inertial

#: Robot collision geoms have contype 1, obstacles (breechblock, seat ring, floor) contype 2.
ROBOT_CONTYPE = 1
OBSTACLE_CONTYPE = 2


#: The lightest shell the model carries, kg; lighter is none.
MIN_PAYLOAD_KG = 1e-6


class LoaderPhysics(dm_mujoco.Physics):
    """dm_control Physics of models/loader/scene.xml with readable accessors."""

    @classmethod
    def load(cls, payload_mass: float = None, plant: "LoaderPlant | None" = None) -> "LoaderPhysics":
        """The scene at its home keyframe; ``payload_mass`` (kg, None: the model's 45 kg) scales
        the shell's geoms' masses, so its inertia scales with them (same shape and density
        distribution), edited with MjSpec before compiling. ``plant`` (None: the nominal
        plant): the true machine, perturbed as ``LoaderPlant`` says (``apply_plant``); its
        ``payload_mass_error`` makes the shell's true mass payload_mass (1 + error)."""
        nominal = plant is None or plant.is_nominal
        if nominal and (payload_mass is None or payload_mass == shell_mass()):
            physics = cls.from_xml_path(str(models.scene_path("loader")))
        else:
            spec = mujoco.MjSpec.from_file(str(models.scene_path("loader")))
            mass = shell_mass() if payload_mass is None else payload_mass
            if not nominal:
                mass = mass * (1.0 + plant.payload_mass_error)
            if mass < MIN_PAYLOAD_KG:
                # MuJoCo cannot find the principal axes of geoms this light (their inertia's
                # eigenvalues round to zero): a shell under a milligram is no shell.
                mass = 0.0
            factor = mass / shell_mass()
            if factor != 1.0:
                for geom in spec.body("shell").find_all(mujoco.mjtObj.mjOBJ_GEOM):
                    geom.mass = geom.mass * factor
            if not nominal:
                apply_plant(spec, plant)
            physics = cls.from_model(dm_mujoco.wrapper.MjModel(spec.compile()))
        physics.reset(keyframe_id=0)
        return physics

    def set_start(self, q: np.ndarray) -> None:
        """Joints and the drives' set-points at ``q`` (theta1 m, theta2 ... theta6 rad), at rest."""
        self.named.data.qpos[self.joint_names] = q
        self.named.data.qvel[self.joint_names] = 0.0
        self.data.act[:] = q
        self.forward()

    @property
    def joint_names(self) -> list[str]:
        return models.loader_spec().names

    def joint_positions(self) -> np.ndarray:
        """theta1 ... theta6: slide (m) and five angles (rad)."""
        return self.named.data.qpos[self.joint_names].copy()

    def joint_velocities(self) -> np.ndarray:
        return self.named.data.qvel[self.joint_names].copy()

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


def apply_plant(spec: mujoco.MjSpec, plant: "LoaderPlant") -> None:
    """Edit the loader's MjSpec into the plant ``plant`` (all but the payload's mass, which
    ``LoaderPhysics.load`` scales). Each edit touches only its own elements:

    * arm_mass_error: the mass and inertia of every body of ``ARM_BODIES`` times (1 + error),
      its centre of mass and principal axes kept (``sims.plant.set_inertial``);
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


def plant_chain(plant: "LoaderPlant | None" = None) -> models.SerialChainSpec:
    """The plant's kinematic chain (``models.loader_spec()`` with its upper-arm length error),
    for the evaluation's shell tip: the checks judge the true machine."""
    chain = models.loader_spec()
    if plant is None or not plant.upper_arm_length_error:
        return chain
    bodies = tuple(dataclasses.replace(b, pos=b.pos + np.array([plant.upper_arm_length_error, 0.0, 0.0]))
                   if b.name == "forearm" else b for b in chain.bodies)
    return dataclasses.replace(chain, bodies=bodies)
