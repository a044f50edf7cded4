"""Ship motion: the heave, heading, pitch and roll that move the deck of the ship antenna.

Frames and angles (ship-antenna paper, eq. 1; REFERENCE.md, "Ship antenna"):
  ship frame X to starboard, Y to the bow, Z up; world frame East-North-Up.
  heading psi about Z, pitch phi about X, roll gamma about Y, rad;
  world-from-ship eTb = Rz(psi) Rx(phi) Ry(gamma) (active rotations; the paper's bTe is the
  transpose: its printed matrices are the passive Ry(gamma)^T Rx(phi)^T Rz(psi)^T).
  psi is counter-clockwise seen from above: a positive psi turns the bow from north toward
  west (the paper's printed matrix implies it), the opposite of a compass course.
  Positive pitch lifts the bow; positive roll lowers the starboard side (Z toward X).
  heave z, m, up positive, at the ship-frame origin (the antenna's base).

The deck of the antenna model carries four joints nested in the order of ``AXES``: heave
slide along Z, yaw hinge about Z, pitch hinge about X, roll hinge about Y, so MuJoCo's joint
values are exactly (z, psi, phi, gamma). ``ShipState.joint_arrays`` returns them in that order.

Two motions:
  ``PaperShipMotion``: the paper's eq. (15)-(16), with t read as the sample count at 0.01 s.
  ``SeaStateMotion``: a JONSWAP sea state seen through response amplitude operators (RAO) of a
  generic 100 m ship: sum_k |RAO(w_k)| sqrt(2 S(w_k) dw) cos(w_e,k t + angle RAO + phi_k)
  per axis (REFERENCE.md; Fossen, MSS), one random phase per wave component for all axes.

Both return exact analytic first and second time derivatives. Bad input raises
``ShipMotionError`` (a ``PlanningError``, so a ``ValueError``) naming the value and its limit.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from planbench.planners.errors import PlanningError

GRAVITY = 9.81  # m/s^2

#: Order of the deck joints of the antenna model, and of the columns of ``ShipState``'s arrays.
AXES = ("heave", "heading", "pitch", "roll")
HEAVE, HEADING, PITCH, ROLL = range(4)

#: Largest (time samples x wave components) block evaluated at once: 2^20 doubles = 8 MiB
#: per table, so a 300 s record at 1 kHz stays at a few tens of MiB.
_BLOCK_ELEMENTS = 1 << 20


class ShipMotionError(PlanningError):
    """Bad input to a ship motion: a sea state, vessel parameter or sample time out of range."""


# --------------------------------------------------------------------------------------------
# The sea states a run accepts (``check_sea_state``; the antenna-sea-state scenario and the
# CLI's --hs, --tp). ``SeaStateMotion`` itself, a sum of waves, takes any Hs, Tp > 0 (the
# tests drive it with a 60 s swell to see the RAOs' long-wave limits).

#: Peak period range, s: Munk (1950), "Origin and generation of waves" (Proc. 1st Conf.
#: Coastal Engineering), the band of ordinary gravity waves, 1-30 s, which holds wind seas
#: and swell. Longer periods are infragravity waves and tides, shorter ones capillary-gravity
#: ripples: neither is a sea state that a JONSWAP spectrum describes or that moves a ship.
SEA_TP_RANGE_S = (1.0, 30.0)
#: Largest significant wave height, m: above any measured. The WMO's record is 19.0 m (buoy
#: K5, North Atlantic, 4 February 2013; WMO Weather and Climate Extremes Archive, 2016).
SEA_HS_MAX_M = 20.0
#: Limiting sea-state steepness Sp = 2 pi Hs / (g Tp^2) (DNV-RP-C205, 2010, section 3.5,
#: "wave steepness"): 1/15 for Tp <= 8 s, 1/25 for Tp >= 15 s, linear in between; steeper
#: seas break. The RAOs are linear (Jensen, Mansour & Olsen 2004: small steepness) and for
#: deep water (depth > g Tp^2 / (4 pi), 700 m at 30 s: the open ocean). DNV-RP-C205 3.5.5.1
#: adds that JONSWAP is a reasonable model for 3.6 < Tp / sqrt(Hs) < 5 and "should be used
#: with caution" outside: a caution, not refused here.
SEA_STEEPNESS_LIMIT = ((8.0, 1.0 / 15.0), (15.0, 1.0 / 25.0))


def steepness_limit(tp: float) -> float:
    """The limiting steepness Sp at peak period tp (s): ``SEA_STEEPNESS_LIMIT``."""
    (t0, s0), (t1, s1) = SEA_STEEPNESS_LIMIT
    return float(np.interp(tp, [t0, t1], [s0, s1]))


def check_wave_height(hs: float) -> float:
    """hs (m) if it is a significant wave height in (0, SEA_HS_MAX_M], else a ShipMotionError."""
    hs = _positive("significant wave height hs", hs, " m")
    if hs > SEA_HS_MAX_M:
        raise ShipMotionError(
            f"significant wave height hs = {hs:g} m is above {SEA_HS_MAX_M:g} m (the highest measured is 19.0 m, WMO)"
        )
    return hs


def check_peak_period(tp: float) -> float:
    """tp (s) if it is a peak period in SEA_TP_RANGE_S, else a ShipMotionError."""
    tp = _positive("peak period tp", tp, " s")
    lo, hi = SEA_TP_RANGE_S
    if not lo <= tp <= hi:
        raise ShipMotionError(
            f"peak period tp = {tp:g} s is outside [{lo:g}, {hi:g}] s, the periods of wind seas and swell (Munk 1950)"
        )
    return tp


def check_sea_state(hs: float, tp: float) -> tuple[float, float]:
    """(hs, tp) if the sea state is one the spectrum and the RAOs describe: hs and tp in their
    ranges (``check_wave_height``, ``check_peak_period``) and no steeper than the limiting
    steepness (``steepness_limit``); else a ShipMotionError naming the value and the limit."""
    hs, tp = check_wave_height(hs), check_peak_period(tp)
    steepness = 2.0 * math.pi * hs / (GRAVITY * tp * tp)
    limit = steepness_limit(tp)
    if steepness > limit:
        hs_max = limit * GRAVITY * tp * tp / (2.0 * math.pi)
        raise ShipMotionError(
            f"sea state hs = {hs:g} m, tp = {tp:g} s is steeper than waves can be: 2 pi Hs / (g Tp^2) "
            f"= 1/{1.0 / steepness:.3g} > 1/{1.0 / limit:.3g} (DNV-RP-C205's limit at tp = {tp:g} s; "
            f"hs <= {hs_max:.3g} m)"
        )
    return hs, tp


def _finite(name: str, value, unit: str = "") -> float:
    value = float(value)
    if not math.isfinite(value):
        raise ShipMotionError(f"{name} = {value!r}{unit} must be finite")
    return value


def _positive(name: str, value, unit: str = "") -> float:
    value = _finite(name, value, unit)
    if value <= 0.0:
        raise ShipMotionError(f"{name} = {value:g}{unit} must be > 0")
    return value


def _times(t) -> np.ndarray:
    """Sample times as a 1-D float array; a scalar becomes shape (1,). NaN or inf raise."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    if t.ndim != 1:
        raise ShipMotionError(f"sample times must be a scalar or 1-D array, got shape {t.shape}")
    bad = ~np.isfinite(t)
    if bad.any():
        i = int(np.argmax(bad))
        raise ShipMotionError(f"sample time t[{i}] = {float(t[i])!r} s must be finite")
    return t


