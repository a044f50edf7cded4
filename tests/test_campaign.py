"""Campaigns (planbench sweep): specs, engines, resume after SIGKILL, the report, bad specs.

The campaign of these tests is 2 x 2 grid points x 2 seeds of hexapod-sync-move (8 runs of
about a second each), run once on the local pool and once on Ray; the tables must be equal
run for run (every column but the wall time).
"""

from __future__ import annotations

import itertools
import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from planbench import cli
from planbench.campaign import report
from planbench.campaign import spec as spec_module
from planbench.campaign.store import CampaignDir
from planbench.params import ParamError

PLANBENCH = [sys.executable, "-m", "planbench.cli"]

SPEC = """\
scenario = "hexapod-sync-move"
seed = 11
seeds = 2
[grid]
wind = [0.0, 6.0]
elevation = [30.0, 90.0]
"""


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def _comparable(table):
    """The table without its timing columns (the only ones that may differ between runs)."""
    return table.drop([c for c in ("wall_s",) if c in table.column_names])


@pytest.fixture(scope="module")
def local_campaign(tmp_path_factory):
    root = tmp_path_factory.mktemp("campaign")
    spec = _write(root / "spec.toml", SPEC)
    out = root / "local"
    code = cli.main(["sweep", str(spec), "--out", str(out), "--workers", "2", "--quiet"])
    assert code == cli.EXIT_OK
    return spec, out, pq.read_table(out / "results.parquet")


def test_campaign_table_has_a_row_per_run(local_campaign):
    spec_path, out, table = local_campaign
    spec = spec_module.load(spec_path)
    assert table.num_rows == spec.size == 8
    assert table.column("run").to_pylist() == list(range(8))
    # Run r of point p, replicate k: the grid in written order, seeds innermost.
    assert table.column("wind").to_pylist() == [0.0] * 4 + [6.0] * 4
    assert table.column("elevation").to_pylist() == [30.0, 30.0, 90.0, 90.0] * 2
    seeds = table.column("seed").to_pylist()
    assert seeds[0::2] == [seeds[0]] * 4 and seeds[1::2] == [seeds[1]] * 4 and seeds[0] != seeds[1]
    assert set(table.column("status").to_pylist()) == {"passed"}
    for name in ("pose_error_final", "strut_force", "following_error"):
        assert np.all(np.isfinite(table.column(f"check.{name}").to_numpy()))
    # Each run's summary.json is the run: its parameters and seed are the row's.
    summary = json.loads((out / "runs" / "000005" / "summary.json").read_text())
    assert summary["seed"] == seeds[5]
    assert summary["parameters"]["wind"] == 6.0 and summary["parameters"]["elevation"] == 30.0
    value = [c["value"] for c in summary["checks"] if c["name"] == "pose_error_final"][0]
    assert value == table.column("check.pose_error_final")[5].as_py()
    # The wind changes the tracking: the axis reaches the physics (as built the struts'
    # friction, not the wind, sets the size of the following error).
    following = table.column("check.following_error").to_numpy()
    assert np.all(np.abs(following[4:] - following[:4]) > 1e-3)


def test_campaign_report(local_campaign):
    _, out, table = local_campaign
    summary = json.loads((out / "campaign.json").read_text())
    assert summary["overall"]["counted"] == 8 and summary["overall"]["passed"] == 8
    low, high = summary["overall"]["pass_rate_ci95"]
    # Wilson's interval of 8 of 8: [n / (n + z^2), 1].
    z = 1.959963984540054
    assert low == pytest.approx(8 / (8 + z * z), rel=1e-9) and high == pytest.approx(1.0)
    point = summary["by_point"][3]
    assert point["grid"] == {"wind": 6.0, "elevation": 90.0} and point["counted"] == 2
    values = table.column("check.pose_error_final").to_numpy()[6:8]
    assert point["checks"]["pose_error_final"]["median"] == pytest.approx(np.median(values))
    assert point["checks"]["pose_error_final"]["p95"] == pytest.approx(np.percentile(values, 95))
    assert summary["checks"]["pose_error_final"]["limit"] == 1.0
    assert (out / "campaign.png").stat().st_size > 10_000
    assert sorted(p.name for p in (out / "plots").iterdir()) == sorted(f"{n}.png" for n in summary["checks"])


