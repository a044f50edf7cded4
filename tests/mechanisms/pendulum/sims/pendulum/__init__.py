"""A one-joint pendulum in MuJoCo: planbench's smallest mechanism, for its tests.

Scenario:
  pendulum-swing  swing the bob from hanging (0 rad) to ``goal`` in ``move_time`` and hold it
                  there; judged by its arrival at rest within 0.5 mrad and its torque.

Everything of the mechanism is in its own folders: models/pendulum/ (the MJCF and its
README.md with every number), planners/pendulum/ (the quintic planner) and this package.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from dm_control import mujoco as dm_mujoco

from planbench import models, run_limits
from planbench.checks import Check
from planbench.controllers import ServoFeedforwardController, demanded_force
from planbench.envs import joint_tracking_reward
from planbench.params import ScenarioParams, param
from planbench.planners import pendulum as pendulum_planner
from planbench.runner import RunLog, Setup
from planbench.scenarios import BENCHMARK, DEMO, Mechanism, Scenario
from planbench.task import Components, JointEncoders, Provenance, Task, plan_checked

CONTROL_DT = 0.005  # s: 200 Hz; five 1 ms physics steps a tick
#: Arrival: within this of the goal (rad) and this slow (rad/s) over the last ARRIVAL_S.
ARRIVAL_ERROR_RAD = 5e-4
ARRIVAL_RATE_RAD_S = 5e-3
ARRIVAL_S = 0.2


class PendulumPhysics(dm_mujoco.Physics):
    """dm_control Physics of models/pendulum/scene.xml."""

    @classmethod
    def load(cls) -> PendulumPhysics:
        physics = cls.from_xml_path(str(models.scene_path("pendulum")))
        physics.reset(keyframe_id=0)
        return physics

    @property
    def swing_qpos(self) -> int:
        return int(self.model.ptr.joint("swing").qposadr[0])

    @property
    def swing_dof(self) -> int:
        return int(self.model.ptr.joint("swing").dofadr[0])

    def set_start(self, angle: float) -> None:
        """At rest at ``angle`` (rad), the drive's set-point there."""
        data = self.data.ptr
        data.qpos[self.swing_qpos] = angle
        data.qvel[:] = 0.0
        data.act[self.model.ptr.actuator("swing").actadr[0]] = angle
        self.forward()


@functools.lru_cache(maxsize=1)
def log_bytes_per_tick() -> float:
    """Bytes a swing preallocates per control tick: the runner's log of the compiled model
    (one planned channel) and the servo controller's set-point and feed-forward torque."""
    return run_limits.floats(run_limits.runlog_floats_per_tick(models.load("pendulum"), 1) + 2)


@dataclass(frozen=True)
class PendulumParams(ScenarioParams):
    """A swing: its goal, its time, the hold after it."""

    goal: float = param(
        1.2,
        "goal angle from hanging",
        "rad",
        low=-2.5,
        high=2.5,
        reason="inside the hinge's +/-3 rad range with margin",
    )
    move_time: float = param(
        1.0,
        "time of the swing",
        "s",
        low=0.2,
        high=60.0,
        reason="faster than 0.2 s the swing needs more than the 40 N m drive",
    )
    hold: float = param(
        0.8,
        "time simulated at the goal after the swing",
        "s",
        low=ARRIVAL_S,
        high=60.0,
        reason="at least the arrival window",
    )

    def check(self) -> None:
        run_limits.check_duration(self.move_time + self.hold, CONTROL_DT, self.log_bytes_per_tick())

    def log_bytes_per_tick(self) -> float:
        return log_bytes_per_tick()


