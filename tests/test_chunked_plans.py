"""Per-tick plans held a block of ticks at a time: the reference (``ChunkedSample``) and the
FAST controller's plan (``PLAN_BLOCK_TICKS``) give the very numbers of the whole arrays."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from planbench import runner
from planbench.fast import FastTrackingParams, build_scenario
from planbench.fast import controller as fast_controller
from planbench.planners.trajectory import ChunkedSample, TrajectorySample


def _spline_sample(t: np.ndarray) -> TrajectorySample:
    """A two-channel trajectory, pointwise in t."""
    position = np.column_stack([np.sin(t), t**3 - 2.0 * t])
    velocity = np.column_stack([np.cos(t), 3.0 * t**2 - 2.0])
    acceleration = np.column_stack([-np.sin(t), 6.0 * t])
    return TrajectorySample(t, position, velocity, acceleration)


@settings(max_examples=40, deadline=None)
@given(
    n=st.integers(0, 60),
    chunk=st.integers(1, 17),
    reads=st.lists(st.tuples(st.integers(0, 60), st.integers(0, 25)), max_size=8),
)
def test_chunked_sample_rows_are_the_whole_sample_rows(n, chunk, reads):
    t = np.linspace(0.0, 3.0, n)
    whole = _spline_sample(t)
    saved = runner.CHUNK_TICKS
    runner.CHUNK_TICKS = chunk
    try:  # sampled as it is read, and sampled once in chunks of a temporary log (the runner's)
        samples = [
            ChunkedSample(_spline_sample, t, chunk),
            runner.stored_reference(SimpleNamespace(sample=_spline_sample), t),
        ]
    finally:
        runner.CHUNK_TICKS = saved
    for lazy in samples:
        for start, length in reads:
            start = min(start, n)
            stop = min(start + length, n)
            part = lazy.rows(start, stop)
            for name in ("t", "position", "velocity", "acceleration"):
                np.testing.assert_array_equal(getattr(part, name), getattr(whole, name)[start:stop])
        head = lazy.head(n // 2)
        for name in ("position", "velocity", "acceleration"):
            np.testing.assert_array_equal(getattr(lazy, name), getattr(whole, name))
        np.testing.assert_array_equal(head.position, whole.position[: n // 2])


def _log(sensors: dict) -> dict:
    setup = build_scenario(FastTrackingParams(duration=3.0, sensors=sensors))
    log = runner.simulate(setup)
    return {name: getattr(log, name) for name in ("qpos", "qvel", "act", "ctrl")}


@pytest.mark.parametrize("system", ["fused", "ideal"])
def test_fast_controller_in_small_plan_blocks_runs_the_same(monkeypatch, system):
    """Blocks of 16 ticks keeping 2 before the present one (the idealized path's fixes lie
    further back: their plan rows are computed alone) give the log of whole-run blocks."""
    whole = _log({"system": system})
    monkeypatch.setattr(fast_controller, "PLAN_BLOCK_TICKS", 16)
    monkeypatch.setattr(fast_controller, "PLAN_HISTORY_TICKS", 2)
    blocks = _log({"system": system})
    for name, value in whole.items():
        np.testing.assert_array_equal(blocks[name], value, err_msg=name)


@settings(max_examples=30, deadline=None)
@given(n=st.integers(1, 40), block=st.integers(1, 9), seed=st.integers(0, 2**32 - 1), stride=st.integers(1, 3))
def test_imu_errors_in_blocks_are_the_whole_run_s_draws(n, block, seed, stride):
    """ImuErrors, read every ``stride``-th tick in blocks of ``block`` ticks: the numbers of the
    whole arrays drawn at once, and the generator left where those draws leave it."""
    from planbench.fast import measurement

    white, bias, walk = 1e-3, 1e-2, 1e-4
    rng = np.random.default_rng(seed)
    whole = (
        rng.normal(0.0, white, (n, 2, 3))
        + rng.normal(0.0, bias, (1, 2, 3))
        + np.cumsum(rng.normal(0.0, walk, (n, 2, 3)), axis=0)
    )
    after = rng.normal(size=4)
    saved = measurement.IMU_BLOCK_TICKS
    measurement.IMU_BLOCK_TICKS = block
    try:
        rng = np.random.default_rng(seed)
        errors = measurement.ImuErrors(rng, n, white, bias, walk)
        np.testing.assert_array_equal(rng.normal(size=4), after)
        for tick in range(0, n, stride):
            np.testing.assert_array_equal(errors[tick], whole[tick])
        np.testing.assert_array_equal(errors[n - 1], whole[n - 1])
        if n > block:  # tick 0's block is gone
            with pytest.raises(IndexError, match="tick order"):
                errors[0]
    finally:
        measurement.IMU_BLOCK_TICKS = saved
