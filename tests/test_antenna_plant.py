"""Plant uncertainty of the ship antenna (planbench.antenna.AntennaPlant): each field edits exactly its
part of the compiled model (or the IMU's true error), the planner and the controller keep the
nominal model and the IMU's datasheet, the nominal plant runs as before, short runs show each
perturbation acting as computed by hand, and bad values are refused."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import mujoco
import numpy as np
import pytest
from model_diff import changed_fields
from plant_model import assert_edits_only

from planbench import antenna, api, models, runner, scenarios
from planbench.antenna import params as antenna_params
from planbench.antenna.ship_motion import world_from_ship
from planbench.params import ParamError

ROOT = Path(__file__).resolve().parents[1]
SPEC = scenarios.get("antenna-sea-state")
#: The IMU without noise and the ideal drives: what a perturbation does is then not hidden by
#: the noise, nor by the gears' backlash and friction (tests/test_antenna_drives.py).
QUIET = dict(imu={"attitude_noise_deg": 0.0, "gyro_noise_deg_s": 0.0}, drives="ideal")
#: Every field off nominal at once, inside its range.
EVERYTHING = dict(
    mass_error=0.1,
    imbalance_offset=(4.0, -3.0, 2.0),
    joint_friction=1.0,
    torque_limit_scale=0.8,
    imu_bias=(0.05, -0.02, 0.1),
)
JOINT_IDS = dict(
    zip(antenna.JOINTS, range(4, 8), strict=True)
)  # the antenna's dofs and actuators follow the deck's four


def plant_model(**fields) -> mujoco.MjModel:
    return antenna.AntennaPhysics.load(antenna.AntennaPlant(**fields)).model.ptr


def build(duration: float, plant=None, **params):
    return SPEC.build(SPEC.resolve(duration=duration, **params), plant=SPEC.resolve_plant(plant or {}))


# ------------------------------------------------------------------ declarations


def test_every_antenna_scenario_declares_the_nominal_antenna_plant():
    for scenario in antenna.SCENARIOS:
        assert isinstance(scenario.plant, antenna.AntennaPlant) and scenario.plant.is_nominal


def test_the_readme_documents_every_plant_field():
    from planbench.params import markdown_table

    assert markdown_table(antenna.AntennaPlant) in (ROOT / "models/antenna/README.md").read_text()


# ------------------------------------------------------------------ each field edits its part of the model


def _mass(nominal, plant):
    ids = [nominal.body(b).id for b in antenna.MOVING_BODIES]
    return {
        "body_mass": {i: 1.1 * nominal.body_mass[i] for i in ids},
        "body_inertia": {i: 1.1 * nominal.body_inertia[i] for i in ids},
    }


def _imbalance(nominal, plant):
    offset = np.array([4e-3, -3e-3, 2e-3])  # m, in the polarization frame = the reflector's axes
    return {
        "body_ipos": {
            nominal.body(b).id: nominal.body_ipos[nominal.body(b).id] + offset for b in ("polarization", "reflector")
        }
    }


def _friction(nominal, plant):
    return {"dof_frictionloss": {nominal.joint(j).dofadr[0]: 2.5 for j in antenna.JOINTS}}


def _torque(nominal, plant):
    ratings = {"azimuth": 40.0, "elevation": 15.0, "cross_elevation": 12.0, "polarization": 10.0}  # N m, README
    return {"actuator_forcerange": {nominal.actuator(j).id: [-0.8 * r, 0.8 * r] for j, r in ratings.items()}}


@pytest.mark.parametrize(
    "fields, edits",
    [
        (dict(mass_error=0.1), _mass),
        (dict(imbalance_offset=(4.0, -3.0, 2.0)), _imbalance),
        (dict(joint_friction=2.5), _friction),
        (dict(torque_limit_scale=0.8), _torque),
    ],
    ids=["mass_error", "imbalance_offset", "joint_friction", "torque_limit_scale"],
)
def test_a_field_changes_its_part_of_the_model_and_nothing_else(fields, edits):
    nominal = models.load("antenna")
    plant = plant_model(**fields)
    assert changed_fields(nominal, plant), "the perturbation changed nothing"
    assert_edits_only(nominal, plant, edits(nominal, plant), rtol=1e-12)


def test_the_imbalance_moves_the_polarization_assembly_s_centre_of_mass_by_itself():
    """By hand: both bodies' centres of mass move by the offset, so the 33 kg assembly's does."""
    offset = np.array([4.0, -3.0, 2.0])
    centres = []
    for model in (models.load("antenna"), plant_model(imbalance_offset=tuple(offset))):
        data = mujoco.MjData(model)
        mujoco.mj_resetDataKeyframe(model, data, 0)
        mujoco.mj_forward(model, data)
        body = model.body("polarization").id
        assert model.body_subtreemass[body] == pytest.approx(33.0)
        centres.append((data.subtree_com[body], data.xmat[body].reshape(3, 3)))
    (before, rotation), (after, _) = centres
    np.testing.assert_allclose(rotation.T @ (after - before), 1e-3 * offset, rtol=0, atol=1e-14)


def test_the_imu_bias_is_the_sensor_s_and_leaves_the_model():
    assert changed_fields(models.load("antenna"), plant_model(imu_bias=(0.3, 0.0, -0.2))) == {}
    setup = build(0.1, {"imu_bias": [0.3, 0.0, -0.2]})
    expected = np.empty(4)
    mujoco.mju_axisAngle2Quat(expected, np.array([0.3, 0.0, -0.2]) / np.hypot(0.3, 0.2), np.radians(np.hypot(0.3, 0.2)))
    matrix = np.empty(9)
    mujoco.mju_quat2Mat(matrix, expected)
    np.testing.assert_allclose(setup.task.sensors.bias_rotation, matrix.reshape(3, 3), rtol=0, atol=1e-15)
    # The datasheet the controller reads keeps the nominal IMU; it only says there is an error.
    nominal = build(0.1).task.sensors
    assert nominal.bias_rotation is None
    assert setup.task.sensors.specs[1:] == nominal.specs[1:]
    assert setup.task.sensors.specs[0] == dataclasses.replace(nominal.specs[0], bias=setup.task.sensors.specs[0].bias)
    assert nominal.specs[0].bias == "none" and "unknown" in setup.task.sensors.specs[0].bias


# ------------------------------------------------------------------ the controller keeps the nominal model


def test_the_controller_gets_the_nominal_model_at_the_plant_s_start():
    setup = build(0.1, EVERYTHING)
    nominal = antenna_params._model(setup.provenance.params.drives)  # the as-built model, unperturbed
    assert changed_fields(nominal, setup.physics.model.ptr)  # the plant is perturbed
    given = setup.task.nominal_physics()
    assert changed_fields(nominal, given.model.ptr) == {}
    for name in ("qpos", "qvel", "act", "ctrl"):
        np.testing.assert_array_equal(getattr(given.data, name), getattr(setup.physics.data, name))
    context = runner.start_episode(setup).context
    assert changed_fields(nominal, context.model) == {}
    assert changed_fields(nominal, context.nominal_physics().model.ptr) == {}
    # The controller's constants come from the nominal model and the IMU's datasheet.
    controller = setup.components.controller
    kp, kv = antenna.AntennaPhysics.load().drive_gains()
    np.testing.assert_array_equal(controller.lead, kv / kp)
    assert (controller.period, controller.latency) == (4, 4)  # 50 Hz and 20 ms at 200 Hz
    assert setup.provenance.plant == antenna.AntennaPlant(**EVERYTHING)


def test_without_an_imu_bias_the_plant_starts_where_the_nominal_one_does():
    fields = {k: v for k, v in EVERYTHING.items() if k != "imu_bias"}
    perturbed, reference = build(0.1, fields), build(0.1)
    for name in ("qpos", "qvel", "act"):
        np.testing.assert_array_equal(getattr(perturbed.physics.data, name), getattr(reference.physics.data, name))
        np.testing.assert_array_equal(
            getattr(perturbed.task.nominal_physics().data, name), getattr(reference.physics.data, name)
        )
    np.testing.assert_array_equal(perturbed.task.problem.theta0, reference.task.problem.theta0)


# ------------------------------------------------------------------ each perturbation acts as computed by hand


@pytest.fixture(scope="module")
def nominal_run():
    setup = build(4.0, **QUIET)
    return runner.run(SPEC.name, setup), setup


def test_an_imu_bias_shifts_the_pointing_by_the_bias(nominal_run):
    """The controller holds N = B^T bTe eTs for the biased deck attitude eTb B, so the dish
    points at exp(-[R b]x) eTs (R = eTb): its boresight misses the satellite by |R b x z_s|."""
    bias = np.array([0.1, -0.05, 0.15])  # deg, IMU (deck) axes
    setup = build(4.0, {"imu_bias": list(bias)}, **QUIET)
    result = runner.run(SPEC.name, setup)
    log = result.log
    deck = log.qpos[:, setup.physics.deck_qpos]
    rotated = world_from_ship(deck[:, 1], deck[:, 2], deck[:, 3]) @ np.radians(bias)
    by_hand = np.degrees(np.linalg.norm(np.cross(rotated, setup.task.problem.satellite[:, 2]), axis=1))
    pointing, _ = setup.task.evaluation.errors_deg(log)
    nominal_pointing, _ = nominal_run[1].task.evaluation.errors_deg(nominal_run[0].log)
    floor = nominal_pointing.max()  # the servo's own error, without the IMU's noise
    assert floor < 0.003 and by_hand.min() > 0.1
    np.testing.assert_allclose(pointing, by_hand, rtol=0, atol=floor + 0.002)
    # The run starts tracking what the biased IMU says (the planner's start is the plant's
    # angles): no start transient in the drives.
    np.testing.assert_array_equal(setup.task.problem.theta0, log.qpos[0, setup.physics.antenna_qpos])
    checks = {c.name: c.value for c in result.checks}
    nominal = {c.name: c.value for c in nominal_run[0].checks}
    assert checks["joint_torque"] == pytest.approx(nominal["joint_torque"], rel=0.1)


def test_a_derated_drive_is_judged_against_its_own_limit(nominal_run):
    """Below the clamp a lower torque limit changes no motion; the check's ratio grows by
    1 / scale exactly."""
    result = runner.run(SPEC.name, build(4.0, {"torque_limit_scale": 0.5}, **QUIET))
    np.testing.assert_array_equal(result.log.qpos, nominal_run[0].log.qpos)
    torque = {c.name: c.value for c in result.checks}["joint_torque"]
    assert torque == pytest.approx(2 * {c.name: c.value for c in nominal_run[0].checks}["joint_torque"], rel=1e-12)


@pytest.mark.parametrize("fields", [dict(mass_error=0.15), dict(imbalance_offset=(0.0, 6.0, -4.0))])
def test_mass_and_imbalance_change_the_holding_torques_by_hand(fields):
    """At rest on a level deck at home, gravity's generalized force on each antenna axis: a
    heavier antenna scales it by 1 + mass_error (its centres of mass stay); an imbalance
    offset adds (axis x (m c)) . g with m = 33 kg and c the offset in the world, where axis is
    the joint's world axis through O (all four pass through it)."""
    out = []
    for model in (models.load("antenna"), plant_model(**fields)):
        data = mujoco.MjData(model)
        mujoco.mj_resetDataKeyframe(model, data, 0)
        mujoco.mj_forward(model, data)
        out.append((data.qfrc_bias[[model.joint(j).dofadr[0] for j in antenna.JOINTS]].copy(), data))
    (before, data), (after, _) = out
    model = models.load("antenna")
    if "mass_error" in fields:
        np.testing.assert_allclose(after, 1.15 * before, rtol=1e-9, atol=1e-12)
        return
    rotation = data.xmat[model.body("polarization").id].reshape(3, 3)
    shift = rotation @ (1e-3 * np.array(fields["imbalance_offset"]))
    weight = 33.0 * model.opt.gravity
    for j, name in enumerate(antenna.JOINTS):
        axis = data.xaxis[model.joint(name).id]
        # qfrc_bias is minus gravity's generalized force: -(axis . (c x m g)).
        assert after[j] - before[j] == pytest.approx(-axis @ np.cross(shift, weight), abs=1e-9)


