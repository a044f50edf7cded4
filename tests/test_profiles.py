"""1-D motion profiles (planners/profiles.py): the FAST paper's Figure 6 profiles.

Checked against closed forms derived by hand (rest-to-rest in both regimes, the pulse), against
brute-force searches over the profile family (minimum time, lowest cruise speed), and against
exact integration of the sampled acceleration and velocity. Limits include the paper's Table 1
(mm -> m): A_max 10, A_t-max 15, A_s-max 25 mm/s^2 and V_s-max 400 mm/s; the paper gives a speed
limit only for source switching, so V_s-max is used with every acceleration limit.
"""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from planbench.planners.errors import LimitError, PlanningError
from planbench.planners.profiles import (
    Profile,
    concatenate,
    cruise,
    min_move_time,
    move_in_time,
    move_min_time,
    velocity_change,
)
from planbench.planners.trajectory import Trajectory, TrajectorySample

A_MAX, A_T_MAX, A_S_MAX = 10e-3, 15e-3, 25e-3  # m/s^2, Table 1
V_S_MAX = 400e-3  # m/s, Table 1
TABLE1 = [(V_S_MAX, A_MAX), (V_S_MAX, A_T_MAX), (V_S_MAX, A_S_MAX)]
RTOL = 1e-12


# --------------------------------------------------------------------------- helpers


def rest_to_rest_time(d, v_max, a_max):
    """Hand-derived: reaching v_c from rest takes 2 v_c / a over v_c^2 / a."""
    d = abs(d)
    if d <= 2 * v_max**2 / a_max:
        return 2 * math.sqrt(2 * d / a_max)
    return d / v_max + 2 * v_max / a_max


def family_times(v, d, v0, v1, a1, a2):
    """Time of the pulse-cruise-pulse profile with peaks a1, a2 and cruise speed v (array) that
    covers d >= 0 from v0 to v1 (>= 0) without reversing; inf where its cruise would be < 0."""
    pulses = (v0 + v) * np.abs(v - v0) / a1 + (v + v1) * np.abs(v1 - v) / a2
    t_pulses = 2 * np.abs(v - v0) / a1 + 2 * np.abs(v1 - v) / a2
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = (d - pulses) / v
    ok = (v > 0) & (tau >= 0)
    return np.where(ok, t_pulses + np.where(ok, tau, 0.0), np.inf)


def family_min_time(d, v0, v1, v_max, a1, a2, n=4001):
    """Brute force: the least of family_times over cruise speeds in (0, v_max] (a linear grid and
    logarithmic ones from 0 and on both sides of v0 and v1, then a fine grid around the best
    point)."""
    g = np.geomspace(v_max * 1e-12, v_max, n)
    v = np.concatenate([np.linspace(0.0, v_max, n), g, v0 + g, v0 - g, v1 + g, v1 - g])
    v = np.unique(v[(v > 0) & (v <= v_max)])
    best = np.inf
    for _ in range(3):  # zoom in twice around the best point
        v = v[np.concatenate(([True], np.diff(v) > 1e-12 * v[1:]))]  # distinct neighbours
        t = family_times(v, d, v0, v1, a1, a2)
        i = int(np.argmin(t))
        best = min(best, t[i])
        v = np.linspace(v[max(i - 1, 0)], v[min(i + 1, v.size - 1)], n)
    return best


def dense_times(p, n=4001):
    """A grid over [0, T] holding every break, and the midpoints of its intervals."""
    t = np.union1d(np.linspace(0.0, p.duration, n), p.breaks)
    return t, 0.5 * (t[1:] + t[:-1])


