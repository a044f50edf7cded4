"""Every check value of every scenario, recomputed independently from the written outputs.

A check is only as good as the code computing its value. For each
registered scenario these tests produce the outputs the public way (the scenario's
``build(scenario.resolve(...))``, ``planbench.runner.run``, ``planbench.outputs.write_run`` into a fresh
directory), then read back ONLY ``summary.json``, ``timeseries.npz`` and the compiled MuJoCo
model, and recompute each check's value from the logged physics (qpos, qvel, act, ctrl,
actuator_force, sensordata) with MuJoCo's own kinematics and actuator model
(``mj_kinematics`` / ``mj_fwdActuation`` on logged rows, ``mj_geomDistance``, ``mj_collision``).
The *reference* each check judges against comes from the planners' public functions (the
registry's ``plan()``, the satellite frame, the hexapod's target pivots, Table 1's key points),
never from the evaluation code (no ``setup.evaluate``, no evaluation class or helper of sims/).

Tolerances (relative unless said otherwise; each assertion states its own):
  * EXACT = 1e-9: the recomputation reads the very numbers the evaluation reads and applies
    the check's definition in other code (other summation order, other formula for the same
    angle): only floating-point round-off can separate them.
  * KIN = 1e-7: the evaluation uses the planners' closed-form kinematics of the logged joint
    angles; here MuJoCo's kinematics of the same rows through the compiled model (a chain of
    quaternion products: ~1e-15 rad apart, i.e. ~1e-12 of a 0.06 deg error).
  * LAW = 1e-6: FAST's cable_tension_max is the elastic-catenary law of each tick; here it is
    re-solved to convergence (the plant takes one Newton step per tick from the last tick's
    tension, which is quadratically converged: ~1e-12) with the span from the logged qpos'
    kinematics, one 2 ms physics step after the state the plant saw (the sag term changes by
    < 1e-8 of the tension).
Every tolerance is at least 1e5 times tighter than the 0.5x / 1.2x mis-scalings these tests
must catch; each test was shown to fail when its check's value is scaled so in the evaluation
code (mutation runs on a copy of the tree).

Check names per scenario are pinned from actual runs (``CHECKS``): a check added or dropped
without a recomputation here fails ``test_check_names``.
"""

from __future__ import annotations

import copy
import dataclasses
import json
import math

import mujoco
import numpy as np
import pytest

from planbench import antenna as antenna_sim
from planbench import fast as fast_sim
from planbench import hexapod as sim_hexapod
from planbench import outputs, runner, scenarios
from planbench.fast import physics as fast_physics
from planbench.planners import antenna as ant
from planbench.planners import hexapod as hexapod_planner
from planbench.planners.antenna.geostationary import look_angles
from planbench.planners.fast import plan as fp
from planbench.planners.fast import sky as sky

EXACT = 1e-9
KIN = 1e-7
LAW = 1e-6

#: The checks of every scenario, as summary.json lists them (from actual runs).
CHECKS = {
    "loader-supply": [
        "keypoint_error",
        "tracking_error",
        "obstacle_contacts",
        "min_clearance",
        "joint_torque",
        "simulation_warnings",
        "controller_errors",
    ],
    "loader-direct": [
        "keypoint_error",
        "tracking_error",
        "obstacle_contacts",
        "min_clearance",
        "joint_torque",
        "simulation_warnings",
        "controller_errors",
    ],
    "hexapod-sync-move": [
        "arrival_spread",
        "strut_velocity",
        "strut_accel",
        "hexapod_speed",
        "following_error",
        "pose_error_final",
        "strut_force",
        "stroke",
        "simulation_warnings",
        "controller_errors",
    ],
    "hexapod-async-move": [
        "arrival_vs_own_time",
        "strut_velocity",
        "strut_accel",
        "hexapod_speed",
        "following_error",
        "pose_error_final",
        "strut_force",
        "stroke",
        "simulation_warnings",
        "controller_errors",
    ],
    "antenna-paper-motion": [
        "pointing_error_max",
        "polarization_error_max",
        "attitude_error_fro_max",
        "joint_rate",
        "joint_torque",
        "simulation_warnings",
        "controller_errors",
    ],
    "antenna-sea-state": [
        "pointing_error_max",
        "pointing_error_rms",
        "polarization_error_max",
        "attitude_error_fro_max",
        "joint_rate",
        "joint_torque",
        "simulation_warnings",
        "controller_errors",
    ],
    **{
        name: [
            "feed_error_rms",
            "feed_error_max",
            "cabin_error_rms",
            "cable_tension_min",
            "cable_tension_max",
            "stewart_stroke",
            "stewart_force",
            "simulation_warnings",
            "controller_errors",
        ]
        for name in ("fast-tracking", "fast-ra-scan", "fast-source-switch")
    },
}

#: Simulated time per scenario (None: the scenario's default). The loader and hexapod runs are
#: whole (every key point reached; the hexapod's settling window of pose_error_final exists);
#: the antenna's are long enough for several ship-motion periods' worth of extremes; the FAST
#: scenarios begin with the ~57 s switch line from park, so a short run of theirs has no
#: observing segment (their checks then fall back to the whole run, tested here) and the
#: observing windows are tested on the short plans of ``fast_observation`` and ``fast_scan``.
#: All stay under FAST's 120 s, beyond which timeseries.npz keeps only every 10th tick.
DURATIONS = {
    "loader-supply": None,
    "loader-direct": None,
    "hexapod-sync-move": None,
    "hexapod-async-move": None,
    "antenna-paper-motion": 12.0,
    "antenna-sea-state": 20.0,
    "fast-tracking": 3.0,
    "fast-ra-scan": 3.0,
    "fast-source-switch": 3.0,
}


class Written:
    """What a run wrote, read back: summary.json, timeseries.npz, and the compiled model."""

    def __init__(self, out_dir, model: mujoco.MjModel, plan, duration: float):
        self.summary = json.loads((out_dir / "summary.json").read_text())
        with np.load(out_dir / "timeseries.npz") as z:
            self.ts = {k: z[k] for k in z.files}
        self.model = model
        self._plan = plan  # the planned motion (or a function giving it), from the planners
        self.duration = duration  # the simulated time asked for

    @property
    def plan(self):
        if callable(self._plan) and not hasattr(self._plan, "sample"):
            self._plan = self._plan()
        return self._plan

    def check(self, name: str) -> float:
        """The value summary.json reports for check ``name`` (a float: never NaN here)."""
        entry = next(c for c in self.summary["checks"] if c["name"] == name)
        value = entry["value"]
        assert isinstance(value, (int, float)) and math.isfinite(value), f"{name} = {value!r}"
        return float(value)

    @property
    def t(self) -> np.ndarray:
        return self.ts["t"]

    def qpos_of(self, joints) -> np.ndarray:
        """(n, len(joints)) logged positions of 1-dof joints, by name through the model."""
        return self.ts["qpos"][:, [self.model.joint(j).qposadr[0] for j in joints]]

    def qvel_of(self, joints) -> np.ndarray:
        return self.ts["qvel"][:, [self.model.joint(j).dofadr[0] for j in joints]]

    def sensor(self, name: str) -> np.ndarray:
        s = self.model.sensor(name)
        return self.ts["sensordata"][:, s.adr[0] : s.adr[0] + s.dim[0]]


