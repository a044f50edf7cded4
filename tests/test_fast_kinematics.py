"""FAST kinematics and statics (planners/fast/__init__.py) against the paper's eq. (1)-(9) (corrected per
REFERENCE.md), hand statics and REFERENCE.md's checked numbers."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from planbench.planners import fast
from planbench.planners.errors import LimitError
from planbench.planners.legs import structure_matrix

DEG = math.pi / 180
angles = st.floats(-math.pi, math.pi, allow_nan=False)
tilts = st.floats(0.0, 40 * DEG, allow_nan=False)


@given(angles, tilts, angles)
def test_tilt_torsion_is_the_composed_rotation_with_the_corrected_entries(phi, theta, omega):
    r = fast.tilt_torsion(phi, theta, omega)
    np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-14)
    expected = Rotation.from_euler("ZYZ", [phi, theta, omega - phi]).as_matrix()
    np.testing.assert_allclose(r, expected, atol=1e-14)
    cp, sp, ct, st_ = math.cos(phi), math.sin(phi), math.cos(theta), math.sin(theta)
    assert r[1, 2] == pytest.approx(sp * st_, abs=1e-14)  # REFERENCE.md: (2,3) = s(phi) s(theta)
    assert r[2, 0] == pytest.approx(-st_ * math.cos(omega - phi), abs=1e-14)  # (3,1)
    assert r[0, 2] == pytest.approx(cp * st_, abs=1e-14) and r[2, 2] == pytest.approx(ct, abs=1e-14)
    # The z axis tilts by theta toward the azimuth phi.
    np.testing.assert_allclose(r[:, 2], [cp * st_, sp * st_, ct], atol=1e-14)


@given(angles, st.floats(0.0, 30 * DEG), st.floats(-math.pi / 2, math.pi / 2))
def test_ab_angles_round_trip_through_r_ab(phi_ab, theta_ab, alpha):
    theta_a, theta_b = fast.ab_angles(phi_ab, theta_ab, alpha)
    r_ab = fast.ab_rotation(theta_a, theta_b, alpha)
    tilt = [math.cos(phi_ab) * math.sin(theta_ab), math.sin(phi_ab) * math.sin(theta_ab), math.cos(theta_ab)]
    np.testing.assert_allclose(r_ab[:, 2], tilt, atol=1e-13)
    # Eq. (7) and the corrected eq. (8).
    s = math.sin(theta_ab)
    assert math.sin(theta_b) == pytest.approx(s * math.sin(alpha - phi_ab), abs=1e-13)
    assert math.sin(theta_a) * math.cos(theta_b) == pytest.approx(s * math.cos(phi_ab - alpha), abs=1e-13)
    # The printed eq. (8) sign (cos a cos phi sin t - sin a sin phi sin t) is wrong unless
    # alpha or phi vanish: check it disagrees somewhere.
    if abs(math.sin(alpha) * math.sin(phi_ab) * s) > 1e-3:
        printed = math.cos(alpha) * math.cos(phi_ab) * s - math.sin(alpha) * math.sin(phi_ab) * s
        assert abs(printed - math.sin(theta_a) * math.cos(theta_b)) > 1e-6


@settings(max_examples=60)
@given(angles, st.floats(50 * DEG, 90 * DEG), st.floats(0.0, 1.0))
def test_eq9_round_trips(azimuth, elevation, share):
    """Feed pose -> cabin pose, A-B angles (eq. 3-9) -> feed (eq. 1, 4) is the identity."""
    s = fast.source_direction(azimuth, elevation)
    za = fast.zenith_angle(s)
    lo, hi = max(0.0, za - fast.FAST_LIMITS.ab_tilt), min(fast.FAST_LIMITS.cabin_tilt, za)
    tilt = lo + share * (hi - lo)
    feed = fast.feed_position(s)
    pose = fast.cabin_pose(feed, s, tilt)
    back = fast.feed_from_cabin(pose.origin, pose.rotation, pose.theta_a, pose.theta_b)
    np.testing.assert_allclose(back, feed, atol=1e-10)
    # The feed looks along s: R_C R_AB z = s.
    r_ab = fast.ab_rotation(pose.theta_a, pose.theta_b)
    np.testing.assert_allclose(pose.rotation @ r_ab[:, 2], s, atol=1e-13)
    assert np.linalg.norm(feed) == pytest.approx(fast.FOCAL_SURFACE_RADIUS)


def test_feed_at_the_zenith_is_r_above_the_centre_below():
    s = fast.source_direction(0.3, math.pi / 2)
    feed = fast.feed_position(s)
    np.testing.assert_allclose(feed, [0, 0, -162.15], atol=1e-9)
    assert feed[2] + fast.REFLECTOR_RADIUS == pytest.approx(137.85)  # above the dish bottom


def test_closest_focal_point():
    p0 = np.array([10.0, -20.0, -150.0])
    ph = fast.closest_focal_point(p0)
    assert np.linalg.norm(ph) == pytest.approx(fast.FOCAL_SURFACE_RADIUS)
    # Closer than any other focal-sphere point (sampled).
    rng = np.random.default_rng(0)
    others = rng.normal(size=(2000, 3))
    others = fast.FOCAL_SURFACE_RADIUS * others / np.linalg.norm(others, axis=1, keepdims=True)
    assert np.linalg.norm(p0 - ph) <= np.linalg.norm(p0 - others, axis=1).min()


def test_zenith_statics_by_hand():
    """REFERENCE.md: straight massless cables, 30 091.8 kg cabin, anchor plane 138.6 m above the
    dish bottom at the zenith: every cable carries 120.7 kN."""
    massless = fast.FastGeometry(cable_mass_per_length=0.0)
    origin = np.array([0.0, 0.0, -fast.REFLECTOR_RADIUS + 138.6])
    tensions = fast.cable_tensions(origin, np.eye(3), massless)
    # By hand: 6 T sin(beta) = m g, beta the cable's elevation at the cabin.
    tower, anchor = massless.tower_anchors[0], massless.cabin_anchors[0] + origin
    d = tower - anchor
    sin_beta = d[2] / np.linalg.norm(d)
    np.testing.assert_allclose(tensions, massless.cabin_mass * fast.GRAVITY / (6 * sin_beta), rtol=1e-12)
    assert tensions[0] / 1e3 == pytest.approx(120.7, abs=0.05)
    # Half of each cable's weight at its anchor adds w L / 2 / sin(beta) per cable.
    with_weight = fast.cable_tensions(origin, np.eye(3))
    length = np.linalg.norm(d)
    extra = 0.5 * fast.FAST.cable_mass_per_length * fast.GRAVITY * length / sin_beta
    np.testing.assert_allclose(with_weight, tensions + extra, rtol=1e-12)


@settings(max_examples=40)
@given(angles, st.floats(50 * DEG, 90 * DEG))
def test_tensions_balance_the_wrench(azimuth, elevation):
    s = fast.source_direction(azimuth, elevation)
    split = fast.split_tilt(fast.feed_position(s), s)
    pose = split.pose
    a = structure_matrix(fast.FAST.tower_anchors, fast.FAST.cabin_anchors, pose.origin, pose.rotation)
    r_ab = fast.ab_rotation(pose.theta_a, pose.theta_b)
    wrench = fast.gravity_wrench(
        pose.origin, pose.rotation, fast.cable_lengths(pose.origin, pose.rotation), ab_rotation=r_ab
    )
    np.testing.assert_allclose(a @ split.tensions + wrench, 0, atol=1e-6)
    # The A-B tilt moves the centre of mass by (m_AB / m)(R_AB - I) r_AB-com in the cabin frame.
    com = fast.cabin_com_at(r_ab)
    g = fast.FAST
    np.testing.assert_allclose(
        g.cabin_mass * com, g.cabin_mass * g.cabin_com + g.ab_mass * (r_ab @ g.ab_com - g.ab_com), atol=1e-9
    )
    assert split.tensions.min() >= fast.FAST_LIMITS.tension_min
    assert split.tensions.max() <= fast.FAST_LIMITS.tension_max


def test_level_cabin_at_40_deg_pushes_and_the_tilt_split_fixes_it():
    """REFERENCE.md: a level cabin at ZA 40 deg needs negative tension; tilting it (up to 14 deg)
    raises the smallest tension above T_min. Checked over all azimuths."""
    az = np.radians(np.arange(0.0, 360.0, 5.0))
    s = fast.source_direction(az, np.radians(50.0))
    feed = fast.feed_position(s)
    level = fast.cabin_pose(feed, s, 0.0)
    with pytest.raises(LimitError, match="tension"):
        fast.check_tensions(fast.cable_tensions(level.origin, level.rotation))
    # Level does not even respect the rotator: it would need 40 deg of A-B tilt.
    assert np.degrees(level.ab_tilt).max() > 26.4
    split = fast.split_tilt(feed, s)
    assert split.tensions.min() > 100e3
    assert np.all(np.degrees(split.pose.cabin_tilt) <= 14 + 1e-9)
    assert np.all(np.degrees(split.pose.ab_tilt) <= 26.4 + 1e-9)


def test_split_maximizes_the_smallest_tension():
    s = fast.source_direction(np.radians(17.0), np.radians(65.0))
    feed = fast.feed_position(s)
    split = fast.split_tilt(feed, s)
    za = fast.zenith_angle(s)
    grid = np.linspace(max(0.0, za - fast.FAST_LIMITS.ab_tilt), min(fast.FAST_LIMITS.cabin_tilt, za), 400)
    poses = fast.cabin_pose(np.broadcast_to(feed, (grid.size, 3)), np.broadcast_to(s, (grid.size, 3)), grid)
    best = fast.cable_tensions(poses.origin, poses.rotation).min(axis=1).max()
    # The soft minimum's optimum is within a few kN of the hard max-min.
    assert split.tensions.min() >= best - 3e3


def test_infeasible_pose_is_a_clear_error():
    s = fast.source_direction(0.0, np.radians(45.0))  # ZA 45 deg > 14 + 26.4
    with pytest.raises(LimitError, match=r"zenith angle 45.000 deg .* beyond"):
        fast.split_tilt(fast.feed_position(s), s)
    with pytest.raises(LimitError, match="zenith angle 45.000 deg at t = 2.000 s is beyond the limit 40.0"):
        fast.check_zenith_angle(np.stack([fast.source_direction(0, np.radians(60)), s]), times=[1.0, 2.0])
    strict = fast.FastLimits(tension_min=400e3)
    s40 = fast.source_direction(0.0, np.radians(50.0))
    with pytest.raises(LimitError, match="below the minimum 400 kN"):
        fast.split_tilt(fast.feed_position(s40), s40, limits=strict)


def test_stewart_legs_at_nominal_and_under_a_correction():
    nominal = fast.stewart_leg_lengths()
    np.testing.assert_allclose(nominal, nominal[0], rtol=1e-12)  # symmetric zig-zag
    assert 1.5 < nominal[0] < 3.0
    # A pure drop of the platform lengthens every leg by the same amount (to first order).
    down = fast.stewart_leg_lengths(offset=[0.0, 0.0, -0.01])
    np.testing.assert_allclose(down - nominal, (down - nominal)[0], rtol=1e-9)
    assert (down - nominal)[0] > 0
    # A sideways shift lengthens some legs and shortens others, within the stroke.
    side = fast.stewart_leg_lengths(offset=[0.05, 0.0, 0.0]) - nominal
    assert side.min() < 0 < side.max() and np.abs(side).max() < fast.STEWART.stroke
    # Batched.
    assert fast.stewart_leg_lengths(offset=np.zeros((7, 3))).shape == (7, 6)


def test_eq1_with_a_stewart_correction():
    """The Stewart platform's offset d (AB frame) moves the feed by R_C R_AB d (eq. 1, 4)."""
    s = fast.source_direction(1.0, math.radians(60.0))
    feed = fast.feed_position(s)
    pose = fast.cabin_pose(feed, s, math.radians(8.0))
    d = np.array([0.03, -0.02, 0.05])
    moved = fast.feed_from_cabin(pose.origin, pose.rotation, pose.theta_a, pose.theta_b, stewart_offset=d)
    r_ab = fast.ab_rotation(pose.theta_a, pose.theta_b)
    np.testing.assert_allclose(moved - feed, pose.rotation @ r_ab @ d, atol=1e-12)
