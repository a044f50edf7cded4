"""Issue 12, part 6: the Python API refuses bad input up front, naming the value and the limit.

Every planner raises a ``PlanningError`` (a ``ValueError`` subclass, ``planbench.planners.errors``) whose
message names the offending value (and its row, joint or axis) and the limit it breaks, before
any planning is done. Key points exactly on a joint limit are accepted: the B-spline's check
between key points allows its own round-off, ``limit_tolerance`` = 64 eps max |P| per joint
(``planbench.planners.bspline``, "Joint limits and round-off"), and nothing more.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.interpolate import CubicSpline

from planbench.planners import antenna, fast, hexapod, loader, profiles
from planbench.planners.errors import LimitError, PlanningError
from planbench.planners.fast import plan as fast_plan
from planbench.planners.loader.bspline import CubicBSplineTrajectory
from planbench.planners.trajectory import MAX_MAGNITUDE, sample_times

NAN, INF = float("nan"), float("inf")
LIMIT = "1e+150"  # MAX_MAGNITUDE as the messages write it
EPS = np.finfo(float).eps
ULPS = 64  # the documented round-off allowance: 64 (eps max |P| + eta), planbench.planners.bspline


def raises_named(call, *fragments, kind=PlanningError):
    """Run ``call``; assert it raises a ValueError subclass of ``kind`` whose message holds
    every fragment. Returns the message."""
    with pytest.raises(ValueError) as info:
        call()
    err = info.value
    assert type(err) is not ValueError, f"plain ValueError, not a planner error: {err}"
    assert isinstance(err, kind), f"{type(err).__name__}: {err}"
    message = str(err)
    assert "\n" not in message
    for fragment in fragments:
        assert fragment in message, f"{fragment!r} not in {message!r}"
    return message


def spline(keys=((0.0,), (1.0,)), times=None, **kwargs):
    keys = np.asarray(keys, dtype=float)
    times = np.arange(len(keys)) * 0.5 if times is None else times
    return CubicBSplineTrajectory(times, keys, **kwargs)


def test_max_magnitude_is_what_the_messages_say():
    assert MAX_MAGNITUDE == 1e150 and f"{MAX_MAGNITUDE:g}" == LIMIT
    # Its reason: a square of 1e4 times it is still a finite double.
    assert math.isfinite((1e4 * MAX_MAGNITUDE) ** 2)


# =========================================================================== 1. limits

BSPLINE_LIMIT_CASES = [
    # (kwargs of CubicBSplineTrajectory([0, 0.5], [[0], [1]]), fragments of the message)
    (dict(lower=[NAN]), ["lower limit of joint q1", "= nan", "non-finite", LIMIT]),
    (dict(upper=[NAN]), ["upper limit of joint q1", "= nan", "non-finite", LIMIT]),
    (dict(lower=[-INF]), ["lower limit of joint q1", "= -inf", "non-finite", LIMIT]),
    (dict(upper=[INF]), ["upper limit of joint q1", "= inf", "non-finite", LIMIT]),
    (dict(lower=[-1e308], upper=[1.0]), ["lower limit of joint q1", "= -1e+308", LIMIT]),
    (dict(lower=[0.0], upper=[1e200]), ["upper limit of joint q1", "= 1e+200", LIMIT]),
    (dict(lower=[1.0], upper=[0.0]), ["joint q1", "lower limit 1", "upper limit 0"]),
    (dict(lower=["low"]), ["lower limits", "'low'"]),
    (dict(lower=[0.0, 0.0]), ["lower limits have shape (2,)", "expected (1,)"]),
]


@pytest.mark.parametrize("kwargs, fragments", BSPLINE_LIMIT_CASES)
def test_bad_joint_limits_are_refused(kwargs, fragments):
    raises_named(lambda: spline(**kwargs), *fragments)


def test_limit_nan_names_the_joint_of_a_multi_joint_spline():
    keys = np.zeros((3, 3))
    raises_named(
        lambda: spline(keys, labels=["a", "b", "c"], lower=[0, 0, 0], upper=[1, NAN, 1]),
        "upper limit of joint b",
        "= nan",
        LIMIT,
    )


HEXAPOD_LIMIT_CASES = [
    ("pose_lower", [NAN, 0, 0, 0, 0, 0], ["pose_lower x", "= nan m", "non-finite", LIMIT]),
    ("pose_upper", [1, 1, 1, 1, INF, 1], ["pose_upper ry", "= inf rad", LIMIT]),
    ("pose_upper", [1, 1, 1, 1, 1], ["pose_upper must have 6 components", "(5,)"]),
    ("pose_lower", [2, 0, 0, 0, 0, 0], ["pose_lower x = 2", "above pose_upper x = 1"]),
    ("stroke", NAN, ["stroke = nan", "finite and > 0"]),
    ("strut_speed", INF, ["strut_speed = inf", "finite and > 0"]),
    ("strut_accel", -1.0, ["strut_accel = -1.0", "> 0"]),
    ("linear_speed", 1e308, ["linear_speed", "= 1e+308", LIMIT]),
]


@pytest.mark.parametrize("field, value, fragments", HEXAPOD_LIMIT_CASES)
def test_bad_hexapod_limits_are_refused(field, value, fragments):
    args = dict(
        pose_lower=[-1] * 6,
        pose_upper=[1] * 6,
        stroke=1.0,
        strut_speed=1.0,
        strut_accel=1.0,
        linear_speed=1.0,
        angular_speed=1.0,
    )
    args[field] = value
    raises_named(lambda: hexapod.HexapodLimits(**args), *fragments)


def test_nan_hexapod_limits_no_longer_plan_a_move():
    """A NaN pose limit used to compare False everywhere, so every pose passed."""
    raises_named(
        lambda: hexapod.plan_moves(
            np.zeros(6), np.zeros(6), limits=hexapod.HexapodLimits([NAN] * 6, [1] * 6, 1, 1, 1, 1, 1)
        ),
        "pose_lower x = nan",
    )


PROFILE_LIMIT_CASES = [
    (lambda: profiles.move_min_time(1.0, INF, 1.0), ["v_max = inf m/s", LIMIT]),
    (lambda: profiles.move_min_time(1.0, 1.0, NAN), ["a_max = nan m/s^2", LIMIT]),
    (lambda: profiles.move_min_time(1.0, 1e308, 1.0), ["v_max = 1e+308 m/s", LIMIT]),
    (lambda: profiles.move_in_time(1.0, 1e308, 1.0, 1.0), ["duration = 1e+308 s", LIMIT]),
    (lambda: profiles.velocity_change(0.0, 1.0, -INF), ["a_max = -inf", LIMIT]),
    (lambda: profiles.cruise(1e308, 1.0), ["velocity = 1e+308 m/s", LIMIT]),
    (lambda: profiles.Profile([1e308, 1e308], [0.0, 1.0, 0.0]), ["profile durations[0] = 1e+308 s", LIMIT]),
    (lambda: profiles.Profile([1e100, 1e100], [0.0, 1e100, 0.0]), ["profile position at break 1", "e+299 m", LIMIT]),
]


@pytest.mark.parametrize("call, fragments", PROFILE_LIMIT_CASES)
def test_bad_profile_numbers_are_refused(call, fragments):
    raises_named(call, *fragments)


# =========================================================================== 2. sample(t)


def _fast_plan():
    s = fast.source_direction(math.radians(10.0), math.radians(70.0))
    return fast_plan.FastPlan([fast_plan.observation_segment(np.array([0.0, 10.0]), np.stack([s, s]), name="hold")])


def _joint_path():
    path = antenna.solve_joint_path(np.tile(np.eye(3), (4, 1, 1)), 0.1, np.zeros(4))
    return antenna.JointPathTrajectory(path)


TRAJECTORIES = {
    "bspline": lambda: spline([[0.0], [1.0], [0.5]]),
    "hexapod move": lambda: hexapod.plan_move(np.zeros(6), [1e-3, 0, 0, 0, 0, 0]),
    "profile": lambda: profiles.move_min_time(1.0, 1.0, 1.0),
    "fast plan": _fast_plan,
    "antenna joint path": _joint_path,
}

BAD_TIMES = [
    ([NAN], ["sample time t[0] = nan s", "non-finite", LIMIT]),
    (NAN, ["sample time t[0] = nan s", LIMIT]),
    ([0.0, 0.5, INF], ["sample time t[2] = inf s", LIMIT]),
    ([-INF], ["sample time t[0] = -inf s", LIMIT]),
    ([0.0, 1e308], ["sample time t[1] = 1e+308 s", LIMIT]),
    ([[0.0, 1.0], [1.0, 2.0]], ["sample times must be a number or a 1-D array", "(2, 2)"]),
    ("soon", ["sample times must be numbers", "'soon'"]),
]


@pytest.fixture(scope="module", params=sorted(TRAJECTORIES))
def trajectory(request):
    return TRAJECTORIES[request.param]()


@pytest.mark.parametrize("t, fragments", BAD_TIMES)
def test_sample_refuses_bad_times_by_name(trajectory, t, fragments):
    raises_named(lambda: trajectory.sample(t), *fragments)


def test_sample_still_takes_numbers_arrays_and_nothing(trajectory):
    assert trajectory.sample(0.25).position.shape[0] == 1
    many = trajectory.sample(np.linspace(-1.0, trajectory.duration + 1.0, 7))
    assert many.position.shape[0] == 7 and np.all(np.isfinite(many.position))
    assert trajectory.sample([]).t.shape == (0,)


def test_sample_times_is_the_one_check():
    np.testing.assert_array_equal(sample_times(2.0), [2.0])
    np.testing.assert_array_equal(sample_times([1, 2]), [1.0, 2.0])
    raises_named(lambda: sample_times([0.0, NAN]), "t[1] = nan")


# =========================================================================== 3. huge values

HUGE_CASES = [
    (lambda: spline([[0.0], [1e308]]), ["key point 1 of joint q1", "= 1e+308", LIMIT]),
    (lambda: spline([[-1e308], [0.0]]), ["key point 0 of joint q1", "= -1e+308", LIMIT]),
    (lambda: spline([[0.0], [1e151]]), ["key point 1 of joint q1", "= 1e+151", LIMIT]),
    (lambda: spline([[0.0], [INF]]), ["key point 1 of joint q1", "= inf", "non-finite"]),
    (lambda: spline([[0.0], [NAN]]), ["key point 1 of joint q1", "= nan", "non-finite"]),
    (lambda: spline([[0.0, 0.0], [0.0, -INF]], labels=["a", "b"]), ["key point 1 of joint b", "= -inf"]),
    (lambda: spline(times=[0.0, 1e308]), ["key time t[1] = 1e+308 s", LIMIT]),
    (lambda: spline(times=[NAN, 1.0]), ["key time t[0] = nan s", "NaN"]),
    (lambda: spline(times=[0.0, 1e-200]), ["key step 1e-200 s is too short", "must be >= 4.9e-75 s"]),
    (lambda: hexapod.plan_moves(np.zeros(6), [1e308, 0, 0, 0, 0, 0]), ["target pose x = 1e+308 m", LIMIT]),
    (lambda: hexapod.plan_moves([0, 0, 0, 0, 0, -1e308], np.zeros(6)), ["start pose rz = -1e+308 rad", LIMIT]),
    (lambda: profiles.move_min_time(1e308, 1.0, 1.0), ["distance = 1e+308 m", LIMIT]),
    (lambda: profiles.move_min_time(-1e308, 1.0, 1.0), ["distance = -1e+308 m", LIMIT]),
    (lambda: fast_plan.switch_times([1e308, 0.0, -100.0], [0.0, 0.0, -160.0]), ["P0 x = 1e+308 m", LIMIT]),
]


@pytest.mark.parametrize("call, fragments", HUGE_CASES)
def test_huge_and_non_finite_values_are_named(call, fragments):
    raises_named(call, *fragments)


def test_largest_accepted_key_point_plans_finite_motion():
    times = [0.0, 10.0, 20.0]  # long enough for accelerations within MAX_MAGNITUDE
    s = spline([[0.0], [MAX_MAGNITUDE], [0.0]], times=times)
    out = s.sample(np.linspace(0.0, 20.0, 11))
    assert all(np.all(np.isfinite(x)) for x in (out.position, out.velocity, out.acceleration))
    # The overshoot check squares the coefficients: still finite, and still finds the bulge.
    raises_named(
        lambda: spline(
            [[MAX_MAGNITUDE], [-MAX_MAGNITUDE], [-MAX_MAGNITUDE], [MAX_MAGNITUDE]],
            times=[0.0, 10.0, 20.0, 30.0],
            lower=[-MAX_MAGNITUDE],
        ),
        "overshoots its lower limit",
        kind=LimitError,
    )
    raises_named(lambda: spline([[0.0], [1.0]], times=[0.0, 0.5]).sample([0.25, 2e150]), "t[1] = 2e+150 s")


def test_hexapod_limit_message_of_a_large_value_is_readable():
    message = raises_named(
        lambda: hexapod.plan_moves(np.zeros(6), [1e140, 0, 0, 0, 0, 0]),
        "target x = 1e+146 um",
        "limit 11400.0 um",
        kind=LimitError,
    )
    assert len(message) < 120


# =========================================================================== 4. plan_moves rows


@pytest.mark.parametrize("row", [0, 2, 4])
@pytest.mark.parametrize("axis, unit", [(0, "m"), (3, "rad"), (5, "rad")])
@pytest.mark.parametrize("value, text", [(NAN, "nan"), (INF, "inf"), (-1e308, "-1e+308")])
def test_plan_moves_names_the_bad_row(row, axis, unit, value, text):
    target = np.zeros((5, 6))
    target[row, axis] = value
    name = hexapod.POSE_LABELS[axis]
    raises_named(
        lambda: hexapod.plan_moves(np.zeros(6), target), f"target pose {name} of row {row} = {text} {unit}", LIMIT
    )
    raises_named(
        lambda: hexapod.plan_moves(target, np.zeros((5, 6))), f"start pose {name} of row {row} = {text} {unit}", LIMIT
    )


def test_plan_strut_moves_names_the_bad_row():
    target = np.zeros((3, 6))
    target[1, 4] = NAN
    raises_named(
        lambda: hexapod.plan_strut_moves(np.zeros((3, 6)), target), "target strut5 position of row 1 = nan m", LIMIT
    )


OTHER_ENTRY_POINTS = [
    (
        lambda: hexapod.plan_moves(np.zeros(6), [1e-3, 0, 0, 0, 0, 0], dt=1e-300),
        ["tick 1e-300 s is too short", "1e+08"],
    ),
    (lambda: hexapod.strut_lengths([0, 0, NAN, 0, 0, 0]), ["pose z = nan m"]),
    (
        lambda: hexapod.HexapodGeometry(np.full((6, 3), NAN), np.ones((6, 3)), np.zeros(3)),
        ["base_pivots[0, 0] = nan m"],
    ),
    (lambda: loader.forward_kinematics([0, 0, 0, NAN, 0, 0]), ["q of joint wrist_pitch = nan", LIMIT]),
    (lambda: loader.forward_kinematics(np.zeros(5)), ["q has 5 joints, the chain has 6"]),
    (lambda: fast_plan.switch_times([NAN, 0.0, -100.0], [0.0, 0.0, -160.0]), ["P0 x = nan m"]),
    (lambda: fast_plan.switch_times([0.0, 0.0, -160.0], [0.0, 0.0, -160.0], multifeed1=NAN), ["multifeed1 = nan rad"]),
    (
        lambda: fast_plan.transition_time(np.zeros(3) + 1, [0, INF, 0], np.ones(3), np.zeros(3)),
        ["transition V0 y = inf m/s"],
    ),
    (
        lambda: fast_plan.observation_segment([0.0, NAN], np.tile([0.0, 0.0, 1.0], (2, 1))),
        ["observation time t[1] = nan s"],
    ),
]


@pytest.mark.parametrize("call, fragments", OTHER_ENTRY_POINTS)
def test_other_entry_points_name_the_value(call, fragments):
    raises_named(call, *fragments)


# =========================================================================== 5. on the limits

OFFSETS = st.sampled_from([0.0, -1.0, 1000.0, -math.pi, 1e-3])
SPANS = st.sampled_from([1.0, 1e-3, 2.5, 360.0])
STEPS = st.sampled_from([0.5, 0.005, 3.0])
UNIT = st.one_of(st.sampled_from([0.0, 1.0]), st.floats(0.0, 1.0))


@st.composite
def on_limit_sequences(draw):
    """Key sequences in [0, 1] (often exactly 0 or 1) whose exact spline stays in [0, 1].

    zig-zag a, b, a, b, ...: with M[i+1] == M[i-1] every knot velocity is 0 (the velocity
    system v[i-1] + 4 v[i] + v[i+1] = 3 (M[i+1] - M[i-1]) / h, v[0] = v[n] = 0), so every
    segment is a monotone smoothstep between a and b. ramp: equally spaced from a to b; the
    knot velocities lie between 0 and 1.27 times the slope, inside the Fritsch-Carlson
    region (<= 3 times it), so every segment is monotone.
    """
    n = draw(st.integers(2, 12))
    a, b = draw(UNIT), draw(UNIT)
    if draw(st.booleans()):
        return np.where(np.arange(n) % 2 == 0, a, b)
    return np.clip(np.linspace(a, b, n), 0.0, 1.0)


def check_within(traj, lower, upper):
    t = np.concatenate([np.linspace(-0.1, traj.duration + 0.1, 4001), traj.key_times])
    pos = traj.sample(t).position
    tol = traj.limit_tolerance
    assert np.all(pos >= lower - tol) and np.all(pos <= upper + tol), ((lower - pos).max(), (pos - upper).max(), tol)


@settings(max_examples=300, deadline=None)
@given(on_limit_sequences(), on_limit_sequences(), OFFSETS, SPANS, STEPS)
def test_key_points_on_the_limits_are_accepted(seq_a, seq_b, offset, span, step):
    n = min(seq_a.size, seq_b.size)
    unit = np.column_stack([seq_a[:n], seq_b[:n]])
    keys = offset + span * unit
    lower, upper = np.full(2, offset), np.full(2, offset + span)
    assert np.all(keys >= lower) and np.all(keys <= upper)
    traj = CubicBSplineTrajectory(np.arange(n) * step, keys, lower=lower, upper=upper)
    check_within(traj, lower, upper)
    # A few dozen ulps of the values' magnitude, not a loosened limit.
    magnitude = max(abs(offset), abs(offset + span))
    assert np.all(traj.limit_tolerance <= ULPS * (EPS * 4 * magnitude + 5e-324))


def test_the_tolerance_is_the_documented_one():
    keys = np.array([[0.0, 1000.0], [1.0, 1001.0], [0.5, 1000.5]])
    traj = spline(keys)
    expected = ULPS * (EPS * np.abs(traj.control_points).max(axis=0) + 5e-324)
    np.testing.assert_array_equal(traj.limit_tolerance, expected)
    assert 1e-14 < traj.limit_tolerance[0] < 1e-13  # a few dozen ulps of ~1, not more


@settings(max_examples=200, deadline=None)
@given(on_limit_sequences(), st.integers(0, 11), st.booleans(), st.sampled_from([1.5, 10.0, 1e6]), OFFSETS, SPANS)
def test_a_key_point_beyond_the_limit_is_refused(seq, where, high, factor, offset, span):
    keys = (offset + span * seq)[:, None]
    k = where % keys.shape[0]
    tol = spline(keys).limit_tolerance[0]
    lower, upper = offset, offset + span
    limit = upper if high else lower
    delta = factor * max(tol, 2 * abs(np.spacing(limit)))  # beyond the tolerance, representable
    keys[k, 0] = upper + delta if high else lower - delta
    assert keys[k, 0] != (upper if high else lower)
    side = "upper" if high else "lower"
    raises_named(lambda: spline(keys, lower=[lower], upper=[upper]), f"beyond its {side} limit", kind=LimitError)


def test_a_key_point_one_ulp_beyond_the_limit_is_refused():
    """Key points are the caller's numbers: they are checked exactly, without tolerance."""
    raises_named(
        lambda: spline([[0.0], [np.nextafter(1.0, 2.0)]], lower=[0.0], upper=[1.0]),
        "q1 = 1.0000000000000002 is beyond its upper limit 1.0",
        kind=LimitError,
    )
    raises_named(
        lambda: spline([[-5e-324], [1.0]], lower=[0.0], upper=[1.0]), "beyond its lower limit 0", kind=LimitError
    )


