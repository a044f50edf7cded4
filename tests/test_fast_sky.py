"""FAST's sky (planners/fast/sky.py): pyerfa's observed az/el against hand spherical
trigonometry, meridian transits, the 40 deg zenith-angle limit (Table 1), the motion scans'
geometry (the paper's section 3.3), horizon rates and bad input.

Two independent checks of ``observed_azel`` (eraAtco13's chain):
* "hand": IAU 1976 precession (Lieske et al. 1977) and GMST (IAU 1982, the continuous form in
  Vallado, Fundamentals of Astrodynamics, eq. 3-47) written out here; no nutation, no
  aberration, so within ~40 arcsec of the truth (nutation <= 19", annual aberration <= 20.5").
* "cirs": the apparent (CIRS) place from erfa.atci13 as input, the Earth rotation angle
  (IAU 2000 closed form) written out here; within ~1 arcsec (diurnal aberration, polar motion).
Both then use the same spherical trigonometry: H = LST - RA,
sin(el) = sin(lat) sin(dec) + cos(lat) cos(dec) cos(H),
az = atan2(-cos(dec) sin(H), sin(dec) cos(lat) - cos(dec) cos(H) sin(lat)).
"""

import math
import re
import warnings

import erfa
import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from planbench.planners.errors import LimitError, PlanningError
from planbench.planners.fast import sky as fs

DEG = math.pi / 180
ARCSEC = DEG / 3600
LAT, LON = fs.SITE_LATITUDE, fs.SITE_LONGITUDE
W = fs.EARTH_ROTATION_RATE
START_2020 = fs.utc_jd("2020-01-01T00:00:00")
DECADE_S = 11 * 365.25 * 86400.0  # 2020-01-01 .. 2030-12-31

ras = st.floats(0.0, 2 * math.pi, exclude_max=True)
decs = st.floats(-math.pi / 2, math.pi / 2)
decade_seconds = st.floats(0.0, DECADE_S)


# ----------------------------------------------------------------------------- hand astronomy


def _quiet():
    ctx = warnings.catch_warnings()
    ctx.__enter__()
    warnings.filterwarnings("ignore", category=erfa.ErfaWarning)
    return ctx


def _horizon(ha, dec, lat=LAT):
    """Spherical trigonometry: hour angle and declination -> (az, el), rad."""
    el = np.arcsin(np.sin(lat) * np.sin(dec) + np.cos(lat) * np.cos(dec) * np.cos(ha))
    az = np.arctan2(-np.cos(dec) * np.sin(ha), np.sin(dec) * np.cos(lat) - np.cos(dec) * np.cos(ha) * np.sin(lat))
    return np.mod(az, 2 * np.pi), el


def _tt_days(jd1, jd2):
    """TT - J2000 in days from UTC: TT = UTC + 37 s + 32.184 s (leap seconds since 2017)."""
    return (jd1 - 2451545.0) + jd2 + 69.184 / 86400.0


def _precession_1976(t_tt):
    """IAU 1976 precession matrix (mean J2000 -> mean of date), passive rotations; Lieske 1977:
    P = R3(-z) R2(theta) R3(-zeta)."""
    t = np.asarray(t_tt, dtype=float)[..., None, None]
    zeta = (2306.2181 + (0.30188 + 0.017998 * t) * t) * t * ARCSEC
    z = (2306.2181 + (1.09468 + 0.018203 * t) * t) * t * ARCSEC
    theta = (2004.3109 + (-0.42665 - 0.041833 * t) * t) * t * ARCSEC

    def r3(a):
        c, s, o, i = np.cos(a), np.sin(a), np.zeros_like(a), np.ones_like(a)
        return np.concatenate(
            [np.concatenate([c, s, o], -1), np.concatenate([-s, c, o], -1), np.concatenate([o, o, i], -1)], -2
        )

    def r2(a):
        c, s, o, i = np.cos(a), np.sin(a), np.zeros_like(a), np.ones_like(a)
        return np.concatenate(
            [np.concatenate([c, o, -s], -1), np.concatenate([o, i, o], -1), np.concatenate([s, o, c], -1)], -2
        )

    return r3(-z) @ r2(theta) @ r3(-zeta)


def _gmst_1982(jd1, jd2):
    """GMST (IAU 1982, continuous in UT1 = UTC), rad."""
    tu = ((jd1 - 2451545.0) + jd2) / 36525.0
    seconds = 67310.54841 + (876600.0 * 3600.0 + 8640184.812866) * tu + 0.093104 * tu**2 - 6.2e-6 * tu**3
    return np.mod(seconds, 86400.0) / 86400.0 * 2 * np.pi


