"""``planbench bench``'s planner row for FAST: planning and sampling a long observation."""

from __future__ import annotations

import time

import numpy as np

from planbench.bench import REPEATS


def fast_plan_rate(hours: float = 4.0, rate_hz: float = 10.0) -> dict:
    """Time to plan a FAST tracking observation of ``hours`` (switch, start, tracking,
    termination) and to sample every channel of it at ``rate_hz`` (best of REPEATS)."""
    from planbench import fast

    best_plan, best_sample = float("inf"), float("inf")
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        plan = fast.tracking_plan(duration=hours * 3600.0)
        t1 = time.perf_counter()
        t = np.arange(0.0, plan.duration, 1.0 / rate_hz)
        plan.state(t)
        t2 = time.perf_counter()
        best_plan, best_sample = min(best_plan, t1 - t0), min(best_sample, t2 - t1)
    return {
        "hours": hours,
        "rate_hz": rate_hz,
        "samples": t.size,
        "plan_s": best_plan,
        "sample_s": best_sample,
        "samples_per_s": t.size / best_sample,
    }


def format_fast(row: dict) -> str:
    return (
        f"FAST plan: {row['hours']:g} h of tracking planned in {row['plan_s']:.3f} s; "
        f"{row['samples']} samples at {row['rate_hz']:g} Hz (feed, cabin pose, A-B angles, "
        f"cables, tensions, Stewart legs) in {row['sample_s']:.3f} s = "
        f"{row['samples_per_s']:.0f} samples/s"
    )


def planner_benchmark() -> str:
    """The rows ``planbench bench`` prints after the scenario table."""
    return format_fast(fast_plan_rate())
