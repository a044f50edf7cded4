"""Each mechanism as a ``dm_control.rl.control.Environment``: a thin adapter over its Task.

The adapter (``TaskAdapter``) runs a scenario's ``runner.Setup`` the way the runner does
(``runner.start_episode``): the same initial state, the same sensors and disturbances seeded
the same way, ``steps_per_tick`` physics steps per action. The agent plays the controller:
its action is the commands of the actuators a controller drives (``Setup.controlled``), its
observation what the task's sensors report (``sims.task``) plus the reference at the current
tick (not the antenna's: its joint path is the true sea's), never the physics state. An
episode starts as the reference controller's run starts (the machine at rest, its drives
holding the start), and lasts the scenario's duration. The reward is exp(-error / scale) of
the task's goal: the joint tracking error (loader, hexapod), the pointing error (antenna),
the feed's distance from its goal path (FAST).
"""

from __future__ import annotations

import collections

import mujoco
import numpy as np
from dm_control.rl import control
from dm_env import specs

from sims import runner


class TaskAdapter(control.Task):
    """A planbench Setup as a dm_control Task.

    Args:
      setup: a scenario's ``runner.Setup`` (its physics at the initial state).
      reward: (physics, tick, adapter) -> reward in (0, 1].
    """

    def __init__(self, setup: runner.Setup, reward):
        self._setup = setup
        self._reward = reward
        episode = runner.start_episode(setup)  # the reference controller's start of the run
        self._times = episode.times
        self._reference = episode.reference
        physics = setup.physics
        model = physics.model.ptr
        self._state_spec = mujoco.mjtState.mjSTATE_INTEGRATION
        self._initial = np.empty(mujoco.mj_stateSize(model, self._state_spec))
        mujoco.mj_getState(model, physics.data.ptr, self._initial, self._state_spec)
        self._controlled = runner.controlled_actuators(setup)
        self.tick = 0

    @property
    def setup(self) -> runner.Setup:
        return self._setup

    @property
    def reference(self):
        """The trajectory sampled at every control tick."""
        return self._reference

    def initialize_episode(self, physics):
        setup = self._setup
        model, data = physics.model.ptr, physics.data.ptr
        mujoco.mj_setState(model, data, self._initial, self._state_spec)
        mujoco.mj_forward(model, data)  # the sensors read sensordata and positions of this state
        self._observation = setup.sensors.reset(physics, self._times, setup.seed)
        if setup.disturbance is not None:
            setup.disturbance.reset(physics, self._times, np.random.default_rng(setup.seed))
        mujoco.mj_forward(model, data)
        self.tick = 0

    def before_step(self, action, physics):
        physics.data.ctrl[self._controlled] = action
        if self._setup.disturbance is not None:
            self._setup.disturbance(min(self.tick, self._times.size - 1), physics)

    def after_step(self, physics):
        self.tick += 1
        self._setup.sensors(min(self.tick, self._times.size - 1), physics)

    def action_spec(self, physics):
        model = physics.model.ptr
        lo, hi = model.actuator_ctrlrange[self._controlled].T
        limited = model.actuator_ctrllimited[self._controlled].astype(bool)
        return specs.BoundedArray((self._controlled.size,), float, np.where(limited, lo, -np.inf),
                                  np.where(limited, hi, np.inf), name="ctrl")

    def get_observation(self, physics):
        k = min(self.tick, self._times.size - 1)
        obs = collections.OrderedDict((name, np.array(value, dtype=float)) for name, value in self._observation.items())
        if self._setup.reference_visible:
            obs["reference_positions"] = self._reference.position[k].copy()
            obs["reference_velocities"] = self._reference.velocity[k].copy()
        return obs

    def get_reward(self, physics):
        return self._reward(physics, min(self.tick, self._times.size - 1), self)


def environment(setup: runner.Setup, reward) -> control.Environment:
    """The dm_control Environment of ``setup``: one action per control tick, ``steps_per_tick``
    physics steps each, for the scenario's duration."""
    task = TaskAdapter(setup, reward)
    n_sub = runner.steps_per_tick(setup.physics.model.ptr, setup.control_dt)
    return control.Environment(setup.physics, task, time_limit=setup.duration, n_sub_steps=n_sub)


def joint_tracking_reward(qpos_index, scale: float):
    """exp(-max |q - q_ref| / scale) over the planned channels (m or rad)."""
    index = np.asarray(qpos_index)

    def reward(physics, tick, adapter):
        error = physics.data.qpos[index] - adapter.reference.position[tick]
        return float(np.exp(-np.abs(error).max() / scale))

    return reward


def make(scenario: str, **params) -> control.Environment:
    """The dm_control Environment of the scenario ``scenario`` (any of ``planbench list``):
    its Setup built with its parameters overridden by ``params`` (e.g. ``duration``, ``seed``,
    ``wind``: ``planbench run NAME --help``), the reward its mechanism declares
    (``environment_reward`` in sims/<mechanism>/)."""
    from sims import scenarios

    spec = scenarios.get(scenario)
    setup = spec.build(spec.resolve(params))
    return environment(setup, scenarios.mechanism_of(scenario).environment_reward(setup))


def loader_environment(plan: str = "supply") -> control.Environment:
    """The loader following the supply (or direct) problem's cubic B-spline."""
    return make(f"loader-{plan}")


def _given(**values) -> dict:
    """The parameters a caller gave (None: the scenario's own default, declared once)."""
    return {key: value for key, value in values.items() if value is not None}


def hexapod_environment(synchronous: bool = True, elevation_deg: float | None = None) -> control.Environment:
    """The hexapod's sync (or async) move at an elevation (None: the scenario's); the action
    is the six drives' set-point rates (m/s)."""
    return make(f"hexapod-{'sync' if synchronous else 'async'}-move", **_given(elevation=elevation_deg))


def antenna_environment(sea_state: bool = True, duration: float | None = None) -> control.Environment:
    """The ship antenna holding its satellite (default: the default sea state) for
    ``duration`` s (None: the scenario's); the action is the four antenna drives' set-point
    rates (rad/s), the deck follows the sea by itself."""
    return make("antenna-sea-state" if sea_state else "antenna-paper-motion", **_given(duration=duration))


def fast_environment(duration: float = 60.0, wind: float | None = None, seed: int | None = None,
                     cable_segments: int | None = None) -> control.Environment:
    """FAST's feed support: ``duration`` s of tracking 3C 286 (no switch: the episode starts
    on the source at rest), in ``wind`` m/s, seeded by ``seed``, on the cables of
    ``cable_segments`` (None: each the default of sims.fast.FastParams). The action is every
    actuator's ctrl: the six winches' unstretched lengths (m), the A-B set-points (rad), the
    six Stewart legs' set-point rates (m/s) and the multi-beam angle (rad)."""
    from sims import fast

    params = fast.FastParams(**_given(wind=wind, seed=seed, cable_segments=cable_segments))
    setup = fast.build(fast.observation_plan(duration), params)
    return environment(setup, fast.environment_reward(setup))
