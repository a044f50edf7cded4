"""dm_env's own conformance suite (``dm_env.test_utils.EnvironmentTestMixin``) for the
dm_control Environment of every registered scenario (``planbench.envs.make``), with an
action sequence that holds the actuators where the episode starts and runs to the end of
the episode, so the contract around LAST and the next FIRST is checked too."""

from __future__ import annotations

import copy
import functools
import unittest

import dm_env
import numpy as np
import pytest
from dm_env import test_utils

from planbench import envs, runner, scenarios


class _Conformance(test_utils.EnvironmentTestMixin):
    """Subclasses set ``make`` (a factory of the Environment)."""

    make = None

    def make_object_under_test(self):
        return type(self).make()

    def hold_action(self):
        """The action that holds the actuators: the episode's initial ctrl (a set-point rate
        of 0 for the servo drives, the winches' lengths for FAST)."""
        env = self.environment
        spec = env.action_spec()
        return np.clip(env.physics.data.ctrl, spec.minimum, spec.maximum).astype(spec.dtype)

    def make_action_sequence(self):
        env = self.environment
        hold = self.hold_action()
        # dm_control has no public accessor of the episode's length in steps.
        steps = int(env._step_limit) + 2  # past LAST, into the next episode's FIRST
        for _ in range(steps):
            yield hold

    def test_the_action_sequence_reaches_the_end_of_an_episode(self):
        """The mixin only logs whether it saw LAST; here it must, then a FIRST after it."""
        self.environment.reset()
        types = [self.environment.step(a).step_type for a in self.make_action_sequence()]
        last = types.index(dm_env.StepType.LAST)
        assert types[last + 1] is dm_env.StepType.FIRST and dm_env.StepType.LAST not in types[:last]


#: Episodes of this many seconds: 10-20 control ticks, to the end and into the next one.
EPISODE_S = 0.1


def _conformance_case(name: str):
    """A TestCase of dm_env's suite for the environment of the scenario ``name``."""
    # A Setup is built once per scenario (plans take seconds); each test gets a fresh
    # Environment over a fresh copy of it.
    setup = functools.cache(lambda: scenarios.get(name).build(scenarios.get(name).resolve(duration=EPISODE_S)))

    def make():
        built = setup()
        fresh = copy.copy(built)
        fresh.physics = built.physics.copy(share_model=False)
        for attribute in vars(built.physics):
            if not attribute.startswith("_") and attribute not in vars(fresh.physics):
                setattr(fresh.physics, attribute, getattr(built.physics, attribute))
        fresh.task = copy.copy(built.task)  # its initial state and nominal model are shared
        fresh.task.sensors = copy.deepcopy(built.task.sensors)
        fresh.task.disturbance = copy.deepcopy(built.task.disturbance)
        fresh.components = copy.copy(built.components)
        fresh.components.controller = copy.deepcopy(built.components.controller)
        return envs.environment(fresh, scenarios.mechanism_of(name).reward(fresh))

    attributes = {"make": staticmethod(make)}
    if scenarios.get(name).online_planner:  # the antenna: its four drives' set-point rates
        attributes["hold_action"] = lambda self: np.zeros(self.environment.action_spec().shape)
    return type(f"EnvironmentTest_{name.replace('-', '_')}", (_Conformance, unittest.TestCase), attributes)


@pytest.mark.parametrize("name", list(scenarios.SCENARIOS))
def test_an_episode_starts_as_a_run_starts(name):
    """The same reset and seeding as the runner: the first observation of each episode equals
    the observation a run's controller gets at its reset with that episode's seed, bit for
    bit, and each episode draws a new seed (dm_control's ``random``)."""
    spec = scenarios.get(name)
    setup = spec.build(spec.resolve(duration=EPISODE_S, seed=3))
    env = envs.make(name, duration=EPISODE_S, seed=3)
    seeds = []
    for _ in range(3):
        observation = env.reset().observation
        seeds.append(env.task.episode_seed)
        setup.task.restore_initial_state(setup.physics)
        run_start = runner.start_episode(setup, seed=seeds[-1]).observation
        for key, value in run_start.items():
            assert np.asarray(value, dtype=float).tobytes() == observation[key].tobytes(), key
        for _ in range(3):
            env.step(np.clip(np.zeros(env.action_spec().shape), env.action_spec().minimum, env.action_spec().maximum))
    assert len(set(seeds)) == len(seeds), seeds


def test_episodes_are_reproducible_from_the_random_state():
    """Two environments with the same ``random`` draw the same episode seeds; another draws others."""

    def seeds(random):
        env = envs.make("loader-supply", random=random, duration=EPISODE_S)
        out = []
        for _ in range(2):
            env.reset()
            out.append(env.task.episode_seed)
        return out

    assert seeds(7) == seeds(7) != seeds(8)


for _name in scenarios.SCENARIOS:  # every registered scenario, no new test code for a new one
    _case = _conformance_case(_name)
    globals()[_case.__name__] = _case
del _case, _name


def test_each_sea_state_episode_has_its_own_sea():
    """The antenna's sea is the disturbance's random state: an episode with a new seed starts
    on that seed's sea (another deck attitude at t = 0, the antenna pointing at the satellite
    through it, its drives at rest on the start), and the seed the scenario was built with
    starts where a run starts."""
    from planbench.antenna import pointing_errors

    env = envs.make("antenna-sea-state", duration=EPISODE_S, seed=3)
    physics, task = env.physics, env.task
    drive, deck = task.setup.task.disturbance, physics.deck_qpos
    built = physics.data.qpos[deck].copy()
    starts = []
    for _ in range(3):
        env.reset()
        starts.append(physics.data.qpos[deck].copy())
        np.testing.assert_allclose(drive.motion.sample(0.0).joint_arrays()[0][0], starts[-1], atol=1e-12)
        pointing, _ = pointing_errors(physics.dish_rotation(physics.data.qpos), task.setup.task.problem.satellite)
        assert np.degrees(pointing[0]) < 1e-6, pointing
        # The set-points are the start with the servo's velocity lead: no force step at reset.
        kp, kv = physics.drive_gains()
        np.testing.assert_allclose(
            physics.data.act[physics.antenna_actuators],
            physics.data.qpos[physics.antenna_qpos] + kv / kp * physics.data.qvel[physics.antenna_dofs],
        )
    assert len({s.tobytes() for s in starts}) == 3
    assert np.abs(np.diff(starts, axis=0)).max() > np.radians(0.1)
    # The built seed: the built sea and the built start.
    drive.draw_start(physics, 3)
    assert drive.motion is drive.built_motion
    task.setup.task.restore_initial_state(physics)
    np.testing.assert_array_equal(physics.data.qpos[deck], built)


@pytest.mark.parametrize("mechanism", [m.name for m in scenarios.mechanisms()])
def test_uniform_random_actions_in_the_spec_are_physically_realizable(mechanism):
    """Every action inside a mechanism's bounded action spec is a command its drives accept:
    five 1 s episodes of uniform random actions run without a PhysicsError."""
    from dm_control.rl.control import PhysicsError

    name = next(m for m in scenarios.mechanisms() if m.name == mechanism).scenarios[0].name
    env = envs.make(name, duration=1.0)
    spec = env.action_spec()
    assert np.isfinite(spec.minimum).all() and np.isfinite(spec.maximum).all()
    rng = np.random.default_rng(1)
    for _ in range(5):
        step = env.reset()
        try:
            while not step.last():
                step = env.step(rng.uniform(spec.minimum, spec.maximum))
        except PhysicsError as error:
            pytest.fail(f"{name}: {error}")
        assert np.isfinite(env.physics.data.qpos).all()