class PendulumEvaluation:
    """Checks of a swing: arrival at rest at the goal, tracking, the drive's torque."""

    def __init__(self, physics: PendulumPhysics, goal: float, arrive_by: float):
        model = physics.model.ptr
        drive = model.actuator("swing").id
        self.qpos, self.dof = physics.swing_qpos, physics.swing_dof
        self.goal, self.arrive_by = goal, arrive_by
        self.kp = model.actuator_gainprm[[drive], 0].copy()
        self.kv = -model.actuator_biasprm[[drive], 2].copy()
        self.force_limit = float(model.actuator_forcerange[drive, 1])

    def evaluate(self, log: RunLog):
        q, qd = log.qpos[:, self.qpos], log.qvel[:, self.dof]
        window = log.t >= self.arrive_by - 1e-9
        torque = np.abs(demanded_force(self.kp, self.kv, log.act, q[:, None], qd[:, None]))[:, 0]
        if window.any():
            arrival = Check("arrival_error", float(np.abs(q[window] - self.goal).max()), ARRIVAL_ERROR_RAD, "rad")
            rest = Check("arrival_rate", float(np.abs(qd[window]).max()), ARRIVAL_RATE_RAD_S, "rad/s")
        else:
            reason = f"the run ended at t = {log.t[-1]:.3f} s, before the arrival window ({self.arrive_by:.3f} s)"
            arrival = Check.not_evaluated("arrival_error", ARRIVAL_ERROR_RAD, "rad", reason=reason)
            rest = Check.not_evaluated("arrival_rate", ARRIVAL_RATE_RAD_S, "rad/s", reason=reason)
        checks = [arrival, rest, Check("drive_torque", float(torque.max() / self.force_limit), 1.0, "ratio")]
        metrics = {"tracking_error_rad": float(np.abs(q - log.reference.position[:, 0]).max())}
        return checks, metrics

    def timeseries(self, log: RunLog) -> dict:
        return {
            "q_planned": log.reference.position[:, 0],
            "q_actual": log.qpos[:, self.qpos],
            "drive_torque": log.actuator_force[:, 0],
        }

    def report(self, log: RunLog, checks, path) -> None:
        from planbench.report import finish, plt

        ts = self.timeseries(log)
        fig, axes = plt.subplots(1, 2, figsize=(10, 4))
        axes[0].plot(log.t, ts["q_actual"], label="simulated")
        axes[0].plot(log.t, ts["q_planned"], "--", label="planned")
        axes[0].set(title="swing angle", xlabel="t [s]", ylabel="rad")
        axes[0].legend(fontsize=8)
        axes[1].plot(log.t, ts["drive_torque"])
        axes[1].set(title="drive torque", xlabel="t [s]", ylabel="N m")
        finish(fig, axes, axes[1], checks, path, top=True)


def problem(params: PendulumParams) -> pendulum_planner.SwingProblem:
    return pendulum_planner.SwingProblem(0.0, params.goal, params.move_time)


def plan(params: PendulumParams):
    """The quintic swing (``planbench plan``)."""
    return pendulum_planner.QuinticPlanner().plan(problem(params))


def build(params: PendulumParams, planner=None, controller=None, plant=None) -> Setup:
    """A swing: ``planner`` (default the quintic) plans it, ``controller`` (default the servo
    with inverse-dynamics feed-forward) follows it through the drive's encoder."""
    swing = problem(params)
    planner = pendulum_planner.QuinticPlanner() if planner is None else planner
    trajectory = plan_checked(planner, swing, swing.labels)
    physics = PendulumPhysics.load()
    physics.set_start(swing.start)
    model = physics.model.ptr
    actuator = model.actuator("swing")
    sensors = JointEncoders(
        [physics.swing_qpos],
        [physics.swing_dof],
        [actuator.actadr[0]],
        "encoder of the swing joint (rad)",
        "rad",
        CONTROL_DT,
    )
    duration = trajectory.duration + params.hold
    evaluation = PendulumEvaluation(physics, params.goal, duration - ARRIVAL_S)
    return Setup(
        physics,
        Task(problem=swing, sensors=sensors, evaluation=evaluation, control_dt=CONTROL_DT, duration=duration),
        Components(
            planner=planner,
            trajectory=trajectory,
            controller=ServoFeedforwardController() if controller is None else controller,
        ),
        provenance=Provenance(seed=params.seed, params=params),
    )


def environment_reward(setup: Setup):
    """The dm_control reward: exp(-|q - q_ref| / 0.01 rad)."""
    return joint_tracking_reward([setup.physics.swing_qpos], 0.01)


SCENARIOS = (
    Scenario(
        "pendulum-swing",
        "one-joint pendulum: a quintic swing from hanging to the goal, held there",
        PendulumParams(),
        build=build,
        plan=plan,
        kinds=lambda: ["hinge"],
        control_dt=CONTROL_DT,
        tags=(DEMO, BENCHMARK),
    ),
)

MECHANISM = Mechanism("pendulum", SCENARIOS, environment_reward, benchmark_runs=1)
