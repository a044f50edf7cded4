"""The PRR-3R ammunition loader in MuJoCo: physics accessors, scenarios, checks, report.

Scenarios:
  loader-supply  Table 1's key points through the cubic B-spline (the paper's supply stage).
  loader-direct  P2 to P3 as one straight joint-space move in the same time; it strikes the
                 breechblock and the seat ring, which is why the paper adds M1 ... M4.

Plant uncertainty (``LoaderPlant``: shell and link masses, upper-arm length, joint friction,
drive force limits, encoder bias) perturbs the simulated loader only (``build(..., plant=)``,
models/loader/README.md "Plant uncertainty").

Modules: sims/loader/params.py (``LoaderParams``, ``LoaderPlant``), sims/loader/physics.py
(``LoaderPhysics``, ``apply_plant``), sims/loader/sensors.py (the encoders),
sims/loader/controller.py (``reference_controller``), sims/loader/task.py (the problem, the
evaluation, ``build``, the reward), sims/loader/collision.py (contacts and clearances),
sims/loader/plan_checks.py (planner-only checks), sims/loader/report.py (report.png).
"""

from __future__ import annotations

from planbench.loader.controller import reference_controller
from planbench.loader.params import CONTROL_DT, SETTLE_S, LoaderParams, LoaderPlant, log_bytes_per_tick
from planbench.loader.physics import (
    ARM_BODIES,
    OBSTACLE_CONTYPE,
    ROBOT_CONTYPE,
    LoaderPhysics,
    apply_plant,
    joint_kinds,
    plant_chain,
    shell_mass,
)
from planbench.loader.plan_checks import judge_plans
from planbench.loader.task import (
    KEYPOINT_LIMIT_DEG,
    TRACKING_LIMIT_DEG,
    LoaderEvaluation,
    build,
    environment_reward,
    plan,
    problem,
)
from planbench.planners import loader as loader_planner
from planbench.scenarios import BENCHMARK, DEMO, Mechanism, Scenario

_RUN = dict(
    build=build, plan=plan, kinds=joint_kinds, control_dt=CONTROL_DT, plant=LoaderPlant(), judge_plans=judge_plans
)

SCENARIOS = (
    Scenario(
        "loader-supply",
        "PRR-3R loader: Table 1 key points P2, M1-M4, P3 through the cubic B-spline, past the "
        "breechblock and seat ring",
        LoaderParams(),
        **_RUN,
        tags=(DEMO, BENCHMARK),
    ),
    Scenario(
        "loader-direct",
        "PRR-3R loader: P2 to P3 as a straight joint-space move in the same 2.5 s; strikes the "
        "obstacles (expected to fail)",
        # The key points checked are the endpoints; M1 ... M4 are not in this problem.
        LoaderParams(key_points=LoaderParams().key_points[::5], key_interval=2.5),
        expect_pass=False,
        **_RUN,
    ),
)


MECHANISM = Mechanism("loader", SCENARIOS, environment_reward, benchmark_runs=5)

__all__ = [
    "ARM_BODIES",
    "CONTROL_DT",
    "KEYPOINT_LIMIT_DEG",
    "LoaderEvaluation",
    "LoaderParams",
    "LoaderPhysics",
    "LoaderPlant",
    "MECHANISM",
    "OBSTACLE_CONTYPE",
    "ROBOT_CONTYPE",
    "SCENARIOS",
    "SETTLE_S",
    "TRACKING_LIMIT_DEG",
    "apply_plant",
    "build",
    "environment_reward",
    "joint_kinds",
    "judge_plans",
    "loader_planner",
    "log_bytes_per_tick",
    "plan",
    "plant_chain",
    "problem",
    "reference_controller",
    "shell_mass",
]
