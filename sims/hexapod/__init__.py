"""The Rubin camera hexapod in MuJoCo: physics accessors, the strut controller, scenarios.

Scenarios:
  hexapod-sync-move   a move of a few mm and ~0.1 deg, every strut arriving on the same tick
  hexapod-async-move  another such move, each strut at its own minimum time
both named defaults of ``HexapodParams``: a start pose and a list of moves, each synchronous
or not, the telescope's elevation (15 ... 90 deg: gravity's direction in the hexapod frame) and
the wind (turbulent drag on the camera).

The hexapod frame is the model's body ``top_end`` (models/hexapod/hexapod.xml); the model is
recompiled per elevation with the top end tilted (MjSpec), so gravity stays the world's -z.
Plant uncertainty (``HexapodPlant``: camera mass and centre of mass, pivot circles, drive
stiffness and force limit, encoder bias) perturbs the simulated hexapod only (``build(...,
plant=)``, models/hexapod/README.md "Plant uncertainty").

The package: sims/hexapod/physics.py (the scene per elevation, the plant edits, ``HexapodPhysics``),
sims/hexapod/params.py (``HexapodParams``, ``HexapodMove``, ``HexapodPlant``),
sims/hexapod/sensors.py (the strut encoders), sims/hexapod/controller.py (``HexapodController``),
sims/hexapod/task.py (the moves, the wind, ``HexapodEvaluation``, ``build``, the reward),
sims/hexapod/plan_checks.py (the planner-only checks); this module re-exports their public names
and declares the mechanism's record.
"""

from __future__ import annotations

from planbench.hexapod import plan_columns
from planbench.hexapod.controller import INTEGRAL_TIME_S, HexapodController
from planbench.hexapod.params import (
    ASYNC_TARGET_MM_DEG,
    CONTROL_DT,
    DEFAULT_WIND_M_S,
    SETTLE_S,
    SYNC_TARGET_MM_DEG,
    HexapodMove,
    HexapodParams,
    HexapodPlant,
    pose_mm_deg,
    pose_si,
)
from planbench.hexapod.physics import (
    DEFAULT_ELEVATION_DEG,
    ELEVATION_RANGE_DEG,
    PLATFORM_KEY_QPOS,
    HexapodPhysics,
    apply_plant,
    check_elevation,
    log_bytes_per_tick,
    magnified_qpos,
    top_end_rotation,
)
from planbench.hexapod.plan_checks import judge_plans
from planbench.hexapod.sensors import sensors
from planbench.hexapod.task import (
    ARRIVAL_SPREAD_LIMIT_S,
    ARRIVAL_TOLERANCE,
    ARRIVAL_ULPS,
    CAMERA_DRAG_COEFFICIENT,
    ENCODER_COUNT_M,
    ENCODER_SETTLE_M,
    FOLLOWING_LIMIT_UM,
    OWN_TIME_LIMIT_S,
    POSE_FINAL_LIMIT_UM,
    SETTLE_WINDOW_S,
    STRUT_MOVE_THRESHOLD_M,
    VIDEO_MAGNIFICATION,
    WIND_AZIMUTH_DEG,
    HexapodEvaluation,
    arrival_times,
    build,
    camera_area,
    default_duration,
    end_tick,
    environment_reward,
    hexapod_speed_check,
    plan,
    plan_moves,
    problems,
    strut_kinds,
    strut_tolerances,
)
from planbench.planners.hexapod import STRUT_LABELS
from planbench.scenarios import BENCHMARK, DEMO, Mechanism, Scenario
from planbench.wind import horizontal_direction

_RUN = dict(
    build=build,
    plan=plan,
    kinds=strut_kinds,
    control_dt=CONTROL_DT,
    plant=HexapodPlant(),
    judge_plans=judge_plans,
    plan_columns=plan_columns,
)

SCENARIOS = (
    Scenario(
        "hexapod-sync-move",
        "Rubin camera hexapod, 3 t camera: synchronous move of ~2 mm and 0.1 deg, all six struts arrive on one tick",
        HexapodParams(moves=(HexapodMove(SYNC_TARGET_MM_DEG, True),)),
        **_RUN,
        tags=(DEMO, BENCHMARK),
    ),
    Scenario(
        "hexapod-async-move",
        "Rubin camera hexapod, 3 t camera: asynchronous move of ~2.6 mm and 0.1 deg, each strut at "
        "its own minimum time",
        HexapodParams(moves=(HexapodMove(ASYNC_TARGET_MM_DEG, False),)),
        **_RUN,
    ),
)


MECHANISM = Mechanism("hexapod", SCENARIOS, environment_reward, benchmark_runs=5)

__all__ = [
    "ARRIVAL_SPREAD_LIMIT_S",
    "ARRIVAL_TOLERANCE",
    "ARRIVAL_ULPS",
    "ASYNC_TARGET_MM_DEG",
    "CAMERA_DRAG_COEFFICIENT",
    "CONTROL_DT",
    "DEFAULT_ELEVATION_DEG",
    "DEFAULT_WIND_M_S",
    "ELEVATION_RANGE_DEG",
    "ENCODER_COUNT_M",
    "ENCODER_SETTLE_M",
    "FOLLOWING_LIMIT_UM",
    "HexapodController",
    "HexapodEvaluation",
    "HexapodMove",
    "HexapodParams",
    "HexapodPhysics",
    "HexapodPlant",
    "INTEGRAL_TIME_S",
    "MECHANISM",
    "OWN_TIME_LIMIT_S",
    "PLATFORM_KEY_QPOS",
    "POSE_FINAL_LIMIT_UM",
    "SCENARIOS",
    "SETTLE_S",
    "SETTLE_WINDOW_S",
    "STRUT_LABELS",
    "STRUT_MOVE_THRESHOLD_M",
    "SYNC_TARGET_MM_DEG",
    "VIDEO_MAGNIFICATION",
    "WIND_AZIMUTH_DEG",
    "apply_plant",
    "arrival_times",
    "build",
    "camera_area",
    "check_elevation",
    "default_duration",
    "end_tick",
    "environment_reward",
    "hexapod_speed_check",
    "horizontal_direction",
    "judge_plans",
    "log_bytes_per_tick",
    "magnified_qpos",
    "plan",
    "plan_columns",
    "plan_moves",
    "pose_mm_deg",
    "pose_si",
    "problems",
    "sensors",
    "strut_kinds",
    "strut_tolerances",
    "top_end_rotation",
]
