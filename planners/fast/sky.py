"""FAST's sky: ICRS (J2000) source positions to azimuth/elevation at the site, and the
observation modes (tracking, drift scan, motion scans in RA and Dec) as horizon paths.

Paper: Yao et al. 2020, "A motion planning algorithm for the feed support system of FAST"
(REFERENCE.md "Papers", "the paper"), section 3.3 and
Table 1 (zenith angle up to 40 deg). Site and astronomy: REFERENCE.md ("FAST feed support system").

Site
----
FAST's published geocentric (ITRF) coordinates, X = -1668557.0 m, Y = 5506838.0 m,
Z = 2744934.0 m: the observatory's site file of 2019-09-19 (https://crafts.bao.ac.cn/pub/fast/
time/fast-coord.txt, the coordinates TEMPO2's observatories.dat and PINT use for FAST, code
"FA"). On the WGS84 ellipsoid (``erfa.gc2gd``) they are longitude 106.856666 deg E, geodetic
latitude 25.652946 deg N, height 1109.1 m (``FAST_SITE``). The rounded 106.856 E, 25.653 N
put the sky about 3 arcsec off.

Astronomy (pyerfa, the IAU SOFA library)
----------------------------------------
``observed_azel`` is ``eraAtco13`` (ICRS -> observed: IAU 2006/2000A precession-nutation,
annual and diurnal aberration, light deflection, Earth rotation angle, the geodetic horizon)
with these settings:

* no refraction: a radio telescope; pressure 0 switches ERFA's refraction model off;
* polar motion xp = yp = 0: at most ~0.5 arcsec;
* dut1 = UT1 - UTC, s: a parameter (``dut1=``, default 0; the IERS Bulletin A gives the day's
  value). |UT1 - UTC| < 0.9 s by the definition of UTC (``MAX_DUT1``), so 0 is at most 0.9 s of
  Earth rotation, 13.5 arcsec of hour angle: on the sky at most 13.5 arcsec x cos(dec); in
  azimuth (d az/dH = sin(lat) - cos(lat) cos(az) tan(el)) at most 13.5 arcsec x
  cos(lat - ZA) / sin(ZA) -- 6 arcsec at the horizon, 20 at ZA = 40 deg, 27 at 30 deg,
  growing as 1/ZA near the zenith, where azimuth is ill-conditioned anyway;
* leap seconds: ERFA's table; after its last entry (2017) UTC - TAI is held at -37 s and ERFA's
  "dubious year" warnings are silenced here.

By default the star-independent astrometry (``eraApco13``: precession-nutation, the Earth's
position and velocity) is computed on whole clock hours and interpolated linearly between
them (continuous in time, so finite differences of a path see no steps), and only the Earth
rotation angle is computed per sample (``eraAper13``, then ``eraAtciq`` / ``eraAtioq``): for a
path, 25 times faster than ``eraAtco13`` per sample and within 0.01 arcsec of it (tested);
``exact=True`` calls ``eraAtco13`` for every sample.

Times
-----
UTC is given as numpy ``datetime64`` (arrays allowed), ISO 8601 strings ("2025-06-01T12:00:00",
a trailing "Z" allowed) or a two-part quasi Julian date ``(jd1, jd2)``, ERFA's representation
(``utc_jd`` converts, with offsets in seconds; ``jd_to_iso`` formats). Paths count time in
seconds from their start; their sample times are start + t, with days of 86 400 s (across a
leap second -- none since 2016 -- 1 s off).

Observation modes (section 3.3 of the paper)
--------------------------------------------
* ``track``: a fixed ICRS (ra, dec), followed from a start time for a duration.
* ``drift_scan``: the feed parked at a fixed (az, el); the sky drifts through the beam, whose
  ICRS (ra, dec) is returned: RA grows at the Earth rotation rate; the declination of date
  stays put, but the ICRS declination drifts slowly: the precession since J2000 tilts the
  frames by n = 20 arcsec/yr times the years since 2000, so d(dec)/d(RA) ~ n sin(RA) -- up to
  ~2.5 arcmin per hour in the 2020s, ~1 arcsec per 10 min near RA 12 h.
* ``MotionScan``: a raster on the sky in (RA, Dec) -- observation legs joined by transition
  segments of planned duration t_2, the paper's "most important parameter".

The paper names the motion scans by the direction in which the raster *advances*, not by the
direction of its observation legs:

  ============================================  ==================  ====================
  paper                                         observation legs    transition steps
  ============================================  ==================  ====================
  motion scan along RA (Fig. 8-10, eq. 11-14)   along Dec at V_dec  in RA (p_c, V_c, l_2)
  motion scan along Dec (Fig. 11-13, eq. 15-20) along RA, reversing in Dec
  ============================================  ==================  ====================

(Fig. 8: "observation segment along the declination direction (vertical line) and transition
segment along the right ascension direction (horizontal line)"; Fig. 11 the other way round,
with V_m forward and V_m-inv reverse along RA on successive legs.) To avoid the ambiguity,
``MotionScan`` names its legs: ``legs_along="dec"`` is the paper's scan along RA, and
``legs_along="ra"`` the paper's scan along Dec (``MotionScan.paper_name`` says which).

Parametrization: centre (ra, dec); ``n_legs`` legs of ``leg_length`` (arc on the sky, rad)
scanned at ``speed`` (rad/s on the sky; 1 deg/h = ``DEG_PER_HOUR`` rad/s, so the paper's
V_dec in deg/h is ``V_dec * DEG_PER_HOUR``); neighbouring legs ``leg_spacing`` apart on the sky
(signed: positive advances toward increasing RA or Dec), centred on the centre; legs
alternate in direction (boustrophedon, as Fig. 11-13) unless ``alternate=False``; each
transition lasts ``t2`` s and is here the straight (linear in time) connection in (RA, Dec) of
one leg's end to the next leg's start, flagged ``on_leg = False`` (its real motion, with the
paper's acceleration sections, is planned elsewhere). Legs along Dec sit at RA offsets of
``leg_spacing / cos(dec)`` (the spacing measured at the centre declination); legs along RA at
declination ``dec_i`` run ``leg_length / cos(dec_i)`` in RA at ``speed / cos(dec_i)`` in RA, so
every leg is ``leg_length`` long on the sky and lasts ``leg_length / speed``.

Zenith-angle limit: every path is checked against the 40 deg of Table 1
(``planbench.planners.fast.MAX_ZENITH_ANGLE``); a ``LimitError`` names the first sample beyond it (UTC,
seconds after the start, zenith angle).

Horizon rates: ``horizon_rates`` differentiates a path numerically (azimuth and elevation rates,
the angular speed of the direction, and the feed's speed r * omega on the focal sphere of
radius r = 162.15 m, as the paper's eq. (11)-(19) speak of feed speeds in mm/s);
``sidereal_rates`` is the closed form for a fixed source: d(el)/dt = w cos(lat) sin(az),
d(az)/dt = w (sin(lat) - cos(lat) cos(az) tan(el)), angular speed w cos(dec) (derived from
ds/dt = -w p x s, p the celestial pole in the horizon frame; tested against the numbers).
"""

