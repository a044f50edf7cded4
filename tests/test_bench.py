"""planbench bench's measurements that are not timings: a run's peak memory in a process of its
own, and a planner-only campaign's counts (never a timed assertion)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from planbench import bench, runner, scenarios


def test_peak_memory_is_the_childs_own_not_its_parents(tmp_path, monkeypatch):
    """The child's high-water mark is of its own address space: a parent holding 800 MB more
    does not raise it (a forked child's ru_maxrss would count those pages). Its run writes
    nothing where the bench is run (not the default results/NAME, which may be a user's)."""
    monkeypatch.chdir(tmp_path)
    small = bench.peak_memory("loader-supply", 0.05)
    ballast = np.ones((100, 1000, 1000))  # 800 MB resident in this process
    assert ballast.sum() > 0
    beside = bench.peak_memory("loader-supply", 0.05)
    assert 50.0 < small < 700.0 and 50.0 < beside < 700.0  # MB: Python, MuJoCo and the loader
    assert abs(beside - small) < 100.0
    assert list(tmp_path.iterdir()) == []


def test_the_planner_only_campaign_counts_its_runs():
    row = bench.planner_only_throughput(workers=1, samples=100)
    assert row["runs"] == 200 and 0 < row["valid"] <= row["runs"]
    assert row["runs_per_s"] > 0 and row["valid_per_s"] <= row["runs_per_s"]
    assert "200 random hexapod moves" in bench.format_planner_only(row)


def test_the_memory_table_names_its_runs_and_the_6_h_log():
    rows = [
        {"duration_s": 300.0, "peak_mb": 240.0},
        {"duration_s": 1330.0, "peak_mb": 300.0},
        {"duration_s": bench.SIX_HOURS_S, "peak_mb": None, "log_mb": 2911.0},
    ]
    text = bench.format_memory(rows)
    assert "1330 s over 300 s: 1.25 x" in text and "2911" in text and "not run" in text
    assert "--six-hours" in text


def test_the_campaign_table_compares_engines_in_the_same_state():
    # Made-up rows: each row's ratios are against the local pools in its own state (a pool
    # started with the campaign, or held from an earlier one), never across states.
    def row(engine, workers, state, runs_per_s):
        return {
            "engine": engine,
            "workers": workers,
            "state": state,
            "campaigns": 2,
            "runs": 8,
            "wall_s": 8 / runs_per_s,
            "runs_per_s": runs_per_s,
            "campaign_s": 9.0,
            "same_table": True,
        }

    rows = [
        row("local", 1, "started", 0.5),
        row("local", 2, "started", 0.8),
        row("local", 1, "held", 0.6),
        row("local", 2, "held", 1.2),
        row("ray", 2, "started", 0.4),
        row("ray", 2, "held", 1.0),
    ]
    lines = bench.format_campaign(rows).splitlines()
    ratios = {line[:44].strip(): line.split()[-3:-1] for line in lines[1:7]}
    assert ratios["local x2, pool started with it (best of 2)"] == ["1.60", "1.00"]
    assert ratios["local x2, pool held (best of 2)"] == ["2.00", "1.00"]
    assert ratios["ray x2, first on its cluster (best of 2)"] == ["0.80", "0.50"]
    assert ratios["ray x2, cluster up (best of 2)"] == ["1.67", "0.83"]
    assert lines[-1].endswith("tables equal run for run: yes")


def _short(name: str, **params):
    scenario = scenarios.get(name)
    return scenario.build(scenario.resolve(duration=0.405, **params))  # 81 ticks of 5 ms


@pytest.mark.parametrize("chunk", [7, 4096])
@pytest.mark.parametrize(
    ("name", "params", "exact"),
    [
        ("loader-supply", {}, True),
        ("hexapod-sync-move", {"wind": 0.0}, True),
        ("hexapod-sync-move", {"wind": 6.0}, False),  # the wind is an external force, not replayed
    ],
)
def test_a_replay_steps_the_runs_own_motion(name, params, exact, chunk):
    """Replaying a run's logged states and commands ends each tick in the next logged state,
    bit for bit, where the plant writes nothing but the command (compared at each chunk's end
    and at the run's); the hexapod's wind, a force the replay does not apply, moves it off."""
    log = runner.simulate(_short(name, **params), chunk_ticks=chunk)
    rate, deviation = bench.replay_steps_per_second(_short(name, **params), log)
    assert rate > 0.0
    assert (deviation == 0.0) if exact else (1e-7 < deviation < 1e-2)


def test_a_replay_refuses_a_log_without_a_tick():
    log = SimpleNamespace(n=1, physics_steps=0)
    with pytest.raises(ValueError, match="this log has 1 rows, 0 steps"):
        bench.replay_steps_per_second(_short("loader-supply"), log)


def test_the_table_splits_loop_over_bare_into_replay_ratios():
    row = {
        "scenario": "loader-direct",
        "sim_time_s": 3.0,
        "wall_time_s": 0.2,
        "realtime_factor": 15.0,
        "physics_steps": 6000,
        "loop_steps_per_s": 90_000.0,
        "bare_steps_per_s": 150_000.0,
        "loop_ratio": 0.6,
        "replay_steps_per_s": 100_000.0,
        "replay_deviation": 0.0,
        "physics_share": 0.9,
        "code_under_test_share": 0.02,
    }
    text = bench.format_table([row])
    line = next(line for line in text.splitlines() if line.startswith("loader-direct") and "100000" in line)
    assert line.split()[-3:] == ["0.67", "0.90", "0.0e+00"]  # replay/bare, loop/replay, off the log