def write(tmp_path_factory, name: str, setup, duration: float, plan, model=None) -> Written:
    """Run ``setup``, write its outputs into a new directory and read them back."""
    result = runner.run(name, setup)
    out = tmp_path_factory.mktemp(name.replace(" ", "-")) / "out"  # not yet existing
    summary = outputs.write_run(result, setup, out)
    assert "timeseries_every_s" not in summary  # every tick written: the checks' own ticks
    if model is None:
        model = copy.copy(setup.physics.model.ptr)
    return Written(out, model, plan, duration)


def scenario_run(tmp_path_factory, name: str) -> Written:
    scenario = scenarios.get(name)
    setup = scenario.build(scenario.resolve(duration=DURATIONS[name]))
    # FAST's cable actuators are re-linearized (or, with the chains, re-sprung) in the run's
    # model every tick: read FAST runs with the compiled model of their cables (the same
    # sensors, sites and leg drives).
    model = fast_physics._compiled(setup.provenance.params.cable_segments) if name.startswith("fast") else None
    return write(tmp_path_factory, name, setup, setup.task.duration, lambda: scenario.plan(scenario.params), model)


def scenario_fixture(name: str):
    """A module-scoped fixture of the scenario ``name``'s run (``scenario_run``)."""

    @pytest.fixture(scope="module")
    def run(tmp_path_factory) -> Written:
        return scenario_run(tmp_path_factory, name)

    return run


@pytest.fixture(scope="module", params=list(scenarios.SCENARIOS))
def any_run(request, tmp_path_factory):
    return request.getfixturevalue(_FIXTURE[request.param])


def test_every_registered_scenario_has_its_checks_pinned():
    """A scenario added to the registry is recomputed here too: its check names, its run's
    length and its fixture are pinned before the suite passes."""
    registered = set(scenarios.SCENARIOS)
    for table in (CHECKS, DURATIONS, _FIXTURE):
        assert registered <= set(table), sorted(registered - set(table))


# ---------------------------------------------------------------- MuJoCo on logged rows


def kinematics_rows(model: mujoco.MjModel, qpos: np.ndarray, read) -> np.ndarray:
    """``read(data)`` after ``mj_kinematics`` of every logged qpos row, stacked."""
    data = mujoco.MjData(model)
    out = []
    for row in qpos:
        data.qpos[:] = row
        mujoco.mj_kinematics(model, data)
        out.append(np.array(read(data), dtype=float))
    return np.array(out)


def unclamped_actuator_forces(model: mujoco.MjModel, w: Written, actuators) -> np.ndarray:
    """(n, len(actuators)) the force MuJoCo's actuator model gives on each logged row
    (qpos, qvel, act) with the force clamp switched off: the demanded force."""
    model = copy.copy(model)
    model.actuator_forcelimited[:] = 0
    data = mujoco.MjData(model)
    ids = [model.actuator(a).id for a in actuators]
    out = np.empty((w.t.size, len(ids)))
    for i in range(w.t.size):
        data.qpos[:] = w.ts["qpos"][i]
        data.qvel[:] = w.ts["qvel"][i]
        data.act[:] = w.ts["act"][i]
        data.ctrl[:] = w.ts["ctrl"][i]
        mujoco.mj_fwdPosition(model, data)
        mujoco.mj_fwdVelocity(model, data)
        mujoco.mj_fwdActuation(model, data)
        out[i] = data.actuator_force[ids]
    return out


def force_limit(model: mujoco.MjModel, actuators) -> np.ndarray:
    """The upper end of each actuator's force range (the drive limit), from the model."""
    return np.array([model.actuator_forcerange[model.actuator(a).id, 1] for a in actuators])


def rms(x) -> float:
    x = np.asarray(x, dtype=float).ravel()
    return math.sqrt(math.fsum(x * x) / x.size)


def assert_value(w: Written, name: str, recomputed: float, rtol: float, atol: float = 0.0):
    reported = w.check(name)
    assert reported == pytest.approx(recomputed, rel=rtol, abs=atol), (
        f"{w.summary['scenario']} {name}: summary.json says {reported!r}, recomputed {recomputed!r}"
    )


# ============================================================================ loader


loader_supply = scenario_fixture("loader-supply")


loader_direct = scenario_fixture("loader-direct")


@pytest.fixture(params=["loader-supply", "loader-direct"])
def loader(request):
    return request.getfixturevalue(_FIXTURE[request.param])


def _loader_joints(w: Written):
    names = [str(n) for n in w.ts["joint_names"]]
    hinge = np.array([w.model.jnt_type[w.model.joint(n).id] == mujoco.mjtJoint.mjJNT_HINGE for n in names])
    return names, hinge


def _collision_geoms(model):
    """(robot, obstacles): collidable geoms on moving bodies / welded to the world."""
    collides = (model.geom_contype | model.geom_conaffinity) > 0
    on_world = model.body_weldid[model.geom_bodyid] == 0
    return np.flatnonzero(collides & ~on_world), np.flatnonzero(collides & on_world)


def test_loader_keypoint_error(loader):
    """Largest angle error (deg) of the five revolute joints at the key times (Table 1's P2,
    M1 ... M4, P3; the direct move's P2 and P3), from the logged qpos at those ticks."""
    w = loader
    names, hinge = _loader_joints(w)
    q = w.qpos_of(names)
    errors = []
    for t_key, point in zip(w.plan.key_times, w.plan.key_points, strict=True):
        assert t_key <= w.t[-1] + 1e-9  # every key point is reached in these whole runs
        i = int(np.argmin(np.abs(w.t - t_key)))
        assert abs(w.t[i] - t_key) < 1e-9  # key times are control ticks
        errors.append(np.abs(q[i, hinge] - point[hinge]))
    assert_value(w, "keypoint_error", float(np.degrees(np.max(errors))), EXACT)


