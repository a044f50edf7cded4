"""Plant uncertainty of FAST (planbench.fast.FastPlant): each field edits exactly its part of the
compiled model or the plant's cable physics, the planner and the controller keep the nominal
model and its feed-forward the nominal constants, the nominal plant runs as before, short runs
show each perturbation acting as computed by hand, and bad values are refused."""

from __future__ import annotations

import dataclasses
import functools
import math
from pathlib import Path

import mujoco
import numpy as np
import pytest
from model_diff import changed_fields
from plant_model import assert_edits_only

from planbench import api, runner, scenarios
from planbench import fast as fast_sim
from planbench.fast import physics as fast_physics
from planbench.fast.params import CABIN_BODIES, FastPlant
from planbench.fast.physics import CABLE_EA, CABLE_WEIGHT, FastPhysics
from planbench.params import ParamError
from planbench.planners import fast

ROOT = Path(__file__).resolve().parents[1]
SPEC = scenarios.get("fast-tracking")
GRAVITY = fast.GRAVITY
CABIN_MASS = 30_091.8  # kg, CASPR (REFERENCE.md)
#: Every field off nominal at once, inside its range.
EVERYTHING = dict(
    cable_ea_error=-0.05,
    cable_mass_error=0.1,
    anchor_radial_error=20.0,
    anchor_height_error=-10.0,
    anchor_errors=((5.0, 0.0, 0.0), (0.0, -8.0, 3.0)) + ((0.0, 0.0, 0.0),) * 4,
    cabin_mass_error=0.03,
    cabin_com_offset=(0.05, -0.02, 0.1),
    stewart_force_scale=0.9,
)


def plant_model(**fields) -> mujoco.MjModel:
    return FastPhysics.load(0, FastPlant(**fields)).model.ptr


@functools.cache
def hold(plant: FastPlant | None = None, duration: float = 2.0, stewart: bool = False):
    """(result, setup): the feed held at the zenith focal point of a short observation, no
    wind, the stabilizer off unless asked (the cabin's own statics), on the lumped cables
    (whose law the hand values below are; the chains have their own tests)."""
    plan = fast_sim.observation_plan(duration)
    setup = fast_sim.build(plan, fast_sim.FastParams(wind=0.0, stewart=stewart, cable_segments=0), plant=plant)
    return runner.run("fast-hold", setup), setup


@functools.cache
def started(plant: FastPlant | None = None):
    """The setup of ``hold`` at its start (the runner's start_episode: the controller's first
    commands, the plant's cable law written), before any step."""
    setup = fast_sim.build(
        fast_sim.observation_plan(2.0), fast_sim.FastParams(wind=0.0, stewart=False, cable_segments=0), plant=plant
    )
    runner.start_episode(setup)
    return setup


# ------------------------------------------------------------------ declarations


def test_every_fast_scenario_declares_the_nominal_fast_plant():
    for scenario in fast_sim.SCENARIOS:
        assert isinstance(scenario.plant, FastPlant) and scenario.plant.is_nominal
    assert FastPlant().cable_ea == CABLE_EA and FastPlant().cable_mass_per_length * GRAVITY == CABLE_WEIGHT


def test_the_readme_documents_every_plant_field():
    from planbench.params import markdown_table

    assert markdown_table(FastPlant) in (ROOT / "models/fast/README.md").read_text()


# ------------------------------------------------------------------ each field edits its part of the model


def _towers(errors_mm):
    """Tower tops moved by (6, 3) mm, and the cable tendons' spring lengths (they have no
    stiffness) that default to their lengths at qpos0."""

    def edits(nominal, plant):
        out = {"site_pos": {}}
        for i in range(6):
            site = nominal.site(f"tower{i + 1}_top").id
            out["site_pos"][site] = nominal.site_pos[site] + 1e-3 * np.asarray(errors_mm[i])
        out["tendon_lengthspring"] = {k: [plant.tendon_length0[k]] * 2 for k in range(6)}
        return out

    return edits


