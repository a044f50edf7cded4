"""dm_env's own conformance suite (``dm_env.test_utils.EnvironmentTestMixin``) for every
mechanism's dm_control Environment, with an action sequence that holds the actuators where
the episode starts and runs to the end of the episode, so the contract around LAST and the
next FIRST is checked too."""

from __future__ import annotations

import unittest

import dm_env
import numpy as np
from dm_env import test_utils

from sims import envs


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


class LoaderEnvironmentTest(_Conformance, unittest.TestCase):
    make = staticmethod(envs.loader_environment)


class HexapodEnvironmentTest(_Conformance, unittest.TestCase):
    make = staticmethod(envs.hexapod_environment)


class AntennaEnvironmentTest(_Conformance, unittest.TestCase):
    make = staticmethod(lambda: envs.antenna_environment(duration=1.0))

    def hold_action(self):
        return np.zeros(self.environment.action_spec().shape)  # the four drives' set-point rates


class FastEnvironmentTest(_Conformance, unittest.TestCase):
    make = staticmethod(lambda: envs.fast_environment(duration=1.0))