def test_loader_tracking_error(loader):
    """Largest |q - q_planned| (deg) of the revolute joints over the whole run; the plan is
    the planner's spline sampled at the logged times."""
    w = loader
    names, hinge = _loader_joints(w)
    ref = w.plan.sample(w.t).position
    value = np.degrees(np.abs(w.qpos_of(names)[:, hinge] - ref[:, hinge]).max())
    assert_value(w, "tracking_error", float(value), EXACT)


def test_loader_obstacle_contacts(loader):
    """Robot-obstacle geom pairs that touched during the run: MuJoCo's collision detection on
    every logged pose (the runner records the contacts of each tick's last physics step,
    0.5 ms before the logged pose; every contact of these runs lasts many ticks, so the sets
    of pairs agree exactly)."""
    w = loader
    robot, obstacles = (set(g.tolist()) for g in _collision_geoms(w.model))
    model = w.model
    data = mujoco.MjData(model)
    pairs = set()
    for row in w.ts["qpos"]:
        data.qpos[:] = row
        mujoco.mj_kinematics(model, data)
        mujoco.mj_collision(model, data)
        for c in data.contact[: data.ncon]:
            g1, g2 = int(c.geom1), int(c.geom2)
            if g1 in obstacles and g2 in robot:
                g1, g2 = g2, g1
            if g1 in robot and g2 in obstacles:
                pairs.add((g1, g2))
    assert_value(w, "obstacle_contacts", float(len(pairs)), 0.0)
    if w.summary["scenario"] == "loader-direct":  # the failure the scenario demonstrates
        assert len(pairs) >= 2


def test_loader_min_clearance(loader):
    """Smallest signed distance (m) between robot and obstacle geoms over the logged poses
    (``mj_geomDistance``, searched up to 0.5 m as the check's note says)."""
    w = loader
    robot, obstacles = _collision_geoms(w.model)
    model = w.model
    data = mujoco.MjData(model)
    best = 0.5
    fromto = np.zeros(6)
    for row in w.ts["qpos"]:
        data.qpos[:] = row
        mujoco.mj_kinematics(model, data)
        for r in robot:
            for o in obstacles:
                best = min(best, mujoco.mj_geomDistance(model, data, int(r), int(o), 0.5, fromto))
    assert_value(w, "min_clearance", best, EXACT)
    expect = w.summary["scenario"] == "loader-supply"
    assert (best > 0) == expect  # the supply path clears, the direct move strikes


def test_loader_joint_torque(loader):
    """Largest demanded drive force / drive limit: MuJoCo's actuator model on every logged
    (qpos, qvel, act) with the force clamp off, over the force range of the model."""
    w = loader
    names, _ = _loader_joints(w)
    demanded = unclamped_actuator_forces(w.model, w, names)
    value = (np.abs(demanded) / force_limit(w.model, names)).max()
    assert_value(w, "joint_torque", float(value), EXACT)


# ============================================================================ hexapod


hexapod_sync = scenario_fixture("hexapod-sync-move")


hexapod_async = scenario_fixture("hexapod-async-move")


@pytest.fixture(scope="module")
def hexapod_sync_driven_async(tmp_path_factory):
    """hexapod-sync-move with its trajectory replaced by the asynchronous planner's move (a
    user's planner plugged in): the sync scenario's arrival_spread is then not 0 (the struts
    arrive over ~5 s), so a mis-scaled spread shows."""
    setup = scenarios.get("hexapod-sync-move").build(scenarios.get("hexapod-sync-move").resolve(duration=1.0))
    [problem] = sim_hexapod.problems(scenarios.get("hexapod-sync-move").params)
    plan = hexapod_planner.PaperMovePlanner().plan(dataclasses.replace(problem, synchronous=False))
    setup.components.trajectory = plan
    setup.task.duration = plan.duration + 1.0
    return write(tmp_path_factory, "hexapod-sync-driven-async", setup, setup.task.duration, plan)


@pytest.fixture(params=["hexapod-sync-move", "hexapod-async-move"])
def hexapod(request):
    return request.getfixturevalue(_FIXTURE[request.param])


STRUTS = [f"strut{i}" for i in range(1, 7)]


def _arrivals(w: Written):
    """(6,) when each strut's planned motion comes to rest on its final value for good (the
    tick after the last one at which it is elsewhere or moving), and which struts move."""
    ref = w.plan.sample(w.t)
    final = ref.position[-1]
    out = np.zeros(6)
    for j in range(6):
        busy = np.flatnonzero((ref.position[:, j] != final[j]) | (ref.velocity[:, j] != 0.0))
        out[j] = w.t[min(busy[-1] + 1, w.t.size - 1)] if busy.size else 0.0
    return out, ref.position[-1] != ref.position[0]


def test_hexapod_strut_names(hexapod):
    assert [str(n) for n in hexapod.ts["strut_names"]] == STRUTS


def test_hexapod_arrival_spread(hexapod_sync, hexapod_sync_driven_async):
    """Last minus first strut arrival (s) of the commanded motion: 0 for the synchronous
    planner (all on one tick), ~5 s for the asynchronous one plugged into the same scenario."""
    for w in (hexapod_sync, hexapod_sync_driven_async):
        arrivals, moving = _arrivals(w)
        spread = float(arrivals[moving].max() - arrivals[moving].min())
        assert_value(w, "arrival_spread", spread, EXACT, atol=1e-12)
    assert hexapod_sync.check("arrival_spread") == 0.0
    assert hexapod_sync_driven_async.check("arrival_spread") > 1.0


def test_hexapod_arrival_vs_own_time(hexapod_async):
    """Largest arrival - own time (s, one-sided) over the moving struts; the own time of each
    strut is the planner's 2 T_i (the move's profiles), the arrival is read off the sampled plan."""
    w = hexapod_async
    arrivals, moving = _arrivals(w)
    own = 2.0 * np.asarray(w.plan.profiles.half_time)
    late = float((arrivals - own)[moving].max())
    assert_value(w, "arrival_vs_own_time", late, EXACT)
    assert late > 0  # nonzero here, so a mis-scaled value shows


def test_hexapod_commanded_strut_velocity_and_accel(hexapod):
    """The generator's peak commanded strut speed (um/s) and acceleration (um/s^2) over the
    run: the planned motion sampled at the logged ticks."""
    w = hexapod
    ref = w.plan.sample(w.t)
    assert_value(w, "strut_velocity", 1e6 * float(np.abs(ref.velocity).max()), EXACT)
    assert_value(w, "strut_accel", 1e6 * float(np.abs(ref.acceleration).max()), EXACT)


