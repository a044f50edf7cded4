"""The columnar path of planner-only campaigns (planbench.campaign: ``worker.ColumnTask``,
``planbench.hexapod.plan_columns``) against the run-by-run path: the same rows, run for run."""

from __future__ import annotations

import time

import numpy as np
import pyarrow.parquet as pq
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from planbench import campaign, cli
from planbench.campaign import spec as spec_module
from planbench.campaign import worker
from planbench.campaign.spec import run_seeds
from planbench.hexapod.params import _POSE_HIGH, _POSE_LOW
from planbench.params import ParamError

AXES = [f"start_pose[{i}]" for i in range(6)] + [f"moves[0].target[{i}]" for i in range(6)]


def _per_run(spec, index):
    """The rows of runs ``index`` by the run-by-run path (one from_mapping and one
    judge_plans list each), as the table the campaign writes."""
    runs = [r for r in spec.iter_runs() if r.index in set(int(i) for i in index)]
    result = worker.run_chunk(campaign.context_of(spec), campaign.tasks_of(spec, runs))
    return worker.rows_table(result["rows"]), result["checks"]


def _columns(spec, index):
    result = worker.run_columns(campaign.context_of(spec), worker.ColumnTask(spec.columns(np.asarray(index))))
    return result["table"], result["checks"]


def _same(a, b):
    a, b = a.drop(["wall_s"]), b.drop(["wall_s"])
    assert a.column_names == b.column_names
    for name in a.column_names:
        assert a.column(name).equals(b.column(name)), (name, a.column(name), b.column(name))
    assert a.schema.equals(b.schema) and a.equals(b)


def test_run_seeds_are_numpys_seed_sequence():
    rng = np.random.default_rng(5)
    for seed in (0, 1, 2026, 2**32 - 1, 2**32, 2**62 + 12345, 2**63 - 1):
        samples, replicates = rng.integers(0, 10**7, 200), rng.integers(0, 100_000, 200)
        samples[:2], replicates[:2] = (0, 2**32 - 1), (0, 99_999)
        got = run_seeds(seed, samples, replicates)
        for s, r, value in zip(samples, replicates, got, strict=True):
            state = np.random.SeedSequence(seed, spawn_key=(2, int(s), int(r))).generate_state(2, np.uint32)
            assert int(value) == (int(state[0]) << 31 ^ int(state[1])) & (2**63 - 1)


def _spec(tmp_path, seed, samples, seeds, axes, grid_sync, grid_axis, extra=""):
    lines = [
        'scenario = "hexapod-sync-move"',
        'mode = "plan"',
        f"seed = {seed}",
        f"samples = {samples}",
        f"seeds = {seeds}",
        'invalid = "skip"',
        extra,
        "[grid]",
    ]
    if grid_sync:
        lines.append(f'"moves[0].synchronous" = [{", ".join(grid_sync)}]')
    if grid_axis is not None:
        key, values = grid_axis
        lines.append(f'"{key}" = [{", ".join(repr(v) for v in values)}]')
    lines.append("[random]")
    for key, low, high in axes:
        lines.append(f'"{key}" = {{ distribution = "uniform", low = {low!r}, high = {high!r} }}')
    path = tmp_path / "spec.toml"
    path.write_text("\n".join(lines) + "\n")
    return spec_module.load(path)


def _bounds(key):
    i = int(key[-2])
    return _POSE_LOW[i], _POSE_HIGH[i]


@st.composite
def specs(draw):
    keys = draw(st.lists(st.sampled_from(AXES), min_size=1, max_size=6, unique=True))
    axes = []
    for key in keys:
        low, high = _bounds(key)
        a = draw(st.floats(0.0, 0.9))
        b = draw(st.floats(a + 0.05, 1.0))
        axes.append((key, low + a * (high - low), low + b * (high - low)))
    grid_sync = draw(st.sampled_from([(), ("true", "false"), ("false",), ("false", "true")]))
    free = [k for k in AXES if k not in keys]
    grid_axis = None
    if free and draw(st.booleans()):
        key = draw(st.sampled_from(free))
        low, high = _bounds(key)
        # (within 80 % of the pose limit: a grid value is checked alone when the spec loads,
        # and one axis near its limit can take a strut past its stroke by itself)
        grid_axis = (key, draw(st.lists(st.floats(0.8 * low, 0.8 * high), min_size=1, max_size=2)))
    return (
        draw(st.integers(0, 2**63 - 1)),
        draw(st.integers(2, 40)),
        draw(st.integers(1, 2)),
        axes,
        grid_sync,
        grid_axis,
    )


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(case=specs(), data=st.data())
def test_columns_give_the_rows_of_the_per_run_path(tmp_path, case, data):
    spec = _spec(tmp_path, *case)
    assert campaign.columnar(spec)
    # Any subset of the runs, as a resumed campaign's chunk has.
    index = sorted(data.draw(st.sets(st.integers(0, spec.size - 1), min_size=1, max_size=spec.size)))
    by_columns, checks = _columns(spec, index)
    by_runs, run_checks = _per_run(spec, index)
    _same(by_columns, by_runs)
    assert checks == run_checks


