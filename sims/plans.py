"""``planbench plan``: the planned motion of a scenario, without physics."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from planbench.outputs import OutputDir
from planbench.planners.trajectory import control_ticks
from planbench.report import plan_plot

PLAN_DT = 0.001  # s, sampling of plan.npz and the plot
MAX_PLAN_SAMPLES = 60_000  # longer plans are sampled coarser (a 300 s plan at 5 ms)


def write_plan(scenario, out_dir, params=None) -> Path:
    """Write plan.npz (t, position, velocity, acceleration, labels, key points), plan.png and
    the scenario's extra files into ``out_dir`` (an OutputDir, or a path validated here), for
    ``params`` (default the scenario's own)."""
    target = out_dir if isinstance(out_dir, OutputDir) else OutputDir(out_dir, kind="plan")
    trajectory = scenario.plan(scenario.params if params is None else params)
    dt = max(PLAN_DT, trajectory.duration / MAX_PLAN_SAMPLES)
    sample = trajectory.sample(control_ticks(trajectory.duration, dt))
    kinds = scenario.kinds()
    with target.staging({"scenario": scenario.name}) as tmp:
        arrays = dict(
            t=sample.t,
            position=sample.position,
            velocity=sample.velocity,
            acceleration=sample.acceleration,
            labels=np.array(trajectory.labels),
            kinds=np.array(kinds),
        )
        key_times = getattr(trajectory, "key_times", None)
        key_points = getattr(trajectory, "key_points", None)
        if key_times is not None:
            arrays.update(key_times=key_times, key_points=key_points)
        np.savez_compressed(tmp / "plan.npz", **arrays)
        plan_plot(
            sample,
            trajectory.labels,
            kinds,
            tmp / "plan.png",
            title=f"{scenario.name}: planned motion",
            key_times=key_times,
            key_points=key_points,
        )
        if scenario.plan_extras is not None:
            scenario.plan_extras(trajectory, tmp)
    return target.path
