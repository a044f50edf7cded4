"""The scenario registry: every runnable scenario of every mechanism, by name.

Each mechanism's package ``sims/<mechanism>/`` declares its own scenarios (``SCENARIOS``, a
tuple of ``Scenario``), plan-only entries (``PLANS``, optional), the scenario that ``planbench
bench`` times (``BENCHMARK``: name and number of runs) and the reward of its dm_control
environment (``environment_reward``). The registry imports the packages of the mechanisms
that ``models.MECHANISMS`` lists (one folder per model, as in MuJoCo Menagerie) the first
time it is asked, as dm_control's suite builds its registry from its domain modules: a fifth
mechanism is its own folders plus its name in that tuple. ``planbench list``, ``run``,
``plan``, ``demo``, ``bench`` and the environments (``sims.envs``) all come from here.
"""

from __future__ import annotations

import functools
import importlib
from dataclasses import dataclass, field
from typing import Callable

import models


@dataclass(frozen=True)
class RunOptions:
    """Options of one run, from the CLI or a caller.

    Attributes:
      seed: seed of every random process of the run (disturbances, noise).
      duration: simulated time in s, None for the scenario's default.
      wind: mean wind speed in m/s, None for the scenario's default (wind scenarios only).
      elevation: telescope elevation in deg, None for the default (hexapod scenarios).
      hs, tp, heading: significant wave height (m), peak period (s) and wave heading off the
        bow (deg, 180 head seas), None for the defaults (sea-state scenarios).
      imu_rate, imu_latency: the antenna IMU's sample rate (Hz) and latency (s), None for the
        defaults; predict: False to switch the antenna controller's prediction off.
      stewart: FAST's Stewart stabilizer on (True) or off (False), None for the default (on).
      wind_direction: the azimuth the wind blows toward, deg from east (+x) toward north, None
        for the default (FAST scenarios).
      cable_segments: FAST's cables as chains of this many elastic segments (>= 2), None or 0
        for the default straight cables with the lumped catenary law.
    """

    seed: int = 0
    duration: float | None = None
    wind: float | None = None
    elevation: float | None = None
    hs: float | None = None
    tp: float | None = None
    heading: float | None = None
    imu_rate: float | None = None
    imu_latency: float | None = None
    predict: bool = True
    stewart: bool | None = None
    wind_direction: float | None = None
    cable_segments: int | None = None


@dataclass(frozen=True)
class Scenario:
    """A named run: a mechanism, a planner and its checks.

    Attributes:
      name: CLI name.
      summary: one line for ``planbench list``.
      build: (RunOptions, planner=None, controller=None) -> runner.Setup; None for the
        defaults (the paper's planner, our reference controller).
      plan: () -> the planned trajectory (``planbench plan``), no physics.
      options: the RunOptions fields beyond seed and duration that it uses (e.g. {"wind"}).
      expect_pass: False for a scenario that demonstrates a failure (loader-direct).
      camera: the default camera of its video.
      kinds: () -> "slide" or "hinge" per planned channel (units of plots).
      plan_extras: optional (plan, out_dir) -> None, more files for ``planbench plan`` (the
        antenna's comparison of the paper's methods, FAST's figures).
      demo_cameras: cameras of further videos that ``planbench demo`` renders (NAME-CAMERA.mp4).
      control_dt: the control period, s (one tick: the shortest run).
      validate: (RunOptions) -> None, raises a ValueError subclass naming the value and the
        limit for options that are valid numbers but not a run (a duration under one tick or
        whose log would not fit in memory, a sea state no sea has, an angle beyond a turn...).
        Cheap: nothing is built. ``planbench run`` calls it while it reads its options, and
        ``build`` calls it again (the Python API).
      online_planner: the scenario's planner is an online one (the antenna's: ``reset`` and
        ``step``, sims.task.OnlinePlanner), not a ``plan(problem)`` that returns a Trajectory.
    """

    name: str
    summary: str
    build: Callable
    plan: Callable
    options: frozenset = field(default_factory=frozenset)
    expect_pass: bool = True
    camera: str = "overview"
    kinds: Callable = lambda: ()
    plan_extras: Callable | None = None
    demo_cameras: tuple = ()
    control_dt: float | None = None
    validate: Callable = lambda options: None
    online_planner: bool = False


@functools.lru_cache(maxsize=1)
def mechanisms() -> tuple:
    """The mechanisms' simulation packages (``sims.<name>`` for each of models.MECHANISMS), in
    that order."""
    return tuple(importlib.import_module(f"sims.{name}") for name in models.MECHANISMS)


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