# --------------------------------------------------------------------------------------------
# Attitude kinematics


def world_from_ship(heading, pitch, roll) -> np.ndarray:
    """eTb = Rz(psi) Rx(phi) Ry(gamma), shape (n, 3, 3), from angles in rad (scalars or (n,)).

    Column j is ship axis j (starboard, bow, up) in East-North-Up. This is scipy's intrinsic
    ``Rotation.from_euler("ZXY", [psi, phi, gamma])`` (tested). The paper's bTe (eq. 1) is its
    transpose.
    """
    psi, phi, gam = np.broadcast_arrays(*(np.atleast_1d(np.asarray(a, dtype=float)) for a in (heading, pitch, roll)))
    cp, sp = np.cos(psi), np.sin(psi)
    cf, sf = np.cos(phi), np.sin(phi)
    cg, sg = np.cos(gam), np.sin(gam)
    out = np.empty(psi.shape + (3, 3))
    # Rz(psi) @ Rx(phi) @ Ry(gamma), multiplied out.
    out[..., 0, 0] = cp * cg - sp * sf * sg
    out[..., 0, 1] = -sp * cf
    out[..., 0, 2] = cp * sg + sp * sf * cg
    out[..., 1, 0] = sp * cg + cp * sf * sg
    out[..., 1, 1] = cp * cf
    out[..., 1, 2] = sp * sg - cp * sf * cg
    out[..., 2, 0] = -cf * sg
    out[..., 2, 1] = sf
    out[..., 2, 2] = cf * cg
    return out


def body_angular_velocity(heading, pitch, roll, heading_rate, pitch_rate, roll_rate) -> np.ndarray:
    """Angular velocity of the ship in its own frame (what a deck gyro reads), rad/s, (n, 3).

    omega_b = Ry(gamma)^T Rx(phi)^T [0, 0, psi'] + Ry(gamma)^T [phi', 0, 0] + [0, gamma', 0],
    the rates of the three nested rotations of eTb = Rz(psi) Rx(phi) Ry(gamma), each carried
    into the ship frame; skew(omega_b) = eTb^T d(eTb)/dt (tested by finite differences).
    Arguments in rad and rad/s, scalars or (n,).
    """
    _, phi, gam, dpsi, dphi, dgam = np.broadcast_arrays(
        *(
            np.atleast_1d(np.asarray(a, dtype=float))
            for a in (heading, pitch, roll, heading_rate, pitch_rate, roll_rate)
        )
    )
    cf, sf = np.cos(phi), np.sin(phi)
    cg, sg = np.cos(gam), np.sin(gam)
    # Rx(phi)^T [0, 0, psi'] = psi' [0, sin phi, cos phi]; then Ry(gamma)^T adds phi' x.
    vx, vy, vz = dphi, dpsi * sf, dpsi * cf
    return np.stack([cg * vx - sg * vz, vy + dgam, sg * vx + cg * vz], axis=-1)


