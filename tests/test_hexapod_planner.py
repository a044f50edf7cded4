"""The Rubin hexapod planner (planners/hexapod/__init__.py) against the paper, REFERENCE.md and
independent computations: kinematics, statics, the continuous generator and its tick-grid
realization.

The paper (REFERENCE.md "Papers") plans *half* moves: its T values
are half-move times, so a whole move of a strut takes 2 T.
"""

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from planbench.planners.errors import LimitError, PlanningError
from planbench.planners.hexapod import (
    CONTROL_DT,
    RUBIN_CAMERA,
    RUBIN_LIMITS,
    KinematicsError,
    euler_rate_matrix,
    forward_kinematics,
    hexapod_space_min_time,
    jacobian,
    long_move_closed_form,
    long_move_iteration,
    plan_move,
    plan_moves,
    plan_strut_moves,
    random_poses,
    rotation_matrix,
    solve_profiles,
    static_strut_forces,
    strut_lengths,
    strut_min_time,
    strut_positions,
)
from planbench.planners.legs import component_norm, leg_vector_components, leg_vectors, structure_matrix

UM = 1e-6
DT = CONTROL_DT
LIM = RUBIN_LIMITS
V_MAX = LIM.strut_speed
A_MAX = LIM.strut_accel
LOW, HIGH = LIM.pose_lower, LIM.pose_upper

# REFERENCE.md, "Rubin hexapod" (ts_mthexapod constants.py, camera hexapod), um, the +/- and
# -/+ pairs written out in order.
REF_BASE_UM = np.array(
    [
        [227_600, 653_800, -525_000],
        [-227_600, 653_800, -525_000],
        [-680_000, -129_700, -525_000],
        [-452_300, -524_000, -525_000],
        [452_300, -524_000, -525_000],
        [680_000, -129_700, -525_000],
    ],
    dtype=float,
)
REF_MIRROR_UM = np.array(
    [
        [472_800, 512_200, -121_400],
        [-472_800, 512_200, -121_400],
        [-680_000, 153_300, -121_400],
        [-207_200, -665_500, -121_400],
        [207_200, -665_500, -121_400],
        [680_000, 153_300, -121_400],
    ],
    dtype=float,
)
REF_PIVOT_UM = np.array([0.0, 0.0, -2_758_400])

BASE = REF_BASE_UM * UM
MIRROR = REF_MIRROR_UM * UM
PIVOT = REF_PIVOT_UM * UM


# --------------------------------------------------------------------------- helpers


def my_strut_lengths(pose):
    """Independent IK: |c + t + R (m_i - c) - b_i| with scipy's rotation, poses (N, 6)."""
    pose = np.atleast_2d(pose)
    rot = Rotation.from_euler("XYZ", pose[:, 3:]).as_matrix()  # (N, 3, 3)
    moved = PIVOT + pose[:, None, :3] + np.einsum("nij,kj->nki", rot, MIRROR - PIVOT)
    return np.linalg.norm(moved - BASE, axis=-1)


def in_stroke(pose):
    change = my_strut_lengths(pose) - np.linalg.norm(MIRROR - BASE, axis=1)
    return np.all(np.abs(change) <= LIM.stroke, axis=-1)


def my_random_poses(rng, n):
    """Uniform poses inside the pose limits and the stroke, by my own rejection."""
    out = []
    count = 0
    while count < n:
        p = rng.uniform(LOW, HIGH, size=(2 * n, 6))
        p = p[in_stroke(p)]
        out.append(p)
        count += len(p)
    return np.vstack(out)[:n]


def optimal_strut_time(distance):
    """Time-optimal rest-to-rest duration of a whole distance D under V_MAX, A_MAX, s."""
    D = np.asarray(distance, dtype=float)
    return np.where(D <= V_MAX**2 / A_MAX, 2.0 * np.sqrt(D / A_MAX), D / V_MAX + V_MAX / A_MAX)


def tick_times(move):
    return np.arange(int(move.n_ticks.max()) + 1) * move.dt


def check_single_move(move, start, target):
    """Every property a planned StrutMove must have, integrated and sampled tick by tick."""
    acc = move.commanded_acceleration()
    pos, vel = move.integrate()
    assert np.all(np.abs(acc) <= A_MAX)
    # Summing a dt tick by tick rounds: where the peak is exactly v_max (a move on the
    # short/long boundary) the running sum ends an ulp above it; allow 1e-13 relative.
    assert np.all(np.abs(vel) <= V_MAX * (1 + 1e-13))
    np.testing.assert_allclose(pos[-1], target, rtol=0, atol=1e-12)
    np.testing.assert_allclose(vel[-1], 0.0, rtol=0, atol=1e-15)
    # Each strut is at rest on its target from its own last tick on.
    for i in range(6):
        n = int(move.n_ticks[i])
        np.testing.assert_allclose(pos[n:, i], target[i], rtol=0, atol=1e-12)
        assert np.all(np.abs(vel[n:, i]) <= 1e-15)
    # sample() at the ticks is the integrated motion.
    t = tick_times(move)
    s = move.sample(t)
    np.testing.assert_allclose(s.position, pos, rtol=0, atol=1e-12)
    np.testing.assert_allclose(s.velocity, vel, rtol=0, atol=1e-12)
    assert np.all(np.abs(s.velocity) <= V_MAX) and np.all(np.abs(s.acceleration) <= A_MAX)
    # After the end: exactly the target, at rest.
    after = move.sample(np.array([move.duration, move.duration + 0.3, move.duration + 100.0]))
    assert np.all(after.position == target[None, :])
    assert np.all(after.velocity == 0.0) and np.all(after.acceleration == 0.0)
    # Monotone from start to target, never beyond either.
    fine = move.sample(np.linspace(0.0, move.duration + DT, 4 * len(t) + 7))
    signed = (fine.position - start) * np.sign(target - start)
    assert np.all(np.diff(signed, axis=0) >= 0.0)
    lo, hi = np.minimum(start, target), np.maximum(start, target)
    assert np.all(fine.position >= lo) and np.all(fine.position <= hi)


# --------------------------------------------------------------------------- strategies

angle = st.floats(-np.pi, np.pi, allow_nan=False, allow_infinity=False)


def _axis(lo, hi):
    """Hypothesis favours tiny floats; the scaled integers spread values over the range."""
    return st.one_of(st.floats(lo, hi), st.integers(-1000, 1000).map(lambda k: (k / 1000) * (hi if k > 0 else -lo)))


@st.composite
def poses(draw):
    return np.array([draw(_axis(float(lo), float(hi))) for lo, hi in zip(LOW, HIGH, strict=True)])


# =========================================================================== 1. kinematics


@given(st.tuples(angle, angle, angle))
def test_rotation_matrix_is_scipy_intrinsic_xyz(angles):
    np.testing.assert_allclose(
        rotation_matrix(np.array(angles)), Rotation.from_euler("XYZ", angles).as_matrix(), atol=1e-14
    )


