"""Short MuJoCo runs of the loader scenarios: checks, collisions, determinism, divergence."""

import numpy as np
import pytest

from planbench import runner, scenarios
from planbench.controllers import ServoFeedforwardController
from planbench.loader import LoaderPhysics
from planbench.loader.collision import clearance
from planbench.planners.loader import direct_plan, supply_plan


def run(name, **options):
    scenario = scenarios.get(name)
    setup = scenario.build(scenario.resolve(**options))
    return runner.run(name, setup), setup


@pytest.fixture(scope="module")
def supply():
    return run("loader-supply")


@pytest.fixture(scope="module")
def direct():
    return run("loader-direct")


def checks(result):
    return {c.name: c for c in result.checks}


def test_supply_checks_hold(supply):
    result, _ = supply
    c = checks(result)
    assert result.passed, [x.to_json() for x in result.checks if not x.passed]
    assert set(c) == {
        "keypoint_error",
        "tracking_error",
        "obstacle_contacts",
        "min_clearance",
        "joint_torque",
        "simulation_warnings",
        "controller_errors",
    }
    assert c["obstacle_contacts"].value == 0
    assert c["min_clearance"].value > 0.05  # the planned path clears by ~6 cm
    assert c["keypoint_error"].value < 0.1 and c["joint_torque"].value < 1.0
    assert result.sim_time_s == pytest.approx(3.0)


def test_supply_reaches_p3_at_rest(supply):
    """The joints (as built, with their motors) end at P3 within 0.01 deg, at rest."""
    result, setup = supply
    model = setup.physics.model.ptr
    joints = [model.joint(n) for n in setup.physics.joint_names]
    q_end = result.log.qpos[-1, [j.qposadr[0] for j in joints]]  # (the motors' coordinates follow)
    np.testing.assert_allclose(q_end, supply_plan().key_points[-1], atol=np.deg2rad(0.01))
    assert np.abs(result.log.qvel[-1]).max() < 1e-3


def test_direct_move_strikes_the_obstacles(direct):
    result, setup = direct
    c = checks(result)
    assert not result.passed
    assert not c["obstacle_contacts"].passed and c["obstacle_contacts"].value >= 2
    assert "breechblock" in c["obstacle_contacts"].note and "seat_ring" in c["obstacle_contacts"].note
    assert c["min_clearance"].value < 0
    assert c["simulation_warnings"].passed  # it collides, it does not diverge


def test_obstacles_sit_between_the_two_planned_paths():
    """Kinematically (no controller): the straight move cuts into the obstacles by > 5 cm;
    the spline path clears them by > 5 cm."""
    physics = LoaderPhysics.load()
    t = np.linspace(0, 2.5, 126)
    model = physics.model.ptr
    robot, obstacles = physics.robot_geoms(), physics.obstacle_geoms()
    c_supply, _ = clearance(model, supply_plan().sample(t).position, robot, obstacles)
    c_direct, _ = clearance(model, direct_plan().sample(t).position, robot, obstacles)
    assert c_supply.min() > 0.05
    assert c_direct.min() < -0.05


def test_same_seed_same_log():
    a, _ = run("loader-supply", seed=3)
    b, _ = run("loader-supply", seed=3)
    for field in ("qpos", "qvel", "act", "ctrl", "actuator_force", "sensordata"):
        np.testing.assert_array_equal(getattr(a.log, field), getattr(b.log, field))
    assert [c.to_json() for c in a.checks] == [c.to_json() for c in b.checks]


def test_without_feedforward_tracking_fails():
    """The tracking checks can fail: PD drives alone lag the spline by more than 0.25 deg."""
    setup = scenarios.get("loader-supply").build(scenarios.get("loader-supply").params)
    c = setup.components.controller
    setup.components.controller = ServoFeedforwardController(c.kp, c.kv, feedforward=False)
    result = runner.run("loader-supply", setup)
    assert not checks(result)["tracking_error"].passed


def test_duration_option_truncates_and_checks_reached_key_points():
    result, _ = run("loader-supply", duration=1.2)
    assert result.log.t[-1] == pytest.approx(1.2)
    assert "3 of 6 key points reached" in checks(result)["keypoint_error"].note