@dataclass(frozen=True)
class ShipState:
    """Ship motion sampled at n times.

    Attributes:
      t: sample times, s, (n,).
      heave: z, m, up positive; heading, pitch, roll: psi, phi, gamma, rad; each (n,).
      rate: first time derivatives, (n, 4), columns in ``AXES`` order
        (heave m/s, heading, pitch, roll rad/s).
      accel: second time derivatives, (n, 4), same order (m/s^2, rad/s^2).
    """

    t: np.ndarray
    heave: np.ndarray
    heading: np.ndarray
    pitch: np.ndarray
    roll: np.ndarray
    rate: np.ndarray
    accel: np.ndarray

    def __post_init__(self):
        n = np.shape(self.t)[0] if np.ndim(self.t) == 1 else -1
        for name in ("heave", "heading", "pitch", "roll"):
            if np.shape(getattr(self, name)) != (n,):
                raise ShipMotionError(
                    f"ShipState.{name} has shape {np.shape(getattr(self, name))}, must be ({n},) like t"
                )
        for name in ("rate", "accel"):
            if np.shape(getattr(self, name)) != (n, 4):
                raise ShipMotionError(f"ShipState.{name} has shape {np.shape(getattr(self, name))}, must be ({n}, 4)")

    def __len__(self) -> int:
        return len(self.t)

    @property
    def position(self) -> np.ndarray:
        """(n, 4): heave (m), heading, pitch, roll (rad), in ``AXES`` (deck joint) order."""
        return np.stack([self.heave, self.heading, self.pitch, self.roll], axis=-1)

    def joint_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(position, velocity, acceleration), each (n, 4) in deck-joint order (``AXES``):
        heave slide, yaw hinge about Z, pitch hinge about X, roll hinge about Y."""
        return self.position, self.rate, self.accel

    def world_from_ship(self) -> np.ndarray:
        """eTb at every sample, (n, 3, 3); see ``world_from_ship``."""
        return world_from_ship(self.heading, self.pitch, self.roll)

    def body_angular_velocity(self) -> np.ndarray:
        """Deck gyro reading at every sample, rad/s, (n, 3); see ``body_angular_velocity``."""
        return body_angular_velocity(
            self.heading, self.pitch, self.roll, self.rate[:, HEADING], self.rate[:, PITCH], self.rate[:, ROLL]
        )

    def with_degrees(self) -> dict[str, np.ndarray]:
        """Angles in degrees and heave in m, for reports and plots (the edges of the code)."""
        return {
            "t": self.t,
            "heave_m": self.heave,
            "heading_deg": np.degrees(self.heading),
            "pitch_deg": np.degrees(self.pitch),
            "roll_deg": np.degrees(self.roll),
        }


# --------------------------------------------------------------------------------------------
# The paper's motion


class PaperShipMotion:
    """The ship motion of the ship-antenna paper, eq. (15)-(16).

    In degrees, with s the sample count at ``sample_time`` = 0.01 s (REFERENCE.md: the paper's
    t is the sample index, so s = t / 0.01 s):
      psi   = 40 sin(2 pi s / 30000) + 0.01 s   -> 40 deg at a 300 s period, plus 1 deg/s turn
      phi   = 40 sin(2 pi s / 800)               -> pitch 40 deg at an 8 s period
      gamma = 45 sin(2 pi s / 1000)              -> roll 45 deg at a 10 s period
    heave = 0. Derivatives are exact (differentiated by hand).
    """

    HEADING_AMPLITUDE = math.radians(40.0)  # rad
    HEADING_PERIOD_SAMPLES = 30000.0
    TURN_PER_SAMPLE = math.radians(0.01)  # rad per sample
    PITCH_AMPLITUDE = math.radians(40.0)
    PITCH_PERIOD_SAMPLES = 800.0
    ROLL_AMPLITUDE = math.radians(45.0)
    ROLL_PERIOD_SAMPLES = 1000.0

    def __init__(
        self,
        sample_time: float = 0.01,
        amplitudes_deg: dict | None = None,
        periods_s: dict | None = None,
        turn_rate_deg_s: float | None = None,
        course_deg: float = 0.0,
    ):
        """``amplitudes_deg`` and ``periods_s`` ({"heading", "pitch", "roll"}: deg, s) and
        ``turn_rate_deg_s`` replace the paper's values (None: eq. 15-16 as printed, at
        ``sample_time`` per sample); ``course_deg`` is added to the heading (the paper's psi
        starts at 0)."""
        self.sample_time = _positive("paper sample time", sample_time, " s")
        amplitudes = {"heading": self.HEADING_AMPLITUDE, "pitch": self.PITCH_AMPLITUDE, "roll": self.ROLL_AMPLITUDE}
        for name, value in (amplitudes_deg or {}).items():
            amplitudes[name] = math.radians(_finite(f"{name} amplitude", value, " deg"))
        periods = {
            name: samples * self.sample_time
            for name, samples in (
                ("heading", self.HEADING_PERIOD_SAMPLES),
                ("pitch", self.PITCH_PERIOD_SAMPLES),
                ("roll", self.ROLL_PERIOD_SAMPLES),
            )
        }
        for name, value in (periods_s or {}).items():
            periods[name] = _positive(f"{name} period", value, " s")
        self.amplitudes, self._periods = amplitudes, periods
        self._turn_rate = (
            self.TURN_PER_SAMPLE / self.sample_time
            if turn_rate_deg_s is None
            else math.radians(_finite("turn rate", turn_rate_deg_s, " deg/s"))
        )
        self.course = math.radians(_finite("course", course_deg, " deg"))

    @property
    def turn_rate(self) -> float:
        """Mean heading rate, rad/s (1 deg/s at 0.01 s per sample)."""
        return self._turn_rate

    def periods(self) -> dict[str, float]:
        """Periods of the heading, pitch and roll oscillations, s."""
        return dict(self._periods)

    def sample(self, t) -> ShipState:
        """ShipState at times t (s, scalar or (n,))."""
        t = _times(t)
        rate = np.zeros((t.size, 4))
        accel = np.zeros((t.size, 4))
        angles = []
        for col, name in ((HEADING, "heading"), (PITCH, "pitch"), (ROLL, "roll")):
            amp = self.amplitudes[name]
            w = 2.0 * np.pi / self._periods[name]  # rad/s
            s, c = np.sin(w * t), np.cos(w * t)
            angles.append(amp * s)
            rate[:, col] = amp * w * c
            accel[:, col] = -amp * w * w * s
        angles[0] = angles[0] + self.turn_rate * t
        if self.course:
            angles[0] = angles[0] + self.course
        rate[:, HEADING] += self.turn_rate
        return ShipState(
            t=t, heave=np.zeros(t.size), heading=angles[0], pitch=angles[1], roll=angles[2], rate=rate, accel=accel
        )


# --------------------------------------------------------------------------------------------
# JONSWAP spectrum


def _jonswap_sigma(u):
    return np.where(u <= 1.0, 0.07, 0.09)


def _jonswap_shape(u, gamma: float):
    """Unnormalized JONSWAP shape in u = omega / omega_p: the Pierson-Moskowitz part
    5 u^-5 exp(-5/4 u^-4) (whose integral over u is exactly 1) times the peak enhancement."""
    u = np.asarray(u, dtype=float)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        pm = np.where(u > 0.0, 5.0 * u**-5.0 * np.exp(-1.25 * u**-4.0), 0.0)
        r = np.exp(-((u - 1.0) ** 2) / (2.0 * _jonswap_sigma(u) ** 2))
    return np.where(u > 0.0, pm * gamma**r, 0.0)


@functools.lru_cache(maxsize=64)
def jonswap_normalization(gamma: float) -> float:
    """1 / integral of the JONSWAP shape over u = omega / omega_p (exact, by quadrature).

    Multiplying the Pierson-Moskowitz spectrum with the peak enhancement gamma^r raises its
    variance; this factor brings m0 back to Hs^2 / 16. DNV-RP-C205 (2010, 3.5.5.2) uses the fit
    A_gamma = 1 - 0.287 ln(gamma) instead: 0.6573 at gamma = 3.3 against 0.6558 here, so a
    spectrum normalized with it has m0 0.24 % above Hs^2 / 16 (0.2 % below at gamma = 2,
    1.8 % below at gamma = 7; exact at gamma = 1, the Pierson-Moskowitz spectrum).
    """
    gamma = float(gamma)
    if not math.isfinite(gamma) or gamma < 1.0:
        raise ShipMotionError(f"JONSWAP peak enhancement gamma = {gamma!r} must be >= 1")

    from scipy import integrate  # (here: importing it costs every command line ~0.3 s)

    def f(u):
        return float(_jonswap_shape(u, gamma))

    # Split at the peak (sigma changes there); below 0.3 the shape is < 1e-50.
    total = sum(
        integrate.quad(f, a, b, epsabs=0.0, epsrel=1e-12, limit=200)[0]
        for a, b in ((0.3, 1.0), (1.0, 3.0), (3.0, np.inf))
    )
    return 1.0 / total


def _check_sea(hs, tp, gamma) -> tuple[float, float, float]:
    hs = _positive("significant wave height hs", hs, " m")
    tp = _positive("peak period tp", tp, " s")
    gamma = float(gamma)
    if not math.isfinite(gamma) or gamma < 1.0:
        raise ShipMotionError(f"JONSWAP peak enhancement gamma = {gamma!r} must be >= 1")
    return hs, tp, gamma


def jonswap_spectrum(omega, hs: float, tp: float, gamma: float = 3.3) -> np.ndarray:
    """One-sided JONSWAP wave spectrum S(omega), m^2 s / rad, at omega (rad/s).

    S(w) = A(gamma) (5/16) Hs^2 wp^4 w^-5 exp(-5/4 (wp/w)^4) gamma^r,
    r = exp(-(w - wp)^2 / (2 sigma^2 wp^2)), sigma = 0.07 (w <= wp) or 0.09 (w > wp),
    wp = 2 pi / Tp (DNV-RP-C205, 3.5.5; Fossen, Handbook of Marine Craft Hydrodynamics 2021,
    ch. 10). A(gamma) = ``jonswap_normalization(gamma)`` is computed by quadrature, so that
    m0 = integral of S = Hs^2 / 16 exactly (Hs = 4 sqrt(m0)); see there for DNV's fit.
    gamma = 1 is the Pierson-Moskowitz spectrum. S = 0 at omega <= 0.
    """
    hs, tp, gamma = _check_sea(hs, tp, gamma)
    wp = 2.0 * np.pi / tp
    u = np.asarray(omega, dtype=float) / wp
    # S(w) dw = (Hs^2/16) A shape(u) du, du = dw / wp.
    return hs**2 / 16.0 * jonswap_normalization(gamma) * _jonswap_shape(u, gamma) / wp


# --------------------------------------------------------------------------------------------
# Response amplitude operators


def encounter_frequency(omega, beta, speed: float = 0.0) -> np.ndarray:
    """w_e = w - w^2 U cos(beta) / g, rad/s: the frequency at which a ship at speed U (m/s)
    meets waves of frequency w (rad/s) arriving from beta (rad; 180 deg = head seas).
    Negative in fast following seas (the ship overtakes the waves)."""
    omega = np.asarray(omega, dtype=float)
    return omega - omega**2 * speed * np.cos(beta) / GRAVITY


def _sinc(x):
    """sin(x) / x with the limit 1 at 0."""
    return np.sinc(np.asarray(x) / np.pi)


def _moment_sinc(x):
    """3 (sin x - x cos x) / x^3, the first-moment analogue of sin(x)/x; limit 1 at 0."""
    x = np.asarray(x, dtype=float)
    small = np.abs(x) < 1e-3
    xs = np.where(small, 1.0, x)
    exact = 3.0 * (np.sin(xs) - xs * np.cos(xs)) / xs**3
    return np.where(small, 1.0 - x**2 / 10.0, exact)


@dataclass(frozen=True)
class VesselRAO:
    """A generic mid-size ship (a ~100 m offshore supply / research vessel class) and its
    response amplitude operators (RAO) in regular waves.

    Attributes (defaults and their reasoning):
      length: 100 m between perpendiculars.
      beam: 16 m (L/B = 6.25, typical of this class).
      draft: 5 m (B/T = 3.2).
      block_coefficient: 0.6 (a fine-ish hull; Jensen et al. 2004 model the hull as a box of
        breadth C_B B).
      roll_period: natural roll period, 12 s. The IMO rolling-period formula
        T = 2 C B / sqrt(GM), C = 0.373 + 0.023 B/T - 0.043 L/100 (IMO IS Code 2008, 2.3.4)
        gives GM = 1.16 m for 12 s: an ordinary loaded condition (``metacentric_height``).
      roll_damping: equivalent linear damping ratio zeta of roll, 0.07: a hull with bilge keels
        at zero speed and moderate roll (ships lie roughly between 0.03 without bilge keels and
        0.1; forward speed raises it).
      wave_slope_coefficient: effective wave slope coefficient r of roll, 0.80: IMO IS Code
        2008, 2.3.4, r = 0.73 + 0.6 OG/d, OG the height of the centre of gravity above the
        waterline. Here KM ~ T/2 + B^2/(12 T) = 6.8 m (box section), KG = KM - GM = 5.6 m,
        OG = 0.6 m, so r = 0.80.
      yaw_coefficient: wave-frequency yaw as a fraction of the yaw a slender hull would have if
        it turned with the water along its length (see ``rao``), 0.4. The hull's lift, the rudder
        and the autopilot resist; 0.4 gives about 1 deg of wave-frequency yaw in 5 m
        bow-quartering seas (0.44 deg standard deviation), the order seen on ships this size.
    """

    length: float = 100.0
    beam: float = 16.0
    draft: float = 5.0
    block_coefficient: float = 0.6
    roll_period: float = 12.0
    roll_damping: float = 0.07
    wave_slope_coefficient: float = 0.80
    yaw_coefficient: float = 0.4

    def __post_init__(self):
        for name, unit in (("length", " m"), ("beam", " m"), ("draft", " m"), ("roll_period", " s")):
            _positive(f"vessel {name}", getattr(self, name), unit)
        # (name, lower limit, whether the lower limit itself is allowed, upper limit)
        for name, lo, closed, hi in (
            ("block_coefficient", 0.0, False, 1.0),
            ("roll_damping", 0.0, False, 1.0),
            ("wave_slope_coefficient", 0.0, False, 1.5),
            ("yaw_coefficient", 0.0, True, 1.0),
        ):
            value = _finite(f"vessel {name}", getattr(self, name))
            if not ((lo <= value if closed else lo < value) and value <= hi):
                bracket = "[" if closed else "("
                raise ShipMotionError(f"vessel {name} = {value:g} must be in {bracket}{lo:g}, {hi:g}]")

    @property
    def roll_frequency(self) -> float:
        """Natural roll frequency, rad/s."""
        return 2.0 * np.pi / self.roll_period

    @property
    def heave_frequency(self) -> float:
        """Natural heave and pitch frequency of the box model, sqrt(g / (2 T)), rad/s
        (added mass equal to the displaced mass; Jensen et al. 2004)."""
        return math.sqrt(GRAVITY / (2.0 * self.draft))

    @property
    def metacentric_height(self) -> float:
        """GM (m) that gives ``roll_period`` by the IMO rolling-period formula."""
        c = 0.373 + 0.023 * self.beam / self.draft - 0.043 * self.length / 100.0
        return (2.0 * c * self.beam / self.roll_period) ** 2

    def rao(self, omega, beta, speed: float = 0.0) -> np.ndarray:
        """Complex RAOs at wave frequencies omega (rad/s) and wave heading beta (rad), (..., 4).

        Columns in ``AXES`` order: heave (m per m of wave amplitude), heading (yaw), pitch,
        roll (rad per m). A regular wave of amplitude A, elevation A cos(w_e t + phi) at the
        ship's origin, gives the response A |RAO| cos(w_e t + phi + angle(RAO)), where
        w_e = ``encounter_frequency(omega, beta, speed)``.

        beta is where the waves come from, relative to the bow: 180 deg head seas, 90 deg beam
        seas from starboard, 0 following seas. In the ship frame a wave travels along
        d = (-sin beta, cos beta), so its slopes at the origin are
        d(eta)/dx = -A k sin(beta) sin(...) and d(eta)/dy = A k cos(beta) sin(...), k = w^2/g.
        A hull that followed the water surface would pitch by d(eta)/dy and roll by -d(eta)/dx
        (positive roll lowers starboard): both are 90 deg out of phase with the elevation.

        Heave and pitch: the closed-form expressions of Jensen, Mansour & Olsen (2004),
        "Estimation of ship motions using closed-form expressions", Ocean Engineering 31,
        61-85, for a homogeneously loaded box of length L, breadth B_e = C_B B, draft T:
          alpha = w_e / w, k_e = |k cos beta|, kappa = exp(-k T),
          A = 2 sin(k B_e alpha^2 / 2) exp(-k T alpha^2)     (sectional damping),
          f = sqrt((1 - k T)^2 + (A^2 / (k B_e alpha^3))^2)   (excitation incl. diffraction),
          F = kappa f sin(k_e L/2) / (k_e L/2),
          G = kappa f k_e 3 (sin x - x cos x) / x^3, x = k_e L / 2,
          eta = 1 / (1 - 2 k T alpha^2 + i A^2 / (k B_e alpha^2))  (heave/pitch oscillator),
          heave = eta F,  pitch = sign(cos beta) eta G e^{-i pi/2}.
        The amplitudes |eta F|, |eta G| are Jensen et al.'s; the phase is that of the
        oscillator eta (its damping term taken odd in w_e) on the excitation, which is taken in
        phase with the elevation (heave) or the slope (pitch): the small phase of f is dropped.
        The depth factor kappa uses the full wave number (a wave's pressure decays as e^{k z}
        whatever its direction), as DTU's NetSSE does; Fossen's MSS (waveresponse345.m) uses
        k_e there. Limits: heave -> 1 and pitch -> the wave slope k cos(beta) for long waves;
        pitch = 0 in beam seas.

        Roll: a damped one-degree-of-freedom oscillator driven by the effective wave slope
        (Bhattacharyya 1978, Dynamics of Marine Vehicles; the IMO weather criterion's r), with
        the slope averaged across the beam and along the length:
          roll = r k sin(beta) sinc(k sin(beta) B/2) sinc(k cos(beta) L/2) H(w_e) e^{-i pi/2},
          H = 1 / (1 - (w_e/w_r)^2 + 2 i zeta w_e / w_r),  w_r = 2 pi / T_roll.
        It peaks near w_r, vanishes in head and following seas and for long waves follows r
        times the wave slope.

        Yaw: the wave-frequency yaw of a slender hull that turned with the water along its
        length (inertia-dominated, the Froude-Krylov sway force of the water's horizontal
        acceleration, moment about midships over the yaw inertia of a uniform hull):
          yaw = -c_yaw k sin(beta) cos(beta) 3 (sin x - x cos x) / x^3,  x = k cos(beta) L/2,
        in phase with the elevation; zero in head, following and beam seas, largest in
        quartering and bow-quartering seas. c_yaw = ``yaw_coefficient`` (< 1: lift, rudder and
        autopilot resist). This is a documented order-of-magnitude model, not a hull's data.

        At Hs = 5 m, Tp = 10 s, gamma = 3.3, beta = 135 deg, zero speed (``SeaStateMotion``
        with the defaults) the spectral standard deviations are roll 2.6 deg, pitch 1.7 deg,
        yaw 0.44 deg, heave 0.78 m: significant double amplitudes (4 sigma) roll 10.5 deg,
        pitch 6.7 deg. Over 300 s records (median of 20 seeds) the largest values reached are
        roll 7.2 deg, pitch 4.7 deg, yaw 1.2 deg, heave 2.1 m.
        """
        omega = np.asarray(omega, dtype=float)
        beta = np.asarray(beta, dtype=float)
        speed = _finite("ship speed", speed, " m/s")
        omega, beta = np.broadcast_arrays(omega, beta)
        w = np.maximum(omega, 1e-12)
        k = w**2 / GRAVITY
        cb, sb = np.cos(beta), np.sin(beta)
        w_e = encounter_frequency(w, beta, speed)
        alpha = w_e / w
        L, T = self.length, self.draft
        B_e = self.block_coefficient * self.beam

        # Heave and pitch (Jensen et al. 2004), written with s = sin(a)/a, a = k B_e alpha^2/2,
        # so nothing divides by alpha (alpha -> 0 in fast following seas):
        #   A = k B_e alpha^2 s E, A^2/(k B_e alpha^2) = k B_e alpha^2 s^2 E^2,
        #   A^2/(k B_e alpha^3) = k B_e alpha s^2 E^2, E = exp(-k T alpha^2).
        s = _sinc(0.5 * k * B_e * alpha**2)
        e = np.exp(-k * T * alpha**2)
        damping = k * B_e * alpha**2 * s**2 * e**2
        f = np.hypot(1.0 - k * T, k * B_e * alpha * s**2 * e**2)
        kappa = np.exp(-k * T)
        x = 0.5 * k * np.abs(cb) * L
        eta = 1.0 / (1.0 - 2.0 * k * T * alpha**2 + 1j * np.sign(alpha) * damping)
        heave = eta * kappa * f * _sinc(x)
        pitch = eta * kappa * f * (k * cb) * _moment_sinc(x) * (-1j)

        # Roll: effective wave slope through a damped oscillator.
        r = w_e / self.roll_frequency
        h_roll = 1.0 / (1.0 - r**2 + 2j * self.roll_damping * r)
        slope = k * sb * _sinc(0.5 * k * sb * self.beam) * _sinc(0.5 * k * cb * L)
        roll = self.wave_slope_coefficient * slope * h_roll * (-1j)

        # Yaw: the hull turning with the water along its length.
        yaw = -self.yaw_coefficient * k * sb * cb * _moment_sinc(x) + 0j

        out = np.stack([heave, yaw, pitch, roll], axis=-1)
        return np.where((omega > 0.0)[..., None], out, np.array([1.0, 0.0, 0.0, 0.0]))


# --------------------------------------------------------------------------------------------
# Sea-state motion


def _uniform_step(t: np.ndarray) -> float | None:
    """The step of an evenly spaced time grid (to within rounding of its times), else None."""
    if t.size < 3:
        return None
    step = (t[-1] - t[0]) / (t.size - 1)
    if step <= 0.0:
        return None
    grid = t[0] + np.arange(t.size) * step
    if np.max(np.abs(t - grid)) > 1e-12 * max(1.0, float(np.max(np.abs(t)))):
        return None
    return float(step)


class SeaStateMotion:
    """Ship motion in a long-crested JONSWAP sea: a sum of regular waves through the RAOs.

    Per axis (REFERENCE.md, "Ship antenna"; Fossen, MSS):
      x(t) = sum_k |RAO(w_k)| a_k cos(w_e,k t + angle RAO(w_k) + phi_k),
      a_k = sqrt(2 S(w_k) dw),
    with one phase phi_k per wave component shared by all four axes (the same wave drives
    heave, yaw, pitch and roll). heading psi = course + yaw response.

    The components cover [omega_min, omega_max] in ``n_components`` equal bins of width dw;
    each frequency is drawn uniformly inside its bin, so the record does not repeat with the
    period 2 pi / dw of an equally spaced sum (a 300 s run sees no repetition). Draws from
    ``rng``, in order: n_components frequency offsets, then n_components phases, both uniform.

    Args:
      hs: significant wave height, m (> 0).
      tp: peak period, s (> 0).
      heading_deg: wave heading beta relative to the bow, deg: 180 head seas, 90 beam seas
        from starboard, 0 following seas (``VesselRAO.rao``).
      rng: numpy Generator for the frequencies and phases.
      gamma: JONSWAP peak enhancement (>= 1; 3.3 North Sea mean, 1 Pierson-Moskowitz).
      vessel: the ship's RAO parameters.
      speed: ship speed U, m/s (>= 0); the motion then oscillates at the encounter frequencies.
      course_deg: the ship's mean heading psi0, deg, in the paper's convention
        (counter-clockwise from north: a compass course C is course_deg = -C).
      n_components: number of wave components (default 400).
      omega_min, omega_max: frequency range, rad/s; default 0.5 and 5 times the peak frequency
        2 pi / Tp, which holds all but about 0.3 % of the wave variance (the high-frequency
        tail, too short to move a ship).
    """

    def __init__(
        self,
        hs: float,
        tp: float,
        heading_deg: float,
        rng: np.random.Generator,
        gamma: float = 3.3,
        vessel: VesselRAO | None = None,
        speed: float = 0.0,
        course_deg: float = 0.0,
        n_components: int = 400,
        omega_min: float | None = None,
        omega_max: float | None = None,
    ):
        self.hs, self.tp, self.gamma = _check_sea(hs, tp, gamma)
        #: Wave heading beta relative to the bow, rad.
        self.wave_heading = math.radians(_finite("wave heading heading_deg", heading_deg, " deg"))
        #: Mean ship heading psi0, rad.
        self.course = math.radians(_finite("course course_deg", course_deg, " deg"))
        self.speed = _finite("ship speed", speed, " m/s")
        if self.speed < 0.0:
            raise ShipMotionError(f"ship speed = {self.speed:g} m/s must be >= 0")
        if not isinstance(rng, np.random.Generator):
            raise TypeError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
        if isinstance(n_components, bool) or int(n_components) != n_components or n_components < 1:
            raise ShipMotionError(f"n_components = {n_components!r} must be an integer >= 1")
        self.vessel = VesselRAO() if vessel is None else vessel
        wp = 2.0 * np.pi / self.tp
        lo = 0.5 * wp if omega_min is None else _positive("omega_min", omega_min, " rad/s")
        hi = 5.0 * wp if omega_max is None else _finite("omega_max", omega_max, " rad/s")
        if hi <= lo:
            raise ShipMotionError(f"omega_max = {hi:g} rad/s must be > omega_min = {lo:g} rad/s")
        n = int(n_components)
        self.omega_min, self.omega_max = lo, hi
        self.d_omega = (hi - lo) / n
        #: Wave frequencies w_k, rad/s, one drawn uniformly in each bin.
        self.omega = lo + (np.arange(n) + rng.uniform(0.0, 1.0, n)) * self.d_omega
        #: Phases phi_k, rad.
        self.phase = rng.uniform(0.0, 2.0 * np.pi, n)
        #: Wave amplitudes a_k = sqrt(2 S(w_k) dw), m.
        self.amplitude = np.sqrt(2.0 * jonswap_spectrum(self.omega, self.hs, self.tp, self.gamma) * self.d_omega)
        #: Encounter frequencies, rad/s.
        self.omega_e = encounter_frequency(self.omega, self.wave_heading, self.speed)
        #: Complex RAOs at the components, (n, 4) in ``AXES`` order.
        self.rao = self.vessel.rao(self.omega, self.wave_heading, self.speed)
        # cos(w_e t + phi + theta) = cos(w_e t + phi) cos(theta) - sin(w_e t + phi) sin(theta):
        # per axis, x = C @ Re(c) - S @ Im(c) with c = a |RAO| e^{i theta}; the derivatives
        # bring down factors of w_e. Columns: [positions, rates, accelerations] x 4 axes.
        c = self.amplitude[:, None] * self.rao
        we = self.omega_e[:, None]
        self._cos_weights = np.hstack([c.real, -we * c.imag, -(we**2) * c.real])
        self._sin_weights = np.hstack([-c.imag, -we * c.real, we**2 * c.imag])

    @property
    def peak_frequency(self) -> float:
        """omega_p = 2 pi / Tp, rad/s."""
        return 2.0 * np.pi / self.tp

    def wave_variance(self) -> float:
        """Variance of ``wave_elevation`` implied by the components, sum a_k^2 / 2, m^2
        (Hs^2 / 16 less the part of the spectrum outside the frequency range)."""
        return float(np.sum(self.amplitude**2) / 2.0)

    def standard_deviation(self) -> np.ndarray:
        """Spectral standard deviation of each axis, (4,) in ``AXES`` order (m, rad):
        sqrt(sum_k |RAO_k|^2 a_k^2 / 2). For heading, that of the yaw response about the
        course."""
        return np.sqrt(np.sum(np.abs(self.rao) ** 2 * self.amplitude[:, None] ** 2, axis=0) / 2)

    def _sum(self, t: np.ndarray, cos_weights: np.ndarray, sin_weights: np.ndarray):
        """sum_k [cos(w_e,k t + phi_k) cos_weights[k] + sin(...) sin_weights[k]], (n_t, m).

        Evaluated in blocks of times so the (times x components) tables stay within
        ``_BLOCK_ELEMENTS``. On a uniform grid (a run's control ticks) each block is
        e^{i (w_e t_b + phi)} (exact, at the block's first time t_b) times one shared table
        e^{i w_e j dt}: a complex product in place of a cosine and a sine per element, about
        4 times faster (300 s at 1 kHz with 400 components: 0.6 s against 2.6 s here) and equal
        to the direct sum to rounding (tested).
        """
        out = np.empty((t.size, cos_weights.shape[1]))
        rows = max(1, _BLOCK_ELEMENTS // self.omega.size)
        # Re(e^{i a} (C - i S)) = C cos a + S sin a.
        weights = cos_weights - 1j * sin_weights
        step = _uniform_step(t)
        if step is not None and t.size > rows:
            table = np.exp(1j * np.multiply.outer(np.arange(rows) * step, self.omega_e))
            for start in range(0, t.size, rows):
                m = min(rows, t.size - start)
                first = np.exp(1j * (t[start] * self.omega_e + self.phase))
                out[start : start + m] = ((table[:m] * first) @ weights).real
            return out
        for start in range(0, t.size, rows):
            arg = np.multiply.outer(t[start : start + rows], self.omega_e)
            arg += self.phase
            out[start : start + rows] = np.cos(arg) @ cos_weights + np.sin(arg) @ sin_weights
        return out

    def sample(self, t) -> ShipState:
        """ShipState at times t (s, scalar or (n,)), with exact derivatives of the sum."""
        t = _times(t)
        out = self._sum(t, self._cos_weights, self._sin_weights)
        pos, rate, accel = out[:, :4], out[:, 4:8], out[:, 8:]
        return ShipState(
            t=t,
            heave=pos[:, HEAVE].copy(),
            heading=self.course + pos[:, HEADING],
            pitch=pos[:, PITCH].copy(),
            roll=pos[:, ROLL].copy(),
            rate=rate.copy(),
            accel=accel.copy(),
        )

    def wave_elevation(self, t) -> np.ndarray:
        """Wave elevation at the ship's origin, m, (n,): sum_k a_k cos(w_e,k t + phi_k).

        The origin moves with the ship, so the elevation oscillates at the encounter
        frequencies (the absolute ones at zero speed). Its variance is ``wave_variance``.
        """
        t = _times(t)
        return self._sum(t, self.amplitude[:, None], np.zeros((self.omega.size, 1)))[:, 0]