def check_profile(p, distance, v0, v1, v_max, a_max, duration=None):
    """Every property a planned move must have; returns the dense sample."""
    scale_p = abs(distance) + v_max * p.duration * 1e-3 + 1e-300
    # Absolute times carry round-off eps T: a sample's acceleration is known to jerk * eps T.
    dt_res = 4 * np.finfo(float).eps * max(p.duration, 1.0)
    jerk = np.max(np.abs(p.jerk), initial=0.0)
    # Exact distance, boundary speeds, duration.
    assert p.p0 == 0.0
    assert p.v0 == v0
    assert abs(p.distance - distance) <= RTOL * scale_p * 10
    assert abs(p.end_velocity - v1) <= RTOL * v_max
    if duration is not None:
        assert abs(p.duration - duration) <= 1e-9
    # Acceleration zero at both ends (exactly at the breaks, and the last piece's left limit).
    assert p.accel[0] == 0.0 and p.accel[-1] == 0.0
    end = p.evaluate(np.array([0.0, p.duration]), side="left")
    assert np.all(np.abs(end.acceleration) <= RTOL * a_max + jerk * dt_res)
    # Limits on a dense sampling.
    t, mid = dense_times(p)
    s = p.evaluate(t)
    m = p.evaluate(mid)
    for x in (s, m):
        assert np.all(np.abs(x.velocity) <= v_max * (1 + RTOL))
        assert np.all(np.abs(x.acceleration) <= a_max * (1 + RTOL))
        # Never reverses: the velocity keeps the sign of the distance.
        sign = np.sign(distance) or np.sign(v0) or np.sign(v1) or 1.0
        assert np.all(sign * x.velocity >= -RTOL * v_max)
    assert p.peak_speed <= v_max * (1 + RTOL)
    assert p.peak_acceleration <= a_max * (1 + RTOL)
    # Continuity of position, velocity and acceleration at every break: the left limit (the
    # previous piece's polynomial at its end) against the break's value, to round-off plus
    # the resolution of absolute times (eps T, times the largest jerk for the acceleration).
    left, right = p.evaluate(p.breaks, side="left"), p.evaluate(p.breaks, side="right")
    np.testing.assert_allclose(left.position, right.position, rtol=0, atol=RTOL * scale_p * 10 + v_max * dt_res)
    np.testing.assert_allclose(left.velocity, right.velocity, rtol=0, atol=RTOL * v_max * 10 + a_max * dt_res)
    np.testing.assert_allclose(left.acceleration, right.acceleration, rtol=0, atol=RTOL * a_max * 10 + jerk * dt_res)
    # Exact integration between neighbouring samples (no break inside an interval): the
    # acceleration is linear (trapezoid exact), the velocity quadratic (Simpson exact).
    dt = np.diff(t)
    np.testing.assert_allclose(
        np.diff(s.velocity),
        0.5 * (s.acceleration[1:] + s.acceleration[:-1]) * dt,
        rtol=0,
        atol=1e-11 * v_max + 4 * a_max * dt_res,
    )
    simpson = dt / 6 * (s.velocity[:-1] + 4 * m.velocity + s.velocity[1:])
    np.testing.assert_allclose(np.diff(s.position), simpson, rtol=0, atol=1e-11 * scale_p + 4 * v_max * dt_res)
    np.testing.assert_allclose(np.diff(s.acceleration), m.jerk * dt, rtol=0, atol=1e-11 * a_max + 4 * jerk * dt_res)
    return s


@st.composite
def limits(draw):
    if draw(st.booleans()):
        return draw(st.sampled_from(TABLE1))
    v_max = 10 ** draw(st.floats(-3.0, 0.5))
    a_max = 10 ** draw(st.floats(-3.0, 0.5))
    return v_max, a_max


@st.composite
def moves(draw):
    """(distance, v_max, a_max, v0, v1): 1 mm to 500 m (plus the least distance the boundary
    speeds need, half the time), either sign, boundary speeds in the direction of motion."""
    v_max, a_max = draw(limits())
    sign = draw(st.sampled_from([1.0, -1.0]))
    frac = st.one_of(st.just(0.0), st.just(1.0), st.floats(0.0, 1.0))
    u0, u1 = draw(frac) * v_max, draw(frac) * v_max
    d = 10 ** draw(st.floats(-3.0, math.log10(500.0)))
    if draw(st.booleans()):
        d += abs(u1**2 - u0**2) / a_max
    return sign * d, v_max, a_max, sign * u0, sign * u1


def feasible(d, a_max, v0, v1):
    return abs(d) >= abs(v1**2 - v0**2) / a_max


# --------------------------------------------------------------------------- the pulse


