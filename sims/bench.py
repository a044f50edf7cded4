"""``planbench bench``: realtime factors and loop-to-bare-``mj_step`` ratios, side by side.

For each scenario (no video) it reports:
  realtime factor  simulated seconds per wall second of the whole run (planning, feed-forward,
                   loop, checks);
  loop ratio       physics steps per second inside the control loop divided by physics steps
                   per second of one bare ``mj_step(model, data, nstep=N)`` call on the same
                   model from the same initial state, with the same N, in the same process;
  the loop's split one more run with the loop's clocks on (``runner.simulate(profile=True)``):
                   the share of MuJoCo's steps, of the code under test (the controller's calls
                   and the online planner inside them) and of the testbed's own cost (sensors,
                   disturbance, logging, divergence scans).
  replay ratio     the loop's physics steps per second divided by those of MuJoCo alone
                   stepping the run's own motion (``replay_steps_per_second``: the logged
                   states and commands set tick by tick), and the replay's over bare: loop/bare
                   = loop/replay x replay/bare, the Python between the steps times MuJoCo's own
                   extra work on the run's motion.
The best of several runs is taken for all three (REPEATS, or the mechanism's ``benchmark_runs``),
so a busy machine affects every side alike; scenarios not tagged "benchmark" get one run each.
For the scenarios with drive trains as built it also reports their cost: the loop's wall time
per physics step against the ideal drives'.

Then: each mechanism's planner microbenchmark, the campaign engines' throughput (local with one
and two workers, Ray), a planner-only campaign's moves per second, and the peak memory of FAST
runs of two lengths (each in a process of its own; ``--six-hours``: also of a 6 h run) with the
disk space each run's log may take.
"""

from __future__ import annotations

import re
import time
import timeit
from pathlib import Path

import mujoco
import numpy as np

from planbench import pipeline, runner, scenarios

REPEATS = 5


def best_time(function, repeats: int = REPEATS):
    """(best wall time in s, the last result) of ``repeats`` calls of ``function()``."""
    last = [None]

    def call():
        last[0] = function()

    return min(timeit.repeat(call, number=1, repeat=repeats)), last[0]


def benchmarks() -> list[tuple[str, int]]:
    """(scenario, runs) of every scenario tagged "benchmark" (planbench.scenarios), with its
    mechanism's ``benchmark_runs``."""
    return [
        (s.name, record.benchmark_runs) for record in scenarios.mechanisms() for s in record.tagged(scenarios.BENCHMARK)
    ]


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


#: The arrays a replay sets before each tick's steps, in the order of MuJoCo's state
#: (``REPLAY_SPEC``): the logged state and the tick's command.
REPLAY_ARRAYS = ("qpos", "qvel", "act", "ctrl", "mocap_pos", "mocap_quat")
REPLAY_SPEC = int(runner.STATE_SPEC | mujoco.mjtState.mjSTATE_CTRL)


