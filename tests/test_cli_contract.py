"""The rest of the CLI contract: every bad input below is exit 2, exactly one line on stderr,
no traceback and nothing written (table-driven, as tests/test_bad_invocations.py); demo's
--out follows run's rules; an interrupted sweep prints one line; a sweep's workers end with
their driver."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import pytest

from planbench.cli import main
from tests.test_bad_invocations import scene  # noqa: F401  (the fixture)
from tests.test_outputs import snapshot

ROOT = Path(__file__).resolve().parents[1]
PLAN_SPEC = (
    'scenario = "loader-supply"\nmode = "plan"\nseed = 1\nsamples = 3\n[random]\n'
    '"key_points[1][0]" = { distribution = "uniform", low = 30, high = 70 }\n'
)


def _summary(**changes) -> str:
    from planbench import scenarios

    data = {
        "scenario": "loader-supply",
        "seed": 0,
        "parameters": scenarios.get("loader-supply").params.to_dict(),
        "plugins": {},
    }
    data.update(changes)
    return json.dumps(data)


# (argv, {file name: contents} laid out first, substrings of the one stderr line)
CASES = [
    (["demo", "--out", "/"], {}, ["root"]),
    (["demo", "--out", "."], {}, ["current directory"]),
    (["demo", "--out", ".."], {}, ["holds the current directory"]),
    (["demo", "--out", "~"], {}, ["home directory"]),
    (["demo", "--out", "{tmp}/mydata"], {}, ["mydata", "thesis.tex", "did not write"]),
    (["demo", "--out", "{tmp}/link"], {}, ["symbolic link"]),
    (
        ["run", "deep.toml", "--out", "{tmp}/r"],
        {"deep.toml": 'scenario = "loader-supply"\n[parameters]\nx = ' + "[" * 5000 + "]" * 5000 + "\n"},
        ["deep.toml", "nested too deep"],
    ),
    (
        ["run", "deep.json", "--out", "{tmp}/r"],
        {"deep.json": '{"parameters": ' + "[" * 100000 + "]" * 100000 + "}"},
        ["deep.json", "nested too deep"],
    ),
    (
        ["sweep", "deep_spec.toml", "--out", "{tmp}/c"],
        {"deep_spec.toml": "x = " + "[" * 5000 + "]" * 5000 + "\n"},
        ["deep_spec.toml", "nested too deep"],
    ),
    (["run", "list_plugins.json", "--out", "{tmp}/r"], {"list_plugins.json": "LIST_PLUGINS"}, ['"plugins"', "table"]),
    (["run", "seed.json", "--out", "{tmp}/r"], {"seed.json": "SEED"}, ['"seed" = 7', "parameters.seed = 0"]),
    (["sweep", "s.toml", "--out", "{tmp}/" + "n" * 256], {"s.toml": PLAN_SPEC}, ["256 bytes", "255"]),
    (["sweep", "s.toml", "--out", ""], {"s.toml": PLAN_SPEC}, ["''", "empty"]),
    (
        ["sweep", "both.toml", "--out", "{tmp}/c"],
        {"both.toml": PLAN_SPEC + '[grid]\n"key_points[1][0]" = [40, 50]\n'},
        ["in both [grid] and [random]"],
    ),
    (
        ["sweep", "overlap.toml", "--out", "{tmp}/c"],
        {"overlap.toml": PLAN_SPEC.replace("[random]", "[grid]\nkey_points = [[[0, 0, 0, 0, 0, 0]]]\n[random]")},
        ["'key_points'", "same value"],
    ),
    (
        ["sweep", "s.toml", "--out", "{tmp}/c", "--engine", "ray", "--address", "127.0.0.1:1"],
        {"s.toml": PLAN_SPEC},
        ["127.0.0.1:1", "nothing listens"],
    ),
    (["run", "loader-supply", "--out", "{tmp}/r", "--duration="], {}, ["--duration is empty"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--set", "duration="], {}, ["--set duration is empty"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--set", "seed=  "], {}, ["--set seed is empty"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--set", "duration=5\nseed=3"], {}, ["line break", "'seed'"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--duration", "5\nseed=3"], {}, ["--duration", "line break"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--set", "duration=" + "[" * 5000], {}, ["nested too deep"]),
    # TOML has no none: a file that writes the flags' "none" is told to leave the key out.
    (
        ["run", "radec.toml", "--out", "{tmp}/r"],
        {"radec.toml": 'scenario = "fast-tracking"\n[parameters]\nsource = "none"\nsource_radec = [202.78, 30.51]\n'},
        ["source = 'none'", "omit it from the file", "give source_radec"],
    ),
    (
        ["run", "both.toml", "--out", "{tmp}/r"],
        {"both.toml": 'scenario = "fast-tracking"\n[parameters]\nsource = "3C 286"\nsource_radec = [202.78, 30.51]\n'},
        ["both given", "leave source out"],
    ),
]


@pytest.mark.parametrize("argv, files, expected", CASES, ids=[" ".join(a)[:50] for a, _, _ in CASES])
def test_bad_input_is_one_line(argv, files, expected, scene, capsys):  # noqa: F811
    tmp = str(scene)
    for name, text in files.items():
        text = {"LIST_PLUGINS": _summary(plugins=["a:b"]), "SEED": _summary(seed=7)}.get(text, text)
        (scene / name).write_text(text)
    argv = [a.replace("{tmp}", tmp) for a in argv]
    before = snapshot(scene)
    code = main(argv)
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert code == 2, (code, captured.err)
    assert len(lines) == 1 and lines[0].startswith("planbench: error: "), lines
    for text in expected:
        assert text in lines[0], (text, lines[0])
    assert snapshot(scene) == before


def test_a_multi_line_toml_value_is_still_one_value():
    from planbench import scenarios
    from planbench.hexapod import HexapodParams  # noqa: F401
    from planbench.params import field_types, parse_value

    cls = type(scenarios.get("hexapod-sync-move").params)
    moves = parse_value(field_types(cls)["moves"], "[\n{target=[0,0,0.01,0,0,0]}\n]", "--set moves")
    assert moves == [{"target": [0, 0, 0.01, 0, 0, 0]}]


def _fake_demo(monkeypatch):
    """cmd_demo with every scenario's build and run replaced: only its outputs' rules act."""
    from planbench import outputs, runner, scenarios

    calls = []
    for name, s in list(scenarios.SCENARIOS.items()):
        monkeypatch.setitem(scenarios.SCENARIOS, name, replace(s, build=lambda params: None))

    class Result:
        checks, passed, sim_time_s, wall_time_s = [], True, 0.0, 0.0

    def run(name, setup, quiet, profile=False, log_path=None):
        calls.append(name)
        result = Result()
        result.passed = scenarios.SCENARIOS[name].expect_pass
        return result

    def write_run(result, setup, out, staging=None, **kw):
        if staging is not None:  # the pipeline's, which it swaps in
            (staging / "summary.json").write_text("{}")
            return
        with out.staging({"scenario": "x"}) as tmp:
            (tmp / "summary.json").write_text("{}")

    monkeypatch.setattr(runner, "run", run)
    monkeypatch.setattr(outputs, "write_run", write_run)
    monkeypatch.setattr("planbench.pipeline.check_log_space", lambda *args: None)
    monkeypatch.setattr("planbench.cli.format_checks", lambda rows: "")
    return calls


def test_demo_twice_into_results_and_beside_other_outputs(tmp_path, monkeypatch, capsys):
    """make demo twice: results/ of an earlier demo, a run's and a campaign's directories in it."""
    from planbench import scenarios

    monkeypatch.chdir(tmp_path)
    calls = _fake_demo(monkeypatch)
    assert main(["demo", "--out", "results", "--quiet"]) == 0
    (tmp_path / "results" / "my-campaign").mkdir()
    (tmp_path / "results" / "my-campaign" / "planbench-campaign.json").write_text("{}")
    assert main(["demo", "--out", "results", "--quiet"]) == 0
    assert len(calls) == 2 * len(scenarios.SCENARIOS)
    (tmp_path / "results" / "notes.txt").write_text("mine")
    before = snapshot(tmp_path)
    assert main(["demo", "--out", "results", "--quiet"]) == 2
    assert "notes.txt" in capsys.readouterr().err and snapshot(tmp_path) == before
    assert len(calls) == 2 * len(scenarios.SCENARIOS)  # refused before any scenario ran


SIM_SPEC = 'scenario = "loader-supply"\nseeds = 8\n'


def _sweep(tmp_path, **kw):
    (tmp_path / "sim.toml").write_text(SIM_SPEC)
    return subprocess.Popen(
        [sys.executable, "-m", "planbench.cli", "sweep", "sim.toml", "--out", "c", "--quiet", "--workers", "2"],
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        **kw,
    )


def _workers_of(pid: int) -> list[int]:
    out = subprocess.run(["ps", "-o", "pid=", "--ppid", str(pid)], capture_output=True, text=True).stdout
    return [int(p) for p in out.split()]


def _wait_for_workers(proc, n=2, limit=120):
    for _ in range(limit * 10):
        if len(_workers_of(proc.pid)) >= n + 1:  # the workers and the resource tracker
            return
        time.sleep(0.1)
    pytest.fail("the sweep started no workers")


@pytest.mark.parametrize("signum, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_interrupted_sweep_prints_one_line(tmp_path, signum, code):
    """The signal to the whole process group (Ctrl-C at a terminal): one line, no tracker's."""
    proc = _sweep(tmp_path, start_new_session=True)
    _wait_for_workers(proc)
    time.sleep(1.0)  # into the workers' first runs (tqdm's lock made: it leaked before)
    os.killpg(proc.pid, signum)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == code, err
    assert err.splitlines() == [
        f"planbench: interrupted by {signal.Signals(signum).name}; nothing half-written was left"
    ], err


def test_workers_end_with_a_killed_driver(tmp_path):
    proc = _sweep(tmp_path)
    _wait_for_workers(proc)
    children = _workers_of(proc.pid)
    proc.kill()  # the driver alone
    proc.wait()
    proc.communicate()  # returns at EOF: no process of the sweep holds the pipes any more
    deadline = time.monotonic() + 60
    while any(Path(f"/proc/{p}").exists() for p in children) and time.monotonic() < deadline:
        time.sleep(0.2)
    alive = [
        p for p in children if Path(f"/proc/{p}").exists() and "Z" not in Path(f"/proc/{p}/stat").read_text().split()[2]
    ]
    assert alive == []
