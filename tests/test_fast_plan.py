"""The FAST plan (planners/fast/plan.py, sims/fast/task.py): source switching (section 3.2, eq. 10),
start and termination (section 3.1), tracking, and a whole plan sampled at 100 Hz."""

import math

import numpy as np
import pytest

from planbench import fast as fast_sims
from planbench.planners import fast
from planbench.planners import profiles as prof
from planbench.planners.errors import LimitError
from planbench.planners.fast import plan as fp


@pytest.fixture(scope="module")
def switch_plan():
    return fast_sims.source_switch_plan()


def _on_sphere(az_deg, el_deg):
    return fast.feed_position(fast.source_direction(math.radians(az_deg), math.radians(el_deg)))


def test_switch_is_a_line_to_the_closest_focal_point_then_an_arc():
    p0 = np.array([5.0, -3.0, -150.0])  # inside the focal sphere
    p1 = _on_sphere(200.0, 60.0)
    segments, times = fp.switch_segments(p0, p1)
    line, arc = segments
    ph = fast.closest_focal_point(p0)
    end_line = line.evaluate(np.array([line.duration]))[0][0]
    np.testing.assert_allclose(end_line, ph, atol=1e-9)
    np.testing.assert_allclose(arc.evaluate(np.array([0.0]))[0][0], ph, atol=1e-9)
    np.testing.assert_allclose(arc.evaluate(np.array([arc.duration]))[0][0], p1, atol=1e-6)
    # The arc stays on the focal sphere; both end at rest.
    tau = np.linspace(0, arc.duration, 500)
    pos, vel, _ = arc.evaluate(tau)
    np.testing.assert_allclose(np.linalg.norm(pos, axis=1), fast.FOCAL_SURFACE_RADIUS, rtol=1e-12)
    assert np.linalg.norm(vel[-1]) < 1e-12 and np.linalg.norm(line.evaluate(np.array([0.0]))[1]) < 1e-12


def test_segment_times_follow_eq_10():
    p0 = np.array([0.0, 0.0, -fast.FOCAL_SURFACE_RADIUS + 2.0])
    p1 = _on_sphere(90.0, 52.0)
    times = fp.switch_times(p0, p1)
    assert times.t_line == max(times.t_p_line, times.t_cable_line, times.t_ab_line, times.t_multifeed_line)
    assert times.t_ab_line == pytest.approx(max(times.t_ab - times.t_focal, 0.0))
    ph = fast.closest_focal_point(p0)
    assert times.t_p_line == pytest.approx(prof.min_move_time(2.0, fast.V_S_MAX, fast.A_S_MAX))
    _, arc = fp._arc_between(ph, p1)
    assert times.t_focal == pytest.approx(
        prof.min_move_time(arc, fast.V_S_MAX, fp.tangential_limit(fast.A_S_MAX, fast.V_S_MAX))
    )
    # A slow A-B rotator makes the rotator, not the feed, set T_line: the line is stretched.
    slow = fp.MechanismLimits(ab_rate=math.radians(0.05), ab_accel=math.radians(0.005))
    slow_times = fp.switch_times(p0, p1, mechanisms=slow)
    assert slow_times.t_line == pytest.approx(slow_times.t_ab_line) and slow_times.t_line > times.t_line
    segments, _ = fp.switch_segments(p0, p1, mechanisms=slow)
    assert segments[0].duration == pytest.approx(slow_times.t_line)
    assert segments[0].profile.distance == pytest.approx(2.0)


def test_tangential_limit_keeps_the_arc_acceleration_inside():
    a_t = fp.tangential_limit(fast.A_S_MAX, fast.V_S_MAX)
    assert math.hypot(a_t, fast.V_S_MAX**2 / fast.FOCAL_SURFACE_RADIUS) == pytest.approx(fast.A_S_MAX)
    with pytest.raises(LimitError, match="centripetal"):
        fp.tangential_limit(0.0005, fast.V_S_MAX)


