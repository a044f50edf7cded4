"""What a campaign's workers run: chunks of runs, rebuilt from plain data (README, "Campaigns").

A worker (a process of the local pool, or a Ray task) gets a ``Context`` once (the scenario's
name, its base parameters and plant as plain mappings, the plug-in specs, the mode) and then
chunks of ``RunTask``s (each run's index, seed and parameter overrides). It rebuilds the models
from the typed parameters itself; no MjModel, Physics or closure is ever pickled, so a Ray
cluster needs only planbench installed (and the plug-ins importable). A run that raises, or
whose parameters break a limit between them, is a row with its error: the chunk never raises.
Each row holds the run's place, seed and axis values, its status, every check's value, limit
and verdict, and its times; a simulated run also returns its summary.json (and, when asked,
timeseries.npz, report.png and a video) as bytes, which the campaign writes under DIR/runs/.
"""

from __future__ import annotations

import contextlib
import json
import signal
import threading
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

@dataclass(frozen=True)
class Context:
    """What every run of a campaign shares, as plain data."""

    scenario: str
    base_params: dict
    base_plant: dict | None
    plugins: dict
    mode: str
    save: tuple
    axes: tuple  # column names, in the order of RunTask.values
    timeout: float | None = None  # each run's wall-time limit, s (None: 600 s + its simulated duration)


@dataclass(frozen=True)
class RunTask:
    """One run, as plain data."""

    index: int
    point: int
    sample: int
    replicate: int
    seed: int
    values: tuple
    params: dict  # overrides of the base parameters (its axes and seed)
    plant: dict  # overrides of the base plant


_cache: dict = {}


def _base(context: Context):
    """(scenario, base params, base plant, made plug-ins), built once per worker and context."""
    key = json.dumps([context.scenario, context.base_params, context.base_plant, context.plugins], sort_keys=True,
                     default=str)
    if key not in _cache:
        from sims import plugins, scenarios

        scenario = scenarios.get(context.scenario)
        params = type(scenario.params).from_mapping(context.base_params)
        plant = None if context.base_plant is None else type(scenario.plant).from_mapping(context.base_plant)
        _cache.clear()
        _cache[key] = (scenario, params, plant, context.plugins, plugins)
    return _cache[key]


def _exception_text(e: BaseException) -> str:
    text = " ".join(f"{type(e).__name__}: {e}".split())
    return text if len(text) <= 500 else text[:497] + "..."


def row_of(context: Context, task: RunTask) -> dict:
    row = {"run": task.index, "point": task.point, "sample": task.sample, "replicate": task.replicate,
           "seed": task.seed}
    for column, value in zip(context.axes, task.values):
        row[column] = value if isinstance(value, (bool, int, float, str)) else json.dumps(value)
    return row


def _checks_into(row: dict, checks, meta: dict) -> None:
    for c in checks:
        row[f"check.{c.name}"] = float(c.value)
        row[f"limit.{c.name}"] = float(c.limit)
        row[f"pass.{c.name}"] = bool(c.passed)
        meta.setdefault(c.name, {"unit": c.unit, "comparison": c.comparison})


def run_chunk(context: Context, tasks: list[RunTask]) -> dict:
    """Run ``tasks``; returns {"rows": [...], "checks": {name: {unit, comparison}},
    "files": {run index: {file name: bytes}}}. Never raises for a run's own failure."""
    scenario, base_params, base_plant, plugin_specs, plugins = _base(context)
    rows, meta, files = [], {}, {}
    resolved = []
    for task in tasks:
        row = row_of(context, task)
        try:
            params = type(base_params).from_mapping(task.params, base=base_params)
            plant = base_plant if base_plant is None else type(base_plant).from_mapping(task.plant, base=base_plant,
                                                                                       prefix="plant.")
        except ValueError as e:
            row.update(status="invalid", passed=None, error=_exception_text(e), wall_s=0.0, sim_s=None)
            rows.append(row)
            continue
        resolved.append((task, row, params, plant))
        rows.append(row)
    if context.mode == "plan":
        _judge(scenario, resolved, plugin_specs, plugins, meta)
    else:
        for task, row, params, plant in resolved:
            files[task.index] = _simulate(scenario, context, params, plant, plugin_specs, row, meta)
    return {"rows": rows, "checks": meta, "files": files}