def test_columns_are_iter_runs(tmp_path):
    spec = _spec(
        tmp_path,
        7,
        9,
        3,
        [("start_pose[1]", -3.0, 3.0), ("moves[0].target[4]", -0.2, 0.2)],
        ("true", "false"),
        ("moves[0].target[2]", [1.0, -2.5]),
    )
    columns = spec.columns(np.arange(spec.size))
    for run in spec.iter_runs():
        assert (
            columns["run"][run.index],
            columns["point"][run.index],
            columns["sample"][run.index],
            columns["replicate"][run.index],
            columns["seed"][run.index],
        ) == (run.index, run.point, run.sample, run.replicate, run.seed)
        for axis, value in zip(spec.axes, run.values, strict=True):
            assert columns[axis.column][run.index] == value and type(columns[axis.column][run.index].item()) is type(
                value
            )


def test_invalid_rows_carry_each_ones_message(tmp_path):
    # Wide draws: most pairs put a strut beyond its stroke, at the target or at the start; the
    # message names the first finding, in from_mapping's order (the target's move, then the
    # start pose).
    spec = _spec(tmp_path, 3, 400, 1, [(k, *_bounds(k)) for k in AXES], ("true",), None)
    table, _ = _columns(spec, np.arange(spec.size))
    reference, _ = _per_run(spec, np.arange(spec.size))
    _same(table, reference)
    errors = [e for e in table.column("error").to_pylist() if e is not None]
    assert any(e.startswith("ParamError: moves[0].target strut") for e in errors)
    assert any(e.startswith("ParamError: start_pose strut") for e in errors)
    assert 0 < len(errors) < spec.size and len(set(errors)) > len(errors) // 2  # each its own numbers


def test_rare_findings_are_validated_run_by_run(tmp_path):
    # A target equal to the pose before it (a move of zero length) is not decided on arrays:
    # the run goes through from_mapping, with its message.
    spec = _spec(
        tmp_path,
        1,
        1,
        2,
        [],
        (),
        ("moves[0].target[0]", [0.0, 1.0, 0.0]),
        extra="[parameters]\nstart_pose = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]\n"
        "moves = [{ target = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0] }]",
    )
    assert campaign.columnar(spec)
    from planbench.hexapod import plan_columns

    paths = [("moves", 0, "target", 0)]
    messages, unsure, _ = plan_columns.validate(spec.base_params, paths, [np.array([0.0, 1.0])], 2)
    assert unsure.tolist() == [True, False] and messages == [None, None]
    table, _ = _columns(spec, np.arange(spec.size))
    reference, _ = _per_run(spec, np.arange(spec.size))
    _same(table, reference)
    zero = "ParamError: moves[0].target equals the pose before it (no strut length changes): a move of zero length"
    assert table.column("error").to_pylist() == [zero, zero, None, None, zero, zero]


def test_several_moves_per_run(tmp_path):
    spec = _spec(
        tmp_path,
        9,
        30,
        1,
        [("moves[0].target[0]", -3.0, 3.0), ("moves[0].target[3]", -0.2, 0.2)],
        ("true", "false"),
        None,
        extra="[parameters]\nmoves = [{ target = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0] }, "
        "{ target = [0.0, 2.0, 0.0, 0.0, 0.0, 0.1], synchronous = false }]",
    )
    assert campaign.columnar(spec)
    table, _ = _columns(spec, np.arange(spec.size))
    reference, _ = _per_run(spec, np.arange(spec.size))
    _same(table, reference)


def test_which_campaigns_take_the_columnar_path(tmp_path):
    def spec_of(extra, random='"start_pose[0]" = { distribution = "uniform", low = -1.0, high = 1.0 }', mode="plan"):
        path = tmp_path / "s.toml"
        path.write_text(f'scenario = "hexapod-sync-move"\nmode = "{mode}"\nsamples = 3\n{extra}\n[random]\n{random}\n')
        return spec_module.load(path)

    assert campaign.columnar(spec_of(""))
    assert not campaign.columnar(spec_of("", mode="simulate"))
    assert not campaign.columnar(spec_of("[grid]\nwind = [0.0, 1.0]"))  # an axis the columns do not take
    assert not campaign.columnar(spec_of('planner = "planbench.planners.hexapod:PaperMovePlanner"'))


@pytest.fixture(scope="module")
def per_run_campaign(tmp_path_factory):
    """(spec, table) of a 200-run planner-only campaign run run by run (the columns off),
    shared by the chunk sizes below."""
    tmp = tmp_path_factory.mktemp("per-run")
    spec = _spec(tmp, 21, 50, 2, [(k, *_bounds(k)) for k in AXES[:3] + AXES[6:9]], ("true", "false"), None)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(campaign, "columnar", lambda spec: False)
        runs = campaign.sweep(spec.path, tmp / "runs", workers=1, quiet=True)
    return spec, runs.table


