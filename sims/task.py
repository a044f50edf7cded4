"""The Task contract: what a controller sees, what a planner gets, what the checks judge.

Modelled on ``dm_control.rl.control.Task``. A scenario builds a task (``runner.Setup``); the
task owns the plant's initial state, its disturbances (wind, the sea), its **sensors** and its
evaluation. The runner drives every run the same way (README.md, "Your own planner or controller"):

* The **planner** gets the task's planning problem, a typed object (``planning_problem`` of
  each mechanism: key points and limits, start and target poses, the satellite and the
  IMU's update interval, sources and times), and returns a ``planbench.planners.trajectory.Trajectory``
  (loader, hexapod, FAST) or, for the antenna, is an online planner that returns the joint
  solution for each attitude the controller hands it (``OnlinePlanner``).
* The **controller** gets a ``ControlContext`` once (the nominal model, the trajectory and its
  reference at every tick, the actuators, the initial observation) and then, once per control
  tick, the task's ``Observation``: what the sensors report, with their rate, latency, noise
  and bias. It writes ``context.command`` (the actuators' ``ctrl``) or returns the command
  vector. It never gets the physics: our reference controllers obey the same rule.
* The **evaluation** judges the task's goal (the key points, the target pose, the satellite
  direction, the planned feed path) from the run's log and the task's own records (what the
  planner returned, what the sensors reported), never from a controller's or planner's
  internals.
"""

from __future__ import annotations

import copy
import inspect
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any, Protocol, runtime_checkable

import mujoco
import numpy as np

from planbench.planners.trajectory import ChunkedSample, Trajectory, TrajectorySample


class PluginError(ValueError):
    """A planner or controller that does not keep the Task contract (a missing method, a
    wrong signature, a trajectory or command of the wrong shape, a non-finite first command):
    bad input, found before MuJoCo takes a step (the CLI's exit 2)."""


# ----------------------------------------------------------------------------- sensors


@dataclass(frozen=True)
class SensorSpec:
    """One sensor of a task, as summary.json and the README describe it.

    Attributes:
      name: the observation key it fills.
      measures: what it reads, in words (e.g. "joint encoders theta1 ... theta6").
      unit: of its reading.
      rate_hz: samples per second (the control rate for a sensor read every tick).
      latency_s: from sampling to the controller, s.
      noise: its noise in words with units (e.g. "white, 1 mm and 20 urad 1-sigma per axis"),
        "none" for an ideal sensor.
      bias: its bias in words, "none" without.
      resolution: one count of its reading, in its unit; 0 for a continuous reading (listed
        in JSON only when it counts).
    """

    name: str
    measures: str
    unit: str
    rate_hz: float
    latency_s: float = 0.0
    noise: str = "none"
    bias: str = "none"
    resolution: float = 0.0

    def to_json(self) -> dict:
        out = asdict(self)
        if not self.resolution:
            del out["resolution"]
        return out


def _is_run(index: np.ndarray) -> bool:
    return index.size > 0 and np.array_equal(index, np.arange(index[0], index[0] + index.size))


def readonly_view(array: np.ndarray, index) -> np.ndarray:
    """A read-only view of ``array[index]`` that follows the live buffer (an ideal sensor at
    no cost per tick). ``index`` must be a contiguous, increasing run of indices."""
    index = np.asarray(index, dtype=int).ravel()
    if not _is_run(index):
        raise ValueError(f"indices {index.tolist()} are not one contiguous run: no view exists")
    view = array[int(index[0]) : int(index[0]) + index.size]
    view.flags.writeable = False
    return view


class Sensors:
    """The observation of a task: a dict of named readings, updated in place every tick.

    Ideal readings (an encoder read every tick, exactly) are read-only views of the physics'
    buffers and cost nothing per tick; modelled sensors (rate, latency, noise, bias) override
    ``__call__`` and write their readings into their arrays. The controller holds the same
    dict for the whole run and reads it once per tick.
    """

    def __init__(self):
        self.observation: dict[str, np.ndarray] = {}
        self.specs: list[SensorSpec] = []

    def reset(self, physics, times: np.ndarray, seed: int) -> dict:
        """Prepare for a run of ``times`` (s, one per control tick) with the physics at its
        initial state; returns the observation (its readings at t = 0)."""
        return self.observation

    def __call__(self, tick: int, physics) -> None:
        """Update the readings for the start of control tick ``tick`` (before the controller)."""

    def describe(self) -> list[dict]:
        return [s.to_json() for s in self.specs]


