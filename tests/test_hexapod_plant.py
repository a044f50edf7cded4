"""Plant uncertainty of the camera hexapod (planbench.hexapod.HexapodPlant): each field edits exactly
its part of the compiled model, the controller keeps the nominal model, the nominal plant runs as
before, short runs show each perturbation acting as computed by hand, and bad values are refused."""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from model_diff import changed_fields
from plant_model import assert_edits_only

from planbench import api, hexapod, runner, scenarios
from planbench.params import ParamError
from planbench.planners import hexapod as hexapod_planner
from planbench.planners.hexapod import RUBIN_CAMERA, STRUT_LABELS

ROOT = Path(__file__).resolve().parents[1]
SPEC = scenarios.get("hexapod-sync-move")
ELEVATION = 45.0  # the scenarios' default
GRAVITY = 9.81
CAMERA_Z = 4.2584  # m: the camera's centre of mass from the rotation pivot, along the platform's z
#: Every field off nominal at once, inside its range.
EVERYTHING = dict(
    camera_mass_error=0.05,
    camera_com_offset=(0.01, -0.02, 0.03),
    base_pivot_radius_error=2e-4,
    platform_pivot_radius_error=-1e-4,
    drive_stiffness_error=-0.1,
    drive_force_scale=0.9,
    encoder_bias_um=(1.0, -2.0, 0.0, 3.0, 0.0, 0.5),
)


def plant_model(**fields) -> mujoco.MjModel:
    return hexapod.HexapodPhysics.load(ELEVATION, hexapod.HexapodPlant(**fields)).model.ptr


def run(plant=None, **params):
    """(result, setup) of hexapod-sync-move with ``params`` and ``plant`` (a mapping)."""
    setup = SPEC.build(SPEC.resolve(**params), plant=SPEC.resolve_plant(plant or {}))
    return runner.run(SPEC.name, setup), setup


def radial(xyz, dr):
    """``xyz`` moved outward by ``dr`` on its circle about the z axis, by hand."""
    x, y, z = xyz
    r = math.hypot(x, y)
    return np.array([x * (r + dr) / r, y * (r + dr) / r, z])


# ------------------------------------------------------------------ declarations


def test_every_hexapod_scenario_declares_the_nominal_hexapod_plant():
    for scenario in hexapod.SCENARIOS:
        assert isinstance(scenario.plant, hexapod.HexapodPlant) and scenario.plant.is_nominal
    assert hexapod.HexapodPlant().geometry() is RUBIN_CAMERA


def test_the_readme_documents_every_plant_field():
    from planbench.params import markdown_table

    assert markdown_table(hexapod.HexapodPlant) in (ROOT / "models/hexapod/README.md").read_text()


# ------------------------------------------------------------------ each field edits its part of the model


def _mass(nominal, plant):
    camera = nominal.body("camera").id
    m, r, length = 3300.0, 0.825, 3.0  # a uniform cylinder, 10 % heavier
    across = m * (3 * r**2 + length**2) / 12
    return {"body_mass": {camera: m}, "body_inertia": {camera: [across, across, m * r**2 / 2]}}


def _com(nominal, plant):
    return {"body_ipos": {nominal.body("camera").id: [0.02, -0.01, 0.05]}}


def _pivots(kind, dr):
    def edits(nominal, plant):
        out = {"site_pos": {}, "body_pos": {}} if kind == "base" else {"site_pos": {}}
        for i, name in enumerate(STRUT_LABELS):
            site = nominal.site(f"{kind}_pivot{i + 1}").id
            out["site_pos"][site] = radial(nominal.site_pos[site], dr)
            if kind == "base":
                housing = nominal.body(f"{name}_housing").id
                out["body_pos"][housing] = radial(nominal.body_pos[housing], dr)
        # The spatial tendons' spring lengths (no stiffness) default to their length at qpos0.
        out["tendon_lengthspring"] = {k: [plant.tendon_length0[k]] * 2 for k in range(6)}
        return out

    return edits


def _stiffness(nominal, plant):
    gain, bias = nominal.actuator_gainprm[:6].copy(), nominal.actuator_biasprm[:6].copy()
    gain[:, 0], bias[:, 1] = 1.2e8, -1.2e8
    return {"actuator_gainprm": dict(enumerate(gain)), "actuator_biasprm": dict(enumerate(bias))}


def _force(nominal, plant):
    return {"actuator_forcerange": {j: [-40_000.0, 40_000.0] for j in range(6)}}


