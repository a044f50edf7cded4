"""``planbench bench``: realtime factors and loop-to-bare-``mj_step`` ratios, side by side.

For each benchmarked scenario (no video) it reports:
  realtime factor  simulated seconds per wall second of the whole run (planning, feed-forward,
                   loop, checks);
  loop ratio       physics steps per second inside the control loop divided by physics steps
                   per second of one bare ``mj_step(model, data, nstep=N)`` call on the same
                   model from the same initial state, with the same N, in the same process;
  the loop's split one more run with the loop's clocks on (``runner.simulate(profile=True)``):
                   the share of MuJoCo's steps, of the code under test (the controller's calls
                   and the online planner inside them) and of the testbed's own cost (sensors,
                   disturbance, logging, divergence scans).
The best of several runs is taken for both (REPEATS, or the mechanism's BENCHMARK count), so
a busy machine affects both sides alike.
"""

from __future__ import annotations

import time
import timeit

import mujoco
import numpy as np

from sims import runner, scenarios

REPEATS = 5


def best_time(function, repeats: int = REPEATS):
    """(best wall time in s, the last result) of ``repeats`` calls of ``function()``."""
    last = [None]

    def call():
        last[0] = function()

    return min(timeit.repeat(call, number=1, repeat=repeats)), last[0]


def benchmarks() -> list[tuple[str, int]]:
    """(scenario, runs) of every mechanism: its package's BENCHMARK (sims.scenarios)."""
    return [package.BENCHMARK for package in scenarios.mechanisms()]


def bare_steps_per_second(setup, n_steps: int) -> float:
    """Steps per second of one bare ``mj_step(..., nstep=n_steps)`` from the setup's state."""
    physics = setup.physics
    model, data = physics.model.ptr, physics.data.ptr
    state_size = mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    state = np.empty(state_size)
    mujoco.mj_getState(model, data, state, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    best = float("inf")
    for _ in range(REPEATS):
        mujoco.mj_setState(model, data, state, mujoco.mjtState.mjSTATE_FULLPHYSICS)
        start = time.perf_counter()
        mujoco.mj_step(model, data, nstep=n_steps)
        best = min(best, time.perf_counter() - start)
    mujoco.mj_setState(model, data, state, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    return n_steps / best


def bench_scenario(name: str, repeats: int = REPEATS) -> dict:
    scenario = scenarios.get(name)
    best_run, best_loop = None, None
    for _ in range(repeats):
        setup = scenario.build(scenario.params)
        result = runner.run(name, setup)
        if best_run is None or result.wall_time_s < best_run.wall_time_s:
            best_run = result
        loop_rate = result.log.physics_steps / result.log.loop_wall_s
        best_loop = loop_rate if best_loop is None else max(best_loop, loop_rate)
    # One more run with the loop's clocks on: physics, code under test, the testbed's own cost.
    profiled = runner.simulate(scenario.build(scenario.params), profile=True)
    setup = scenario.build(scenario.params)
    bare = bare_steps_per_second(setup, best_run.log.physics_steps)
    return {
        "scenario": name,
        "sim_time_s": best_run.sim_time_s,
        "wall_time_s": best_run.wall_time_s,
        "realtime_factor": best_run.sim_time_s / best_run.wall_time_s,
        "physics_steps": best_run.log.physics_steps,
        "loop_steps_per_s": best_loop,
        "bare_steps_per_s": bare,
        "loop_ratio": best_loop / bare,
        "planner_wall_s": best_run.metrics.get("planner_wall_s"),
        "physics_share": profiled.physics_wall_s / profiled.loop_wall_s,
        "code_under_test_share": profiled.controller_wall_s / profiled.loop_wall_s,
        "passed": best_run.passed,
    }


def run_all() -> list[dict]:
    return [bench_scenario(name, repeats) for name, repeats in benchmarks()]


def format_table(rows: list[dict]) -> str:
    lines = [
        f"{'scenario':<20} {'sim s':>7} {'wall s':>7} {'realtime x':>10} {'steps':>8} "
        f"{'loop steps/s':>13} {'bare steps/s':>13} {'loop/bare':>9}"
    ]
    for r in rows:
        lines.append(
            f"{r['scenario']:<20} {r['sim_time_s']:>7.2f} {r['wall_time_s']:>7.3f} "
            f"{r['realtime_factor']:>10.1f} {r['physics_steps']:>8d} {r['loop_steps_per_s']:>13.0f} "
            f"{r['bare_steps_per_s']:>13.0f} {r['loop_ratio']:>9.2f}"
        )
    lines.append("")
    lines.append(f"{'the loop, of its wall time':<28} {'physics':>8} {'planner + controller':>21} {'testbed':>8}")
    for r in rows:
        testbed = 1.0 - r["physics_share"] - r["code_under_test_share"]
        lines.append(f"{r['scenario']:<28} {100 * r['physics_share']:>7.0f}% {100 * r['code_under_test_share']:>20.0f}% "
                     f"{100 * testbed:>7.0f}%")
    for r in rows:
        if r.get("planner_wall_s"):
            loop_wall = r["physics_steps"] / r["loop_steps_per_s"]
            share = r["planner_wall_s"] / loop_wall
            lines.append(f"{r['scenario']}: the online planner's updates take {r['planner_wall_s']:.2f} s "
                         f"({100 * share:.0f} % of the loop); without them loop/bare would be "
                         f"{r['loop_ratio'] / (1 - share):.2f}")
    for r in rows:
        if r["scenario"] == "fast-tracking":
            lines.append(f"fast-tracking: 20 min of observation (the plan's {r['sim_time_s']:.0f} s with the "
                         f"switch) in {r['wall_time_s']:.1f} s of wall time (target <= 60 s, issue 6)")
    lines.append("loop/bare target >= 0.8 (issue 2); realtime x = simulated / wall time of the whole run")
    return "\n".join(lines)


def planner_benchmarks() -> list[str]:
    """Each mechanism's planner rows (``sims/<mechanism>/bench.py``'s ``planner_benchmark``,
    where it has one), in the registry's order."""
    import importlib.util

    texts = []
    for package in scenarios.mechanisms():
        name = f"{package.__name__}.bench"
        if importlib.util.find_spec(name) is not None:
            texts.append(importlib.import_module(name).planner_benchmark())
    return texts