class JointEncoders(Sensors):
    """Encoders on actuated joints, read every control tick, and the drives' set-points.

    Observation keys: ``joint_positions`` (m or rad), ``joint_velocities`` (m/s or rad/s, the
    drive's velocity estimate), ``setpoints`` (the drives' position set-points: a motion
    controller knows what it commanded). Without noise, bias and resolution the readings are
    exact, as read-only views of the physics' buffers (no cost per tick); with them, each
    tick's position reading is the true one plus ``bias`` plus white noise of ``noise`` (1
    sigma, seeded from the run's seed), counted in steps of ``resolution``: the encoder's
    count times its resolution, floor(x / r) r (computed as floor(x (1/r)) r).

    Args:
      qpos, dofs, acts: the joints' qpos and dof addresses and the drives' activation
        addresses, in the controller's channel order.
      measures: what they read, in words; unit: of the positions.
      noise, bias: per joint (or one for all), in the positions' unit.
      resolution: per joint (or one for all), one count in the positions' unit; 0: exact.
    """

    def __init__(
        self, qpos, dofs, acts, measures: str, unit: str, control_dt: float, noise=0.0, bias=0.0, resolution=0.0
    ):
        super().__init__()
        self.qpos = np.asarray(qpos, dtype=int)
        self.dofs = np.asarray(dofs, dtype=int)
        self.acts = np.asarray(acts, dtype=int)
        self.noise = np.broadcast_to(np.asarray(noise, dtype=float), self.qpos.shape).copy()
        self.bias = np.broadcast_to(np.asarray(bias, dtype=float), self.qpos.shape).copy()
        self.resolution = np.broadcast_to(np.asarray(resolution, dtype=float), self.qpos.shape).copy()
        if not (
            np.isfinite(self.noise).all()
            and np.isfinite(self.bias).all()
            and (self.noise >= 0).all()
            and np.isfinite(self.resolution).all()
            and (self.resolution >= 0).all()
        ):
            raise ValueError(
                f"encoder noise {self.noise.tolist()} and resolution {self.resolution.tolist()} must be "
                f"finite and >= 0 and bias {self.bias.tolist()} finite"
            )
        rate = 1.0 / control_dt
        ideal = not self.noise.any() and not self.bias.any() and not self.resolution.any()
        noise_text = "none" if not self.noise.any() else f"white, {self.noise.tolist()} {unit} 1-sigma"
        bias_text = "none" if not self.bias.any() else f"{self.bias.tolist()} {unit}"
        self.specs = [
            SensorSpec(
                "joint_positions", measures, unit, rate, 0.0, noise_text, bias_text, float(self.resolution.max())
            ),
            SensorSpec("joint_velocities", f"rates of the {measures}", f"{unit}/s", rate),
            SensorSpec("setpoints", "the drives' position set-points (what was commanded)", unit, rate),
        ]
        self._ideal = ideal
        self._noisy = bool(self.noise.any() or self.bias.any())
        self._counted = self.resolution > 0
        self._all_counted = bool(self._counted.all())
        self._counts_per_unit = np.divide(1.0, self.resolution, out=np.zeros_like(self.resolution), where=self._counted)
        self._copies: list[tuple] = []  # (live buffer, index, out) read by __call__ every tick
        self._counted_run: tuple | None = None  # (live view, out): counted positions read in one pass

    def reset(self, physics, times: np.ndarray, seed: int) -> dict:
        data = physics.data.ptr
        self._rng = np.random.default_rng([seed, 0xE4C])
        self._data = data
        obs = {}
        self._copies = []
        sources = [
            ("joint_positions", lambda d: d.qpos, self.qpos),
            ("joint_velocities", lambda d: d.qvel, self.dofs),
            ("setpoints", lambda d: d.act, self.acts),
        ]
        self._counted_run = None
        for name, getter, index in sources:
            buffer = getter(data)
            if _is_run(index) and (self._ideal or name != "joint_positions"):
                obs[name] = readonly_view(buffer, index)
            elif _is_run(index) and self._all_counted and not self._noisy:
                # Counted, noiseless positions of a run of joints: floor(x (1/r)) r straight
                # from the live buffer (the same arithmetic as copying first).
                out = np.empty(index.size)
                self._counted_run = (readonly_view(buffer, index), out)
                obs[name] = out
            else:
                out = np.empty(index.size)
                self._copies.append((buffer, index, out))
                obs[name] = out
        self._positions = obs["joint_positions"]
        self.observation = obs
        self(0, physics)
        return obs

    def __call__(self, tick: int, physics) -> None:
        for buffer, index, out in self._copies:
            np.take(buffer, index, out=out)
        if self._counted_run is not None:
            source, positions = self._counted_run
            np.multiply(source, self._counts_per_unit, out=positions)
            np.floor(positions, out=positions)
            np.multiply(positions, self.resolution, out=positions)
        elif not self._ideal:
            if self._noisy:
                self._positions += self.bias + self.noise * self._rng.standard_normal(self.noise.size)
            if self._all_counted:  # in place: a tick's reading costs no new arrays
                positions = self._positions
                np.multiply(positions, self._counts_per_unit, out=positions)
                np.floor(positions, out=positions)
                positions *= self.resolution
            elif self._counted.any():
                counted = self._counted
                self._positions[counted] = (
                    np.floor(self._positions[counted] * self._counts_per_unit[counted]) * self.resolution[counted]
                )


