"""Suite-wide tests over every registered scenario (in the spirit of dm_control's
``suite_test.py``): a scenario added to ``planbench.scenarios.SCENARIOS`` gets them with no new
test code. Each runs a short stretch (SHORT_S) of the scenario, twice with one seed and once
with another.
"""

from __future__ import annotations

import functools
import json
import math

import numpy as np
import pytest

from planbench import outputs, pipeline, runner, scenarios
from planbench.checks import NOT_EVALUATED
from planbench.task import PluginError

SHORT_S = 0.25  # s: 25-50 control ticks, enough for every disturbance and sensor to act
LOGGED = ("t", "qpos", "qvel", "act", "ctrl", "actuator_force", "sensordata", "mocap_pos", "mocap_quat")
NAMES = list(scenarios.SCENARIOS)


@functools.cache
def short_run(name: str, seed: int):
    setup = scenarios.get(name).build(scenarios.get(name).resolve(duration=SHORT_S, seed=seed))
    return setup, runner.run(name, setup)


@pytest.mark.parametrize("name", NAMES)
def test_a_short_run_has_no_mujoco_warning(name):
    _, result = short_run(name, 1)
    log = result.log
    assert log.diverged_at is None and log.warnings == {}, (log.warnings, log.divergence_message)
    dt = log.t[1] - log.t[0]  # the run ends at the last whole tick within SHORT_S
    assert SHORT_S - dt < log.t[-1] <= SHORT_S + 1e-9 and np.isfinite(log.qpos).all() and np.isfinite(log.qvel).all()
    [warnings] = [c for c in result.checks if c.name == "simulation_warnings"]
    assert warnings.passed and warnings.value == 0


@pytest.mark.parametrize("name", NAMES)
def test_the_same_seed_gives_an_identical_log(name):
    _, a = short_run(name, 1)
    setup = scenarios.get(name).build(scenarios.get(name).resolve(duration=SHORT_S, seed=1))
    b = runner.run(name, setup)  # a fresh build, not the cached one
    for field in LOGGED:
        x, y = getattr(a.log, field), getattr(b.log, field)
        assert x.shape == y.shape and x.tobytes() == y.tobytes(), field  # bit for bit
    assert [c.to_json() for c in a.checks] == [c.to_json() for c in b.checks]


#: Scenarios whose runs draw random numbers (wind, sea, sensor noise): another seed must
#: change their log. The loader has none.
STOCHASTIC = [n for n in NAMES if not n.startswith("loader")]


@pytest.mark.parametrize("name", STOCHASTIC)
def test_another_seed_gives_another_log(name):
    _, a = short_run(name, 1)
    _, b = short_run(name, 2)
    assert not np.array_equal(a.log.qpos, b.log.qpos)


@pytest.mark.parametrize("name", NAMES)
def test_every_check_has_a_unit_and_a_limit(name):
    _, result = short_run(name, 1)
    names = [c.name for c in result.checks]
    assert len(names) == len(set(names)) >= 2
    for c in result.checks:
        assert c.name.isidentifier() and c.name.islower()
        assert isinstance(c.unit, str) and c.unit.strip(), c
        assert math.isfinite(float(c.limit)), c
        assert c.comparison in ("<=", "<", ">=", ">", "=="), c
        if not c.evaluated:  # a short run may not reach a check's window: it says so and fails
            assert c.note.startswith(NOT_EVALUATED) and not c.passed, c


@pytest.mark.parametrize("name", NAMES)
def test_the_summary_is_strict_json_and_names_what_ran(name, tmp_path):
    setup, result = short_run(name, 1)
    out = tmp_path / "out"
    outputs.write_run(result, setup, out)

    def no_constants(text):
        raise AssertionError(f"summary.json holds {text}, which is not JSON")

    summary = json.loads((out / "summary.json").read_text(), parse_constant=no_constants)
    assert summary["scenario"] == name and summary["seed"] == 1
    components = summary["components"]
    assert set(components) == {"planner", "trajectory", "controller", "sensors", "disturbance"}
    assert components["planner"].startswith("planbench.planners.") and components["trajectory"].startswith(
        "planbench.planners."
    )
    assert components["controller"].startswith("planbench.") and components["sensors"].startswith("planbench.")
    assert summary["plugins"] == {}
    assert summary["sensors"] and all(s["rate_hz"] > 0 and s["name"] for s in summary["sensors"])
    assert [c["name"] for c in summary["checks"]] == [c.name for c in result.checks]
    manifest = json.loads((out / outputs.MANIFEST).read_text())
    assert manifest["scenario"] == name and set(manifest["files"]) >= set(outputs.RUN_FILES)


class FaultyController:
    """The scenario's own controller until ``tick``, then a fault: it raises, or writes NaN
    into its last actuator (a user's controller with a bug)."""

    def __init__(self, inner, tick: int, fault: str):
        self.inner, self.tick, self.fault = inner, tick, fault

    def reset(self, context):
        self.command = context.command
        self.inner.reset(context)

    def __call__(self, tick, observation):
        self.inner(tick, observation)
        if tick == self.tick:
            if self.fault == "raise":
                raise RuntimeError("observation 'imu' missing\nin my controller")
            self.command[-1] = np.nan


