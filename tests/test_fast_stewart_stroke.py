"""stewart_stroke judges both what the Stewart drives were told (their set-points, the
actuators' activation) and where the legs went (the measured joint): a constructed log of a
short run in which only one of the two exceeds the +/-250 mm stroke fails either way."""

import dataclasses
import functools

import numpy as np
import pytest

from planbench import fast as fast_sim
from planbench import runner
from planbench.planners import fast


@functools.cache
def short_run():
    setup = fast_sim.build(fast_sim.observation_plan(2.0), fast_sim.FastParams(wind=0.0, seed=0))
    return runner.run("stroke", setup), setup


def stroke_check(log, setup):
    checks, _ = setup.task.evaluation.evaluate(log)
    return next(c for c in checks if c.name == "stewart_stroke")


def test_the_short_run_stays_inside_the_stroke():
    result, setup = short_run()
    check = stroke_check(result.log, setup)
    assert check.passed and check.value < 0.5 * 1e3 * fast.STEWART.stroke


@pytest.mark.parametrize("saturated", ["setpoint", "leg"])
def test_a_saturating_stewart_log_fails_the_stroke(saturated):
    result, setup = short_run()
    p, log = setup.physics, result.log
    beyond = 1.2 * fast.STEWART.stroke  # m, one leg and one tick past the +/-250 mm stroke
    act, qpos = log.act.copy(), log.qpos.copy()
    tick = log.t.size // 2
    if saturated == "setpoint":  # the drive told to go past the stroke; the measured leg did not
        act[tick, p.leg_act[0]] = beyond
    else:  # the leg measured past the stroke; its set-point within it
        qpos[tick, p.leg_qpos[0]] = -beyond
    assert np.abs(log.qpos[:, p.leg_qpos]).max() < fast.STEWART.stroke
    assert np.abs(log.act[:, p.leg_act]).max() < fast.STEWART.stroke
    check = stroke_check(dataclasses.replace(log, act=act, qpos=qpos), setup)
    assert not check.passed
    assert check.value == pytest.approx(1e3 * beyond)
