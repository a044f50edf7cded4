"""Plant uncertainty of the loader (planbench.loader.LoaderPlant): each field edits exactly its part of
the compiled model, the controller keeps the nominal model, the nominal plant runs as before,
short runs show each perturbation acting as computed by hand, and bad values are refused."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from model_diff import changed_fields
from plant_model import assert_edits_only

from planbench import api, loader, models, runner, scenarios
from planbench.params import ParamError
from planbench.planners.loader import forward_kinematics, table1_to_si

ROOT = Path(__file__).resolve().parents[1]
SPEC = scenarios.get("loader-supply")
CHAIN = models.loader_spec()
GRAVITY = 9.81
#: Every field off nominal at once, inside its range.
EVERYTHING = dict(
    payload_mass_error=0.08,
    arm_mass_error=-0.04,
    upper_arm_length_error=0.0015,
    joint_viscous_friction=0.05,
    drive_force_scale=0.9,
    encoder_bias=(0.5, 0.02, -0.03, 0.01, 0.0, 0.05),
)


def plant_model(payload_mass: float = 45.0, **fields) -> mujoco.MjModel:
    return loader.LoaderPhysics.load(payload_mass, loader.LoaderPlant(**fields)).model.ptr


def body(model, name: str) -> int:
    return model.body(name).id


def run(plant=None, **params):
    """(result, setup) of loader-supply with ``params`` and ``plant`` (a mapping)."""
    setup = SPEC.build(SPEC.resolve(**params), plant=SPEC.resolve_plant(plant or {}))
    return runner.run(SPEC.name, setup), setup


# ------------------------------------------------------------------ declarations


def test_every_loader_scenario_declares_the_nominal_loader_plant():
    for scenario in loader.SCENARIOS:
        assert isinstance(scenario.plant, loader.LoaderPlant) and scenario.plant.is_nominal
    assert not loader.LoaderPlant(arm_mass_error=0.01).is_nominal


def test_the_readme_documents_every_plant_field():
    from planbench.params import markdown_table

    assert markdown_table(loader.LoaderPlant) in (ROOT / "models/loader/README.md").read_text()


# ------------------------------------------------------------------ each field edits its part of the model


def _payload(nominal, plant):
    shell = body(nominal, "shell")
    # Its mass and inertia scale; its centre of mass stays (to the round-off of the sums).
    return {
        "body_mass": {shell: 45.0 * 1.1},
        "body_inertia": {shell: 1.1 * nominal.body_inertia[shell]},
        "body_ipos": {shell: nominal.body_ipos[shell]},
    }


def _arm(nominal, plant):
    rows = [body(nominal, n) for n in loader.ARM_BODIES]
    # Each link's mass and inertia scale; its centre of mass and principal axes stay.
    return {
        "body_mass": {r: 1.05 * nominal.body_mass[r] for r in rows},
        "body_inertia": {r: 1.05 * nominal.body_inertia[r] for r in rows},
    }


def _length(nominal, plant):
    forearm = body(nominal, "forearm")
    return {"body_pos": {forearm: [1.0 + 0.002, 0.0, 0.0]}}


def _friction(nominal, plant):
    # Rated force / rated speed x 0.1: slide 3000 N / 0.5 m/s, shoulder 8000 N m / 2 rad/s, ...
    by_hand = 0.1 * np.array([3000 / 0.5, 8000 / 2, 4000 / 2, 1000 / 3, 250 / 3, 60 / 3])
    return {"dof_damping": {nominal.joint(n).dofadr[0]: by_hand[j] for j, n in enumerate(CHAIN.names)}}


def _force(nominal, plant):
    rated = np.array([3000, 8000, 4000, 1000, 250, 60.0])
    return {
        "actuator_forcerange": {
            nominal.actuator(n).id: [-0.8 * rated[j], 0.8 * rated[j]] for j, n in enumerate(CHAIN.names)
        }
    }


def _bias(nominal, plant):
    # 1 mm on the slide, 0.05 deg on the shoulder: biasprm[0] = -kp b.
    slide, shoulder = nominal.actuator("slide").id, nominal.actuator("shoulder").id
    rows = {}
    for row, b in ((slide, 1e-3), (shoulder, np.deg2rad(0.05))):
        expected = nominal.actuator_biasprm[row].copy()
        expected[0] = -nominal.actuator_gainprm[row, 0] * b
        rows[row] = expected
    return {"actuator_biasprm": rows}


@pytest.mark.parametrize(
    "fields, edits",
    [
        (dict(payload_mass_error=0.1), _payload),
        (dict(arm_mass_error=0.05), _arm),
        (dict(upper_arm_length_error=0.002), _length),
        (dict(joint_viscous_friction=0.1), _friction),
        (dict(drive_force_scale=0.8), _force),
        (dict(encoder_bias=(1.0, 0.05, 0.0, 0.0, 0.0, 0.0)), _bias),
    ],
    ids=[
        "payload_mass_error",
        "arm_mass_error",
        "upper_arm_length_error",
        "joint_viscous_friction",
        "drive_force_scale",
        "encoder_bias",
    ],
)
def test_a_field_changes_its_part_of_the_model_and_nothing_else(fields, edits):
    nominal = models.load("loader")
    plant = plant_model(**fields)
    diff = assert_edits_only(nominal, plant, edits(nominal, plant), roundoff=("bvh_aabb",))
    assert diff, "the perturbation changed nothing"


def test_the_payload_error_is_relative_to_the_payload_the_controller_is_told():
    nominal = loader.LoaderPhysics.load(60.0).model.ptr
    plant = plant_model(60.0, payload_mass_error=-0.1)
    shell = body(nominal, "shell")
    assert_edits_only(
        nominal,
        plant,
        {
            "body_mass": {shell: 54.0},
            "body_inertia": {shell: 0.9 * nominal.body_inertia[shell]},
            "body_ipos": {shell: nominal.body_ipos[shell]},
        },
        roundoff=("bvh_aabb",),
    )


# ------------------------------------------------------------------ the controller keeps the nominal model


@pytest.mark.parametrize("drives", ["as-built", "ideal"])
def test_the_controller_gets_the_nominal_model_at_the_nominal_start(drives):
    params = SPEC.resolve(duration=0.1, drives=drives)
    setup = SPEC.build(params, plant=loader.LoaderPlant(**EVERYTHING))
    reference = SPEC.build(params)
    nominal = loader.LoaderPhysics.load(drives=drives).model.ptr
    assert changed_fields(nominal, setup.physics.model.ptr)  # the plant is perturbed
    given_model = setup.task.nominal_physics()
    assert changed_fields(nominal, given_model.model.ptr) == {}
    for name in ("qpos", "qvel", "act"):
        np.testing.assert_array_equal(getattr(given_model.data, name), getattr(reference.physics.data, name))
    context = runner.start_episode(setup)
    context = context.context
    assert changed_fields(nominal, context.model) == {}
    assert changed_fields(nominal, context.nominal_physics().model.ptr) == {}
    # The plant starts where its encoders read the first key point (as built: the motors'
    # encoders, which read the reducers' deflection under gravity too, in counts).
    bias = table1_to_si(np.array(EVERYTHING["encoder_bias"]))
    q0 = setup.task.problem.key_points[0]
    np.testing.assert_allclose(setup.physics.joint_positions(), q0 - bias, rtol=0, atol=1e-15)
    if drives == "ideal":
        np.testing.assert_allclose(context.observation["joint_positions"], q0, rtol=0, atol=1e-15)
    else:
        motors = setup.physics.data.qpos[setup.physics.drive_qpos]
        resolution = setup.task.sensors.specs[0].resolution
        np.testing.assert_allclose(context.observation["joint_positions"], motors + bias, rtol=0, atol=resolution)
    # Its datasheet does not reveal the bias; the record of the run does.
    assert str(EVERYTHING["encoder_bias"][1]) not in context.sensors[0].bias
    assert setup.provenance.plant == loader.LoaderPlant(**EVERYTHING)


# ------------------------------------------------------------------ the perturbations act


# The runs below are on the ideal drives: as built, the motors' Coulomb friction holds up to 3 %
# of each peak torque at rest, so a drive's holding torque is not gravity's alone
# (tests/test_loader_drives.py checks the drive trains).
IDEAL = dict(drives="ideal")


@pytest.fixture(scope="module")
def nominal_run():
    return run(**IDEAL)


def _gravity_torques(physics, qpos, mass: float) -> np.ndarray:
    """(6,) drive forces that hold an extra ``mass`` (kg) at the shell's centre of mass at rest at
    ``qpos``: minus the generalized gravity force, axis . ((c - anchor) x m g) per hinge."""
    model, data = physics.model.ptr, mujoco.MjData(physics.model.ptr)
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    c = data.xipos[body(model, "shell")]
    weight = np.array([0.0, 0.0, -GRAVITY * mass])
    out = np.zeros(6)
    for j, name in enumerate(CHAIN.names):
        joint = model.joint(name).id
        axis, anchor = data.xaxis[joint], data.xanchor[joint]
        out[j] = -(axis @ weight if j == 0 else axis @ np.cross(c - anchor, weight))
    return out


def test_a_heavier_shell_raises_the_holding_torques_by_its_extra_weight(nominal_run):
    nominal, _ = nominal_run
    heavy, setup = run(dict(payload_mass_error=0.1), **IDEAL)
    # At P3 after 0.5 s of settling the arm is at rest: each drive holds gravity alone.
    expected = _gravity_torques(setup.physics, heavy.log.qpos[-1], 0.1 * 45.0)
    measured = heavy.log.actuator_force[-1] - nominal.log.actuator_force[-1]
    np.testing.assert_allclose(measured[1:4], expected[1:4], rtol=5e-3)
    assert abs(expected[1]) > 80.0  # the shoulder holds the extra 4.5 kg 2.1 m out: 93 N m
    assert np.abs(measured[[0, 4, 5]]).max() < 1.0  # the slide and the shell axis take no gravity


def test_a_weaker_drive_saturates_at_its_own_limit(nominal_run):
    nominal, _ = nominal_run
    weak, setup = run(dict(drive_force_scale=0.5), **IDEAL)
    limit = 0.5 * CHAIN.force_limit
    force = np.abs(weak.log.actuator_force)
    assert np.all(force <= limit * (1 + 1e-12))
    shoulder = CHAIN.names.index("shoulder")
    # The spline asks the shoulder for 4.8 kN m at its peak; half its 8 kN m rating is 4 kN m.
    assert np.isclose(force[:, shoulder].max(), limit[shoulder], rtol=1e-12)
    assert np.abs(nominal.log.actuator_force[:, shoulder]).max() > limit[shoulder]
    checks = {c.name: c for c in weak.checks}
    assert checks["joint_torque"].value > 1.0 and not checks["joint_torque"].passed
    ratio = np.abs(setup.task.evaluation.timeseries(weak.log)["drive_force_demanded"]) / limit
    assert checks["joint_torque"].value == pytest.approx(ratio.max(), rel=1e-12)


def test_an_encoder_bias_offsets_the_true_joints_by_minus_the_bias(nominal_run):
    nominal, _ = nominal_run
    bias_table = (0.0, 0.05, 0.0, -0.04, 0.0, 0.0)
    biased, setup = run(dict(encoder_bias=bias_table), **IDEAL)
    bias = table1_to_si(np.array(bias_table))
    dofs = [setup.physics.model.ptr.joint(n).dofadr[0] for n in CHAIN.names]
    # The drives hold the encoder readings on the plan, so the true joints end off by -bias.
    offset = biased.log.qpos[-1, dofs] - nominal.log.qpos[-1, dofs]
    np.testing.assert_allclose(offset, -bias, rtol=0, atol=np.deg2rad(2e-4))
    checks = {c.name: c.value for c in biased.checks}
    assert checks["keypoint_error"] == pytest.approx(0.05, abs=0.003)


def test_a_longer_upper_arm_moves_the_shell_tip_the_evaluation_reports():
    result, setup = run(dict(upper_arm_length_error=0.002))
    q = setup.task.evaluation.timeseries(result.log)["q_actual"][-1]
    theta2 = q[CHAIN.names.index("shoulder")]
    nominal_tip = forward_kinematics(q, ["shell_tip"])["shell_tip"].reshape(3)
    # The same joints put the tip 2 mm further along the upper arm (at theta2 above horizontal).
    np.testing.assert_allclose(
        np.array(result.metrics["final_shell_tip_m"]) - nominal_tip,
        0.002 * np.array([np.cos(theta2), 0.0, np.sin(theta2)]),
        rtol=0,
        atol=1e-12,
    )
    # ... where MuJoCo's plant has it.
    data = mujoco.MjData(setup.physics.model.ptr)
    data.qpos[:] = result.log.qpos[-1]
    mujoco.mj_kinematics(setup.physics.model.ptr, data)
    np.testing.assert_allclose(
        result.metrics["final_shell_tip_m"], data.site_xpos[setup.physics.model.ptr.site("shell_tip").id], atol=1e-12
    )


# ------------------------------------------------------------------ bad values


@given(st.integers(0, 5), st.floats(1e-6, 10.0))
@settings(max_examples=30, deadline=None)
def test_an_encoder_bias_out_of_its_range_names_the_joint(column, excess):
    bias = [0.0] * 6
    bias[column] = loader.params._BIAS_LIMIT[column] + excess
    unit = loader.params._BIAS_UNITS[column]
    with pytest.raises(ParamError, match=rf"^plant\.encoder_bias\[{column}\] = .* {unit} is outside"):
        SPEC.resolve_plant({"encoder_bias": bias})


def test_api_run_refuses_bad_plants_before_building():
    for plant, words in [
        ({"payload_mass_error": 0.5}, "plant.payload_mass_error = 0.5 fraction is outside"),
        ({"encoder_bias": [0, 0]}, "plant.encoder_bias has 2 values, not 6"),
        ({"payload_mass": 50}, "unknown parameter 'plant.payload_mass'"),
    ]:
        with pytest.raises(ParamError) as refused:
            api.run("loader-supply", plant=plant)
        assert words in str(refused.value), str(refused.value)
