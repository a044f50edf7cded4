"""The runner: the control loop around MuJoCo, shared by every mechanism.

Per control tick it updates the task's sensors (``sims.task.Sensors``: the observation),
calls the controller once with that observation (it writes or returns the actuator commands;
it never gets the physics, ``sims.task``), applies the disturbance, lets MuJoCo take ``k``
physics steps with ``mj_step(model, data, nstep=k)`` and copies the state into preallocated
logs. Everything else (the planned motion, checks,
rendering) works on whole arrays before or after the loop.

Divergence (a NaN in the state, or any MuJoCo warning such as the bad-qacc reset) ends the
run early; the ``simulation_warnings`` check then fails with a message that says when and why.
So does a controller fault, ours or a user's: an exception raised by the controller, or a
non-finite command it wrote (found before MuJoCo steps with it), ends the run at that tick and
fails ``controller_errors`` with the exception's message or the command; the log up to it is
evaluated and written as usual.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from math import isfinite

import mujoco
import numpy as np
from tqdm import tqdm

from planners.trajectory import Trajectory, TrajectorySample, control_ticks
from sims.checks import Check, controller_check, divergence_check
from sims import supervise
from sims.task import (Components, ControlContext, Disturbance, Output, PluginError, Provenance, Task,
                       check_controller, check_first_command, fault_text, sample_checked)

#: How often (in control ticks) the loop scans for divergence: NaN or inf in the logged
#: state since the last scan, and MuJoCo's warning counters (its bad-qacc detection resets the
#: state and raises a warning). A divergence ends the run within this many ticks.
SCAN_TICKS = 10


@dataclass
class Setup:
    """Everything one run needs, built by a scenario, as dm_control's ``Environment`` holds a
    physics and a task.

    Attributes:
      physics: a ``dm_control.mujoco.Physics`` of the scene, at the task's initial state.
      task: the ``sims.task.Task`` (problem, sensors, disturbance, evaluation, timing),
        attached to ``physics`` (its initial state recorded).
      components: the planner, the trajectory and the controller (``sims.task.Components``).
      output: how the files are written (``sims.task.Output``).
      provenance: seed, parameters, plant and plug-ins (``sims.task.Provenance``).
    """

    physics: object
    task: Task
    components: Components
    output: Output = field(default_factory=Output)
    provenance: Provenance = field(default_factory=Provenance)

    def __post_init__(self):
        if self.task._initial_state is None:
            self.task.attach(self.physics)


@dataclass
class RunLog:
    """State at every control tick (row i is the state at time ``t[i]``; row 0 is the start).

    Arrays: t (n,), qpos, qvel, act, ctrl, actuator_force, sensordata (n, size), mocap_pos
    and mocap_quat (n, nmocap, 3|4) when the model has mocap bodies. ``reference`` is the
    planned motion sampled at ``t``. ``ctrl`` row i holds the controls applied from ``t[i]``;
    the last row, after which no physics runs, the controls still held there. ``contacts``
    lists (tick, geom1, geom2, distance) of every contact seen at a tick's end. ``n`` may be
    shorter than planned when the run diverged.
    """

    t: np.ndarray
    qpos: np.ndarray
    qvel: np.ndarray
    act: np.ndarray
    ctrl: np.ndarray
    actuator_force: np.ndarray
    sensordata: np.ndarray
    mocap_pos: np.ndarray
    mocap_quat: np.ndarray
    reference: TrajectorySample
    contacts: list = field(default_factory=list)
    warnings: dict = field(default_factory=dict)
    diverged_at: float | None = None
    divergence_message: str = ""
    controller_error: tuple[float, str] | None = None
    physics_steps: int = 0
    loop_wall_s: float = 0.0
    controller_wall_s: float | None = None
    physics_wall_s: float | None = None


@dataclass
class RunResult:
    """A finished run. ``components``: what ran, by class (``module.QualName``): the
    ``planner``, the ``trajectory`` it returned, the ``controller``, the ``sensors`` and the
    ``disturbance`` (None when there is none). ``plugins``: the ``MODULE:FACTORY`` of a user's
    planner or controller given on the command line. ``sensors``: each sensor's SensorSpec.
    ``parameters``: the setup's parameters, every one resolved (an unset duration is the one
    the run took), written to summary.json (``planbench run DIR/summary.json`` repeats it);
    ``plant``: its plant uncertainty's fields (None: a mechanism without them)."""

    scenario: str
    seed: int
    log: RunLog
    checks: list[Check]
    metrics: dict
    sim_time_s: float
    wall_time_s: float
    components: dict = field(default_factory=dict)
    plugins: dict = field(default_factory=dict)
    sensors: list = field(default_factory=list)
    parameters: dict | None = None
    plant: dict | None = None

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)