# ----------------------------------------------------------------------------- the task


@runtime_checkable
class Disturbance(Protocol):
    """Wind, ship motion, payload forces...: applied once per control tick. Part of the
    plant, so it may read and write the physics.

    A disturbance whose random state sets where an episode starts (the antenna's sea: the
    deck and the antenna start where the sea puts them) also has ``draw_start(physics,
    seed)``: it puts the physics at the start drawn from ``seed``, before the sensors and the
    disturbance reset, and leaves the task's initial state as it is for the seed the task
    was built with."""

    def reset(self, physics, times: np.ndarray, rng: np.random.Generator) -> None: ...

    def __call__(self, tick: int, physics) -> None: ...


@runtime_checkable
class Evaluation(Protocol):
    """How a task judges a run, from its log (``planbench.runner.RunLog``) and the task's own
    records: never from a planner's or controller's internals."""

    def evaluate(self, log) -> tuple[list, dict]:
        """(checks, metrics): the task's checks (``planbench.checks.Check``) and its figures."""

    def timeseries(self, log) -> dict:
        """{name: array}: what timeseries.npz keeps besides the log."""

    def report(self, log, checks, path) -> None:
        """Draws report.png at ``path``."""


@dataclass
class Task:
    """What one run asks of the components, modelled on ``dm_control.rl.control.Task``.

    The physics is not part of it (as in dm_control, the environment holds the physics and
    hands it to the task). The task owns the initial state the physics was built at, the
    disturbance, the sensors (the controller's observation), the planning problem and the
    evaluation.

    Attributes:
      problem: the planning problem (typed, per mechanism).
      sensors: the controller's observation (``Sensors``).
      evaluation: the checks, timeseries and report (``Evaluation``).
      control_dt: the control period, s; a whole multiple of the model's timestep.
      duration: simulated time, s.
      disturbance: optional (``Disturbance``).
      controlled: indices of the actuators a controller drives (the dm_control action), None
        for all (the antenna's deck drives are the sea's).
      reference_visible: False when the trajectory is not a plan but the truth (the antenna's
        joint path for the true ship motion): the controller then gets no trajectory and no
        reference (``ControlContext``), nor the environment's agent.
      nominal_physics: () -> the controller's nominal model at the initial state
        (``ControlContext.nominal_physics``); None: a copy of the physics as the task found it.
    """

    problem: Any
    sensors: Sensors
    evaluation: Evaluation
    control_dt: float
    duration: float
    disturbance: Disturbance | None = None
    controlled: np.ndarray | None = None
    reference_visible: bool = True
    nominal_physics: Callable | None = None
    _initial_state: np.ndarray | None = field(default=None, init=False, repr=False)

    _STATE = mujoco.mjtState.mjSTATE_INTEGRATION

    def attach(self, physics) -> Task:
        """Record ``physics``'s present state as the task's initial state (and, without a
        nominal model, a copy of it as the controller's); returns the task."""
        model, data = physics.model.ptr, physics.data.ptr
        self._initial_state = np.empty(mujoco.mj_stateSize(model, self._STATE))
        mujoco.mj_getState(model, data, self._initial_state, self._STATE)
        if self.nominal_physics is None:
            self.nominal_physics = nominal_copy(physics)
        return self

    def restore_initial_state(self, physics) -> None:
        """Put ``physics`` back at the state it had when the task was attached, evaluated."""
        model, data = physics.model.ptr, physics.data.ptr
        mujoco.mj_setState(model, data, self._initial_state, self._STATE)
        mujoco.mj_forward(model, data)

    def times(self) -> np.ndarray:
        """The control ticks' times, s (``planbench.planners.trajectory.control_ticks``)."""
        from planbench.planners.trajectory import control_ticks

        return control_ticks(self.duration, self.control_dt)

    def initialize_episode(self, physics, times: np.ndarray, seed: int) -> dict:
        """Start an episode from the physics' present state (or, for a disturbance with a
        random start, from the state it draws from ``seed``): the sensors and the disturbance reset,
        seeded from ``seed``; returns the observation at t = 0."""
        draw_start = getattr(self.disturbance, "draw_start", None)
        if draw_start is not None:
            draw_start(physics, seed)
        observation = self.sensors.reset(physics, times, seed)
        if self.disturbance is not None:
            self.disturbance.reset(physics, times, np.random.default_rng(seed))
        return observation

    def before_step(self, tick: int, physics) -> None:
        """The disturbance of control tick ``tick``, applied before the physics steps."""
        if self.disturbance is not None:
            self.disturbance(tick, physics)

    def observe(self, tick: int, physics) -> None:
        """The sensors' readings for the start of control tick ``tick``."""
        self.sensors(tick, physics)