def _bias(nominal, plant):
    bias = nominal.actuator_biasprm[:6].copy()
    bias[0, 0], bias[5, 0] = -1e8 * 1e-6, -1e8 * -2e-6  # -kp b: 100 N against 1 um
    return {"actuator_biasprm": {0: bias[0], 5: bias[5]}}


@pytest.mark.parametrize(
    "fields, edits",
    [
        (dict(camera_mass_error=0.1), _mass),
        (dict(camera_com_offset=(0.02, -0.01, 0.05)), _com),
        (dict(base_pivot_radius_error=1e-3), _pivots("base", 1e-3)),
        (dict(platform_pivot_radius_error=-5e-4), _pivots("platform", -5e-4)),
        (dict(drive_stiffness_error=0.2), _stiffness),
        (dict(drive_force_scale=0.8), _force),
        (dict(encoder_bias_um=(1.0, 0.0, 0.0, 0.0, 0.0, -2.0)), _bias),
    ],
    ids=[
        "camera_mass_error",
        "camera_com_offset",
        "base_pivot_radius_error",
        "platform_pivot_radius_error",
        "drive_stiffness_error",
        "drive_force_scale",
        "encoder_bias_um",
    ],
)
def test_a_field_changes_its_part_of_the_model_and_nothing_else(fields, edits):
    nominal = hexapod.physics._compiled(ELEVATION)
    plant = plant_model(**fields)
    assert changed_fields(nominal, plant), "the perturbation changed nothing"
    assert_edits_only(nominal, plant, edits(nominal, plant), rtol=1e-12)


def test_the_plant_geometry_is_the_model_s():
    """HexapodPlant.geometry (the plant's start and video) holds the pivots its model has."""
    plant = hexapod.HexapodPlant(base_pivot_radius_error=7e-4, platform_pivot_radius_error=-3e-4)
    physics = hexapod.HexapodPhysics.load(90.0, plant)
    model = physics.model.ptr
    geometry = physics.geometry
    for i in range(6):
        base = model.site_pos[model.site(f"base_pivot{i + 1}").id]
        platform = model.site_pos[model.site(f"platform_pivot{i + 1}").id] + RUBIN_CAMERA.rotation_pivot
        np.testing.assert_allclose(geometry.base_pivots[i], base, rtol=0, atol=1e-15)
        np.testing.assert_allclose(geometry.platform_pivots[i], platform, rtol=0, atol=1e-15)
        assert math.hypot(*geometry.base_pivots[i, :2]) - math.hypot(*RUBIN_CAMERA.base_pivots[i, :2]) == pytest.approx(
            7e-4, abs=1e-15
        )


def test_the_nominal_compile_stays_cached():
    hexapod.physics._compiled(ELEVATION)
    plant_model(camera_mass_error=0.02)  # a plant compiles its own model, not a nominal one
    before = hexapod.physics._compiled.cache_info()
    models = [
        hexapod.HexapodPhysics.load(ELEVATION).model.ptr,
        hexapod.HexapodPhysics.load(ELEVATION, hexapod.HexapodPlant()).model.ptr,
    ]
    after = hexapod.physics._compiled.cache_info()
    assert after.misses == before.misses and after.hits == before.hits + 2
    assert all(changed_fields(hexapod.physics._compiled(ELEVATION), m) == {} for m in models)


# ------------------------------------------------------------------ the controller keeps the nominal model


def test_the_controller_gets_the_nominal_model_at_the_nominal_start():
    params = SPEC.resolve(duration=0.1)
    setup = SPEC.build(params, plant=hexapod.HexapodPlant(**EVERYTHING))
    reference = SPEC.build(params)
    nominal = hexapod.physics._compiled(ELEVATION, params.drives)
    assert changed_fields(nominal, setup.physics.model.ptr)  # the plant is perturbed
    given_model = setup.task.nominal_physics()
    assert changed_fields(nominal, given_model.model.ptr) == {}
    assert given_model.geometry is RUBIN_CAMERA and given_model.encoder_bias is None
    for name in ("qpos", "qvel", "act"):
        np.testing.assert_array_equal(getattr(given_model.data, name), getattr(reference.physics.data, name))
    context = runner.start_episode(setup).context
    assert changed_fields(nominal, context.model) == {}
    assert changed_fields(nominal, context.nominal_physics().model.ptr) == {}
    # The plant starts where its encoders read the start pose's strut positions, at rest.
    readings = hexapod_planner.strut_positions(np.zeros(6))
    np.testing.assert_allclose(context.observation["joint_positions"], readings, rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        setup.physics.strut_positions(), readings - 1e-6 * np.array(EVERYTHING["encoder_bias_um"]), rtol=0, atol=1e-12
    )
    assert setup.physics.loop_closure_error() < 1e-9 and not setup.physics.data.qvel.any()
    assert "unknown" in context.sensors[0].bias
    assert setup.provenance.plant == hexapod.HexapodPlant(**EVERYTHING)