def replay_steps_per_second(setup, log, repeats: int = 1) -> tuple[float, float]:
    """MuJoCo alone on a run's own motion: for each tick of ``log`` (a finished run of the
    same scenario and parameters as ``setup``), its logged state (qpos, qvel, act, mocap) and
    command set with one ``mj_setState``, then the loop's ``mj_step(model, data, nstep=k)``;
    best of ``repeats`` passes.

    Bare stepping starts from rest; a run's motion can cost MuJoCo more per step (the drives'
    friction and the joint limits as active constraints, the solver's iterations while the
    machine accelerates), which loop/bare counts as if it were the loop's own. loop/replay
    leaves that out: what remains is the Python between the steps (the code under test and the
    testbed) and its effect on MuJoCo's caches. Not replayed: what the plant's Python writes
    besides the command (external forces such as the wind's, FAST's cable parameters); the
    solver's warm start is the replay's own previous step's.

    Returns (steps per second, the largest |difference| between the state a replayed tick
    ends in and the next logged state over the last pass: 0.0 where the run's plant writes
    nothing but the command, and the loop's MuJoCo calls are exactly these)."""
    physics = setup.physics
    model, data = physics.model.ptr, physics.data.ptr
    names = [name for name in REPLAY_ARRAYS if model.nmocap or not name.startswith("mocap")]
    ticks = log.n - 1
    k = log.physics_steps // ticks if ticks > 0 else 0
    if ticks <= 0 or k * ticks != log.physics_steps:
        raise ValueError(f"a replay needs a run of whole ticks; this log has {log.n} rows, {log.physics_steps} steps")
    size = mujoco.mj_stateSize(model, REPLAY_SPEC)
    commands = model.nq + model.nv + model.na  # where the command's columns begin
    state = np.r_[0:commands, commands + model.nu : size]  # a row's columns but the command
    end = np.empty(size)
    best, deviation = float("inf"), 0.0
    for _ in range(repeats):
        elapsed, deviation, pending = 0.0, 0.0, None
        for start, part in log.chunks(names):
            rows = np.concatenate([part[name].reshape(part[name].shape[0], -1) for name in names], axis=1)
            if rows.shape[1] != size:
                raise RuntimeError("MuJoCo's state layout is not qpos, qvel, act, ctrl, mocap_pos, mocap_quat")
            if pending is not None:  # the last chunk's final tick ended at this chunk's first row
                deviation = max(deviation, float(np.max(np.abs(pending - rows[0, state]))))
            steps = rows[: max(0, ticks - start)]
            clock = time.perf_counter()
            for row in steps:
                mujoco.mj_setState(model, data, row, REPLAY_SPEC)
                mujoco.mj_step(model, data, nstep=k)
            elapsed += time.perf_counter() - clock
            mujoco.mj_getState(model, data, end, REPLAY_SPEC)
            if steps.shape[0] < rows.shape[0]:  # the run's last row is in this chunk
                deviation = max(deviation, float(np.max(np.abs(end[state] - rows[steps.shape[0], state]))))
                pending = None
            else:
                pending = end[state].copy()
        best = min(best, elapsed)
    return ticks * k / best, deviation


def bench_scenario(name: str, repeats: int = REPEATS, drives_cost: bool = True) -> dict:
    """One scenario's row (module docstring): the best of ``repeats`` runs, one profiled run,
    bare stepping, and (``drives_cost``, where the scenario has drive trains as built) the
    loop's wall time per physics step against the ideal drives'."""
    scenario = scenarios.get(name)
    best_run, best_loop = None, None
    for _ in range(repeats):
        setup, result = pipeline.execute(scenario, scenario.params)
        if best_run is None or result.wall_time_s < best_run.wall_time_s:
            best_run = result
        loop_rate = result.log.physics_steps / result.log.loop_wall_s
        best_loop = loop_rate if best_loop is None else max(best_loop, loop_rate)
    # One more run with the loop's clocks on: physics, code under test, the testbed's own cost.
    profiled = pipeline.execute(scenario, scenario.params, profile=True)[1].log
    fresh = pipeline.build(scenario, scenario.params)
    bare = bare_steps_per_second(fresh, best_run.log.physics_steps)
    replay, replay_deviation = replay_steps_per_second(fresh, best_run.log, repeats)
    cost = None
    if drives_cost and "drives" in type(scenario.params).names() and scenario.params.drives != "ideal":
        # The drive trains' cost: the loop's wall time per tick against the ideal drives'.
        ideal = scenario.params.replace(drives="ideal")
        ideal_loop = max(
            result.log.physics_steps / result.log.loop_wall_s
            for _, result in (pipeline.execute(scenario, ideal) for _ in range(repeats))
        )
        cost = ideal_loop / best_loop - 1.0
    return {
        "scenario": name,
        "sim_time_s": best_run.sim_time_s,
        "wall_time_s": best_run.wall_time_s,
        "realtime_factor": best_run.sim_time_s / best_run.wall_time_s,
        "physics_steps": best_run.log.physics_steps,
        "loop_steps_per_s": best_loop,
        "bare_steps_per_s": bare,
        "loop_ratio": best_loop / bare,
        "replay_steps_per_s": replay,
        "replay_deviation": replay_deviation,
        "planner_wall_s": best_run.metrics.get("planner_wall_s"),
        "physics_share": profiled.physics_wall_s / profiled.loop_wall_s,
        "code_under_test_share": profiled.controller_wall_s / profiled.loop_wall_s,
        "drives_cost": cost,
        "benchmark": drives_cost,
        "passed": best_run.passed,
    }


