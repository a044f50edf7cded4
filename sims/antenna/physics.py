"""The ship antenna's MuJoCo physics: ``AntennaPhysics``, the dm_control Physics of
models/antenna/scene.xml (the nominal model, or one an ``AntennaPlant`` edited) with named
accessors of the deck and antenna joints, drives and sensors.
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np
from dm_control import mujoco as dm_mujoco

from planbench import models
from planbench.antenna.params import DECK_JOINTS, JOINTS, MAST_JOINTS, AntennaPlant, _model
from planbench.antenna.ship_motion import world_from_ship
from planbench.drives import drive_coordinates
from planbench.planners import antenna as ant
from planbench.planners.rotations import rot_x, rot_y


class AntennaPhysics(dm_mujoco.Physics):
    """dm_control Physics of models/antenna/scene.xml with named accessors."""

    drives = "ideal"

    @classmethod
    def load(cls, plant: AntennaPlant | None = None, drives: str = "ideal") -> AntennaPhysics:
        """The scene at its home keyframe with the pedestal's ``drives`` (``DRIVES``);
        ``plant`` (None or nominal: the model as it is) perturbs the compiled model
        (``AntennaPlant.model``)."""
        if plant is not None and not plant.is_nominal:
            model = plant.model(drives)
        else:  # a model of its own: the nominal as-built compile is cached
            model = models.load("antenna") if drives == "ideal" else copy.copy(_model(drives))
        physics = cls.from_model(dm_mujoco.wrapper.MjModel(model))
        physics.drives = drives
        physics.reset(keyframe_id=0)
        return physics

    def _ids(self, names, kind):
        model = self.model.ptr
        return np.array([getattr(model, kind)(n).id for n in names])

    @property
    def deck_qpos(self) -> np.ndarray:
        return self.model.ptr.jnt_qposadr[self._ids(DECK_JOINTS, "joint")]

    @property
    def deck_dofs(self) -> np.ndarray:
        return self.model.ptr.jnt_dofadr[self._ids(DECK_JOINTS, "joint")]

    @property
    def antenna_qpos(self) -> np.ndarray:
        return self.model.ptr.jnt_qposadr[self._ids(JOINTS, "joint")]

    @property
    def antenna_dofs(self) -> np.ndarray:
        return self.model.ptr.jnt_dofadr[self._ids(JOINTS, "joint")]

    @property
    def drive_qpos(self) -> np.ndarray:
        """qpos index of the coordinate each axis's drive acts on and reads: its motor's (as
        built), the axis's own (ideal)."""
        return drive_coordinates(self.model.ptr, JOINTS)[0]

    @property
    def drive_dofs(self) -> np.ndarray:
        return drive_coordinates(self.model.ptr, JOINTS)[1]

    @property
    def antenna_actuators(self) -> np.ndarray:
        return self._ids(JOINTS, "actuator")

    @property
    def deck_actuators(self) -> np.ndarray:
        """The sea's drives of the deck joints (heave, yaw, pitch, roll), actuator indices."""
        return self._ids(DECK_JOINTS, "actuator")

    def _actuator_param(self, names, field, column):
        ids = self._ids(names, "actuator")
        return np.array(getattr(self.model.ptr, field)[ids, column])

    def drive_gains(self, names=JOINTS):
        """(kp, kv) of the named drives: kp (setpoint - q) - kv qdot."""
        return (self._actuator_param(names, "actuator_gainprm", 0), -self._actuator_param(names, "actuator_biasprm", 2))

    def torque_limit(self, names=JOINTS) -> np.ndarray:
        return self._actuator_param(names, "actuator_forcerange", 1)

    def rate_limit(self, names=JOINTS) -> np.ndarray:
        """Rated speeds, rad/s: the drives' set-point rate range."""
        return self._actuator_param(names, "actuator_ctrlrange", 1)

    def sensor(self, name: str) -> np.ndarray:
        model = self.model.ptr
        s = model.sensor(name)
        return self.data.ptr.sensordata[s.adr[0] : s.adr[0] + s.dim[0]]

    def sensor_slice(self, name: str) -> slice:
        s = self.model.ptr.sensor(name)
        return slice(int(s.adr[0]), int(s.adr[0] + s.dim[0]))

    def pedestal_rotation(self, qpos) -> np.ndarray:
        """(n, 3, 3) world-from-pedestal rotations of logged qpos rows: eTb(deck), times the
        mast's bending Rx(mast_x) Ry(mast_y) as built (the IMU sits on the pedestal)."""
        qpos = np.atleast_2d(qpos)
        deck = qpos[:, self.deck_qpos]
        rotation = world_from_ship(deck[:, 1], deck[:, 2], deck[:, 3])
        if self.drives == "ideal":
            return rotation
        model = self.model.ptr
        x, y = (qpos[:, model.jnt_qposadr[model.joint(n).id]] for n in MAST_JOINTS)
        return rotation @ rot_x(x) @ rot_y(y)

    def dish_rotation(self, qpos) -> np.ndarray:
        """(n, 3, 3) world-from-antenna rotations of logged qpos rows: eTb(deck) (the mast's
        bending) f(Theta)."""
        qpos = np.atleast_2d(qpos)
        return self.pedestal_rotation(qpos) @ ant.forward_kinematics(qpos[:, self.antenna_qpos])

    def set_state(self, deck_position, deck_velocity, theta, theta_rate) -> None:
        """Put the deck and the antenna at a state (SI) and the antenna set-points with it."""
        data = self.data.ptr
        data.qpos[self.deck_qpos] = deck_position
        data.qvel[self.deck_dofs] = deck_velocity
        data.qpos[self.antenna_qpos] = theta
        data.qvel[self.antenna_dofs] = theta_rate
        if self.drives != "ideal":  # the motors with their axes, the mast straight
            data.qpos[self.drive_qpos] = theta
            data.qvel[self.drive_dofs] = theta_rate
        kp, kv = self.drive_gains()
        data.act[self.antenna_actuators] = theta + kv / kp * theta_rate
        mujoco.mj_forward(self.model.ptr, data)