def _outward(dr_mm):
    """By hand: tower i stands at azimuth 30 + 60 (i - 1) deg."""
    azimuths = np.radians(30.0 + 60.0 * np.arange(6))
    return np.column_stack([dr_mm * np.cos(azimuths), dr_mm * np.sin(azimuths), np.zeros(6)])


def _cabin_mass(nominal, plant):
    ids = [nominal.body(b).id for b in CABIN_BODIES]
    return {
        "body_mass": {i: 1.05 * nominal.body_mass[i] for i in ids},
        "body_inertia": {i: 1.05 * nominal.body_inertia[i] for i in ids},
    }


def _cabin_com(nominal, plant):
    shell = nominal.body("cabin").id
    ratio = CABIN_MASS / 23_231.8  # the cabin's mass over the shell's (models/fast/README.md)
    return {"body_ipos": {shell: nominal.body_ipos[shell] + ratio * np.array([0.1, -0.2, 0.05])}}


def _cable_mass(nominal, plant):
    # A third of two 320 m cables of 11 kg/m at each anchor point.
    return {"body_mass": {nominal.body(f"anchor_mass{i}").id: 1.1 * 2133.9 for i in range(1, 4)}}


def _stewart_force(nominal, plant):
    return {"actuator_forcerange": {nominal.actuator(f"leg{i}").id: [-24_000.0, 24_000.0] for i in range(1, 7)}}


@pytest.mark.parametrize(
    "fields, edits",
    [
        (dict(anchor_radial_error=50.0), _towers(_outward(50.0))),
        (dict(anchor_height_error=-30.0), _towers(np.tile([0.0, 0.0, -30.0], (6, 1)))),
        (
            dict(anchor_errors=((10.0, -20.0, 5.0),) + ((0.0, 0.0, 0.0),) * 4 + ((0.0, 7.0, 0.0),)),
            _towers([[10.0, -20.0, 5.0]] + [[0.0, 0.0, 0.0]] * 4 + [[0.0, 7.0, 0.0]]),
        ),
        (
            dict(anchor_radial_error=-40.0, anchor_height_error=25.0, anchor_errors=((0.0, 0.0, 5.0),) * 6),
            _towers(_outward(-40.0) + [0.0, 0.0, 30.0]),
        ),
        (dict(cabin_mass_error=0.05), _cabin_mass),
        (dict(cabin_com_offset=(0.1, -0.2, 0.05)), _cabin_com),
        (dict(cable_mass_error=0.1), _cable_mass),
        (dict(stewart_force_scale=0.8), _stewart_force),
    ],
    ids=[
        "anchor_radial_error",
        "anchor_height_error",
        "anchor_errors",
        "anchors_together",
        "cabin_mass_error",
        "cabin_com_offset",
        "cable_mass_error",
        "stewart_force_scale",
    ],
)
def test_a_field_changes_its_part_of_the_model_and_nothing_else(fields, edits):
    nominal = fast_physics._compiled(0)
    plant = plant_model(**fields)
    assert changed_fields(nominal, plant), "the perturbation changed nothing"
    assert_edits_only(nominal, plant, edits(nominal, plant), rtol=1e-12)


def test_the_cabin_mass_and_com_are_the_whole_cabin_s():
    """By hand at home (the cabin level, every part at its nominal pose): the cabin's 30 091.8 kg
    times 1.05, its centre of mass moved by the offset."""
    offset = np.array([0.1, -0.2, 0.05])
    out = []
    for model in (fast_physics._compiled(0), plant_model(cabin_mass_error=0.05, cabin_com_offset=tuple(offset))):
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        ids = [model.body(b).id for b in CABIN_BODIES]
        mass = model.body_mass[ids]
        out.append((mass.sum(), (mass[:, None] * data.xipos[ids]).sum(axis=0) / mass.sum()))
    (m0, c0), (m1, c1) = out
    assert m0 == pytest.approx(CABIN_MASS, rel=1e-12) and m1 == pytest.approx(1.05 * CABIN_MASS, rel=1e-12)
    np.testing.assert_allclose(c1 - c0, offset, rtol=0, atol=1e-12)