@pytest.mark.parametrize(
    "v0, v1, a",
    [(0.0, 0.4, A_S_MAX), (0.4, 0.0, A_S_MAX), (0.0, 0.01019, A_MAX), (-0.2, 0.3, A_T_MAX), (0.1, -0.05, 2.0)],
)
def test_velocity_change_is_the_triangular_pulse(v0, v1, a):
    p = velocity_change(v0, v1, a)
    T = 2 * abs(v1 - v0) / a
    assert p.duration == pytest.approx(T, rel=1e-15)
    assert p.distance == pytest.approx((v0 + v1) / 2 * T, rel=1e-12, abs=1e-15)
    assert p.end_velocity == pytest.approx(v1, abs=1e-15)
    s = p.evaluate(np.array([0.0, T / 4, T / 2, 3 * T / 4, T]))
    sgn = np.sign(v1 - v0)
    # Linear rise to the peak at T/2 and linear fall: a = 0, a/2, a, a/2, 0.
    np.testing.assert_allclose(s.acceleration, sgn * a * np.array([0, 0.5, 1, 0.5, 0]), rtol=0, atol=1e-15)
    np.testing.assert_allclose(s.jerk, sgn * a / (T / 2) * np.array([1, 1, -1, -1, 0]), rtol=1e-12)
    # Point symmetry: the speed at T/2 is the mean.
    assert s.velocity[2] == pytest.approx((v0 + v1) / 2, abs=1e-15)


def test_velocity_change_without_change_is_empty():
    p = velocity_change(0.3, 0.3, 1.0)
    assert p.duration == 0.0 and p.breaks.tolist() == [0.0]
    s = p.evaluate(np.array([-1.0, 0.0, 2.0]))
    np.testing.assert_array_equal(s.position, [-0.3, 0.0, 0.6])
    np.testing.assert_array_equal(s.velocity, [0.3, 0.3, 0.3])


# --------------------------------------------------------------------------- minimum time


@pytest.mark.parametrize(
    "d, v_max, a, T",
    [
        (100.0, V_S_MAX, A_S_MAX, 100 / 0.4 + 2 * 0.4 / 0.025),  # 282 s, cruises
        (5.0, V_S_MAX, A_S_MAX, 2 * math.sqrt(2 * 5 / 0.025)),  # 40 s, no cruise
        (12.8, V_S_MAX, A_S_MAX, 64.0),  # 2 v^2 / a: just reaches v_max
        (-0.5, V_S_MAX, A_MAX, 2 * math.sqrt(2 * 0.5 / 0.01)),  # 20 s
        (
            math.radians(26.4),
            math.radians(0.5),
            math.radians(0.05),  # an angle, rad
            math.radians(26.4) / math.radians(0.5) + 2 * 0.5 / 0.05,
        ),
    ],
)
def test_rest_to_rest_closed_form(d, v_max, a, T):
    assert T == pytest.approx(rest_to_rest_time(d, v_max, a), rel=1e-14)
    p = move_min_time(d, v_max, a)
    assert p.duration == pytest.approx(T, rel=1e-13)
    assert min_move_time(d, v_max, a) == pytest.approx(T, rel=1e-13)
    check_profile(p, d, 0.0, 0.0, v_max, a)
    v_c = min(v_max, math.sqrt(abs(d) * a / 2))
    assert p.peak_speed == pytest.approx(v_c, rel=1e-12)
    assert p.peak_acceleration == a


def test_table1_example_numbers():
    # 12.8 m = 2 V_s-max^2 / A_s-max is where the source switching move starts to cruise.
    assert move_min_time(5.0, V_S_MAX, A_S_MAX).duration == pytest.approx(40.0, rel=1e-14)
    assert move_min_time(100.0, V_S_MAX, A_S_MAX).duration == pytest.approx(282.0, rel=1e-14)
    # Start segment to the observation speed V_m = 10.19 mm/s (eq. 11 at V_dec = 0) at A_max.
    p = velocity_change(0.0, 10.19e-3, A_MAX)
    assert p.duration == pytest.approx(2.038, rel=1e-14)
    assert p.distance == pytest.approx(10.19e-3 * 1.019, rel=1e-12)


@given(moves())
def test_move_min_time_properties(move):
    d, v_max, a, v0, v1 = move
    d_min = abs(v1**2 - v0**2) / a  # the speed change alone, at a_max
    if abs(d) < d_min * (1 - 1e-9):
        with pytest.raises(LimitError, match="too short") as err:
            move_min_time(d, v_max, a, v0, v1)
        assert repr(d) in str(err.value)
        return
    if abs(d) < d_min:
        return  # within round-off of the limit: planned on it or refused, both are right
    p = move_min_time(d, v_max, a, v0, v1)
    check_profile(p, d, v0, v1, v_max, a)
    assert p.duration == pytest.approx(min_move_time(d, v_max, a, v0, v1), rel=1e-12)
    if v0 == 0 and v1 == 0:
        assert p.duration == pytest.approx(rest_to_rest_time(d, v_max, a), rel=1e-12)


