"""The mechanisms are found from their folders: every models/<name>/ with a scene.xml, whose
simulation is sims/<name>/."""

from __future__ import annotations

import pytest

import models
from sims import scenarios


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
