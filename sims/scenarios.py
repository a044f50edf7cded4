"""The scenario registry: every runnable scenario of every mechanism, by name.

Each mechanism's package ``sims/<mechanism>/`` declares one record, ``MECHANISM``
(``Mechanism``): its scenarios, each tagged as dm_control's suite tags its tasks ("demo": run by
``planbench demo``; "benchmark": timed by ``planbench bench``), its plan-only entries, how many
runs the bench takes the best of, and the reward of its dm_control environment. The registry
imports the packages of the mechanisms that ``models.MECHANISMS`` lists (one folder per model,
as in MuJoCo Menagerie) the first time it is asked, as dm_control's suite builds its registry
from its domain modules; the tuple is the folders of models/ that hold a scene.xml (and those
of the roots that ``PLANBENCH_MECHANISMS`` names), so a fifth mechanism is its own folders
(models/<name>/ and sims/<name>/) and nothing else. ``planbench list``, ``run``, ``plan``,
``demo``, ``bench`` and the environments (``planbench.envs``) all come from here.
"""

from __future__ import annotations

import functools
import importlib
from collections.abc import Callable
from dataclasses import dataclass

from dm_control.utils import containers

from planbench import models

#: The tags of a scenario: ``planbench demo`` runs those tagged DEMO, ``planbench bench`` times
#: those tagged BENCHMARK.
DEMO = "demo"
BENCHMARK = "benchmark"


@dataclass(frozen=True)
class Scenario:
    """A named run: a mechanism, its parameters' named defaults, a planner and its checks.

    Attributes:
      name: CLI name.
      summary: one line for ``planbench list``.
      params: the scenario's parameters with its defaults (a ``planbench.params.Params``: typed,
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
        ``step``, planbench.task.OnlinePlanner), not a ``plan(problem)`` that returns a Trajectory.
      judge_plans: optional (list of params, planner=None) -> one list of checks per params:
        the run's planner checks on the planned trajectory alone, no physics, vectorized
        over the list (planner-only campaigns, ``mode = "plan"``).
      plan_columns: optional module with ``supports(base, axis paths)``, ``validate(base,
        paths, values, n)`` and ``judge(poses)``: a planner-only campaign's chunks validated
        and judged as columns (planbench.hexapod.plan_columns); None: run by run.
      plant: the nominal plant (an instance of the mechanism's ``planbench.params.PlantParams``:
        its plant-uncertainty fields at their nominal values); ``build(..., plant=...)`` takes
        a perturbed one. None: the mechanism declares no plant uncertainty.
      tags: DEMO, BENCHMARK or neither (a plan-only entry has none).
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
    plan_columns: object = None
    tags: tuple = (DEMO,)

    @property
    def __name__(self) -> str:  # a named factory, as the tasks of dm_control's TaggedTasks
        return self.name

    def __call__(self, params=None, **components):
        """The Setup of a run with ``params`` (None: the scenario's defaults) and
        ``components`` (planner, controller, plant) as ``build`` takes them."""
        return self.build(self.params if params is None else params, **components)

    def resolve(self, overrides: dict | None = None, **changes):
        """The scenario's parameters with ``overrides`` (a mapping, as a scenario file's
        [parameters]) and ``changes`` applied and validated (a ParamError names a bad key)."""
        return type(self.params).from_mapping({**(overrides or {}), **changes}, base=self.params)

    def resolve_plant(self, overrides: dict | None = None):
        """The nominal plant with ``overrides`` (a scenario file's or a campaign's [plant]
        table) applied and validated; a ParamError names a bad key, or says that this
        scenario's mechanism declares no plant uncertainty."""
        from planbench.params import ParamError

        if self.plant is None:
            if overrides:
                raise ParamError(f"plant: {self.name} declares no plant uncertainty, got {', '.join(overrides)}")
            return None
        return type(self.plant).from_mapping(dict(overrides or {}), base=self.plant, prefix="plant.")


@dataclass(frozen=True)
class Mechanism:
    """One mechanism's record, declared by its package (``sims.<name>.MECHANISM``).

    Attributes:
      name: its folders' name (models/<name>/, sims/<name>/).
      scenarios: its runnable scenarios, each with its tags.
      reward: (setup) -> (physics, tick, adapter) -> reward in (0, 1], of its dm_control
        environment (``planbench.envs``).
      plans: plan-only entries (``planbench plan``), no physics.
      benchmark_runs: how many runs ``planbench bench`` takes the best of.
    """

    name: str
    scenarios: tuple
    reward: Callable
    plans: tuple = ()
    benchmark_runs: int = 5

    @functools.cached_property
    def tasks(self) -> containers.TaggedTasks:
        """Its scenarios by name and tag (dm_control's ``TaggedTasks``)."""
        tasks = containers.TaggedTasks()
        for scenario in self.scenarios:
            tasks.add(*scenario.tags)(scenario)
        return tasks

    def tagged(self, tag: str) -> tuple:
        """Its scenarios tagged ``tag``, in declaration order."""
        names = self.tasks.tagged(tag)
        return tuple(s for s in self.scenarios if s.name in names)