def steps_per_tick(model: mujoco.MjModel, control_dt: float) -> int:
    """Physics steps per control tick; the control period must be a multiple of the timestep."""
    k = control_dt / model.opt.timestep
    if k < 1 or abs(k - round(k)) > 1e-6:
        raise ValueError(
            f"control period {control_dt} s is not a whole multiple of the model timestep "
            f"{model.opt.timestep} s"
        )
    return int(round(k))


def warning_counts(data: mujoco.MjData) -> dict[str, int]:
    """MuJoCo's warning counters that are non-zero, by warning name."""
    out = {}
    for name, index in _WARNINGS:
        n = int(data.warning[index].number)
        if n:
            out[name] = n
    return out


_WARNINGS = [
    (name, int(getattr(mujoco.mjtWarning, name)))
    for name in dir(mujoco.mjtWarning)
    if name.startswith("mjWARN_")
]


def _divergence(data, qpos, qvel, times, i: int, window: int):
    """(time, message) if the state diverged in the ticks up to ``i``, else None."""
    lo = max(0, i - window)
    finite = np.isfinite(qpos[lo : i + 1]).all(axis=1) & np.isfinite(qvel[lo : i + 1]).all(axis=1)
    if not finite.all():
        first = lo + int(np.argmin(finite))
        return float(times[first]), f"non-finite state at t = {times[first]:.4f} s"
    warnings = warning_counts(data) if data.warning.number.any() else None  # (one call, not one per warning)
    if warnings:
        detail = ", ".join(f"{name} x{count}" for name, count in warnings.items())
        return float(times[i]), f"MuJoCo warning {detail} by t = {times[i]:.4f} s"
    return None


_exception_text = fault_text


def _start(role: str, reset, argument) -> None:
    """``reset(argument)``; any exception (or SystemExit) but a PluginError becomes one naming
    ``role``."""
    supervise.phase(f"the {role}'s reset")
    try:
        reset(argument)
    except PluginError:
        raise
    except (Exception, SystemExit) as e:
        raise PluginError(f"the {role}'s reset raised {_exception_text(e)}") from None


def _bad_command(model, ctrl: np.ndarray, t: float) -> str:
    """What is wrong with a command vector that is not finite, for the check's note."""
    j = int(np.argmax(~np.isfinite(ctrl)))
    name = model.actuator(j).name or f"actuator {j}"
    return f"the controller wrote ctrl[{j}] ({name}) = {ctrl[j]} at t = {t:.4f} s"


@dataclass
class Episode:
    """A run's start, shared by ``simulate`` and the dm_control environments (``sims.envs``):
    the control ticks, the reference sampled at them, the observation and the controller's
    context. ``start_episode`` makes it."""

    times: np.ndarray
    reference: TrajectorySample
    observation: dict
    context: ControlContext
    steps_per_tick: int


def controlled_actuators(setup: Setup) -> np.ndarray:
    """Indices of the actuators the controller drives (``Task.controlled``; None: all)."""
    nu = setup.physics.model.ptr.nu
    controlled = setup.task.controlled
    return np.arange(nu) if controlled is None else np.asarray(controlled, dtype=int)


def controlled_names(setup: Setup) -> tuple:
    """The names of the actuators the controller drives, in its command's order."""
    model = setup.physics.model.ptr
    return tuple(model.actuator(int(j)).name for j in controlled_actuators(setup))


def controlled_views(setup: Setup):
    """(command, act addresses): the controller's command, a view of ``data.ctrl`` for its
    actuators (a contiguous run of them: the others, such as the antenna's deck drives, belong
    to the disturbance and are neither seen nor written), and the activation addresses of
    its drives' set-points (all activations when it drives every actuator)."""
    model, data = setup.physics.model.ptr, setup.physics.data.ptr
    ids = controlled_actuators(setup)
    if ids.size == 0 or np.any(np.diff(ids) != 1):
        raise ValueError(f"the controlled actuators {ids.tolist()} must be one contiguous run")
    if ids.size == model.nu:
        return data.ctrl, slice(None)
    adr = model.actuator_actadr[ids]
    return data.ctrl[ids[0]:ids[-1] + 1], adr[adr >= 0]


