"""The PRR-3R ammunition loader in MuJoCo: physics accessors, scenarios, checks, report.

Scenarios:
  loader-supply  Table 1's key points through the cubic B-spline (the paper's supply stage).
  loader-direct  P2 to P3 as one straight joint-space move in the same time; it strikes the
                 breechblock and the seat ring, which is why the paper adds M1 ... M4.

Plant uncertainty (``LoaderPlant``: shell and link masses, upper-arm length, joint friction,
drive force limits, encoder bias) perturbs the simulated loader only (``build(..., plant=)``,
models/loader/README.md "Plant uncertainty").
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass

import mujoco
import numpy as np
from dm_control import mujoco as dm_mujoco

import models
from planners import loader as loader_planner
from planners.loader import forward_kinematics
from sims import run_limits
from sims.checks import Check
from sims.loader.collision import clearance, geoms_by_contype, obstacle_contact_pairs
from sims.controllers import ServoFeedforwardController, demanded_force
from sims.runner import RunLog, Setup
from sims.params import PlantParams, ScenarioParams, param
from sims.plant import set_inertial
from sims.task import Components, JointEncoders, Provenance, Task, nominal_copy, plan_checked

#: Robot collision geoms have contype 1, obstacles (breechblock, seat ring, floor) contype 2.
ROBOT_CONTYPE = 1
OBSTACLE_CONTYPE = 2

CONTROL_DT = 0.005  # s: 200 Hz motion controller; the drives run at the 0.5 ms physics step
SETTLE_S = 0.5  # s simulated after the plan ends, so the arrival is seen at rest

#: Check limits. 0.1 deg at the key points is 3.8 mm at the 2.2 m reach of the shell tip, a
#: small fraction of the 6 cm by which the planned path clears the obstacles; the run-wide
#: tracking limit allows 0.25 deg (9.6 mm at the tip) while the arm accelerates.
KEYPOINT_LIMIT_DEG = 0.1
TRACKING_LIMIT_DEG = 0.25


class LoaderPhysics(dm_mujoco.Physics):
    """dm_control Physics of models/loader/scene.xml with readable accessors."""

    @classmethod
    def load(cls, payload_mass: float = None, plant: "LoaderPlant | None" = None) -> "LoaderPhysics":
        """The scene at its home keyframe; ``payload_mass`` (kg, None: the model's 45 kg) scales
        the shell's geoms' masses, so its inertia scales with them (same shape and density
        distribution), edited with MjSpec before compiling. ``plant`` (None: the nominal
        plant): the true machine, perturbed as ``LoaderPlant`` says (``apply_plant``); its
        ``payload_mass_error`` makes the shell's true mass payload_mass (1 + error)."""
        nominal = plant is None or plant.is_nominal
        if nominal and (payload_mass is None or payload_mass == shell_mass()):
            physics = cls.from_xml_path(str(models.scene_path("loader")))
        else:
            spec = mujoco.MjSpec.from_file(str(models.scene_path("loader")))
            mass = shell_mass() if payload_mass is None else payload_mass
            if not nominal:
                mass = mass * (1.0 + plant.payload_mass_error)
            factor = mass / shell_mass()
            if factor != 1.0:
                for geom in spec.body("shell").find_all(mujoco.mjtObj.mjOBJ_GEOM):
                    geom.mass = geom.mass * factor
            if not nominal:
                apply_plant(spec, plant)
            physics = cls.from_model(dm_mujoco.wrapper.MjModel(spec.compile()))
        physics.reset(keyframe_id=0)
        return physics

    def set_start(self, q: np.ndarray) -> None:
        """Joints and the drives' set-points at ``q`` (theta1 m, theta2 ... theta6 rad), at rest."""
        self.named.data.qpos[self.joint_names] = q
        self.named.data.qvel[self.joint_names] = 0.0
        self.data.act[:] = q
        self.forward()

    @property
    def joint_names(self) -> list[str]:
        return models.loader_spec().names

    def joint_positions(self) -> np.ndarray:
        """theta1 ... theta6: slide (m) and five angles (rad)."""
        return self.named.data.qpos[self.joint_names].copy()

    def joint_velocities(self) -> np.ndarray:
        return self.named.data.qvel[self.joint_names].copy()

    def setpoints(self) -> np.ndarray:
        """The drives' position set-points (their activations), m and rad."""
        return self.data.act.copy()

    def actuator_forces(self) -> np.ndarray:
        """Drive force (N) and torques (N m) after the force-range clamp."""
        return self.named.data.actuator_force[self.joint_names].copy()

    def shell_tip(self) -> np.ndarray:
        """World position of the shell's nose, m."""
        return self.named.data.site_xpos["shell_tip"].copy()

    def shell_tip_log(self, sensordata: np.ndarray) -> np.ndarray:
        """The ``shell_tip_pos`` sensor's columns of a logged sensordata array, m.

        MuJoCo evaluates sensors before integrating, so after ``mj_step`` they describe the
        state one physics step (0.5 ms) before the logged qpos.
        """
        sensor = self.model.ptr.sensor("shell_tip_pos")
        return sensordata[:, sensor.adr[0] : sensor.adr[0] + sensor.dim[0]]

    def robot_geoms(self) -> np.ndarray:
        return geoms_by_contype(self.model.ptr, ROBOT_CONTYPE)

    def obstacle_geoms(self) -> np.ndarray:
        return geoms_by_contype(self.model.ptr, OBSTACLE_CONTYPE)


def joint_kinds() -> list[str]:
    return [j.kind for j in models.loader_spec().joints]


@functools.lru_cache(maxsize=1)
def shell_mass() -> float:
    """The model's shell (the payload body ``shell``), kg."""
    model = models.load("loader")
    return float(model.body_mass[model.body("shell").id])


def _joint_dofs(physics: LoaderPhysics) -> np.ndarray:
    model = physics.model.ptr
    return np.array([model.joint(n).dofadr[0] for n in physics.joint_names])


#: The arm's links, carriage to gripper: the bodies whose geoms' masses ``arm_mass_error``
#: scales (the shell is the payload, ``payload_mass_error``).
ARM_BODIES = ("carriage", "upper_arm", "forearm", "wrist_pitch_link", "wrist_yaw_link", "gripper")


def apply_plant(spec: mujoco.MjSpec, plant: "LoaderPlant") -> None:
    """Edit the loader's MjSpec into the plant ``plant`` (all but the payload's mass, which
    ``LoaderPhysics.load`` scales). Each edit touches only its own elements:

    * arm_mass_error: the mass and inertia of every body of ``ARM_BODIES`` times (1 + error),
      its centre of mass and principal axes kept (``sims.plant.set_inertial``);
    * upper_arm_length_error: the elbow axis (body ``forearm``) moved along the upper arm, m
      (the beam's geom and mass are left: a bore position error, not another beam);
    * joint_viscous_friction: each joint's damping (N s/m, N m s/rad) = fraction x its drive's
      rated force / rated speed, so the friction at rated speed is that fraction of the rating;
    * drive_force_scale: every drive's force range times the scale;
    * encoder_bias: the drives close their loop on the biased encoder, so the drive force is
      kp (set-point - (q + b)) - kv qdot: affine bias term biasprm[0] = -kp b.
    """
    chain = models.loader_spec()
    if plant.arm_mass_error:
        nominal = models.load("loader")  # the links' inertials as MuJoCo computes them from their geoms
        for name in ARM_BODIES:
            set_inertial(spec, nominal, name, 1.0 + plant.arm_mass_error)
    if plant.upper_arm_length_error:
        forearm = spec.body("forearm")
        forearm.pos = np.asarray(forearm.pos) + np.array([plant.upper_arm_length_error, 0.0, 0.0])
    bias = plant.encoder_bias_si()
    for j, name in enumerate(chain.names):
        if plant.joint_viscous_friction:
            joint = spec.joint(name)
            damping = np.array(joint.damping)
            damping[0] = plant.joint_viscous_friction * chain.force_limit[j] / chain.rate_limit[j]
            joint.damping = damping
        actuator = spec.actuator(name)
        if plant.drive_force_scale != 1.0:
            actuator.forcerange = plant.drive_force_scale * np.asarray(actuator.forcerange)
        if bias[j]:
            biasprm = np.array(actuator.biasprm)
            biasprm[0] = -actuator.gainprm[0] * bias[j]
            actuator.biasprm = biasprm


def plant_chain(plant: "LoaderPlant | None" = None) -> models.SerialChainSpec:
    """The plant's kinematic chain (``models.loader_spec()`` with its upper-arm length error),
    for the evaluation's shell tip: the checks judge the true machine."""
    chain = models.loader_spec()
    if plant is None or not plant.upper_arm_length_error:
        return chain
    bodies = tuple(dataclasses.replace(b, pos=b.pos + np.array([plant.upper_arm_length_error, 0.0, 0.0]))
                   if b.name == "forearm" else b for b in chain.bodies)
    return dataclasses.replace(chain, bodies=bodies)


class LoaderEvaluation:
    """Checks and outputs of a loader run (keypoints are Table 1's, in SI units)."""

    def __init__(self, physics: LoaderPhysics, key_times: np.ndarray, key_points: np.ndarray,
                 plant: "LoaderPlant | None" = None):
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

    def _demanded(self, log: RunLog, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """(n, 6) force/torque the drives demand, N and N m: their PD on what their encoders
        read (q + encoder bias)."""
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
        tau = self._demanded(log, q, qd)
        torque_ratio = np.abs(tau) / self.force_limit
        robot, obstacles = self.physics.robot_geoms(), self.physics.obstacle_geoms()
        pairs = obstacle_contact_pairs(log.contacts, robot, obstacles)
        clear, closest = self.clearance(log)
        i_min = int(np.argmin(clear))
        names = lambda pair: f"{model.geom(int(pair[0])).name}/{model.geom(int(pair[1])).name}"
        contact_note = ", ".join(
            f"{names(p)} from t = {log.t[v[0]]:.3f} s for {v[1]} ticks, {1e3 * v[2]:.1f} mm deep"
            for p, v in sorted(pairs.items(), key=lambda kv: kv[1][0])
        )
        reached_note = f"{int(reached.sum())} of {self.key_times.size} key points reached"
        checks = [
            Check("keypoint_error", float(key_err_deg.max()), KEYPOINT_LIMIT_DEG, "deg", note=reached_note)
            if key_err_deg.size else
            Check.not_evaluated("keypoint_error", KEYPOINT_LIMIT_DEG, "deg",
                                reason=f"the run ended at t = {log.t[-1]:.3f} s, before the first "
                                       f"key point (t = {self.key_times.min():.3f} s)"),
            Check("tracking_error", float(err_deg.max()), TRACKING_LIMIT_DEG, "deg"),
            Check("obstacle_contacts", len(pairs), 0, "count", "==", note=contact_note),
            Check("min_clearance", float(clear[i_min]), 0.0, "m", ">",
                  note=f"{names(closest[i_min])} at t = {log.t[i_min]:.3f} s"
                  if closest[i_min, 0] >= 0 else "nothing within 0.5 m"),
            Check("joint_torque", float(torque_ratio.max()), 1.0, "ratio",
                  note=f"peak on {self.spec.names[int(np.argmax(torque_ratio.max(0)))]}"),
        ]
        metrics = {
            "keypoint_error_slide_mm": float(key_err_slide_mm.max()) if key_err_slide_mm.size else None,
            "tracking_error_slide_mm": float(1e3 * np.abs(err[:, 0]).max()),
            "tracking_error_deg_per_joint": dict(zip(self.spec.names[1:], err_deg.max(0).round(6).tolist())),
            "peak_torque_per_joint": dict(zip(self.spec.names, np.abs(tau).max(0).round(3).tolist())),
            "torque_limit_per_joint": dict(zip(self.spec.names, self.force_limit.tolist())),
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
            "drive_force_demanded": self._demanded(log, q, qd),
            "drive_force_limit": self.force_limit,
            "shell_tip_pos": self._shell_tip(log),
            "clearance": clear,
            "key_times": self.key_times,
            "key_points": self.key_points,
        }

    def report(self, log: RunLog, checks, path) -> None:
        from sims.loader.report import loader_report

        loader_report(self.timeseries(log), log.t, checks, path)


@functools.lru_cache(maxsize=1)
def log_bytes_per_tick() -> float:
    """Bytes a loader run preallocates per control tick: the runner's log of the compiled
    model (6 planned joints) and the servo controller's set-points and feed-forward torques
    (6 + 6 doubles). The contact list of loader-direct (a few hundred ticks) is left out."""
    model = models.load("loader")
    return run_limits.floats(run_limits.runlog_floats_per_tick(model, 6) + 2 * 6)


def sensors(physics: LoaderPhysics, bias=None) -> JointEncoders:
    """The loader's sensors: the drives' encoders on theta1 ... theta6, exact, every tick
    (no encoder figures are published for it; an assumption, README.md). ``bias`` (6,) m and
    rad: the plant's encoder zero offsets (``LoaderPlant.encoder_bias``), added to every
    reading; None or zeros: none."""
    model = physics.model.ptr
    joints = [model.joint(n) for n in physics.joint_names]
    encoders = JointEncoders([j.qposadr[0] for j in joints], [j.dofadr[0] for j in joints],
                             [model.actuator(n).actadr[0] for n in physics.joint_names],
                             "encoders of theta1 (m) ... theta6 (rad)", "m|rad", CONTROL_DT,
                             bias=0.0 if bias is None else bias)
    if bias is not None and np.any(bias):
        # The datasheet a controller is given (ControlContext.sensors) cannot state the true
        # zero offset of this machine's encoders: it is the plant's (summary.json's "plant").
        encoders.specs[0] = dataclasses.replace(encoders.specs[0], bias="unknown zero offset (plant uncertainty)")
    return encoders


def reference_controller() -> ServoFeedforwardController:
    """Our controller: the drives' PD with the nominal model's inverse dynamics as
    feed-forward (``ServoFeedforwardController``)."""
    spec = models.loader_spec()
    return ServoFeedforwardController(spec.kp, spec.kv)


def problem(params: "LoaderParams") -> loader_planner.LoaderProblem:
    """The run's planning problem: the key points at uniform times, the model's limits."""
    points = loader_planner.table1_to_si(np.array(params.key_points))
    times = np.arange(len(points)) * params.key_interval
    spec = models.loader_spec()
    return loader_planner.LoaderProblem(times, points, tuple(spec.names), spec.lower, spec.upper,
                                        spec.rate_limit, spec.force_limit)


def plan(params: "LoaderParams"):
    """The paper's cubic B-spline through the run's key points (``planbench plan``)."""
    return loader_planner.CubicBSplinePlanner().plan(problem(params))


def build(params: "LoaderParams", planner=None, controller=None, plant: "LoaderPlant | None" = None) -> Setup:
    """A loader run: ``planner`` (default the paper's cubic B-spline) plans the key points,
    ``controller`` (default ``reference_controller()``) follows it from the first key point, at
    rest; the checks judge the key points, the obstacles and the drive limits.

    ``plant`` (None: the nominal plant) perturbs the simulated machine only: the planner and
    the controller keep the nominal model (``Task.nominal_physics``). The plant starts at
    rest where its encoders read the first key point, i.e. at key_points[0] - encoder bias
    (the controller sees only the encoders); the checks judge its true joints.
    """
    plant = LoaderPlant() if plant is None else plant
    task = problem(params)
    planner = loader_planner.CubicBSplinePlanner() if planner is None else planner
    trajectory = plan_checked(planner, task, task.labels)
    duration = params.duration if params.duration is not None else trajectory.duration + params.settle
    run_limits.check_duration(duration, CONTROL_DT, log_bytes_per_tick())
    physics = LoaderPhysics.load(params.payload_mass, plant)
    bias = plant.encoder_bias_si()
    physics.set_start(task.key_points[0] - bias if bias.any() else task.key_points[0])
    nominal_physics = None  # the nominal plant: a copy of the physics, as it is now
    if not plant.is_nominal:
        nominal = LoaderPhysics.load(params.payload_mass)
        nominal.set_start(task.key_points[0])
        nominal_physics = nominal_copy(nominal)
    evaluation = LoaderEvaluation(physics, task.key_times, task.key_points, plant)
    return Setup(
        physics,
        Task(problem=task, sensors=sensors(physics, bias), evaluation=evaluation, control_dt=CONTROL_DT,
             duration=duration, nominal_physics=nominal_physics),
        Components(planner=planner, trajectory=trajectory,
                   controller=reference_controller() if controller is None else controller),
        provenance=Provenance(seed=params.seed, params=params, plant=plant),
    )


# ----------------------------------------------------------------------------- parameters

_JOINTS = models.loader_spec()
#: Each key point column's range in Table 1's units (mm, deg): the model's joint ranges.
_KEY_LOW = tuple(float(v) for v in loader_planner.si_to_table1(_JOINTS.lower))
_KEY_HIGH = tuple(float(v) for v in loader_planner.si_to_table1(_JOINTS.upper))


@dataclass(frozen=True)
class LoaderParams(ScenarioParams):
    """A loader run: key points through the cubic B-spline, the payload, the run's length."""

    key_points: tuple[tuple[float, ...], ...] = param(
        tuple(tuple(float(v) for v in row) for row in loader_planner.TABLE1),
        "key points, one row per point: theta1 (mm), theta2 ... theta6 (deg), as Table 1; the "
        "first is the start pose", unit=("mm", "deg", "deg", "deg", "deg", "deg"), low=_KEY_LOW, high=_KEY_HIGH,
        reason="the joint ranges of models/loader/loader.xml", length=6, min_items=2, max_items=200)
    key_interval: float = param(0.5, "time from one key point to the next (uniform, as Table 1)", "s",
                                low=CONTROL_DT, high=60.0,
                                reason="at least one control tick; a minute is longer than any loading stroke")
    settle: float = param(SETTLE_S, "time simulated after the last key point, so the arrival is seen at rest",
                          "s", low=0.0, high=60.0, reason="the drives settle in well under a second")
    payload_mass: float = param(45.0, "mass of the shell in the gripper (its inertia scales with it)", "kg",
                                low=0.0, high=90.0,
                                reason="none to twice the 45 kg 155 mm shell the drives are sized for "
                                       "(models/loader/README.md)")
    duration: float | None = param(None, "simulated time; none: the key points' span plus the settle time",
                                   "s", low=CONTROL_DT, reason="at least one control tick (5 ms)")

    def check(self) -> None:
        duration = self.duration if self.duration is not None else \
            (len(self.key_points) - 1) * self.key_interval + self.settle
        run_limits.check_duration(duration, CONTROL_DT, log_bytes_per_tick())


#: Each encoder's zero offset range, in Table 1's units (mm, deg).
_BIAS_UNITS = ("mm", "deg", "deg", "deg", "deg", "deg")
_BIAS_LIMIT = (1.0, 0.1, 0.1, 0.1, 0.1, 0.1)


@dataclass(frozen=True)
class LoaderPlant(PlantParams):
    """The loader as built, against its model (plant uncertainty, for campaigns).

    The paper gives no masses, dimensions or drive data: the nominal model's numbers are all
    assumptions (models/loader/README.md), and so are these ranges; each states its reasoning.
    The defaults are the nominal plant. The planner and the controller keep the nominal
    model; ``apply_plant`` edits the plant's MjSpec, the encoders take the bias.
    """

    payload_mass_error: float = param(
        0.0, "true shell mass relative to payload_mass (which the controller is told): m = payload_mass (1 + error); "
        "its inertia scales with it", "fraction", low=-0.1, high=0.1,
        reason="155 mm HE projectiles weigh 43-47 kg (+-4.4 % of 45 kg, models/loader/README.md); +-10 % "
               "also covers a fuze or projectile lot the loader was not told of (assumption)")
    arm_mass_error: float = param(
        0.0, "mass (and inertia) of every arm link, carriage to gripper, relative to the model's", "fraction",
        low=-0.05, high=0.05,
        reason="welded beams and castings come within a few % of their drawing mass; +-5 % assumed (the "
               "link masses are themselves assumptions, models/loader/README.md)")
    upper_arm_length_error: float = param(
        0.0, "error of the upper arm's shoulder-to-elbow axis distance (1.0 m in the model)", "m",
        low=-0.002, high=0.002,
        reason="a welded arm whose bores are machined after welding holds +-0.5 mm; +-2 mm allows an "
               "unmachined weldment (assumption)")
    joint_viscous_friction: float = param(
        0.0, "viscous friction of every joint (reducer, bearings, seals): its force/torque at the drive's rated "
        "speed as a fraction of the drive's rated force/torque; the model has none", "fraction", low=0.0, high=0.1,
        reason="friction only takes energy (>= 0); servo gearboxes lose 5-10 % at rated speed (efficiency "
               "90-95 %): up to 10 %, all of it taken as viscous (assumption: no drive data are published)")
    drive_force_scale: float = param(
        1.0, "every drive's force/torque limit relative to its rating (models/loader/README.md)", "fraction",
        low=0.5, high=1.0,
        reason="a drive delivers at most its rated force; down to half of it when derated (heat, a low DC bus, "
               "an aged motor); assumption")
    encoder_bias: tuple[float, ...] = param(
        (0.0,) * 6, "zero offset of each drive's encoder, theta1 (mm), theta2 ... theta6 (deg): the drive and "
        "the controller read q + bias", unit=_BIAS_UNITS, low=tuple(-b for b in _BIAS_LIMIT), high=_BIAS_LIMIT,
        length=6,
        reason="the joints' zero (mastering) offsets of a calibrated arm, assumed within the 0.1 deg key-point "
               "limit and 1 mm of the slide's homing; no encoder data are published")

    def encoder_bias_si(self) -> np.ndarray:
        """(6,) the encoder biases in joint units, m and rad."""
        return loader_planner.table1_to_si(np.array(self.encoder_bias))


# ----------------------------------------------------------------------------- registry

from sims.scenarios import BENCHMARK, DEMO, Mechanism, Scenario  # noqa: E402  (the registry imports this package lazily)

def judge_plans(params_list, planner=None):
    """The planner checks of each run, no physics (planner-only campaigns; sims/loader/plan_checks.py)."""
    from sims.loader.plan_checks import judge_plans as judge  # it imports this package

    return judge(params_list, planner=planner)


_RUN = dict(build=build, plan=plan, kinds=joint_kinds, control_dt=CONTROL_DT, plant=LoaderPlant(), judge_plans=judge_plans)

SCENARIOS = (
    Scenario(
        "loader-supply",
        "PRR-3R loader: Table 1 key points P2, M1-M4, P3 through the cubic B-spline, past the breechblock and seat ring",
        LoaderParams(),
        **_RUN,
        tags=(DEMO, BENCHMARK),
    ),
    Scenario(
        "loader-direct",
        "PRR-3R loader: P2 to P3 as a straight joint-space move in the same 2.5 s; strikes the obstacles (expected to fail)",
        # The key points checked are the endpoints; M1 ... M4 are not in this problem.
        LoaderParams(key_points=LoaderParams().key_points[::5], key_interval=2.5),
        expect_pass=False,
        **_RUN,
    ),
)


def environment_reward(setup: Setup):
    """The dm_control reward: exp(-max joint tracking error / 0.1 deg)."""
    from sims.envs import joint_tracking_reward

    return joint_tracking_reward(setup.task.sensors.qpos, np.deg2rad(0.1))


MECHANISM = Mechanism("loader", SCENARIOS, environment_reward, benchmark_runs=5)