def run_all() -> list[dict]:
    """Every scenario's row: those tagged "benchmark" with their mechanism's runs and the drive
    trains' cost, the others from one run each (their ratios are the noisier for it)."""
    tagged = dict(benchmarks())
    return [
        bench_scenario(name, tagged[name]) if name in tagged else bench_scenario(name, 1, drives_cost=False)
        for name in scenarios.SCENARIOS
    ]


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
        lines.append(
            f"{r['scenario']:<28} {100 * r['physics_share']:>7.0f}% {100 * r['code_under_test_share']:>20.0f}% "
            f"{100 * testbed:>7.0f}%"
        )
    lines.append("")
    lines.append(
        f"{'MuJoCo alone on the run (replay)':<33} {'replay steps/s':>14} {'replay/bare':>11} {'loop/replay':>11} "
        f"{'off the log':>11}"
    )
    for r in rows:
        if r.get("replay_steps_per_s"):
            replay = r["replay_steps_per_s"]
            lines.append(
                f"{r['scenario']:<33} {replay:>14.0f} {replay / r['bare_steps_per_s']:>11.2f} "
                f"{r['loop_steps_per_s'] / replay:>11.2f} {r.get('replay_deviation', float('nan')):>11.1e}"
            )
    lines.append(
        "replay: the run's logged states and commands set tick by tick, then the loop's mj_step; loop/bare = "
        "loop/replay x replay/bare, the Python between the steps times MuJoCo's own extra work on the run's motion; "
        "off the log: the largest |state - logged state| where a replayed tick ends (0: the run's own steps, bit for "
        "bit; above 0: the plant also writes what the replay leaves out, such as external forces)"
    )
    for r in rows:
        if r.get("planner_wall_s"):
            loop_wall = r["physics_steps"] / r["loop_steps_per_s"]
            share = r["planner_wall_s"] / loop_wall
            lines.append(
                f"{r['scenario']}: the online planner's updates take {r['planner_wall_s']:.2f} s "
                f"({100 * share:.0f} % of the loop); without them loop/bare would be "
                f"{r['loop_ratio'] / (1 - share):.2f}"
            )
    for r in rows:
        if r.get("drives_cost") is not None:
            lines.append(
                f"{r['scenario']}: the drive trains as built take {100 * r['drives_cost']:+.0f} % wall time "
                f"per physics step of the loop against the ideal drives (target <= +20 %)"
            )
    for r in rows:
        if r["scenario"] == "fast-tracking":
            lines.append(
                f"fast-tracking: 20 min of observation (the plan's {r['sim_time_s']:.0f} s with the "
                f"switch) in {r['wall_time_s']:.1f} s of wall time (target <= 60 s)"
            )
    one = [r["scenario"] for r in rows if not r.get("benchmark", True)]
    if one:
        lines.append(f"from one run each (the others the best of their mechanism's): {', '.join(one)}")
    lines.append(
        "targets: loop/bare >= 0.8 (the antenna's >= 0.5), the testbed's share <= 10 %; "
        "realtime x = simulated / wall time of the whole run"
    )
    return "\n".join(lines)


#: The campaign that ``planbench bench`` times: 2 x 2 grid points x 2 seeds of a hexapod
#: move with 40 s simulated (about 2 s of wall time per run), so that the workers' start
#: (spawning, importing MuJoCo) is a small part of it.
CAMPAIGN_SPEC = """\
scenario = "hexapod-sync-move"
seed = 1
seeds = 2
[parameters]
duration = 40.0
[grid]
wind = [0.0, 6.0]
elevation = [30.0, 90.0]
"""


