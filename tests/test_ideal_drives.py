"""The ideal drives reproduce the testbed's results from before the drive trains as built: a
0.3 s run of every scenario (with ``drives = "ideal"`` where the scenario has drive trains)
gives the sums of |qpos|, |qvel|, |actuator_force| and |ctrl| over its log pinned here, recorded
with the code before them. They are bit-for-bit equal on the machine that recorded them, and
equal to round-off on another: the libraries' last bits differ by CPU. A change of behaviour
moves them by far more than 1e-9. The ideal drives refuse the plant's errors of elements they
do not have."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from planbench import models, runner, scenarios
from planbench.params import ParamError

PINNED = {
    "antenna-paper-motion": {
        "qpos": 252.34256240492317,
        "qvel": 128.28624452325786,
        "actuator_force": 20713686.967366107,
        "ctrl": 127.9771675287166,
    },
    "antenna-sea-state": {
        "qpos": 264.0240670894295,
        "qvel": 31.3026832596626,
        "actuator_force": 15079585.390954917,
        "ctrl": 31.193862731179948,
    },
    "fast-tracking": {
        "qpos": 5292.11026597701,
        "qvel": 5.350335413100478,
        "actuator_force": 17654107.002991028,
        "ctrl": 30362.018840919285,
    },
    "fast-ra-scan": {
        "qpos": 5292.11026574644,
        "qvel": 5.350331607808686,
        "actuator_force": 17654107.00424168,
        "ctrl": 30362.018839855256,
    },
    "fast-source-switch": {
        "qpos": 5292.110264382776,
        "qvel": 5.35031396269065,
        "actuator_force": 17654107.10910619,
        "ctrl": 30362.01883910747,
    },
    "hexapod-sync-move": {
        "qpos": 592.1689425602143,
        "qvel": 0.10496202700922959,
        "actuator_force": 5920776.582194269,
        "ctrl": 0.013786003990783786,
    },
    "hexapod-async-move": {
        "qpos": 592.1737896568366,
        "qvel": 0.15913301070342056,
        "actuator_force": 5923083.467612122,
        "ctrl": 0.02200296249013369,
    },
    "loader-supply": {
        "qpos": 155.88961946411544,
        "qvel": 132.0233743032341,
        "actuator_force": 259827.5585538222,
        "ctrl": 151.97080180492284,
    },
    "loader-direct": {
        "qpos": 158.2774618722995,
        "qvel": 8.878348235051707,
        "actuator_force": 241618.8591297445,
        "ctrl": 10.663487705567412,
    },
}


@pytest.mark.parametrize("name", list(scenarios.SCENARIOS))
def test_the_ideal_drives_are_the_earlier_plant(name):
    scenario = scenarios.get(name)
    overrides = {"duration": 0.3}
    if "drives" in type(scenario.params).names():
        overrides["drives"] = "ideal"
    log = runner.simulate(scenario.build(scenario.resolve(**overrides)))
    for key, value in PINNED[name].items():
        assert float(np.abs(getattr(log, key)).sum()) == pytest.approx(value, rel=1e-9, abs=0.0), key


def test_the_as_built_drives_are_another_plant():
    """The pins can fail: the as-built hexapod's log differs from the ideal one's."""
    scenario = scenarios.get("hexapod-sync-move")
    log = runner.simulate(scenario.build(scenario.resolve(duration=0.3)))
    assert float(np.abs(log.actuator_force).sum()) != pytest.approx(
        PINNED["hexapod-sync-move"]["actuator_force"], rel=1e-6
    )


def _with_drive_train_errors():
    """(scenario, field, value) for every scenario whose plant declares errors of the drive
    trains as built: each field at the top of its range."""
    cases = []
    for name in scenarios.SCENARIOS:
        scenario = scenarios.get(name)
        plant = scenario.plant
        if plant is None or "drives" not in type(scenario.params).names():
            continue
        declared = {f.name: f.metadata["declared"] for f in dataclasses.fields(plant)}
        cases += [(name, field, declared[field].high) for field in type(plant).AS_BUILT_FIELDS]
    return cases


@pytest.mark.parametrize("name, field, value", _with_drive_train_errors())
def test_the_ideal_drives_refuse_errors_of_the_drive_trains(name, field, value, monkeypatch):
    """An error of an element the ideal drives lack would be ignored: it is refused, naming the
    field and its value, before any model file is opened."""
    scenario = scenarios.get(name)
    plant = scenario.resolve_plant({field: value})
    params = scenario.resolve(drives="ideal", duration=0.01)
    opened = []
    original = models.scene_path
    monkeypatch.setattr(models, "scene_path", lambda *a, **k: opened.append(a) or original(*a, **k))
    with pytest.raises(ParamError, match=f"plant {field} = {value!r}: an error of the drive trains as built"):
        scenario.build(params, plant=plant)
    assert opened == []


def test_every_mechanism_with_drive_trains_declares_their_errors():
    cases = _with_drive_train_errors()
    assert {name.split("-")[0] for name, _, _ in cases} == {"antenna", "hexapod", "loader"}