def test_the_cable_constants_are_the_plant_s_and_the_model_keeps_them_out():
    """EA and the weight per length live in the plant's cable physics (the catenary law, the
    applied half weights), not in the compiled model."""
    assert changed_fields(fast_physics._compiled(0), plant_model(cable_ea_error=-0.1)) == {}
    _, setup = hold(FastPlant(cable_ea_error=-0.1, cable_mass_error=0.1))
    loads = setup.task.disturbance
    assert loads.ea == pytest.approx(1.35e8, rel=1e-15)
    assert loads.mass_per_length == pytest.approx(11.0, rel=1e-15)
    assert loads.weight == pytest.approx(11.0 * GRAVITY, rel=1e-15)
    _, nominal = hold()
    assert (nominal.task.disturbance.ea, nominal.task.disturbance.weight) == (CABLE_EA, CABLE_WEIGHT)


def test_the_discretized_cables_take_the_plant_s_ea_and_mass():
    plan = fast_sim.observation_plan(2.0)
    plant = FastPlant(cable_ea_error=-0.1, cable_mass_error=0.1, cabin_mass_error=0.02)
    setup = fast_sim.build(plan, fast_sim.FastParams(wind=0.0, cable_segments=3), plant=plant)
    runner.start_episode(setup)  # the chain's reset writes its node masses and springs
    model, physics = setup.physics.model.ptr, setup.physics
    rest = setup.physics.data.ctrl[physics.cable_ids] / 3
    np.testing.assert_allclose(
        model.body_mass[physics.node_bodies],
        (fast_physics.node_mass_factor(3) * 11.0 * rest)[:, None] * np.ones((6, 2)),
        rtol=1e-15,
    )
    np.testing.assert_allclose(
        model.tendon_stiffness[physics.segment_tendons[:, 1:]], (1.35e8 / rest)[:, None] * np.ones((6, 2)), rtol=1e-15
    )
    nominal = setup.task.nominal_physics().model.ptr
    assert changed_fields(fast_physics._compiled(3), nominal) == {}


# ------------------------------------------------------------------ the controller keeps the nominal model


def test_the_controller_gets_the_nominal_model_and_its_feedforward_stays_nominal():
    params = SPEC.resolve(duration=0.5)
    setup = SPEC.build(params, plant=FastPlant(**EVERYTHING))
    reference = SPEC.build(params)
    nominal = fast_physics._compiled(params.cable_segments)
    assert changed_fields(nominal, setup.physics.model.ptr)  # the plant is perturbed
    given = setup.task.nominal_physics()
    assert changed_fields(nominal, given.model.ptr) == {}
    for name in ("qpos", "qvel", "act", "ctrl"):
        np.testing.assert_array_equal(getattr(given.data, name), getattr(reference.physics.data, name))
    np.testing.assert_array_equal(given.tower_tops, reference.physics.tower_tops)
    # The plant is parked with the nominal model's winch lengths.
    np.testing.assert_array_equal(setup.physics.data.ctrl, reference.physics.data.ctrl)
    context = runner.start_episode(setup).context
    assert changed_fields(nominal, context.model) == {}
    assert changed_fields(nominal, context.nominal_physics().model.ptr) == {}
    runner.start_episode(reference)
    # Feed-forward: the winches' stretch and sag at the nominal EA and weight, the nominal
    # tower tops; the A-B rotator's gravity torque of the nominal masses.
    for name in ("l0_ff", "ab_setpoint", "p_platform", "r_platform"):
        np.testing.assert_array_equal(
            getattr(setup.components.controller, name), getattr(reference.components.controller, name), name
        )
    np.testing.assert_array_equal(setup.task.evaluation.planned_tower_tops, reference.physics.tower_tops)
    assert setup.provenance.plant == FastPlant(**EVERYTHING) and reference.provenance.plant == FastPlant()