def test_wilson_interval_against_the_formula():
    for k, n in ((0, 10), (3, 10), (7, 9), (50, 100)):
        z = 1.959963984540054
        p = k / n
        centre = (p + z * z / (2 * n)) / (1 + z * z / n)
        half = z / (1 + z * z / n) * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n))
        low, high = report.wilson(k, n)
        assert low == pytest.approx(max(0.0, centre - half), abs=1e-12)
        assert high == pytest.approx(min(1.0, centre + half), abs=1e-12)
    assert report.wilson(0, 0) == (None, None)


def test_resume_skips_finished_runs_and_keeps_their_rows(local_campaign, capsys):
    spec, out, table = local_campaign
    before = {p.name: p.stat().st_mtime_ns for p in (out / "table").iterdir()}
    code = cli.main(["sweep", str(spec), "--out", str(out), "--quiet"])
    assert code == cli.EXIT_OK
    assert "(0 run now, 8 resumed)" in capsys.readouterr().out
    assert {p.name: p.stat().st_mtime_ns for p in (out / "table").iterdir()} == before
    assert _comparable(pq.read_table(out / "results.parquet")).equals(_comparable(table))


def test_a_changed_spec_is_refused(local_campaign, tmp_path, capsys):
    spec, out, _ = local_campaign
    changed = _write(tmp_path / "spec.toml", SPEC.replace("seed = 11", "seed = 12"))
    before = sorted(p.name for p in (out / "table").iterdir())
    code = cli.main(["sweep", str(changed), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert code == cli.EXIT_BAD_INPUT and len(err.splitlines()) == 1 and "another spec" in err
    assert sorted(p.name for p in (out / "table").iterdir()) == before


def test_ray_engine_gives_the_same_table(local_campaign, tmp_path):
    ray = pytest.importorskip("ray", reason="the ray extra is not installed (pip install 'planbench[ray]')")
    spec, _, table = local_campaign
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
    try:
        code = cli.main(["sweep", str(spec), "--out", str(tmp_path / "ray"), "--engine", "ray", "--quiet"])
    finally:
        ray.shutdown()
    assert code == cli.EXIT_OK
    assert _comparable(pq.read_table(tmp_path / "ray" / "results.parquet")).equals(_comparable(table))


def test_sigkill_then_resume_loses_and_duplicates_nothing(local_campaign, tmp_path):
    spec, _, table = local_campaign
    out = tmp_path / "killed"
    process = subprocess.Popen(
        [*PLANBENCH, "sweep", str(spec), "--out", str(out), "--workers", "2", "--quiet"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    deadline = time.monotonic() + 120
    try:
        while time.monotonic() < deadline:
            parts = list((out / "table").glob("part-*.parquet")) if (out / "table").is_dir() else []
            if len(parts) >= 2 or process.poll() is not None:
                break
            time.sleep(0.05)
    finally:
        os.killpg(process.pid, signal.SIGKILL)  # the campaign and its workers, mid-run
        process.wait()
    killed = CampaignDir(out)
    done = killed.done()
    assert 2 <= len(done) < 8, f"the kill came too late to test anything ({len(done)} rows)"
    rows_before = killed.table()
    assert len(rows_before.column("run").to_pylist()) == len(set(rows_before.column("run").to_pylist()))
    code = cli.main(["sweep", str(spec), "--out", str(out), "--quiet"])
    assert code == cli.EXIT_OK
    after = pq.read_table(out / "results.parquet")
    assert after.column("run").to_pylist() == list(range(8))
    assert _comparable(after).equals(_comparable(table))
    # The rows of the killed campaign are kept as they were written.
    kept = after.filter(np.isin(after.column("run").to_numpy(), sorted(done)))
    assert _comparable(kept).equals(_comparable(rows_before))


def test_a_run_that_raises_is_a_row_not_a_crash(tmp_path, capsys):
    _write(
        tmp_path / "bad_planner.py",
        """
from planbench.planners.hexapod import PaperMovePlanner

class Picky(PaperMovePlanner):
    def plan(self, problem):
        if problem.target_pose[0] > 0.0015:
            raise RuntimeError("refuses long moves")
        return super().plan(problem)

def make():
    return Picky()
""",
    )
    spec = _write(
        tmp_path / "spec.toml",
        """
scenario = "hexapod-sync-move"
planner = "bad_planner.py:make"
[parameters]
duration = 1.0
[grid]
"moves[0].target[0]" = [1.0, 2.0]
""",
    )
    code = cli.main(["sweep", str(spec), "--out", str(tmp_path / "out"), "--workers", "1", "--quiet"])
    assert code == cli.EXIT_CHECK_FAILED
    table = pq.read_table(tmp_path / "out" / "results.parquet")
    assert table.column("status").to_pylist()[1] == "error"
    assert "refuses long moves" in table.column("error").to_pylist()[1]
    assert table.column("status").to_pylist()[0] in ("passed", "failed")
    assert re.search(r"NOT ALL PASSED: [01] of 2 runs passed", capsys.readouterr().out)


def test_a_worker_that_dies_costs_only_its_run(tmp_path):
    planner = _write(
        tmp_path / "fatal_planner.py",
        """
import os
from planbench.planners.hexapod import PaperMovePlanner

class Fatal(PaperMovePlanner):
    def plan(self, problem):
        if problem.target_pose[0] > 0.0015:
            os._exit(3)  # the process dies, as on an out-of-memory kill
        return super().plan(problem)

def make():
    return Fatal()
""",
    )
    spec = _write(
        tmp_path / "spec.toml",
        f"""
scenario = "hexapod-sync-move"
planner = "{planner.name}:make"
[parameters]
duration = 0.5
[grid]
"moves[0].target[0]" = [1.0, 2.0, 1.2]
""",
    )
    code = cli.main(["sweep", str(spec), "--out", str(tmp_path / "out"), "--workers", "1", "--quiet"])
    assert code == cli.EXIT_CHECK_FAILED
    table = pq.read_table(tmp_path / "out" / "results.parquet")
    assert table.column("run").to_pylist() == [0, 1, 2]
    status = table.column("status").to_pylist()
    assert status[1] == "error" and "died twice" in table.column("error").to_pylist()[1]
    assert status[0] != "error" and status[2] != "error"


class _PoolThatBreaksOnSubmit:
    """An in-process stand-in for ProcessPoolExecutor whose first pool refuses its third
    submit, as a real pool does when a worker died between two submits."""

    pools = 0

    def __init__(self, max_workers, mp_context, initializer, initargs):
        import concurrent.futures as cf

        self._cf, self._submits = cf, 0
        self._breaks = _PoolThatBreaksOnSubmit.pools == 0
        _PoolThatBreaksOnSubmit.pools += 1
        initializer(*initargs)

    def submit(self, fn, *args):
        self._submits += 1
        if self._breaks and self._submits == 3:
            raise self._cf.process.BrokenProcessPool("a child process terminated abruptly")
        future = self._cf.Future()
        future.set_result(fn(*args))
        return future

    def shutdown(self, wait=True, cancel_futures=False):
        pass


def test_a_pool_that_breaks_between_submits_loses_no_run(tmp_path, monkeypatch):
    from planbench.campaign import engines

    monkeypatch.setattr(engines.cf, "ProcessPoolExecutor", _PoolThatBreaksOnSubmit)
    _PoolThatBreaksOnSubmit.pools = 0
    spec = _write(
        tmp_path / "spec.toml",
        """
scenario = "hexapod-sync-move"
[grid]
"moves[0].target[0]" = [1.0, 1.1, 1.2, 1.3]
""",
    )
    tables = {}
    for name, pools_before in (("broken", 0), ("whole", 1)):  # the second never breaks
        _PoolThatBreaksOnSubmit.pools = pools_before
        cli.main(["sweep", str(spec), "--out", str(tmp_path / name), "--workers", "1", "--quiet"])
        tables[name] = _comparable(pq.read_table(tmp_path / name / "results.parquet").sort_by("run"))
        assert _PoolThatBreaksOnSubmit.pools == pools_before + (2 if name == "broken" else 1)
    assert tables["broken"].column("run").to_pylist() == [0, 1, 2, 3]
    assert tables["broken"].column("status").to_pylist() == ["passed"] * 4
    assert tables["broken"].equals(tables["whole"])


# ------------------------------------------------------------------------------ bad specs

BAD_SPECS = {
    "unknown parameter": ('scenario = "hexapod-sync-move"\n[grid]\nwindd = [1.0]\n', "unknown parameter 'windd'"),
    "empty axis": ('scenario = "hexapod-sync-move"\n[grid]\nwind = []\n', "grid.wind is empty"),
    "distribution outside the range": (
        'scenario = "hexapod-sync-move"\nsamples = 4\n[random]\n'
        'wind = { distribution = "uniform", low = 10.0, high = 60.0 }\n',
        "outside wind's range [0, 50] m/s",
    ),
    "untruncated normal on a bounded parameter": (
        'scenario = "hexapod-sync-move"\nsamples = 4\n[random]\n'
        'wind = { distribution = "normal", mean = 4.0, std = 1.0 }\n',
        "truncate it",
    ),
    "grid value out of range": ('scenario = "hexapod-sync-move"\n[grid]\nelevation = [20.0, 95.0]\n', "elevation = 95"),
    "unknown key": ('scenario = "hexapod-sync-move"\nsed = 3\n', "unknown key 'sed'"),
    "unknown scenario": ('scenario = "no-such"\n', "no-such"),
    "plant of nothing": ('scenario = "hexapod-sync-move"\n[grid.plant]\nnot_a_field = [1.0]\n', "not_a_field"),
    "seed as an axis": ('scenario = "hexapod-sync-move"\n[grid]\nseed = [1, 2]\n', "seeds = N"),
    "index beyond the list": ('scenario = "hexapod-sync-move"\n[grid]\n"moves[3].target[0]" = [1.0]\n', "moves[3]"),
    "plan mode without planner checks": ('scenario = "antenna-sea-state"\nmode = "plan"\n', "planner-only"),
}


@pytest.mark.parametrize("case", sorted(BAD_SPECS))
def test_bad_spec_exits_2_with_one_line_before_any_run(case, tmp_path, capsys):
    text, expected = BAD_SPECS[case]
    spec = _write(tmp_path / "spec.toml", text)
    out = tmp_path / "out"
    code = cli.main(["sweep", str(spec), "--out", str(out), "--quiet"])
    captured = capsys.readouterr()
    assert code == cli.EXIT_BAD_INPUT, captured.err
    assert len(captured.err.strip().splitlines()) == 1, captured.err
    assert expected in captured.err and "Traceback" not in captured.err
    assert not out.exists()


def test_bad_spec_from_the_shell_has_no_traceback(tmp_path):
    spec = _write(tmp_path / "spec.toml", BAD_SPECS["empty axis"][0])
    result = subprocess.run(
        [*PLANBENCH, "sweep", str(spec), "--out", str(tmp_path / "out")], capture_output=True, text=True, timeout=120
    )
    assert result.returncode == 2 and result.stderr.count("\n") == 1 and "grid.wind is empty" in result.stderr
    assert not (tmp_path / "out").exists()


def test_a_foreign_directory_is_refused(tmp_path):
    spec = _write(tmp_path / "spec.toml", SPEC)
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("keep me")
    with pytest.raises(Exception, match="not a planbench campaign"):
        CampaignDir(out)
    assert cli.main(["sweep", str(spec), "--out", str(out), "--quiet"]) == cli.EXIT_BAD_INPUT
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]


def test_an_invalid_combination_is_refused_or_skipped(tmp_path):
    # Each axis value is valid on the base; together, run 1's target equals its start: a move
    # of zero length, a limit between parameters.
    text = (
        'scenario = "hexapod-sync-move"\n[parameters]\nmoves = [{ target = [3, 0, 0, 0, 0, 0] }]\n'
        'start_pose = [2, 0, 0, 0, 0, 0]\n[grid]\n"start_pose[0]" = [1.0]\n"moves[0].target[0]" = [4.0, 1.0]\n'
    )
    spec = spec_module.load(_write(tmp_path / "refuse.toml", text))
    spec.resolve(spec.runs()[0])
    with pytest.raises(ParamError, match=r"run 1 \(start_pose\[0\] = 1, moves\[0\]\.target\[0\] = 1, .*zero length"):
        spec.resolve(spec.runs()[1])
    result = subprocess.run(
        [*PLANBENCH, "sweep", str(tmp_path / "refuse.toml"), "--out", str(tmp_path / "out"), "--quiet"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 2 and "run 1" in result.stderr and not (tmp_path / "out").exists()
    spec = spec_module.load(_write(tmp_path / "skip.toml", 'invalid = "skip"\n' + text))
    from planbench.campaign import context_of, tasks_of, worker

    result = worker.run_chunk(context_of(spec), tasks_of(spec, spec.runs())[1:])
    assert result["rows"][0]["status"] == "invalid" and "zero length" in result["rows"][0]["error"]


# ------------------------------------------------------------------------------ determinism


@settings(max_examples=30)
@given(
    seed=st.integers(0, 2**63 - 1),
    samples=st.integers(1, 5),
    seeds=st.integers(1, 4),
    winds=st.lists(st.floats(0.0, 50.0), min_size=1, max_size=3, unique=True),
)
def test_the_same_spec_gives_the_same_runs(tmp_path_factory, seed, samples, seeds, winds):
    folder = tmp_path_factory.mktemp("spec")
    text = (
        f'scenario = "hexapod-sync-move"\nseed = {seed}\nseeds = {seeds}\nsamples = {samples}\n'
        f"[grid]\nwind = {[float(w) for w in winds]}\n"
        '[random]\nelevation = { distribution = "uniform", low = 20.0, high = 90.0 }\n'
    )
    a = spec_module.load(_write(folder / "a.toml", text))
    b = spec_module.load(_write(folder / "b.toml", text))
    runs_a, runs_b = a.runs(), b.runs()
    assert runs_a == runs_b and a.fingerprint == b.fingerprint
    assert len(runs_a) == len(winds) * samples * seeds
    for run in runs_a:
        assert run.index == (run.point * samples + run.sample) * seeds + run.replicate
        assert run.values[0] == winds[run.point]
        assert 20.0 <= run.values[1] <= 90.0
    # Common random numbers: a sample's draw and seed are the same at every grid point.
    by_place = {}
    for run in runs_a:
        by_place.setdefault((run.sample, run.replicate), set()).add((run.seed, run.values[1]))
    assert all(len(v) == 1 for v in by_place.values())
    assert len({r.seed for r in runs_a}) == samples * seeds


def test_distributions_draw_what_they_name(tmp_path):
    text = (
        'scenario = "hexapod-sync-move"\nseed = 3\nsamples = 20000\n[random]\n'
        'wind = { distribution = "normal", mean = 5.0, std = 1.0, low = 3.0, high = 9.0 }\n'
        'elevation = { distribution = "log-uniform", low = 20.0, high = 80.0 }\n'
        '"start_pose[0]" = { distribution = "uniform", low = -1.0, high = 1.0 }\n'
    )
    spec = spec_module.load(_write(tmp_path / "s.toml", text))
    wind, elevation, x = spec.draws()
    assert wind.min() >= 3.0 and wind.max() <= 9.0
    from scipy import stats

    assert stats.kstest(wind, stats.truncnorm(-2.0, 4.0, loc=5.0, scale=1.0).cdf).pvalue > 1e-3
    assert stats.kstest(np.log(elevation), stats.uniform(np.log(20), np.log(4)).cdf).pvalue > 1e-3
    assert stats.kstest(x, stats.uniform(-1, 2).cdf).pvalue > 1e-3


def test_rerun_worst_replays_the_worst_run_with_a_video(tmp_path, capsys):
    spec = _write(
        tmp_path / "spec.toml",
        """
scenario = "hexapod-sync-move"
seed = 5
[parameters]
duration = 1.5
[grid]
wind = [0.0, 8.0]
""",
    )
    out = tmp_path / "out"
    code = cli.main(["sweep", str(spec), "--out", str(out), "--workers", "1", "--quiet", "--rerun-worst", "1"])
    assert code in (cli.EXIT_OK, cli.EXIT_CHECK_FAILED)
    table = pq.read_table(out / "results.parquet")
    summary = json.loads((out / "campaign.json").read_text())
    meta = {n: {"comparison": c["comparison"]} for n, c in summary["checks"].items()}
    worst = report.worst_runs(table, 1, meta)
    folder = out / "worst" / f"01-run-{worst[0]:06d}"
    assert (folder / "hexapod-sync-move.mp4").stat().st_size > 10_000
    rerun = json.loads((folder / "summary.json").read_text())
    row = table.to_pylist()[worst[0]]
    for check in rerun["checks"]:  # null in JSON is a check that could not be evaluated: NaN
        value = math.nan if check["value"] is None else check["value"]
        assert np.array_equal(value, row[f"check.{check['name']}"], equal_nan=True), check["name"]
    assert "differs" not in capsys.readouterr().out


def test_worst_runs_rank_by_the_ratio_to_the_limit():
    import pyarrow as pa

    table = pa.table(
        {
            "run": [0, 1, 2, 3],
            "status": ["passed", "failed", "error", "passed"],
            "check.a": [0.5, 1.2, None, 0.9],
            "limit.a": [1.0, 1.0, None, 1.0],
            "check.b": [10.0, 10.0, None, 2.0],
            "limit.b": [5.0, 5.0, None, 5.0],
        }
    )
    meta = {"a": {"comparison": "<="}, "b": {"comparison": ">="}}
    # run 3: b is 2 where it must be >= 5 (ratio 2.5); run 1: a is 1.2 of its limit; run 0: 0.5.
    assert report.worst_runs(table, 4, meta) == [3, 1, 0]


@pytest.mark.parametrize("example", sorted(str(p) for p in Path("examples").glob("*/*_campaign.toml")))
def test_example_campaign_specs_are_valid(example):
    spec = spec_module.load(example)
    assert spec.size >= 1 and spec.axes
    resolved = 0
    for run in itertools.islice(spec.iter_runs(), 50):
        try:
            spec.resolve(run)
            resolved += 1
        except ParamError:
            assert spec.invalid == "skip"  # otherwise every run must be valid
    assert resolved == min(50, spec.size) if spec.invalid == "refuse" else resolved >= 5


def test_a_perturbed_run_repeats_from_its_summary(tmp_path, capsys):
    first, again = tmp_path / "first", tmp_path / "again"
    assert cli.main(
        [
            "run",
            "hexapod-sync-move",
            "--set",
            "plant.camera_mass_error=0.1",
            "--duration",
            "1.0",
            "--out",
            str(first),
            "--quiet",
        ]
    ) in (cli.EXIT_OK, cli.EXIT_CHECK_FAILED)
    summary = json.loads((first / "summary.json").read_text())
    assert summary["plant"]["camera_mass_error"] == 0.1
    cli.main(["run", str(first / "summary.json"), "--out", str(again), "--quiet"])
    a, b = np.load(first / "timeseries.npz"), np.load(again / "timeseries.npz")
    assert sorted(a) == sorted(b) and all(np.array_equal(a[k], b[k]) for k in a)
    # ... and the plant acted: the struts carry 10 % more camera than the nominal run's.
    nominal = tmp_path / "nominal"
    cli.main(["run", "hexapod-sync-move", "--duration", "1.0", "--out", str(nominal), "--quiet"])
    assert not np.array_equal(np.load(nominal / "timeseries.npz")["actuator_force"], a["actuator_force"])
    assert cli.main(["run", "hexapod-sync-move", "--set", "plant.camera_mass_error=0.5", "--quiet"]) == 2
    assert "plant.camera_mass_error = 0.5 fraction is outside [-0.1, 0.1]" in capsys.readouterr().err


def test_saved_outputs_only_when_asked(tmp_path):
    from planbench.campaign import context_of, tasks_of, worker

    text = 'scenario = "loader-supply"\n{save}[parameters]\nduration = 0.2\n[grid]\npayload_mass = [40.0]\n'
    saved = spec_module.load(_write(tmp_path / "saved.toml", text.format(save='save = ["timeseries"]\n')))
    files = worker.run_chunk(context_of(saved), tasks_of(saved, saved.runs()))["files"][0]
    assert set(files) == {"summary.json", "timeseries.npz", "report.png"}
    assert files["report.png"][:8] == b"\x89PNG\r\n\x1a\n"
    plain = spec_module.load(_write(tmp_path / "plain.toml", text.format(save="")))
    assert set(worker.run_chunk(context_of(plain), tasks_of(plain, plain.runs()))["files"][0]) == {"summary.json"}


def test_a_planner_only_campaign_judges_the_plans_without_physics(tmp_path):
    spec = _write(
        tmp_path / "spec.toml",
        """
scenario = "hexapod-sync-move"
mode = "plan"
seed = 4
samples = 60
invalid = "skip"
[grid]
"moves[0].synchronous" = [true, false]
[random]
"moves[0].target[0]" = { distribution = "uniform", low = -5.0, high = 5.0 }
"moves[0].target[5]" = { distribution = "uniform", low = -0.05, high = 0.05 }
""",
    )
    out = tmp_path / "out"
    assert cli.main(["sweep", str(spec), "--out", str(out), "--workers", "1", "--quiet"]) == cli.EXIT_OK
    table = pq.read_table(out / "results.parquet")
    assert table.num_rows == 120 and set(table.column("status").to_pylist()) == {"passed"}
    assert not (out / "runs").exists() or not any((out / "runs").iterdir())  # no physics, no run outputs
    # Each row is the judge's verdict on that run's own plan.
    from planbench.hexapod.plan_checks import judge_plans

    loaded = spec_module.load(spec)
    run = loaded.runs()[70]
    [checks] = judge_plans([loaded.resolve(run)[0]])
    row = table.to_pylist()[70]
    assert row["moves[0].synchronous"] is False
    for c in checks:
        assert np.array_equal(c.value, row[f"check.{c.name}"], equal_nan=True), c.name


def _random_target_spec(tmp_path, samples: int) -> Path:
    """A planner-only hexapod campaign of ``samples`` moves, each to a random x target."""
    return _write(
        tmp_path / "spec.toml",
        f"""
scenario = "hexapod-sync-move"
mode = "plan"
samples = {samples}
invalid = "skip"
[random]
"moves[0].target[0]" = {{ distribution = "uniform", low = -5.0, high = 5.0 }}
""",
    )


def test_a_pool_held_across_campaigns_serves_each_and_ends_with_its_block(tmp_path):
    from planbench import campaign
    from planbench.campaign.engines import LocalEngine

    spec = _random_target_spec(tmp_path, samples=40)
    from planbench.campaign import context_of, worker

    loaded = spec_module.load(spec)  # the rows computed here, in one chunk, for reference
    own = worker.run_columns(context_of(loaded), worker.ColumnTask(loaded.columns(np.arange(loaded.size))))["table"]
    with LocalEngine(2) as engine:
        with pytest.raises(ParamError, match="the engine's own"):
            campaign.sweep(spec, tmp_path / "refused", engine=engine, workers=2, quiet=True)
        started = dict(engine._pool._processes)
        held = [campaign.sweep(spec, tmp_path / f"held-{i}", engine=engine, quiet=True).table for i in range(2)]
        assert engine._pool is not None and dict(engine._pool._processes) == started  # the same workers, still up
    # Gone: no process with a worker's pid, or only its zombie until the executor's thread reaps
    # it (Process.is_alive cannot say: after another thread's waitpid its poll finds no child
    # and reads "running").
    assert engine._pool is None and not [pid for pid in started if _running(pid)]
    for table in held:
        assert _comparable(table).equals(_comparable(own))


def _running(pid: int) -> bool:
    """A process with ``pid`` exists and is not a zombie."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except (FileNotFoundError, ProcessLookupError):
        return False


def test_a_pool_closed_before_its_runs_leaves_no_thread_behind():
    """A campaign refused after its pool started (a plug-in that fails its check) ends the
    pool at once: its workers and its manager thread are gone when ``close`` returns, so
    concurrent.futures' exit hook has nothing to wake (a still-running manager thread can
    close the wake-up pipe under it and print a traceback after the one-line error)."""
    import concurrent.futures.process as cfp

    from planbench.campaign.engines import LocalEngine

    engine = LocalEngine(2)
    engine.start()
    started = dict(engine._pool._processes)
    managers = [t for t in cfp._threads_wakeups if t.is_alive()]
    assert managers, "a started pool runs its manager thread"
    engine.close()
    assert not [t for t in managers if t.is_alive()]
    assert not [pid for pid in started if _running(pid)]


@settings(max_examples=25, deadline=None)
@given(
    st.lists(st.integers(0, 10**7), min_size=1, max_size=30, unique=True).flatmap(
        lambda runs: st.tuples(st.permutations(runs), st.lists(st.integers(1, len(runs)), min_size=1, max_size=6))
    )
)
def test_the_results_table_is_in_run_order_whatever_its_parts_hold(tmp_path_factory, drawn):
    """Part files written in run order (a campaign without a break) are joined as they are;
    parts whose runs overlap or interleave (a resumed campaign's) are sorted."""
    import pyarrow as pa

    runs, cuts = drawn
    out = CampaignDir(tmp_path_factory.mktemp("parts") / "campaign")
    out.table_dir.mkdir(parents=True)
    bounds = sorted({0, len(runs), *(c % len(runs) for c in cuts)})
    for lo, hi in itertools.pairwise(bounds):  # each part's rows in run order, as a chunk writes them
        part = sorted(runs[lo:hi])
        out.append(pa.table({"run": pa.array(part, pa.int64()), "value": pa.array([2.0 * r for r in part])}), {})
    table = out.table()
    assert table.column("run").to_pylist() == sorted(runs)
    assert table.column("value").to_pylist() == [2.0 * r for r in sorted(runs)]


def test_a_write_that_fails_midway_leaves_neither_the_file_nor_a_half_written_one(tmp_path):
    from planbench.campaign.store import write_atomic

    (tmp_path / "results.parquet").write_bytes(b"the old table")

    def half(f):
        f.write(b"half of a table")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_atomic(tmp_path / "results.parquet", half)
    assert [p.name for p in tmp_path.iterdir()] == ["results.parquet"]
    assert (tmp_path / "results.parquet").read_bytes() == b"the old table"
    write_atomic(tmp_path / "results.parquet", lambda f: f.write(b"the new table"))
    assert [p.name for p in tmp_path.iterdir()] == ["results.parquet"]
    assert (tmp_path / "results.parquet").read_bytes() == b"the new table"


def test_a_failed_results_write_fails_the_campaign_after_its_report(tmp_path, monkeypatch):
    """results.parquet is written beside the report (another thread): an error there is the
    campaign's error, raised once both are done, never lost in the thread."""
    from planbench import campaign

    spec = _random_target_spec(tmp_path, samples=20)

    def disk_full(self, table):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(CampaignDir, "write_results", disk_full)
    with pytest.raises(OSError, match="No space left"):
        campaign.sweep(spec, tmp_path / "out", workers=1, quiet=True)
    assert (tmp_path / "out" / "campaign.json").is_file()  # the report, whole
    assert not (tmp_path / "out" / "results.parquet").exists()
    monkeypatch.undo()
    outcome = campaign.sweep(spec, tmp_path / "out", workers=1, quiet=True)  # resumed: every row done
    assert outcome.ran == 0 and pq.read_table(tmp_path / "out" / "results.parquet").num_rows == 20
