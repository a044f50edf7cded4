"""What a campaign's workers run: chunks of runs, rebuilt from plain data (README, "Campaigns").

A worker (a process of the local pool, or a Ray task) gets with each chunk a ``Context`` (the
scenario's name, its base parameters and plant as plain mappings, the plug-in specs, the mode)
and the chunk: ``RunTask``s (each run's index, seed and parameter overrides), or a planner-only
campaign's ``ColumnTask`` (its runs as arrays, ``run_columns``). It rebuilds the models
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
import tempfile
import threading
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
    mechanism: str | None = None  # the scenario's mechanism: a worker imports its package alone (None: all)


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


@dataclass(frozen=True)
class ColumnTask:
    """A chunk of runs of a planner-only campaign as columns (``CampaignSpec.columns``:
    "run", "point", "sample", "replicate", "seed" and each axis's values), validated and
    judged on arrays (``run_columns``)."""

    columns: dict

    def __len__(self) -> int:
        return len(self.columns["run"])


_cache: dict = {}


def _base(context: Context):
    """(scenario, base params, base plant, made plug-ins), built once per worker and context."""
    key = json.dumps(
        [context.scenario, context.base_params, context.base_plant, context.plugins], sort_keys=True, default=str
    )
    if key not in _cache:
        from planbench import plugins, scenarios

        scenario = (
            scenarios.get(context.scenario)
            if context.mechanism is None
            else scenarios.get_of(context.mechanism, context.scenario)
        )
        params = type(scenario.params).from_mapping(context.base_params)
        plant = None if context.base_plant is None else type(scenario.plant).from_mapping(context.base_plant)
        _cache.clear()
        _cache[key] = (scenario, params, plant, context.plugins, plugins)
    return _cache[key]


def prepare(context: Context) -> None:
    """What the runs of ``context`` share, made now (a local worker's start, while the driver
    checks the runs): the scenario's mechanism imported, the base parameters built."""
    _base(context)


def _exception_text(e: BaseException) -> str:
    text = " ".join(f"{type(e).__name__}: {e}".split())
    return text if len(text) <= 500 else text[:497] + "..."


def row_of(context: Context, task: RunTask) -> dict:
    row = {
        "run": task.index,
        "point": task.point,
        "sample": task.sample,
        "replicate": task.replicate,
        "seed": task.seed,
    }
    for column, value in zip(context.axes, task.values, strict=True):
        row[column] = value if isinstance(value, (bool, int, float, str)) else json.dumps(value)
    return row


def _checks_into(row: dict, checks, meta: dict) -> None:
    for c in checks:
        row[f"check.{c.name}"] = float(c.value)
        row[f"limit.{c.name}"] = float(c.limit)
        row[f"pass.{c.name}"] = bool(c.passed)
        meta.setdefault(c.name, {"unit": c.unit, "comparison": c.comparison})


def run_chunk(context: Context, tasks) -> dict:
    """Run ``tasks``; returns {"rows": [...], "checks": {name: {unit, comparison}},
    "files": {run index: {file name: bytes}}} (a ``ColumnTask``: {"table": ..., "checks":
    ..., "files": {}}, ``run_columns``). Never raises for a run's own failure."""
    if isinstance(tasks, ColumnTask):
        return run_columns(context, tasks)
    scenario, base_params, base_plant, plugin_specs, plugins = _base(context)
    rows, meta, files = [], {}, {}
    resolved = []
    for task in tasks:
        row = row_of(context, task)
        try:
            params = type(base_params).from_mapping(task.params, base=base_params)
            plant = (
                base_plant
                if base_plant is None
                else type(base_plant).from_mapping(task.plant, base=base_plant, prefix="plant.")
            )
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
    for (_, row, _, _), run_checks in zip(resolved, checks, strict=True):
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
    """One run in MuJoCo (``planbench.pipeline.execute``); its row filled in, its files returned."""
    from planbench import outputs, pipeline, supervise
    from planbench.logfile import LOG_FILE

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
                _, result = pipeline.execute(
                    scenario,
                    params,
                    plant,
                    plugins=plugin_specs,
                    out=out,
                    video=video,
                    on_built=follow_duration,
                    on_judged=lambda _: signal.setitimer(signal.ITIMER_REAL, 0),
                )
            if out is not None:
                # A campaign keeps a run's summary, timeseries, report and video, not its log
                # (the per-tick state: timeseries.npz has it at the rate saved).
                files = {
                    p.name: p.read_bytes()
                    for p in out.iterdir()
                    if p.is_file() and p.name not in (outputs.MANIFEST, LOG_FILE)
                }
                summary = json.loads(files["summary.json"])
                if summary.pop("log", None) is not None:
                    files["summary.json"] = (json.dumps(summary, indent=2) + "\n").encode()
            else:
                files = {"summary.json": (json.dumps(outputs.summary_dict(result), indent=2) + "\n").encode()}
    except RunTimeout:
        row.update(
            status="error",
            passed=None,
            error=f"timed out: the run passed its wall-time limit of {limit:g} s in {board.read_phase()}",
            wall_s=time.perf_counter() - start,
            sim_s=None,
        )
        return {}
    except (Exception, SystemExit) as e:  # noqa: BLE001  (a run that raises is a row with its error)
        row.update(
            status="error", passed=None, error=_exception_text(e), wall_s=time.perf_counter() - start, sim_s=None
        )
        return {}
    _checks_into(row, result.checks, meta)
    row.update(
        status="passed" if result.passed else "failed",
        passed=result.passed,
        error=None,
        wall_s=time.perf_counter() - start,
        sim_s=result.sim_time_s,
    )
    return files


# --------------------------------------------------------------------------- columns


#: A row's columns besides its place, its axes and its checks, in the order of the table.
STATUS_COLUMNS = ("status", "passed", "error", "wall_s", "sim_s")


def _check_key(key: str) -> bool:
    return key.startswith(("check.", "limit.", "pass."))


def rows_table(rows: list[dict]):
    """``rows`` (dicts) as an Arrow table: every key any row has (a row without it: null),
    in the order they first appear, the checks' columns last; the types as Arrow infers
    them from the values (as ``pa.Table.from_pylist``, which would keep only the first
    row's keys)."""
    import pyarrow as pa

    keys: dict = {}
    for row in rows:
        for key in row:
            keys.setdefault(key, None)
    order = [k for k in keys if not _check_key(k)] + [k for k in keys if _check_key(k)]
    return pa.Table.from_pydict({k: [row.get(k) for row in rows] for k in order})


def _head_arrays(context: Context, columns: dict, n: int) -> dict:
    import numpy as np
    import pyarrow as pa

    out = {k: pa.array(np.asarray(columns[k], dtype=np.int64)) for k in ("run", "point", "sample", "replicate", "seed")}
    for column in context.axes:
        values = columns[column]
        if isinstance(values, np.ndarray):
            out[column] = pa.array(values)
        else:
            out[column] = pa.array([v if isinstance(v, (bool, int, float, str)) else json.dumps(v) for v in values])
    return out


def _status_arrays(status: list, passed: list, errors: list, wall) -> dict:
    import pyarrow as pa

    n = len(status)
    return {
        "status": pa.array(status),
        "passed": pa.array(passed),
        "error": pa.array(errors),
        "wall_s": pa.array(wall, pa.float64()),
        "sim_s": pa.nulls(n),
    }


def lost_columns(context: Context, task: ColumnTask, why: str) -> dict:
    """The rows of a column chunk whose worker died: status "error" with the reason."""
    import pyarrow as pa

    n = len(task)
    arrays = {
        **_head_arrays(context, task.columns, n),
        **_status_arrays(["error"] * n, [None] * n, [why] * n, [0.0] * n),
    }
    return {"table": pa.Table.from_pydict(arrays), "checks": {}, "files": {}}


def columns_supported(scenario, base_params, context_axes, plugins: dict, mode: str) -> bool:
    """Whether a campaign's chunks can be columns: planner-only, the scenario's own planner
    (no plug-in), a scenario with a columnar judge (``plan_columns``) that takes every axis."""
    from planbench.campaign.spec import parse_path

    columnar = getattr(scenario, "plan_columns", None)
    if mode != "plan" or columnar is None or plugins.get("planner"):
        return False
    if any(axis.startswith("plant.") for axis in context_axes):
        return False
    return columnar.supports(base_params, [parse_path(axis) for axis in context_axes])


def _overrides(base: dict, paths, values, seed: int) -> dict:
    """A run's parameter overrides (``CampaignSpec.overrides``) from its axis values."""
    import copy

    from planbench.campaign.spec import set_path

    out = {"seed": seed}
    for path, value in zip(paths, values, strict=True):
        if len(path) == 1:
            out[path[0]] = value
            continue
        if path[0] not in out:
            out[path[0]] = copy.deepcopy(base[path[0]])
        set_path({path[0]: out[path[0]]}, path, value, str(path))
    return out


def _plain(value):
    return value.item() if hasattr(value, "item") else value


def run_columns(context: Context, task: ColumnTask) -> dict:
    """A planner-only chunk as columns: its runs validated on arrays (the rare ones the
    columnar check is unsure of by ``from_mapping``, one at a time), every valid run judged
    at once (``scenario.plan_columns``), its rows an Arrow table built from arrays; the same
    rows as ``run_chunk`` of the same runs one at a time (tested)."""
    import numpy as np
    import pyarrow as pa

    from planbench.campaign.spec import parse_path

    scenario, base_params, _, _, _ = _base(context)
    columnar = scenario.plan_columns
    columns = task.columns
    n = len(task)
    paths = [parse_path(axis) for axis in context.axes]
    values = [columns[axis] for axis in context.axes]
    messages, unsure, poses = columnar.validate(base_params, paths, values, n)
    # validate's messages are one line with single spaces, far under 500 characters: the
    # text _exception_text gives their ParamError.
    errors = [None if m is None else "ParamError: " + m for m in messages]
    base_dict = None
    for i in np.flatnonzero(unsure):
        base_dict = base_params.to_dict() if base_dict is None else base_dict
        mapping = _overrides(base_dict, paths, [_plain(v[i]) for v in values], int(columns["seed"][i]))
        try:
            type(base_params).from_mapping(mapping, base=base_params)
            errors[i] = None
        except ValueError as e:
            errors[i] = _exception_text(e)
    valid = np.array([e is None for e in errors], dtype=bool)
    status = np.where(valid, "passed", "invalid").astype(object)
    passed = np.full(n, None, dtype=object)
    wall = np.zeros(n)
    checks, meta = [], {}
    index = np.flatnonzero(valid)
    if index.size:
        start = time.perf_counter()
        try:
            checks = columnar.judge(tuple(p[index] for p in poses))
        except (Exception, SystemExit) as e:  # noqa: BLE001  (the chunk's rows carry it)
            status[index] = "error"
            text = _exception_text(e)
            for i in index:
                errors[i] = text
        else:
            wall[index] = (time.perf_counter() - start) / index.size
            ok = np.ones(index.size, dtype=bool)
            for name, unit, comparison, _limit, _value, present, good in checks:
                ok &= ~present | good
                meta.setdefault(name, {"unit": unit, "comparison": comparison})
            status[index] = np.where(ok, "passed", "failed")
            passed[index] = ok.tolist()
    arrays = {**_head_arrays(context, columns, n), **_status_arrays(status.tolist(), passed.tolist(), errors, wall)}
    for name, _unit, _comparison, limit, value, present, good in checks:
        mask = np.ones(n, dtype=bool)
        mask[index[present]] = False
        full = np.zeros(n)
        full[index] = value
        limits = np.zeros(n)
        limits[index] = limit
        verdict = np.zeros(n, dtype=bool)
        verdict[index] = good
        arrays[f"check.{name}"] = pa.array(full, mask=mask)
        arrays[f"limit.{name}"] = pa.array(limits, mask=mask)
        arrays[f"pass.{name}"] = pa.array(verdict, mask=mask)
    # The checks' columns in the order the rows list them, each check's three together.
    return {"table": pa.Table.from_pydict(arrays), "checks": meta, "files": {}}