def test_hexapod_following_error(hexapod):
    """Largest |encoder - planned strut position| (um) while the move lasts (up to the last
    strut's arrival); the encoders are the struts' slide joints in the logged qpos."""
    w = hexapod
    arrivals, _ = _arrivals(w)
    during = w.t <= arrivals.max() + 1e-9
    assert during.sum() < w.t.size  # the settling after the move is left out
    error = np.abs(w.qpos_of(STRUTS) - w.plan.sample(w.t).position)[during]
    assert_value(w, "following_error", 1e6 * float(error.max()), EXACT)


def test_hexapod_pose_error_final(hexapod):
    """Largest distance (um) of the six mirror-side pivots from where the target pose puts
    them, over the run's last 0.25 s: the pivots are the model's platform_pivot sites after
    mj_kinematics of each logged row, in the hexapod frame (body top_end); the target pivots
    are the planner's ``pivot_positions`` of the planned target pose."""
    w = hexapod
    assert w.t[-1] >= _arrivals(w)[0].max() + 1.0 - 1e-9  # the run includes the settling
    window = w.t >= w.t[-1] - 0.25 - 1e-9
    model = w.model
    sites = [model.site(f"platform_pivot{i}").id for i in range(1, 7)]
    top = model.body("top_end").id

    def pivots(data):
        rotation = data.xmat[top].reshape(3, 3)
        return (data.site_xpos[sites] - data.xpos[top]) @ rotation

    actual = kinematics_rows(model, w.ts["qpos"][window], pivots)
    wanted = hexapod_planner.pivot_positions(w.plan.target_pose)
    value = 1e6 * np.linalg.norm(actual - wanted, axis=-1).max()
    # Nanometre-scale errors on 2.6 m lever arms: MuJoCo's and the planner's pose chains
    # agree to ~1e-15 m, ~1e-9 of the sub-micrometre value.
    assert_value(w, "pose_error_final", float(value), 1e-6)


def test_hexapod_strut_force(hexapod):
    """Peak demanded strut drive force (N): MuJoCo's actuator model on the logged rows with
    the clamp off. The check's limit is the smallest force range of the struts."""
    w = hexapod
    demanded = unclamped_actuator_forces(w.model, w, STRUTS)
    assert_value(w, "strut_force", float(np.abs(demanded).max()), EXACT)
    limit = next(c["limit"] for c in w.summary["checks"] if c["name"] == "strut_force")
    assert limit == force_limit(w.model, STRUTS).min()


def test_hexapod_stroke(hexapod):
    """Largest |strut length change| (mm) measured by the encoders (logged qpos)."""
    w = hexapod
    assert_value(w, "stroke", 1e3 * float(np.abs(w.qpos_of(STRUTS)).max()), EXACT)


# ============================================================================ antenna


antenna_paper = scenario_fixture("antenna-paper-motion")


antenna_sea = scenario_fixture("antenna-sea-state")


@pytest.fixture(params=["antenna-paper-motion", "antenna-sea-state"])
def antenna(request):
    return request.getfixturevalue(_FIXTURE[request.param])


ANTENNA_JOINTS = ["azimuth", "elevation", "cross_elevation", "polarization"]


def _satellite_angles(name: str):
    """(azimuth, elevation, polarization) rad of the scenario's satellite: the paper's
    section 5.1 values, or the look angles of the geostationary slot from the ship."""
    if name == "antenna-paper-motion":
        return np.radians(ant.PAPER_SATELLITE_DEG)
    return look_angles(
        np.radians(antenna_sim.SATELLITE_LON_DEG),
        np.radians(antenna_sim.SHIP_LAT_DEG),
        np.radians(antenna_sim.SHIP_LON_DEG),
    )


def _antenna_errors(w: Written):
    """(pointing, polarization) errors in rad at every logged tick, from MuJoCo's dish site.

    Pointing: the angle between the dish's boresight (site z axis in the world, East-North-Up)
    and the direction of the satellite, (cos El sin Az, cos El cos Az, sin El), as the chord
    formula 2 asin(|a - b| / 2). Polarization: turn the dish by the smallest rotation that
    lays its boresight on the satellite's (Rodrigues), then the angle about that boresight
    from the satellite frame's x axis to the dish's.
    """
    az, el, pol = _satellite_angles(w.summary["scenario"])
    reported = w.summary["metrics"]["satellite_az_el_pol_deg"]
    np.testing.assert_allclose(reported, np.degrees([az, el, pol]), atol=1e-4)  # same satellite
    satellite = ant.satellite_attitude(az, el, pol)
    target = np.array([math.cos(el) * math.sin(az), math.cos(el) * math.cos(az), math.sin(el)])
    np.testing.assert_allclose(satellite[:, 2], target, atol=1e-15)
    site = w.model.site("dish").id
    dish = kinematics_rows(w.model, w.ts["qpos"], lambda d: d.site_xmat[site].reshape(3, 3))
    z = dish[:, :, 2]
    pointing = 2.0 * np.arcsin(np.clip(np.linalg.norm(z - target, axis=1) / 2.0, 0.0, 1.0))
    axis = np.cross(z, target)
    sin, cos = np.linalg.norm(axis, axis=1, keepdims=True), z @ target
    k = axis / np.where(sin > 0, sin, 1.0)
    x = dish[:, :, 0]  # Rodrigues' formula turns it with the boresight onto the target:
    x = x * cos[:, None] + np.cross(k, x) * sin + k * (k * x).sum(axis=1, keepdims=True) * (1.0 - cos[:, None])
    x_s = satellite[:, 0]
    twist = np.arctan2(np.cross(x_s, x) @ target, x @ x_s)
    return pointing, twist


@pytest.fixture(scope="module")
def antenna_errors(antenna_paper, antenna_sea):
    return {w.summary["scenario"]: _antenna_errors(w) for w in (antenna_paper, antenna_sea)}


def test_antenna_pointing_error_max(antenna, antenna_errors):
    """Largest angle (deg) between boresight and satellite over the run."""
    pointing, _ = antenna_errors[antenna.summary["scenario"]]
    assert_value(antenna, "pointing_error_max", float(np.degrees(pointing.max())), KIN)


def test_antenna_pointing_error_rms(antenna_sea, antenna_errors):
    """RMS (deg) of the pointing error over every logged tick (sea state only)."""
    pointing, _ = antenna_errors["antenna-sea-state"]
    assert_value(antenna_sea, "pointing_error_rms", rms(np.degrees(pointing)), KIN)