from __future__ import annotations

import math
import warnings
from contextlib import contextmanager
from dataclasses import dataclass
from typing import NamedTuple

import erfa
import numpy as np

from planbench.planners.errors import PlanningError
from planbench.planners.fast import FOCAL_SURFACE_RADIUS, MAX_ZENITH_ANGLE, ZenithLimitError, source_direction

#: 1 deg/h in rad/s: the paper's scan speeds (V_dec, deg/h) at the edges.
DEG_PER_HOUR = math.radians(1.0) / 3600.0
#: The Earth's rotation rate relative to the stars (the rate of the Earth rotation angle,
#: IAU 2000: 2 pi x 1.00273781191135448 per UT1 day), rad/s.
EARTH_ROTATION_RATE = 2.0 * math.pi * 1.00273781191135448 / 86400.0
SECONDS_PER_DAY = 86400.0
#: Most samples a path may have (memory guard).
MAX_SAMPLES = 2_000_000
#: The cadence of the full astrometry in ``observed_azel`` (the ERA is updated per sample).
ANCHOR_INTERVAL = 3600.0  # s
_J2000 = 2451545.0


@dataclass(frozen=True)
class Site:
    """An observatory: geodetic latitude and east longitude (rad), height above WGS84 (m)."""

    latitude: float
    longitude: float
    height: float


#: FAST's published ITRF coordinates, m (the observatory's site file of 2019-09-19, module docstring).
FAST_ITRF_XYZ = (-1668557.0, 5506838.0, 2744934.0)
_lon, _lat, _height = erfa.gc2gd(1, np.array(FAST_ITRF_XYZ))  # WGS84
#: FAST on WGS84: 106.856666 deg E, 25.652946 deg N, 1109.1 m.
FAST_SITE = Site(latitude=float(_lat), longitude=float(_lon), height=float(_height))
#: |UT1 - UTC| stays below 0.9 s by the definition of UTC.
MAX_DUT1 = 0.9  # s
SITE_LATITUDE = FAST_SITE.latitude
SITE_LONGITUDE = FAST_SITE.longitude
SITE_HEIGHT = FAST_SITE.height


