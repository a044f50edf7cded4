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


class FastTask(TrajectoryTrackingTask):
    """Keep FAST's feed on its plan: the feed support for a user's controller.

    The action is every actuator's ctrl: the six winches' unstretched lengths (m), the A-B
    set-points (rad), the six Stewart legs' set-point rates (m/s) and the multi-beam angle
    (rad). The plant's per-tick physics (the cables' catenary law, their weight and the wind,
    ``sims.fast_physics.CableLoads``) runs before every step. Observations: the cabin pose
    (position, quaternion), the feed position, the cable tensions and lengths, the A-B angles,
    the leg encoders, the planned feed and the plan's static tensions and unstretched-length
    feed-forward at the current time. The reward is exp(-feed error / scale).
    """

    def __init__(self, setup, error_scale: float = 0.01):
        super().__init__(setup.trajectory, [], error_scale)
        self._setup = setup

    def prepare(self, physics, control_dt: float, duration: float):
        from planners.trajectory import control_ticks

        self._times = control_ticks(duration, control_dt)
        self._dt = control_dt
        self._initial = physics.get_state().copy()
        self._setup.controller.reset(physics, self._setup.trajectory.sample(self._times), control_dt)
        self._initial_ctrl = physics.data.ctrl.copy()

    def initialize_episode(self, physics):
        physics.set_state(self._initial)
        physics.data.ctrl[:] = self._initial_ctrl
        physics.forward()
        self._setup.disturbance.reset(physics, self._times, np.random.default_rng(self._setup.seed))

    def tick(self, physics) -> int:
        return min(int(round(physics.data.time / self._dt)), self._times.size - 1)

    def before_step(self, action, physics):
        physics.data.ctrl[:] = action
        self._setup.disturbance(self.tick(physics), physics)

    def action_spec(self, physics):
        from dm_env import specs

        lo, hi = physics.model.actuator_ctrlrange.T
        return specs.BoundedArray((physics.model.nu,), float, lo, hi, name="ctrl")

    def get_observation(self, physics):
        state = self._setup.controller.state
        k = self.tick(physics)
        origin, rotation = physics.cabin_pose()
        obs = collections.OrderedDict()
        obs["cabin_position"] = origin
        obs["cabin_quat"] = physics.data.xquat[physics.cabin_body].copy()
        obs["feed_position"] = physics.feed_position()
        obs["cable_tensions"] = physics.cable_tensions()
        obs["cable_lengths"] = physics.cable_lengths()
        obs["ab_angles"] = physics.ab_angles()
        obs["stewart_legs"] = physics.stewart_legs()
        obs["reference_feed"] = state.feed[k]
        obs["reference_tensions"] = state.tension[k]
        obs["reference_unstretched_lengths"] = self._setup.controller.l0_ff[k]
        return obs

    def get_reward(self, physics):
        error = np.linalg.norm(physics.feed_position() - self._setup.controller.state.feed[self.tick(physics)])
        return float(np.exp(-error / self._scale))


def fast_environment(duration: float = 60.0, wind: float = 4.0, seed: int = 0) -> control.Environment:
    """FAST's feed support as a dm_control Environment: ``duration`` s of tracking 3C 286 (no
    switch: the episode starts on the source at rest), in ``wind`` m/s."""
    from sims import fast
    from sims.fast_physics import CONTROL_DT
    from sims.scenarios import RunOptions

    setup = fast.build(fast.observation_plan(duration), RunOptions(wind=wind, seed=seed))
    task = FastTask(setup)
    total = setup.trajectory.duration
    task.prepare(setup.physics, CONTROL_DT, total)
    n_sub = int(round(CONTROL_DT / setup.physics.model.opt.timestep))
    return control.Environment(setup.physics, task, time_limit=total, n_sub_steps=n_sub)
