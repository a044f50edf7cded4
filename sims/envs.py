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


class AntennaTask(TrajectoryTrackingTask):
    """Hold the satellite while the ship moves: the ship antenna for a user's controller.

    The action is the four antenna drives' set-point rates (rad/s); the deck follows the ship
    motion by itself (the sea). Observations add what a real controller has: the IMU's
    orientation quaternion and gyro; ``reference_positions`` are the joint angles for the
    true ship motion (what a perfect controller would reach; a real one must estimate them
    from the IMU). The reward is exp(-pointing error / scale).
    """

    def __init__(self, setup, error_scale: float = np.deg2rad(0.1)):
        super().__init__(setup.trajectory, list(setup.trajectory.labels), error_scale)
        self._setup = setup
        self._times = None

    def initialize_episode(self, physics):
        from sims.antenna import AntennaPhysics  # noqa: F401  (the setup's physics type)

        physics.set_state(*self._initial)
        self._setup.disturbance.reset(physics, self._times, np.random.default_rng(0))

    def prepare(self, physics, control_dt: float, duration: float):
        from planners.trajectory import control_ticks

        self._times = control_ticks(duration, control_dt)
        data = physics.data.ptr
        self._initial = (data.qpos[physics.deck_qpos].copy(), data.qvel[physics.deck_dofs].copy(),
                         data.qpos[physics.antenna_qpos].copy(), data.qvel[physics.antenna_dofs].copy())
        self._dt = control_dt

    def before_step(self, action, physics):
        tick = int(round(physics.data.time / self._dt))
        self._setup.disturbance(min(tick, self._times.size - 1), physics)
        physics.data.ctrl[physics.antenna_actuators] = action

    def action_spec(self, physics):
        from dm_env import specs

        lo, hi = physics.model.actuator_ctrlrange[physics.antenna_actuators].T
        return specs.BoundedArray((4,), float, lo, hi, name="antenna_setpoint_rates")

    def get_observation(self, physics):
        obs = super().get_observation(physics)
        obs["imu_quat"] = physics.sensor("imu_quat").copy()
        obs["imu_gyro"] = physics.sensor("imu_gyro").copy()
        return obs

    def get_reward(self, physics):
        from sims.antenna import pointing_errors

        pointing, _ = pointing_errors(physics.dish_rotation(physics.data.qpos), self._setup.evaluate.satellite)
        return float(np.exp(-pointing[0] / self._scale))


def antenna_environment(sea_state: bool = True, duration: float = 60.0,
                        control_dt: float = 0.005) -> control.Environment:
    """The ship antenna as a dm_control Environment (default: the default sea state)."""
    from sims import antenna
    from sims.scenarios import RunOptions

    build = antenna.build_sea_state if sea_state else antenna.build_paper_motion
    setup = build(RunOptions(duration=duration))
    task = AntennaTask(setup)
    task.prepare(setup.physics, control_dt, duration)
    n_sub = int(round(control_dt / setup.physics.model.opt.timestep))
    return control.Environment(setup.physics, task, time_limit=duration, n_sub_steps=n_sub)