def _era(jd1, jd2):
    """Earth rotation angle (IAU 2000), UT1 = UTC, rad."""
    tu = (jd1 - 2451545.0) + jd2
    frac = np.mod(jd1, 1.0) + np.mod(jd2, 1.0)
    return np.mod(2 * np.pi * (frac + 0.7790572732640 + 0.00273781191135448 * tu), 2 * np.pi)


def hand_azel(ra, dec, jd1, jd2):
    """Mean place of date by IAU 1976 precession, GMST 1982, spherical trig."""
    v = np.stack(np.broadcast_arrays(np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)), -1)
    p = _precession_1976(_tt_days(jd1, jd2) / 36525.0)
    v = np.einsum("...ij,...j->...i", p, v)
    ra_d, dec_d = np.arctan2(v[..., 1], v[..., 0]), np.arcsin(np.clip(v[..., 2], -1, 1))
    return _horizon(_gmst_1982(jd1, jd2) + LON - ra_d, dec_d)


def cirs_azel(ra, dec, jd1, jd2):
    """erfa's apparent (CIRS) place as input, ERA by hand, spherical trig."""
    ctx = _quiet()
    try:
        tai1, tai2 = erfa.utctai(jd1, jd2)
        tt1, tt2 = erfa.taitt(tai1, tai2)
        ri, di, _ = erfa.atci13(ra, dec, 0.0, 0.0, 0.0, 0.0, tt1, tt2)
    finally:
        ctx.__exit__(None, None, None)
    return _horizon(_era(jd1, jd2) + LON - ri, di)


def separation(az1, el1, az2, el2):
    """Great-circle angle between two horizon directions, rad."""
    a = np.stack([np.cos(el1) * np.sin(az1), np.cos(el1) * np.cos(az1), np.sin(el1)], -1)
    b = np.stack([np.cos(el2) * np.sin(az2), np.cos(el2) * np.cos(az2), np.sin(el2)], -1)
    return 2 * np.arcsin(np.minimum(np.linalg.norm(a - b, axis=-1) / 2, 1.0))


def test_hand_precession_matches_erfa_pmat76():
    for t in (-0.3, 0.2, 0.31):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            expected = erfa.pmat76(2451545.0, t * 36525.0)
        np.testing.assert_allclose(_precession_1976(t), expected, atol=1e-12)


# ----------------------------------------------------------------------------- erfa vs hand


@given(ras, decs, decade_seconds)
def test_observed_azel_agrees_with_hand_spherical_trig_within_1_arcmin(ra, dec, seconds):
    jd1, jd2 = fs.utc_jd(START_2020, seconds)
    az, el = fs.observed_azel(ra, dec, (jd1, jd2))
    assume(el > 10 * DEG)
    az_h, el_h = hand_azel(ra, dec, jd1, jd2)
    assert separation(az, el, az_h, el_h) < 60 * ARCSEC
    az_c, el_c = cirs_azel(ra, dec, jd1, jd2)
    assert separation(az, el, az_c, el_c) < 1 * ARCSEC


def test_observed_azel_agrees_with_hand_over_the_decade_dense():
    rng = np.random.default_rng(1)
    seconds = rng.uniform(0, DECADE_S, (200, 1))  # 200 times x 100 sources
    ra = rng.uniform(0, 2 * np.pi, 100)
    dec = np.arcsin(rng.uniform(-1, 1, 100))
    jd1, jd2 = fs.utc_jd(START_2020, seconds)
    az, el = fs.observed_azel(ra, dec, (jd1, jd2))
    assert az.shape == (200, 100)
    up = el > 10 * DEG
    assert up.sum() > 6000
    sep_hand = separation(az, el, *hand_azel(ra, dec, jd1, jd2))[up]
    sep_cirs = separation(az, el, *cirs_azel(ra, dec, jd1, jd2))[up]
    assert sep_hand.max() < 60 * ARCSEC
    assert sep_cirs.max() < 1 * ARCSEC
    # The hand chain leaves out nutation and aberration, so it must differ by more than
    # rounding: a test of the test.
    assert sep_hand.max() > 10 * ARCSEC