# ------------------------------------------------------------------ each perturbation acts as computed by hand


def _vertical_pull(physics) -> float:
    """Sum of the cables' vertical force components on the cabin, N (the chord tensions)."""
    return float(physics.anchor_forces()[:, 2].sum())


def test_a_heavier_cabin_raises_the_cables_vertical_pull_by_its_extra_weight():
    """+5 %: the six cables hold 0.05 x 30 091.8 kg x g = 14.76 kN more (and the lumped half
    cable weights of their chords, a few N longer), at rest: the plant starts in its own
    equilibrium under the nominal winch lengths, lower."""
    nominal_setup, setup = started(), started(FastPlant(cabin_mass_error=0.05))
    extra = _vertical_pull(setup.physics) - _vertical_pull(nominal_setup.physics)
    longer = 0.5 * CABLE_WEIGHT * (setup.physics.cable_lengths() - nominal_setup.physics.cable_lengths()).sum()
    assert extra == pytest.approx(0.05 * CABIN_MASS * GRAVITY + longer, rel=1e-4)
    # Each tension is the statics' (six cables, six degrees of freedom: A t + W = 0 has one
    # solution) of the heavier cabin where it hangs, as the planner computes it for the
    # nominal one (tests/test_fast_physics.py: within 0.2 %).
    heavy = dataclasses.replace(fast.FAST, cabin_mass=1.05 * CABIN_MASS, ab_mass=1.05 * fast.FAST.ab_mass)
    origin, rotation = setup.physics.cabin_pose()
    theta_a, theta_b = setup.physics.ab_angles()
    statics = fast.cable_tensions(origin, rotation, heavy, ab_rotation=fast.ab_rotation(theta_a, theta_b, 0.0))
    np.testing.assert_allclose(setup.physics.cable_tensions(), statics, rtol=0.002)
    # At rest from the start, no drop test: released at the nominal pose it would fall at up
    # to 0.1 m x 1.9 rad/s (its heave mode); here only the cable loop's slow integral lifts it.
    nominal, _ = hold()
    heavier, held = hold(FastPlant(cabin_mass_error=0.05))
    cabin = heavier.log.sensordata[:, held.physics.sensor_block("cabin_pos")]
    planned = nominal.log.sensordata[0, held.physics.sensor_block("cabin_pos")]
    assert np.abs(heavier.log.qvel[:, 2]).max() < 0.01  # m/s, the cabin's vertical speed
    assert -0.15 < cabin[0, 2] - planned[2] < -0.05
    assert {c.name: c.value for c in heavier.checks}["cable_tension_max"] > {c.name: c.value for c in nominal.checks}[
        "cable_tension_max"
    ] + 5.0  # kN


def test_softer_cables_obey_the_plant_s_law_and_let_the_cabin_down():
    """EA -10 %: every chord is the elastic catenary's L0 (1 + T / EA') - w^2 l^2 L0 / (24 T^2)
    at its tension with the plant's EA' (the nominal EA misses it by the extra stretch
    L0 T (1/EA' - 1/EA), ~4 cm), and the tensions are the statics' where the cabin hangs."""
    setup = started(FastPlant(cable_ea_error=-0.1))
    physics = setup.physics
    tension, chords = physics.cable_tensions(), physics.cable_lengths()
    vectors = physics.data.site_xpos[physics.anchor_sites] - physics.tower_tops
    span = np.hypot(vectors[:, 0], vectors[:, 1])
    l0 = physics.data.ctrl[physics.cable_ids]

    def law(ea):
        return l0 * (1 + tension / ea) - (CABLE_WEIGHT * span) ** 2 * l0 / (24 * tension**2)

    np.testing.assert_allclose(chords, law(0.9 * CABLE_EA), rtol=0, atol=2e-4)
    assert np.all(chords - law(CABLE_EA) > 0.03)
    origin, rotation = physics.cabin_pose()
    theta_a, theta_b = physics.ab_angles()
    statics = fast.cable_tensions(origin, rotation, ab_rotation=fast.ab_rotation(theta_a, theta_b, 0.0))
    np.testing.assert_allclose(tension, statics, rtol=0.002)
    assert physics.cabin_pose()[0][2] < started().physics.cabin_pose()[0][2] - 0.05


