"""planbench in a user's Python environment: one top-level name, ``planbench``.

The folders sims/, planners/ and models/ are installed as ``planbench``, ``planbench.planners``
and ``planbench.models`` (pyproject.toml). A built wheel holds nothing else at the top level;
a user's own packages called ``models``, ``sims`` or ``planners`` neither break a run nor get
imported by it; a plug-in written against the old top-level names is told the new one in one
line; the public API is what ``planbench.__all__`` names.
"""

from __future__ import annotations

import importlib.metadata
import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

import planbench

ROOT = Path(__file__).resolve().parents[1]
OLD_NAMES = ("sims", "planners", "models")


def _environment(path: Path | None = None) -> dict:
    """The process environment with ``path`` (or nothing) on PYTHONPATH: planbench itself is
    found through its installation, never through the repository folder."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    if path is not None:
        env["PYTHONPATH"] = str(path)
    return env


def _python_passes(code: str, cwd: Path) -> None:
    """Run ``code`` in a fresh Python (planbench as installed) and require it to exit 0."""
    proc = subprocess.run(
        [sys.executable, "-c", code], cwd=cwd, env=_environment(), capture_output=True, text=True, timeout=300
    )
    assert proc.returncode == 0, proc.stderr


def _planbench(*args, cwd: Path, path: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "planbench.cli", *map(str, args)],
        cwd=cwd,
        env=_environment(path),
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    """A wheel built from a copy of the project's tracked files (the build writes only there)."""
    source = tmp_path_factory.mktemp("source")
    for name in ("pyproject.toml", "README.md", "LICENSE", "CHANGELOG.md"):
        shutil.copy2(ROOT / name, source / name)
    for folder in ("sims", "planners", "models"):
        shutil.copytree(ROOT / folder, source / folder, ignore=shutil.ignore_patterns("__pycache__"))
    dist = tmp_path_factory.mktemp("dist")
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "--quiet",
            "--no-deps",
            "--no-build-isolation",
            "--no-index",
            "--wheel-dir",
            str(dist),
            str(source),
        ],
        check=True,
        capture_output=True,
        timeout=300,
    )
    [built] = dist.glob("planbench-*.whl")
    return built


def test_the_wheel_holds_planbench_alone_at_the_top_level(wheel, tmp_path):
    names = zipfile.ZipFile(wheel).namelist()
    version = planbench.__version__
    assert {name.split("/")[0] for name in names} == {"planbench", f"planbench-{version}.dist-info"}
    # The package data and every mechanism's packages are in it, under their planbench names.
    for path in (
        "planbench/models/loader/scene.xml",
        "planbench/models/fast/assets/reflector.obj",
        "planbench/planners/hexapod/__init__.py",
        "planbench/fast/measurement.py",
        "planbench/campaign/worker.py",
        "planbench/py.typed",
    ):
        assert path in names, path
    # Every package folder of the project is one of the wheel's (pyproject.toml lists them).
    prefixes = {"sims": "planbench", "planners": "planbench/planners", "models": "planbench/models"}
    for folder, prefix in prefixes.items():
        for init in (ROOT / folder).rglob("__init__.py"):
            relative = init.relative_to(ROOT / folder).as_posix()
            assert f"{prefix}/{relative}" in names, f"{init.relative_to(ROOT)} is missing from the wheel"
    # Installed (without its dependencies, which are this environment's), the same: one name.
    target = tmp_path / "site"
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "install",
            "--quiet",
            "--no-deps",
            "--no-index",
            "--target",
            str(target),
            str(wheel),
        ],
        check=True,
        capture_output=True,
        timeout=300,
    )
    top = {p.name for p in target.iterdir()} - {"bin"}
    assert top == {"planbench", f"planbench-{version}.dist-info"}


