"""Plug-ins are untrusted code: every way a planner or controller can misbehave (raise,
``sys.exit``, ``os._exit``, hang) at every place it runs (import, factory, ``plan``,
``sample``, ``reset``, ``__call__``) is a fault with a clear verdict, never a pass, and leaves
no lock or staging directory behind. Through the real command line, as a user meets it."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pyarrow.parquet as pq
import pytest

PLUGIN = textwrap.dedent("""
    import os, sys, time

    MODE = os.environ["PB_MODE"]
    WHERE = os.environ["PB_WHERE"]

    def act():
        if MODE == "raise":
            raise RuntimeError("boom")
        if MODE == "exit0":
            sys.exit(0)
        if MODE == "exit3":
            sys.exit(3)
        if MODE == "os_exit0":
            os._exit(0)
        if MODE == "sleep":
            time.sleep(3600)

    if WHERE == "import":
        act()

    from planbench.planners.loader import CubicBSplinePlanner
    from planbench.loader import reference_controller

    class Controller:
        def reset(self, context):
            if WHERE == "reset":
                act()
            self.inner = reference_controller()
            return self.inner.reset(context)

        def __call__(self, tick, observation):
            if WHERE == "call" and tick == 5:
                act()
            return self.inner(tick, observation)

    class Sampled:
        def __init__(self, trajectory):
            self.inner, self.duration, self.labels = trajectory, trajectory.duration, trajectory.labels

        def sample(self, t):
            act()
            return self.inner.sample(t)

    class Planner:
        def plan(self, problem):
            if WHERE == "plan":
                act()
            trajectory = CubicBSplinePlanner().plan(problem)
            return Sampled(trajectory) if WHERE == "sample" else trajectory

    def controller():
        if WHERE == "factory":
            act()
        return Controller()

    def planner():
        if WHERE == "factory":
            act()
        return Planner()