def test_rotation_matrix_vectorized():
    rng = np.random.default_rng(1)
    angles = rng.uniform(-np.pi, np.pi, size=(4, 5, 3))
    expected = Rotation.from_euler("XYZ", angles.reshape(-1, 3)).as_matrix().reshape(4, 5, 3, 3)
    np.testing.assert_allclose(rotation_matrix(angles), expected, atol=1e-14)


def test_geometry_matches_reference():
    np.testing.assert_array_equal(RUBIN_CAMERA.base_pivots, BASE)
    np.testing.assert_array_equal(RUBIN_CAMERA.platform_pivots, MIRROR)
    np.testing.assert_array_equal(RUBIN_CAMERA.rotation_pivot, PIVOT)
    # Six nominal strut lengths, by hand, are equal to each other within 0.2 mm...
    by_hand = np.sqrt(np.sum((MIRROR - BASE) ** 2, axis=1))
    assert by_hand.max() - by_hand.min() < 0.2e-3
    assert 0.49 < by_hand.min() and by_hand.max() < 0.50
    np.testing.assert_allclose(RUBIN_CAMERA.nominal_lengths, by_hand, rtol=0, atol=1e-15)
    # ...and the zero pose has them.
    np.testing.assert_allclose(strut_lengths(np.zeros(6)), by_hand, rtol=0, atol=1e-15)
    np.testing.assert_allclose(strut_positions(np.zeros(6)), 0.0, atol=1e-15)


def test_limits_match_reference():
    np.testing.assert_allclose(
        LIM.pose_upper,
        [11_400 * UM, 11_400 * UM, 13_100 * UM, np.radians(0.36), np.radians(0.36), np.radians(0.10)],
        rtol=1e-15,
    )
    np.testing.assert_allclose(LIM.pose_lower, -LIM.pose_upper, rtol=1e-15)
    assert LIM.stroke == pytest.approx(14_100 * UM, rel=1e-15)
    assert LIM.strut_speed == pytest.approx(500 * UM, rel=1e-15)
    assert LIM.strut_accel == pytest.approx(500 * UM, rel=1e-15)
    assert LIM.linear_speed == pytest.approx(2_000 * UM, rel=1e-15)
    assert LIM.angular_speed == pytest.approx(np.radians(0.1146), rel=1e-15)
    assert LIM.threshold_distance == pytest.approx((500 * UM) ** 2 / (2 * 500 * UM), rel=1e-15)
    assert DT == 1 / 200


@given(poses())
def test_ik_fk_round_trip(pose):
    assume(in_stroke(pose)[0])
    found, iterations = forward_kinematics(strut_lengths(pose))
    np.testing.assert_allclose(found[:3], pose[:3], rtol=0, atol=1e-9)
    np.testing.assert_allclose(found[3:], pose[3:], rtol=0, atol=1e-9)
    assert iterations <= 6


def test_ik_fk_round_trip_batch():
    rng = np.random.default_rng(2)
    batch = my_random_poses(rng, 1000)
    found, iterations = forward_kinematics(strut_lengths(batch))
    assert found.shape == (1000, 6)
    assert np.abs(found - batch).max() < 1e-9
    assert iterations <= 6


def test_random_poses_are_inside_limits_and_stroke():
    p = random_poses(500, np.random.default_rng(3))
    assert p.shape == (500, 6)
    assert np.all(p >= LOW) and np.all(p <= HIGH)
    assert np.all(in_stroke(p))


def test_jacobian_is_finite_differences():
    rng = np.random.default_rng(4)
    for pose in my_random_poses(rng, 20):
        h = 1e-6
        fd = np.empty((6, 6))
        for j in range(6):
            e = np.zeros(6)
            e[j] = h
            fd[:, j] = (my_strut_lengths(pose + e)[0] - my_strut_lengths(pose - e)[0]) / (2 * h)
        np.testing.assert_allclose(jacobian(pose), fd, rtol=0, atol=2e-8)
    # Vectorized: a stack of poses gives a stack of Jacobians.
    batch = my_random_poses(rng, 7)
    stacked = jacobian(batch)
    for k in range(7):
        np.testing.assert_allclose(stacked[k], jacobian(batch[k]), atol=1e-15)


def _jacobian_as_arrays(pose):
    """``jacobian``'s formula on (..., 6, 3) arrays and einsum (the reference form of its
    component arithmetic)."""
    position, rotation = RUBIN_CAMERA.rotation_pivot + pose[..., :3], rotation_matrix(pose[..., 3:])
    vectors = leg_vectors(RUBIN_CAMERA.base_pivots, RUBIN_CAMERA.platform_local, position, rotation)
    units = vectors / np.linalg.norm(vectors, axis=-1, keepdims=True)
    arms = np.einsum("...jk,nk->...nj", rotation, RUBIN_CAMERA.platform_local)
    angular = np.einsum("...nj,...jk->...nk", np.cross(arms, units), euler_rate_matrix(pose[..., 3:]))
    return np.concatenate([units, angular], axis=-1)


@given(st.lists(poses(), min_size=1, max_size=5), st.floats(1.0, 1e4))
def test_components_are_the_array_form_bit_for_bit(pose_list, scale):
    """The kinematics on components (``leg_vector_components``, ``jacobian``) gives the numbers
    of the (..., 6, 3) array form, bit for bit, in and far outside the pose limits."""
    batch = np.array(pose_list) * np.array([scale, scale, scale, 1.0, 1.0, 1.0])
    position, rotation = RUBIN_CAMERA.rotation_pivot + batch[:, :3], rotation_matrix(batch[:, 3:])
    arrays = leg_vectors(RUBIN_CAMERA.base_pivots, RUBIN_CAMERA.platform_local, position, rotation)
    vectors, arms = leg_vector_components(RUBIN_CAMERA.base_pivots, RUBIN_CAMERA.platform_local, position, rotation)
    np.testing.assert_array_equal(np.stack(vectors, axis=-1), arrays)
    np.testing.assert_array_equal(
        np.stack(arms, axis=-1), np.einsum("...jk,nk->...nj", rotation, RUBIN_CAMERA.platform_local)
    )
    np.testing.assert_array_equal(component_norm(*vectors), np.linalg.norm(arrays, axis=-1))
    np.testing.assert_array_equal(jacobian(batch), _jacobian_as_arrays(batch))
    np.testing.assert_array_equal(jacobian(batch[0]), _jacobian_as_arrays(batch[0]))


def test_ik_independent_formula():
    rng = np.random.default_rng(5)
    batch = np.vstack([my_random_poses(rng, 500), rng.uniform(-0.05, 0.05, size=(100, 6))])  # also outside the limits
    np.testing.assert_allclose(strut_lengths(batch), my_strut_lengths(batch), rtol=1e-14, atol=0)
    np.testing.assert_allclose(
        strut_positions(batch), my_strut_lengths(batch) - np.linalg.norm(MIRROR - BASE, axis=1), rtol=0, atol=1e-14
    )