def test_fast_path_matches_atco13_per_sample():
    rng = np.random.default_rng(2)
    n = 3000
    ra, dec = rng.uniform(0, 2 * np.pi, n), np.arcsin(rng.uniform(-1, 1, n))
    jd = fs.utc_jd(START_2020, rng.uniform(0, DECADE_S, n))
    az, el = fs.observed_azel(ra, dec, jd)
    az_x, el_x = fs.observed_azel(ra, dec, jd, exact=True)
    assert separation(az, el, az_x, el_x).max() < 0.05 * ARCSEC


def test_fast_path_is_continuous_across_the_hourly_astrometry():
    jd1, jd2 = fs.meridian_transit(2.0, 0.3, "2027-09-01T00:00:00")
    hours = ((jd1 - 2451545.0) + jd2) * 24.0
    boundary = jd2 + (np.ceil(hours) - hours) / 24.0  # the next whole hour
    t = np.arange(-1.0, 1.0, 0.005)  # 200 Hz across it
    rates = fs.horizon_rates(t, *fs.observed_azel(2.0, 0.3, (jd1, boundary + t / 86400.0)))
    assert np.ptp(rates.angular_speed) < 1e-5 * rates.angular_speed.mean()


# ----------------------------------------------------------------------------- times and shapes


def test_utc_jd_of_j2000_and_offsets():
    jd1, jd2 = fs.utc_jd("2000-01-01T12:00:00Z", [0.0, 86400.0, -43200.0])
    np.testing.assert_allclose(jd1 + jd2, [2451545.0, 2451546.0, 2451544.5], rtol=0, atol=1e-9)
    assert fs.jd_to_iso(*fs.utc_jd("2027-03-04T05:06:07.25", 0.0)) == "2027-03-04T05:06:07.250Z"


def test_utc_forms_agree_and_vectorize():
    iso = ["2024-02-29T23:59:30", "2025-06-01T12:00:00", "2029-12-31T06:30:00.5"]
    dt = np.array(iso, dtype="datetime64[ms]")
    ra = np.array([[0.1], [2.0], [4.5], [6.0]])  # 4 sources x 3 times
    az1, el1 = fs.observed_azel(ra, 0.4, dt)
    az2, el2 = fs.observed_azel(ra, 0.4, [s + "Z" for s in iso])
    az3, el3 = fs.observed_azel(ra, 0.4, fs.utc_jd(dt))
    assert az1.shape == el1.shape == (4, 3)
    np.testing.assert_array_equal(np.stack([az1, el1]), np.stack([az2, el2]))
    np.testing.assert_allclose(np.stack([az1, el1]), np.stack([az3, el3]), rtol=0, atol=1e-12)
    for i in range(4):
        for j in range(3):
            a, e = fs.observed_azel(float(ra[i, 0]), 0.4, iso[j])
            assert (float(a), float(e)) == pytest.approx((az1[i, j], el1[i, j]), abs=1e-12)
    # the exact chain broadcasts the same way
    assert fs.observed_azel(ra, 0.4, dt, exact=True)[0].shape == (4, 3)


@given(st.floats(0, 2 * math.pi, exclude_max=True), st.floats(5 * DEG, 89.9 * DEG), decade_seconds)
def test_sky_position_inverts_observed_azel(az, el, seconds):
    jd = fs.utc_jd(START_2020, seconds)
    ra, dec = fs.sky_position(az, el, jd)
    az2, el2 = fs.observed_azel(ra, dec, jd)
    assert separation(az, el, az2, el2) < 1e-3 * ARCSEC


# ----------------------------------------------------------------------------- meridian transit


@given(ras, st.floats(-60 * DEG, 85 * DEG), decade_seconds)
def test_source_transits_the_meridian_at_maximum_elevation(ra, dec, seconds):
    assume(abs(dec - LAT) > 1 * DEG)
    near = fs.utc_jd(START_2020, seconds)
    jd1, jd2 = fs.meridian_transit(ra, dec, near)
    assert abs((jd1 + jd2) - (near[0] + near[1])) <= 0.51  # the nearest, within half a day
    az, el = fs.observed_azel(ra, dec, (jd1, jd2))
    # due south below the zenith's declination, due north above it
    expected_az = math.pi if dec < LAT else 0.0
    assert abs(math.remainder(float(az) - expected_az, 2 * math.pi)) < 1e-6
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tt = erfa.taitt(*erfa.utctai(jd1, jd2))
        _, dec_apparent, _ = erfa.atci13(ra, dec, 0.0, 0.0, 0.0, 0.0, *tt)
    assert float(el) == pytest.approx(math.pi / 2 - abs(LAT - dec_apparent), abs=1 * ARCSEC)
    # the maximum: sampled every 0.5 s for +/- 2 min, and far around
    t = np.arange(-120.0, 120.01, 0.5)
    _, els = fs.observed_azel(ra, dec, (jd1, jd2 + t / 86400.0))
    assert abs(t[np.argmax(els)]) <= 5.0
    _, far = fs.observed_azel(ra, dec, (jd1, jd2 + np.array([-3600.0, -600.0, 600.0, 3600.0]) / 86400.0))
    assert np.all(far < el)