def test_users_packages_called_models_sims_and_planners_do_not_disturb_a_run(tmp_path):
    # The user's own packages: models is theirs to use; sims and planners fail if imported.
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "__init__.py").write_text("OWNER = 'the user'\n")
    for name in ("sims", "planners"):
        (tmp_path / name).mkdir()
        (tmp_path / name / "__init__.py").write_text(f"raise RuntimeError('the user\\'s {name} was imported')\n")
    (tmp_path / "mine.py").write_text(
        "import models  # the user's own package, beside planbench\n"
        "from planbench.loader.controller import reference_controller\n\n"
        "assert models.OWNER == 'the user', models\n\n"
        "def make():\n"
        "    return reference_controller()\n"
    )
    proc = _planbench(
        "run",
        "loader-supply",
        "--controller",
        "mine.py:make",
        "--out",
        tmp_path / "out",
        "--quiet",
        cwd=tmp_path,
        path=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["passed"] and summary["plugins"] == {"controller": "mine.py:make"}


def test_planbench_imports_no_old_top_level_name(tmp_path):
    # Every module of planbench imported: none of the old top-level names comes with them.
    code = (
        "import pkgutil, importlib, sys\n"
        "import planbench\n"
        "for m in pkgutil.walk_packages(planbench.__path__, 'planbench.'):\n"
        "    importlib.import_module(m.name)\n"
        f"old = sorted(n for n in sys.modules if n.split('.')[0] in {OLD_NAMES!r})\n"
        "print(len(sys.modules), old)\n"
        "assert not old, old\n"
    )
    _python_passes(code, tmp_path)


@pytest.mark.parametrize(
    "old, new",
    [("planners.trajectory", "planbench.planners"), ("sims.task", "planbench"), ("models", "planbench.models")],
)
def test_a_plugin_with_an_old_name_gets_one_line_with_the_new_one(tmp_path, old, new):
    (tmp_path / "old_style.py").write_text(f"import {old}\n\ndef make():\n    return None\n")
    for spec in ("old_style.py:make", f"{old}:make"):
        proc = _planbench("run", "loader-supply", "--controller", spec, cwd=tmp_path, path=tmp_path)
        assert proc.returncode == 2, proc.stderr
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
        assert f"import {new!r} instead" in lines[0], lines[0]


def test_the_version_comes_from_one_place(tmp_path):
    proc = _planbench("--version", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == f"planbench {planbench.__version__}"
    assert importlib.metadata.version("planbench") == planbench.__version__
    changelog = (ROOT / "CHANGELOG.md").read_text()
    assert f"## [{planbench.__version__}]" in changelog


def test_the_public_api_is_what_all_names():
    for name in planbench.__all__:
        assert getattr(planbench, name) is not None, name
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        planbench.no_such_name  # noqa: B018
    readme = (ROOT / "README.md").read_text()
    section = readme.split("## Python API", 1)[1].split("\n## ", 1)[0]
    for name in planbench.__all__:
        assert f"`{name}" in section, f"README's Python API section does not list {name}"


def test_finding_the_scenarios_imports_no_module_a_run_may_not_need(tmp_path):
    """Every command line looks its scenario up: by its name's prefix, that mechanism alone
    is imported; the whole registry (the four mechanisms) leaves out what only some runs use
    (scipy.signal and scipy.stats, about 0.4 s; scipy.integrate, 0.3 s; the video writer),
    imported where they are used."""
    code = (
        "import sys\n"
        "from planbench import scenarios\n"
        "assert scenarios.get('loader-supply').name == 'loader-supply'\n"
        "assert 'loader-supply' in scenarios.KnownNames()\n"
        "others = sorted(n for n in sys.modules if n.split('.')[:2] in "
        "(['planbench', 'fast'], ['planbench', 'antenna'], ['planbench', 'hexapod']))\n"
        "assert not others, others\n"
        "assert 'loader-nope' not in scenarios.KnownNames()  # (asks the whole registry)\n"
        "assert 'fast-dec-scan' in scenarios.KnownNames(plans=True) and 'fast-dec-scan' not in scenarios.KnownNames()\n"
        "assert scenarios.get_plan('fast-dec-scan').name == 'fast-dec-scan'\n"
        "scenarios.mechanisms()\n"
        "heavy = sorted(n for n in ('scipy.signal', 'scipy.stats', 'scipy.integrate', 'mediapy') if n in sys.modules)\n"
        "assert not heavy, heavy\n"
    )
    _python_passes(code, tmp_path)


def test_a_planner_only_campaign_worker_starts_without_the_simulation_or_the_report(tmp_path):
    """A local worker of a planner-only campaign imports the campaign's worker side and the
    scenario's mechanism only: not the simulation pipeline, not the report's matplotlib and
    scipy.stats, not the spec's distributions (the driver draws); a simulating worker imports
    the pipeline as it starts."""
    code = (
        "import os, sys\n"
        "from planbench.campaign import engines, worker\n"
        "context = worker.Context('hexapod-sync-move', {}, None, {}, 'plan', (), (), mechanism='hexapod')\n"
        "engines._init_worker(os.getppid(), context)\n"
        "assert 'planbench.hexapod.plan_columns' in sys.modules\n"
        "heavy = sorted(n for n in ('planbench.pipeline', 'planbench.campaign.report', 'matplotlib', 'scipy.stats')"
        " if n in sys.modules)\n"
        "assert not heavy, heavy\n"
        "engines._init_worker(os.getppid(), context.__class__(**{**context.__dict__, 'mode': 'simulate'}))\n"
        "assert 'planbench.pipeline' in sys.modules\n"
    )
    _python_passes(code, tmp_path)