def _provably_unreachable(lengths):
    """Triangle inequality: |m_i - m_j| <= L_i + |b_i - b_j| + L_j for every pair, and
    L_i <= L_j + |b_i - b_j| + |m_i - m_j|; a violated pair means no pose has these lengths."""
    for i in range(6):
        for j in range(6):
            if i == j:
                continue
            bb = np.linalg.norm(BASE[i] - BASE[j])
            mm = np.linalg.norm(MIRROR[i] - MIRROR[j])
            if mm > lengths[i] + bb + lengths[j] or lengths[i] > lengths[j] + bb + mm:
                return True
    return False


@pytest.mark.parametrize(
    "lengths",
    [
        RUBIN_CAMERA.nominal_lengths + np.array([2.0, 0, 0, 0, 0, 0]),
        np.zeros(6),
        RUBIN_CAMERA.nominal_lengths * 0.1,
    ],
)
def test_fk_unreachable_lengths_raise(lengths):
    assert _provably_unreachable(lengths)
    with pytest.raises(KinematicsError, match="did not converge|singular"):
        forward_kinematics(lengths)
    assert issubclass(KinematicsError, PlanningError)


def test_fk_far_but_reachable_lengths_converge():
    """Nominal + 0.4 m on one strut is not unreachable for a hexapod without joint limits:
    FK finds a pose (far outside the pose limits) that has exactly these lengths."""
    lengths = RUBIN_CAMERA.nominal_lengths + np.array([0.4, 0, 0, 0, 0, 0])
    assert not _provably_unreachable(lengths)
    pose, _ = forward_kinematics(lengths)
    np.testing.assert_allclose(my_strut_lengths(pose)[0], lengths, rtol=0, atol=1e-11)
    assert np.abs(pose[:3]).max() > 0.1


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_fk_non_finite_lengths_raise(bad):
    lengths = RUBIN_CAMERA.nominal_lengths.copy()
    lengths[2] = bad
    with pytest.raises(PlanningError):
        forward_kinematics(lengths)


def test_fk_wrong_shape_raises():
    with pytest.raises(PlanningError):
        forward_kinematics(np.ones(5) * 0.49)


def _equilibrium_residual(pose, wrench, forces):
    """Sum of strut forces (tension positive: each pulls the platform along -u_i) and the
    external wrench (about the pivot's current position), computed from the raw pivots."""
    rot = Rotation.from_euler("XYZ", pose[3:]).as_matrix()
    origin = PIVOT + pose[:3]
    arms = (rot @ (MIRROR - PIVOT).T).T
    legs = origin + arms - BASE
    units = legs / np.linalg.norm(legs, axis=1, keepdims=True)
    force = np.sum(forces[:, None] * -units, axis=0) + wrench[:3]
    moment = np.sum(np.cross(arms, -forces[:, None] * units), axis=0) + wrench[3:]
    return force, moment


def test_static_forces_vertical_load_at_zero_pose():
    fz = -30_000.0  # about 3 t of camera, weight pointing down
    wrench = np.array([0, 0, fz, 0, 0, 0])
    f = static_strut_forces(np.zeros(6), wrench)
    force, moment = _equilibrium_residual(np.zeros(6), wrench, f)
    np.testing.assert_allclose(force, 0.0, atol=1e-9 * abs(fz))
    np.testing.assert_allclose(moment, 0.0, atol=1e-9 * abs(fz))
    # All struts push (compression, f < 0) and share the load nearly equally (the layout
    # is three-fold symmetric up to the um rounding of the pivots).
    units = (MIRROR - BASE) / np.linalg.norm(MIRROR - BASE, axis=1, keepdims=True)
    equal_share = fz / (6 * units[:, 2].mean())
    assert np.all(f < 0)
    np.testing.assert_allclose(f, equal_share, rtol=2e-3)


def test_static_forces_general_wrench_balances():
    rng = np.random.default_rng(6)
    for pose in my_random_poses(rng, 10):
        wrench = rng.normal(size=6) * np.array([1e4, 1e4, 3e4, 1e3, 1e3, 1e3])
        f = static_strut_forces(pose, wrench)
        force, moment = _equilibrium_residual(pose, wrench, f)
        assert np.abs(force).max() < 1e-8 * np.abs(wrench).max()
        assert np.abs(moment).max() < 1e-8 * np.abs(wrench).max()
        # In pose coordinates: J^T f = W' = (F, E^T M), E the Euler-rate matrix, written out
        # here (columns e_x, Rx e_y, Rx Ry e_z). (The docstring of static_strut_forces says
        # -W'; the sign there is wrong, see the report.)
        rx, ry = pose[3], pose[4]
        e = np.column_stack(
            [[1, 0, 0], [0, np.cos(rx), np.sin(rx)], [np.sin(ry), -np.sin(rx) * np.cos(ry), np.cos(rx) * np.cos(ry)]]
        )
        expected = np.concatenate([wrench[:3], e.T @ wrench[3:]])
        np.testing.assert_allclose(jacobian(pose).T @ f, expected, rtol=0, atol=1e-9 * np.abs(wrench).max())


def test_static_forces_virtual_work():
    """Virtual work of the strut forces plus that of the external force vanishes.

    A strut in tension f_i pulls the platform along -u_i, so for a virtual displacement the
    struts do the work sum f_i (-u_i . dx_i) = -f . dL = -f . (J delta); equilibrium makes the
    total zero: -f . (J delta) + F . delta_xyz = 0.
    """
    rng = np.random.default_rng(7)
    pose = np.zeros(6)
    for _ in range(5):
        force = rng.normal(size=3) * 1e4
        wrench = np.concatenate([force, np.zeros(3)])
        f = static_strut_forces(pose, wrench)
        delta = np.concatenate([rng.normal(size=3) * 1e-6, np.zeros(3)])
        # dL by central differences of my own IK, and by the module's Jacobian.
        dL = (my_strut_lengths(pose + delta)[0] - my_strut_lengths(pose - delta)[0]) / 2
        strut_work = -f @ dL
        assert strut_work == pytest.approx(-force @ delta[:3], rel=1e-6)
        assert -f @ (jacobian(pose) @ delta) == pytest.approx(-force @ delta[:3], rel=1e-9)
    # With rotations: J^T f = (F, E^T M); checked as the work of a random small displacement.
    for pose in my_random_poses(rng, 5):
        wrench = rng.normal(size=6) * np.array([1e4, 1e4, 1e4, 1e3, 1e3, 1e3])
        f = static_strut_forces(pose, wrench)
        delta = rng.normal(size=6) * 1e-7
        dL = (my_strut_lengths(pose + delta)[0] - my_strut_lengths(pose - delta)[0]) / 2
        # Small rotation vector of the Euler-angle change, in the fixed frame.
        r0 = Rotation.from_euler("XYZ", pose[3:])
        dphi = (
            (Rotation.from_euler("XYZ", pose[3:] + delta[3:]) * r0.inv()).as_rotvec()
            - (Rotation.from_euler("XYZ", pose[3:] - delta[3:]) * r0.inv()).as_rotvec()
        ) / 2
        external = wrench[:3] @ delta[:3] + wrench[3:] @ dphi
        assert -f @ dL + external == pytest.approx(0.0, abs=1e-6 * abs(external))


