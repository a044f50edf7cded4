"""The loader's task: the planning problem (key points at uniform times), the evaluation (checks,
timeseries, report), the build of a run's Setup, and the environment's reward."""

from __future__ import annotations

import numpy as np

from planbench import models, run_limits
from planbench.checks import Check
from planbench.controllers import demanded_force
from planbench.loader.collision import clearance, obstacle_contact_pairs
from planbench.loader.controller import reference_controller
from planbench.loader.params import CONTROL_DT, LoaderParams, LoaderPlant
from planbench.loader.physics import LoaderPhysics, _joint_dofs, plant_chain
from planbench.loader.sensors import sensors
from planbench.planners import loader as loader_planner
from planbench.planners.loader import forward_kinematics
from planbench.runner import RunLog, Setup
from planbench.task import Components, Provenance, Task, nominal_copy, plan_checked

#: Check limits. 0.1 deg at the key points is 3.8 mm at the 2.2 m reach of the shell tip, a
#: small fraction of the 6 cm by which the planned path clears the obstacles; the run-wide
#: tracking limit allows 0.25 deg (9.6 mm at the tip) while the arm accelerates.
KEYPOINT_LIMIT_DEG = 0.1
TRACKING_LIMIT_DEG = 0.25


class LoaderEvaluation:
    """Checks and outputs of a loader run (keypoints are Table 1's, in SI units)."""

    def __init__(
        self, physics: LoaderPhysics, key_times: np.ndarray, key_points: np.ndarray, plant: LoaderPlant | None = None
    ):
        self.physics = physics
        self.spec = models.loader_spec()
        self.key_times = np.asarray(key_times)
        self.key_points = np.asarray(key_points)
        self._clearance = None
        # The plant's drives and kinematics (equal to the nominal ones for the nominal plant):
        # a weaker drive saturates at its own limit, which the joint_torque check judges.
        model = physics.model.ptr
        drives = [model.actuator(n).id for n in self.spec.names]
        self.kp = model.actuator_gainprm[drives, 0].copy()
        self.kv = -model.actuator_biasprm[drives, 2].copy()
        self.force_limit = model.actuator_forcerange[drives, 1].copy()
        plant = LoaderPlant() if plant is None else plant
        self.chain = plant_chain(plant)
        self.encoder_bias = plant.encoder_bias_si()

    def _demanded(self, log: RunLog) -> np.ndarray:
        """(n, 6) force/torque the drives demand before their clamp, N and N m: their PD on
        what their encoders read (the motors' coordinates as built, the joints' with the ideal
        drives, plus the encoder bias)."""
        q, qd = log.qpos[:, self.physics.drive_qpos], log.qvel[:, self.physics.drive_dofs]
        q_drive = q + self.encoder_bias if self.encoder_bias.any() else q
        return demanded_force(self.kp, self.kv, log.act, q_drive, qd)

    def clearance(self, log: RunLog):
        if self._clearance is None or self._clearance[0] is not log:
            c, pairs = clearance(
                self.physics.model.ptr, log.qpos, self.physics.robot_geoms(), self.physics.obstacle_geoms()
            )
            self._clearance = (log, c, pairs)
        return self._clearance[1], self._clearance[2]

    def _shell_tip(self, log: RunLog) -> np.ndarray:
        """Shell nose position (m) at every logged tick, from the logged joint positions."""
        q, _ = self._joint_log(log)
        return forward_kinematics(q, ["shell_tip"], spec=self.chain)["shell_tip"]

    def _joint_log(self, log: RunLog):
        dofs = _joint_dofs(self.physics)
        return log.qpos[:, dofs], log.qvel[:, dofs]

    def evaluate(self, log: RunLog):
        model = self.physics.model.ptr
        q, qd = self._joint_log(log)
        ref = log.reference.position
        err = q - ref
        err_deg = np.rad2deg(np.abs(err[:, 1:]))
        # Key times that the run reached: nearest logged tick (key times are tick multiples).
        reached = self.key_times <= log.t[-1] + 1e-9
        ticks = np.searchsorted(log.t, self.key_times[reached] - 1e-9)
        key_err_deg = np.rad2deg(np.abs(q[ticks, 1:] - self.key_points[reached, 1:]))
        key_err_slide_mm = 1e3 * np.abs(q[ticks, 0] - self.key_points[reached, 0])
        tau = self._demanded(log)
        torque_ratio = np.abs(tau) / self.force_limit
        robot, obstacles = self.physics.robot_geoms(), self.physics.obstacle_geoms()
        pairs = obstacle_contact_pairs(log.contacts, robot, obstacles)
        clear, closest = self.clearance(log)
        i_min = int(np.argmin(clear))

        def names(pair):
            return f"{model.geom(int(pair[0])).name}/{model.geom(int(pair[1])).name}"

        contact_note = ", ".join(
            f"{names(p)} from t = {log.t[v[0]]:.3f} s for {v[1]} ticks, {1e3 * v[2]:.1f} mm deep"
            for p, v in sorted(pairs.items(), key=lambda kv: kv[1][0])
        )
        reached_note = f"{int(reached.sum())} of {self.key_times.size} key points reached"
        checks = [
            Check("keypoint_error", float(key_err_deg.max()), KEYPOINT_LIMIT_DEG, "deg", note=reached_note)
            if key_err_deg.size
            else Check.not_evaluated(
                "keypoint_error",
                KEYPOINT_LIMIT_DEG,
                "deg",
                reason=f"the run ended at t = {log.t[-1]:.3f} s, before the first "
                f"key point (t = {self.key_times.min():.3f} s)",
            ),
            Check("tracking_error", float(err_deg.max()), TRACKING_LIMIT_DEG, "deg"),
            Check("obstacle_contacts", len(pairs), 0, "count", "==", note=contact_note),
            Check(
                "min_clearance",
                float(clear[i_min]),
                0.0,
                "m",
                ">",
                note=f"{names(closest[i_min])} at t = {log.t[i_min]:.3f} s"
                if closest[i_min, 0] >= 0
                else "nothing within 0.5 m",
            ),
            Check(
                "joint_torque",
                float(torque_ratio.max()),
                1.0,
                "ratio",
                note=f"peak on {self.spec.names[int(np.argmax(torque_ratio.max(0)))]}",
            ),
        ]
        metrics = {
            "keypoint_error_slide_mm": float(key_err_slide_mm.max()) if key_err_slide_mm.size else None,
            "tracking_error_slide_mm": float(1e3 * np.abs(err[:, 0]).max()),
            "tracking_error_deg_per_joint": dict(
                zip(self.spec.names[1:], err_deg.max(0).round(6).tolist(), strict=True)
            ),
            "peak_torque_per_joint": dict(zip(self.spec.names, np.abs(tau).max(0).round(3).tolist(), strict=True)),
            "torque_limit_per_joint": dict(zip(self.spec.names, self.force_limit.tolist(), strict=True)),
            "final_shell_tip_m": self._shell_tip(log)[-1].tolist(),
            "contact_ticks": int(sum(v[1] for v in pairs.values())),
        }
        return checks, metrics

    def timeseries(self, log: RunLog) -> dict:
        q, qd = self._joint_log(log)
        clear, _ = self.clearance(log)
        return {
            "joint_names": np.array(self.spec.names),
            "q_planned": log.reference.position,
            "qd_planned": log.reference.velocity,
            "qdd_planned": log.reference.acceleration,
            "q_actual": q,
            "qd_actual": qd,
            "setpoint": log.act,
            "drive_force": log.actuator_force,
            "drive_force_demanded": self._demanded(log),
            "drive_force_limit": self.force_limit,
            "shell_tip_pos": self._shell_tip(log),
            "clearance": clear,
            "key_times": self.key_times,
            "key_points": self.key_points,
        }

    def report(self, log: RunLog, checks, path) -> None:
        from planbench.loader.report import loader_report  # lazy: matplotlib, only when a report is drawn

        loader_report(self.timeseries(log), log.t, checks, path)