# ------------------------------------------------------------------ the perturbations act


HOLD = dict(duration=1.0, wind=0.0)  # the integral action has taken any load within ~0.5 s


@pytest.fixture(scope="module")
def nominal_hold():
    return run(**HOLD)


@pytest.fixture(scope="module")
def ideal_hold():
    return run(drives="ideal", **HOLD)


@pytest.fixture(scope="module")
def nominal_full():
    return run(wind=0.0)


def _static_drive_change(pose, elevation, force, moment) -> np.ndarray:
    """(6,) change of the drive forces (push positive) that holds an extra wrench on the platform
    (force N, moment N m about the rotation pivot, hexapod frame): minus the strut tensions."""
    return -hexapod_planner.static_strut_forces(pose, np.concatenate([force, moment]))


def _gravity(elevation):
    return GRAVITY * np.array([0.0, -math.cos(math.radians(elevation)), math.sin(math.radians(elevation))])


@pytest.mark.parametrize("error", [0.1, -0.1])
def test_a_camera_mass_error_changes_the_strut_forces_by_its_weight(ideal_hold, error):
    """On the ideal drives, whose struts carry the load and nothing else (as built, the end
    flexures' moments share the load too, and the 0.95 below is the rigid struts' share)."""
    nominal, _ = ideal_hold
    result, setup = run(dict(camera_mass_error=error), drives="ideal", **HOLD)
    pose = setup.physics.poses_from_qpos(result.log.qpos[-1])[0]
    rotation = hexapod_planner.rotation_matrix(pose[3:])
    weight = error * 3000.0 * _gravity(ELEVATION)
    expected = _static_drive_change(pose, ELEVATION, weight, np.cross(rotation @ [0, 0, CAMERA_Z], weight))
    measured = result.log.actuator_force[-1, :6] - nominal.log.actuator_force[-1, :6]
    np.testing.assert_allclose(measured, expected, rtol=2e-3, atol=2.0)
    # ~10 % of each strut's load: the camera is 3000 of the 3150 kg on the platform.
    fraction = measured / nominal.log.actuator_force[-1, :6]
    assert np.all(np.abs(fraction - error * 0.95) < 0.015), fraction


def test_a_camera_com_offset_adds_its_moment(nominal_hold):
    nominal, _ = nominal_hold
    offset = np.array([0.03, -0.02, 0.04])
    result, setup = run(dict(camera_com_offset=tuple(offset)), **HOLD)
    pose = setup.physics.poses_from_qpos(result.log.qpos[-1])[0]
    rotation = hexapod_planner.rotation_matrix(pose[3:])
    moment = np.cross(rotation @ offset, 3000.0 * _gravity(ELEVATION))
    expected = _static_drive_change(pose, ELEVATION, np.zeros(3), moment)
    measured = result.log.actuator_force[-1, :6] - nominal.log.actuator_force[-1, :6]
    np.testing.assert_allclose(measured, expected, rtol=5e-3, atol=2.0)
    assert np.abs(expected).max() > 100.0


def test_a_softer_drive_deflects_more_under_the_same_load(nominal_hold):
    nominal, _ = nominal_hold
    result, setup = run(dict(drive_stiffness_error=-0.3), **HOLD)

    def deflection(r):
        return r.log.act[-1, :6] - r.log.qpos[-1, setup.physics.drive_qpos]

    # The same static force through 0.7 kp: the servo's deflection (set-point - the position
    # its loop reads, the motor's) / 0.7.
    np.testing.assert_allclose(deflection(result), deflection(nominal) / 0.7, rtol=2e-3)
    np.testing.assert_allclose(result.log.actuator_force[-1, :6], nominal.log.actuator_force[-1, :6], rtol=2e-3)