def test_antenna_polarization_error_max(antenna, antenna_errors):
    """Largest |twist about the boresight| (deg) between dish and satellite frame."""
    _, twist = antenna_errors[antenna.summary["scenario"]]
    assert_value(antenna, "polarization_error_max", float(np.degrees(np.abs(twist).max())), KIN)


def test_antenna_attitude_error_fro_max(antenna):
    """The planner's own ||f(Theta) - N||_F, largest over its updates. N (the attitude the
    controller asked for: its noisy, predicted IMU reading times eTs) is not written, so this
    can only be checked against the per-update log in timeseries.npz (update_error_fro), not
    recomputed from physics; it also checks that there is one update per IMU sample."""
    w = antenna
    errors = w.ts["update_error_fro"]
    assert errors.size == w.ts["update_t"].size
    rate = w.summary["metrics"]["imu_rate_hz"]
    assert abs(errors.size - w.t[-1] * rate) <= 2
    assert_value(w, "attitude_error_fro_max", float(errors.max()), EXACT)


def test_antenna_joint_rate(antenna):
    """Largest measured joint speed (logged qvel) over its rated speed (the drive's set-point
    rate range in the model)."""
    w = antenna
    qd = w.qvel_of(ANTENNA_JOINTS)
    rated = np.array([w.model.actuator_ctrlrange[w.model.actuator(j).id, 1] for j in ANTENNA_JOINTS])
    assert_value(w, "joint_rate", float((np.abs(qd) / rated).max()), EXACT)


def test_antenna_joint_torque(antenna):
    """Largest demanded drive torque / drive limit: MuJoCo's actuator model on every logged
    row with the clamp off."""
    w = antenna
    demanded = unclamped_actuator_forces(w.model, w, ANTENNA_JOINTS)
    value = (np.abs(demanded) / force_limit(w.model, ANTENNA_JOINTS)).max()
    assert_value(w, "joint_torque", float(value), EXACT)


# ============================================================================ FAST


fast_tracking = scenario_fixture("fast-tracking")


fast_ra_scan = scenario_fixture("fast-ra-scan")


fast_source_switch = scenario_fixture("fast-source-switch")


def _short_scan_plan() -> fp.FastPlan:
    """A small motion scan along RA (2 legs of 0.02 deg at 15 deg/h, 3 arcmin apart, the
    shortest t2) with its start and termination: legs and a transition in ~22 s."""
    ra, dec = fast_sim.SOURCES["3C 286"]
    jd1, jd2 = sky.meridian_transit(ra, dec, fast_sim.OBSERVING_NIGHT)

    def make(t2):
        return sky.MotionScan(ra, dec, "dec", np.radians(0.02), 2, np.radians(0.05), 15.0 * sky.DEG_PER_HOUR, t2)

    t2 = fp.minimum_t2(make, (jd1, jd2))
    segments, _, _ = fp.scan_segments(make(t2), (jd1, jd2))
    return fp.FastPlan([fp.start_segment(segments[0])] + segments + [fp.termination_segment(segments[-1])])


@pytest.fixture(scope="module")
def fast_observation(tmp_path_factory):
    """The tests' short FAST run (tests/test_fast_physics.py): start, 10 s of tracking,
    termination, 4 m/s wind, Stewart on; its observing window is the middle 10 s."""
    plan = fast_sim.observation_plan(10.0)
    setup = fast_sim.build(plan, fast_sim.FastParams(wind=4.0))
    return write(
        tmp_path_factory,
        "fast-observation",
        setup,
        setup.task.duration,
        plan,
        fast_physics._compiled(setup.provenance.params.cable_segments),
    )


@pytest.fixture(scope="module")
def fast_scan(tmp_path_factory):
    """A short motion scan: its observing window is the legs and the transition between."""
    plan = _short_scan_plan()
    setup = fast_sim.build(plan, fast_sim.FastParams(wind=4.0, seed=1))
    return write(
        tmp_path_factory,
        "fast-scan",
        setup,
        setup.task.duration,
        plan,
        fast_physics._compiled(setup.provenance.params.cable_segments),
    )


FAST_RUNS = ["fast-tracking", "fast-ra-scan", "fast-source-switch", "fast-observation", "fast-scan"]


@pytest.fixture(params=FAST_RUNS)
def fast_run(request):
    return request.getfixturevalue(_FIXTURE[request.param])


CABLES = [f"cable{i}" for i in range(1, 7)]
LEGS = [f"leg{i}" for i in range(1, 7)]
OBSERVING = ("observation", "leg", "transition")  # the segments where the feed must hold


def _observing_window(w: Written):
    """(n,) the ticks inside the plan's observing segments (observations, scan legs and
    their transitions), from the segments' names and times; the whole run if none."""
    inside = np.zeros(w.t.size, bool)
    for k, seg in enumerate(w.plan.segments):
        last = k == len(w.plan.segments) - 1
        end = seg.t0 + seg.duration
        during = (w.t >= seg.t0) & ((w.t < end) | (last & (w.t >= end)))
        if seg.name.startswith(OBSERVING):
            inside |= during
    return inside if inside.any() else np.ones(w.t.size, bool), bool(inside.any())


def test_fast_observing_window(fast_run):
    """The window really is what each run should judge: none in the scenarios' first seconds
    (their switch from park), the observation or the scan's legs and transition otherwise."""
    w = fast_run
    window, observing = _observing_window(w)
    names = {seg.name for seg in w.plan.segments if seg.t0 <= w.t[-1] and seg.name.startswith(OBSERVING)}
    assert observing == (w.summary["scenario"] not in CHECKS)
    if w.summary["scenario"] == "fast-scan":
        assert {"leg 1", "leg 2", "transition 1"} <= names
    np.testing.assert_array_equal(window, w.ts["observing"] if observing else np.ones(w.t.size, bool))
    note = next(c["note"] for c in w.summary["checks"] if c["name"] == "feed_error_max")
    assert ("no observing segment" in note) == (not observing)


def test_fast_feed_error_rms_and_max(fast_run):
    """RMS and largest distance (mm) of the feed (the model's feed_pos sensor: the feed site
    in the world) from its planned position (the plan sampled at the logged ticks), over the
    observing window."""
    w = fast_run
    window, _ = _observing_window(w)
    planned = w.plan.state(w.t).feed
    error_mm = 1e3 * np.linalg.norm(w.sensor("feed_pos") - planned, axis=1)[window]
    assert_value(w, "feed_error_rms", rms(error_mm), EXACT)
    assert_value(w, "feed_error_max", float(error_mm.max()), EXACT)