def problem(params: LoaderParams) -> loader_planner.LoaderProblem:
    """The run's planning problem: the key points at uniform times, the model's limits."""
    points = loader_planner.table1_to_si(np.array(params.key_points))
    times = np.arange(len(points)) * params.key_interval
    spec = models.loader_spec()
    return loader_planner.LoaderProblem(
        times, points, tuple(spec.names), spec.lower, spec.upper, spec.rate_limit, spec.force_limit
    )


def plan(params: LoaderParams):
    """The paper's cubic B-spline through the run's key points (``planbench plan``)."""
    return loader_planner.CubicBSplinePlanner().plan(problem(params))


def build(params: LoaderParams, planner=None, controller=None, plant: LoaderPlant | None = None) -> Setup:
    """A loader run: ``planner`` (default the paper's cubic B-spline) plans the key points,
    ``controller`` (default ``reference_controller()``) follows it from the first key point, at
    rest; the checks judge the key points, the obstacles and the drive limits.

    ``plant`` (None: the nominal plant) perturbs the simulated machine only: the planner and
    the controller keep the nominal model (``Task.nominal_physics``). The plant starts at
    rest where its encoders read the first key point, i.e. at key_points[0] - encoder bias
    (the controller sees only the encoders); the checks judge its true joints.
    """
    plant = LoaderPlant() if plant is None else plant
    plant.check_drives(params.drives)
    task = problem(params)
    planner = loader_planner.CubicBSplinePlanner() if planner is None else planner
    trajectory = plan_checked(planner, task, task.labels)
    duration = params.duration if params.duration is not None else trajectory.duration + params.settle
    run_limits.check_duration(duration, CONTROL_DT, params.log_bytes_per_tick())
    physics = LoaderPhysics.load(params.payload_mass, plant, params.drives)
    bias = plant.encoder_bias_si()
    physics.set_start(task.key_points[0] - bias if bias.any() else task.key_points[0])
    nominal_physics = None  # the nominal plant: a copy of the physics, as it is now
    if not plant.is_nominal:
        nominal = LoaderPhysics.load(params.payload_mass, drives=params.drives)
        nominal.set_start(task.key_points[0])
        nominal_physics = nominal_copy(nominal)
    evaluation = LoaderEvaluation(physics, task.key_times, task.key_points, plant)
    return Setup(
        physics,
        Task(
            problem=task,
            sensors=sensors(physics, bias),
            evaluation=evaluation,
            control_dt=CONTROL_DT,
            duration=duration,
            nominal_physics=nominal_physics,
        ),
        Components(
            planner=planner,
            trajectory=trajectory,
            controller=reference_controller() if controller is None else controller,
        ),
        provenance=Provenance(seed=params.seed, params=params, plant=plant),
    )


def environment_reward(setup: Setup):
    """The dm_control reward: exp(-max joint tracking error / 0.1 deg)."""
    # Lazy: planbench.envs loads dm_control.suite (about a second), needed only by the environments.
    from planbench.envs import joint_tracking_reward

    physics = setup.physics
    return joint_tracking_reward(
        physics.model.ptr.jnt_qposadr[[physics.model.ptr.joint(n).id for n in physics.joint_names]], np.deg2rad(0.1)
    )
