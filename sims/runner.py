"""The runner: the control loop around MuJoCo, shared by every mechanism.

Per control tick it updates the task's sensors (``planbench.task.Sensors``: the observation),
calls the controller once with that observation (it writes or returns the actuator commands;
it never gets the physics, ``planbench.task``), applies the disturbance, lets MuJoCo take ``k``
physics steps with ``mj_step(model, data, nstep=k)`` and copies the state into the log's
chunk buffer, which streams to disk a chunk at a time (``planbench.logfile``). Everything else (the
planned motion, checks, rendering) works before or after the loop, on whole arrays or on the
log's chunks (``RunLog.chunks``).

Divergence (a NaN in the state, or any MuJoCo warning such as the bad-qacc reset) ends the
run early; the ``simulation_warnings`` check then fails with a message that says when and why.
So does a controller fault, ours or a user's: an exception raised by the controller, or a
non-finite command it wrote (found before MuJoCo steps with it), ends the run at that tick and
fails ``controller_errors`` with the exception's message or the command; the log up to it is
evaluated and written as usual.
"""

from __future__ import annotations

import tempfile
import time
import weakref
from dataclasses import dataclass, field
from functools import partial
from math import isfinite
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from tqdm import tqdm

from planbench import supervise
from planbench.checks import Check, controller_check, divergence_check
from planbench.logfile import (
    CHUNK_TICKS,
    LOG_FILE,
    ChunkWriter,
    LogFile,
    model_shapes,
    read_log,
    remove_quietly,
    temporary_writer,
)
from planbench.planners.trajectory import ChunkedSample, TrajectorySample
from planbench.task import (
    Components,
    ControlContext,
    Output,
    PluginError,
    Provenance,
    Task,
    check_controller,
    check_first_command,
    fault_text,
    sample_checked,
)