def test_fast_cabin_error_rms(fast_run):
    """RMS distance (mm) of the cabin origin (cabin_pos sensor) from the planned cabin pose's
    origin (``FastPlan.state``), over the observing window."""
    w = fast_run
    window, _ = _observing_window(w)
    planned = w.plan.state(w.t).cabin_origin
    error_mm = 1e3 * np.linalg.norm(w.sensor("cabin_pos") - planned, axis=1)[window]
    assert_value(w, "cabin_error_rms", rms(error_mm), EXACT)


def test_fast_cable_tension_min(fast_run):
    """Lowest cable tension (kN) over the run: minus the logged force of the six cable
    actuators (a cable only pulls)."""
    w = fast_run
    force = w.ts["actuator_force"][:, [w.model.actuator(c).id for c in CABLES]]
    assert (force <= 0).all()
    assert_value(w, "cable_tension_min", float(-force.max()) / 1e3, EXACT)


def _catenary_tension(chord, l0, span):
    """The elastic catenary's tension (N) for chord ``chord``, unstretched length ``l0`` and
    horizontal span ``span`` (m): the root of L0 (1 + T / EA) - w^2 l_h^2 L0 / (24 T^2) = L
    (Irvine; models/fast/README.md), by bisection then Newton to convergence."""
    ea, weight = fast_physics.CABLE_EA, fast_physics.CABLE_WEIGHT
    a = (weight * span) ** 2 * l0 / 24.0

    def f(t):
        return l0 * (1.0 + t / ea) - a / t**2 - chord

    lo, hi = np.full_like(chord, 1e3), np.full_like(chord, 1e7)
    assert (f(lo) < 0).all() and (f(hi) > 0).all()
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        low = f(mid) < 0
        lo, hi = np.where(low, mid, lo), np.where(low, hi, mid)
    t = 0.5 * (lo + hi)
    for _ in range(3):
        t = t - f(t) / (l0 / ea + 2.0 * a / t**3)
    return t


def test_fast_cable_tension_max(fast_run):
    """Highest cable tension (kN) before the winch's clamp. Chains: the winch segment's spring
    at its length in each logged pose. Lumped cables: the catenary law
    re-solved at every tick the plant applied it (all but the last, where no physics runs),
    with the chord from the cable-length sensors (the state the plant saw), the winch's
    unstretched length from the logged ctrl and the span from the logged pose's kinematics."""
    w = fast_run
    model = w.model
    l0 = w.ts["ctrl"][:, [model.actuator(c).id for c in CABLES]]
    segments = w.summary["parameters"]["cable_segments"]
    if segments:
        # The chains: the winch's segment, a spring EA / (L0 / n) of rest length L0 / n
        # (ChainCableLoads), at its length in the logged pose.
        first = [model.tendon(f"{c}_seg1").id for c in CABLES]
        length = kinematics_rows(
            model, w.ts["qpos"][:-1], lambda d: (mujoco.mj_fwdPosition(model, d), d.ten_length[first])[1]
        )
        rest = l0[:-1] / segments
        tension = np.maximum(fast_physics.CABLE_EA / rest * (length - rest), 0.0)
        assert_value(w, "cable_tension_max", float(tension.max()) / 1e3, LAW)
        return
    towers = [model.site(f"tower{i}_top").id for i in range(1, 7)]
    anchors = [model.site(f"anchor{i}").id for i in range(1, 7)]
    vectors = kinematics_rows(model, w.ts["qpos"], lambda d: d.site_xpos[anchors] - d.site_xpos[towers])
    span = np.hypot(vectors[..., 0], vectors[..., 1])
    chord = np.column_stack([w.sensor(f"{c}_length")[:, 0] for c in CABLES])
    tension = _catenary_tension(chord[:-1], l0[:-1], span[:-1])
    assert_value(w, "cable_tension_max", float(tension.max()) / 1e3, LAW)


def test_fast_stewart_stroke(fast_run):
    """Largest Stewart leg change (mm), measured (the leg joints in the logged qpos) or
    commanded (the legs' drive set-points, their activations in the logged act)."""
    w = fast_run
    model = w.model
    setpoints = w.ts["act"][:, [model.actuator(f"leg{i}").actadr[0] for i in range(1, 7)]]
    stroke = max(np.abs(w.qpos_of(LEGS)).max(), np.abs(setpoints).max())
    assert_value(w, "stewart_stroke", 1e3 * float(stroke), EXACT)


def test_fast_stewart_force(fast_run):
    """Peak demanded Stewart leg force (kN): MuJoCo's actuator model (the compiled model's leg
    drives) on every logged row with the clamp off."""
    w = fast_run
    demanded = unclamped_actuator_forces(w.model, w, LEGS)
    assert_value(w, "stewart_force", float(np.abs(demanded).max()) / 1e3, EXACT)


# ============================================================================ all runs


@pytest.fixture(scope="module")
def diverging_loader(tmp_path_factory):
    """loader-supply in a gravity of 1e12 m/s^2: the accelerations pass MuJoCo's 1e10 at the
    first step, it warns (bad qacc) and resets, and the runner ends the run at its divergence
    scan. (A non-finite command would be the controller's fault and never reach MuJoCo:
    ``faulty_loader``.)"""
    setup = scenarios.get("loader-supply").build(scenarios.get("loader-supply").resolve(duration=0.5))
    setup.physics.model.ptr.opt.gravity[:] = [0.0, 0.0, -1e12]
    return write(
        tmp_path_factory,
        "loader-diverging",
        setup,
        setup.task.duration,
        scenarios.get("loader-supply").plan(scenarios.get("loader-supply").params),
    )


FAULT_TICK = 40


@pytest.fixture(scope="module")
def faulty_loader(tmp_path_factory):
    """loader-supply with a user's controller that raises at tick FAULT_TICK."""
    setup = scenarios.get("loader-supply").build(scenarios.get("loader-supply").resolve(duration=0.5))
    inner = setup.components.controller

    class RaisingController:
        def reset(self, context):
            inner.reset(context)

        def __call__(self, tick, observation):
            if tick == FAULT_TICK:
                raise ZeroDivisionError("gain schedule hit 0")
            inner(tick, observation)

    setup.components.controller = RaisingController()
    return write(
        tmp_path_factory,
        "loader-faulty",
        setup,
        setup.task.duration,
        scenarios.get("loader-supply").plan(scenarios.get("loader-supply").params),
    )