def test_a_weaker_drive_saturates_at_its_own_limit():
    result, setup = run(dict(drive_force_scale=0.5), duration=0.2, wind=0.0)
    force = result.log.actuator_force[:, :6]
    # At 45 deg struts 1 and 2 carry 31 kN; half the 50 kN rating is 25 kN.
    assert np.all(np.abs(force) <= 25_000.0 * (1 + 1e-12))
    assert np.isclose(force[1:, :2].min(), -25_000.0, rtol=1e-12)
    checks = {c.name: c for c in result.checks}
    assert checks["strut_force"].limit == pytest.approx(25_000.0, rel=1e-12) and not checks["strut_force"].passed


def test_an_encoder_bias_offsets_the_true_struts_by_minus_the_bias(nominal_full):
    nominal, _ = nominal_full
    bias_um = np.array([2.0, -3.0, 0.0, 1.0, 0.0, -1.0])
    result, setup = run(dict(encoder_bias_um=tuple(bias_um)), wind=0.0)
    q = setup.physics.strut_qpos
    offset = 1e6 * (result.log.qpos[-1, q] - nominal.log.qpos[-1, q])
    np.testing.assert_allclose(offset, -bias_um, rtol=0, atol=0.05)
    checks = {c.name: c for c in result.checks}
    assert checks["pose_error_final"].value > 1.0 and not checks["pose_error_final"].passed


def test_a_pivot_radius_error_puts_the_platform_where_its_geometry_does(nominal_full):
    nominal, _ = nominal_full
    dr = 1e-4
    result, setup = run(dict(base_pivot_radius_error=dr), wind=0.0)
    geometry = setup.physics.geometry
    # At the start: the struts at their zero-pose length (the encoders read 0), so the pose moves
    # by -J^-1 dL, dL_i = u_i . (-(b'_i - b_i)) the length change the moved pivots make.
    start = setup.physics.poses_from_qpos(result.log.qpos[0])[0]
    units = RUBIN_CAMERA.platform_pivots - RUBIN_CAMERA.base_pivots
    units /= np.linalg.norm(units, axis=1, keepdims=True)
    length_change = -np.einsum("ij,ij->i", units, geometry.base_pivots - RUBIN_CAMERA.base_pivots)
    by_hand = -np.linalg.solve(hexapod_planner.jacobian(np.zeros(6)), length_change)
    np.testing.assert_allclose(start, by_hand, rtol=2e-3, atol=1e-12)
    # At the end the encoders are at the target's (nominal) strut positions: the plant's pivots
    # put the platform at its forward kinematics of them, and the check judges that true pose.
    target = setup.task.problem.target_pose
    lengths = hexapod_planner.strut_positions(target) + RUBIN_CAMERA.nominal_lengths
    true_pose, _ = hexapod_planner.forward_kinematics(lengths, geometry, initial=target)
    miss = (
        1e6
        * np.linalg.norm(
            hexapod_planner.pivot_positions(true_pose) - hexapod_planner.pivot_positions(target), axis=-1
        ).max()
    )
    checks = {c.name: c for c in result.checks}
    nominal_floor = {c.name: c for c in nominal.checks}["pose_error_final"].value
    assert checks["pose_error_final"].value == pytest.approx(miss, abs=nominal_floor + 0.05)
    assert miss > 10.0 and not checks["pose_error_final"].passed


# ------------------------------------------------------------------ bad values


_VECTORS = {name: d for name, kind, d, _ in hexapod.HexapodPlant.declarations() if kind.kind == "vector"}


@given(st.sampled_from(sorted(_VECTORS)), st.data(), st.floats(1e-9, 1e3))
@settings(max_examples=30, deadline=None)
def test_a_vector_element_out_of_its_range_is_refused_naming_it(key, data, excess):
    declared = _VECTORS[key]
    column = data.draw(st.integers(0, declared.length - 1))
    value = [0.0] * declared.length
    value[column] = declared.high + excess
    with pytest.raises(ParamError, match=rf"^plant\.{key}\[{column}\] = .* is outside"):
        SPEC.resolve_plant({key: value})


def test_api_run_refuses_bad_plants_before_building():
    for plant, words in [
        ({"camera_mass_error": 0.2}, "plant.camera_mass_error = 0.2 fraction is outside"),
        ({"camera_com_offset": [0, 0]}, "plant.camera_com_offset has 2 values, not 3"),
        ({"payload_mass_error": 0.1}, "unknown parameter 'plant.payload_mass_error'"),
    ]:
        with pytest.raises(ParamError) as refused:
            api.run("hexapod-sync-move", plant=plant)
        assert words in str(refused.value), str(refused.value)