def start_episode(setup: Setup, seed: int | None = None) -> Episode:
    """Put ``setup`` at the start of its run: the task's episode (``Task.initialize_episode``:
    its sensors and disturbance seeded from ``seed``, default ``setup.provenance.seed``), then
    the online planner and the controller (its ``reset`` with the ControlContext, the drives'
    initial set-points it chose), and evaluate the physics."""
    physics, task, components = setup.physics, setup.task, setup.components
    model, data = physics.model.ptr, physics.data.ptr
    k = steps_per_tick(model, task.control_dt)
    times = task.times()
    reference = sample_checked(components.trajectory, times)
    controller = components.controller
    check_controller(controller)
    observation = task.initialize_episode(physics, times, setup.provenance.seed if seed is None else seed)
    command, act_adr = controlled_views(setup)
    visible = task.reference_visible
    planner = components.planner
    context = ControlContext(
        model=task.nominal_physics().model.ptr, nominal_physics=task.nominal_physics,
        problem=task.problem, trajectory=components.trajectory if visible else None,
        reference=reference if visible else None,
        control_dt=task.control_dt, command=command, setpoint=data.act[act_adr].copy(),
        actuators=controlled_names(setup), observation=observation,
        sensors=tuple(task.sensors.specs),
        planner=planner if hasattr(planner, "step") else None)
    # Before the first tick a plug-in that cannot start is bad input, not a failed run.
    if context.planner is not None:  # an online planner starts from the problem
        _start("planner", context.planner.reset, task.problem)
    _start("controller", controller.reset, context)
    data.act[act_adr] = context.setpoint
    mujoco.mj_forward(model, data)
    return Episode(times, reference, observation, context, k)