@pytest.mark.parametrize("fault, fault_tick", [("raise", 0), ("raise", 7), ("nan", 7)])  # 0: the initial state alone
@pytest.mark.parametrize("name", NAMES)
def test_a_controller_fault_ends_the_run_as_a_failed_check(name, fault, fault_tick, tmp_path):
    setup = scenarios.get(name).build(scenarios.get(name).resolve(duration=SHORT_S, seed=1))
    setup.components.controller = FaultyController(setup.components.controller, fault_tick, fault)
    result = runner.run(name, setup)
    checks = {c.name: c for c in result.checks}
    error = checks["controller_errors"]
    assert not error.passed and error.value == 1 and not result.passed
    expected = (
        "RuntimeError: observation 'imu' missing in my controller"
        if fault == "raise"
        else f"({setup.physics.model.actuator(setup.physics.model.nu - 1).name}) = nan"
    )
    assert expected in error.note, error.note
    assert checks["simulation_warnings"].passed  # no NaN ever reached MuJoCo
    assert result.log.t.size == fault_tick + 1  # ended at the fault
    assert np.isfinite(result.log.ctrl).all()
    outputs.write_run(result, setup, tmp_path / "out")  # outputs still written
    summary = json.loads((tmp_path / "out" / "summary.json").read_text(), parse_constant=_not_json)
    assert summary["passed"] is False


def _not_json(constant: str):
    """json.loads' hook for NaN and Infinity, which Python writes but JSON does not have."""
    raise AssertionError(f"summary.json holds {constant}, which is not JSON")


@pytest.mark.parametrize("name", NAMES)
def test_a_nan_first_command_is_bad_input_before_any_step(name):
    """A non-finite command at the first tick is a broken contract, found before MuJoCo
    steps: a PluginError (the CLI's exit 2) naming the actuator, not a run."""
    setup = scenarios.get(name).build(scenarios.get(name).resolve(duration=SHORT_S, seed=1))
    setup.components.controller = FaultyController(setup.components.controller, 0, "nan")
    last = setup.physics.model.actuator(setup.physics.model.nu - 1).name
    with pytest.raises(PluginError, match=rf"\({last}\) = nan at t = 0.0000 s, its first command"):
        runner.run(name, setup)
    assert setup.physics.data.time == 0.0


class HoldStill:
    """A user's simplest controller: it writes nothing, so the task's initial commands hold
    (servo set-point rates 0, FAST's winches parked at the start)."""

    def reset(self, context):
        self.observed = set(context.observation)

    def __call__(self, tick, observation):
        assert set(observation) == self.observed  # the same readings every tick


@pytest.mark.parametrize("name", NAMES)
def test_a_hold_still_plugin_controller_runs_and_is_judged(name, tmp_path):
    """Every scenario runs a user's controller that only holds, through the CLI's plug-in
    path: every check is evaluated or says why not, and summary.json names the plug-in."""
    from planbench import api

    result = api.run(name, controller=HoldStill(), params=dict(duration=SHORT_S, seed=1), out=tmp_path / "out")
    checks = {c.name: c for c in result.checks}
    assert checks["controller_errors"].passed and checks["simulation_warnings"].passed, checks
    assert SHORT_S - (result.log.t[1] - result.log.t[0]) < result.log.t[-1] <= SHORT_S + 1e-9  # the last whole tick
    for c in result.checks:
        assert c.evaluated or c.note.startswith(NOT_EVALUATED), c
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["components"]["controller"] == f"{__name__}.HoldStill"


@pytest.mark.parametrize("name", NAMES)
def test_the_nominal_plant_runs_bit_for_bit_as_without_one(name):
    # A scenario's nominal plant, given explicitly, is the machine built without one (issue
    # 15: plant uncertainty perturbs only when it is set).

    scenario = scenarios.get(name)
    assert scenario.plant is not None and scenario.plant.is_nominal
    setup, result = short_run(name, 1)
    params = scenario.resolve(duration=SHORT_S, seed=1)
    for other_setup in (
        scenario.build(params, plant=type(scenario.plant)()),
        pipeline.build(scenario, params, scenario.resolve_plant({})),
    ):
        other = runner.run(name, other_setup)
        for key in LOGGED:
            np.testing.assert_array_equal(getattr(other.log, key), getattr(result.log, key), err_msg=key)
        ours, theirs = setup.task.evaluation.timeseries(result.log), other_setup.task.evaluation.timeseries(other.log)
        assert ours.keys() == theirs.keys()
        for key in ours:
            np.testing.assert_array_equal(theirs[key], ours[key], err_msg=key)
        np.testing.assert_array_equal([c.value for c in other.checks], [c.value for c in result.checks])
        assert other.plant == type(scenario.plant)().to_dict() == result.plant