@dataclass
class Components:
    """What a run judges: the planner that ran (for the antenna, the task's
    ``RecordingPlanner`` around the online planner), the trajectory it returned (for the
    antenna, the ideal joint path for the true sea, a reference for plots) and the
    controller (``Controller``)."""

    planner: Any
    trajectory: Trajectory
    controller: Any


@dataclass
class Output:
    """How a run's files are written.

    Attributes:
      video_speed: video clock / simulated clock (1 real time, 0.5 slow motion, 20 time-lapse).
      video_qpos: optional (log, ticks) -> qpos rows to render at those ticks, for a video
        that shows something other than the logged state (the hexapod's magnified motion).
      video_note: what the video shows, written to summary.json (e.g. the magnification).
      output_stride: timeseries.npz keeps every this-many-th tick (the checks use them all):
        long runs at a high control rate would otherwise write hundreds of MB.
    """

    video_speed: float = 1.0
    video_qpos: Callable | None = None
    video_note: str = ""
    output_stride: int = 1


@dataclass
class Provenance:
    """Where a run came from, recorded in summary.json.

    Attributes:
      seed: the episode's seed (sensors, disturbance).
      params: the scenario's parameters (planbench.params) the run was built from, None for a task
        built by hand; the result records them resolved.
      plant: the plant's uncertainty (planbench.params.PlantParams) the physics was built with,
        None for a mechanism without one.
      plugins: the ``MODULE:FACTORY`` of a user's planner or controller, by role.
    """

    seed: int = 0
    params: Any = None
    plant: Any = None
    plugins: dict = field(default_factory=dict)


# ----------------------------------------------------------------------------- the contract