@given(moves(), st.floats(0.05, 1.0), st.floats(0.05, 1.0))
def test_no_profile_of_the_family_is_faster(move, k1, k2):
    """Brute force over cruise speeds with both pulses at a_max, and with weaker pulses."""
    d, v_max, a, v0, v1 = move
    if not feasible(d, a, v0, v1):
        return
    T = min_move_time(d, v_max, a, v0, v1)
    u = (abs(d), abs(v0), abs(v1))
    full = family_min_time(*u, v_max, a, a)
    assert full >= T * (1 - 1e-12)
    assert full <= T * (1 + 1e-9)  # and the closed form is attained
    weak = family_min_time(*u, v_max, k1 * a, k2 * a)
    assert weak >= T * (1 - 1e-12)


@given(moves())
def test_move_in_time_just_below_the_minimum_raises(move):
    d, v_max, a, v0, v1 = move
    if not feasible(d, a, v0, v1) or min_move_time(d, v_max, a, v0, v1) == 0:
        return
    T = min_move_time(d, v_max, a, v0, v1)
    with pytest.raises(LimitError, match="shorter than the minimum time") as err:
        move_in_time(d, T * (1 - 1e-6), v_max, a, v0, v1)
    assert repr(T * (1 - 1e-6)) in str(err.value) and repr(T) in str(err.value)


# --------------------------------------------------------------------------- prescribed time


@given(moves(), st.one_of(st.just(0.0), st.floats(0.0, 3.0)))
def test_move_in_time_properties(move, stretch):
    d, v_max, a, v0, v1 = move
    if not feasible(d, a, v0, v1):
        return
    T_min = min_move_time(d, v_max, a, v0, v1)
    T = T_min * (1 + stretch)
    try:
        p = move_in_time(d, T, v_max, a, v0, v1)
    except LimitError as err:
        # Only a move with boundary speeds can be too slow, and only if it really is: the
        # slowest profile of that duration (independent grid search) covers more than d.
        assert "too long" in str(err) and (v0 != 0 or v1 != 0)
        u0, u1 = abs(v0), abs(v1)
        v = np.linspace(0, v_max, 20001)
        t_pulses = 2 * (np.abs(v - u0) + np.abs(v - u1)) / a
        covered = (u0 + v) * np.abs(v - u0) / a + (v + u1) * np.abs(u1 - v) / a + v * (T - t_pulses)
        assert np.min(np.where(t_pulses <= T, covered, np.inf)) > abs(d) * (1 - 1e-9)
        return
    check_profile(p, d, v0, v1, v_max, a, duration=T)
    assert p.duration >= T_min * (1 - 1e-12)  # never faster than the minimum time


@given(moves())
def test_move_in_time_at_the_minimum_is_the_minimum_profile(move):
    d, v_max, a, v0, v1 = move
    if not feasible(d, a, v0, v1):
        return
    fast = move_min_time(d, v_max, a, v0, v1)
    p = move_in_time(d, fast.duration, v_max, a, v0, v1)
    assert p.duration == fast.duration
    t = np.linspace(0, fast.duration, 2001)
    s, f = p.evaluate(t), fast.evaluate(t)
    np.testing.assert_allclose(s.velocity, f.velocity, rtol=0, atol=1e-6 * v_max)
    np.testing.assert_allclose(s.position, f.position, rtol=0, atol=1e-9 * abs(d) + 1e-15)


@given(limits(), st.floats(-3.0, math.log10(500.0)), st.floats(0.0, 5.0), st.floats(0.05, 1.0), st.floats(0.05, 1.0))
def test_move_in_time_rest_to_rest_has_the_lowest_cruise_speed(lim, log_d, stretch, k1, k2):
    v_max, a = lim
    d = 10**log_d
    T = min_move_time(d, v_max, a) * (1 + stretch)
    p = move_in_time(d, T, v_max, a)
    check_profile(p, d, 0.0, 0.0, v_max, a, duration=T)
    v = p.peak_speed
    assert v == pytest.approx((a * T - math.sqrt(max(a * a * T * T - 8 * a * d, 0))) / 4, rel=1e-6)
    # Any member of the family with peaks k1 a, k2 a covering d in T cruises at least as fast:
    # d = v T - c v^2 with c = 1 / a1 + 1 / a2 (lower root, the one with a cruise >= 0).
    c = 1 / (k1 * a) + 1 / (k2 * a)
    disc = T * T - 4 * c * d
    if disc >= 0:
        # (1e-6: near the minimum time the root is a near-double root, known to ~sqrt(eps))
        assert (T - math.sqrt(disc)) / (2 * c) >= v * (1 - 1e-6)


