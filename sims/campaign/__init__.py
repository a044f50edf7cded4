"""Campaigns: many runs of a typed scenario, locally or on Ray (README, "Campaigns").

``planbench sweep SPEC.toml --out DIR`` = ``sweep(...)``:
  1. read and check the spec (planbench.campaign.spec): every axis, value and distribution, and,
     unless ``invalid = "skip"``, every run's parameters, before any run starts;
  2. open DIR (planbench.campaign.store): new, or the same spec resumed (finished runs skipped);
  3. send chunks of runs to the engine (planbench.campaign.engines: a spawned process pool, started
     once the spec and the options hold, or Ray), and write each finished chunk's rows (one part file of
     the results table) and its runs' summaries as they come, under a tqdm bar of runs done,
     failures and time left; a planner-only campaign whose scenario judges columns sends its
     chunks as arrays (``worker.ColumnTask``) and gets Arrow tables back;
  4. write results.parquet and the report (planbench.campaign.report), print its table;
  5. ``--rerun-worst K``: simulate the K worst runs again, with video, into DIR/worst/.
"""

from __future__ import annotations

import math
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

from tqdm import tqdm

from planbench.campaign import engines, worker
from planbench.campaign import spec as spec_module
from planbench.campaign import store as store_module

#: Runs per task of a planner-only campaign (one vectorized judge_plans call each).
PLAN_CHUNK = 5_000


@dataclass
class Outcome:
    """What a campaign did: its summary (campaign.json), the runs run now, the table."""

    summary: dict
    ran: int
    skipped: int
    table: object
    worst: list
    engine_wall_s: float = (
        0.0  # from the first chunk sent to the last row written (what is left of the workers' start included)
    )
    campaign_wall_s: float = 0.0  # from the call to the last row written: the spec's reading and checks, the
    #                               workers' whole start, every run (the report not)


def context_of(spec) -> worker.Context:
    from planbench import scenarios

    try:
        mechanism = scenarios.mechanism_of(spec.scenario.name).name
    except ValueError:  # a scenario outside the registry: the workers look it up there as well
        mechanism = None
    return worker.Context(
        spec.scenario.name,
        spec.base_params.to_dict(),
        None if spec.base_plant is None else spec.base_plant.to_dict(),
        dict(spec.plugins),
        spec.mode,
        spec.save,
        tuple(a.column for a in spec.axes),
        spec.timeout,
        mechanism,
    )


def check_plugins(spec) -> None:
    """Make every plug-in of ``spec`` once, supervised (import, factory, contract), before any
    run: a PluginError (one line, exit 2) when one is missing, broken, exits or hangs."""
    if not spec.plugins:
        return
    from planbench import plugins, supervise
    from planbench.task import PluginError

    online = spec.scenario.online_planner

    def make_all():
        for role, plugin_spec in spec.plugins.items():
            plugins.make(plugin_spec, role, online_planner=online and role == "planner")

    limit = spec.timeout if spec.timeout is not None else supervise.DEFAULT_TIMEOUT_BASE_S
    try:
        supervise.run_supervised(make_all, limit)
    except supervise.Fault as fault:
        names = ", ".join(f"{role} = {s!r}" for role, s in spec.plugins.items())
        raise PluginError(
            f"{spec.path.name}: making its plug-ins ({names}) ended in {fault.ended.phase} "
            f"without completing: {fault.ended.how}"
        ) from None


def tasks_of(spec, runs) -> list[worker.RunTask]:
    out = []
    for run in runs:
        params, plant = spec.overrides(run)
        values = tuple(float(v) if a.leaf.kind == "float" else v for a, v in zip(spec.axes, run.values, strict=True))
        out.append(worker.RunTask(run.index, run.point, run.sample, run.replicate, run.seed, values, params, plant))
    return out


def columnar(spec) -> bool:
    """Whether the campaign's chunks go to the workers as columns (``worker.ColumnTask``):
    a planner-only campaign of a scenario with a columnar judge that takes its axes."""
    return worker.columns_supported(
        spec.scenario, spec.base_params, tuple(a.column for a in spec.axes), spec.plugins, spec.mode
    )