@dataclass
class ControlContext:
    """What a controller is given at ``reset``: what a real one is configured with.

    Attributes:
      model: the nominal model (a copy of the plant's ``mujoco.MjModel``: gains, limits,
        masses), for feed-forward; the plant may differ from it.
      nominal_physics: () -> a dm_control Physics of the nominal model at the task's initial
        configuration (the machine at rest at its start), for model-based feed-forward.
      problem: the task's planning problem.
      trajectory: what the planner returned (loader, hexapod, FAST); None for the antenna,
        whose planner is online: its ideal joint path is computed from the true ship motion,
        which no controller can know.
      reference: the trajectory sampled at every control tick (None with it): a
        ``planbench.planners.trajectory.ChunkedSample``, whose ``rows(start, stop)`` samples those ticks
        only and whose ``position``, ``velocity``, ``acceleration`` are the whole arrays.
      control_dt: the control period, s.
      command: the commands (``ctrl``) of the actuators this controller drives, in the
        order of ``actuators``: write it every tick, or return the vector from ``__call__``.
        Actuators that belong to the task's disturbance (the antenna's deck drives, moved by
        the sea) are not in it.
      setpoint: the position set-points (the integrator activations) of those drives at the
        start; a controller may set them in ``reset`` (the set-points a motion controller
        loads when it enables the drives). Writing it later has no effect.
      actuators: the names of the actuators the controller drives, in ``command``'s order.
      observation: the task's observation (the same dict every tick, updated in place).
      sensors: the ``SensorSpec`` of every reading (rate, latency, noise: the datasheets).
      planner: the antenna's online planner (its ``step`` records every update for the
        checks), None elsewhere.
    """

    model: mujoco.MjModel
    nominal_physics: Callable
    problem: Any
    trajectory: Trajectory | None
    reference: TrajectorySample | ChunkedSample | None
    control_dt: float
    command: np.ndarray
    setpoint: np.ndarray
    actuators: tuple
    observation: dict
    sensors: tuple = ()
    planner: Any = None


@runtime_checkable
class Controller(Protocol):
    """A controller plugged into the runner (ours or a user's): see the module docstring."""

    def reset(self, context: ControlContext) -> None: ...

    def __call__(self, tick: int, observation: dict) -> np.ndarray | None: ...


@runtime_checkable
class Planner(Protocol):
    """A planner that turns the task's problem into a Trajectory (loader, hexapod, FAST)."""

    def plan(self, problem) -> Trajectory: ...


@runtime_checkable
class OnlinePlanner(Protocol):
    """The antenna's planner: a joint solution per attitude sample.

    ``reset(problem)`` once (the satellite, the start angles, the joint limits and weights);
    ``step(t, attitude)`` for each update: ``attitude`` is N = bTe eTs (3, 3), the antenna's
    wanted orientation in the ship frame for time ``t`` (s), and the result the joint angles
    Theta (4,) rad with f(Theta) = N (paper, eq. 1). It may set ``last_info`` (an object with
    ``iterations``, ``damped``, ``rate_limited``) for the metrics.
    """

    def reset(self, problem) -> None: ...

    def step(self, t: float, attitude: np.ndarray) -> np.ndarray: ...


class StepTimeError(ValueError):
    """An online planner stepped at a time that does not come after its previous step."""


