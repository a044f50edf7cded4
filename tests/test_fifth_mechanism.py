"""A mechanism is its own folders and nothing else.

tests/mechanisms/pendulum/ holds a one-joint pendulum as a user would add a fifth mechanism,
three folders under one root: tests/mechanisms/pendulum/models/pendulum/ (MJCF and README),
tests/mechanisms/pendulum/planners/pendulum/ (a quintic planner) and
tests/mechanisms/pendulum/sims/pendulum/ (physics, task, evaluation, scenario, reward, its
MECHANISM record). Named by
PLANBENCH_MECHANISMS, it is found by its folders alone: ``planbench list``, ``run``, ``plan``,
``sweep`` and the dm_control environment reach it, in fresh processes (the registry is read
once per process). Nothing of it is named anywhere else in the project.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from planbench import models

ROOT = Path(__file__).resolve().parents[1]
PENDULUM = ROOT / "tests" / "mechanisms" / "pendulum"
#: m g L of the pendulum's bob (tests/mechanisms/pendulum/models/pendulum/README.md), N m.
GRAVITY_TORQUE = 2.0 * 9.81 * 0.5


def planbench(*args, cwd, check=True, **env):
    """``python -m planbench.cli ARGS`` with the pendulum's root in PLANBENCH_MECHANISMS."""
    environ = {**os.environ, models.ROOTS_VARIABLE: str(PENDULUM), "PYTHONPATH": str(ROOT), **env}
    done = subprocess.run(
        [sys.executable, "-m", "planbench.cli", *args],
        cwd=cwd,
        env=environ,
        capture_output=True,
        text=True,
        timeout=600,
    )
    if check:
        assert done.returncode == 0, done.stderr
    return done


def python(code: str, cwd):
    environ = {**os.environ, models.ROOTS_VARIABLE: str(PENDULUM), "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=cwd, env=environ, capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_it_is_listed_and_runs_to_a_pass_that_holds_by_hand(tmp_path):
    assert "pendulum-swing" in planbench("list", cwd=tmp_path).stdout
    assert (
        "pendulum"
        not in subprocess.run(
            [sys.executable, "-m", "planbench.cli", "list"],
            cwd=tmp_path,
            env={**os.environ, "PYTHONPATH": str(ROOT)},
            capture_output=True,
            text=True,
            check=True,
        ).stdout
    )
    planbench("run", "pendulum-swing", "--goal", "1.2", "--out", "run", "--quiet", cwd=tmp_path)
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["passed"] is True
    ts = np.load(tmp_path / "run" / "timeseries.npz")
    # At rest at the goal the drive holds the bob's weight: m g L sin(q).
    assert ts["q_actual"][-1] == pytest.approx(1.2, abs=5e-4)
    assert ts["drive_torque"][-1] == pytest.approx(GRAVITY_TORQUE * np.sin(1.2), rel=1e-3)


def test_its_bad_parameter_is_named_before_any_work(tmp_path):
    done = planbench("run", "pendulum-swing", "--goal", "4", "--out", "run", cwd=tmp_path, check=False)
    assert done.returncode == 2 and "goal = 4" in done.stderr and "Traceback" not in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and not (tmp_path / "run").exists()


def test_it_plans_without_physics(tmp_path):
    planbench("plan", "pendulum-swing", "--move-time", "2", "--out", "plan", cwd=tmp_path)
    assert {"plan.npz", "plan.png"} <= {p.name for p in (tmp_path / "plan").iterdir()}
    arrays = np.load(tmp_path / "plan" / "plan.npz")
    assert arrays["t"][-1] == pytest.approx(2.0) and list(arrays["labels"]) == ["swing"]
    assert arrays["position"][0, 0] == 0.0 and arrays["position"][-1, 0] == pytest.approx(1.2, abs=1e-12)
    assert np.abs(arrays["velocity"][[0, -1], 0]).max() < 1e-12  # rest to rest


def test_a_sweep_over_its_parameters(tmp_path):
    (tmp_path / "spec.toml").write_text('scenario = "pendulum-swing"\nseed = 1\n\n[grid]\ngoal = [-1.0, 0.5, 2.0]\n')
    done = planbench("sweep", "spec.toml", "--out", "sweep", "--workers", "1", "--quiet", cwd=tmp_path)
    assert "3 of 3 runs passed" in done.stdout


def test_the_dm_control_environment_holds_the_start_and_rewards_tracking(tmp_path):
    out = python(
        "import numpy as np\n"
        "from dm_env import test_utils\n"
        "from planbench.envs import make\n"
        "env = make('pendulum-swing')\n"
        "step = env.reset()\n"
        "assert set(step.observation) >= {'joint_positions', 'setpoints', 'reference_positions'}\n"
        "rewards = []\n"
        "while not step.last():\n"
        "    step = env.step(np.zeros(1))\n"
        "    rewards.append(step.reward)\n"
        "print(len(rewards), rewards[0], min(rewards))\n",
        cwd=tmp_path,
    )
    n, first, lowest = out.split()
    assert int(n) == 360  # (1.0 s + 0.8 s) / 5 ms
    # Holding the start, the reward is 1 while the plan has barely moved, and falls far
    # below it as the plan swings away to 1.2 rad (exp(-1.2 / 0.01)).
    assert float(first) > 0.99 and float(lowest) < 1e-6


def test_nothing_outside_its_folders_names_it():
    listed = subprocess.run(
        ["git", "ls-files", "--cached", "--others", "--exclude-standard"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    outside = [
        f
        for f in listed
        if not f.startswith("tests/mechanisms/pendulum/")
        and f != "tests/test_fifth_mechanism.py"
        and (ROOT / f).is_file()
        and "pendulum" in (ROOT / f).read_text(errors="replace").lower()
    ]
    assert outside == []


def test_a_name_it_shares_with_a_built_in_scenario_is_refused(tmp_path):
    """A mechanism of one's own that declares loader-supply: the command line does not take the
    loader's by its name's prefix alone; the registry refuses the name as taken."""
    root = tmp_path / "mine"
    shutil.copytree(PENDULUM, root, ignore=shutil.ignore_patterns("__pycache__"))
    package = root / "sims" / "pendulum" / "__init__.py"
    package.write_text(package.read_text().replace('"pendulum-swing",', '"loader-supply",'))
    done = planbench(
        "run", "loader-supply", "--out", "out", cwd=tmp_path, check=False, **{models.ROOTS_VARIABLE: str(root)}
    )
    assert done.returncode == 2, done.stdout + done.stderr
    assert "scenario name 'loader-supply' of sims.pendulum is taken" in done.stderr
    assert not (tmp_path / "out").exists()