@contextmanager
def _quiet_erfa():
    """Silence ERFA's 'dubious year' warnings (dates after its leap-second table)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*dubious year", category=erfa.ErfaWarning)
        yield


# ----------------------------------------------------------------------------- input checks


def _finite(name: str, value, unit: str = "") -> np.ndarray:
    a = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(a)):
        bad = float(a[~np.isfinite(a)].flat[0])
        raise PlanningError(f"{name} {bad!r}{' ' + unit if unit else ''} must be finite")
    return a


def _positive(name: str, value, unit: str, allow_zero: bool = False) -> float:
    v = float(_finite(name, value, unit))
    if v < 0.0 or (v == 0.0 and not allow_zero):
        raise PlanningError(f"{name} {v!r} {unit} must be {'>= 0' if allow_zero else '> 0'}")
    return v


def _declination(name: str, value) -> np.ndarray:
    d = _finite(name, value, "rad")
    if np.any(np.abs(d) > math.pi / 2):
        bad = float(d[np.abs(d) > math.pi / 2].flat[0])
        raise PlanningError(f"{name} {math.degrees(bad):.6g} deg is beyond +/-90 deg")
    return d


def _dut1(dut1) -> float:
    """UT1 - UTC, s: finite, |dut1| < 0.9 s."""
    v = float(_finite("UT1 - UTC", dut1, "s"))
    if not abs(v) < MAX_DUT1:
        raise PlanningError(f"UT1 - UTC {v!r} s is outside (-{MAX_DUT1:g}, {MAX_DUT1:g}) s, the range UTC keeps it in")
    return v


def _check_site(site: Site) -> None:
    _finite("site longitude", site.longitude, "rad")
    _finite("site height", site.height, "m")
    _declination("site latitude", site.latitude)


# ----------------------------------------------------------------------------- times


def _datetime_to_jd(times) -> tuple[np.ndarray, np.ndarray]:
    """datetime64 (any unit) -> ERFA two-part UTC quasi JD (day start + fraction)."""
    t = np.asarray(times)
    if np.any(np.isnat(t)):
        raise PlanningError("UTC time NaT (not a time) must be a valid date")
    day = t.astype("datetime64[D]")
    month = t.astype("datetime64[M]")
    year = t.astype("datetime64[Y]")
    iy = year.astype(np.int64) + 1970
    im = month.astype(np.int64) - (iy - 1970) * 12 + 1
    iday = (day - month.astype("datetime64[D]")).astype(np.int64) + 1
    seconds = (t - day) / np.timedelta64(1, "s")
    with _quiet_erfa():
        jd1, jd2 = erfa.dtf2d("UTC", iy, im, iday, 0, 0, 0.0)
    return np.asarray(jd1, dtype=float), np.asarray(jd2 + seconds / SECONDS_PER_DAY, dtype=float)


def _parse_datetime(value) -> np.ndarray:
    a = np.asarray(value)
    if a.dtype.kind in "US":
        flat = [str(s).strip() for s in a.ravel()]
        flat = [s[:-1] if s.endswith(("Z", "z")) else s for s in flat]
        try:
            a = np.array([np.datetime64(s, "ns") for s in flat]).reshape(a.shape)
        except ValueError as exc:
            raise PlanningError(f"UTC time {value!r} is not an ISO 8601 date: {exc}") from None
    if a.dtype.kind != "M":
        raise PlanningError(f"UTC time {value!r} must be datetime64, an ISO 8601 string or (jd1, jd2)")
    return a


def as_utc_jd(utc) -> tuple[np.ndarray, np.ndarray]:
    """UTC as datetime64 / ISO string(s) / (jd1, jd2) -> ERFA's two-part quasi JD (arrays)."""
    if isinstance(utc, tuple) and len(utc) == 2 and all(np.asarray(x).dtype.kind in "fiu" for x in utc):
        jd1 = _finite("UTC jd1", utc[0], "d")
        jd2 = _finite("UTC jd2", utc[1], "d")
        return np.broadcast_arrays(jd1, jd2)
    return _datetime_to_jd(_parse_datetime(utc))


def utc_jd(start, offsets_s=0.0) -> tuple[np.ndarray, np.ndarray]:
    """Two-part UTC quasi JD (jd1, jd2) of ``start`` plus ``offsets_s`` seconds.

    Args:
      start: datetime64, ISO 8601 string ("2025-06-01T12:00:00[Z]") or (jd1, jd2).
      offsets_s: seconds after ``start`` (array allowed; days of 86 400 s).
    Returns arrays broadcast over ``start`` and ``offsets_s``; jd1 the day (or whatever part
    ``start`` had), jd2 the rest, as ``erfa.dtf2d`` gives.
    """
    jd1, jd2 = as_utc_jd(start)
    off = _finite("time offset", offsets_s, "s")
    jd1, jd2, off = np.broadcast_arrays(jd1, jd2, off)
    return jd1.astype(float), jd2 + off / SECONDS_PER_DAY


