"""FAST's winches as built (planbench.fast.loads.Winches): each rope within its drive's speed and
acceleration, at its command whenever the limits allow; and any action inside the dm_env
action spec is one the drives can follow."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from planbench import envs
from planbench.fast.loads import WINCH_MAX_ACCEL, WINCH_MAX_SPEED, Winches

DT = 0.02


@settings(max_examples=60, deadline=None)
@given(st.lists(st.lists(st.floats(150.0, 700.0), min_size=6, max_size=6), min_size=1, max_size=40))
def test_the_ropes_keep_their_speed_and_acceleration_limits(commands):
    winches = Winches()
    winches.reset(np.full(6, 320.0), DT)
    length, rate = winches.length.copy(), np.zeros(6)
    for command in commands:
        command = np.array(command)
        wanted = command.copy()
        winches(command)
        new_rate = (command - length) / DT
        assert np.all(np.abs(new_rate) <= WINCH_MAX_SPEED * (1 + 1e-9))
        assert np.all(np.abs(new_rate - rate) <= WINCH_MAX_ACCEL * DT * (1 + 1e-9) + 1e-12)
        # toward the command, never past it
        assert np.all((wanted - command) * (wanted - length) >= -1e-12)
        length, rate = command.copy(), new_rate


def test_within_the_limits_the_rope_is_the_command_to_the_bit():
    winches = Winches()
    winches.reset(np.full(6, 320.0), DT)
    t = np.arange(1, 200) * DT
    for k in t:  # 0.3 m/s reached at 0.02 m/s^2: inside 0.5 m/s and 0.05 m/s^2
        wanted = 320.0 + 0.5 * 0.02 * np.minimum(k, 15.0) ** 2 + 0.3 * np.maximum(k - 15.0, 0.0) + np.arange(6) * 0.0
        command = wanted.copy()
        winches(command)
        np.testing.assert_array_equal(command, wanted)


def test_a_far_command_is_reached_at_the_speed_limit_and_braked_onto():
    """A 10 m step: up to 0.5 m/s in 10 s, on at 0.5 m/s, braking at 0.05 m/s^2 onto the target;
    the time-optimal move takes 10 / 0.5 + 0.5 / 0.05 = 30 s."""
    winches = Winches()
    winches.reset(np.full(6, 320.0), DT)
    lengths = []
    for _ in range(int(40.0 / DT)):
        command = np.full(6, 330.0)
        winches(command)
        lengths.append(command[0])
    lengths = np.array(lengths)
    rate = np.diff(lengths) / DT
    assert rate.max() == pytest.approx(WINCH_MAX_SPEED, rel=1e-9)
    arrived = np.argmax(np.abs(lengths - 330.0) < 1e-6) * DT
    assert arrived == pytest.approx(30.0, abs=0.1)  # 29.94 s: each 20 ms tick moves at its own end speed
    # It arrives on a tick it may (its speed change within a dt) and brakes after: 60 um past
    # the target, then back onto it.
    assert lengths.max() <= 330.0 + 1e-4
    assert lengths[-1] == pytest.approx(330.0, abs=1e-9)


def test_uniform_random_actions_in_the_spec_run_without_a_physics_error():
    """Five 4 s episodes of uniform random actions inside the action spec (winch lengths
    150-700 m, the A-B angles, the Stewart legs): every step is physically realizable, no
    PhysicsError. With the ideal winches (ropes at the command) MuJoCo diverges within a
    few ticks."""
    env = envs.make("fast-tracking", duration=4.0)
    spec = env.action_spec()
    rng = np.random.default_rng(0)
    for _ in range(5):
        step = env.reset()
        n = 0
        while not step.last():
            step = env.step(rng.uniform(spec.minimum, spec.maximum))
            n += 1
        assert n == 200
        assert np.isfinite(env.physics.data.qpos).all()


def _vectorized_winches(winches: Winches, command: np.ndarray, state: dict) -> None:
    """The winches' tick in numpy on 6-vectors (the earlier implementation): what the scalar
    one must equal to the bit."""
    dt, dv = winches.dt, winches.max_accel * winches.dt
    rate = (command - state["length"]) / dt
    target_rate = (command - state["last"]) / dt
    state["last"][:] = command
    if np.all(np.abs(rate) <= winches.max_speed) and np.all(np.abs(rate - state["rate"]) <= dv):
        state["length"][:] = command
        state["rate"] = rate
        return
    error = command - state["length"]
    ticks = np.abs(error) / (dv * dt)
    n = np.floor((np.sqrt(1.0 + 8.0 * ticks) - 1.0) / 2.0)
    closing = np.minimum(dv * (n + np.clip(ticks / (n + 1.0) - n / 2.0, 0.0, 1.0)), np.abs(error) / dt)
    rate = np.clip(target_rate + np.sign(error) * closing, -winches.max_speed, winches.max_speed)
    rate = np.clip(rate, state["rate"] - dv, state["rate"] + dv)
    state["length"] += rate * dt
    state["rate"] = rate
    command[:] = state["length"]


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.lists(st.floats(-3e-2, 3e-2), min_size=6, max_size=6), min_size=1, max_size=60),
    st.floats(0.0, 1e-3),
    st.floats(0.0, 1.0),
)
def test_the_scalar_ropes_equal_the_vectorized_law_to_the_bit(steps, drift, far):
    """Commands that creep (inside the limits), jitter (the acceleration limit) and jump (the
    speed limit and the braking): every tick's ropes, rates and commands as written equal
    those of the law on 6-vectors, bit for bit."""
    winches = Winches()
    start = 320.0 + np.arange(6)
    winches.reset(start, DT)
    state = {"length": start.copy(), "rate": np.zeros(6), "last": start.copy()}
    target = start.copy()
    for k, step in enumerate(steps):
        target = target + drift + np.array(step) * (1.0 + 300.0 * far * (k % 7 == 3))
        ours, theirs = target.copy(), target.copy()
        winches(ours)
        _vectorized_winches(winches, theirs, state)
        np.testing.assert_array_equal(ours, theirs)
        np.testing.assert_array_equal(winches.length, state["length"])
        np.testing.assert_array_equal(winches.rate, state["rate"])