def simulate(setup: Setup, quiet: bool = True, progress_after_s: float = 2.0, profile: bool = False) -> RunLog:
    """Run the control loop of ``setup`` and return its log.

    ``profile``: also time the code under test (the controller's calls, the online planner's
    updates inside them) and MuJoCo's steps (``RunLog.controller_wall_s``,
    ``physics_wall_s``); the rest of ``loop_wall_s`` is the testbed's own cost (sensors,
    disturbance, logging). Off, the loop reads no clock per tick."""
    physics = setup.physics
    model, data = physics.model.ptr, physics.data.ptr
    episode = start_episode(setup)
    times, reference, observation, context = episode.times, episode.reference, episode.observation, episode.context
    k, n = episode.steps_per_tick, episode.times.size
    controller = setup.components.controller

    log = RunLog(
        t=times,
        qpos=np.empty((n, model.nq)),
        qvel=np.empty((n, model.nv)),
        act=np.empty((n, model.na)),
        ctrl=np.zeros((n, model.nu)),
        actuator_force=np.empty((n, model.nu)),
        sensordata=np.empty((n, model.nsensordata)),
        mocap_pos=np.empty((n, model.nmocap, 3)),
        mocap_quat=np.empty((n, model.nmocap, 4)),
        reference=reference,
    )
    qpos, qvel, act, ctrl = log.qpos, log.qvel, log.act, log.ctrl
    frc, sens, mpos, mquat = log.actuator_force, log.sensordata, log.mocap_pos, log.mocap_quat
    has_mocap = model.nmocap > 0

    def record(i: int) -> None:
        qpos[i] = data.qpos
        qvel[i] = data.qvel
        act[i] = data.act
        frc[i] = data.actuator_force
        sens[i] = data.sensordata
        if has_mocap:
            mpos[i] = data.mocap_pos
            mquat[i] = data.mocap_quat

    record(0)
    initial_ctrl = data.ctrl.copy()
    task = setup.task
    observe, before_step = task.observe, task.before_step  # the same tick as sims.envs'
    ctrl_now = context.command
    contacts = []  # (tick, geoms (ncon, 2), distances (ncon,)) of every tick with contacts
    bar = tqdm(total=n - 1, unit="tick", delay=progress_after_s, disable=quiet, leave=False,
               desc="simulating")
    update_every = max(1, (n - 1) // 200)
    last = n - 1
    clock = time.perf_counter
    controller_wall = physics_wall = 0.0
    supervise.phase("the control loop (the controller's __call__, or an online planner's step in it)")
    start = clock()
    for i in range(n - 1):
        observe(i, physics)
        if profile:
            t0 = clock()
        try:
            command = controller(i, observation)
            if command is not None:
                # At the first call a wrong shape is a broken contract (bad input), not a fault.
                ctrl_now[:] = command if i else check_first_command(command, ctrl_now.size, context.actuators)
        except PluginError:
            raise
        except (Exception, SystemExit) as e:  # a controller's fault ends the run as a failed check
            log.controller_error = (float(times[i]), _exception_text(e))
            last = i
            break
        if profile:
            controller_wall += clock() - t0
        if not isfinite(data.ctrl.sum()):  # ~1 us: no NaN command ever reaches MuJoCo
            if i == 0:
                raise PluginError(_bad_command(model, data.ctrl, times[i]) + ", its first command "
                                  "(before any physics step)")
            log.controller_error = (float(times[i]), _bad_command(model, data.ctrl, times[i]))
            last = i
            break
        before_step(i, physics)
        ctrl[i] = data.ctrl
        if profile:
            t1 = clock()
            mujoco.mj_step(model, data, nstep=k)
            physics_wall += clock() - t1
        else:
            mujoco.mj_step(model, data, nstep=k)
        record(i + 1)
        if data.ncon:  # the contact list's arrays: iterating over its structs costs ~100 us a tick
            contact = data.contact
            contacts.append((i + 1, contact.geom.copy(), contact.dist.copy()))
        if i % SCAN_TICKS == 0 or i == n - 2:
            message = _divergence(data, qpos, qvel, times, i + 1, SCAN_TICKS)
            if message:
                log.warnings = warning_counts(data)
                log.diverged_at, log.divergence_message = message
                last = i + 1
                break
        if i % update_every == 0:
            bar.update(update_every)
    log.loop_wall_s = clock() - start
    supervise.phase("evaluating the run (planbench's own code)")
    if profile:
        log.controller_wall_s, log.physics_wall_s = controller_wall, physics_wall
    bar.close()
    if log.controller_error is None:
        ctrl[last] = data.ctrl  # held at the end (no controller call there)
    else:
        ctrl[last] = ctrl[last - 1] if last > 0 else initial_ctrl  # the last good command, held
    log.physics_steps = last * k
    log.contacts = [(tick, int(g1), int(g2), float(dist)) for tick, geoms, dists in contacts
                    for (g1, g2), dist in zip(geoms.tolist(), dists.tolist())]
    if last < n - 1:
        for name in ("t", "qpos", "qvel", "act", "ctrl", "actuator_force", "sensordata",
                     "mocap_pos", "mocap_quat"):
            setattr(log, name, getattr(log, name)[: last + 1])
        r = log.reference
        log.reference = TrajectorySample(r.t[: last + 1], r.position[: last + 1],
                                         r.velocity[: last + 1], r.acceleration[: last + 1])
    if not log.warnings:
        log.warnings = warning_counts(data)
    return log


def run(name: str, setup: Setup, quiet: bool = True, profile: bool = False) -> RunResult:
    """Simulate ``setup`` (``profile``: see ``simulate``) and evaluate its checks."""
    start = time.perf_counter()
    log = simulate(setup, quiet=quiet, profile=profile)
    task, components, provenance = setup.task, setup.components, setup.provenance
    checks, metrics = task.evaluation.evaluate(log)
    checks = list(checks) + [
        divergence_check(log.warnings, log.diverged_at, log.divergence_message),
        controller_check(log.controller_error),
    ]
    wall = time.perf_counter() - start
    sim_time = float(log.t[-1])
    metrics = dict(metrics)
    metrics["physics_steps"] = log.physics_steps
    metrics["loop_wall_s"] = log.loop_wall_s
    planner = getattr(components.planner, "planner", components.planner)  # the one a RecordingPlanner holds
    roles = (("planner", planner), ("trajectory", components.trajectory), ("controller", components.controller),
             ("sensors", task.sensors), ("disturbance", task.disturbance))
    described = {role: None if obj is None else f"{type(obj).__module__}.{type(obj).__qualname__}"
                 for role, obj in roles}
    plant = provenance.plant
    return RunResult(name, provenance.seed, log, checks, metrics, sim_time, wall, described,
                     plugins=dict(provenance.plugins), sensors=task.sensors.describe(),
                     parameters=_resolved(setup), plant=None if plant is None else plant.to_dict())


def _resolved(setup: Setup) -> dict | None:
    params = setup.provenance.params
    if params is None:
        return None
    values = params.to_dict()
    if "duration" in values and values["duration"] is None:
        values["duration"] = float(setup.task.duration)
    return values
