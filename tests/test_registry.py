"""The mechanisms are found from their folders: every models/<name>/ with a scene.xml, whose
simulation is sims/<name>/."""

from __future__ import annotations

import pytest

from planbench import models, scenarios


def test_the_mechanisms_are_the_model_folders():
    folders = sorted(p.parent.name for p in models.MODELS_DIR.glob("*/scene.xml"))
    assert list(models.MECHANISMS) == folders == ["antenna", "fast", "hexapod", "loader"]
    assert [m.name for m in scenarios.mechanisms()] == folders
    # every scenario comes from one of them
    assert {scenarios.mechanism_of(n).name for n in scenarios.SCENARIOS} == set(folders)


def test_a_model_folder_without_its_simulation_package_is_named(monkeypatch):
    monkeypatch.setattr(models, "MECHANISMS", (*models.MECHANISMS, "crane"))
    scenarios.mechanisms.cache_clear()
    try:
        name = "crane"
        with pytest.raises(ImportError, match=f"models/{name}/scene.xml has no simulation package sims/{name}/"):
            scenarios.mechanisms()
    finally:
        monkeypatch.undo()
        scenarios.mechanisms.cache_clear()


def test_a_scenario_found_by_its_mechanism_imports_that_mechanism_alone():
    # A campaign's worker (planbench.campaign.worker) looks its scenario up with get_of: the same
    # scenario as the registry's, without importing the other mechanisms' packages.
    import subprocess
    import sys

    code = (
        "import sys; from planbench import scenarios\n"
        "by_mechanism = {m: scenarios.get_of(m, n) for m, n in [('hexapod', 'hexapod-sync-move'), "
        "('loader', 'loader-supply')]}\n"
        "print(sorted(m for m in ('planbench.fast', 'planbench.antenna') if m in sys.modules))\n"
        "print(all(s is scenarios.get(s.name) for s in by_mechanism.values()))\n"
        "print(scenarios.get_of('hexapod', 'fast-tracking').name)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.splitlines() == ["[]", "True", "fast-tracking"]
