"""The scenario registry: every runnable scenario of every mechanism, by name.

Each mechanism's package ``sims/<mechanism>/`` declares its own scenarios (``SCENARIOS``, a
tuple of ``Scenario``), plan-only entries (``PLANS``, optional), the scenario that ``planbench
bench`` times (``BENCHMARK``: name and number of runs) and the reward of its dm_control
environment (``environment_reward``). The registry imports the packages of the mechanisms
that ``models.MECHANISMS`` lists (one folder per model, as in MuJoCo Menagerie) the first
time it is asked, as dm_control's suite builds its registry from its domain modules; the
tuple is the folders of models/ that hold a scene.xml, so a fifth mechanism is its own
folders (models/<name>/ and sims/<name>/) and nothing else. ``planbench list``, ``run``,
``plan``, ``demo``, ``bench`` and the environments (``sims.envs``) all come from here.
"""

from __future__ import annotations

import functools
import importlib
from dataclasses import dataclass
from typing import Callable

import models


@dataclass(frozen=True)
class Scenario:
    """A named run: a mechanism, its parameters' named defaults, a planner and its checks.

    Attributes:
      name: CLI name.
      summary: one line for ``planbench list``.
      params: the scenario's parameters with its defaults (a ``sims.params.Params``: typed,
        ranged and validated; ``planbench run NAME --set KEY=VALUE`` and scenario files
        override them).
      build: (params, planner=None, controller=None) -> runner.Setup; None for the defaults
        (the paper's planner, our reference controller).
      plan: (params) -> the planned trajectory (``planbench plan``), no physics.
      expect_pass: False for a scenario that demonstrates a failure (loader-direct).
      camera: the default camera of its video.
      kinds: () -> "slide" or "hinge" per planned channel (units of plots).
      plan_extras: optional (plan, out_dir) -> None, more files for ``planbench plan`` (the
        antenna's comparison of the paper's methods, FAST's figures).
      demo_cameras: cameras of further videos that ``planbench demo`` renders (NAME-CAMERA.mp4).
      control_dt: the control period, s (one tick: the shortest run).
      online_planner: the scenario's planner is an online one (the antenna's: ``reset`` and
        ``step``, sims.task.OnlinePlanner), not a ``plan(problem)`` that returns a Trajectory.
      judge_plans: optional (list of params, planner=None) -> one list of checks per params:
        the run's planner checks on the planned trajectory alone, no physics, vectorized
        over the list (planner-only campaigns, ``mode = "plan"``).
      plant: the nominal plant (an instance of the mechanism's ``sims.params.PlantParams``:
        its plant-uncertainty fields at their nominal values); ``build(..., plant=...)`` takes
        a perturbed one. None: the mechanism declares no plant uncertainty.
    """

    name: str
    summary: str
    params: object
    build: Callable
    plan: Callable
    expect_pass: bool = True
    camera: str = "overview"
    kinds: Callable = lambda: ()
    plan_extras: Callable | None = None
    demo_cameras: tuple = ()
    control_dt: float | None = None
    online_planner: bool = False
    plant: object = None
    judge_plans: Callable | None = None

    def resolve(self, overrides: dict | None = None, **changes):
        """The scenario's parameters with ``overrides`` (a mapping, as a scenario file's
        [parameters]) and ``changes`` applied and validated (a ParamError names a bad key)."""
        return type(self.params).from_mapping({**(overrides or {}), **changes}, base=self.params)

    def resolve_plant(self, overrides: dict | None = None):
        """The nominal plant with ``overrides`` (a scenario file's or a campaign's [plant]
        table) applied and validated; a ParamError names a bad key, or says that this
        scenario's mechanism declares no plant uncertainty."""
        from sims.params import ParamError

        if self.plant is None:
            if overrides:
                raise ParamError(f"plant: {self.name} declares no plant uncertainty, got {', '.join(overrides)}")
            return None
        return type(self.plant).from_mapping(dict(overrides or {}), base=self.plant, prefix="plant.")


@functools.lru_cache(maxsize=1)
def mechanisms() -> tuple:
    """The mechanisms' simulation packages (``sims.<name>`` for each of models.MECHANISMS), in
    that order; a model folder without its package is an error naming both."""
    packages = []
    for name in models.MECHANISMS:
        try:
            packages.append(importlib.import_module(f"sims.{name}"))
        except ModuleNotFoundError as e:
            if e.name != f"sims.{name}":
                raise
            raise ImportError(f"models/{name}/scene.xml has no simulation package sims/{name}/") from None
    return tuple(packages)


@functools.lru_cache(maxsize=1)
def _registry() -> tuple[dict, dict]:
    scenarios, plans = {}, {}
    for package in mechanisms():
        for table, entries in ((scenarios, getattr(package, "SCENARIOS", ())), (plans, getattr(package, "PLANS", ()))):
            for entry in entries:
                if entry.name in scenarios or entry.name in plans:
                    raise ValueError(f"scenario name {entry.name!r} of {package.__name__} is taken")
                table[entry.name] = entry
    return scenarios, plans


def mechanism_of(name: str):
    """The package (``sims.<mechanism>``) that declares the scenario ``name``."""
    for package in mechanisms():
        if any(s.name == name for s in (*getattr(package, "SCENARIOS", ()), *getattr(package, "PLANS", ()))):
            return package
    raise ValueError(f"unknown scenario {name!r}")


def __getattr__(attribute: str):
    # SCENARIOS and PLANS are built on first use: the mechanisms' packages import this module.
    if attribute == "SCENARIOS":
        return _registry()[0]
    if attribute == "PLANS":
        return _registry()[1]
    raise AttributeError(f"module {__name__!r} has no attribute {attribute!r}")


def get(name: str) -> Scenario:
    """The scenario called ``name``; a ValueError lists the known names otherwise."""
    scenarios = _registry()[0]
    try:
        return scenarios[name]
    except KeyError:
        raise ValueError(
            f"unknown scenario {name!r}; known: {', '.join(scenarios)}"
        ) from None


def get_plan(name: str) -> Scenario:
    """A scenario or a plan-only entry called ``name`` (``planbench plan``)."""
    scenarios, plans = _registry()
    if name in plans:
        return plans[name]
    try:
        return get(name)
    except ValueError:
        raise ValueError(f"unknown scenario {name!r}; known: {', '.join([*scenarios, *plans])}") from None