def jd_to_iso(jd1, jd2) -> str | np.ndarray:
    """UTC (jd1, jd2) -> ISO 8601 string(s) to the millisecond, e.g. "2025-06-01T12:00:00.000Z"."""
    with _quiet_erfa():
        iy, im, iday, ihmsf = erfa.d2dtf("UTC", 3, jd1, jd2)
    fmt = np.vectorize(
        lambda y, m, d, h, mi, s, f: f"{y:04d}-{m:02d}-{d:02d}T{h:02d}:{mi:02d}:{s:02d}.{f:03d}Z", otypes=[object]
    )
    out = fmt(iy, im, iday, ihmsf["h"], ihmsf["m"], ihmsf["s"], ihmsf["f"])
    return str(out) if np.ndim(out) == 0 else out


# ----------------------------------------------------------------------------- astrometry


def _astrom(jd1, jd2, site: Site, dut1: float = 0.0):
    """ERFA star-independent astrometry for each UTC (jd1, jd2): ``eraApco13`` on the whole
    clock hours (counted from J2000) around each sample, interpolated linearly in time between
    them (continuous, so finite differences of a path see no steps; the fields -- Earth
    position and velocity, precession-nutation matrix -- bend by < 1e-8 of themselves in an
    hour), then ``eraAper13`` per sample (the Earth rotation angle)."""
    jd1, jd2 = np.broadcast_arrays(np.asarray(jd1, dtype=float), np.asarray(jd2, dtype=float))
    per_day = SECONDS_PER_DAY / ANCHOR_INTERVAL
    hours = ((jd1 - _J2000) + jd2) * per_day
    k = np.floor(hours)
    f = hours - k
    anchors, inverse = np.unique(np.concatenate([k.ravel(), k.ravel() + 1.0]), return_inverse=True)
    with _quiet_erfa():
        table, _ = erfa.apco13(
            _J2000, anchors / per_day, dut1, site.longitude, site.latitude, site.height, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        )
        table = np.atleast_1d(table)
        lo = table[inverse[: k.size].reshape(k.shape)]
        hi = table[inverse[k.size :].reshape(k.shape)]
        astrom = lo.copy()
        for name in table.dtype.names:
            w = f.reshape(f.shape + (1,) * (lo[name].ndim - f.ndim))
            astrom[name] = (1.0 - w) * lo[name] + w * hi[name]
        ut11, ut12 = erfa.utcut1(jd1, jd2, dut1)
        return erfa.aper13(ut11, ut12, astrom)


def _observed(ra, dec, utc, site: Site, exact: bool, dut1: float = 0.0):
    """(azimuth, zenith distance, hour angle, declination) observed; arrays broadcast."""
    _check_site(site)
    dut1 = _dut1(dut1)
    ra = _finite("right ascension", ra, "rad")
    dec = _declination("declination", dec)
    jd1, jd2 = as_utc_jd(utc)
    with _quiet_erfa():
        if exact:
            aob, zob, hob, dob, _, _ = erfa.atco13(
                ra,
                dec,
                0.0,
                0.0,
                0.0,
                0.0,
                jd1,
                jd2,
                dut1,
                site.longitude,
                site.latitude,
                site.height,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
            )
        else:
            astrom = _astrom(jd1, jd2, site, dut1)
            ri, di = erfa.atciq(ra, dec, 0.0, 0.0, 0.0, 0.0, astrom)
            aob, zob, hob, dob, _ = erfa.atioq(ri, di, astrom)
    return aob, zob, hob, dob


def observed_azel(ra, dec, utc, *, site: Site = FAST_SITE, exact: bool = False, dut1: float = 0.0):
    """Azimuth and elevation (rad) at the site of ICRS (J2000) positions at UTC times.

    Args:
      ra, dec: ICRS right ascension and declination, rad (arrays broadcast with the times).
      utc: datetime64 / ISO 8601 string(s) / two-part UTC quasi JD ``(jd1, jd2)`` (arrays).
      site: the observatory (default FAST).
      exact: ``eraAtco13`` per sample instead of the hourly astrometry (module docstring).
      dut1: UT1 - UTC, s (|dut1| < 0.9 s; default 0).
    Returns (az, el): azimuth from north through east in [0, 2 pi), elevation, rad; shape the
    broadcast of ra, dec and the times. No refraction (radio), no polar motion.
    Raises PlanningError for NaN, |dec| > 90 deg or bad times.
    """
    aob, zob, _, _ = _observed(ra, dec, utc, site, exact, dut1)
    return np.mod(aob, 2.0 * np.pi), np.pi / 2 - zob


