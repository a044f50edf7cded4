"""The scenario registry: every runnable scenario of every mechanism, by name."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

from sims import antenna, fast, hexapod, loader


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


#: What the FAST runs share: options, plan plots and the paper's figures.
FAST_RUN = dict(options=frozenset({"wind", "wind_direction", "stewart", "cables"}), kinds=fast.plan_kinds,
                plan_extras=fast.write_figures, control_dt=fast.CONTROL_DT, validate=fast.validate)
LOADER_RUN = dict(kinds=loader.joint_kinds, control_dt=loader.CONTROL_DT, validate=loader.validate)
HEXAPOD_RUN = dict(options=frozenset({"wind", "elevation"}), kinds=hexapod.strut_kinds,
                   control_dt=hexapod.CONTROL_DT, validate=hexapod.validate)

SCENARIOS: dict[str, Scenario] = {
    s.name: s
    for s in (
        Scenario(
            "loader-supply",
            "PRR-3R loader: Table 1 key points P2, M1-M4, P3 through the cubic B-spline, past the breechblock and seat ring",
            loader.build_supply,
            lambda: loader.loader_planner.supply_plan(),
            **LOADER_RUN,
        ),
        Scenario(
            "loader-direct",
            "PRR-3R loader: P2 to P3 as a straight joint-space move in the same 2.5 s; strikes the obstacles (expected to fail)",
            loader.build_direct,
            lambda: loader.loader_planner.direct_plan(),
            expect_pass=False,
            **LOADER_RUN,
        ),
        Scenario(
            "hexapod-sync-move",
            "Rubin camera hexapod, 3 t camera: synchronous move of ~2 mm and 0.1 deg, all six struts arrive on one tick (--elevation, --wind)",
            hexapod.build_sync,
            lambda: hexapod.plan(True),
            **HEXAPOD_RUN,
        ),
        Scenario(
            "hexapod-async-move",
            "Rubin camera hexapod, 3 t camera: asynchronous move of ~2.6 mm and 0.1 deg, each strut at its own minimum time (--elevation, --wind)",
            hexapod.build_async,
            lambda: hexapod.plan(False),
            **HEXAPOD_RUN,
        ),
        Scenario(
            "antenna-paper-motion",
            "ship antenna, 4 axes: the paper's extreme ship motion (pitch 40 deg/8 s, roll 45 deg/10 s, 1 deg/s turn), IMU at 50 Hz, CRR planner, 60 s (--imu-rate, --imu-latency, --no-prediction)",
            antenna.build_paper_motion,
            antenna.plan_paper_motion,
            options=frozenset({"imu"}),
            kinds=antenna.joint_kinds,
            plan_extras=antenna.write_method_comparison,
            control_dt=antenna.CONTROL_DT,
            validate=antenna.validate_paper_motion,
            online_planner=True,
        ),
        Scenario(
            "antenna-sea-state",
            "ship antenna, 4 axes: JONSWAP sea Hs 5 m, Tp 10 s, waves 135 deg off the bow, holding a GEO satellite at 15 W from 40 N 20 W, 300 s (--hs, --tp, --heading, --imu-rate, --imu-latency, --no-prediction)",
            antenna.build_sea_state,
            antenna.plan_sea_state,
            options=frozenset({"hs", "tp", "heading", "imu"}),
            kinds=antenna.joint_kinds,
            control_dt=antenna.CONTROL_DT,
            validate=antenna.validate_sea_state,
            online_planner=True,
        ),
        Scenario(
            "fast-tracking",
            "FAST feed support: park -> 3C 286 (line + focal arc), start, 20 min of tracking across its transit, termination; cables, A-B rotator, Stewart stabilizer under wind (--wind, --wind-direction, --stewart on|off, --cable-segments)",
            fast.build_tracking,
            fast.tracking_plan,
            **FAST_RUN,
            demo_cameras=("closeup",),
        ),
        Scenario(
            "fast-ra-scan",
            "FAST feed support: the paper's motion scan along RA around 3C 286 (4 legs along Dec at 15 deg/h, transitions of the shortest t2 under A_t-max) under wind (--wind, --wind-direction, --stewart on|off, --cable-segments)",
            fast.build_ra_scan,
            fast.ra_scan_plan,
            **FAST_RUN,
        ),
        Scenario(
            "fast-source-switch",
            "FAST feed support: park -> 3C 286, 5 min of tracking, focal-arc switch to 3C 295, 5 min of tracking, under wind (--wind, --wind-direction, --stewart on|off, --cable-segments)",
            fast.build_source_switch,
            fast.source_switch_plan,
            **FAST_RUN,
        ),
    )
}


def get(name: str) -> Scenario:
    """The scenario called ``name``; a ValueError lists the known names otherwise."""
    try:
        return SCENARIOS[name]
    except KeyError:
        raise ValueError(
            f"unknown scenario {name!r}; known: {', '.join(SCENARIOS)}"
        ) from None


#: Plans with no run of their own (``planbench plan`` only).
PLANS: dict[str, Scenario] = {
    s.name: s
    for s in (
        Scenario(
            "fast-dec-scan",
            "FAST feed: the paper's motion scan along Dec around 3C 286: 3 legs along RA at 5 deg/h, transitions, beside the paper's eq. 15-20",
            None,
            fast.dec_scan_plan,
            kinds=fast.plan_kinds,
            plan_extras=fast.write_figures,
        ),
    )
}


def get_plan(name: str) -> Scenario:
    """A scenario or a plan-only entry called ``name`` (``planbench plan``)."""
    if name in PLANS:
        return PLANS[name]
    try:
        return get(name)
    except ValueError:
        raise ValueError(f"unknown scenario {name!r}; known: {', '.join([*SCENARIOS, *PLANS])}") from None