def test_friction_holds_a_static_error_the_nominal_plant_has_not(nominal_run):
    """Coulomb friction against the servo: the axes stick until kp times the error exceeds
    it, so the pointing error grows (by at most friction / kp per axis, 0.013 deg on
    polarization at 2.5 N m: 2.5 / 11000 rad)."""
    result = runner.run(SPEC.name, build(4.0, {"joint_friction": 2.5}, **QUIET))
    rms = result.metrics["pointing_error_rms_deg"]
    assert rms > 3 * nominal_run[0].metrics["pointing_error_rms_deg"]
    kp, _ = antenna.AntennaPhysics.load().drive_gains()
    # Each axis sticks within friction / kp of its set-point; the boresight moves by at most the sum.
    assert result.metrics["pointing_error_p99_deg"] < np.degrees(np.sum(2.5 / kp)) + nominal_run[0].checks[0].value
    assert result.passed


# ------------------------------------------------------------------ bad values


def test_api_run_refuses_bad_plants_before_building():
    for plant, words in [
        ({"mass_error": 0.5}, "plant.mass_error = 0.5 fraction is outside [-0.2, 0.2]"),
        ({"imu_bias": [0.1, 0.1]}, "plant.imu_bias has 2 values, not 3"),
        ({"gyro_bias": [0, 0, 0]}, "unknown parameter 'plant.gyro_bias'"),
    ]:
        with pytest.raises(ParamError) as refused:
            api.run("antenna-sea-state", plant=plant)
        assert words in str(refused.value), str(refused.value)