def test_a_moved_tower_top_moves_the_cabin_and_the_stabilizer_keeps_the_feed():
    """One tower top 50 mm outward: its cable pulls the cabin toward it; the Stewart stabilizer
    still holds the feed on its path (the checks judge the true feed)."""
    plant = FastPlant(
        anchor_errors=((50.0 * math.cos(math.radians(30)), 50.0 * math.sin(math.radians(30)), 0.0),)
        + ((0.0, 0.0, 0.0),) * 5
    )
    result, setup = hold(plant, stewart=True)
    nominal, _ = hold(stewart=True)
    start = result.log.sensordata[0, setup.physics.sensor_block("cabin_pos")]
    planned = nominal.log.sensordata[0, setup.physics.sensor_block("cabin_pos")]
    toward = np.array([math.cos(math.radians(30)), math.sin(math.radians(30))])
    assert (start - planned)[:2] @ toward > 0.005
    checks = {c.name: c for c in result.checks}
    assert checks["feed_error_max"].passed and checks["cabin_error_rms"].value > 5.0


def test_a_derated_stewart_is_judged_against_its_own_limit():
    result, setup = hold(FastPlant(stewart_force_scale=0.5), stewart=True)
    check = {c.name: c for c in result.checks}["stewart_force"]
    assert check.limit == pytest.approx(15.0) and check.value < check.limit


# ------------------------------------------------------------------ bad values


_FIELDS = {name: (kind, d) for name, kind, d, _ in FastPlant.declarations()}


@pytest.mark.parametrize("key", sorted(_FIELDS))
@pytest.mark.parametrize("above", [True, False])
def test_a_field_out_of_its_range_is_refused_naming_it(key, above):
    kind, declared = _FIELDS[key]
    value = declared.high + 1e-6 if above else declared.low - 1e-6
    if key == "anchor_errors":
        table = [[0.0] * 3 for _ in range(6)]
        table[4][1] = value
        value, name = table, r"anchor_errors\[4\]\[1\]"
    elif declared.length:
        value, name = [0.0, value, 0.0], rf"{key}\[1\]"
    else:
        name = key
    with pytest.raises(ParamError, match=rf"^plant\.{name} = .* is outside \[{declared.low:g}, {declared.high:g}\]"):
        SPEC.resolve_plant({key: value})


def test_api_run_refuses_bad_plants_before_building():
    for plant, words in [
        ({"cable_ea_error": 0.2}, "plant.cable_ea_error = 0.2 fraction is outside [-0.35, 0.1]"),
        ({"anchor_errors": [[0, 0, 0]] * 5}, "plant.anchor_errors has 5 rows, fewer than 6"),
        ({"cabin_com_offset": [0, 0]}, "plant.cabin_com_offset has 2 values, not 3"),
        ({"tower_height_error": 1.0}, "unknown parameter 'plant.tower_height_error'"),
    ]:
        with pytest.raises(ParamError) as refused:
            api.run("fast-tracking", plant=plant)
        assert words in str(refused.value), str(refused.value)


def test_stiffer_cables_are_refused_with_too_many_segments():
    """EA +10 % raises the segments' axial mode by sqrt(1.1): 14 segments then break the
    timestep's limit that 14 nominal ones keep (max_cable_segments)."""
    params = SPEC.resolve(duration=0.1, cable_segments=14)
    with pytest.raises(ParamError, match=r"^cable_segments = 14 with plant\.cable_ea_error = 0\.1 .* at most 13"):
        SPEC.build(params, plant=FastPlant(cable_ea_error=0.1))
