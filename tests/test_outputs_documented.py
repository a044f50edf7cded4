"""Every file, array and key that a run or a plan writes is documented in README.md's
"### Outputs" section: short runs of every scenario (and a hexapod move list) and the plans
of every mechanism, each name written checked against the names the section spells out in
backticks. A new array, metric or file that the README does not mention fails here."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from planbench import api, scenarios

README = Path(__file__).resolve().parents[1] / "README.md"
RUNS = {  # short runs (s): every array and metric is written whatever the duration
    "loader-supply": 0.2,
    "loader-direct": 0.2,
    "hexapod-sync-move": 0.2,
    "hexapod-async-move": 0.2,
    "antenna-paper-motion": 0.2,
    "antenna-sea-state": 0.2,
    "fast-tracking": 0.2,
    "fast-ra-scan": 0.2,
    "fast-source-switch": 0.2,
}
MOVE_LIST = {
    "duration": 0.2,
    "moves": [
        {"target": [0.1, 0, 0, 0, 0, 0], "synchronous": True},
        {"target": [0, 0.1, 0, 0, 0, 0], "synchronous": False},
    ],
}
PLANS = [
    "loader-supply",
    "hexapod-sync-move",
    "antenna-paper-motion",
    "fast-tracking",
    "fast-ra-scan",
    "fast-dec-scan",
    "fast-source-switch",
]


def documented() -> set[str]:
    """The names in backticks of the Outputs section; `a_b`/`_c` also gives a_c."""
    text = README.read_text()
    start = text.index("\n### Outputs\n")
    end = min(i for i in (text.find("\n## ", start + 1), text.find("\n### ", start + 1)) if i > 0)
    names, last = set(), ""
    for token in re.findall(r"`([^`\n]+)`", text[start:end]):
        if token.startswith("_") and last:
            names.add(last.rsplit("_", 1)[0] + token)
        else:
            names.add(token)
            last = token
        for part in re.split(r"[\s/.,]+", token):
            names.add(part)
    return names


def json_keys(value, skip=frozenset(), path="") -> set[tuple[str, str]]:
    """(path, key) of every key of nested dicts and lists of dicts, but those in ``skip``
    (names of the run's joints, struts, cables, segments) whose values are still walked."""
    out = set()
    if isinstance(value, dict):
        for k, v in value.items():
            if k not in skip:
                out.add((path, k))
            out |= json_keys(v, skip, f"{path}.{k}")
    elif isinstance(value, list):
        for v in value:
            out |= json_keys(v, skip, path)
    return out


def undocumented(written: set[tuple[str, str]]) -> list[str]:
    names = documented()
    return sorted(f"{where}: {key}" for where, key in written if key not in names)


def test_the_section_lists_every_scenario_of_the_registry():
    runs, plans = scenarios._registry()
    assert set(RUNS) == set(runs)
    assert set(PLANS) >= {"fast-dec-scan"} and set(PLANS) <= set(runs) | set(plans)


@pytest.mark.parametrize(
    "name, params",
    [(n, {"duration": d}) for n, d in RUNS.items()] + [("hexapod-sync-move", MOVE_LIST)],
    ids=[*RUNS, "hexapod-move-list"],
)
def test_every_run_output_is_documented(tmp_path, name, params):
    out = tmp_path / "run"
    api.run(name, params=params, out=out)
    written = {("files", f.name) for f in out.iterdir()}
    with np.load(out / "timeseries.npz") as npz:
        written |= {("timeseries.npz", k) for k in npz.files}
        skip = {str(v) for k in ("joint_names", "strut_names", "cable_names") if k in npz.files for v in npz[k]}
    summary = json.loads((out / "summary.json").read_text())
    skip |= set(summary["metrics"].get("segments", {}))
    written |= {("summary.json", k) for k in summary}
    written |= {("summary.json components", k) for k in summary["components"]}
    written |= {("summary.json sensors", k) for s in summary["sensors"] for k in s}
    written |= {("summary.json checks", k) for c in summary["checks"] for k in c}
    written |= {(f"metrics{p}", k) for p, k in json_keys(summary["metrics"], frozenset(skip))}
    assert undocumented(written) == []


@pytest.mark.parametrize("name", PLANS)
def test_every_plan_output_is_documented(written_plan, name):
    code, out = written_plan(name)
    assert code == 0
    written = {("files", f.name) for f in out.iterdir()}
    for f in out.glob("*.npz"):
        with np.load(f) as npz:
            written |= {(f.name, k) for k in npz.files}
    if (out / "segments.json").exists():
        written |= {(f"segments.json{p}", k) for p, k in json_keys(json.loads((out / "segments.json").read_text()))}
    assert undocumented(written) == []


def test_an_undocumented_array_fails():
    assert undocumented({("timeseries.npz", "q_planned"), ("timeseries.npz", "undocumented_array")}) == [
        "timeseries.npz: undocumented_array"
    ]