def test_start_and_termination_join_the_observation(switch_plan):
    plan = switch_plan
    names = [s.name for s in plan.segments]
    for k, name in enumerate(names):
        if not name.startswith("observation"):
            continue
        obs, start, stop = plan.segments[k], plan.segments[k - 1], plan.segments[k + 1]
        assert start.name == "start" and stop.name == "termination"
        for a, b in ((start, obs), (obs, stop)):
            pa, va, _ = (x[0] for x in a.evaluate(np.array([a.duration])))
            pb, vb, _ = (x[0] for x in b.evaluate(np.array([0.0])))
            np.testing.assert_allclose(pa, pb, atol=1e-9)
            np.testing.assert_allclose(va, vb, atol=1e-12)
        # From rest / to rest, with one pulse of A_max (Table 1).
        assert np.linalg.norm(start.evaluate(np.array([0.0]))[1]) < 1e-15
        assert np.linalg.norm(stop.evaluate(np.array([stop.duration]))[1]) < 1e-15


def test_whole_plan_at_100_hz(switch_plan):
    """Continuous velocity, every segment's acceleration limit, zenith angle <= 40 deg, all six
    static tensions in [T_min, T_max] at every sample."""
    plan = switch_plan
    t = np.arange(0.0, plan.duration, 0.01)
    s = plan.state(t)
    acc = np.linalg.norm(s.feed_acceleration, axis=1)
    limit = np.array([plan.segments[k].accel_limit for k in s.segment])
    assert np.all(acc <= limit * (1 + 1e-9))
    jump = np.linalg.norm(np.diff(s.feed_velocity, axis=0), axis=1)
    assert jump.max() <= fast.A_S_MAX * 0.01 * (1 + 1e-6)  # no step: at most a_max dt
    assert np.linalg.norm(s.feed_velocity, axis=1).max() <= fast.V_S_MAX * (1 + 1e-12)
    assert np.degrees(s.zenith_angle).max() <= 40.0
    assert s.tension.min() >= plan.limits.tension_min and s.tension.max() <= plan.limits.tension_max
    assert np.all(np.degrees(s.cabin_tilt) <= 14 + 1e-9) and np.all(np.degrees(s.ab_tilt) <= 26.4 + 1e-9)
    plan.check()
    # The derived channels are continuous too: cable rates change by little per tick.
    sample = plan.sample(t[::10])
    cable_rate = sample.velocity[:, 7:]
    assert np.abs(np.diff(cable_rate, axis=0)).max() < 0.01  # m/s per 0.1 s
    # The Stewart legs sit at their nominal lengths in a plan.
    assert np.abs(s.stewart_leg - fast.stewart_leg_lengths()).max() < 1e-12


def test_tracking_follows_the_sky():
    plan = fast_sims.tracking_plan(duration=120.0)
    obs = next(s for s in plan.segments if s.name.startswith("observation"))
    t = obs.t0 + np.linspace(0.0, obs.duration, 50)
    s = plan.state(t)
    # On the focal sphere at the sidereal rate: |v| = r w cos(dec) = 11.8 cos(dec) mm/s.
    np.testing.assert_allclose(np.linalg.norm(s.feed, axis=1), fast.FOCAL_SURFACE_RADIUS, rtol=1e-9)
    dec = fast_sims.SOURCES["3C 286"][1]
    expected = fast.FOCAL_SURFACE_RADIUS * 7.2921150e-5 * math.cos(dec)
    np.testing.assert_allclose(np.linalg.norm(s.feed_velocity, axis=1), expected, rtol=2e-3)


def test_paper_t2_of_eq_20_solves_its_quadratic():
    """Eq. (15)-(20) with Table 1's A_max and A_Smax (mm/s^2), V_asc as printed."""
    for v_asc in (0.0, 1.0, 3.0, 5.0):
        out = fp.paper_dec_scan_t2(v_asc)
        a, t3, v_d, t2 = fast.A_S_MAX * 1e3, out["t3_s"], out["V_D_mm_s"], out["t2_s"]
        assert a * t2**2 - (2 * a * t3 + 8 * v_d) * t2 + a * t3**2 == pytest.approx(0.0, abs=1e-6)
        assert out["t3_s"] == pytest.approx(2 * (out["V_m_mm_s"] + out["V_m_inv_mm_s"]) / (fast.A_MAX * 1e3))
        assert t2 > t3
    fits = fp.paper_ra_scan_fits(10.0, 60.0)
    assert fits["V_m_mm_s"] == pytest.approx(0.8 + 2.92 + 10.19)
    assert fits["l_2_mm"] == pytest.approx(0.5 * 60.0 * (-0.71 + 10.68))


