"""models/fast against the planner (planbench.planners.fast) and against hand calculations."""

import functools
import math

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from planbench import models
from planbench.fast import physics as fp
from planbench.fast.physics import FastPhysics
from planbench.planners import fast

G = fast.FAST


@functools.cache
def shared_physics() -> FastPhysics:
    return FastPhysics.load()


@pytest.fixture
def physics():
    return shared_physics()


def _random_pose(rng):
    origin = np.array([0.0, 0.0, -155.65]) + rng.uniform([-60, -60, -15], [60, 60, 15])
    rotation = Rotation.from_rotvec(rng.uniform(-0.25, 0.25, 3)).as_matrix()
    return origin, rotation


def test_cable_lengths_equal_the_planner_at_random_poses(physics):
    rng = np.random.default_rng(1)
    for _ in range(20):
        origin, rotation = _random_pose(rng)
        physics.set_configuration(origin, rotation, 0.0, 0.0)
        np.testing.assert_allclose(physics.cable_lengths(), fast.cable_lengths(origin, rotation), atol=1e-9)
        np.testing.assert_allclose(physics.tower_tops, G.tower_anchors, atol=1e-9)


@settings(max_examples=25)
@given(st.floats(-0.45, 0.45), st.floats(-0.45, 0.45), st.floats(-0.6, 0.6))
def test_feed_equals_eq1_at_random_rotator_angles(theta_a, theta_b, multifeed):
    """Forward kinematics, eq. (1) and (4): the model's feed site is the planner's feed."""
    physics = shared_physics()
    origin, rotation = _random_pose(np.random.default_rng(int(1e6 * (theta_a + 1))))
    physics.set_configuration(origin, rotation, theta_a, theta_b, multifeed)
    expected = fast.feed_from_cabin(origin, rotation, theta_a, theta_b)
    np.testing.assert_allclose(physics.feed_position(), expected, atol=1e-9)
    assert physics.loop_closure_error() < 1e-8  # the MJCF's 9 digits  # the set configuration closes the Stewart loops


def test_stewart_joint_sites_equal_the_planner_geometry(physics):
    """Leg lengths between the model's joint sites equal planbench.planners.fast.stewart_leg_lengths, at
    the nominal pose and with the platform displaced and turned in the AB frame."""
    model, data = physics.model.ptr, physics.data.ptr
    base = [model.site(f"base_joint{i}").id for i in range(1, 7)]
    plat = [model.site(f"platform_joint{i}").id for i in range(1, 7)]
    physics.set_configuration([0, 0, -155.65], np.eye(3), 0.0, 0.0)
    np.testing.assert_allclose(
        np.linalg.norm(data.site_xpos[plat] - data.site_xpos[base], axis=1), fast.stewart_leg_lengths(), atol=1e-9
    )
    # Move the free platform by an offset and rotation in the AB frame (= world at this pose).
    offset, turn = np.array([0.05, -0.03, 0.02]), Rotation.from_rotvec([0.01, -0.02, 0.03])
    adr = model.joint("feed_platform").qposadr[0]
    data.qpos[adr : adr + 3] += offset
    data.qpos[adr + 3 : adr + 7] = np.roll(turn.as_quat(), 1)
    mujoco.mj_kinematics(model, data)
    lengths = np.linalg.norm(data.site_xpos[plat] - data.site_xpos[base], axis=1)
    np.testing.assert_allclose(lengths, fast.stewart_leg_lengths(offset, turn.as_matrix()), atol=1e-9)
    # The legs' slides measure the change from nominal: the rod tip at slide 0 is the platform joint.
    for i in range(1, 7):
        assert model.body(f"leg{i}_rod").pos[2] == pytest.approx(fast.stewart_leg_lengths()[i - 1], abs=1e-8)


def test_masses_and_centre_of_mass_equal_the_planner(physics):
    physics.set_configuration([0, 0, -155.65], np.eye(3), 0.0, 0.0)
    cabin = ["cabin", "ab_a", "ab_b", "feed_platform", "receiver"] + [
        f"leg{i}_{part}" for i in range(1, 7) for part in ("housing", "rod")
    ]
    mass, com = physics.subtree_mass(cabin)
    assert mass == pytest.approx(G.cabin_mass, abs=1e-6)  # CASPR's 30 091.8 kg
    np.testing.assert_allclose(com - [0, 0, -155.65], G.cabin_com, atol=1e-5)
    tilted = [n for n in cabin if n not in ("cabin", "ab_a")]
    ab_mass, ab_com = physics.subtree_mass(tilted)
    assert ab_mass == pytest.approx(G.ab_mass)
    centre = physics.data.site_xpos[physics.model.site("ab_center").id]
    np.testing.assert_allclose(ab_com - centre, G.ab_com, atol=1e-5)
    # The tilted part moves the centre of mass as planbench.planners.fast.cabin_com_at says.
    r_ab = fast.ab_rotation(0.3, -0.2)
    physics.set_configuration([0, 0, -155.65], np.eye(3), 0.3, -0.2)
    _, com = physics.subtree_mass(cabin)
    np.testing.assert_allclose(com - [0, 0, -155.65], fast.cabin_com_at(r_ab), atol=1e-5)