def _true_extremes(times, keys):
    """Largest and smallest value of the clamped spline (scipy, its derivative's roots)."""
    cs = CubicSpline(times, keys, bc_type="clamped")
    roots = cs.derivative().roots(extrapolate=False)
    values = np.concatenate([cs(roots), keys])
    return values.max(), values.min()


@settings(max_examples=200, deadline=None)
@given(st.floats(0.05, 1.0), st.booleans(), st.sampled_from([2.0, 5.0, 1e3]), OFFSETS, SPANS)
@example(b=0.6431516570555993, high=False, factor=2.0, offset=0.0, span=360.0)  # found by it
def test_a_real_overshoot_beyond_the_tolerance_is_refused(b, high, factor, offset, span):
    """Two equal key points bulge beyond themselves; a limit ``factor`` tolerances inside
    the bulge's tip (found independently with scipy) is refused, one outside is not."""
    unit = np.array([0.0, b, b, 0.0]) if high else np.array([1.0, 1.0 - b, 1.0 - b, 1.0])
    keys = offset + span * unit
    times = np.arange(4) * 0.5
    top, bottom = _true_extremes(times, keys)
    tol = spline(keys[:, None]).limit_tolerance[0]
    if high:
        assert top > keys.max() + factor * tol  # a real bulge
        bad, good = dict(upper=[top - factor * tol]), dict(upper=[top + factor * tol])
    else:
        assert bottom < keys.min() - factor * tol
        bad, good = dict(lower=[bottom + factor * tol]), dict(lower=[bottom - factor * tol])
    side = "upper" if high else "lower"
    raises_named(
        lambda: spline(keys[:, None], **bad), f"overshoots its {side} limit", "round-off tolerance", kind=LimitError
    )
    spline(keys[:, None], **good)