class RecordingPlanner:
    """The task's record of an online planner: every (t, attitude given, Theta returned).

    The controller calls ``step`` as it would the planner; the checks judge the returned
    angles against the attitudes they were asked for (f(Theta) = N), nothing inside the
    planner. ``wall_s`` is the time spent in the planner.
    """

    def __init__(self, planner, size: int):
        self.planner = planner
        self.t = np.full(size, np.nan)
        self.attitude = np.full((size, 3, 3), np.nan)
        self.theta = np.full((size, 4), np.nan)
        self.iterations = np.zeros(size, dtype=int)
        self.damped = np.zeros(size, dtype=bool)
        self.rate_limited = np.zeros(size, dtype=bool)
        self.count = 0
        self.wall_s = 0.0

    def reset(self, problem) -> None:
        """A new run: the record starts empty, the planner from the problem."""
        self.count = 0
        self.wall_s = 0.0
        self.planner.reset(problem)

    def step(self, t: float, attitude: np.ndarray) -> np.ndarray:
        """The planner's ``step(t, attitude)``, recorded. ``t`` (s) must come after the previous
        step's, and the first after the problem's start (t = 0, where ``theta0`` holds): a step
        at the same time is an interval of zero, whose angular velocity (eq. 6) does not exist."""
        last = float(self.t[self.count - 1]) if self.count else 0.0
        if not float(t) > last:
            since = "its previous step at" if self.count else "the problem's start (theta0) at"
            raise StepTimeError(
                f"the online planner was stepped at t = {float(t):.6g} s, not after {since} "
                f"{last:.6g} s: steps must have increasing times"
            )
        start = time.perf_counter()
        theta = np.array(self.planner.step(t, attitude), dtype=float)
        self.wall_s += time.perf_counter() - start
        if theta.shape != (4,):
            raise PluginError(f"the antenna planner's step returned shape {theta.shape}, not (4,) joint angles")
        if not np.isfinite(theta).all():  # before any use: NaN angles only make numpy warn downstream
            raise PluginError(
                f"the antenna planner's step at t = {t:g} s returned non-finite joint angles "
                f"{np.array2string(theta, precision=4)}"
            )
        i = self.count
        if i == self.t.size:  # more updates than the IMU's rate gives: grow
            for name in ("t", "attitude", "theta", "iterations", "damped", "rate_limited"):
                old = getattr(self, name)
                setattr(self, name, np.concatenate([old, np.zeros_like(old)]))
        self.t[i], self.attitude[i], self.theta[i] = t, attitude, theta
        info = getattr(self.planner, "last_info", None)
        if info is not None:
            self.iterations[i] = getattr(info, "iterations", 0)
            self.damped[i] = getattr(info, "damped", False)
            self.rate_limited[i] = getattr(info, "rate_limited", False)
        self.count += 1
        return theta

    def records(self) -> dict:
        n = self.count
        return {
            "t": self.t[:n],
            "attitude": self.attitude[:n],
            "theta": self.theta[:n],
            "iterations": self.iterations[:n],
            "damped": self.damped[:n],
            "rate_limited": self.rate_limited[:n],
        }


# ----------------------------------------------------------------------------- plug-in checks


def _callable_with(function, n_args: int, what: str) -> None:
    """PluginError unless ``function`` accepts ``n_args`` positional arguments."""
    try:
        signature = inspect.signature(function)
    except (TypeError, ValueError):
        return  # a builtin or C function: no signature to check
    try:
        signature.bind(*range(n_args))
    except TypeError as e:
        raise PluginError(f"{what} must take {n_args} argument{'s' if n_args != 1 else ''}: {e}") from None


def check_controller(controller) -> None:
    """PluginError unless ``controller`` has ``reset(context)`` and ``__call__(tick, observation)``."""
    name = type(controller).__name__
    reset = getattr(controller, "reset", None)
    if not callable(reset):
        raise PluginError(f"controller {name} has no reset(context) method")
    if not callable(controller):
        raise PluginError(f"controller {name} is not callable as controller(tick, observation)")
    _callable_with(reset, 1, f"controller {name}'s reset(context)")
    _callable_with(controller, 2, f"controller {name}'s __call__(tick, observation)")


def check_planner(planner, online: bool) -> None:
    """PluginError unless ``planner`` has ``plan(problem)`` (or, ``online``, ``reset(problem)``
    and ``step(t, attitude)``)."""
    name = type(planner).__name__
    if online:
        for method, n in (("reset", 1), ("step", 2)):
            if not callable(getattr(planner, method, None)):
                raise PluginError(
                    f"antenna planner {name} has no {method}() method (an online planner "
                    "needs reset(problem) and step(t, attitude))"
                )
            _callable_with(getattr(planner, method), n, f"planner {name}'s {method}")
        return
    if not callable(getattr(planner, "plan", None)):
        raise PluginError(f"planner {name} has no plan(problem) method")
    _callable_with(planner.plan, 1, f"planner {name}'s plan(problem)")