# ----------------------------------------------------------------------------- zenith-angle limit


def _transit(dec=LAT, ra=1.0):
    return fs.meridian_transit(ra, dec, "2026-03-20T00:00:00")


def test_tracking_through_the_zenith_stays_within_40_deg():
    jd1, jd2 = _transit()
    path = fs.track(1.0, LAT, (jd1, jd2 - 3600.0 / 86400.0), 7200.0, step=10.0)
    assert path.zenith_angle.min() < 0.1 * DEG
    assert path.zenith_angle.max() < 16 * DEG
    assert path.t[0] == 0.0 and path.t[-1] == 7200.0 and path.t.size == 721
    assert path.on_leg.all() and (path.leg == 0).all()


def test_zenith_angle_limit_names_the_first_time_and_angle():
    jd1, jd2 = _transit()
    with pytest.raises(LimitError) as info:
        fs.track(1.0, LAT, (jd1, jd2), 4 * 3600.0, step=10.0)
    message = str(info.value)
    free = fs.track(1.0, LAT, (jd1, jd2), 4 * 3600.0, step=10.0, za_limit=None)
    first = int(np.argmax(free.zenith_angle > 40 * DEG))
    assert first > 0 and free.zenith_angle[first - 1] <= 40 * DEG
    match = re.search(r"zenith angle ([\d.]+) deg at (\S+) UTC \(([\d.]+) s after the start\)", message)
    assert match, message
    assert float(match.group(1)) == pytest.approx(math.degrees(free.zenith_angle[first]), abs=1e-3)
    assert float(match.group(3)) == pytest.approx(free.t[first])
    assert match.group(2) == fs.jd_to_iso(free.jd1[first], free.jd2[first])
    assert "limit 40.0 deg" in message
    # dec = lat: cos(ZA) = sin^2(lat) + cos^2(lat) cos(H) gives ZA = 40 deg at H ~ 2.9 h
    h = math.acos((math.cos(40 * DEG) - math.sin(LAT) ** 2) / math.cos(LAT) ** 2)
    assert free.t[first] == pytest.approx(h / W, abs=60.0)


def test_a_source_far_from_the_zenith_is_refused_at_the_start():
    jd1, jd2 = _transit(dec=LAT + 41 * DEG)
    with pytest.raises(LimitError, match=r"zenith angle 41\.\d+ deg at .* \(0\.0 s after the start\)"):
        fs.track(1.0, LAT + 41 * DEG, (jd1, jd2), 600.0)
    with pytest.raises(LimitError, match=r"parked beam .* zenith angle 45\.000 deg"):
        fs.drift_scan(0.0, 45 * DEG, "2026-01-01T00:00:00", 60.0)


# ----------------------------------------------------------------------------- drift scan


def test_drift_scan_sky_moves_at_the_earth_rotation_rate():
    path = fs.drift_scan(3.0, 70 * DEG, "2026-05-05T15:00:00", 1800.0, step=30.0)
    assert np.all(path.az == path.az[0]) and np.all(path.el == 70 * DEG)
    ra_rate = np.diff(np.unwrap(path.ra)) / np.diff(path.t)
    np.testing.assert_allclose(ra_rate, W, rtol=2e-3)
    assert np.ptp(path.dec) < 60 * ARCSEC
    az, el = fs.observed_azel(path.ra, path.dec, (path.jd1, path.jd2))
    assert separation(az, el, path.az, path.el).max() < 1e-3 * ARCSEC


# ----------------------------------------------------------------------------- horizon rates