def test_move_in_time_hand_examples():
    # Rest to rest, 10 m in 100 s at 0.4 m/s, 0.025 m/s^2: 2 v^2 - 2.5 v + 0.25 = 0.
    p = move_in_time(10.0, 100.0, V_S_MAX, A_S_MAX)
    assert p.peak_speed == pytest.approx((2.5 - math.sqrt(2.5**2 - 2.0)) / 4, rel=1e-12)
    assert p.duration == 100.0  # to the last bit
    # Zero distance from rest: hold still.
    hold = move_in_time(0.0, 7.0, V_S_MAX, A_S_MAX)
    assert hold.duration == 7.0 and hold.peak_speed == 0.0 and hold.distance == 0.0
    # 1.6 m at 1 m/s in and out (a = 1) in 2 s: slow to v with 2 + 2 (v - 1)... region below
    # both speeds: 2 v^2 + (2 - 4) v + (2 - 1.6) = 0 -> v = (2 + sqrt(4 - 3.2)) / 4.
    p = move_in_time(1.6, 2.0, 1.0, 1.0, 1.0, 1.0)
    assert np.min(p.velocities) == pytest.approx((2 + math.sqrt(0.8)) / 4, rel=1e-12)
    check_profile(p, 1.6, 1.0, 1.0, 1.0, 1.0, duration=2.0)
    # 1.4 m in 2 s cannot be done: slowing down to 0.5 m/s and back covers 1.5 m already.
    with pytest.raises(LimitError, match="too long") as err:
        move_in_time(1.4, 2.0, 1.0, 1.0, 1.0, 1.0)
    assert "1.4" in str(err.value) and "1.5" in str(err.value) and "2.0 s" in str(err.value)


@pytest.mark.parametrize(
    "move, stretch",
    [
        ((100.0, 0.01, 1.0, 0.01, 0.0), 1e-9),  # slows by ~1e-11 m/s over a 1e4 s cruise
        ((1.0000000000000002, 1.0, 1.0, 1.0, 0.9999999999999999), 0.0),  # a 1e-16 s pulse
        ((1.0, 0.01, 1.0, 0.0, 0.01), 1e-12),
    ],
)
def test_pulses_below_the_time_resolution(move, stretch):
    """A speed change far shorter than eps T is widened to 8 eps T with a lower peak: the
    breaks stay distinct and the speed change and distance stay exact."""
    d, v_max, a, v0, v1 = move
    T = min_move_time(d, v_max, a, v0, v1) * (1 + stretch)
    p = move_in_time(d, T, v_max, a, v0, v1)
    check_profile(p, d, v0, v1, v_max, a, duration=T)
    assert np.all(np.diff(p.breaks) > 0)
    assert np.min(p.durations) >= 4 * np.finfo(float).eps * T
    q = move_min_time(d, v_max, a, v0, v1)
    check_profile(q, d, v0, v1, v_max, a)
    assert np.all(np.diff(q.breaks) > 0)


# --------------------------------------------------------------------------- sampling


def test_sampling_before_and_after():
    p = move_min_time(-3.0, V_S_MAX, A_MAX, v0=-0.05, v1=-0.1)
    T = p.duration
    s = p.evaluate(np.array([-2.0, -1e-9, T + 1e-9, T + 5.0]))
    np.testing.assert_allclose(s.position[:2], [0.1, 0.05e-9], rtol=1e-12)
    np.testing.assert_array_equal(s.velocity[:2], [-0.05, -0.05])
    np.testing.assert_allclose(s.position[2:], p.end_position + p.end_velocity * np.array([1e-9, 5.0]), rtol=1e-14)
    np.testing.assert_array_equal(s.velocity[2:], [p.end_velocity] * 2)
    np.testing.assert_array_equal(s.acceleration, 0.0)
    np.testing.assert_array_equal(s.jerk, 0.0)
    # From rest to rest: held at rest before and after.
    q = move_min_time(2.0, V_S_MAX, A_S_MAX)
    r = q.evaluate(np.array([-10.0, q.duration + 10.0]))
    np.testing.assert_array_equal(r.velocity, [0.0, 0.0])
    np.testing.assert_allclose(r.position, [0.0, 2.0], rtol=1e-14)