def test_source_beyond_40_deg_is_refused():
    with pytest.raises(LimitError, match="zenith angle"):
        fast_sims.tracking_plan(duration=8 * 3600.0)  # 3C 286 is 40 deg down 3.1 h from transit


@pytest.mark.parametrize("build", [fast_sims.ra_scan_plan, fast_sims.dec_scan_plan])
def test_motion_scans_with_transitions(build):
    plan = build()
    names = [s.name for s in plan.segments]
    assert names.count("transition 1") == 1 and names[-1] == "termination"
    plan.check()  # |a| <= A_t-max on transitions, A_max on legs, tensions, zenith angle
    t2 = plan.info["geometric"]["t2_s"]
    transitions = [s for s in plan.segments if s.name.startswith("transition")]
    assert all(s.duration == pytest.approx(t2) and s.accel_limit == fast.A_T_MAX for s in transitions)
    peaks = plan.info["geometric"]["transition_peak_accel_mm_s2"]
    assert max(peaks) <= 15.0 and max(peaks) > 14.0  # the shortest t2: the limit is nearly met
    # Continuous velocity across legs and transitions.
    t = np.arange(0.0, plan.duration, 0.01)
    v = plan.state(t).feed_velocity
    assert np.linalg.norm(np.diff(v, axis=0), axis=1).max() <= fast.A_S_MAX * 0.01 * (1 + 1e-6)
    # The paper's empirical values sit beside the geometric ones, of the same order.
    paper, geometric = plan.info["paper_empirical"], plan.info["geometric"]
    assert 0.5 < geometric["V_m_mm_s"] / paper["V_m_mm_s"] < 1.5


def test_shorter_t2_breaks_a_t_max():
    make = fast_sims.task._scan_factory(fast_sims.DEC_SCAN)
    jd1, jd2 = fast_sims.params._transit("3C 286")
    start = (jd1, jd2)
    t2 = fp.minimum_t2(make, start)
    with pytest.raises(LimitError, match="A_t-max 15.0 mm/s"):
        fp.scan_segments(make(t2 - 0.2), start)
    fp.scan_segments(make(t2), start)


def test_multifeed_rotation_follows_the_parallactic_angle_and_stays_c1(switch_plan):
    from planbench.planners.fast import sky as fast_sky

    plan = switch_plan
    t = np.arange(0.0, plan.duration, 0.01)
    s = plan.state(t)
    rate = np.diff(s.multifeed) / 0.01
    limits = fp.MECHANISM_LIMITS
    assert np.abs(rate).max() <= limits.multifeed_rate
    assert np.abs(np.diff(rate)).max() / 0.01 <= limits.multifeed_accel * (1 + 1e-3)
    # On an observation it is the parallactic angle (modulo the beams' 60 deg symmetry).
    obs = next(x for x in plan.segments if x.name.startswith("observation"))
    tt = obs.t0 + np.linspace(0.0, obs.duration, 20)
    st = plan.state(tt)
    az = np.arctan2(st.axis[:, 0], st.axis[:, 1])
    el = np.arcsin(st.axis[:, 2])
    q = fast_sky.parallactic_angle(az, el)
    diff = np.angle(np.exp(1j * (st.multifeed - q) * 6)) / 6  # modulo 60 deg
    assert np.abs(diff).max() < 1e-4


def test_eq10_includes_the_multifeed_rotation():
    p0 = np.array([0.0, 0.0, -fast.FOCAL_SURFACE_RADIUS + 2.0])
    p1 = _on_sphere(90.0, 80.0)
    times = fp.switch_times(p0, p1, multifeed0=0.0, multifeed1=math.radians(170.0))
    assert times.t_multifeed == pytest.approx(
        prof.min_move_time(math.radians(170.0), fp.MECHANISM_LIMITS.multifeed_rate, fp.MECHANISM_LIMITS.multifeed_accel)
    )
    assert times.t_line == pytest.approx(times.t_multifeed - times.t_focal)  # the rotator is the slowest