@given(st.floats(-14 * DEG, 65 * DEG), st.floats(-5000.0, 5000.0))
def test_tracking_rates_match_the_closed_form(dec, offset):
    jd1, jd2 = fs.meridian_transit(2.0, dec, "2027-09-01T00:00:00")
    path = fs.track(2.0, dec, (jd1, jd2 + offset / 86400.0), 600.0, step=20.0, za_limit=None)
    assume(path.zenith_angle.min() > 3 * DEG and path.el.min() > 5 * DEG)
    rates = path.rates()
    _, _, _, dec_obs = fs._observed(2.0, dec, (path.jd1, path.jd2), fs.FAST_SITE, False)
    np.testing.assert_allclose(rates.angular_speed, W * np.cos(dec_obs), rtol=1e-5)
    np.testing.assert_allclose(rates.feed_speed, 162.15 * rates.angular_speed)
    az_rate, el_rate = fs.sidereal_rates(path.az, path.el)
    inner = slice(1, -1)  # central differences
    np.testing.assert_allclose(rates.el_rate[inner], el_rate[inner], atol=1e-4 * W)
    # (the azimuth rate bends fast near the zenith: a looser relative bound for the differences)
    np.testing.assert_allclose(rates.az_rate[inner], az_rate[inner], rtol=1e-3, atol=1e-4 * W)


# ----------------------------------------------------------------------------- motion scans

scan_params = st.fixed_dictionaries(
    {
        "ra": ras,
        "dec": st.floats(-70 * DEG, 70 * DEG),
        "legs_along": st.sampled_from(["dec", "ra"]),
        "leg_length": st.floats(0.05 * DEG, 5 * DEG),
        "n_legs": st.integers(1, 6),
        "leg_spacing": st.floats(0.005 * DEG, 0.5 * DEG) | st.floats(-0.5 * DEG, -0.005 * DEG),
        "speed": st.floats(1.0, 60.0).map(lambda v: v * fs.DEG_PER_HOUR),  # deg/h -> rad/s
        "t2": st.floats(1.0, 300.0),
        "alternate": st.booleans(),
    }
)


def _wrap(a):
    return np.mod(np.asarray(a) + np.pi, 2 * np.pi) - np.pi


@given(scan_params)
@settings(max_examples=150)
def test_motion_scan_geometry(p):
    scan = fs.MotionScan(**p)
    n, T = p["n_legs"], p["leg_length"] / p["speed"]
    assert scan.leg_duration == pytest.approx(T)
    np.testing.assert_allclose(scan.leg_end - scan.leg_start, T)
    np.testing.assert_allclose(scan.leg_start[1:] - scan.leg_end[:-1], p["t2"])
    assert scan.duration == pytest.approx(n * T + (n - 1) * p["t2"])
    assert scan.paper_name.startswith(
        "motion scan along the " + ("right ascension" if p["legs_along"] == "dec" else "declination")
    )
    u = np.linspace(0.0, 1.0, 11)
    legs = []
    for i in range(n):
        t = scan.leg_start[i] + u * T
        ra, dec, on_leg, leg = scan.sky(t)
        assert on_leg.all() and (leg == i).all()
        sense = -1.0 if p["alternate"] and i % 2 else 1.0
        if p["legs_along"] == "dec":
            # along Dec: RA fixed, Dec changes by V_dec dt
            np.testing.assert_allclose(_wrap(ra - ra[0]), 0.0, atol=1e-12)
            np.testing.assert_allclose(dec - dec[0], sense * p["speed"] * (t - t[0]), atol=1e-12)
            legs.append((ra[0], dec.mean()))
        else:
            # along RA: Dec fixed, RA changes by speed / cos(dec) dt
            np.testing.assert_allclose(dec, dec[0], atol=1e-15)
            np.testing.assert_allclose(_wrap(ra - ra[0]) * np.cos(dec[0]), sense * p["speed"] * (t - t[0]), atol=1e-11)
            legs.append((_wrap(ra[5] - p["ra"]) + p["ra"], dec[0]))
            # on-sky (great-circle) speed over 1 s
            r1, d1, _, _ = scan.sky(t[5] + np.array([0.0, 1.0]))
            step = separation(r1[0], d1[0], r1[1], d1[1])  # (ra, dec) as (az, el): same geometry
            assert step == pytest.approx(p["speed"], rel=1e-6)
        assert separation(ra[0], dec[0], ra[-1], dec[-1]) == pytest.approx(p["leg_length"], rel=0.02)
    legs = np.array(legs)
    # legs spaced as asked, centred on the centre
    if p["legs_along"] == "dec":
        spacing = _wrap(np.diff(legs[:, 0])) * math.cos(p["dec"])
        np.testing.assert_allclose(legs[:, 1], p["dec"], atol=1e-12)
        assert abs(_wrap(legs[:, 0] - p["ra"]).mean()) < 1e-9
    else:
        spacing = np.diff(legs[:, 1])
        np.testing.assert_allclose(_wrap(legs[:, 0] - p["ra"]), 0.0, atol=1e-9)
        assert legs[:, 1].mean() == pytest.approx(p["dec"], abs=1e-12)
    np.testing.assert_allclose(spacing, p["leg_spacing"], rtol=1e-9, atol=1e-13)
    # transitions: flagged, numbered by the leg before, straight from one leg's end to the next start
    for i in range(n - 1):
        t = scan.leg_end[i] + np.array([0.25, 0.5, 0.75]) * p["t2"]
        ra, dec, on_leg, leg = scan.sky(t)
        assert not on_leg.any() and (leg == i).all()
        ra_a, dec_a, _, _ = scan.sky(scan.leg_end[i])
        ra_b, dec_b, on_b, leg_b = scan.sky(scan.leg_start[i + 1])
        assert on_b and leg_b == i + 1
        np.testing.assert_allclose(dec, dec_a + np.array([0.25, 0.5, 0.75]) * (dec_b - dec_a), atol=1e-12)
        np.testing.assert_allclose(_wrap(ra - ra_a), np.array([0.25, 0.5, 0.75]) * _wrap(ra_b - ra_a), atol=1e-12)


