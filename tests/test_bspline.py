"""The loader paper's cubic B-spline (eq. 7-11) against its Table 1, eq. (11) and scipy."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from scipy.interpolate import CubicSpline

from planbench.planners.errors import LimitError, PlanningError
from planbench.planners.loader import TABLE1, TABLE1_TIMES, direct_plan, supply_plan, table1_to_si
from planbench.planners.loader.bspline import CubicBSplineTrajectory, solve_control_points

# Eq. (11) of the paper: theta2(t) piecewise, rows a3, a2, a1, a0 per segment (deg, s).
EQ11 = np.array(
    [
        [193.2552, -146.2284, 0.0, 55.8],
        [-163.7664, 143.6556, -1.287, 43.4],
        [46.6104, -101.9944, 19.5444, 58.2],
        [130.1240, -32.0784, -47.4918, 48.3],
        [-241.5080, 163.1080, 18.0230, 32.8],
    ]
)
# The control points the paper prints for theta2 (its "P_1" row).
PAPER_THETA2_CONTROL = [31.4287, 67.9856, 31.4287, 66.6995, 50.9732, 19.2077, 68.9962, 19.2077]


def table1_spline():
    return CubicBSplineTrajectory(TABLE1_TIMES, TABLE1)


def test_theta2_reproduces_eq11():
    coef = table1_spline().segment_polynomials()[:, :, 1]
    nonzero = EQ11 != 0
    rel = np.abs(coef[nonzero] - EQ11[nonzero]) / np.abs(EQ11[nonzero])
    assert rel.max() < 1e-3, rel.max()
    assert np.abs(coef[~nonzero]).max() < 1e-9


def test_theta2_control_points_match_paper():
    np.testing.assert_allclose(table1_spline().control_points[:, 1], PAPER_THETA2_CONTROL, atol=1e-4)


def test_eq12_13_do_not_match_table1():
    """REFERENCE.md: eq. (12)-(13) use other data; their first values differ from Table 1."""
    coef = table1_spline().segment_polynomials()
    assert coef[0, 3, 2] == pytest.approx(-70.6) and coef[0, 3, 2] != pytest.approx(-126.1)
    assert coef[0, 3, 3] == pytest.approx(20.0) and coef[0, 3, 3] != pytest.approx(70.0)


def test_control_points_satisfy_eq7_and_eq8():
    keys = table1_to_si(TABLE1)
    p = solve_control_points(keys)
    np.testing.assert_allclose((p[:-2] + 4 * p[1:-1] + p[2:]) / 6, keys, atol=1e-12)
    np.testing.assert_allclose(p[0], p[2], atol=1e-12)
    np.testing.assert_allclose(p[-1], p[-3], atol=1e-12)


def test_equals_scipy_clamped_cubic_spline():
    spline = table1_spline()
    reference = CubicSpline(TABLE1_TIMES, TABLE1, bc_type="clamped")
    t = np.linspace(0, 2.5, 1001)
    s = spline.sample(t)
    np.testing.assert_allclose(s.position, reference(t), atol=1e-10)
    np.testing.assert_allclose(s.velocity, reference(t, 1), atol=1e-9)
    np.testing.assert_allclose(s.acceleration, reference(t, 2), atol=1e-7)


def check_spline_properties(times, keys):
    spline = CubicBSplineTrajectory(times, keys)
    s = spline.sample(times)
    scale = 1.0 + np.abs(keys).max()
    np.testing.assert_allclose(s.position, keys, atol=1e-9 * scale)
    assert np.abs(s.velocity[[0, -1]]).max() <= 1e-9 * scale / (times[1] - times[0])
    eps = 1e-9 * (times[1] - times[0])
    inner = times[1:-1]
    left, right = spline.sample(inner - eps), spline.sample(inner + eps)
    h = times[1] - times[0]
    for a, b, tol in (
        (left.position, right.position, 1e-6),
        (left.velocity, right.velocity, 1e-6 / h),
        (left.acceleration, right.acceleration, 1e-5 / h**2),
    ):
        np.testing.assert_allclose(a, b, atol=tol * scale)
    # Outside the key times the trajectory holds still.
    out = spline.sample([times[0] - 1.0, times[-1] + 1.0])
    np.testing.assert_allclose(out.position, keys[[0, -1]], atol=1e-9 * scale)
    assert not out.velocity.any() and not out.acceleration.any()


def test_table1_properties():
    check_spline_properties(TABLE1_TIMES, table1_to_si(TABLE1))


@given(
    n=st.integers(2, 12),
    t0=st.floats(-10, 10),
    h=st.floats(0.01, 5.0),
    data=st.data(),
)
def test_random_key_points(n, t0, h, data):
    m = data.draw(st.integers(1, 6))
    keys = data.draw(hnp.arrays(np.float64, (n, m), elements=st.floats(-10, 10)))
    times = t0 + h * np.arange(n)
    check_spline_properties(times, keys)


@given(hnp.arrays(np.float64, (5, 3), elements=st.floats(-3, 3)))
def test_sampling_is_vectorized_and_pointwise_equal(keys):
    spline = CubicBSplineTrajectory(np.arange(5) * 0.5, keys)
    t = np.linspace(-0.2, 2.2, 37)
    batch = spline.sample(t)
    for i in (0, 5, 18, 36):
        one = spline.sample(t[i])
        np.testing.assert_array_equal(one.position[0], batch.position[i])


@pytest.mark.parametrize(
    "times, keys, match",
    [
        ([0.0], [[1.0]], "at least 2 key points"),
        ([0.0, 0.5, 0.5], [[0.0], [1.0], [2.0]], "increase strictly"),
        ([0.0, 1.0, 0.5], [[0.0], [1.0], [2.0]], "increase strictly"),
        ([0.0, 0.5, 1.5], [[0.0], [1.0], [2.0]], "uniformly spaced"),
        ([0.0, np.nan], [[0.0], [1.0]], "NaN"),
        ([0.0, 1.0], [[0.0], [np.nan]], "nan"),
        ([0.0, 1.0, 2.0], [[0.0], [1.0]], "shape"),
    ],
)
def test_bad_input_is_rejected(times, keys, match):
    with pytest.raises(PlanningError, match=match):
        CubicBSplineTrajectory(times, keys)


def test_mismatched_joint_counts_rejected():
    with pytest.raises(PlanningError, match="2 joint labels for 3"):
        CubicBSplineTrajectory([0, 1], np.zeros((2, 3)), labels=["a", "b"])
    with pytest.raises(PlanningError, match="lower limits have shape"):
        CubicBSplineTrajectory([0, 1], np.zeros((2, 3)), lower=[0, 0])


def test_key_point_outside_joint_limit_names_joint_and_limit():
    keys = table1_to_si(TABLE1).copy()
    keys[2, 4] = np.deg2rad(80.0)  # wrist_yaw beyond its 1.2 rad limit
    from planbench.models import loader_spec

    spec = loader_spec()
    with pytest.raises(LimitError, match=r"wrist_yaw = 1\.39626 is beyond its upper limit 1\.2"):
        CubicBSplineTrajectory(TABLE1_TIMES, keys, labels=spec.names, lower=spec.lower, upper=spec.upper)


def test_overshoot_between_key_points_is_rejected():
    # Two key points at the limit: the spline bulges above it between them.
    keys = np.array([[0.0], [1.0], [1.0], [0.0]])
    peak = CubicBSplineTrajectory([0, 1, 2, 3], keys).sample(np.linspace(0, 3, 3001)).position.max()
    assert peak > 1.0
    with pytest.raises(LimitError, match="overshoots its upper limit"):
        CubicBSplineTrajectory([0, 1, 2, 3], keys, upper=[1.0])
    CubicBSplineTrajectory([0, 1, 2, 3], keys, upper=[peak + 1e-9])  # fits a wider range


def test_loader_plans():
    supply, direct = supply_plan(), direct_plan()
    assert supply.duration == direct.duration == 2.5
    # The direct move is a straight line in joint space: every sample lies on P2-P3.
    q = direct.sample(np.linspace(0, 2.5, 51)).position
    p2, p3 = table1_to_si(TABLE1[[0, -1]])
    s = (q - p2) @ (p3 - p2) / np.dot(p3 - p2, p3 - p2)
    np.testing.assert_allclose(q, p2 + s[:, None] * (p3 - p2), atol=1e-12)