#: The arrays of MuJoCo's state that the log records with one ``mj_getState`` a tick, in its
#: order (``STATE_SPEC``): a row of the log's buffer block (``ChunkWriter(block=...)``).
STATE_ARRAYS = ("qpos", "qvel", "act", "mocap_pos", "mocap_quat")
STATE_SPEC = int(
    mujoco.mjtState.mjSTATE_QPOS
    | mujoco.mjtState.mjSTATE_QVEL
    | mujoco.mjtState.mjSTATE_ACT
    | mujoco.mjtState.mjSTATE_MOCAP_POS
    | mujoco.mjtState.mjSTATE_MOCAP_QUAT
)

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
      task: the ``planbench.task.Task`` (problem, sensors, disturbance, evaluation, timing),
        attached to ``physics`` (its initial state recorded).
      components: the planner, the trajectory and the controller (``planbench.task.Components``).
      output: how the files are written (``planbench.task.Output``).
      provenance: seed, parameters, plant and plug-ins (``planbench.task.Provenance``).
    """

    physics: Any  # a dm_control.mujoco.Physics (dm_control has no type information)
    task: Task
    components: Components
    output: Output = field(default_factory=Output)
    provenance: Provenance = field(default_factory=Provenance)

    def __post_init__(self):
        if self.task._initial_state is None:
            self.task.attach(self.physics)


class _Logged:
    """A per-tick array of RunLog: read from the run's log file (``RunLog.file``) on first
    use, or the array it was given."""

    def __set_name__(self, owner, name):
        self.name = name

    def __get__(self, log, owner=None) -> Any:
        if log is None:
            return None  # the dataclass default
        value = log.__dict__.get(self.name)
        if value is None and log.file is not None:
            value = log.__dict__[self.name] = log.file.column(self.name)
        return value

    def __set__(self, log, value):
        log.__dict__[self.name] = value


@dataclass
class RunLog:
    """State at every control tick (row i is the state at time ``t[i]``; row 0 is the start).

    Arrays: t (n,), qpos, qvel, act, ctrl, actuator_force, sensordata (n, size), mocap_pos
    and mocap_quat (n, nmocap, 3|4) when the model has mocap bodies. ``reference`` is the
    planned motion sampled at ``t`` (of a simulated run, a ``ChunkedSample``: its ``rows``
    sample a chunk of ticks, its arrays are sampled whole when first read). ``ctrl`` row i
    holds the controls applied from ``t[i]``; the last row, after which no physics runs, the
    controls still held there. ``contacts``
    lists (tick, geom1, geom2, distance) of every contact seen at a tick's end. ``n`` may be
    shorter than planned when the run diverged.

    A simulated run's arrays live in its log file (``file``, a ``planbench.logfile.LogFile``,
    streamed to disk as the run went): each is read whole on first use; ``file.chunks()``
    reads them a chunk at a time.
    """

    t: _Logged = _Logged()  # an np.ndarray when read
    qpos: _Logged = _Logged()  # an np.ndarray when read
    qvel: _Logged = _Logged()  # an np.ndarray when read
    act: _Logged = _Logged()  # an np.ndarray when read
    ctrl: _Logged = _Logged()  # an np.ndarray when read
    actuator_force: _Logged = _Logged()  # an np.ndarray when read
    sensordata: _Logged = _Logged()  # an np.ndarray when read
    mocap_pos: _Logged = _Logged()  # an np.ndarray when read
    mocap_quat: _Logged = _Logged()  # an np.ndarray when read
    reference: TrajectorySample | ChunkedSample | None = None
    contacts: list = field(default_factory=list)
    warnings: dict = field(default_factory=dict)
    diverged_at: float | None = None
    divergence_message: str = ""
    controller_error: tuple[float, str] | None = None
    physics_steps: int = 0
    loop_wall_s: float = 0.0
    controller_wall_s: float | None = None
    physics_wall_s: float | None = None
    file: LogFile | None = field(default=None, repr=False, compare=False)

    def held(self, name: str) -> bool:
        """Whether the array ``name`` is in memory (given, or read whole already)."""
        return self.__dict__.get(name) is not None

    @property
    def n(self) -> int:
        """Ticks logged."""
        return self.file.n if self.file is not None and not self.held("t") else len(self.t)

    def chunks(self, names, size: int = CHUNK_TICKS):
        """(first row, {name: rows}) for each chunk of the log in turn: the file's chunks
        (read one at a time), or, for a log held in memory, slices of ``size`` rows."""
        if self.file is not None and not any(self.held(name) for name in names):
            start = 0
            for part in self.file.chunks(list(names)):
                yield start, part
                start += part[names[0]].shape[0]
            return
        n = self.n
        for start in range(0, n, size):
            yield start, {name: getattr(self, name)[start : start + size] for name in names}

    def every(self, name: str, stride: int) -> np.ndarray | None:
        """Rows 0, stride, 2 stride, ... of the array ``name`` (None: a model without it) (``array[::stride]``), read a
        chunk at a time."""
        if self.file is None or self.held(name):
            value = getattr(self, name)
            return value if value is None else value[::stride]
        return self.file.every(name, stride)


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
            f"control period {control_dt} s is not a whole multiple of the model timestep {model.opt.timestep} s"
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
    (name, int(getattr(mujoco.mjtWarning, name))) for name in dir(mujoco.mjtWarning) if name.startswith("mjWARN_")
]


def _divergence(data, qpos, qvel, times, i: int, window: int, base: int = 0):
    """(time, message) if the state diverged in the ticks up to ``i``, else None. ``qpos``
    and ``qvel`` hold the run's rows from ``base`` on (the log's chunk buffer)."""
    lo = max(0, i - window)
    rows = slice(lo - base, i + 1 - base)
    if not (np.isfinite(qpos[rows]).all() and np.isfinite(qvel[rows]).all()):  # (the row only then)
        finite = np.isfinite(qpos[rows]).all(axis=1) & np.isfinite(qvel[rows]).all(axis=1)
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
    """A run's start, shared by ``simulate`` and the dm_control environments (``planbench.envs``):
    the control ticks, the reference sampled at them, the observation and the controller's
    context. ``start_episode`` makes it."""

    times: np.ndarray
    reference: ChunkedSample
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
    return data.ctrl[ids[0] : ids[-1] + 1], adr[adr >= 0]


def stored_reference(trajectory, times: np.ndarray) -> ChunkedSample:
    """``trajectory`` sampled at ``times``, a chunk of CHUNK_TICKS ticks at a time, each chunk
    stored in a temporary log (``planbench.logfile.temporary_writer``) and read back from it as it
    is asked for: the run holds a chunk, whatever its length, and samples once, before its
    first tick (a trajectory that cannot be sampled is bad input before any physics step)."""
    sample = partial(sample_checked, trajectory)
    writer = None
    for start in range(0, times.size, CHUNK_TICKS):
        part = sample(times[start : start + CHUNK_TICKS])
        arrays = {
            name: np.asarray(getattr(part, name), dtype=float) for name in ("position", "velocity", "acceleration")
        }
        if writer is None:
            shapes = {name: value.shape[1:] for name, value in arrays.items()}
            writer = temporary_writer(shapes, times, CHUNK_TICKS, prefix="planbench-reference-")
        writer.append(arrays)
    return ChunkedSample(sample, times, CHUNK_TICKS, None if writer is None else writer.read_back(times.size))


def start_episode(setup: Setup, seed: int | None = None) -> Episode:
    """Put ``setup`` at the start of its run: the task's episode (``Task.initialize_episode``:
    its sensors and disturbance seeded from ``seed``, default ``setup.provenance.seed``), then
    the online planner and the controller (its ``reset`` with the ControlContext, the drives'
    initial set-points it chose), and evaluate the physics."""
    physics, task, components = setup.physics, setup.task, setup.components
    model, data = physics.model.ptr, physics.data.ptr
    k = steps_per_tick(model, task.control_dt)
    times = task.times()
    reference = stored_reference(components.trajectory, times)
    controller = components.controller
    check_controller(controller)
    observation = task.initialize_episode(physics, times, setup.provenance.seed if seed is None else seed)
    command, act_adr = controlled_views(setup)
    visible = task.reference_visible
    planner = components.planner
    nominal_physics = task.nominal_physics
    if nominal_physics is None:  # Task.attach sets it (a Setup attaches its task)
        raise RuntimeError("the task is not attached to its physics: Task.attach(physics) first")
    context = ControlContext(
        model=nominal_physics().model.ptr,
        nominal_physics=nominal_physics,
        problem=task.problem,
        trajectory=components.trajectory if visible else None,
        reference=reference if visible else None,
        control_dt=task.control_dt,
        command=command,
        setpoint=data.act[act_adr].copy(),
        actuators=controlled_names(setup),
        observation=observation,
        sensors=tuple(task.sensors.specs),
        planner=planner if hasattr(planner, "step") else None,
    )
    # Before the first tick a plug-in that cannot start is bad input, not a failed run.
    if context.planner is not None:  # an online planner starts from the problem
        _start("planner", context.planner.reset, task.problem)
    _start("controller", controller.reset, context)
    data.act[act_adr] = context.setpoint
    mujoco.mj_forward(model, data)
    return Episode(times, reference, observation, context, k)


def simulate(
    setup: Setup,
    quiet: bool = True,
    progress_after_s: float = 2.0,
    profile: bool = False,
    log_path=None,
    chunk_ticks: int = CHUNK_TICKS,
) -> RunLog:
    """Run the control loop of ``setup`` and return its log.

    ``profile``: also time the code under test (the controller's calls, the online planner's
    updates inside them) and MuJoCo's steps (``RunLog.controller_wall_s``,
    ``physics_wall_s``); the rest of ``loop_wall_s`` is the testbed's own cost (sensors,
    disturbance, logging). Off, the loop reads no clock per tick.

    The log streams to ``log_path`` (``planbench.logfile``: a chunk of ``chunk_ticks`` ticks at a
    time; complete, with its footer, when this returns). None: to a temporary file, removed
    from the file system once the run is over (the returned log keeps it open)."""
    physics = setup.physics
    model, data = physics.model.ptr, physics.data.ptr
    episode = start_episode(setup)
    times, reference, observation, context = episode.times, episode.reference, episode.observation, episode.context
    k, n = episode.steps_per_tick, episode.times.size
    controller = setup.components.controller

    log = RunLog(reference=reference)
    temporary = log_path is None
    if temporary:
        log_path = Path(tempfile.mkdtemp(prefix="planbench-log-")) / LOG_FILE
    # Rows go to a chunk buffer (run row j is buffer row j - base); full chunks to the file.
    writer = ChunkWriter(
        log_path, model_shapes(model), times, chunk=chunk_ticks, history=SCAN_TICKS, block=STATE_ARRAYS
    )
    if temporary:  # also when the run raises
        weakref.finalize(writer, remove_quietly, log_path)
    buffers, state = writer.buffers, writer.block
    if state.shape[1] != mujoco.mj_stateSize(model, STATE_SPEC):
        raise RuntimeError("MuJoCo's state layout is not qpos, qvel, act, mocap_pos, mocap_quat")
    qpos, qvel, ctrl = buffers["qpos"], buffers["qvel"], buffers["ctrl"]
    frc, sens = buffers["actuator_force"], buffers["sensordata"]
    base, end = writer.base, writer.end
    get_state = mujoco.mj_getState
    # MuJoCo's arrays as views, looked up once (each attribute read makes a new one).
    ctrl_now, force_now, sensors_now = data.ctrl, data.actuator_force, data.sensordata

    def record(i: int) -> None:
        nonlocal base, end
        if i == end:
            writer.flush()
            base, end = writer.base, writer.end
        j = i - base
        get_state(model, data, state[j], STATE_SPEC)  # qpos, qvel, act and mocap in one copy
        frc[j] = force_now
        sens[j] = sensors_now

    record(0)
    initial_ctrl = ctrl_now.copy()
    task = setup.task
    observe, before_step = task.observe, task.before_step  # the same tick as planbench.envs'
    command_now = context.command
    contacts = []  # (tick, geoms (ncon, 2), distances (ncon,)) of every tick with contacts
    bar = tqdm(total=n - 1, unit="tick", delay=progress_after_s, disable=quiet, leave=False, desc="simulating")
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
                command_now[:] = command if i else check_first_command(command, command_now.size, context.actuators)
        except PluginError:
            raise
        except (Exception, SystemExit) as e:  # a controller's fault ends the run as a failed check
            log.controller_error = (float(times[i]), _exception_text(e))
            last = i
            break
        if profile:
            controller_wall += clock() - t0
        if not isfinite(sum(ctrl_now.tolist())):  # <1 us (numpy's sum: 2 us): no NaN command reaches MuJoCo
            if i == 0:
                raise PluginError(
                    _bad_command(model, data.ctrl, times[i]) + ", its first command (before any physics step)"
                )
            log.controller_error = (float(times[i]), _bad_command(model, data.ctrl, times[i]))
            last = i
            break
        before_step(i, physics)
        ctrl[i - base] = ctrl_now
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
            message = _divergence(data, qpos, qvel, times, i + 1, SCAN_TICKS, base)
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
        ctrl[last - base] = data.ctrl  # held at the end (no controller call there)
    else:  # the last good command, held
        ctrl[last - base] = ctrl[last - 1 - base] if last > 0 else initial_ctrl
    log.physics_steps = last * k
    log.contacts = [
        (tick, int(g1), int(g2), float(dist))
        for tick, geoms, dists in contacts
        for (g1, g2), dist in zip(geoms.tolist(), dists.tolist(), strict=True)
    ]
    writer.close(last + 1)  # the rows up to ``last`` and the footer: the log is complete
    log.file = read_log(log_path)
    if temporary:  # the open file keeps the data until the log is dropped
        remove_quietly(log_path)
    if last < n - 1 and log.reference is not None:
        log.reference = log.reference.head(last + 1)
    if not log.warnings:
        log.warnings = warning_counts(data)
    return log


def run(name: str, setup: Setup, quiet: bool = True, profile: bool = False, log_path=None) -> RunResult:
    """Simulate ``setup`` (``profile``, ``log_path``: see ``simulate``) and evaluate its checks."""
    start = time.perf_counter()
    log = simulate(setup, quiet=quiet, profile=profile, log_path=log_path)
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
    roles = (
        ("planner", planner),
        ("trajectory", components.trajectory),
        ("controller", components.controller),
        ("sensors", task.sensors),
        ("disturbance", task.disturbance),
    )
    described = {
        role: None if obj is None else f"{type(obj).__module__}.{type(obj).__qualname__}" for role, obj in roles
    }
    plant = provenance.plant
    return RunResult(
        name,
        provenance.seed,
        log,
        checks,
        metrics,
        sim_time,
        wall,
        described,
        plugins=dict(provenance.plugins),
        sensors=task.sensors.describe(),
        parameters=_resolved(setup),
        plant=None if plant is None else plant.to_dict(),
    )


def _resolved(setup: Setup) -> dict | None:
    params = setup.provenance.params
    if params is None:
        return None
    values = params.to_dict()
    if "duration" in values and values["duration"] is None:
        values["duration"] = float(setup.task.duration)
    return values