def _replayed_warnings(w: Written) -> int:
    """MuJoCo warnings of the run, replayed: every logged tick's state and ctrl stepped
    through the control period again, the warning counters summed."""
    model = w.model
    data = mujoco.MjData(model)
    k = int(round((w.t[1] - w.t[0]) / model.opt.timestep))
    total = 0
    for i in range(w.t.size - 1):
        mujoco.mj_resetData(model, data)
        data.time = w.t[i]
        data.qpos[:] = w.ts["qpos"][i]
        data.qvel[:] = w.ts["qvel"][i]
        data.act[:] = w.ts["act"][i]
        data.ctrl[:] = w.ts["ctrl"][i]
        mujoco.mj_step(model, data, nstep=k)
        total += sum(int(data.warning[j].number) for j in range(len(data.warning)))
    return total


def test_simulation_warnings_of_a_diverging_run(diverging_loader):
    """A run that diverges: the count is the number of MuJoCo warnings, recounted by replaying
    the logged ticks; the log stops early, and every check still has a value."""
    w = diverging_loader
    count = _replayed_warnings(w)
    assert count >= 1
    assert_value(w, "simulation_warnings", float(count), 0.0)
    assert w.t[-1] < w.duration - 1e-9
    assert not w.summary["passed"]


def test_simulation_warnings(any_run):
    """Every scenario: 0 warnings, and the log shows a run that went the whole way with a
    finite state (a warning or a NaN would have ended it early)."""
    w = any_run
    assert all(np.isfinite(w.ts[k]).all() for k in ("qpos", "qvel", "act", "actuator_force", "sensordata"))
    assert w.t[-1] == pytest.approx(w.duration, abs=1e-6)
    assert w.summary["sim_time_s"] == pytest.approx(w.duration, abs=1e-6)
    assert_value(w, "simulation_warnings", 0.0, 0.0)


def test_check_names(any_run):
    """summary.json lists exactly the checks recomputed here, each with a finite value."""
    w = any_run
    assert [c["name"] for c in w.summary["checks"]] == CHECKS[w.summary["scenario"]]
    for c in w.summary["checks"]:
        w.check(c["name"])


_FIXTURE = {
    "loader-supply": "loader_supply",
    "loader-direct": "loader_direct",
    "hexapod-sync-move": "hexapod_sync",
    "hexapod-async-move": "hexapod_async",
    "antenna-paper-motion": "antenna_paper",
    "antenna-sea-state": "antenna_sea",
    "fast-tracking": "fast_tracking",
    "fast-ra-scan": "fast_ra_scan",
    "fast-source-switch": "fast_source_switch",
    "fast-observation": "fast_observation",
    "fast-scan": "fast_scan",
}


# ============================================================================ the papers' constants
# Pinned by what they do, with the papers' literal numbers (REFERENCE.md "Papers"): a permutation or
# a scaling of the constants in planners/ changes a planned motion or a solution here.

#: Ship-antenna paper, section 3.3, eq. (7): "W = [10 5 2 1]^T" (w1 > w2 > w3 > w4).
PAPER_W = np.array([10.0, 5.0, 2.0, 1.0])


def _least_norm_rates(jac, omega, weights):
    """The joint rates of least sum w_i thetadot_i^2 with J thetadot = omega, by another route
    than eq. (7): substitute y = sqrt(W) thetadot and take the minimum-norm least-squares y."""
    scale = 1.0 / np.sqrt(weights)
    return scale * np.linalg.lstsq(np.asarray(jac) * scale, omega, rcond=None)[0]


@pytest.mark.parametrize("axis, share", [(0, (1 / 11, 10 / 11)), (1, (1 / 6, 5 / 6)), (2, (1 / 3, 2 / 3))])
def test_paper_weights_split_a_shared_axis_by_their_ratio(axis, share):
    """By hand: let joint 4 turn about the same axis as joint k (J = [e1 e2 e3 e_k]) and ask
    for a unit rate about it. Minimizing w_k a^2 + w_4 b^2 with a + b = 1 gives
    a = w_4 / (w_k + w_4), b = w_k / (w_k + w_4): with W = [10 5 2 1], 1/11 and 10/11 for
    k = 1, 1/6 and 5/6 for k = 2, 1/3 and 2/3 for k = 3. Any permutation or change of the
    ratios of the planner's default weights moves one of them."""
    jac = np.eye(3, 4)
    jac[:, 3] = jac[:, axis]
    omega = np.eye(3)[axis]
    expected = np.zeros(4)
    expected[axis], expected[3] = share
    np.testing.assert_allclose(ant.weighted_pseudo_inverse(jac) @ omega, expected, atol=1e-14)
    np.testing.assert_allclose(_least_norm_rates(jac, omega, PAPER_W), expected, atol=1e-14)


def _paper_step():
    """Theta0 and the attitudes N(0), N(dT) of the paper's section 5.1 (eq. 15-16)."""
    from planbench.antenna.ship_motion import PaperShipMotion

    ship = PaperShipMotion().sample(np.array([0.0, 0.01]))
    az, el, pol = np.radians([223.49, 60.0, -28.8])
    attitudes = ant.desired_attitude(ship.heading, ship.pitch, ship.roll, az, el, pol)
    return np.radians([136.51, -60.0, 0.0, -28.8]), attitudes, 0.01


def test_planner_and_controller_solve_with_the_paper_weights():
    """The joint rates of eq. (7) at the paper's Theta0 for its first angular velocity, and
    the direction of one CRR step (eq. 12-14: the RK4 average of those rates), equal the
    hand solution with the paper's W, from the planner's defaults and with the weights of the
    antenna task's planning problem; the weights [10, 5, 1, 2] would give other ones."""
    theta0, attitudes, dt = _paper_step()
    omega = ant.angular_velocity_eq6(attitudes[0], attitudes[1], dt)
    hand = _least_norm_rates(ant.jacobian(theta0), omega, PAPER_W)
    permuted = _least_norm_rates(ant.jacobian(theta0), omega, np.array([10.0, 5.0, 1.0, 2.0]))
    assert np.abs(permuted - hand).max() > 0.05 * np.abs(hand).max()  # the test can tell
    np.testing.assert_allclose(ant.joint_rates(theta0, omega)[0], hand, rtol=1e-10, atol=1e-14)
    problem = (
        scenarios.get("antenna-paper-motion")
        .build(scenarios.get("antenna-paper-motion").resolve(duration=0.1))
        .task.problem
    )  # what the controller gets
    np.testing.assert_allclose(ant.joint_rates(theta0, omega, problem.weights)[0], hand, rtol=1e-10, atol=1e-14)

    def rk4_direction(weights):
        def rate(th):
            return _least_norm_rates(ant.jacobian(th), omega, weights)

        k1 = rate(theta0)
        k2 = rate(theta0 + dt / 2 * k1)
        k3 = rate(theta0 + dt / 2 * k2)
        k4 = rate(theta0 + dt * k3)
        average = (k1 + 2 * k2 + 2 * k3 + k4) / 6
        return average / np.linalg.norm(average)

    new, _ = ant.crr_step(theta0, attitudes[0], attitudes[1], dt)
    delta = (new - theta0) / np.linalg.norm(new - theta0)
    assert delta @ rk4_direction(PAPER_W) == pytest.approx(1.0, abs=1e-12)
    assert delta @ rk4_direction(np.array([10.0, 5.0, 1.0, 2.0])) < 0.999