""")

MODES = ("raise", "exit0", "exit3", "os_exit0", "sleep")
#: (where, role): where the fault is, and which plug-in carries it.
PLACES = (
    ("import", "controller"),
    ("factory", "controller"),
    ("reset", "controller"),
    ("call", "controller"),
    ("factory", "planner"),
    ("plan", "planner"),
    ("sample", "planner"),
)
#: The wall-time limit of a hanging plug-in's run (s): the limit is what ends it.
TIMEOUT_S = 4
#: The limit of the other faults' runs (s), never reached: a run slowed by a busy machine is
#: judged by its fault alone, not also by a wall_time check.
LIMIT_NOT_REACHED_S = 600


def expected_exit(where: str, mode: str) -> int:
    """Before the first physics step a fault is a broken contract (2); during the run it ends
    the run as a failed check (1). A hang is a failed wall_time check (1) wherever it is."""
    if mode == "sleep" or where == "call":
        return 1
    return 2


def planbench(*args, env=None, cwd=None, timeout=120):
    return subprocess.run(
        [sys.executable, "-m", "planbench.cli", *map(str, args)],
        capture_output=True,
        text=True,
        env={**os.environ, **(env or {})},
        cwd=cwd,
        timeout=timeout,
    )


def leftovers(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.iterdir() if p.name.startswith((".planbench-tmp", ".planbench-lock")))


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("where, role", PLACES)
def test_every_plugin_fault_has_a_verdict_and_leaves_nothing_behind(tmp_path, where, role, mode):
    (tmp_path / "faulty.py").write_text(PLUGIN)
    out = tmp_path / "out"
    proc = planbench(
        "run",
        "loader-supply",
        f"--{role}",
        f"faulty.py:{role}",
        "--out",
        out,
        "--quiet",
        "--duration",
        "0.2",
        "--timeout",
        TIMEOUT_S if mode == "sleep" else LIMIT_NOT_REACHED_S,
        env={"PB_MODE": mode, "PB_WHERE": where},
        cwd=tmp_path,
    )
    assert proc.returncode == expected_exit(where, mode), (proc.returncode, proc.stdout, proc.stderr)
    assert "Traceback" not in proc.stderr, proc.stderr
    lines = proc.stderr.splitlines()
    if proc.returncode == 2:
        assert len(lines) == 1 and lines[0].startswith("planbench: error: "), lines
        assert not out.exists(), "a refused plug-in writes nothing"
    else:
        summary = json.loads((out / "summary.json").read_text())
        assert summary["passed"] is False
        failed = [c for c in summary["checks"] if not c["passed"]]
        if mode == "sleep":
            assert [c["name"] for c in failed] == ["wall_time"], failed
            assert f"--{role} faulty.py:{role}" in failed[0]["note"], failed[0]["note"]
        elif mode == "os_exit0":
            assert [c["name"] for c in failed] == ["run_completed"], failed
        else:
            assert [c["name"] for c in failed] == ["controller_errors"], failed
            assert ("SystemExit" if mode.startswith("exit") else "RuntimeError") in failed[0]["note"]
        assert "PASSED" not in proc.stdout
    assert leftovers(tmp_path) == [], "no lock or staging directory is left"


def test_a_run_without_faults_still_passes_under_supervision(tmp_path):
    """The supervision itself is no fault: the same plug-in, doing nothing wrong, passes."""
    (tmp_path / "faulty.py").write_text(PLUGIN)
    proc = planbench(
        "run",
        "loader-supply",
        "--controller",
        "faulty.py:controller",
        "--planner",
        "faulty.py:planner",
        "--out",
        tmp_path / "out",
        "--quiet",
        env={"PB_MODE": "none", "PB_WHERE": "nowhere"},
        cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    assert "PASSED" in proc.stdout


@pytest.mark.parametrize("value", ["0", "-1", "nan", "inf", "soon", ""])
def test_a_bad_timeout_is_one_line(tmp_path, value):
    proc = planbench("run", "loader-supply", f"--timeout={value}", "--out", tmp_path / "out")
    assert proc.returncode == 2 and len(proc.stderr.splitlines()) == 1, proc.stderr
    assert not (tmp_path / "out").exists()


def _spec(tmp_path: Path, body: str) -> Path:
    (tmp_path / "faulty.py").write_text(PLUGIN)
    path = tmp_path / "spec.toml"
    path.write_text(body)
    return path


def test_a_campaign_records_a_hung_run_as_an_error_row_and_goes_on(tmp_path):
    spec = _spec(
        tmp_path,
        'scenario = "loader-supply"\ncontroller = "faulty.py:controller"\nseeds = 2\n'
        f"timeout = {TIMEOUT_S}\n[parameters]\nduration = 0.2\n",
    )
    out = tmp_path / "campaign"
    proc = planbench(
        "sweep",
        spec,
        "--out",
        out,
        "--quiet",
        "--workers",
        "1",
        env={"PB_MODE": "sleep", "PB_WHERE": "call"},
        cwd=tmp_path,
    )
    assert proc.returncode == 1, proc.stderr
    rows = pq.read_table(out / "results.parquet").to_pylist()
    assert [r["status"] for r in rows] == ["error", "error"]
    assert all("timed out" in r["error"] and "control loop" in r["error"] for r in rows), rows


@pytest.mark.parametrize("mode", ["raise", "exit0", "os_exit0", "sleep"])
def test_a_campaign_checks_its_plugins_before_the_first_run(tmp_path, mode):
    spec = _spec(
        tmp_path, f'scenario = "loader-supply"\ncontroller = "faulty.py:controller"\nseeds = 2\ntimeout = {TIMEOUT_S}\n'
    )
    out = tmp_path / "campaign"
    proc = planbench("sweep", spec, "--out", out, "--quiet", env={"PB_MODE": mode, "PB_WHERE": "import"}, cwd=tmp_path)
    assert proc.returncode == 2, (proc.stdout, proc.stderr)
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("planbench: error: ") and "Traceback" not in proc.stderr, lines
    assert not out.exists(), "nothing is written"


def test_a_campaign_with_a_missing_plugin_is_refused_before_any_run(tmp_path):
    spec = _spec(tmp_path, 'scenario = "loader-supply"\ncontroller = "nothere.py:controller"\nseeds = 2\n')
    proc = planbench("sweep", spec, "--out", tmp_path / "campaign", "--quiet", cwd=tmp_path)
    assert proc.returncode == 2 and len(proc.stderr.splitlines()) == 1, proc.stderr
    assert "no such file" in proc.stderr
    assert not (tmp_path / "campaign").exists()


@pytest.mark.parametrize("value", ["0", "-3", '"soon"', "true", "inf"])
def test_a_bad_campaign_timeout_is_one_line(tmp_path, value):
    spec = _spec(tmp_path, f'scenario = "loader-supply"\ntimeout = {value}\n')
    proc = planbench("sweep", spec, "--out", tmp_path / "campaign", "--quiet", cwd=tmp_path)
    assert proc.returncode == 2 and len(proc.stderr.splitlines()) == 1, proc.stderr
    assert "timeout" in proc.stderr