def test_motion_scan_path_in_the_horizon_frame():
    ra, dec = 3.0, 20 * DEG
    jd1, jd2 = fs.meridian_transit(ra, dec, "2026-10-10T00:00:00")
    scan = fs.MotionScan(ra, dec, "dec", 1.0 * DEG, 4, 0.05 * DEG, 20 * fs.DEG_PER_HOUR, 40.0)
    path = scan.path((jd1, jd2 - scan.duration / 2 / 86400.0), step=7.0)
    assert np.isin(scan.leg_start, path.t).all() and np.isin(scan.leg_end, path.t).all()
    assert path.t[-1] == pytest.approx(scan.duration)
    assert path.on_leg.sum() > 0 and (~path.on_leg).sum() > 0
    inside = np.zeros_like(path.on_leg)
    for a, b in zip(scan.leg_start, scan.leg_end, strict=True):
        inside |= (path.t >= a) & (path.t <= b)
    np.testing.assert_array_equal(path.on_leg, inside)
    az, el = fs.observed_azel(path.ra, path.dec, (path.jd1, path.jd2))
    np.testing.assert_array_equal(np.stack([az, el]), np.stack([path.az, path.el]))
    rates = path.rates()
    assert rates.angular_speed.shape == path.t.shape and np.all(np.isfinite(rates.angular_speed))
    # along Dec at 20 deg/h while the Earth turns: the direction's speed is the vector sum of
    # the sidereal motion W cos(dec) and the scan speed (at right angles on the sky)
    mid = (path.t > scan.leg_start[0] + 20) & (path.t < scan.leg_end[0] - 20)
    expected = math.hypot(W * math.cos(dec), 20 * fs.DEG_PER_HOUR)
    np.testing.assert_allclose(rates.angular_speed[mid], expected, rtol=2e-3)
    # started 2.8 h after the transit (zenith angle ~39 deg) the raster sets below 40 deg
    with pytest.raises(LimitError) as info:
        scan.path((jd1, jd2 + 2.8 / 24), step=7.0)
    match = re.search(
        r"motion scan along the right ascension direction centred .* "
        r"zenith angle 40\.0\d\d deg .* \((\d+\.\d) s after the start\)",
        str(info.value),
    )
    assert match, str(info.value)
    assert 0.0 < float(match.group(1)) < scan.duration


# ----------------------------------------------------------------------------- bad input

T0 = "2026-01-01T00:00:00"
GOOD_SCAN = {
    "ra": 1.0,
    "dec": 0.3,
    "legs_along": "dec",
    "leg_length": 0.02,
    "n_legs": 3,
    "leg_spacing": 0.001,
    "speed": 1e-4,
    "t2": 30.0,
}