def campaign_throughput(repeats: int = 2) -> list[dict]:
    """Runs per second of the same 8-run campaign (CAMPAIGN_SPEC) on the local engine with 1
    and 2 workers and on Ray with 2 CPUs, each timed from the first run sent to the last row
    written (planbench.campaign.Outcome.engine_wall_s), on engines in two states:

      started  the engine's workers start with the campaign: a local campaign's own pool, as
               ``planbench sweep`` starts it (once the spec is read; what is left of the
               workers' start is inside), the best of ``repeats``; Ray's first campaign on a
               fresh local cluster (its worker processes start inside, ``ray.init`` not);
      held     the best of ``repeats`` campaigns on an engine that served one campaign
               before: a local pool held across campaigns (``with LocalEngine(n)``), Ray's
               cluster with its workers up.

    The whole campaign up to its last row (``campaign_wall_s``: the spec's reading and, on a
    started engine, the workers' whole start) is reported beside it. The local campaigns run
    interleaved (x1, x2, then again) with no Ray process on the machine, then Ray's on a local
    cluster started for them alone. The tables must be equal run for run."""
    import contextlib
    import tempfile

    from planbench import campaign
    from planbench.campaign.engines import LocalEngine, ray_available

    outcomes: dict = {}
    with tempfile.TemporaryDirectory(prefix="planbench-bench-") as tmp:
        spec = Path(tmp) / "campaign.toml"
        spec.write_text(CAMPAIGN_SPEC)
        runs = iter(range(10**6))

        def sweep(key, engine, workers=None):
            outcome = campaign.sweep(
                spec,
                Path(tmp) / f"campaign-{next(runs)}",
                engine=engine,
                workers=workers,
                quiet=True,
                echo=lambda *_: None,
            )
            outcomes.setdefault(key, []).append(outcome)

        for _ in range(repeats):
            for workers in (1, 2):
                sweep(("local", workers, "started"), "local", workers)
        with contextlib.ExitStack() as stack:
            held = {workers: stack.enter_context(LocalEngine(workers)) for workers in (1, 2)}
            for workers in (1, 2):  # each pool's first campaign: its workers import the mechanism
                sweep(("local", workers, "warming"), held[workers])
            for _ in range(repeats):
                for workers in (1, 2):
                    sweep(("local", workers, "held"), held[workers])
        if ray_available():
            import ray

            # Ray's own processes (GCS, raylet, its idle workers) would share the two cores with
            # the local campaigns: its cluster is up for its campaigns only.
            ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
            try:
                sweep(("ray", 2, "started"), "ray")
                for _ in range(repeats):
                    sweep(("ray", 2, "held"), "ray")
            finally:
                ray.shutdown()
    tables = [o.table.drop(["wall_s"]) for done in outcomes.values() for o in done]
    same = all(t.equals(tables[0]) for t in tables[1:])
    rows = []
    for (engine, workers, state), done in outcomes.items():
        if state == "warming":
            continue
        best = min(done, key=lambda o: o.engine_wall_s)
        rows.append(
            {
                "engine": engine,
                "workers": workers,
                "state": state,
                "campaigns": len(done),
                "runs": best.ran,
                "wall_s": best.engine_wall_s,
                "runs_per_s": best.ran / best.engine_wall_s,
                "campaign_s": min(o.campaign_wall_s for o in done),
                "same_table": same,
            }
        )
    return rows