def test_structure_matrix_is_minus_jacobian_transpose():
    rng = np.random.default_rng(8)
    for _ in range(5):
        anchors = rng.normal(size=(6, 3))
        points = rng.normal(size=(6, 3)) * 0.5
        position = rng.normal(size=3) + np.array([0, 0, 2.0])
        rot0 = Rotation.random(random_state=rng.integers(1 << 31)).as_matrix()

        def lengths(x, anchors=anchors, points=points, position=position, rot0=rot0):
            rot = Rotation.from_rotvec(x[3:]).as_matrix() @ rot0
            return np.linalg.norm(position + x[:3] + points @ rot.T - anchors, axis=1)

        h = 1e-6
        fd = np.empty((6, 6))
        for j in range(6):
            e = np.zeros(6)
            e[j] = h
            fd[:, j] = (lengths(e) - lengths(-e)) / (2 * h)
        a = structure_matrix(anchors, points, position, rot0)
        assert a.shape == (6, 6)
        np.testing.assert_allclose(a.T, -fd, rtol=0, atol=1e-8)


# =========================================================================== 2. generator


def test_strut_min_time_formula():
    th = V_MAX**2 / (2 * A_MAX)
    assert LIM.threshold_distance == pytest.approx(th, rel=1e-15)
    short = np.linspace(0, th, 50)
    np.testing.assert_allclose(strut_min_time(short), np.sqrt(2 * short / A_MAX), rtol=1e-14)
    long = np.linspace(th * 1.0001, 0.02, 50)
    np.testing.assert_allclose(strut_min_time(long), (long - th) / V_MAX + V_MAX / A_MAX, rtol=1e-14)
    # Continuous at the threshold (both branches give v/a there).
    at = float(strut_min_time(th))
    assert at == pytest.approx(V_MAX / A_MAX, rel=1e-14)
    for eps in (1e-15, 1e-12, 1e-9):
        assert float(strut_min_time(th * (1 + eps))) == pytest.approx(at, rel=10 * eps + 1e-14)
        assert float(strut_min_time(th * (1 - eps))) == pytest.approx(at, rel=10 * eps + 1e-14)
    assert np.all(np.diff(strut_min_time(np.linspace(0, 0.02, 2001))) > 0)


@pytest.mark.parametrize(
    "axis, delta, speed",
    [
        (0, 0.010, 2_000e-6),
        (1, -0.007, 2_000e-6),
        (2, -0.0123, 2_000e-6),
        (3, np.radians(0.5), np.radians(0.1146)),
        (4, np.radians(-0.2), np.radians(0.1146)),
        (5, np.radians(0.2), np.radians(0.1146)),
    ],
)
def test_hexapod_space_min_time_pure_moves(axis, delta, speed):
    d = np.zeros(6)
    d[axis] = delta
    # d' = |delta| / 2, t' = 2 d' / v' = |delta| / v'.
    assert float(hexapod_space_min_time(d)) == pytest.approx(abs(delta) / speed, rel=1e-14)


def test_hexapod_space_min_time_combined():
    d = np.array([3e-3, -4e-3, 1e-3, 0, 0, 0])  # radial |(3, 4)| = 5 mm
    assert float(hexapod_space_min_time(d)) == pytest.approx(5e-3 / 2e-3, rel=1e-14)
    w = np.radians(0.1146)
    d = np.array([1e-3, 0, 0, np.radians(0.3), np.radians(-0.4), np.radians(0.1)])
    assert float(hexapod_space_min_time(d)) == pytest.approx(np.radians(0.5) / w, rel=1e-13)
    batch = np.array([[2e-3, 0, 0, 0, 0, 0], [0, 0, 0, 0, 0, 0]])
    np.testing.assert_allclose(hexapod_space_min_time(batch), [1.0, 0.0], rtol=1e-14)


def _long_cases(rng, n):
    th = LIM.threshold_distance
    d = rng.uniform(th * 1.001, 0.0141, size=n)
    t_min = strut_min_time(d)
    t_max = 2 * d / V_MAX  # v_avg = v/2
    t = t_min + rng.uniform(0, 1, size=n) * (t_max - t_min)
    return d, t


def test_long_move_iteration_matches_closed_form():
    rng = np.random.default_rng(9)
    d, t = _long_cases(rng, 5000)
    v_avg = d / t
    assert np.all((v_avg > V_MAX / 2) & (v_avg <= V_MAX))
    a_it, iterations = long_move_iteration(d, t, V_MAX, A_MAX)
    a_cf = long_move_closed_form(d, t, V_MAX)
    np.testing.assert_allclose(a_it, a_cf, rtol=1e-12, atol=0)
    assert np.all(a_it >= 0) and np.all(a_it <= A_MAX)
    assert iterations < 200
    # One at a time too.
    for k in range(20):
        a1, _ = long_move_iteration(d[k], t[k], V_MAX, A_MAX)
        assert float(a1) == pytest.approx(a_cf[k], rel=1e-12)


def test_long_move_at_minimum_time_uses_a_max():
    rng = np.random.default_rng(10)
    d = rng.uniform(LIM.threshold_distance * 1.001, 0.0141, size=200)
    t = strut_min_time(d)
    a_it, _ = long_move_iteration(d, t, V_MAX, A_MAX)
    np.testing.assert_allclose(a_it, A_MAX, rtol=1e-12)
    assert np.all(a_it <= A_MAX)
    np.testing.assert_allclose(long_move_closed_form(d, t, V_MAX), A_MAX, rtol=1e-12)