def test_a_dip_whose_cubic_term_is_round_off_is_found():
    """360, 128.5, 128.5, 360 dips to 70.58 in its middle segment, whose u^3 coefficient is
    round-off (-1.4e-14). The overshoot check's old root formula lost that extremum and
    accepted a lower limit of 75 (hypothesis found it with the test above)."""
    b = 0.6431516570555993
    keys = (360.0 * np.array([1.0, 1.0 - b, 1.0 - b, 1.0]))[:, None]
    top, bottom = _true_extremes(np.arange(4) * 0.5, keys[:, 0])
    assert bottom == pytest.approx(70.58175432, abs=1e-6)
    raises_named(lambda: spline(keys, lower=[75.0]), "q1 = 70.5818 overshoots its lower limit 75", kind=LimitError)
    spline(keys, lower=[70.58])


def test_three_hundred_ramps_from_0_to_1_are_accepted():
    """Issue 12's case: straight key sequences 0 -> 1 in [0, 1], n = 2 ... 301 key points.
    With a strict comparison 24 of these 300 were refused for overshoots of <= 4.4e-16."""
    refused = []
    for n in range(2, 302):
        try:
            traj = spline(np.linspace(0.0, 1.0, n)[:, None], lower=[0.0], upper=[1.0])
        except LimitError:
            refused.append(n)
            continue
        if n % 50 == 0:
            check_within(traj, 0.0, 1.0)
    assert refused == []