def check_trajectory(trajectory, labels: tuple, duration_min: float = 0.0) -> None:
    """PluginError unless ``trajectory`` keeps the Trajectory contract with the channels
    ``labels``: a finite duration > 0, and ``sample`` giving (n, len(labels)) finite arrays."""
    name = type(trajectory).__name__
    for attribute in ("duration", "labels", "sample"):
        if not hasattr(trajectory, attribute):
            raise PluginError(
                f"the planner returned a {name} without '{attribute}' (a Trajectory has duration, labels and sample(t))"
            )
    duration = trajectory.duration
    if not isinstance(duration, (int, float, np.floating, np.integer)) or not math.isfinite(duration) or duration <= 0:
        raise PluginError(f"the planner's trajectory has duration {duration!r}; it must be a finite number > 0 s")
    try:
        given = tuple(str(label) for label in trajectory.labels)
    except (Exception, SystemExit) as e:
        raise PluginError(f"the planner's trajectory labels are not a sequence of names ({fault_text(e)})") from None
    if given != tuple(labels):
        # The channels are matched by name, not by count: a trajectory whose third channel
        # is another strut's would drive the wrong actuator.
        raise PluginError(
            f"the planner's trajectory has {len(given)} channels ({', '.join(given)}); this "
            f"task needs {len(labels)}: {', '.join(labels)}, in that order"
        )
    t = np.linspace(0.0, float(duration), 5)
    sample = sample_checked(trajectory, t)
    for part in ("position", "velocity", "acceleration"):
        values = np.asarray(getattr(sample, part, None), dtype=float)
        if values.shape != (t.size, len(labels)):
            raise PluginError(
                f"the planner's trajectory sample gives {part} of shape {values.shape} for "
                f"{t.size} times; expected {(t.size, len(labels))}"
            )
        if not np.isfinite(values).all():
            raise PluginError(f"the planner's trajectory has non-finite {part} within [0, {duration:g}] s")


def fault_text(e: BaseException) -> str:
    """``Type: message`` of plug-in code's exception (or SystemExit) on one line, at most 300
    characters."""
    if isinstance(e, SystemExit):
        text = f"SystemExit({e.code!r}): plug-in code may not end the process"
    else:
        text = f"{type(e).__name__}: {e}"
    text = " ".join(text.split())
    return text if len(text) <= 300 else text[:297] + "..."


def sample_checked(trajectory, t: np.ndarray):
    """``trajectory.sample(t)``; an exception or SystemExit in it is a PluginError."""
    try:
        return trajectory.sample(t)
    except (Exception, SystemExit) as e:
        raise PluginError(
            f"the planner's trajectory ({type(trajectory).__name__}) sample() raised {fault_text(e)}"
        ) from None


def check_first_command(command, nu: int, actuators) -> np.ndarray | None:
    """The command a controller returned at its first call, checked: None (it wrote
    ``context.command``) or a vector of ``nu`` numbers; PluginError otherwise (the runner
    checks every command, this one too, for non-finite values)."""
    if command is None:
        return None
    try:
        values = np.asarray(command, dtype=float)
    except (TypeError, ValueError):
        raise PluginError(
            f"the controller returned {type(command).__name__}, not a vector of {nu} actuator commands"
        ) from None
    if values.shape != (nu,):
        raise PluginError(
            f"the controller returned a command of shape {values.shape}; this task has "
            f"{nu} actuators ({', '.join(actuators)})"
        )
    return values


def nominal_copy(physics) -> Callable:
    """() -> a fresh copy of ``physics`` (model and data, of the same class and attributes):
    the nominal model at the state it has now, for ControlContext.nominal_physics."""
    snapshot = physics.copy(share_model=False)
    extra = {k: v for k, v in vars(physics).items() if not k.startswith("_") and k not in vars(snapshot)}

    def make():
        new = snapshot.copy(share_model=False)
        for key, value in extra.items():
            setattr(new, key, copy.deepcopy(value))
        return new

    return make


def plan_checked(planner, problem, labels) -> Trajectory:
    """``planner.plan(problem)``, checked to keep the contract (``check_planner``,
    ``check_trajectory`` with the task's channel ``labels``). A ``planbench.planners.errors.PlanningError``
    (a problem the planner cannot plan) passes through; any other exception becomes a
    PluginError naming the planner."""
    from planbench.planners.errors import PlanningError

    check_planner(planner, online=False)
    from planbench import supervise

    supervise.phase(f"the planner's plan ({type(planner).__name__})")
    try:
        trajectory = planner.plan(problem)
    except PlanningError:
        raise
    except (Exception, SystemExit) as e:
        raise PluginError(f"planner {type(planner).__name__} raised {fault_text(e)}") from None
    supervise.phase(f"the planner's trajectory ({type(planner).__name__})")
    check_trajectory(trajectory, tuple(labels))
    return trajectory