def test_solve_profiles_methods_agree_and_paper_equations_hold():
    rng = np.random.default_rng(11)
    d = rng.uniform(0, 0.0141, size=(2000, 6))
    d[::7, 2] = 0.0
    # Half times from the minimum up to 3x it (some long cases become short).
    t = np.maximum(strut_min_time(d), 1e-3) * rng.uniform(1, 3, size=d.shape)
    it = solve_profiles(d, t, method="iteration")
    cf = solve_profiles(d, t, method="closed")
    np.testing.assert_allclose(it.accel, cf.accel, rtol=1e-12, atol=0)
    np.testing.assert_allclose(it.t_accel, cf.t_accel, rtol=1e-12, atol=0)
    # t_vmax = 2 (T - t_accel) cancels: compare on the scale of T.
    assert np.all(np.abs(it.t_vmax - cf.t_vmax) <= 1e-12 * t)
    np.testing.assert_array_equal(it.short, cf.short)
    moving = d > 0
    v_avg = np.where(moving, d / t, 0)
    short = moving & (v_avg <= V_MAX / 2)
    long = moving & ~short
    np.testing.assert_array_equal(it.short, short)
    assert long.sum() > 1000 and short.sum() > 1000
    for p in (it, cf):
        a, ta, tv = p.accel[long], p.t_accel[long], p.t_vmax[long]
        T, D = t[long], d[long]
        np.testing.assert_allclose(ta, V_MAX / a, rtol=1e-12)
        np.testing.assert_allclose(T, tv / 2 + ta, rtol=1e-12)
        np.testing.assert_allclose(D, a * ta**2 / 2 + V_MAX * tv / 2, rtol=1e-11)
        assert np.all(a <= A_MAX * (1 + 1e-12)) and np.all(a > 0) and np.all(tv >= 0)
        np.testing.assert_array_equal(p.t_vmax[short], 0.0)
        np.testing.assert_allclose(p.t_accel[short], t[short], rtol=1e-15)
        np.testing.assert_allclose(p.accel[short], 2 * d[short] / t[short] ** 2, rtol=1e-13)
        # The short triangle covers d in T: a T^2 / 2.
        np.testing.assert_allclose(p.accel[short] * t[short] ** 2 / 2, d[short], rtol=1e-13)
        assert np.all(p.accel[short] <= A_MAX * (1 + 1e-12))
        assert np.all(p.accel[~moving] == 0) and np.all(p.t_vmax[~moving] == 0)


def test_solve_profiles_bad_method():
    with pytest.raises(PlanningError, match="method"):
        solve_profiles(np.ones(6) * 1e-3, np.ones(6) * 5.0, method="bisect")


@pytest.fixture(scope="module")
def random_moves():
    rng = np.random.default_rng(12)
    n = 10_000
    return my_random_poses(rng, n), my_random_poses(rng, n)


@pytest.fixture(scope="module")
def planned(random_moves):
    start, target = random_moves
    return {sync: plan_moves(start, target, synchronous=sync) for sync in (True, False)}


@pytest.fixture(scope="module")
def small_moves():
    """10 000 short moves (triangle profiles, a few hundred ticks): the regime where the tick
    rounding matters (odd tick counts need an extra tick)."""
    rng = np.random.default_rng(18)
    start = my_random_poses(rng, 12_000)
    target = np.clip(
        start + rng.uniform(LOW, HIGH, size=start.shape) * 10 ** rng.uniform(-5, -2.5, size=(len(start), 1)), LOW, HIGH
    )
    keep = in_stroke(target)
    return start[keep][:10_000], target[keep][:10_000]


@pytest.fixture(scope="module")
def batches(planned, small_moves):
    out = {("full", sync): moves for sync, moves in planned.items()}
    for sync in (True, False):
        out[("small", sync)] = plan_moves(*small_moves, synchronous=sync)
    return out


def test_durations_equal_independent_time_optimum(random_moves, planned):
    moves = planned[True]
    D = np.abs(moves.target - moves.start)
    optimum = optimal_strut_time(D).max(axis=1)
    free = 2 * moves.hexapod_half_time < optimum * (1 - 1e-9)
    assert free.sum() > 9000
    np.testing.assert_allclose(2 * moves.profiles.half_time.max(axis=1)[free], optimum[free], rtol=1e-12)
    dur = moves.durations[free]
    assert np.all(dur >= optimum[free] * (1 - 1e-12))
    assert np.all(dur < optimum[free] + 2 * DT)
    # Asynchronous: every moving strut that the hexapod-space limit does not bind takes its
    # own optimum (up to 2 ticks).
    amoves = planned[False]
    own = optimal_strut_time(D)
    both = (2 * amoves.hexapod_half_time[:, None] < own * (1 - 1e-9)) & (D > 0)
    assert both.sum() > 30_000
    np.testing.assert_allclose((2 * amoves.profiles.half_time)[both], own[both], rtol=1e-12)
    end = amoves.n_ticks * DT
    assert np.all(end[both] >= own[both] * (1 - 1e-12))
    assert np.all(end[both] < own[both] + 2 * DT)


def test_hexapod_limit_sets_half_time(random_moves, planned):
    """T_i = max(t_i, t'_min), synchronous T = max_i T_i, with the strut and hexapod times
    computed here."""
    start, target = random_moves
    D = np.abs(planned[True].target - planned[True].start)
    disp = target - start
    w, v = np.radians(0.1146), 2_000e-6
    t_hex = np.max(
        np.stack(
            [
                np.hypot(disp[:, 0], disp[:, 1]) / v,
                np.abs(disp[:, 2]) / v,
                np.hypot(disp[:, 3], disp[:, 4]) / w,
                np.abs(disp[:, 5]) / w,
            ]
        ),
        axis=0,
    )
    np.testing.assert_allclose(planned[True].hexapod_half_time, t_hex, rtol=1e-13)
    half_own = optimal_strut_time(D) / 2
    t_i = np.maximum(half_own, t_hex[:, None])
    np.testing.assert_allclose(planned[False].profiles.half_time, t_i, rtol=1e-12)
    np.testing.assert_allclose(
        planned[True].profiles.half_time, np.broadcast_to(t_i.max(axis=1, keepdims=True), D.shape), rtol=1e-12
    )
    binding = t_hex > half_own.max(axis=1) * (1 + 1e-6)
    assert binding.sum() > 50
    dur = planned[True].durations[binding]
    assert np.all(dur >= 2 * t_hex[binding] * (1 - 1e-12))
    assert np.all(dur < 2 * t_hex[binding] + 2 * DT)


# =========================================================================== 3. tick grid


@pytest.mark.parametrize("sync", [True, False])
@pytest.mark.parametrize("kind", ["full", "small"])
def test_tick_counts(random_moves, small_moves, batches, kind, sync):
    moves = batches[kind, sync]
    start, target = random_moves if kind == "full" else small_moves
    assert len(moves) == 10_000
    np.testing.assert_array_equal(moves.start_pose, start)
    np.testing.assert_array_equal(moves.target_pose, target)
    D = np.abs(moves.target - moves.start)
    half_time = moves.profiles.half_time
    moving = D > 0
    end = moves.n_ticks * DT
    if sync:
        assert np.all(moves.n_ticks == moves.n_ticks[:, :1])
        assert np.all(half_time == half_time[:, :1])
    else:
        # Idle struts (none expected among random poses) take no ticks.
        assert np.all(moves.n_ticks[~moving] == 0)
    tol = 1e-9 * DT
    assert np.all(end[moving] >= 2 * half_time[moving] - tol)
    assert np.all(end[moving] < 2 * half_time[moving] + 2 * DT)
    np.testing.assert_allclose(moves.durations, end.max(axis=1), rtol=0, atol=0)