def _import_mechanism(name: str):
    import planbench
    from planbench import planners

    # A mechanism of a root PLANBENCH_MECHANISMS names: its sims/ and planners/ folders
    # are searched after the project's own (as a namespace package's portions), as
    # planbench.<name> and planbench.planners.<name>.
    for root in models.extra_roots():
        for package, folder in ((planbench, root / "sims"), (planners, root / "planners")):
            if folder.is_dir() and str(folder) not in package.__path__:
                package.__path__.append(str(folder))
    try:
        return importlib.import_module(f"planbench.{name}")
    except ModuleNotFoundError as e:
        if e.name != f"planbench.{name}":
            raise
        raise ImportError(f"models/{name}/scene.xml has no simulation package sims/{name}/") from None


@functools.lru_cache(maxsize=1)
def mechanisms() -> tuple:
    """The mechanisms' records (``sims.<name>.MECHANISM`` for each of models.MECHANISMS), in
    that order; a model folder without its package, or a package without its record, is an
    error naming it."""
    records = []
    for name in models.MECHANISMS:
        package = _import_mechanism(name)
        record = getattr(package, "MECHANISM", None)
        if not isinstance(record, Mechanism) or record.name != name:
            raise ImportError(f"sims/{name}/ declares no MECHANISM = Mechanism({name!r}, ...)")
        records.append(record)
    return tuple(records)


@functools.lru_cache(maxsize=1)
def _registry() -> tuple[dict, dict]:
    scenarios, plans = {}, {}
    for record in mechanisms():
        for table, entries in ((scenarios, record.scenarios), (plans, record.plans)):
            for entry in entries:
                if entry.name in scenarios or entry.name in plans:
                    raise ValueError(f"scenario name {entry.name!r} of sims.{record.name} is taken")
                table[entry.name] = entry
    return scenarios, plans


def mechanism_of(name: str) -> Mechanism:
    """The record of the mechanism that declares the scenario (or plan) ``name``."""
    for record in mechanisms():
        if any(s.name == name for s in (*record.scenarios, *record.plans)):
            return record
    raise ValueError(f"unknown scenario {name!r}")


def tagged(tag: str) -> tuple:
    """Every mechanism's scenarios tagged ``tag`` (DEMO, BENCHMARK), in registry order."""
    return tuple(s for record in mechanisms() for s in record.tagged(tag))


def __getattr__(attribute: str):
    # SCENARIOS and PLANS are built on first use: the mechanisms' packages import this module.
    if attribute == "SCENARIOS":
        return _registry()[0]
    if attribute == "PLANS":
        return _registry()[1]
    raise AttributeError(f"module {__name__!r} has no attribute {attribute!r}")


def _by_prefix(name: str, plans: bool = False) -> Scenario | None:
    """Before the registry is built: the scenario (or, with ``plans``, plan-only entry)
    ``name`` if the mechanism its prefix names declares it (``loader-supply``: loader), that
    mechanism's package imported alone; None otherwise. A command line that runs one
    scenario then imports one mechanism, not all four (FAST's and the antenna's scipy
    modules cost each start about 0.4 s)."""
    prefix = name.split("-", 1)[0]
    return _declared_by(prefix, name, plans) if prefix in models.MECHANISMS else None


def _declared_by(mechanism: str, name: str, plans: bool = False) -> Scenario | None:
    """Before the registry is built: the entry ``name`` that ``mechanism`` declares, that
    mechanism's package imported alone; None otherwise (or once the registry is built, or
    where PLANBENCH_MECHANISMS adds mechanisms: one of those may declare the same name, which
    the registry refuses)."""
    if _registry.cache_info().currsize or models.extra_roots():
        return None
    record = getattr(_import_mechanism(mechanism), "MECHANISM", None)
    entries = (*getattr(record, "scenarios", ()), *(getattr(record, "plans", ()) if plans else ()))
    return next((entry for entry in entries if entry.name == name), None)


class KnownNames:
    """``name in KnownNames(plans)``: whether ``name`` is a scenario (or, with ``plans``, a
    plan-only entry), asked of the mechanism its prefix names first (``_by_prefix``), then of
    the whole registry."""

    def __init__(self, plans: bool = False):
        self.plans = plans

    def __contains__(self, name) -> bool:
        if _by_prefix(name, self.plans) is not None:
            return True
        scenarios, plans = _registry()
        return name in scenarios or (self.plans and name in plans)


def get(name: str) -> Scenario:
    """The scenario called ``name``; a ValueError lists the known names otherwise."""
    found = _by_prefix(name)
    if found is not None:
        return found
    scenarios = _registry()[0]
    try:
        return scenarios[name]
    except KeyError:
        raise ValueError(f"unknown scenario {name!r}; known: {', '.join(scenarios)}") from None


def get_of(mechanism: str, name: str) -> Scenario:
    """The scenario ``name`` of the mechanism ``mechanism`` with that mechanism's package
    imported alone: a campaign's worker needs one mechanism, and importing the others (FAST's
    and the antenna's scipy modules) would cost each worker about a second of its start.
    Once the registry is built, its answer; a name the mechanism does not declare is looked
    up in the registry (``get``: a ValueError lists the known names)."""
    found = _declared_by(mechanism, name)
    return found if found is not None else get(name)


def get_plan(name: str) -> Scenario:
    """A scenario or a plan-only entry called ``name`` (``planbench plan``)."""
    found = _by_prefix(name, plans=True)
    if found is not None:
        return found
    scenarios, plans = _registry()
    if name in plans:
        return plans[name]
    try:
        return get(name)
    except ValueError:
        raise ValueError(f"unknown scenario {name!r}; known: {', '.join([*scenarios, *plans])}") from None