def _judge(scenario, resolved, plugin_specs, plugins, meta) -> None:
    """Planner-only: the scenario's ``judge_plans`` on every valid run of the chunk at once."""
    if not resolved:
        return
    start = time.perf_counter()
    try:
        planner = None
        if "planner" in plugin_specs:
            planner = plugins.make(plugin_specs["planner"], "planner")
        checks = scenario.judge_plans([p for _, _, p, _ in resolved], planner=planner)
    except (Exception, SystemExit) as e:  # noqa: BLE001  (the chunk's rows carry it)
        for _, row, _, _ in resolved:
            row.update(status="error", passed=None, error=_exception_text(e), wall_s=0.0, sim_s=None)
        return
    wall = (time.perf_counter() - start) / len(resolved)
    for (_, row, _, _), run_checks in zip(resolved, checks):
        _checks_into(row, run_checks, meta)
        passed = all(c.passed for c in run_checks)
        row.update(status="passed" if passed else "failed", passed=passed, error=None, wall_s=wall, sim_s=None)


class RunTimeout(BaseException):
    """A run passed its wall-time limit (raised by SIGALRM in the worker's main thread; a
    BaseException, so plug-in code's ``except Exception`` does not swallow it)."""


def _alarm(signum, frame):
    raise RunTimeout


@contextlib.contextmanager
def _watchdog(limit_s: float):
    """SIGALRM after ``limit_s`` s of wall time, in a worker's main thread (elsewhere: none).
    Python code that hangs (a sleep, a loop) is stopped; native code that never returns to
    the interpreter is not, and holds its worker until the campaign ends."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.setitimer(signal.ITIMER_REAL, limit_s)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def _simulate(scenario, context, params, plant, plugin_specs, row, meta) -> dict:
    """One run in MuJoCo (``sims.pipeline.execute``); its row filled in, its files returned."""
    from sims import outputs, pipeline, supervise
    from sims.logfile import LOG_FILE

    start = time.perf_counter()
    board = supervise.in_worker()
    limit = context.timeout if context.timeout is not None else supervise.DEFAULT_TIMEOUT_BASE_S

    def follow_duration(setup):
        if context.timeout is None:  # the default limit follows the simulated duration
            nonlocal limit
            limit += setup.task.duration
            signal.setitimer(signal.ITIMER_REAL, max(1e-3, limit - (time.perf_counter() - start)))

    try:
        with contextlib.ExitStack() as stack:
            out = video = None
            if context.save:
                out = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="planbench-run-"))) / "run"
                video = out / f"{scenario.name}.mp4" if "video" in context.save else None
            with _watchdog(limit):
                # The run's own time is limited; writing its files (planbench's) is not.
                _, result = pipeline.execute(scenario, params, plant, plugins=plugin_specs, out=out, video=video,
                                             on_built=follow_duration,
                                             on_judged=lambda _: signal.setitimer(signal.ITIMER_REAL, 0))
            if out is not None:
                # A campaign keeps a run's summary, timeseries, report and video, not its log
                # (the per-tick state: timeseries.npz has it at the rate saved).
                files = {p.name: p.read_bytes() for p in out.iterdir()
                         if p.is_file() and p.name not in (outputs.MANIFEST, LOG_FILE)}
                summary = json.loads(files["summary.json"])
                if summary.pop("log", None) is not None:
                    files["summary.json"] = (json.dumps(summary, indent=2) + "\n").encode()
            else:
                files = {"summary.json": (json.dumps(outputs.summary_dict(result), indent=2) + "\n").encode()}
    except RunTimeout:
        row.update(status="error", passed=None, error=f"timed out: the run passed its wall-time limit of "
                   f"{limit:g} s in {board.read_phase()}", wall_s=time.perf_counter() - start, sim_s=None)
        return {}
    except (Exception, SystemExit) as e:  # noqa: BLE001  (a run that raises is a row with its error)
        row.update(status="error", passed=None, error=_exception_text(e), wall_s=time.perf_counter() - start,
                   sim_s=None)
        return {}
    _checks_into(row, result.checks, meta)
    row.update(status="passed" if result.passed else "failed", passed=result.passed, error=None,
               wall_s=time.perf_counter() - start, sim_s=result.sim_time_s)
    return files