def format_campaign(rows: list[dict]) -> str:
    """The campaign table: each row against the local engine's x1 and x2 in the same state."""
    local = {(r["workers"], r["state"]): r for r in rows if r["engine"] == "local"}
    lines = [
        f"{'campaign throughput (8 runs)':<44} {'wall s':>7} {'runs/s':>7} {'vs local x1':>11} "
        f"{'vs local x2':>11} {'campaign s':>10}"
    ]
    for r in rows:
        what = (
            f"{r['engine']} x{r['workers']}, "
            + ("pool started with it" if r["engine"] == "local" else "first on its cluster")
            if r["state"] == "started"
            else f"{r['engine']} x{r['workers']}, " + ("pool held" if r["engine"] == "local" else "cluster up")
        )
        if r["campaigns"] > 1:
            what += f" (best of {r['campaigns']})"
        ratios = [
            f"{r['runs_per_s'] / local[(w, r['state'])]['runs_per_s']:>11.2f}"
            if (w, r["state"]) in local
            else f"{'':>11}"
            for w in (1, 2)
        ]
        lines.append(
            f"{what:<44} {r['wall_s']:>7.2f} {r['runs_per_s']:>7.3f} {' '.join(ratios)} {r['campaign_s']:>10.2f}"
        )
    lines.append(
        "wall s: first run sent to last row written; campaign s: the whole campaign to its last row (the "
        "spec's reading, and a started engine's workers' start, included; Ray's cluster itself already up)"
    )
    lines.append(
        "targets: local x2 >= 1.85 x local x1; local x2 no slower than ray x2; tables equal run for run: "
        + ("yes" if rows and rows[0]["same_table"] else "NO")
    )
    return "\n".join(lines)


#: The planner-only campaign that ``planbench bench`` times: the hexapod's random-moves example
#: (examples/hexapod/random_moves_campaign.toml) as it is, 10^6 moves (500 000 samples of each
#: of its two grid points), long enough that the workers' start is a small part of it.
PLAN_CAMPAIGN = Path(__file__).resolve().parents[1] / "examples" / "hexapod" / "random_moves_campaign.toml"


def planner_only_throughput(workers: int = 2, samples: int | None = None) -> dict:
    """Runs (moves) per second of a planner-only campaign of random hexapod moves on the local
    engine with ``workers`` workers, timed from the first chunk sent to the last row written,
    and the valid ones per second (invalid pairs, whose struts would leave their stroke, are
    skipped rows); ``total_s``: the whole ``sweep`` call, the workers' start, results.parquet
    and the report included. ``samples``: of each grid point (None: the example's own)."""
    import tempfile

    from planbench import campaign

    text = PLAN_CAMPAIGN.read_text()
    if samples is not None:
        text = re.sub(r"(?m)^samples = .*$", f"samples = {samples}", text)
    with tempfile.TemporaryDirectory(prefix="planbench-bench-") as tmp:
        spec = Path(tmp) / "moves.toml"
        spec.write_text(text)
        start = time.perf_counter()
        outcome = campaign.sweep(spec, Path(tmp) / "out", workers=workers, quiet=True, echo=lambda *_: None)
        total = time.perf_counter() - start
    counted = outcome.summary["overall"]["counted"]
    return {
        "runs": outcome.ran,
        "valid": counted,
        "wall_s": outcome.engine_wall_s,
        "workers": workers,
        "runs_per_s": outcome.ran / outcome.engine_wall_s,
        "valid_per_s": counted / outcome.engine_wall_s,
        "campaign_s": outcome.campaign_wall_s,
        "total_s": total,
    }


def format_planner_only(row: dict) -> str:
    return (
        f"planner-only campaign, {row['runs']} random hexapod moves ({row['valid']} valid), local x{row['workers']}: "
        f"{row['wall_s']:.2f} s, {row['runs_per_s']:.0f} moves/s ({row['valid_per_s']:.0f} valid/s); "
        f"{row.get('campaign_s', float('nan')):.2f} s from the call to the last row, "
        f"{row.get('total_s', float('nan')):.2f} s with results.parquet and the report; target >= 100000 moves/s"
    )


#: The runs whose peak memory ``planbench bench`` measures: FAST's tracking at these lengths, s.
MEMORY_SCENARIO = "fast-tracking"
MEMORY_DURATIONS_S = (300.0, None)  # None: the scenario's own length
SIX_HOURS_S = 6 * 3600.0