def sky_position(az, el, utc, *, site: Site = FAST_SITE, dut1: float = 0.0):
    """ICRS (ra, dec), rad, of the direction (az, el) at the site at UTC times (the inverse of
    ``observed_azel``: ``eraAtoiq`` then ``eraAticq``, same settings)."""
    _check_site(site)
    az = _finite("azimuth", az, "rad")
    el = _declination("elevation", el)
    jd1, jd2 = as_utc_jd(utc)
    with _quiet_erfa():
        astrom = _astrom(jd1, jd2, site, _dut1(dut1))
        ri, di = erfa.atoiq("A", az, np.pi / 2 - el, astrom)
        rc, dc = erfa.aticq(ri, di, astrom)
    return np.mod(rc, 2.0 * np.pi), dc


def meridian_transit(ra, dec, near, *, site: Site = FAST_SITE, dut1: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """UTC (jd1, jd2) of the upper meridian transit (observed hour angle 0) nearest ``near``.

    Newton's method on the hour angle from ``observed_azel``'s chain, whose rate is the Earth
    rotation rate; three steps reach microseconds. Useful to start a path while the source is
    high: ``start = transit - duration / 2``.
    """
    jd1, jd2 = as_utc_jd(near)
    for _ in range(3):
        _, _, hob, _ = _observed(ra, dec, (jd1, jd2), site, False, dut1)
        h = np.mod(hob + np.pi, 2.0 * np.pi) - np.pi
        jd2 = jd2 - h / EARTH_ROTATION_RATE / SECONDS_PER_DAY
        jd1, jd2 = np.broadcast_arrays(jd1, jd2)
    return np.asarray(jd1, dtype=float), np.asarray(jd2, dtype=float)


# ----------------------------------------------------------------------------- horizon rates


class HorizonRates(NamedTuple):
    """Rates of a direction in the horizon frame along a path (arrays like the path's)."""

    az_rate: np.ndarray  # rad/s; unbounded near the zenith
    el_rate: np.ndarray  # rad/s
    angular_speed: np.ndarray  # rad/s, |ds/dt| of the unit vector s
    feed_speed: np.ndarray  # m/s: r |ds/dt|, the feed on the focal sphere (P_feed = -r s)


def horizon_rates(t, az, el, radius: float = FOCAL_SURFACE_RADIUS) -> HorizonRates:
    """Numerical rates along a sampled path; time along the last axis.

    Second-order finite differences (``np.gradient``, uneven spacing allowed) of the unwrapped
    azimuth, the elevation and the unit vector s(az, el). Across the corner between an
    observation leg and a transition the difference mixes both sides.
    """
    t = _finite("time", t, "s")
    az = _finite("azimuth", az, "rad")
    el = _finite("elevation", el, "rad")
    if t.ndim != 1 or t.size < 2 or np.any(np.diff(t) <= 0):
        raise PlanningError(f"times must be 1-D and increasing with at least 2 samples, got shape {t.shape}")
    az_rate = np.gradient(np.unwrap(az, axis=-1), t, axis=-1)
    el_rate = np.gradient(el, t, axis=-1)
    s = source_direction(az, el)
    speed = np.linalg.norm(np.gradient(s, t, axis=-2), axis=-1)
    return HorizonRates(az_rate, el_rate, speed, radius * speed)


def sidereal_rates(az, el, *, site: Site = FAST_SITE) -> tuple[np.ndarray, np.ndarray]:
    """(d az/dt, d el/dt), rad/s, of a fixed source at (az, el) carried by the Earth's rotation.

    From ds/dt = -w p x s, with p = (0, cos lat, sin lat) the pole in East-North-Up:
    d el/dt = w cos(lat) sin(az), d az/dt = w (sin(lat) - cos(lat) cos(az) tan(el)).
    """
    az = _finite("azimuth", az, "rad")
    el = _finite("elevation", el, "rad")
    w, lat = EARTH_ROTATION_RATE, site.latitude
    return (w * (math.sin(lat) - math.cos(lat) * np.cos(az) * np.tan(el)), w * math.cos(lat) * np.sin(az))


# ----------------------------------------------------------------------------- paths


@dataclass(frozen=True, eq=False)
class SkyPath:
    """A sampled pointing path: where the beam looks on the sky and in the horizon frame.

    Attributes:
      t: (n,) s after the start; jd1, jd2: (n,) UTC two-part quasi JD of the samples.
      ra, dec: (n,) ICRS pointing, rad. az, el: (n,) rad (azimuth from north through east).
      on_leg: (n,) True on an observation leg, False in a transition between legs.
      leg: (n,) index of the leg (for a transition: of the leg before it).
      leg_start, leg_end: (n_legs,) s after the start.
    """

    t: np.ndarray
    jd1: np.ndarray
    jd2: np.ndarray
    ra: np.ndarray
    dec: np.ndarray
    az: np.ndarray
    el: np.ndarray
    on_leg: np.ndarray
    leg: np.ndarray
    leg_start: np.ndarray
    leg_end: np.ndarray

    @property
    def zenith_angle(self) -> np.ndarray:
        """rad."""
        return np.pi / 2 - self.el

    @property
    def duration(self) -> float:
        return float(self.t[-1])

    def directions(self) -> np.ndarray:
        """(n, 3) unit vectors to the sky in East-North-Up (planbench.planners.fast's frame)."""
        return source_direction(self.az, self.el)

    def rates(self) -> HorizonRates:
        return horizon_rates(self.t, self.az, self.el)


def _sample_times(duration: float, step: float, boundaries=()) -> np.ndarray:
    """0, step, 2 step, ... up to ``duration``, plus ``duration`` and the boundaries exactly;
    grid points within 1e-6 step of a boundary are dropped."""
    ratio = duration / step * (1.0 + 1e-12)
    if not ratio + 1 + len(boundaries) <= MAX_SAMPLES:
        raise PlanningError(
            f"duration {duration!r} s at step {step!r} s gives {ratio:.4g} samples; the limit is {MAX_SAMPLES}"
        )
    bounds = np.unique(np.concatenate([[0.0, duration], np.asarray(boundaries, dtype=float)]))
    grid = step * np.arange(math.floor(ratio) + 1)
    i = np.clip(np.searchsorted(bounds, grid), 1, bounds.size - 1)
    near = np.minimum(np.abs(grid - bounds[i - 1]), np.abs(grid - bounds[i])) <= 1e-6 * step
    return np.sort(np.concatenate([grid[~near & (grid < duration)], bounds]))


def _check_zenith(what: str, za: np.ndarray, t: np.ndarray, jd1, jd2, limit) -> None:
    if limit is None:
        return
    bad = np.flatnonzero(za > limit + 1e-12)
    if bad.size:
        i = int(bad[0])
        raise ZenithLimitError(
            f"{what} reaches zenith angle {math.degrees(za[i]):.3f} deg at "
            f"{jd_to_iso(jd1[i], jd2[i])} UTC ({t[i]:.1f} s after the start), beyond the FAST "
            f"limit {math.degrees(limit):.1f} deg"
        )


def _limit(za_limit):
    if za_limit is None:
        return None
    v = _positive("zenith-angle limit", za_limit, "rad")
    if v > math.pi:
        raise PlanningError(f"zenith-angle limit {math.degrees(v):.3f} deg is beyond 180 deg")
    return v


def track(
    ra: float,
    dec: float,
    start,
    duration: float,
    *,
    step: float = 1.0,
    za_limit: float | None = MAX_ZENITH_ANGLE,
    site: Site = FAST_SITE,
    exact: bool = False,
    dut1: float = 0.0,
) -> SkyPath:
    """Tracking: the beam follows the fixed ICRS (ra, dec), rad, from ``start`` (UTC, see
    ``utc_jd``) for ``duration`` s, sampled every ``step`` s (and at the end).

    Raises LimitError at the first sample whose zenith angle exceeds ``za_limit`` (40 deg,
    Table 1; None: no check), PlanningError for NaN, |dec| > 90 deg, duration or step <= 0.
    """
    ra = float(_finite("right ascension", ra, "rad"))
    dec = float(_declination("declination", dec))
    duration = _positive("duration", duration, "s")
    step = _positive("step", step, "s")
    limit = _limit(za_limit)
    t = _sample_times(duration, step)
    jd1, jd2 = utc_jd(start, t)
    az, el = observed_azel(ra, dec, (jd1, jd2), site=site, exact=exact, dut1=dut1)
    _check_zenith(
        f"the source at RA {math.degrees(ra):.4f} deg, Dec {math.degrees(dec):.4f} deg",
        np.pi / 2 - el,
        t,
        jd1,
        jd2,
        limit,
    )
    n = t.size
    return SkyPath(
        t,
        jd1,
        jd2,
        np.full(n, ra % (2 * np.pi)),
        np.full(n, dec),
        az,
        el,
        np.ones(n, bool),
        np.zeros(n, int),
        np.array([0.0]),
        np.array([duration]),
    )


def drift_scan(
    az: float,
    el: float,
    start,
    duration: float,
    *,
    step: float = 1.0,
    za_limit: float | None = MAX_ZENITH_ANGLE,
    site: Site = FAST_SITE,
    dut1: float = 0.0,
) -> SkyPath:
    """Drift scan: the feed parked at (az, el), rad, while the sky drifts through the beam.

    Returns the constant az/el and the ICRS (ra, dec) the beam sees at each sample (RA grows at
    about the Earth rotation rate; the module docstring says how Dec drifts). Raises
    LimitError (at the start) when the parked zenith angle exceeds ``za_limit``, PlanningError
    for bad input.
    """
    az = float(_finite("azimuth", az, "rad")) % (2 * np.pi)
    el = float(_declination("elevation", el))
    duration = _positive("duration", duration, "s")
    step = _positive("step", step, "s")
    limit = _limit(za_limit)
    t = _sample_times(duration, step)
    jd1, jd2 = utc_jd(start, t)
    n = t.size
    _check_zenith(
        f"the parked beam at az {math.degrees(az):.4f} deg, el {math.degrees(el):.4f} deg",
        np.full(n, np.pi / 2 - el),
        t,
        jd1,
        jd2,
        limit,
    )
    ra, dec = sky_position(np.full(n, az), np.full(n, el), (jd1, jd2), site=site, dut1=dut1)
    return SkyPath(
        t,
        jd1,
        jd2,
        ra,
        dec,
        np.full(n, az),
        np.full(n, el),
        np.ones(n, bool),
        np.zeros(n, int),
        np.array([0.0]),
        np.array([duration]),
    )


LEG_AXES = ("dec", "ra")


@dataclass(frozen=True)
class MotionScan:
    """A motion scan (the paper's section 3.3): a raster of observation legs on the sky.

    Attributes (see the module docstring for the geometry and the paper's names):
      ra, dec: the raster's centre, ICRS, rad.
      legs_along: "dec" (legs along declination, steps in RA: the paper's "motion scan along
        the right ascension direction", Fig. 8) or "ra" (legs along RA, steps in Dec: the
        paper's "motion scan along the declination direction", Fig. 11).
      leg_length: arc length of each leg on the sky, rad (> 0).
      n_legs: number of observation legs (>= 1).
      leg_spacing: on-sky distance between neighbouring legs, rad; its sign sets the direction
        the raster advances (nonzero when n_legs > 1).
      speed: scan speed on the sky along a leg, rad/s (> 0); V_dec deg/h -> V_dec * DEG_PER_HOUR.
      t2: duration of each transition segment, s (> 0 when n_legs > 1).
      alternate: legs reverse direction one after the other (default, boustrophedon).
    """

    ra: float
    dec: float
    legs_along: str
    leg_length: float
    n_legs: int
    leg_spacing: float
    speed: float
    t2: float
    alternate: bool = True

    def __post_init__(self):
        _finite("right ascension", self.ra, "rad")
        _declination("declination", self.dec)
        if self.legs_along not in LEG_AXES:
            raise PlanningError(f"legs_along {self.legs_along!r} is not one of {', '.join(LEG_AXES)}")
        integer = isinstance(self.n_legs, (int, np.integer)) and not isinstance(self.n_legs, bool)
        if not integer or self.n_legs < 1:
            raise PlanningError(f"number of legs {self.n_legs!r} must be an integer >= 1")
        _positive("leg length", self.leg_length, "rad")
        _positive("scan speed", self.speed, "rad/s")
        _finite("leg spacing", self.leg_spacing, "rad")
        _positive("transition time t2", self.t2, "s", allow_zero=True)
        if self.n_legs > 1:
            if self.leg_spacing == 0.0:
                raise PlanningError(f"leg spacing {self.leg_spacing!r} rad must be nonzero for {self.n_legs} legs")
            if self.t2 == 0.0:
                raise PlanningError(f"transition time t2 {self.t2!r} s must be > 0 for {self.n_legs} legs")
        half = 0.5 * (self.n_legs - 1) * abs(self.leg_spacing)
        if self.legs_along == "dec":
            extent = abs(self.dec) + 0.5 * self.leg_length
            if self.n_legs > 1 and abs(self.dec) >= math.pi / 2:
                raise PlanningError(
                    f"declination {math.degrees(self.dec):.4f} deg: legs cannot be spaced in RA at a pole"
                )
        else:
            extent = abs(self.dec) + half
        if extent > math.pi / 2 or (self.legs_along == "ra" and extent >= math.pi / 2):
            raise PlanningError(f"the raster reaches declination {math.degrees(extent):.4f} deg, beyond +/-90 deg")

    @property
    def paper_name(self) -> str:
        if self.legs_along == "dec":
            return "motion scan along the right ascension direction (Fig. 8-10, eq. 11-14)"
        return "motion scan along the declination direction (Fig. 11-13, eq. 15-20)"

    @property
    def leg_duration(self) -> float:
        """s: leg_length / speed."""
        return self.leg_length / self.speed

    @property
    def duration(self) -> float:
        """s: n_legs legs and n_legs - 1 transitions."""
        return self.n_legs * self.leg_duration + (self.n_legs - 1) * self.t2

    @property
    def leg_start(self) -> np.ndarray:
        return np.arange(self.n_legs) * (self.leg_duration + self.t2)

    @property
    def leg_end(self) -> np.ndarray:
        return self.leg_start + self.leg_duration

    def _leg_position(self, k: np.ndarray, tau: np.ndarray):
        """(ra, dec) on leg k at tau s after its start (RA not wrapped)."""
        offset = (k - 0.5 * (self.n_legs - 1)) * self.leg_spacing
        sense = np.where((k % 2 == 1) & self.alternate, -1.0, 1.0)
        along = sense * (self.speed * tau - 0.5 * self.leg_length)
        if self.legs_along == "dec":
            return self.ra + offset / math.cos(self.dec) + 0.0 * along, self.dec + along
        dec = self.dec + offset
        return self.ra + along / np.cos(dec), dec

    def sky(self, t):
        """(ra, dec, on_leg, leg) at times t (s after the start, in [0, duration]).

        ra, dec: ICRS pointing, rad (ra in [0, 2 pi)); on_leg: observation (True) or transition;
        leg: the leg's index (a transition's: the leg before it).
        """
        t = _finite("time", t, "s")
        if np.any(t < 0.0) or np.any(t > self.duration * (1 + 1e-12)):
            bad = float(t[(t < 0.0) | (t > self.duration * (1 + 1e-12))].flat[0])
            raise PlanningError(f"time {bad!r} s is outside the scan [0, {self.duration!r}] s")
        starts, ends = self.leg_start, self.leg_end
        k = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, self.n_legs - 1)
        tau = np.minimum(t - starts[k], self.leg_duration)
        on_leg = t <= ends[k]
        ra, dec = self._leg_position(k, tau)
        if self.n_legs > 1:
            f = np.clip((t - ends[k]) / self.t2, 0.0, 1.0)
            nxt = np.minimum(k + 1, self.n_legs - 1)
            ra_a, dec_a = self._leg_position(k, np.full_like(t, self.leg_duration))
            ra_b, dec_b = self._leg_position(nxt, np.zeros_like(t))
            ra = np.where(on_leg, ra, (1 - f) * ra_a + f * ra_b)
            dec = np.where(on_leg, dec, (1 - f) * dec_a + f * dec_b)
        return np.mod(ra, 2.0 * np.pi), dec, on_leg, k

    def path(
        self,
        start,
        *,
        step: float = 1.0,
        za_limit: float | None = MAX_ZENITH_ANGLE,
        site: Site = FAST_SITE,
        exact: bool = False,
        dut1: float = 0.0,
    ) -> SkyPath:
        """The scan from ``start`` (UTC) sampled every ``step`` s and at every leg start and
        end; LimitError at the first sample beyond ``za_limit`` (40 deg; None: no check)."""
        step = _positive("step", step, "s")
        limit = _limit(za_limit)
        t = _sample_times(self.duration, step, np.concatenate([self.leg_start, self.leg_end]))
        ra, dec, on_leg, leg = self.sky(t)
        jd1, jd2 = utc_jd(start, t)
        az, el = observed_azel(ra, dec, (jd1, jd2), site=site, exact=exact, dut1=dut1)
        _check_zenith(
            f"the {self.paper_name.split(' (')[0]} centred at RA "
            f"{math.degrees(self.ra):.4f} deg, Dec {math.degrees(self.dec):.4f} deg",
            np.pi / 2 - el,
            t,
            jd1,
            jd2,
            limit,
        )
        return SkyPath(t, jd1, jd2, ra, dec, az, el, on_leg, leg, self.leg_start, self.leg_end)


def parallactic_angle(az, el, *, site: Site = FAST_SITE) -> np.ndarray:
    """Parallactic angle (rad) of the directions (az, el) at the site: the angle at the source
    between the directions to the zenith and to the celestial pole (erfa ae2hd, hd2pa). The
    19-beam receiver turns by it to keep its beam pattern fixed on the sky."""
    az, el = np.broadcast_arrays(np.asarray(az, dtype=float), np.asarray(el, dtype=float))
    ha, dec = erfa.ae2hd(az, el, site.latitude)
    return np.asarray(erfa.hd2pa(ha, dec, site.latitude))