def test_paper_theta0_holds_the_papers_satellite():
    """Section 5.1: the satellite at azimuth 223.49 deg, elevation 60 deg, polarization
    -28.8 deg, and Theta0 = [136.51, -60, 0, -28.8] deg, the joint angles that hold it on a
    level ship at heading 0. The planner's constants must put the boresight of f(Theta0) and
    of the satellite frame on the hand-computed direction (cos El sin Az, cos El cos Az,
    sin El) and the whole attitude f(Theta0) on the satellite frame of the literal angles;
    the paper's comparison of methods runs at its dT = 0.01 s."""
    az, el, pol = np.radians([223.49, 60.0, -28.8])
    boresight = [np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.sin(el)]
    attitude = ant.forward_kinematics(np.radians(ant.PAPER_THETA0_DEG))
    satellite = ant.satellite_attitude(*np.radians(ant.PAPER_SATELLITE_DEG))
    np.testing.assert_allclose(attitude[:, 2], boresight, atol=1e-12)
    np.testing.assert_allclose(satellite[:, 2], boresight, atol=1e-12)
    np.testing.assert_allclose(attitude, ant.satellite_attitude(az, el, pol), atol=1e-12)
    np.testing.assert_allclose(satellite, ant.satellite_attitude(az, el, pol), atol=1e-12)
    np.testing.assert_allclose(np.diff(antenna_sim.compare_methods(0.05)["crr"].t), 0.01, rtol=1e-12)


#: Loader paper, Table 1 as printed: P2, M1 ... M4, P3 at T = 0, 0.5, ... 2.5 s; theta1 in mm,
#: theta2 ... theta6 in degrees.
PAPER_TABLE1 = np.array(
    [
        [50, 55.8, -70.6, 20, 0, 0],
        [50, 43.4, -49.6, 15, 20, 10],
        [50, 58.2, -37.8, 34.3, 30, 10],
        [50, 48.3, -27.2, 42.9, 30, 10],
        [50, 32.8, -18.5, 15.4, 20, 0],
        [50, 52.4, -20.5, 29.6, 0, 0],
    ]
)


def test_loader_plans_pass_the_papers_key_points():
    """The supply plan passes Table 1's six key points at its times (mm -> m, deg -> rad by
    hand); the direct move joins P2 at 0 s to P3 at 2.5 s."""
    from planbench.planners import loader as loader_planner

    times = np.arange(6) * 0.5
    keys = np.column_stack([PAPER_TABLE1[:, 0] / 1000.0, PAPER_TABLE1[:, 1:] * (np.pi / 180.0)])
    np.testing.assert_allclose(loader_planner.supply_plan().sample(times).position, keys, atol=1e-12)
    np.testing.assert_allclose(loader_planner.direct_plan().sample(times[[0, -1]]).position, keys[[0, -1]], atol=1e-12)


def _peaks(plan, name_prefix: str):
    """(largest |feed acceleration| mm/s^2, largest feed speed mm/s) over the plan's
    segments whose names start with ``name_prefix``."""
    accel = speed = 0.0
    for seg in plan.segments:
        if seg.name.startswith(name_prefix):
            t = np.linspace(seg.t0 + 1e-6, seg.t0 + seg.duration - 1e-6, 2001)
            s = plan.state(t)
            accel = max(accel, 1e3 * np.linalg.norm(s.feed_acceleration, axis=1).max())
            speed = max(speed, 1e3 * np.linalg.norm(s.feed_velocity, axis=1).max())
    return accel, speed


def test_fast_plans_reach_the_papers_table1_limits(fast_tracking, fast_scan):
    """FAST paper, Table 1: A_max = 10 mm/s^2 (start, termination, observation),
    A_t-max = 15 mm/s^2 (transitions), V_s-max = 400 mm/s and A_s-max = 25 mm/s^2 (source
    switching). The planned feed motion reaches each limit where the plan is time-optimal:
    the start and termination at A_max, the switch line at A_s-max, the focal arc at V_s-max,
    the scan's shortest transition just under A_t-max (t2 bisected to 0.01 s)."""
    for plan in (fast_tracking.plan, fast_scan.plan):
        for name in ("start", "termination"):
            assert _peaks(plan, name)[0] == pytest.approx(10.0, rel=1e-3)
    assert _peaks(fast_tracking.plan, "switch-line")[0] == pytest.approx(25.0, rel=1e-3)
    assert _peaks(fast_tracking.plan, "switch-focal")[1] == pytest.approx(400.0, rel=1e-6)
    assert _peaks(fast_tracking.plan, "switch")[0] <= 25.0 * (1 + 1e-6)
    assert 14.8 <= _peaks(fast_scan.plan, "transition")[0] <= 15.0 * (1 + 1e-6)


def test_controller_errors(any_run):
    """Every scenario: 0 faults; the log shows finite commands over the whole duration (a
    fault would have ended it early)."""
    w = any_run
    assert np.isfinite(w.ts["ctrl"]).all() and w.t[-1] == pytest.approx(w.duration, abs=1e-6)
    assert_value(w, "controller_errors", 0.0, 0.0)


def test_controller_errors_of_a_raising_controller(faulty_loader):
    """A controller that raises: the log ends at that tick without any MuJoCo warning (no
    divergence), so the count is 1, and the outputs are still written."""
    w = faulty_loader
    dt = w.t[1] - w.t[0]
    ended_early = bool(w.t[-1] < w.duration - 1e-9)
    assert ended_early and w.t[-1] == pytest.approx(FAULT_TICK * dt)
    assert _replayed_warnings(w) == 0 and np.isfinite(w.ts["ctrl"]).all()
    assert_value(w, "controller_errors", float(ended_early), 0.0)
    [check] = [c for c in w.summary["checks"] if c["name"] == "controller_errors"]
    assert "ZeroDivisionError: gain schedule hit 0" in check["note"] and not w.summary["passed"]