class NaNForce:
    """A disturbance that injects a NaN force at a given tick."""

    def __init__(self, tick):
        self.tick = tick

    def reset(self, physics, times, rng):
        pass

    def __call__(self, tick, physics):
        if tick == self.tick:
            physics.data.qfrc_applied[1] = np.nan


def test_divergence_ends_the_run_as_a_failed_check():
    setup = scenarios.get("loader-supply").build(scenarios.get("loader-supply").params)
    setup.task.disturbance = NaNForce(tick=100)
    result = runner.run("loader-supply", setup)
    c = checks(result)["simulation_warnings"]
    assert not c.passed and not result.passed
    assert "t = 0.5" in c.note or "by t = 0.5" in c.note
    assert result.log.t[-1] <= 0.5 + runner.SCAN_TICKS * setup.task.control_dt + 1e-9
    assert np.isfinite(result.log.qpos).all() or "non-finite" in c.note


def test_steps_per_tick_rejects_non_multiples():
    model = LoaderPhysics.load().model.ptr
    assert runner.steps_per_tick(model, 0.005) == 10
    with pytest.raises(ValueError, match="not a whole multiple"):
        runner.steps_per_tick(model, 0.0012)


def test_dm_control_environment_steps():
    from planbench.envs import loader_environment

    env = loader_environment()
    ts = env.reset()
    assert set(ts.observation) == {
        "joint_positions",
        "joint_velocities",
        "setpoints",
        "reference_positions",
        "reference_velocities",
    }
    # The episode starts where a run starts: the model's keyframe, P2 to its 6 digits; the
    # motors' encoders read the reducers' deflection under gravity on top (1.1e-3 rad at most).
    np.testing.assert_allclose(ts.observation["joint_positions"], ts.observation["reference_positions"], atol=1.5e-3)
    spec = env.action_spec()
    for _ in range(20):
        ts = env.step(np.zeros(spec.shape))
    # Holding still while the plan moves on: the reward drops below its maximum.
    assert 0.0 < ts.reward < 1.0
    assert env.physics.data.time == pytest.approx(0.1)


def test_benchmark_reports_ratios_against_bare_stepping():
    from planbench import bench

    row = bench.bench_scenario("loader-supply")
    assert row["physics_steps"] == 6000 and row["passed"]
    assert 0 < row["loop_ratio"] and np.isfinite(row["loop_ratio"])
    assert row["realtime_factor"] > 0
    assert "loader-supply" in bench.format_table([row])


def test_shell_tip_sensor_matches_planner_kinematics(supply):
    """The sensor lags the logged qpos by one physics step; at rest at the end they agree."""
    from planbench.planners.loader import forward_kinematics

    result, setup = supply
    tip = setup.physics.shell_tip_log(result.log.sensordata)
    q, _ = setup.task.evaluation._joint_log(result.log)
    expected = forward_kinematics(q, ["shell_tip"])["shell_tip"]
    np.testing.assert_allclose(tip[-1], expected[-1], atol=1e-7)
    step = setup.physics.model.opt.timestep
    tip_speed = np.linalg.norm(np.diff(expected, axis=0), axis=1) / setup.task.control_dt
    lag = np.linalg.norm(tip - expected, axis=1)
    assert np.all(lag[1:] <= 1.5 * tip_speed.max() * step + 1e-9)


@pytest.mark.parametrize("mass", [1e-12, 1e-7, 0.0])
def test_a_shell_lighter_than_a_milligram_is_none(mass):
    """MuJoCo cannot diagonalize the inertia of geoms that light (found by hypothesis at
    1e-12 kg): the model then carries no shell, as at 0 kg, and still builds and runs."""
    from planbench.loader.physics import LoaderPhysics

    physics = LoaderPhysics.load(mass)
    model = physics.model.ptr
    assert model.body_subtreemass[model.body("shell").id] == 0.0
    scenario = scenarios.get("loader-supply")
    runner.run("loader-supply", scenario.build(scenario.resolve(payload_mass=mass, duration=0.1)))