def column_chunks(spec, done, chunk_size: int):
    """The runs not in ``done`` (a sorted int64 array, or None), ``chunk_size`` indices at a
    time, as ``worker.ColumnTask``s (the random draws made once)."""
    import numpy as np

    draws = spec.draws()
    for lo in range(0, spec.size, chunk_size):
        index = np.arange(lo, min(lo + chunk_size, spec.size), dtype=np.int64)
        if done is not None and done.size:
            index = index[~np.isin(index, done, assume_unique=True)]
        if index.size:
            yield worker.ColumnTask(spec.columns(index, draws))


def count_status(rows) -> tuple[int, int]:
    """(failed, errors) among ``rows`` (dicts, or an Arrow table)."""
    if isinstance(rows, list):
        return (sum(r["status"] == "failed" for r in rows), sum(r["status"] == "error" for r in rows))
    import pyarrow.compute as pc

    status = rows.column("status")
    return (pc.sum(pc.equal(status, "failed")).as_py() or 0, pc.sum(pc.equal(status, "error")).as_py() or 0)


def check_runs(spec, runs, quiet: bool, total: int | None = None) -> None:
    """Every run's parameters validated (a ParamError naming the first bad run)."""
    if columnar(spec):
        return check_columns(spec, quiet)
    for run in tqdm(runs, desc="checking parameters", unit="run", disable=quiet, delay=2.0, leave=False, total=total):
        spec.resolve(run)


def check_columns(spec, quiet: bool) -> None:
    """``check_runs`` on columns: the runs validated on arrays a chunk at a time, and the first
    that the columnar check finds invalid or is unsure of resolved on its own (its ParamError,
    naming the run, is the one ``spec.resolve`` gives)."""
    import numpy as np

    from planbench.campaign.spec import Run, parse_path

    paths = [parse_path(a.column) for a in spec.axes]
    bar = tqdm(total=spec.size, desc="checking parameters", unit="run", disable=quiet, delay=2.0, leave=False)
    try:
        for task in column_chunks(spec, None, PLAN_CHUNK):
            c = task.columns
            messages, unsure, _ = spec.scenario.plan_columns.validate(
                spec.base_params, paths, [c[a.column] for a in spec.axes], len(task)
            )
            for i in np.flatnonzero(unsure | np.array([m is not None for m in messages], dtype=bool)):
                run = Run(
                    int(c["run"][i]),
                    int(c["point"][i]),
                    int(c["sample"][i]),
                    int(c["replicate"][i]),
                    int(c["seed"][i]),
                    tuple(worker._plain(c[a.column][i]) for a in spec.axes),
                )
                spec.resolve(run)
            bar.update(len(task))
    finally:
        bar.close()


def sweep(
    spec_path,
    out,
    engine="local",
    workers: int | None = None,
    address: str | None = None,
    rerun_worst: int = 0,
    quiet: bool = False,
    echo=print,
) -> Outcome:
    """Run (or resume) the campaign of ``spec_path`` into ``out``; see the module's steps.
    ``engine``: "local", "ray", or an engine the caller holds (``engines.LocalEngine`` in a
    ``with`` block: its workers serve this campaign and the next)."""
    from planbench.params import ParamError

    start = time.perf_counter()
    spec = spec_module.load(spec_path)
    target = store_module.CampaignDir(out)
    runner_engine = engines.make(engine, workers, address)
    if rerun_worst < 0:
        raise ParamError(f"--rerun-worst {rerun_worst} must be >= 0")
    if rerun_worst and spec.mode == "plan":
        raise ParamError("--rerun-worst replays simulated runs; a planner-only campaign has none")
    # The spec and the options hold: a local pool's workers start now (they import planbench
    # and MuJoCo while the runs' parameters and the plug-ins are checked and the directory is
    # opened); a campaign that stops before its runs ends them (``close``).
    context = context_of(spec)
    own_pool = isinstance(runner_engine, engines.LocalEngine) and not runner_engine.kept
    if own_pool:
        runner_engine.start(context)
    try:
        return _sweep(spec, context, target, runner_engine, rerun_worst, quiet, echo, start)
    finally:
        if own_pool:
            runner_engine.close()