@pytest.mark.parametrize("sync", [True, False])
@pytest.mark.parametrize("kind", ["full", "small"])
def test_tick_limits_over_batch(batches, kind, sync):
    moves = batches[kind, sync]
    D = np.abs(moves.target - moves.start)
    assert np.all(moves.accel <= A_MAX) and np.all(moves.accel >= 0)
    assert np.all(moves.accel * moves.n_accel * DT <= V_MAX)
    moving = D > 0
    assert np.all(moves.n_accel[moving] >= 1)
    assert np.all(2 * moves.n_accel <= moves.n_ticks)
    # The distance the tick profile covers is the strut's distance.
    covered = moves.accel * moves.n_accel * (moves.n_ticks - moves.n_accel) * DT**2
    np.testing.assert_allclose(covered, D, rtol=1e-13, atol=0)


def _feasible(D, m):
    """Whether some tick profile of m ticks covers D within v_max and a_max: accelerate k
    ticks, cruise, brake k ticks (k <= m / 2); peak D / ((m - k) dt), acceleration
    D / (k (m - k) dt^2). Brute force over every k."""
    D = np.atleast_1d(D)
    m = np.atleast_1d(m)
    out = np.zeros(D.shape, dtype=bool)
    for idx in np.ndindex(D.shape):
        d, mm = D[idx], int(m[idx])
        k = np.arange(1, mm // 2 + 1)
        if d == 0:
            out[idx] = True
        elif k.size:
            ok = (d / ((mm - k) * DT) <= V_MAX) & (d / (k * (mm - k) * DT**2) <= A_MAX)
            out[idx] = bool(ok.any())
    return out


@pytest.mark.parametrize("sync", [True, False])
@pytest.mark.parametrize("kind", ["full", "small"])
def test_tick_counts_are_minimal_and_acceleration_least(batches, kind, sync):
    """n_ticks is ceil(2 T / dt) or, where rounding broke a limit, the fewest ticks that keep
    the limits; on its ticks each strut uses the longest acceleration phase (the least
    acceleration) that keeps its cruise speed <= v_max."""
    moves = batches[kind, sync]
    D = np.abs(moves.target - moves.start)
    n = moves.n_ticks
    base = np.ceil(2 * moves.profiles.half_time / DT - 1e-9).astype(int)
    if sync:
        base = np.broadcast_to(base.max(axis=1, keepdims=True), base.shape)
    assert np.all(n >= np.where(D > 0, base, 0))
    over = n > np.where(D > 0, base, 0)
    extra = np.argwhere(over.any(axis=1))[:, 0]
    if kind == "small":
        assert len(extra) > 50  # the rounding case is exercised
    for k in extra[:300]:
        if sync:  # one tick less breaks a limit for some strut
            moving = D[k] > 0
            assert not _feasible(D[k][moving], n[k][moving] - 1).all()
        else:  # each strut with an extra tick could not do with one less
            assert not _feasible(D[k][over[k]], n[k][over[k]] - 1).any()
    moving = D > 0
    k = moves.n_accel[moving]
    m = n[moving]
    d = D[moving]
    longer = k + 1
    # One more acceleration tick is impossible (beyond half) or would overshoot v_max.
    possible = longer <= m // 2
    assert np.all(d[possible] / ((m[possible] - longer[possible]) * DT) > V_MAX)


@pytest.mark.parametrize("sync", [True, False])
@pytest.mark.parametrize("odd", [101, 151, 399])
def test_odd_tick_count_short_move_takes_one_more_tick(sync, odd):
    """A short move whose time-optimal duration lies just below an odd tick count: ceil gives
    the odd count, whose best profile (k = (n-1)/2 ticks each way) would need
    4 D / ((n^2 - 1) dt^2) > a_max, so the planner must add a tick."""
    D = A_MAX * (odd * DT) ** 2 / 4 * (1 - 1e-7)
    assert D <= V_MAX**2 / A_MAX  # a triangle move
    assert np.ceil(2 * np.sqrt(D / A_MAX) / DT) == odd
    assert not _feasible(D, odd)[0] and _feasible(D, odd + 1)[0]
    start = np.zeros(6)
    target = np.array([D, 0.5 * D, 0, 0, 0, -D])
    move = plan_strut_moves(start, target, synchronous=sync).move(0)
    assert move.n_ticks[0] == odd + 1
    assert np.all(move.accel <= A_MAX)
    check_single_move(move, start, target)


@pytest.mark.parametrize("sync", [True, False])
@pytest.mark.parametrize("kind", ["full", "small"])
def test_tick_moves_integrate_and_sample(batches, kind, sync):
    moves = batches[kind, sync]
    rng = np.random.default_rng(13 + sync)
    for k in rng.choice(len(moves), size=200, replace=False):
        move = moves.move(int(k))
        assert move.synchronous is sync
        check_single_move(move, moves.start[k], moves.target[k])
        if sync:
            assert len(set(move.n_ticks.tolist())) == 1


def test_iteration_and_closed_plans_agree(random_moves):
    start, target = random_moves[0][:500], random_moves[1][:500]
    for sync in (True, False):
        a = plan_moves(start, target, synchronous=sync, method="closed")
        b = plan_moves(start, target, synchronous=sync, method="iteration")
        np.testing.assert_array_equal(a.n_ticks, b.n_ticks)
        np.testing.assert_array_equal(a.accel, b.accel)
        np.testing.assert_allclose(a.profiles.accel, b.profiles.accel, rtol=1e-12)


def test_plan_move_single_equals_batch(random_moves):
    start, target = random_moves[0][5], random_moves[1][5]
    single = plan_move(start, target, synchronous=True)
    batch = plan_moves(start[None], target[None], synchronous=True).move(0)
    np.testing.assert_array_equal(single.n_ticks, batch.n_ticks)
    np.testing.assert_array_equal(single.accel, batch.accel)
    assert single.labels == tuple(f"strut{i}" for i in range(1, 7))
    assert single.duration == pytest.approx(single.n_ticks.max() * DT)


@pytest.mark.parametrize("sync", [True, False])
def test_zero_length_moves(sync):
    rng = np.random.default_rng(14)
    p = my_random_poses(rng, 5)
    moves = plan_moves(p, p, synchronous=sync)
    np.testing.assert_array_equal(moves.durations, 0.0)
    np.testing.assert_array_equal(moves.n_ticks, 0)
    for k in range(5):
        move = moves.move(k)
        assert move.duration == 0.0
        s = move.sample(np.array([0.0, 0.5, 10.0]))
        assert np.all(s.position == moves.start[k])
        assert np.all(s.velocity == 0) and np.all(s.acceleration == 0)
        pos, vel = move.integrate()
        assert np.all(pos == moves.start[k]) and np.all(vel == 0)
    single = plan_move(p[0], p[0], synchronous=sync)
    assert single.duration == 0.0


@pytest.mark.parametrize("sync", [True, False])
@pytest.mark.parametrize("strut, delta", [(0, 0.02), (2, -3e-4), (4, 1e-6), (5, -0.0141)])
def test_one_strut_moves(sync, strut, delta):
    rng = np.random.default_rng(15)
    start = rng.uniform(-0.007, 0.007, size=6)
    target = start.copy()
    target[strut] = np.clip(start[strut] + delta, -LIM.stroke, LIM.stroke)
    moves = plan_strut_moves(start, target, pose_displacement=None, synchronous=sync)
    move = moves.move(0)
    optimum = float(optimal_strut_time(abs(target[strut] - start[strut])))
    assert optimum <= move.duration * (1 + 1e-12) and move.duration < optimum + 2 * DT
    others = [i for i in range(6) if i != strut]
    pos, vel = move.integrate()
    assert np.all(pos[:, others] == start[others]) and np.all(vel[:, others] == 0)
    s = move.sample(np.linspace(0, move.duration + 1, 777))
    assert np.all(s.position[:, others] == start[others])
    assert np.all(s.velocity[:, others] == 0)
    check_single_move(move, start, target)


@pytest.mark.parametrize("sync", [True, False])
def test_idle_struts_with_hexapod_limit(sync):
    """Struts that do not move stay still; asynchronous idle struts take no ticks even when a
    pose displacement makes the hexapod-space half time longer than the moving struts' own."""
    start = np.array([1e-3, -2e-3, 0, 3e-3, 0, 0])
    target = start + np.array([0, 0, 2e-3, 0, 0, -1e-3])
    displacement = np.array([0.01, 0, 0, 0, 0, 0])  # t'_min = 5 s, longer than the struts
    moves = plan_strut_moves(start, target, pose_displacement=displacement, synchronous=sync)
    move = moves.move(0)
    assert float(moves.hexapod_half_time[0]) == pytest.approx(5.0, rel=1e-14)
    moving = target != start
    end = move.end_times
    assert np.all(end[moving] >= 10.0 - 1e-9) and np.all(end[moving] < 10.0 + 2 * DT)
    if sync:
        assert np.all(move.n_ticks == move.n_ticks[0])
    else:
        assert np.all(move.n_ticks[~moving] == 0)
    pos, vel = move.integrate()
    assert np.all(pos[:, ~moving] == start[~moving]) and np.all(vel[:, ~moving] == 0)
    check_single_move(move, start, target)


@pytest.mark.parametrize("sync", [True, False])
def test_short_long_boundary(sync):
    th = LIM.threshold_distance
    durations = []
    for half in (th - 1e-12, th, th + 1e-12):
        start = np.array([-1e-3, 2e-3, 0, 0, 0, 0])
        target = start + np.array([2 * half, -2 * half, half, 0, 2 * half, 0])
        moves = plan_strut_moves(start, target, synchronous=sync)
        move = moves.move(0)
        check_single_move(move, start, target)
        assert np.all(moves.accel <= A_MAX)
        assert np.all(moves.accel * moves.n_accel * DT <= V_MAX)
        durations.append(move.duration)
        # The whole boundary move takes 2 v / a = 2 s (2 T with T = v / a).
        assert 2 * V_MAX / A_MAX * (1 - 1e-9) <= move.duration < 2 * V_MAX / A_MAX + 2 * DT
    assert max(durations) - min(durations) <= DT * (1 + 1e-9)
    for method in ("closed", "iteration"):
        prof = solve_profiles(
            np.array([th - 1e-12, th, th + 1e-12]),
            strut_min_time(np.array([th - 1e-12, th, th + 1e-12])),
            method=method,
        )
        np.testing.assert_allclose(prof.accel, A_MAX, rtol=1e-6)
        assert np.all(prof.accel <= A_MAX * (1 + 1e-12))


def test_pure_rz_rotation_respects_hexapod_limit():
    drz = np.radians(0.2)
    start = np.array([0, 0, 0, 0, 0, -np.radians(0.1)])
    target = np.array([0, 0, 0, 0, 0, np.radians(0.1)])
    for sync in (True, False):
        moves = plan_moves(start, target, synchronous=sync)
        assert float(moves.hexapod_half_time[0]) == pytest.approx(drz / np.radians(0.1146))
        assert moves.durations[0] >= 2 * drz / np.radians(0.1146)
        check_single_move(moves.move(0), moves.start[0], moves.target[0])


def test_hexapod_limit_binds_in_sync_and_async():
    """The move among random ones whose hexapod-space time most exceeds its struts' time:
    synchronous and asynchronous moves take 2 t'_min (a pure rz move of the whole range does
    not bind: its struts need 3.72 s, the hexapod-space limit 3.49 s)."""
    # Find a binding move among random ones (struts short, hexapod motion long).
    rng = np.random.default_rng(16)
    s, t = my_random_poses(rng, 3000), my_random_poses(rng, 3000)
    D = np.abs(my_strut_lengths(t) - my_strut_lengths(s))
    strut_opt = optimal_strut_time(D)
    t_hex = hexapod_space_min_time(t - s)
    k = int(np.argmax(2 * t_hex / strut_opt.max(axis=1)))
    assert 2 * t_hex[k] > strut_opt[k].max() * 1.2
    start, target = s[k], t[k]
    sync = plan_moves(start, target, synchronous=True).move(0)
    assert 2 * t_hex[k] * (1 - 1e-12) <= sync.duration < 2 * t_hex[k] + 2 * DT
    check_single_move(sync, sync.start, sync.target)
    asyn = plan_moves(start, target, synchronous=False).move(0)
    moving = D[k] > 0
    end = asyn.end_times[moving]
    assert np.all(end >= 2 * t_hex[k] * (1 - 1e-12)) and np.all(end < 2 * t_hex[k] + 2 * DT)
    check_single_move(asyn, asyn.start, asyn.target)


# =========================================================================== 4. bad input


@pytest.mark.parametrize(
    "axis, value, pattern",
    [
        (0, 0.012, r"target x = 12000\.0 um is beyond its limit 11400\.0 um"),
        (1, -0.0115, r"target y = -11500\.0 um is beyond its limit -11400\.0 um"),
        (2, 0.0132, r"target z = 13200\.0 um is beyond its limit 13100\.0 um"),
        (3, np.radians(0.4), r"target rx = 0\.4000 deg is beyond its limit 0\.3600 deg"),
        (4, np.radians(-0.37), r"target ry = -0\.3700 deg is beyond its limit -0\.3600 deg"),
        (5, np.radians(0.11), r"target rz = 0\.1100 deg is beyond its limit 0\.1000 deg"),
    ],
)
def test_pose_limit_errors(axis, value, pattern):
    target = np.zeros(6)
    target[axis] = value
    with pytest.raises(LimitError, match=pattern):
        plan_moves(np.zeros(6), target)
    with pytest.raises(ValueError, match=pattern):
        plan_move(np.zeros(6), target)
    with pytest.raises(LimitError, match=pattern.replace("target", "start")):
        plan_moves(target, np.zeros(6))
    # In a batch, the message says which move.
    batch = np.zeros((3, 6))
    batch[2] = target
    with pytest.raises(LimitError, match=pattern + r" \(move 2\)"):
        plan_moves(np.zeros((3, 6)), batch)


@pytest.mark.parametrize("axis", range(6))
@pytest.mark.parametrize("side", [0, 1])
def test_pose_limits_are_inclusive_and_sharp(axis, side):
    limit = float((LOW, HIGH)[side][axis])
    target = np.zeros(6)
    target[axis] = limit
    if in_stroke(target)[0]:
        plan_moves(np.zeros(6), target)  # exactly on the limit: allowed
    target[axis] = limit + (1e-12 if side else -1e-12)
    with pytest.raises(LimitError, match=rf"target {['x', 'y', 'z', 'rx', 'ry', 'rz'][axis]} ="):
        plan_moves(np.zeros(6), target)


def test_stroke_limit_error():
    rng = np.random.default_rng(17)
    p = rng.uniform(LOW, HIGH, size=(200, 6))
    change = my_strut_lengths(p) - np.linalg.norm(MIRROR - BASE, axis=1)
    outside = np.any(np.abs(change) > LIM.stroke, axis=1)
    k = int(np.argmax(outside))
    assert outside[k]
    strut = int(np.argmax(np.abs(change[k]) > LIM.stroke)) + 1
    pattern = rf"target strut{strut} length change .* beyond the stroke limit \+/-14\.1 mm"
    with pytest.raises(LimitError, match=pattern):
        plan_moves(np.zeros(6), p[k])
    with pytest.raises(LimitError, match=pattern.replace("target", "start")):
        plan_moves(p[k], np.zeros(6))
    with pytest.raises(LimitError, match=r"strut3 .*14\.1 mm"):
        plan_strut_moves(np.zeros(6), np.array([0, 0, -0.0142, 0, 0, 0]))


@pytest.mark.parametrize("where", [0, 3, 5])
def test_nan_pose_raises(where):
    bad = np.zeros(6)
    bad[where] = np.nan
    with pytest.raises(PlanningError, match="non-finite"):
        plan_moves(np.zeros(6), bad)
    with pytest.raises(PlanningError, match="non-finite"):
        plan_moves(bad, np.zeros(6))
    with pytest.raises(PlanningError):
        plan_strut_moves(np.zeros(6), bad)
    with pytest.raises(PlanningError):
        strut_lengths(bad)


@pytest.mark.parametrize(
    "start, target",
    [
        (np.zeros(6), np.zeros(5)),
        (np.zeros(7), np.zeros(7)),
        (np.zeros((2, 5)), np.zeros((2, 5))),
        (np.zeros(()), np.zeros(6)),
    ],
)
def test_wrong_pose_shapes_raise(start, target):
    with pytest.raises(PlanningError):
        plan_moves(start, target)


@pytest.mark.parametrize(
    "start, target",
    [
        (np.zeros(6), np.zeros(5)),
        (np.zeros((2, 6)), np.zeros((3, 6))),
        (np.zeros((2, 7)), np.zeros((2, 7))),
    ],
)
def test_wrong_strut_shapes_raise(start, target):
    with pytest.raises(PlanningError):
        plan_strut_moves(start, target)


def test_mismatched_pose_batches_raise_planning_error():
    with pytest.raises(PlanningError):
        plan_moves(np.zeros((2, 6)), np.zeros((3, 6)))


def test_three_dimensional_pose_batch_raises_planning_error():
    with pytest.raises(PlanningError):
        plan_moves(np.zeros((2, 3, 6)), np.zeros((2, 3, 6)))


def test_mismatched_pose_displacement_raises_planning_error():
    with pytest.raises(PlanningError):
        plan_strut_moves(np.zeros((2, 6)), np.full((2, 6), 1e-3), pose_displacement=np.zeros((3, 6)))


def test_sample_before_start_holds_start():
    """Like the B-spline planner, a move should hold its start at rest before t = 0."""
    move = plan_move(np.zeros(6), np.array([1e-3, 0, 0, 0, 0, 0]))
    s = move.sample(np.array([-1.0, -0.01]))
    assert np.all(s.position == move.start) and np.all(s.velocity == 0)
    assert np.all(s.acceleration == 0)


def test_bad_geometry_raises():
    from planbench.planners.hexapod import HexapodGeometry, HexapodLimits

    with pytest.raises(PlanningError):
        HexapodGeometry(BASE[:5], MIRROR[:5], PIVOT)
    with pytest.raises(PlanningError):
        HexapodGeometry(BASE, BASE, PIVOT)  # zero strut lengths
    with pytest.raises(PlanningError):
        HexapodLimits(LOW, HIGH, 0.0141, -1.0, 5e-4, 2e-3, 0.002)


# =========================================================================== 5. properties


@given(poses(), poses(), st.booleans())
def test_random_single_moves(start, target, sync):
    assume(in_stroke(start)[0] and in_stroke(target)[0])
    move = plan_move(start, target, synchronous=sync)
    p0, p1 = strut_positions(start), strut_positions(target)
    np.testing.assert_array_equal(move.start, p0)
    np.testing.assert_array_equal(move.target, p1)
    check_single_move(move, p0, p1)
    if sync:
        assert np.all(move.n_ticks == move.n_ticks[0])
    optimum = optimal_strut_time(np.abs(p1 - p0)).max()
    t_hex = float(hexapod_space_min_time(target - start))
    if np.all(p1 == p0):
        # A pose change below the rounding of the strut lengths moves no strut.
        assert move.duration == 0.0
    else:
        assert move.duration >= max(optimum, 2 * t_hex) * (1 - 1e-12)
        assert move.duration < max(optimum, 2 * t_hex) + 2 * DT


def test_a_pose_change_below_the_struts_round_off_is_a_move_of_zero_length():
    # Found by hypothesis: rz = 5e-222 deg changes no strut length, and its plan had duration 0.
    from planbench.hexapod import HexapodMove, HexapodParams
    from planbench.params import ParamError

    with pytest.raises(ParamError, match=r"moves\[0\]\.target equals the pose before it \(no strut length changes\)"):
        HexapodParams(moves=(HexapodMove((0.0, 0.0, 0.0, 0.0, 0.0, 5.0165313870954834e-222), False),))
    HexapodParams(moves=(HexapodMove((1e-9, 0.0, 0.0, 0.0, 0.0, 0.0), False),))  # 0.5 pm of strut: a move
