"""Each mechanism as a ``dm_control.rl.control.Environment``, for users' own controllers.

The task follows a planner's trajectory: the action is the actuators' ``ctrl`` (for the
loader, the drives' set-point rates), observations are the joint state and the planned
motion at the current time, and the reward is exp(-|tracking error| / scale), in (0, 1].
"""

from __future__ import annotations

import collections

import numpy as np
from dm_control.rl import control

from planners.trajectory import Trajectory


class TrajectoryTrackingTask(control.Task):
    """Follow ``trajectory`` with the joints ``joint_names`` of a physics.

    Args:
      trajectory: planned motion, one channel per joint.
      joint_names: MJCF joint names, in the trajectory's channel order.
      error_scale: tracking error (m or rad) at which the reward falls to 1/e.
    """

    def __init__(self, trajectory: Trajectory, joint_names, error_scale: float = np.deg2rad(0.1)):
        self._trajectory = trajectory
        self._joints = list(joint_names)
        self._scale = float(error_scale)

    def initialize_episode(self, physics):
        physics.reset(keyframe_id=0)
        start = self._trajectory.sample(0.0).position[0]
        physics.named.data.qpos[self._joints] = start
        if physics.model.na:
            physics.data.act[:] = start
        physics.forward()

    def before_step(self, action, physics):
        physics.set_control(action)

    def action_spec(self, physics):
        from dm_env import specs

        lo, hi = physics.model.actuator_ctrlrange.T
        return specs.BoundedArray((physics.model.nu,), float, lo, hi, name="ctrl")

    def reference(self, physics) -> np.ndarray:
        return self._trajectory.sample(physics.data.time).position[0]

    def get_observation(self, physics):
        obs = collections.OrderedDict()
        obs["joint_positions"] = physics.named.data.qpos[self._joints].copy()
        obs["joint_velocities"] = physics.named.data.qvel[self._joints].copy()
        sample = self._trajectory.sample(physics.data.time)
        obs["reference_positions"] = sample.position[0]
        obs["reference_velocities"] = sample.velocity[0]
        return obs

    def get_reward(self, physics):
        error = physics.named.data.qpos[self._joints] - self.reference(physics)
        return float(np.exp(-np.abs(error).max() / self._scale))


def loader_environment(plan: str = "supply", control_dt: float = 0.005) -> control.Environment:
    """The loader as a dm_control Environment following the supply (or direct) plan."""
    import models
    from planners import loader as loader_planner
    from sims.loader import LoaderPhysics, SETTLE_S

    trajectory = loader_planner.supply_plan() if plan == "supply" else loader_planner.direct_plan()
    physics = LoaderPhysics.load()
    task = TrajectoryTrackingTask(trajectory, models.loader_spec().names)
    n_sub = int(round(control_dt / physics.model.opt.timestep))
    return control.Environment(
        physics, task, time_limit=trajectory.duration + SETTLE_S, n_sub_steps=n_sub
    )


def hexapod_environment(synchronous: bool = True, elevation_deg: float = 45.0,
                        control_dt: float = 0.005) -> control.Environment:
    """The hexapod as a dm_control Environment following the sync (or async) move.

    The action is the six drives' set-point rates (m/s); the episode starts at rest at the
    zero pose with the set-points at zero, so a controller must take up the gravity load.
    """
    from sims.hexapod import SETTLE_S, HexapodPhysics, plan

    trajectory = plan(synchronous)
    physics = HexapodPhysics.load(elevation_deg)
    task = TrajectoryTrackingTask(trajectory, list(trajectory.labels), error_scale=10e-6)
    n_sub = int(round(control_dt / physics.model.opt.timestep))
    return control.Environment(
        physics, task, time_limit=trajectory.duration + SETTLE_S, n_sub_steps=n_sub
    )