def _sweep(spec, context, target, runner_engine, rerun_worst, quiet, echo, campaign_start) -> Outcome:
    if spec.invalid == "refuse":
        check_runs(spec, spec.iter_runs(), quiet, spec.size)
    check_plugins(spec)
    with target.reserved():
        target.open(spec, spec.path.read_text())
        done = target.done_array()  # the part files read once
        pending = spec.size - done.size
        chunk_size = (
            1
            if spec.mode == "simulate"
            else max(1, min(PLAN_CHUNK, math.ceil(pending / (4 * (runner_engine.workers or 1)))))
        )
        # Chunks are made as the engine asks for them: a campaign of 10^6 runs is never held whole.
        if columnar(spec):
            chunks = column_chunks(spec, done if done.size else None, chunk_size)
        else:
            done_set = set(done.tolist())
            chunks = (
                tasks_of(spec, runs)
                for runs in spec_module.iter_chunks(
                    (r for r in spec.iter_runs() if r.index not in done_set), chunk_size
                )
            )
        if done.size and not quiet:
            echo(f"resuming {target}: {done.size} of {spec.size} runs done, {pending} to go")
        failed = errors = 0
        bar = tqdm(total=spec.size, initial=done.size, unit="run", disable=quiet, desc="campaign", smoothing=0.1)
        start = time.perf_counter()
        try:
            for _, result in runner_engine.run(context, chunks):
                for index, files in result["files"].items():
                    target.write_run_files(index, files, spec.scenario.name)
                rows = result["table"] if "table" in result else result["rows"]
                target.append(rows, result["checks"])
                n_failed, n_errors = count_status(rows)
                failed += n_failed
                errors += n_errors
                bar.set_postfix(failed=failed, errors=errors, refresh=False)
                bar.update(len(rows))
        finally:
            bar.close()
        engine_wall = time.perf_counter() - start
        campaign_wall = time.perf_counter() - campaign_start
        table = target.table()
        from planbench.campaign import report  # (matplotlib and scipy.stats: the driver's alone)

        # results.parquet is encoded (Arrow's C++, outside the GIL) while the report draws:
        # a 10^6-run campaign's last seconds overlap. Both are whole when this block ends.
        with ThreadPoolExecutor(1, thread_name_prefix="planbench-results") as writer:
            written = writer.submit(target.write_results, table)
            summary = report.write(target, spec, table)
            written.result()
        worst = []
        if rerun_worst:
            worst = rerun_worst_runs(spec, target, table, rerun_worst, quiet, echo)
    return Outcome(summary, pending, done.size, table, worst, engine_wall, campaign_wall)


def rerun_worst_runs(spec, target, table, k: int, quiet: bool, echo) -> list:
    """Simulate the ``k`` worst runs again with a video each, into DIR/worst/RANK-run-NNNNNN/;
    the rerun's check values must equal the table's (the same parameters and seed)."""
    import numpy as np

    from planbench import outputs, pipeline
    from planbench.campaign import report

    picked = report.worst_runs(table, k, target.checks())
    rows = {r["run"]: r for r in table.to_pylist() if r["run"] in set(picked)}
    by_index = {run.index: run for run in spec.iter_runs() if run.index in rows}
    (target.path / "worst").mkdir(exist_ok=True)
    out = []
    for rank, index in enumerate(picked, start=1):
        params, plant = spec.resolve(by_index[index])
        folder = target.path / "worst" / f"{rank:02d}-run-{index:06d}"
        directory = outputs.OutputDir(folder, option="--rerun-worst")
        _, result = pipeline.execute(
            spec.scenario,
            params,
            plant,
            plugins=spec.plugins,
            out=directory,
            video=folder / f"{spec.scenario.name}.mp4",
            quiet=quiet,
        )
        row = rows[index]
        differ = [
            c.name
            for c in result.checks
            if not np.array_equal(np.float64(c.value), np.float64(row.get(f"check.{c.name}", np.nan)), equal_nan=True)
        ]
        note = "" if not differ else f" (differs from the campaign's row in {', '.join(differ)})"
        echo(
            f"worst #{rank}: run {index} ({spec.describe(by_index[index])}): "
            f"{'passed' if result.passed else 'FAILED'} -> {folder}{note}"
        )
        out.append((index, folder, differ))
    return out