def test_sampling_outside_a_profile_that_ends_accelerating():
    """A general profile may start/end with a != 0: outside it the velocity is held, a = 0."""
    p = Profile([2.0], [0.5, 1.5], p0=1.0, v0=0.25)  # a = 0.5 + 0.5 t, jerk 0.5
    assert p.end_velocity == pytest.approx(0.25 + 0.5 * 2 + 0.25 * 4, rel=1e-15)  # 2.25
    assert p.end_position == pytest.approx(1.0 + 0.25 * 2 + 0.25 * 4 + 0.5 * 8 / 6, rel=1e-15)
    s = p.evaluate(np.array([-1.0, 0.0, 1.0, 2.0, 3.0]))
    np.testing.assert_allclose(s.acceleration, [0.0, 0.5, 1.0, 1.5, 0.0], rtol=0, atol=1e-15)
    np.testing.assert_allclose(s.jerk, [0.0, 0.5, 0.5, 0.0, 0.0], rtol=0, atol=1e-15)
    np.testing.assert_allclose(s.velocity, [0.25, 0.25, 1.0, 2.25, 2.25], rtol=1e-15)
    np.testing.assert_allclose(
        s.position, [0.75, 1.0, 1.0 + 0.25 + 0.25 + 0.5 / 6, p.end_position, p.end_position + 2.25], rtol=1e-15
    )
    left = p.evaluate(2.0, side="left")
    assert left.jerk == 0.5 and left.acceleration == pytest.approx(1.5, rel=1e-15)


def test_exact_at_breakpoints_and_shapes():
    p = move_min_time(30.0, V_S_MAX, A_S_MAX, 0.1, 0.2)
    s = p.evaluate(p.breaks)
    np.testing.assert_array_equal(s.position, p.positions)
    np.testing.assert_array_equal(s.velocity, p.velocities)
    np.testing.assert_array_equal(s.acceleration, p.accel)
    assert p.evaluate(3.0).position.shape == ()
    assert p.evaluate(np.zeros((2, 3))).velocity.shape == (2, 3)


def test_trajectory_protocol():
    p = move_min_time(1.0, V_S_MAX, A_S_MAX).with_start(2.0)
    assert isinstance(p, Trajectory)
    assert p.labels == ("s",)
    ts = p.sample(np.linspace(0, p.duration, 11))
    assert isinstance(ts, TrajectorySample)
    assert ts.position.shape == ts.velocity.shape == ts.acceleration.shape == (11, 1)
    assert ts.position[0, 0] == 2.0 and ts.position[-1, 0] == pytest.approx(3.0, rel=1e-14)
    assert p.sample(0.5).position.shape == (1, 1)


# --------------------------------------------------------------------------- composition


def test_concatenate_start_observation_termination():
    """Section 3.1: start segment to the observation speed, observation, termination."""
    v_obs = 10.19e-3
    start = velocity_change(0.0, v_obs, A_MAX)
    obs = cruise(v_obs, 60.0)
    stop = velocity_change(v_obs, 0.0, A_MAX)
    whole = concatenate([start, obs, stop]).with_start(-1.0)
    assert whole.duration == pytest.approx(start.duration + 60.0 + stop.duration, rel=1e-14)
    d = start.distance + 60 * v_obs + stop.distance
    assert whole.end_position == pytest.approx(-1.0 + d, rel=1e-12)
    w = check_profile(whole.with_start(0.0), d, 0.0, 0.0, V_S_MAX, A_MAX)
    joins = np.array([start.duration, start.duration + 60.0])
    for t in joins:  # the joins are breaks of the composite
        assert np.min(np.abs(whole.breaks - t)) <= 1e-12
    mid = whole.evaluate(start.duration + 30.0)
    assert mid.velocity == pytest.approx(v_obs, rel=1e-12) and mid.acceleration == 0.0
    assert w.velocity.max() == pytest.approx(v_obs, rel=1e-12)
    # A start segment over a set distance (0.5 m) may overshoot the observation speed.
    longer = move_min_time(0.5, V_S_MAX, A_MAX, 0.0, v_obs).then(obs, stop)
    check_profile(longer, 0.5 + 60 * v_obs + stop.distance, 0.0, 0.0, V_S_MAX, A_MAX)
    assert longer.peak_speed > v_obs
    assert start.then(obs, stop).duration == whole.duration