def test_random_sequences_from_0_to_1_are_refused_only_for_real_overshoots():
    """0, two uniform values, 1 (300 seeds), limits [0, 1]: every refusal is a real overshoot
    (many tolerances, measured with scipy) and every sequence accepted stays inside."""
    refused = 0
    for seed in range(300):
        rng = np.random.default_rng(seed)
        keys = np.r_[0.0, rng.uniform(0.0, 1.0, 2), 1.0]
        times = np.arange(4) * 0.5
        top, bottom = _true_extremes(times, keys)
        overshoot = max(top - 1.0, -bottom)
        tol = spline(keys[:, None]).limit_tolerance[0]
        try:
            traj = spline(keys[:, None], lower=[0.0], upper=[1.0])
        except LimitError:
            refused += 1
            assert overshoot > 1e3 * tol, (seed, overshoot, tol)
        else:
            assert overshoot <= tol, (seed, overshoot, tol)
            check_within(traj, 0.0, 1.0)
    assert 0 < refused < 300  # the family has both kinds; before the fix 33 more were refused


def test_move_from_1_to_0_within_0_1_is_accepted():
    """The smallest case: 1 -> 0 evaluated to -2.2e-16 and was refused."""
    traj = spline([[1.0], [0.0]], lower=[0.0], upper=[1.0])
    check_within(traj, 0.0, 1.0)