@pytest.mark.parametrize(
    "call, text",
    [
        (lambda: fs.observed_azel(float("nan"), 0.0, T0), "right ascension nan rad must be finite"),
        (lambda: fs.observed_azel(0.0, 91 * DEG, T0), "declination 91 deg is beyond +/-90 deg"),
        (lambda: fs.observed_azel(0.0, -1.7, T0), "declination -97.4028 deg is beyond +/-90 deg"),
        (lambda: fs.observed_azel(0.0, float("nan"), T0), "declination nan rad must be finite"),
        (lambda: fs.observed_azel(0.0, 0.0, "yesterday"), "UTC time 'yesterday' is not an ISO 8601 date"),
        (lambda: fs.observed_azel(0.0, 0.0, np.datetime64("NaT")), "NaT"),
        (lambda: fs.observed_azel(0.0, 0.0, (2461000.5, float("nan"))), "UTC jd2 nan d must be finite"),
        (lambda: fs.track(0.0, 0.0, T0, -5.0), "duration -5.0 s must be > 0"),
        (lambda: fs.track(0.0, 0.0, T0, 60.0, step=0.0), "step 0.0 s must be > 0"),
        (lambda: fs.track(0.0, 0.0, T0, 1e9, step=1.0), "gives 1e+09 samples; the limit is 2000000"),
        (lambda: fs.track(0.0, 0.0, T0, 1e9, step=1e-320), "gives inf samples"),
        (lambda: fs.drift_scan(0.0, 95 * DEG, T0, 60.0), "elevation 95 deg is beyond +/-90 deg"),
        (lambda: fs.MotionScan(**{**GOOD_SCAN, "speed": 0.0}), "scan speed 0.0 rad/s must be > 0"),
        (lambda: fs.MotionScan(**{**GOOD_SCAN, "speed": -1e-4}), "scan speed -0.0001 rad/s must be > 0"),
        (lambda: fs.MotionScan(**{**GOOD_SCAN, "speed": float("nan")}), "scan speed nan rad/s must be finite"),
        (lambda: fs.MotionScan(**{**GOOD_SCAN, "leg_length": -0.1}), "leg length -0.1 rad must be > 0"),
        (lambda: fs.MotionScan(**{**GOOD_SCAN, "n_legs": 0}), "number of legs 0 must be an integer >= 1"),
        (lambda: fs.MotionScan(**{**GOOD_SCAN, "n_legs": 2.5}), "number of legs 2.5"),
        (lambda: fs.MotionScan(**{**GOOD_SCAN, "t2": -1.0}), "transition time t2 -1.0 s must be >= 0"),
        (lambda: fs.MotionScan(**{**GOOD_SCAN, "t2": 0.0}), "transition time t2 0.0 s must be > 0 for 3 legs"),
        (lambda: fs.MotionScan(**{**GOOD_SCAN, "leg_spacing": 0.0}), "leg spacing 0.0 rad must be nonzero"),
        (lambda: fs.MotionScan(**{**GOOD_SCAN, "legs_along": "az"}), "legs_along 'az' is not one of dec, ra"),
        (lambda: fs.MotionScan(**{**GOOD_SCAN, "dec": 89.5 * DEG}), "reaches declination 90.0730 deg"),
        (lambda: fs.MotionScan(**{**GOOD_SCAN, "dec": 100 * DEG}), "declination 100 deg is beyond"),
        (lambda: fs.MotionScan(**GOOD_SCAN).sky([-1.0]), "time -1.0 s is outside the scan"),
        (lambda: fs.MotionScan(**GOOD_SCAN).path(T0, step=-2.0), "step -2.0 s must be > 0"),
        (lambda: fs.horizon_rates([0.0, 0.0], [0.0, 0.1], [1.0, 1.0]), "increasing"),
    ],
)
def test_bad_input_names_the_value(call, text):
    with pytest.raises(PlanningError) as info:
        call()
    assert isinstance(info.value, ValueError)
    assert text in str(info.value)


def test_site_is_fasts_published_itrf_position():
    """The observatory's ITRF coordinates (-1668557.0, 5506838.0, 2744934.0) m on WGS84."""
    assert math.degrees(fs.FAST_SITE.latitude) == pytest.approx(25.652946, abs=1e-6)
    assert math.degrees(fs.FAST_SITE.longitude) == pytest.approx(106.856666, abs=1e-6)
    assert fs.FAST_SITE.height == pytest.approx(1109.1, abs=0.05)
    back = erfa.gd2gc(1, fs.FAST_SITE.longitude, fs.FAST_SITE.latitude, fs.FAST_SITE.height)
    np.testing.assert_allclose(back, fs.FAST_ITRF_XYZ, atol=1e-6)
    assert fs.SITE_LATITUDE == fs.FAST_SITE.latitude


