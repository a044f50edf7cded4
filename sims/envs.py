"""Each mechanism as a ``dm_control.rl.control.Environment``: a thin adapter over its Task.

The adapter (``TaskAdapter``) is the runner's loop with the agent in the controller's place:
each episode starts from the task's initial state (``planbench.task.Task``: its
``initialize_episode``, the sensors and the disturbance seeded from a fresh seed drawn from the
adapter's ``random``, as dm_control's suite tasks draw theirs; a disturbance whose random state
sets the start, the antenna's sea, draws a new sea and its start from it), and each action is one control
tick as the runner takes it: the task's disturbance (``Task.before_step``), ``steps_per_tick``
physics steps with ``mj_step`` (MuJoCo's own step, not dm_control's legacy one, as in the
runner), then the sensors (``Task.observe``). The action is the commands of the actuators a
controller drives (``Task.controlled``), the observation what the task's sensors report plus
the reference at the current tick (not the antenna's: its joint path is the true sea's), never
the physics state. An episode starts with the machine at rest, its drives holding the start,
and lasts the scenario's duration. The reward is exp(-error / scale) of the task's goal: the
joint tracking error (loader, hexapod), the pointing error (antenna), the feed's distance from
its goal path (FAST).
"""

from __future__ import annotations

import collections

import mujoco
import numpy as np
from dm_control.rl import control
from dm_control.suite import base
from dm_env import specs

from planbench import runner
from planbench.task import sample_checked

#: Episode seeds are drawn from [0, this).
SEED_RANGE = 2**31 - 1


class TaskAdapter(base.Task):
    """A planbench Setup as a dm_control Task.

    Args:
      setup: a scenario's ``runner.Setup`` (its physics at the task's initial state).
      reward: (physics, tick, adapter) -> reward in (0, 1].
      random: the episodes' random state (an int seed or a ``numpy.random.RandomState``);
        None: seeded from the setup's seed, so that an environment is reproducible.
    """

    def __init__(self, setup: runner.Setup, reward, random=None):
        super().__init__(random=setup.provenance.seed if random is None else random)
        self._setup = setup
        self._reward = reward
        self._times = setup.task.times()
        self._reference = sample_checked(setup.components.trajectory, self._times)
        self._controlled = runner.controlled_actuators(setup)
        # The reference controller's start chooses the drives' initial set-points (their
        # activations: the hexapod's struts hold the start under gravity); each episode starts
        # with them, as a run does.
        start = runner.start_episode(setup)
        self._act_adr = runner.controlled_views(setup)[1]
        self._setpoint = start.context.setpoint.copy()
        self._last = self._times.size - 1
        self.episode_seed: int | None = None
        self.tick = 0

    @property
    def setup(self) -> runner.Setup:
        return self._setup

    @property
    def reference(self):
        """The trajectory sampled at every control tick."""
        return self._reference

    def initialize_episode(self, physics):
        task = self._setup.task
        task.restore_initial_state(physics)
        physics.data.act[self._act_adr] = self._setpoint
        mujoco.mj_forward(physics.model.ptr, physics.data.ptr)
        self.episode_seed = int(self.random.randint(SEED_RANGE))
        # After the set-points: a task with a random start (the antenna's sea) puts the
        # drives at the start it draws.
        self._observation = task.initialize_episode(physics, self._times, self.episode_seed)
        self.tick = 0
        task.observe(0, physics)  # the runner's first tick reads the sensors before the controller

    def before_step(self, action, physics):
        physics.data.ctrl[self._controlled] = action
        self._setup.task.before_step(min(self.tick, self._last), physics)

    def after_step(self, physics):
        self.tick += 1
        if self.tick <= self._last:
            self._setup.task.observe(self.tick, physics)

    def action_spec(self, physics):
        model = physics.model.ptr
        lo, hi = model.actuator_ctrlrange[self._controlled].T
        limited = model.actuator_ctrllimited[self._controlled].astype(bool)
        return specs.BoundedArray(
            (self._controlled.size,), float, np.where(limited, lo, -np.inf), np.where(limited, hi, np.inf), name="ctrl"
        )

    def get_observation(self, physics):
        k = min(self.tick, self._last)
        obs = collections.OrderedDict((name, np.array(value, dtype=float)) for name, value in self._observation.items())
        if self._setup.task.reference_visible:
            obs["reference_positions"] = self._reference.position[k].copy()
            obs["reference_velocities"] = self._reference.velocity[k].copy()
        return obs

    def get_reward(self, physics):
        return self._reward(physics, min(self.tick, self._last), self)


def environment(setup: runner.Setup, reward, random=None) -> control.Environment:
    """The dm_control Environment of ``setup``: one action per control tick, ``steps_per_tick``
    physics steps each (``mj_step``, as the runner), for the scenario's duration. ``random``:
    see ``TaskAdapter``."""
    task = TaskAdapter(setup, reward, random)
    physics = setup.physics
    physics.legacy_step = False  # mj_step(nstep), the runner's step, not mj_step2 + mj_step1
    n_sub = runner.steps_per_tick(physics.model.ptr, setup.task.control_dt)
    return control.Environment(physics, task, time_limit=setup.task.duration, n_sub_steps=n_sub)


def joint_tracking_reward(qpos_index, scale: float):
    """exp(-max |q - q_ref| / scale) over the planned channels (m or rad)."""
    index = np.asarray(qpos_index)

    def reward(physics, tick, adapter):
        error = physics.data.qpos[index] - adapter.reference.position[tick]
        return float(np.exp(-np.abs(error).max() / scale))

    return reward


def make(scenario: str, random=None, **params) -> control.Environment:
    """The dm_control Environment of the scenario ``scenario`` (any of ``planbench list``):
    its Setup built with its parameters overridden by ``params`` (e.g. ``duration``, ``seed``,
    ``wind``: ``planbench run NAME --help``), the reward its mechanism declares. ``random``:
    the episodes' random state (None: from the ``seed`` parameter)."""
    from planbench import scenarios

    spec = scenarios.get(scenario)
    setup = spec.build(spec.resolve(params))
    return environment(setup, scenarios.mechanism_of(scenario).reward(setup), random)


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


def fast_environment(
    duration: float = 60.0, wind: float | None = None, seed: int | None = None, cable_segments: int | None = None
) -> control.Environment:
    """FAST's feed support: ``duration`` s of tracking 3C 286 (no switch: the episode starts
    on the source at rest), in ``wind`` m/s, seeded by ``seed``, on the cables of
    ``cable_segments`` (None: each the default of planbench.fast.FastParams). The action is every
    actuator's ctrl: the six winches' unstretched lengths (m), the A-B set-points (rad), the
    six Stewart legs' set-point rates (m/s) and the multi-beam angle (rad)."""
    from planbench import fast

    params = fast.FastParams(**_given(wind=wind, seed=seed, cable_segments=cable_segments))
    setup = fast.build(fast.observation_plan(duration), params)
    return environment(setup, fast.MECHANISM.reward(setup))
