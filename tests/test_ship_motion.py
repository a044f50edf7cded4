"""Ship motion (sims/antenna/ship_motion.py): attitude kinematics, the paper's motion (ship-antenna paper,
eq. 15-16), the JONSWAP spectrum, the RAOs and the sea-state motion."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy import integrate
from scipy.spatial.transform import Rotation

from planbench.antenna.ship_motion import (
    AXES,
    HEADING,
    HEAVE,
    PITCH,
    ROLL,
    PaperShipMotion,
    SeaStateMotion,
    ShipMotionError,
    ShipState,
    VesselRAO,
    body_angular_velocity,
    encounter_frequency,
    jonswap_normalization,
    jonswap_spectrum,
    world_from_ship,
)
from planbench.planners.errors import PlanningError

angle = st.floats(-2 * np.pi, 2 * np.pi, allow_nan=False)


def _vee(m):
    """The vector of a skew-symmetric (n, 3, 3) matrix."""
    return np.stack([m[:, 2, 1] - m[:, 1, 2], m[:, 0, 2] - m[:, 2, 0], m[:, 1, 0] - m[:, 0, 1]], axis=-1) / 2.0


def _gyro_by_finite_differences(motion, t, h=1e-5):
    """omega from skew(omega) = eTb^T d(eTb)/dt, d/dt by central differences."""
    r = motion.sample(t).world_from_ship()
    dr = (motion.sample(t + h).world_from_ship() - motion.sample(t - h).world_from_ship()) / (2 * h)
    return _vee(np.einsum("nji,njk->nik", r, dr))


def _sea(seed=0, **kw):
    kw = {"hs": 5.0, "tp": 10.0, "heading_deg": 135.0, **kw}
    return SeaStateMotion(rng=np.random.default_rng(seed), **kw)


# ---- attitude kinematics --------------------------------------------------------------------


@given(angle, angle, angle)
def test_world_from_ship_is_scipy_intrinsic_zxy(psi, phi, gamma):
    expected = Rotation.from_euler("ZXY", [psi, phi, gamma]).as_matrix()
    np.testing.assert_allclose(world_from_ship(psi, phi, gamma)[0], expected, atol=1e-12)


def test_world_from_ship_vectorized_and_conventions():
    rng = np.random.default_rng(1)
    a = rng.uniform(-np.pi, np.pi, (3, 50))
    r = world_from_ship(*a)
    assert r.shape == (50, 3, 3)
    np.testing.assert_allclose(r, Rotation.from_euler("ZXY", a.T).as_matrix(), atol=1e-12)
    # The paper's bTe (eq. 1): Ry(gamma)^T Rx(phi)^T Rz(psi)^T as printed, = eTb^T.
    psi, phi, gam = a[:, 0]
    c, s = np.cos, np.sin
    ry_t = np.array([[c(gam), 0, -s(gam)], [0, 1, 0], [s(gam), 0, c(gam)]])
    rx_t = np.array([[1, 0, 0], [0, c(phi), s(phi)], [0, -s(phi), c(phi)]])
    rz_t = np.array([[c(psi), s(psi), 0], [-s(psi), c(psi), 0], [0, 0, 1]])
    np.testing.assert_allclose(ry_t @ rx_t @ rz_t, r[0].T, atol=1e-12)
    bow = np.array([0.0, 1.0, 0.0])
    # psi is counter-clockwise: +90 deg turns the bow from north to west.
    np.testing.assert_allclose(world_from_ship(np.pi / 2, 0, 0)[0] @ bow, [-1, 0, 0], atol=1e-15)
    # Positive pitch lifts the bow; positive roll lowers starboard (the mast leans to +X).
    assert (world_from_ship(0, 0.1, 0)[0] @ bow)[2] > 0
    assert (world_from_ship(0, 0, 0.1)[0] @ [0, 0, 1])[0] > 0
    assert (world_from_ship(0, 0, 0.1)[0] @ [1, 0, 0])[2] < 0


def test_body_angular_velocity_matches_finite_differences_of_attitude():
    t = np.linspace(0.0, 300.0, 37)
    for motion in (PaperShipMotion(), _sea(3, course_deg=30.0, speed=6.0)):
        gyro = motion.sample(t).body_angular_velocity()
        np.testing.assert_allclose(gyro, _gyro_by_finite_differences(motion, t), rtol=0, atol=1e-8 * np.abs(gyro).max())


@given(angle, angle, angle, angle, angle, angle)
def test_body_angular_velocity_of_constant_rates(psi, phi, gam, dpsi, dphi, dgam):
    # Angles moving at constant rates over +-h: compare with the same finite difference.
    h = 1e-6
    rates = np.array([dpsi, dphi, dgam])
    angles = np.array([psi, phi, gam])
    r0 = world_from_ship(*angles)[0]
    dr = world_from_ship(*(angles + h * rates))[0] - world_from_ship(*(angles - h * rates))[0]
    expected = _vee((r0.T @ dr / (2 * h))[None])[0]
    got = body_angular_velocity(psi, phi, gam, dpsi, dphi, dgam)[0]
    np.testing.assert_allclose(got, expected, atol=1e-7 * (1 + np.abs(rates).max()))


def test_ship_state_joint_arrays_in_deck_joint_order():
    state = PaperShipMotion().sample(np.array([0.7, 2.0, 3.1]))
    pos, vel, acc = state.joint_arrays()
    assert AXES == ("heave", "heading", "pitch", "roll")
    assert pos.shape == vel.shape == acc.shape == (3, 4)
    np.testing.assert_array_equal(pos[:, HEAVE], state.heave)
    np.testing.assert_array_equal(pos[:, HEADING], state.heading)
    np.testing.assert_array_equal(pos[:, PITCH], state.pitch)
    np.testing.assert_array_equal(pos[:, ROLL], state.roll)
    assert len(state) == 3
    with pytest.raises(ShipMotionError, match=r"rate has shape \(3, 3\)"):
        ShipState(
            t=state.t,
            heave=state.heave,
            heading=state.heading,
            pitch=state.pitch,
            roll=state.roll,
            rate=vel[:, :3],
            accel=acc,
        )


# ---- the paper's motion (eq. 15-16) ---------------------------------------------------------


def test_paper_motion_is_eq_15_16_with_t_as_sample_count():
    s = np.array([0.0, 1.0, 137.0, 12345.0, 29999.0])  # sample counts
    state = PaperShipMotion().sample(s * 0.01)
    psi = 40 * np.sin(2 * np.pi / 30000 * s) + 0.01 * s
    phi = 40 * np.sin(2 * np.pi / 800 * s)
    gamma = 45 * np.sin(2 * np.pi / 1000 * s)
    np.testing.assert_allclose(np.degrees(state.heading), psi, atol=1e-10)
    np.testing.assert_allclose(np.degrees(state.pitch), phi, atol=1e-10)
    np.testing.assert_allclose(np.degrees(state.roll), gamma, atol=1e-10)
    np.testing.assert_array_equal(state.heave, 0.0)


def test_paper_motion_periods_and_turn_rate():
    m = PaperShipMotion()
    t = np.linspace(0.0, 20.0, 201)
    a, b8, b10, half8 = m.sample(t), m.sample(t + 8.0), m.sample(t + 10.0), m.sample(t + 4.0)
    np.testing.assert_allclose(b8.pitch, a.pitch, atol=1e-12)  # pitch: 8 s
    np.testing.assert_allclose(half8.pitch, -a.pitch, atol=1e-12)  # and not 4 s
    np.testing.assert_allclose(b10.roll, a.roll, atol=1e-12)  # roll: 10 s
    np.testing.assert_allclose(m.sample(t + 5.0).roll, -a.roll, atol=1e-12)
    assert m.periods() == pytest.approx({"heading": 300.0, "pitch": 8.0, "roll": 10.0})
    # Heading: 300 s oscillation on a 1 deg/s turn; over whole periods the mean rate is 1 deg/s.
    c = m.sample(t + 300.0)
    np.testing.assert_allclose(np.degrees(c.heading - a.heading), 300.0, atol=1e-9)
    rate = m.sample(np.linspace(0, 300, 30001)).rate[:-1, HEADING]
    assert np.degrees(rate.mean()) == pytest.approx(1.0, abs=1e-9)
    assert np.degrees(np.ptp(m.sample(np.linspace(0, 8, 801)).pitch)) == pytest.approx(80.0)


@pytest.mark.parametrize("motion", [PaperShipMotion(), PaperShipMotion(0.02)])
def test_paper_motion_derivatives_match_finite_differences(motion):
    t, h = np.linspace(0.0, 600.0, 97), 1e-4
    s, lo, hi = motion.sample(t), motion.sample(t - h), motion.sample(t + h)
    np.testing.assert_allclose(s.rate, (hi.position - lo.position) / (2 * h), atol=1e-7)
    np.testing.assert_allclose(s.accel, (hi.rate - lo.rate) / (2 * h), atol=1e-7)


# ---- JONSWAP --------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "hs, tp, gamma", [(1.0, 6.0, 1.0), (5.0, 10.0, 3.3), (2.5, 8.0, 2.0), (9.0, 14.0, 7.0), (0.3, 3.0, 1.5)]
)
def test_jonswap_variance_is_hs2_over_16_and_peak_at_omega_p(hs, tp, gamma):
    wp = 2 * np.pi / tp

    def f(w):
        return float(jonswap_spectrum(w, hs, tp, gamma))

    m0 = sum(
        integrate.quad(f, a * wp, b * wp, epsrel=1e-11, limit=200)[0]
        for a, b in ((0.2, 1.0), (1.0, 4.0), (4.0, np.inf))
    )
    assert m0 == pytest.approx(hs**2 / 16, rel=1e-8)
    assert 4 * np.sqrt(m0) == pytest.approx(hs, rel=1e-8)
    w = np.linspace(0.5 * wp, 2.0 * wp, 30001)
    assert w[np.argmax(jonswap_spectrum(w, hs, tp, gamma))] == pytest.approx(wp, rel=2e-3)


def test_jonswap_is_pierson_moskowitz_times_peak_enhancement():
    hs, tp = 4.0, 9.0
    wp = 2 * np.pi / tp
    w = np.linspace(0.3, 3.0, 500)
    pm = 5 / 16 * hs**2 * wp**4 * w**-5 * np.exp(-1.25 * (wp / w) ** 4)
    np.testing.assert_allclose(jonswap_spectrum(w, hs, tp, 1.0), pm, rtol=1e-12)
    sigma = np.where(w <= wp, 0.07, 0.09)
    enhancement = 3.3 ** np.exp(-((w - wp) ** 2) / (2 * sigma**2 * wp**2))
    np.testing.assert_allclose(
        jonswap_spectrum(w, hs, tp, 3.3), jonswap_normalization(3.3) * pm * enhancement, rtol=1e-12
    )
    assert jonswap_spectrum(0.0, hs, tp) == 0.0


@pytest.mark.parametrize("gamma, dnv_error", [(1.0, 0.0), (2.0, -0.0022), (3.3, 0.0024), (7.0, -0.0175)])
def test_jonswap_normalization_against_dnv_fit(gamma, dnv_error):
    # The docstring's numbers: DNV's A_gamma = 1 - 0.287 ln(gamma) against the exact factor.
    dnv = 1 - 0.287 * np.log(gamma)
    assert dnv / jonswap_normalization(gamma) - 1 == pytest.approx(dnv_error, abs=5e-4)


def test_wave_elevation_variance_over_three_hours():
    t = np.arange(0.0, 3 * 3600.0, 0.5)  # 3 h at 2 Hz
    for seed, (hs, tp) in enumerate([(5.0, 10.0), (2.0, 7.0)]):
        m = _sea(seed, hs=hs, tp=tp)
        m0 = hs**2 / 16
        assert m.wave_variance() == pytest.approx(m0, rel=0.01)  # the components' sum
        eta = m.wave_elevation(t)
        assert abs(eta.mean()) < 0.01 * hs
        assert np.var(eta) == pytest.approx(m0, rel=0.04)


def test_sea_state_does_not_repeat():
    m = _sea(4)
    edges = m.omega_min + np.arange(m.omega.size + 1) * m.d_omega
    assert np.all((m.omega >= edges[:-1]) & (m.omega <= edges[1:]))
    assert np.std(np.diff(m.omega)) > 0.2 * m.d_omega  # not equally spaced
    # An equally spaced sum would repeat (up to a carrier phase) after 2 pi / d_omega.
    t = np.arange(0.0, 300.0, 0.1)
    period = 2 * np.pi / m.d_omega
    a, b = m.wave_elevation(t), m.wave_elevation(t + period)
    assert abs(np.corrcoef(a, b)[0, 1]) < 0.3
    analytic_a = a + 1j * m._sum(t, m.amplitude[:, None], -np.ones((m.omega.size, 1)))[:, 0]
    analytic_b = b + 1j * m._sum(t + period, m.amplitude[:, None], -np.ones((m.omega.size, 1)))[:, 0]
    coherence = abs(np.vdot(analytic_a, analytic_b)) / np.linalg.norm(analytic_a) / np.linalg.norm(analytic_b)
    assert coherence < 0.3


# ---- RAOs -----------------------------------------------------------------------------------


def test_roll_rao_peaks_at_roll_natural_frequency_and_vanishes_head_and_following():
    v = VesselRAO()
    w = np.linspace(0.05, 2.5, 4901)
    for beta_deg in (90.0, 60.0, 120.0):
        roll = np.abs(v.rao(w, np.radians(beta_deg))[:, ROLL])
        assert w[np.argmax(roll)] == pytest.approx(v.roll_frequency, rel=0.05)
        # Resonant amplification: the peak stands well above the wave slope there.
        k = v.roll_frequency**2 / 9.81
        assert roll.max() > 3 * v.wave_slope_coefficient * k * np.sin(np.radians(beta_deg))
    for beta_deg in (0.0, 180.0, -180.0, 360.0):
        assert np.abs(v.rao(w, np.radians(beta_deg))[:, ROLL]).max() < 1e-12
        assert np.abs(v.rao(w, np.radians(beta_deg))[:, HEADING]).max() < 1e-12
    # Beam seas from starboard and from port roll the ship in opposite senses.
    np.testing.assert_allclose(v.rao(w, np.radians(-90.0))[:, ROLL], -v.rao(w, np.radians(90.0))[:, ROLL], atol=1e-15)


def test_pitch_and_yaw_raos_vanish_in_beam_seas():
    v = VesselRAO()
    w = np.linspace(0.05, 2.5, 500)
    for beta_deg in (90.0, 270.0):
        r = v.rao(w, np.radians(beta_deg))
        assert np.abs(r[:, PITCH]).max() < 1e-12
        assert np.abs(r[:, HEADING]).max() < 1e-12
    assert np.abs(v.rao(w, np.radians(135.0))[:, PITCH]).max() > 0.01  # rad/m
    assert np.abs(v.rao(w, np.radians(135.0))[:, HEADING]).max() > 0.001


@pytest.mark.parametrize("beta_deg", [0.0, 45.0, 90.0, 135.0, 180.0, 250.0])
def test_long_wave_limits_follow_the_water_surface(beta_deg):
    v, beta, w = VesselRAO(), np.radians(beta_deg), 0.002
    k = w**2 / 9.81
    r = v.rao(w, beta)
    assert r[HEAVE] == pytest.approx(1.0, abs=1e-4)
    # Pitch = slope along Y, roll = r x minus the slope along X: 90 deg behind the elevation.
    assert r[PITCH] == pytest.approx(-1j * k * np.cos(beta), rel=1e-3, abs=1e-12)
    assert r[ROLL] == pytest.approx(-1j * v.wave_slope_coefficient * k * np.sin(beta), rel=1e-3, abs=1e-12)
    assert r[HEADING] == pytest.approx(-v.yaw_coefficient * k * np.sin(beta) * np.cos(beta), rel=1e-3, abs=1e-12)
    np.testing.assert_allclose(np.abs(v.rao([1e-4, 1e-3, 0.02], beta)[:, HEAVE]), 1.0, atol=1e-3)


def test_raos_are_finite_with_speed_and_short_waves_are_filtered():
    v = VesselRAO()
    w = np.linspace(0.0, 4.0, 801)
    for beta_deg in range(0, 361, 15):
        for speed in (0.0, 5.0, 10.0):
            assert np.all(np.isfinite(v.rao(w, np.radians(beta_deg), speed)))
    # Waves much shorter than the ship barely move it.
    short = np.abs(v.rao(3.0, np.radians(150.0)))
    assert short[HEAVE] < 0.02 and short[PITCH] < 1e-3 and short[ROLL] < 1e-3
    # Head seas at speed: the ship meets the waves more often.
    assert encounter_frequency(0.6, np.pi, 5.0) == pytest.approx(0.6 + 0.36 * 5 / 9.81)
    m = _sea(heading_deg=180.0, speed=8.0)
    assert np.all(m.omega_e > m.omega)


# ---- sea-state motion -----------------------------------------------------------------------


def test_same_seed_same_motion_different_seed_different():
    t = np.linspace(0.0, 300.0, 3001)
    a, b, c = _sea(7).sample(t), _sea(7).sample(t), _sea(8).sample(t)
    for x, y, z in zip(a.joint_arrays(), b.joint_arrays(), c.joint_arrays(), strict=True):
        np.testing.assert_array_equal(x, y)
        assert np.abs(x - z).max() > 0.1 * np.abs(x).max()
    np.testing.assert_array_equal(_sea(7).wave_elevation(t), _sea(7).wave_elevation(t))


def test_one_wave_drives_every_axis():
    # A swell of long waves only (w <= 0.15 rad/s): the ship follows the surface, so heave is
    # the elevation and pitch / roll are the slopes of the same waves (cot(beta) / r apart).
    # Independent phases per axis would make these records uncorrelated.
    m = _sea(6, hs=1.0, tp=60.0, heading_deg=120.0, omega_min=0.05, omega_max=0.15)
    t = np.arange(0.0, 3000.0, 1.0)
    s = m.sample(t)
    assert np.corrcoef(s.heave, m.wave_elevation(t))[0, 1] > 0.999
    assert np.corrcoef(s.pitch, s.roll)[0, 1] < -0.95  # cos(120 deg) < 0 < sin(120 deg)
    ratio = np.std(s.pitch) / np.std(s.roll)
    assert ratio == pytest.approx(abs(1 / (np.tan(np.radians(120.0)) * 0.8)), abs=0.1)


def test_sea_state_derivatives_match_finite_differences():
    t, h = np.linspace(0.0, 300.0, 61), 1e-4
    for m in (_sea(1), _sea(2, heading_deg=60.0, speed=7.0, course_deg=-40.0, gamma=1.0)):
        s, lo, hi = m.sample(t), m.sample(t - h), m.sample(t + h)
        scale = np.abs(s.rate).max(axis=0)
        np.testing.assert_allclose(s.rate, (hi.position - lo.position) / (2 * h), rtol=0, atol=1e-6 * scale.max())
        np.testing.assert_allclose(s.accel, (hi.rate - lo.rate) / (2 * h), rtol=0, atol=1e-6 * np.abs(s.accel).max())
        assert np.all(scale > 0)


def test_sea_state_scalar_and_blocked_samples_agree():
    m = _sea(5, speed=4.0)
    t = np.linspace(0.0, 300.0, 12001)  # several blocks of (times x components), uniform
    whole = m.sample(t)
    uneven = t.copy()
    uneven[7] += 1e-3  # no longer a uniform grid: the direct sum of cosines
    direct = m.sample(uneven)
    keep = np.arange(t.size) != 7
    for x, y in zip(whole.joint_arrays(), direct.joint_arrays(), strict=True):
        np.testing.assert_allclose(x[keep], y[keep], rtol=0, atol=1e-12 * np.abs(x).max())
    np.testing.assert_allclose(m.wave_elevation(t)[keep], m.wave_elevation(uneven)[keep], rtol=0, atol=1e-12)
    for x, y in zip(direct.joint_arrays(), m.sample(uneven[7]).joint_arrays(), strict=True):
        np.testing.assert_allclose(x[7], y[0], rtol=1e-12, atol=1e-12)
    for i in (0, 4567, 12000):
        one = m.sample(float(t[i]))
        assert len(one) == 1
        for x, y in zip(one.joint_arrays(), whole.joint_arrays(), strict=True):
            np.testing.assert_allclose(x[0], y[i], rtol=1e-12, atol=1e-12)


def test_sea_state_amplitudes_at_hs5_tp10_bow_quartering():
    # The numbers in VesselRAO.rao's docstring.
    m = _sea(0)
    sd = m.standard_deviation()
    assert sd[HEAVE] == pytest.approx(0.78, abs=0.03)
    assert np.degrees(sd[ROLL]) == pytest.approx(2.6, abs=0.15)
    assert np.degrees(sd[PITCH]) == pytest.approx(1.67, abs=0.1)
    assert np.degrees(sd[HEADING]) == pytest.approx(0.44, abs=0.05)
    state = m.sample(np.arange(0.0, 600.0, 0.1))
    assert abs(np.mean(state.heading) - m.course) < 0.3 * sd[HEADING]
    # The record's spread matches the spectral one (long enough for the fast axes).
    assert np.std(state.pitch) == pytest.approx(sd[PITCH], rel=0.25)
    assert np.std(state.heave) == pytest.approx(sd[HEAVE], rel=0.25)


def test_course_shifts_heading_only():
    t = np.linspace(0, 100, 501)
    a, b = _sea(9).sample(t), _sea(9, course_deg=-72.0).sample(t)
    np.testing.assert_allclose(b.heading - a.heading, np.radians(-72.0), atol=1e-12)
    np.testing.assert_array_equal(a.roll, b.roll)
    np.testing.assert_array_equal(a.rate, b.rate)


# ---- bad input ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: _sea(hs=-1.0), r"significant wave height hs = -1 m must be > 0"),
        (lambda: _sea(hs=0.0), r"hs = 0 m must be > 0"),
        (lambda: _sea(hs=float("nan")), r"hs = nan m must be finite"),
        (lambda: _sea(hs=float("inf")), r"hs = inf m must be finite"),
        (lambda: _sea(tp=0.0), r"peak period tp = 0 s must be > 0"),
        (lambda: _sea(tp=-3.0), r"tp = -3 s must be > 0"),
        (lambda: _sea(gamma=0.5), r"gamma = 0.5 must be >= 1"),
        (lambda: _sea(gamma=float("nan")), r"gamma = nan must be >= 1"),
        (lambda: _sea(heading_deg=float("nan")), r"heading_deg = nan deg must be finite"),
        (lambda: _sea(course_deg=float("inf")), r"course_deg = inf deg must be finite"),
        (lambda: _sea(speed=-2.0), r"ship speed = -2 m/s must be >= 0"),
        (lambda: _sea(n_components=0), r"n_components = 0 must be an integer >= 1"),
        (lambda: _sea(n_components=2.5), r"n_components = 2.5 must be an integer >= 1"),
        (lambda: _sea(omega_min=1.0, omega_max=0.5), r"omega_max = 0.5 rad/s must be > omega_min = 1 rad/s"),
        (lambda: _sea(omega_min=-1.0), r"omega_min = -1 rad/s must be > 0"),
        (lambda: _sea().sample([0.0, float("nan")]), r"t\[1\] = nan s must be finite"),
        (lambda: _sea().wave_elevation(float("inf")), r"t\[0\] = inf s must be finite"),
        (lambda: _sea().sample(np.zeros((2, 2))), r"shape \(2, 2\)"),
        (lambda: PaperShipMotion().sample(float("nan")), r"t\[0\] = nan s must be finite"),
        (lambda: PaperShipMotion(sample_time=0.0), r"paper sample time = 0 s must be > 0"),
        (lambda: jonswap_spectrum(1.0, hs=-1.0, tp=10.0), r"hs = -1 m must be > 0"),
        (lambda: jonswap_spectrum(1.0, hs=2.0, tp=10.0, gamma=0.9), r"gamma = 0.9 must be >= 1"),
        (lambda: VesselRAO(length=-100.0), r"vessel length = -100 m must be > 0"),
        (lambda: VesselRAO(roll_period=0.0), r"vessel roll_period = 0 s must be > 0"),
        (lambda: VesselRAO(roll_damping=0.0), r"vessel roll_damping = 0 must be in \(0, 1\]"),
        (lambda: VesselRAO(block_coefficient=1.2), r"vessel block_coefficient = 1.2 must be in \(0, 1\]"),
        (lambda: VesselRAO(yaw_coefficient=-0.1), r"vessel yaw_coefficient = -0.1 must be in \[0, 1\]"),
        (lambda: VesselRAO(draft=float("nan")), r"vessel draft = nan m must be finite"),
    ],
)
def test_bad_input_raises_naming_value_and_limit(make, message):
    with pytest.raises(ShipMotionError, match=message) as info:
        make()
    assert isinstance(info.value, PlanningError) and isinstance(info.value, ValueError)


def test_rng_must_be_a_generator():
    with pytest.raises(TypeError, match="numpy.random.Generator"):
        SeaStateMotion(5.0, 10.0, 135.0, rng=0)


def test_zero_yaw_coefficient_is_allowed():
    m = _sea(vessel=VesselRAO(yaw_coefficient=0.0))
    np.testing.assert_array_equal(m.sample([0.0, 1.0]).heading, m.course)
    assert math.isclose(m.standard_deviation()[HEADING], 0.0)
