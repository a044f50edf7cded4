"""Users' plug-ins through the CLI (``--controller/--planner MODULE:FACTORY``) and the Python
API: a bad plug-in is refused with exit 2 and one line naming the problem before anything
runs or is written; one that raises during the run ends it as a failed check, outputs
written; summary.json records what ran."""

from __future__ import annotations

import json
import textwrap
from pathlib import Path

import numpy as np
import pytest

from planbench import api
from planbench.cli import main
from planbench.task import PluginError

PLUGINS = textwrap.dedent("""
    import numpy as np

    class Hold:
        def reset(self, context):
            pass
        def __call__(self, tick, observation):
            return None

    class WrongShape(Hold):
        def __call__(self, tick, observation):
            return np.zeros(3)

    class NanFirst(Hold):
        def __call__(self, tick, observation):
            return np.full(6, np.nan)

    class RaisesLater(Hold):
        def __call__(self, tick, observation):
            if tick == 5:
                raise KeyError("setpoint")

    class ResetRaises(Hold):
        def reset(self, context):
            raise RuntimeError("no gains for this model")

    class NoReset:
        def __call__(self, tick, observation):
            pass

    class OldSignature:
        def reset(self, physics, reference, control_dt):
            pass
        def __call__(self, tick, physics):
            pass

    def needs_args(gain):
        return Hold()

    def factory_raises():
        raise ValueError("bad gain table")

    NOT_CALLABLE = 3

    class TwoChannels:
        labels = ("a", "b")
        duration = 1.0
        def sample(self, t):
            raise AssertionError("never sampled")

    class WrongChannelsPlanner:
        def plan(self, problem):
            return TwoChannels()

    class NanTrajectoryPlanner:
        def plan(self, problem):
            from examples.loader.quintic_planner import QuinticPlanner
            trajectory = QuinticPlanner().plan(problem)
            trajectory.spline.c[:] = np.nan
            return trajectory

    class NotAPlanner:
        pass

    class NotOnline:
        def plan(self, problem):
            return None
""")

# (argv after "run", words the one stderr line must contain)
BAD = [
    (["loader-supply", "--controller", "{p}"], ["MODULE:FACTORY"]),
    (["loader-supply", "--controller", "{tmp}/missing.py:Hold"], ["missing.py", "no such file"]),
    (["loader-supply", "--controller", "no_such_module_xyz:Hold"], ["no module named 'no_such_module_xyz'"]),
    (["loader-supply", "--controller", "{p}:Missing"], ["has no attribute 'Missing'"]),
    (["loader-supply", "--controller", "{p}:NOT_CALLABLE"], ["NOT_CALLABLE is a int, not a callable"]),
    (["loader-supply", "--controller", "{p}:needs_args"], ["the factory must take 0 arguments"]),
    (["loader-supply", "--controller", "{p}:factory_raises"], ["the factory raised ValueError: bad gain table"]),
    (["loader-supply", "--controller", "{p}:NoReset"], ["controller NoReset has no reset(context)"]),
    (["loader-supply", "--controller", "{p}:OldSignature"], ["OldSignature's reset(context) must take 1 argument"]),
    (["loader-supply", "--controller", "{p}:WrongShape"], ["command of shape (3,)", "6 actuators"]),
    (["loader-supply", "--controller", "{p}:NanFirst"], ["ctrl[0]", "= nan at t = 0.0000 s", "first command"]),
    (["loader-supply", "--controller", "{p}:ResetRaises"], ["reset raised RuntimeError: no gains for this model"]),
    (["loader-supply", "--planner", "{p}:NotAPlanner"], ["planner NotAPlanner has no plan(problem)"]),
    (["loader-supply", "--planner", "{p}:WrongChannelsPlanner"], ["2 channels (a, b)", "needs 6"]),
    (["loader-supply", "--planner", "{p}:NanTrajectoryPlanner"], ["non-finite position"]),
    (["antenna-paper-motion", "--planner", "{p}:NotOnline"], ["NotOnline has no reset()", "step(t, attitude)"]),
    (["hexapod-sync-move", "--planner", "{p}:WrongChannelsPlanner"], ["needs 6", "strut1"]),
]


@pytest.fixture
def plugin_file(tmp_path, monkeypatch):
    path = tmp_path / "my_plugins.py"
    path.write_text(PLUGINS)
    monkeypatch.chdir(tmp_path)
    return path


@pytest.mark.parametrize("argv, words", BAD)
def test_a_bad_plugin_is_one_line_exit_2_and_writes_nothing(argv, words, plugin_file, capsys, monkeypatch):
    monkeypatch.syspath_prepend(str(Path(__file__).resolve().parents[1]))  # examples/ for one planner
    tmp = plugin_file.parent
    argv = [a.replace("{p}", str(plugin_file)).replace("{tmp}", str(tmp)) for a in argv]
    out = tmp / "out"
    code = main(["run", *argv, "--out", str(out), "--quiet", "--duration", "0.05"])
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert code == 2, (code, captured.out, captured.err)
    assert len(lines) == 1 and lines[0].startswith("planbench: error: ") and "Traceback" not in captured.err, lines
    for text in words:
        assert text in lines[0], (text, lines[0])
    assert not out.exists()  # nothing written, not even the output directory
    assert not any(p.name.startswith(".planbench") for p in tmp.iterdir())


def test_a_plugin_that_raises_during_the_run_fails_a_check_and_writes_outputs(plugin_file, capsys):
    out = plugin_file.parent / "out"
    spec = f"{plugin_file}:RaisesLater"
    code = main(["run", "loader-supply", "--controller", spec, "--out", str(out), "--quiet"])
    assert code == 1
    summary = json.loads((out / "summary.json").read_text())
    [error] = [c for c in summary["checks"] if c["name"] == "controller_errors"]
    assert not error["passed"] and "KeyError: 'setpoint'" in error["note"] and "t = 0.0250 s" in error["note"]
    assert summary["plugins"] == {"controller": spec}
    assert summary["components"]["controller"].endswith(".RaisesLater")
    assert summary["components"]["planner"] == "planbench.planners.loader.CubicBSplinePlanner"


def test_a_module_plugin_and_the_python_api_run_the_same(plugin_file, monkeypatch):
    """``MODULE:FACTORY`` as an importable module gives the run that the API gives with the
    object: bit for bit."""
    monkeypatch.syspath_prepend(str(plugin_file.parent))
    out = plugin_file.parent / "cli"
    assert main(
        [
            "run",
            "hexapod-sync-move",
            "--controller",
            "my_plugins:Hold",
            "--out",
            str(out),
            "--duration",
            "0.2",
            "--quiet",
        ]
    ) in (0, 1)
    import my_plugins

    result = api.run("hexapod-sync-move", controller=my_plugins.Hold(), params=dict(duration=0.2))
    with np.load(out / "timeseries.npz") as ts:
        assert ts["qpos"].tobytes() == result.log.qpos.tobytes()
    summary = json.loads((out / "summary.json").read_text())
    assert [c["value"] for c in summary["checks"]] == [c.to_json()["value"] for c in result.checks]


def test_the_api_refuses_a_broken_plugin_before_running():
    class NoCall:
        def reset(self, context):
            pass

    with pytest.raises(PluginError, match="not callable as controller"):
        api.run("loader-supply", controller=NoCall())
    with pytest.raises(PluginError, match="has no reset"):
        api.run("antenna-sea-state", planner=object())
