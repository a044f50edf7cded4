"""A controller sees and writes only the actuators it drives: the antenna's four joint drives,
not the four deck drives (heave, yaw, pitch, roll) that belong to the sea; every other
mechanism's controller drives all of its actuators."""

from __future__ import annotations

import numpy as np
import pytest

from planbench import runner, scenarios
from planbench.antenna import AntennaController
from planbench.planners.antenna import JOINT_LABELS
from planbench.plugins import PluginError

DECK = ("heave", "yaw", "pitch", "roll")


class Spy(AntennaController):
    """Our controller, recording what its context offers."""

    def reset(self, context):
        self.names, self.size = context.actuators, context.command.size
        self.setpoint_size = context.setpoint.size
        super().reset(context)


class Returns:
    """Returns a command vector of ``size`` zeros."""

    def __init__(self, size):
        self.size = size

    def reset(self, context):
        pass

    def __call__(self, tick, observation):
        return np.zeros(self.size)


def build(name, controller, duration=0.5):
    scenario = scenarios.get(name)
    return scenario.build(scenario.resolve(duration=duration), controller=controller)


@pytest.mark.parametrize("name", ["antenna-paper-motion", "antenna-sea-state"])
def test_the_antenna_controller_gets_only_its_four_drives(name):
    spy = Spy()
    setup = build(name, spy)
    result = runner.run(name, setup)
    assert spy.names == tuple(JOINT_LABELS) and spy.size == 4 and spy.setpoint_size == 4
    assert not set(spy.names) & set(DECK)
    # The sea still moves the deck through its own drives.
    model = setup.physics.model.ptr
    deck = [model.actuator(n).id for n in DECK]
    assert np.abs(np.diff(result.log.ctrl[:, deck], axis=0)).max() > 0


def test_a_command_for_every_actuator_is_refused_naming_the_four():
    setup = build("antenna-sea-state", Returns(8))
    with pytest.raises(PluginError, match=r"shape \(8,\); this task has 4 actuators \(azimuth, elevation"):
        runner.run("antenna-sea-state", setup)


def test_a_controller_returning_zeros_leaves_the_deck_to_the_sea():
    """Zero joint rates: the antenna's set-points stay where they started; the deck's drives are
    the sea's as in a run with our controller."""
    ours = runner.run("antenna-sea-state", build("antenna-sea-state", None))
    setup = build("antenna-sea-state", Returns(4))
    idle = runner.run("antenna-sea-state", setup)
    model = setup.physics.model.ptr
    deck = [model.actuator(n).id for n in DECK]
    joints = [model.actuator(n).id for n in JOINT_LABELS]
    np.testing.assert_array_equal(idle.log.ctrl[:, deck], ours.log.ctrl[:, deck])
    np.testing.assert_array_equal(idle.log.ctrl[:, joints], 0.0)


@pytest.mark.parametrize("name", ["loader-supply", "hexapod-sync-move", "fast-tracking"])
def test_other_controllers_drive_every_actuator(name):
    setup = scenarios.get(name).build(scenarios.get(name).resolve(duration=0.1))
    model = setup.physics.model.ptr
    assert runner.controlled_names(setup) == tuple(model.actuator(j).name for j in range(model.nu))


def test_the_servo_controller_finds_its_drives_by_name():
    """ServoFeedforwardController on a command that is not the model's first actuators (the
    antenna's four joints, actuators 4 ... 7) reads those drives' gains, not the deck's."""
    from planbench.controllers import ServoFeedforwardController
    from planbench.planners.trajectory import TrajectorySample
    from planbench.task import ControlContext

    setup = build("antenna-paper-motion", None)
    model = setup.physics.model.ptr
    n = 3
    reference = TrajectorySample(np.arange(n) * 0.005, np.zeros((n, 4)), np.zeros((n, 4)), np.zeros((n, 4)))
    context = ControlContext(
        model=model,
        nominal_physics=lambda: setup.physics,
        problem=None,
        trajectory=None,
        reference=reference,
        control_dt=0.005,
        command=np.zeros(4),
        setpoint=np.zeros(4),
        actuators=tuple(JOINT_LABELS),
        observation={},
    )
    servo = ServoFeedforwardController(feedforward=False, integral_time=0.1)
    servo.reset(context)
    ids = [model.actuator(name).id for name in JOINT_LABELS]
    assert min(ids) == 4
    np.testing.assert_array_equal(servo.kp, model.actuator_gainprm[ids, 0])
    np.testing.assert_array_equal(servo.force_limit, model.actuator_forcerange[ids, 1])


@pytest.mark.parametrize("channels", [4, 3])
def test_the_servo_controller_refuses_a_reference_that_is_not_its_command(channels):
    """The reference's channels are the command's actuators one for one: a reordered or short
    trajectory is refused by name in reset, not driven onto the wrong joints."""
    from types import SimpleNamespace

    from planbench.controllers import ServoFeedforwardController
    from planbench.planners.trajectory import TrajectorySample
    from planbench.task import ControlContext

    setup = build("antenna-paper-motion", None)
    n = 3
    reference = TrajectorySample(np.arange(n) * 0.005, *(np.zeros((n, channels)),) * 3)
    labels = tuple(reversed(JOINT_LABELS))[:channels]
    context = ControlContext(
        model=setup.physics.model.ptr,
        nominal_physics=lambda: setup.physics,
        problem=None,
        trajectory=SimpleNamespace(labels=labels),
        reference=reference,
        control_dt=0.005,
        command=np.zeros(4),
        setpoint=np.zeros(4),
        actuators=tuple(JOINT_LABELS),
        observation={},
    )
    with pytest.raises(ValueError, match="are not the commanded actuators"):
        ServoFeedforwardController(feedforward=False).reset(context)
