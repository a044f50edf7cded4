"""The online planner's contract: steps have increasing times, the first after the problem's
start (t = 0, where theta0 holds). A step at the same time is an interval of zero; it is a
clear error naming both times, never a LinAlgError, and our controller never makes one."""

from __future__ import annotations

import numpy as np
import pytest

from planbench import scenarios
from planbench.planners import antenna as ant
from planbench.planners.errors import PlanningError
from planbench.task import RecordingPlanner, StepTimeError


def _problem():
    satellite = ant.satellite_attitude(np.radians(223.49), np.radians(60.0), np.radians(-28.8))
    theta0 = np.array([0.3, 0.4, 0.1, -0.2])
    return ant.AntennaProblem(
        satellite, 223.49, 60.0, -28.8, theta0, ant.AntennaLimits(rate=np.full(4, 1.0)), update_dt=0.02
    )


@pytest.mark.parametrize(
    "times, bad",
    [
        ((0.0,), 0),  # at the reset time: the problem's start
        ((-0.02,), 0),  # before it
        ((0.02, 0.02), 1),  # twice at the same time
        ((0.02, 0.04, 0.03), 2),  # back in time
    ],
)
@pytest.mark.parametrize("wrapped", [False, True], ids=["planner", "task's record"])
def test_a_step_not_after_the_previous_one_names_both_times(times, bad, wrapped):
    problem = _problem()
    planner = ant.CrrPlanner()
    stepper = RecordingPlanner(planner, 8) if wrapped else planner
    stepper.reset(problem)
    attitude = ant.forward_kinematics(problem.theta0)
    for t in times[:bad]:
        stepper.step(t, attitude)
    with pytest.raises(StepTimeError if wrapped else PlanningError) as raised:
        stepper.step(times[bad], attitude)
    message = str(raised.value)
    assert f"t = {times[bad]:.6g} s" in message and f"{(times[bad - 1] if bad else 0.0):.6g} s" in message, message


def test_increasing_steps_are_accepted():
    problem = _problem()
    recorder = RecordingPlanner(ant.CrrPlanner(), 4)
    recorder.reset(problem)
    attitude = ant.forward_kinematics(problem.theta0)
    for t in (0.001, 0.02, 0.04):
        assert np.isfinite(recorder.step(t, attitude)).all()
    assert recorder.records()["t"].tolist() == [0.001, 0.02, 0.04]


def test_our_controller_steps_at_increasing_times_after_the_start():
    scenario = scenarios.get("antenna-paper-motion")
    params = type(scenario.params).from_mapping({"duration": 2.0}, base=scenario.params)
    from planbench import runner

    setup = scenario.build(params)
    result = runner.run(scenario.name, setup)
    t = setup.components.planner.records()["t"]
    assert t.size > 10 and t[0] > 0.0 and (np.diff(t) > 0).all()
    assert all(c.passed for c in result.checks if c.name == "controller_errors")