#: The child that ``peak_memory`` runs: the command line, which writes at its exit the larger of
#: its own memory's high-water mark (VmHWM, of its own address space: ru_maxrss of an exec'd
#: child would count the pages it held, as its parent's fork, before exec) and that of the
#: processes it forked and reaped (the run itself runs in one: planbench.supervise).
_PEAK_CHILD = """\
import atexit, resource, sys

def _peak():
    own = 0
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmHWM:"):
                own = int(line.split()[1])
    forked = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    sys.stderr.write(f"PEAK_KB {max(own, forked)}\\n")

atexit.register(_peak)
from planbench.cli import main
sys.exit(main(sys.argv[1:]))
"""


def peak_memory(scenario: str, duration: float | None) -> float:
    """Peak resident memory of ``planbench run SCENARIO [--duration D] --quiet`` in a process
    of its own, its outputs written to a temporary directory, MB (``_PEAK_CHILD``: Linux)."""
    import subprocess
    import sys
    import tempfile

    with tempfile.TemporaryDirectory(prefix="planbench-bench-") as tmp:
        # Its outputs (written as a run writes them) go to a directory of the bench's own, never
        # to the default results/NAME, which may hold a run of the user's.
        command = ["run", scenario, "--quiet", "--out", str(Path(tmp) / "run")] + (
            [] if duration is None else ["--duration", repr(duration)]
        )
        done = subprocess.run(
            [sys.executable, "-c", _PEAK_CHILD, *command], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True
        )
    peaks = [line.split()[1] for line in done.stderr.splitlines() if line.startswith("PEAK_KB ")]
    if done.returncode not in (0, 1) or not peaks:  # 1: a check failed, which still ran the whole run
        raise RuntimeError(f"planbench {' '.join(command)} exited {done.returncode}: {done.stderr[-500:]}")
    return int(peaks[-1]) / 1024.0


def memory_by_run_length(six_hours: bool = False) -> list[dict]:
    """Peak memory of MEMORY_SCENARIO at each of MEMORY_DURATIONS_S and, with ``six_hours``,
    of a 6 h run (minutes of wall time); each row with the disk its log may take (its
    parameters' log bytes per tick times its ticks: the log streams to disk)."""
    scenario = scenarios.get(MEMORY_SCENARIO)
    task = pipeline.build(scenario, scenario.params).task
    rows = []
    for duration in (*MEMORY_DURATIONS_S, SIX_HOURS_S):
        length = task.duration if duration is None else duration
        measured = duration != SIX_HOURS_S or six_hours
        rows.append(
            {
                "duration_s": length,
                "peak_mb": peak_memory(MEMORY_SCENARIO, duration) if measured else None,
                "log_mb": scenario.resolve(duration=length).log_bytes_per_tick() * length / task.control_dt / 2**20,
            }
        )
    return rows


def format_memory(rows: list[dict]) -> str:
    lines = [f"peak memory, {MEMORY_SCENARIO}   {'simulated s':>12} {'peak MB':>9}  {'log on disk, MB':>15}"]
    measured = [r for r in rows if r["peak_mb"] is not None]
    for r in rows:
        peak = "not run" if r["peak_mb"] is None else f"{r['peak_mb']:.0f}"
        log = f"{r['log_mb']:.0f}" if r.get("log_mb") is not None else ""
        note = "  (planbench bench --six-hours measures it)" if r["peak_mb"] is None else ""
        lines.append(f"{'':<30}{r['duration_s']:>12.0f} {peak:>9}  {log:>15}{note}")
    if len(measured) >= 2:
        first, last = measured[0], measured[-1]
        lines.append(
            f"{last['duration_s']:.0f} s over {first['duration_s']:.0f} s: {last['peak_mb'] / first['peak_mb']:.2f} x "
            f"(target: a 6 h run within 1.3 x the {first['duration_s']:.0f} s one's peak)"
        )
    return "\n".join(lines)


def planner_benchmarks() -> list[str]:
    """Each mechanism's planner rows (``sims/<mechanism>/bench.py``'s ``planner_benchmark``,
    where it has one), in the registry's order."""
    import importlib.util

    texts = []
    for record in scenarios.mechanisms():
        name = f"planbench.{record.name}.bench"
        if importlib.util.find_spec(name) is not None:
            texts.append(importlib.import_module(name).planner_benchmark())
    return texts