def _independent_azel(ra, dec, jd1, jd2, dut1):
    """(az, el), rad, by the equinox route from erfa's primitives, not the planner's CIO chain
    (atco13 / apco13 + atciq + atioq): Sun's light deflection (ld), annual + diurnal
    aberration from the observer's barycentric velocity (epv00 + the site's rotation) (ab),
    the IAU 2006/2000A bias-precession-nutation matrix (pnm06a) and Greenwich apparent
    sidereal time (gst06a) to the terrestrial frame, polar motion 0, then the geodetic
    horizon of the published ITRF position. No refraction, as the plan."""
    ctx = _quiet()
    try:
        tai1, tai2 = erfa.utctai(jd1, jd2)
        tt1, tt2 = erfa.taitt(tai1, tai2)
        ut1, ut2 = erfa.utcut1(jd1, jd2, dut1)
        pvh, pvb = erfa.epv00(tt1, tt2)
        rnpb = erfa.pnm06a(tt1, tt2)
        gast = erfa.gst06a(ut1, ut2, tt1, tt2)
    finally:
        ctx.__exit__(None, None, None)
    r_itrs = np.asarray(fs.FAST_ITRF_XYZ, dtype=float)
    omega = fs.EARTH_ROTATION_RATE
    v_itrs = omega * np.array([-r_itrs[1], r_itrs[0], 0.0])  # m/s, the site's rotation
    r3 = erfa.rz(-gast, np.eye(3))  # true-of-date -> terrestrial is R3(gast); its inverse
    to_gcrs = rnpb.T @ r3
    r_obs = to_gcrs @ r_itrs / erfa.DAU
    v_obs = pvb[1] + (to_gcrs @ v_itrs) / erfa.DAU * 86400.0  # au/d
    p_sun = pvh[0] + r_obs  # Sun -> observer, au
    em = np.linalg.norm(p_sun)
    c_au_d = erfa.CMPS * 86400.0 / erfa.DAU
    v = v_obs / c_au_d
    bm1 = math.sqrt(1.0 - v @ v)
    p = erfa.s2c(ra, dec)
    p = erfa.ld(1.0, p, p, p_sun / em, em, 1e-6)
    p = erfa.ab(p, v, em, bm1)
    t = erfa.rz(gast, np.eye(3)) @ rnpb @ p  # GCRS -> terrestrial (polar motion 0)
    lon, lat = fs.FAST_SITE.longitude, fs.FAST_SITE.latitude
    east = np.array([-math.sin(lon), math.cos(lon), 0.0])
    north = np.array([-math.sin(lat) * math.cos(lon), -math.sin(lat) * math.sin(lon), math.cos(lat)])
    up = np.array([math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat)])
    return math.atan2(t @ east, t @ north) % (2 * math.pi), math.asin(t @ up)


@pytest.mark.parametrize("dut1", [0.0, -0.35, 0.8])
def test_plan_agrees_with_an_independent_ephemeris_across_a_transit(dut1):
    """3C 286 tracked for 4 h across its transit (the plan's hourly astrometry and atco13):
    within 0.5 arcsec of the equinox route above on the sky, at the same UT1 - UTC."""
    ra, dec = math.radians(202.784533), math.radians(30.509155)
    transit = fs.meridian_transit(ra, dec, "2026-03-01T00:00:00", dut1=dut1)
    offsets = np.linspace(-2 * 3600.0, 2 * 3600.0, 9)
    jd1, jd2 = fs.utc_jd((float(transit[0]), float(transit[1])), offsets)
    worst = 0.0
    for exact in (False, True):
        az, el = fs.observed_azel(ra, dec, (jd1, jd2), exact=exact, dut1=dut1)
        for i in range(offsets.size):
            az_i, el_i = _independent_azel(ra, dec, float(jd1[i]), float(jd2[i]), dut1)
            sep = erfa.seps(az[i], el[i], az_i, el_i)
            worst = max(worst, sep / ARCSEC)
    assert worst <= 0.5, f"{worst:.3f} arcsec"
    if dut1:  # the parameter reaches the plan: 0 instead is off by about dut1 of rotation
        az0, el0 = fs.observed_azel(ra, dec, (jd1, jd2), dut1=0.0)
        az1, el1 = fs.observed_azel(ra, dec, (jd1, jd2), dut1=dut1)
        shift = erfa.seps(az0, el0, az1, el1) / ARCSEC
        assert np.all(shift > 0.5 * abs(dut1) * 15.0 * math.cos(dec))


@pytest.mark.parametrize("dut1", [0.9, -0.9, 1e9, float("nan")])
def test_ut1_minus_utc_beyond_09_s_is_refused(dut1):
    with pytest.raises(PlanningError, match="UT1 - UTC"):
        fs.observed_azel(0.0, 0.0, "2026-03-01T00:00:00", dut1=dut1)