@pytest.mark.parametrize("chunk", [1, 7, 40, 64])
def test_a_columnar_campaign_writes_the_per_run_table(tmp_path, monkeypatch, chunk, per_run_campaign):
    spec, per_run = per_run_campaign
    monkeypatch.setattr(campaign, "PLAN_CHUNK", chunk)
    assert campaign.columnar(spec)
    columns = campaign.sweep(spec.path, tmp_path / "columns", workers=1, quiet=True)
    assert columns.table.num_rows == spec.size == 200
    _same(columns.table, per_run)
    parts = sorted((tmp_path / "columns" / "table").glob("part-*.parquet"))
    size = min(chunk, -(-spec.size // 4))  # at most a quarter of the one worker's share (50 runs)
    assert len(parts) == -(-spec.size // size)
    assert sum(pq.read_metadata(p).num_rows for p in parts) == spec.size


def test_a_resumed_columnar_campaign_runs_only_the_missing_runs(tmp_path, monkeypatch):
    spec = _spec(tmp_path, 5, 40, 1, [(k, *_bounds(k)) for k in AXES[:2] + AXES[6:8]], ("true", "false"), None)
    monkeypatch.setattr(campaign, "PLAN_CHUNK", 10)
    out = tmp_path / "out"
    whole = campaign.sweep(spec.path, out, workers=1, quiet=True).table
    parts = sorted((out / "table").glob("part-*.parquet"))
    for part in parts[1::3]:  # as if killed with these chunks in flight
        part.unlink()
    missing = spec.size - sum(pq.read_metadata(p).num_rows for p in sorted((out / "table").glob("part-*.parquet")))
    resumed = campaign.sweep(spec.path, out, workers=1, quiet=True)
    assert resumed.ran == missing > 0 and resumed.skipped == spec.size - missing
    _same(resumed.table, whole)


def test_refuse_names_the_first_invalid_run_as_the_per_run_check(tmp_path):
    spec = _spec(tmp_path, 3, 50, 1, [(k, *_bounds(k)) for k in AXES], ("true",), None)
    path = spec.path
    path.write_text(path.read_text().replace('invalid = "skip"', 'invalid = "refuse"'))
    spec = spec_module.load(path)
    with pytest.raises(ParamError) as columnar:
        campaign.check_runs(spec, spec.iter_runs(), quiet=True)
    with pytest.raises(ParamError) as per_run:
        for run in spec.iter_runs():
            spec.resolve(run)
    assert str(columnar.value) == str(per_run.value) and str(columnar.value).startswith("run ")
    assert cli.main(["sweep", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    assert not (tmp_path / "o").exists()


def test_a_part_keeps_every_rows_keys():
    # The first row an invalid run's (no checks): the valid row after it keeps its check values.
    rows = [
        {"run": 0, "status": "invalid", "error": "ParamError: x", "wall_s": 0.0},
        {"run": 1, "check.a": 1.5, "limit.a": 2.0, "pass.a": True, "status": "passed", "error": None, "wall_s": 0.1},
    ]
    table = worker.rows_table(rows)
    assert table.column_names == ["run", "status", "error", "wall_s", "check.a", "limit.a", "pass.a"]
    assert table.column("check.a").to_pylist() == [None, 1.5] and table.column("pass.a").to_pylist() == [None, True]


def test_a_bad_spec_starts_no_worker_and_a_campaign_refused_later_ends_its_workers(tmp_path):
    import multiprocessing

    def children():
        return set(p.pid for p in multiprocessing.active_children())

    before = children()
    bad = tmp_path / "bad.toml"
    bad.write_text('scenario = "hexapod-sync-move"\n[grid]\nwindd = [1.0]\n')
    with pytest.raises(ParamError, match="unknown parameter 'windd'"):
        campaign.sweep(bad, tmp_path / "out", workers=2, quiet=True)
    assert children() <= before  # refused before the pool starts
    assert not (tmp_path / "out").exists()
    # A run refused by its parameters (invalid = "refuse"): found after the workers started.
    spec = _spec(tmp_path, 3, 50, 1, [(k, *_bounds(k)) for k in AXES], ("true",), None)
    spec.path.write_text(spec.path.read_text().replace('invalid = "skip"', 'invalid = "refuse"'))
    with pytest.raises(ParamError, match="^run "):
        campaign.sweep(spec.path, tmp_path / "refused", workers=2, quiet=True)
    # Ended, or ending: a worker still starting up when terminated takes its SIGTERM once it
    # unblocks its signals; it must be gone within seconds, not linger until the driver exits.
    deadline = time.monotonic() + 10.0
    while children() - before and time.monotonic() < deadline:
        time.sleep(0.1)
    assert children() <= before
    assert not (tmp_path / "refused").exists()