def test_concatenate_rejects_a_jump():
    a = move_min_time(1.0, V_S_MAX, A_S_MAX, 0.0, 0.1)
    with pytest.raises(PlanningError, match=r"v0 = 0\.2 m/s .* ends at 0\.1"):
        concatenate([a, cruise(0.2, 1.0)])
    half = Profile([1.0], [0.0, 0.5])
    with pytest.raises(PlanningError, match="a0 = 0.0 m/s\\^2 but the one before it ends at 0.5"):
        half.then(cruise(0.25, 1.0))
    with pytest.raises(PlanningError, match="at least one"):
        concatenate([])


# --------------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: move_min_time(float("nan"), 1.0, 1.0), "distance = nan m"),
        (lambda: move_min_time(float("inf"), 1.0, 1.0), "distance = inf m"),
        (lambda: move_min_time(1.0, 0.0, 1.0), "v_max = 0.0 m/s must be > 0"),
        (lambda: move_min_time(1.0, -1.0, 1.0), "v_max = -1.0 m/s must be > 0"),
        (lambda: move_min_time(1.0, 1.0, 0.0), r"a_max = 0.0 m/s\^2 must be > 0"),
        (lambda: move_min_time(1.0, 1.0, float("nan")), r"a_max = nan m/s\^2"),
        (lambda: move_min_time(1.0, 1.0, 1.0, v0=float("nan")), "v0 = nan m/s"),
        (lambda: move_min_time(1.0, 1.0, 1.0, v1="fast"), "v1 = 'fast' m/s is not a number"),
        (lambda: move_in_time(1.0, -2.0, 1.0, 1.0), "duration = -2.0 s must be >= 0"),
        (lambda: move_in_time(1.0, float("nan"), 1.0, 1.0), "duration = nan s"),
        (lambda: velocity_change(0.0, 1.0, -1.0), r"a_max = -1.0 m/s\^2 must be > 0"),
        (lambda: cruise(1.0, -1.0), "duration = -1.0 s"),
        (lambda: move_min_time(1.0, 1.0, 1.0).evaluate(np.array([0.0, np.nan])), "nan s"),
        (lambda: move_min_time(1.0, 1.0, 1.0).evaluate(0.0, side="middle"), "'middle'"),
        (lambda: Profile.from_breaks([0.0, 1.0, 1.0], [0.0, 1.0, 0.0]), r"breaks\[2\] = 1.0 s <= breaks\[1\]"),
        (lambda: Profile.from_breaks([0.5, 1.0], [0.0, 0.0]), r"breaks\[0\] = 0.5 s"),
        (lambda: Profile([1.0, -2.0], [0.0, 1.0, 0.0]), r"durations\[1\] = -2.0 s"),
        (lambda: Profile([1.0], [0.0]), "1 pieces needs 2 accelerations, got 1"),
        (lambda: Profile([1.0], [0.0, np.nan]), "non-finite"),
    ],
)
def test_bad_input_raises_planning_error(call, match):
    with pytest.raises(PlanningError, match=match):
        call()


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: move_min_time(1.0, 0.4, 0.025, v0=0.5), r"\|v0\| = 0.5 m/s exceeds v_max = 0.4"),
        (lambda: move_min_time(1.0, 0.4, 0.025, v1=-0.1), "v1 = -0.1 m/s points against the distance 1.0 m"),
        (lambda: move_min_time(0.0, 0.4, 0.025, v0=0.1), "needs at least 0.4000"),
        (
            lambda: move_min_time(-1.0, 0.4, 0.01, v0=-0.2),
            "distance -1.0 m is too short .* v0 = -0.2 .* at least -4.000",
        ),
        (lambda: move_in_time(1.0, 1.0, 0.4, 0.025), "duration 1.0 s is shorter than the minimum time 17.88854"),
        (lambda: move_min_time(np.float64(1.0), 0.4, 0.025, v0=np.float64(0.5)), r"\|v0\| = 0.5 m/s"),
    ],
)
def test_limits_raise_limit_error(call, match):
    with pytest.raises(LimitError, match=match):
        call()