def test_lumped_cable_mass_and_gravity_compensation(physics):
    """A third of each cable's mass (10 kg/m, the zenith lengths) moves with its anchor, two
    cables per anchor point, gravity-compensated (the half weight is an applied force)."""
    model = physics.model.ptr
    length = fast.cable_lengths(np.array([0, 0, -155.65]), np.eye(3))[0]
    for i in range(1, 4):
        body = model.body(f"anchor_mass{i}")
        assert body.mass[0] == pytest.approx(2 * G.cable_mass_per_length * length / 3, rel=1e-4)
        assert model.body_gravcomp[body.id] == 1.0
    np.testing.assert_allclose(np.sort(model.body("anchor_mass1").pos), np.sort(G.cabin_anchors[0]), atol=1e-8)


def test_cable_actuators_pull_only_within_the_tension_limit(physics):
    model = physics.model.ptr
    for i in physics.cable_ids:
        assert model.actuator_forcerange[i, 0] == -fast.FAST_LIMITS.tension_max
        assert model.actuator_forcerange[i, 1] == 0.0  # a cable never pushes
        assert model.actuator_trntype[i] == mujoco.mjtTrn.mjTRN_TENDON


def test_home_keyframe_is_the_zenith_equilibrium(physics):
    """At home the default (zenith) cable law gives the planner's static tensions."""
    physics.reset(keyframe_id=0)
    mujoco.mj_forward(physics.model.ptr, physics.data.ptr)
    origin, rotation = physics.cabin_pose()
    np.testing.assert_allclose(origin, [0, 0, -155.65], atol=1e-9)
    np.testing.assert_allclose(physics.cable_tensions(), fast.cable_tensions(origin, rotation), rtol=1e-4)
    np.testing.assert_allclose(physics.feed_position(), [0, 0, -fast.FOCAL_SURFACE_RADIUS], atol=1e-9)


def test_reflector_mesh_is_the_300_m_cap_with_a_500_m_aperture():
    vertices = np.array(
        [
            [float(v) for v in line.split()[1:]]
            for line in (models.model_dir("fast") / "assets" / "reflector.obj").read_text().splitlines()
            if line.startswith("v ")
        ]
    )
    np.testing.assert_allclose(np.linalg.norm(vertices, axis=1), fast.REFLECTOR_RADIUS, rtol=1e-6)
    assert np.hypot(vertices[:, 0], vertices[:, 1]).max() == pytest.approx(250.0, rel=1e-6)
    assert vertices[:, 2].min() == pytest.approx(-fast.REFLECTOR_RADIUS)


# ----------------------------------------------------------------------------- cable law


def test_ernst_modulus_at_the_reference_check():
    """REFERENCE.md: E A = 1.5e8 N, w = 98 N/m at the zenith (120.7 kN with massless cables,
    horizontal span 294.4 m): E_eq ~ E / 7."""
    span = 294.3888
    ratio = fp.tangent_stiffness(120.7e3, span, 320.0) / (fp.CABLE_EA / 320.0)
    assert 1 / ratio == pytest.approx(6.9, abs=0.05)


@settings(max_examples=60)
@given(st.floats(20e3, 1.2e6), st.floats(150.0, 560.0), st.floats(0.3, 1.0))
def test_catenary_round_trip_and_tangent(tension, chord, span_ratio):
    span = span_ratio * chord
    l0 = fp.unstretched_length(chord, tension, span)
    assert fp.catenary_tension(chord, l0, span, guess=2 * tension) == pytest.approx(tension, rel=1e-9)
    # dT/dL at fixed L0 by central differences equals the tangent (Ernst) stiffness.
    h = 1e-4
    up = fp.catenary_tension(chord + h, l0, span, guess=tension)
    down = fp.catenary_tension(chord - h, l0, span, guess=tension)
    assert (up - down) / (2 * h) == pytest.approx(float(fp.tangent_stiffness(tension, span, l0)), rel=1e-5)


def test_a_slack_cable_keeps_only_its_sag_tension():
    """10 m paid out on a 320 m cable across 294 m: only the hanging cable's tension remains,
    w^2 l_h^2 L0 / (24 T^2) = L0 - L by hand."""
    chord, span = 320.0, 294.0
    l0 = chord + 10.0
    t = fp.catenary_tension(chord, l0, span, guess=150e3)
    by_hand = math.sqrt(fp.CABLE_WEIGHT**2 * span**2 * l0 / (24 * 10.0))
    assert t == pytest.approx(by_hand, rel=0.01)
    assert t < fast.FAST_LIMITS.tension_min
