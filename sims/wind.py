"""Wind: a mean speed plus one-point turbulence, and the drag it puts on a body.

Spectra (REFERENCE.md, "Wind"):
  Kaimal (IEC 61400-1): S(f) = 4 sigma^2 (L/U) / (1 + 6 f L/U)^(5/3),
                        sigma = I_ref (0.75 U + 5.6), L = 8.1 * 42 m = 340.2 m.
  Davenport:            S(n) = 4 kappa U10^2 x^2 / (n (1 + x^2)^(4/3)), x = 1200 n / U10,
                        kappa = 0.005.
One-point series: u(t) = U + sum_k sqrt(2 S(f_k) df) cos(2 pi f_k t + phi_k), phi_k uniform
on [0, 2 pi) from the run's seed, f_k = k df.

The series is computed for every control tick before the run; per tick the disturbance only
writes ``data.xfrc_applied`` (drag F = 1/2 rho Cd A |u| u along the wind direction, at the
body's centre of mass). Spatial coherence over the body (aerodynamic admittance) is left out:
one point's gusts act on the whole body, which overstates the load of the shortest gusts.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from planbench.run_limits import ANGLE_LIMIT_DEG

AIR_DENSITY = 1.2  # kg/m^3; about 1.0 at Rubin's 2700 m and FAST's 1000 m: conservative
#: Largest mean wind speed accepted, m/s: the reference wind speed V_ref of IEC 61400-1
#: (ed. 3, 2005) class I, the 10-min mean 50-year extreme of the windiest class of the
#: standard whose Kaimal turbulence model this module uses. Beyond it the turbulence model
#: (and any telescope) is outside its range.
MAX_MEAN_SPEED_M_S = 50.0
#: The range of a mean wind speed parameter (``planbench.params.param`` keywords), m/s.
MEAN_SPEED = dict(
    unit="m/s", low=0.0, high=MAX_MEAN_SPEED_M_S, reason="IEC 61400-1 class I reference speed, the Kaimal model's range"
)
IEC_KAIMAL_LENGTH = 8.1 * 42.0  # m, IEC 61400-1 longitudinal integral scale above 60 m hub
IEC_TURBULENCE_B = 0.14  # I_ref of IEC class B


def check_mean_speed(mean_speed: float) -> float:
    """The mean wind speed (m/s) if it is finite and in [0, MAX_MEAN_SPEED_M_S], else a
    ValueError naming the value and the limit."""
    value = float(mean_speed)
    if not np.isfinite(value) or value < 0:
        raise ValueError(f"mean wind speed {mean_speed!r} m/s must be finite and >= 0")
    if value > MAX_MEAN_SPEED_M_S:
        raise ValueError(
            f"mean wind speed {value:g} m/s is above {MAX_MEAN_SPEED_M_S:g} m/s, the "
            "reference wind speed of IEC 61400-1 class I (the Kaimal model's range)"
        )
    return value


def horizontal_direction(azimuth_deg: float) -> np.ndarray:
    """The unit vector (3,) of a horizontal direction given as an azimuth, deg from +x toward +y."""
    az = math.radians(azimuth_deg)
    return np.array([math.cos(az), math.sin(az), 0.0])


def kaimal_spectrum(
    f, mean_speed: float, turbulence_ref: float = IEC_TURBULENCE_B, length_scale: float = IEC_KAIMAL_LENGTH
) -> np.ndarray:
    """One-sided Kaimal spectrum of the along-wind speed, (m/s)^2/Hz, at frequencies f (Hz)."""
    f = np.asarray(f, dtype=float)
    if mean_speed <= 0:
        return np.zeros_like(f)
    sigma = turbulence_ref * (0.75 * mean_speed + 5.6)
    scale = length_scale / mean_speed
    return 4.0 * sigma**2 * scale / (1.0 + 6.0 * f * scale) ** (5.0 / 3.0)


def davenport_spectrum(f, mean_speed_10m: float, kappa: float = 0.005) -> np.ndarray:
    """One-sided Davenport spectrum, (m/s)^2/Hz, at frequencies f > 0 (Hz)."""
    f = np.asarray(f, dtype=float)
    if mean_speed_10m <= 0:
        return np.zeros_like(f)
    x = 1200.0 * f / mean_speed_10m
    return 4.0 * kappa * mean_speed_10m**2 * x**2 / (f * (1.0 + x**2) ** (4.0 / 3.0))


SPECTRA: dict[str, Callable] = {"kaimal": kaimal_spectrum, "davenport": davenport_spectrum}


def wind_speed_series(
    times: np.ndarray,
    mean_speed: float,
    rng: np.random.Generator,
    spectrum: str = "kaimal",
    f_max: float = 10.0,
    df: float | None = None,
    turbulence_intensity: float | None = None,
) -> np.ndarray:
    """Along-wind speed u(t), m/s, at the given times (s): mean plus turbulence.

    Args:
      spectrum: "kaimal" or "davenport".
      f_max: highest frequency of the sum, Hz (gusts shorter than ~0.1 s carry little energy
        and act on a fraction of a body a metre across).
      df: frequency step, Hz; default the smaller of 1 / (run length) and 1/600 Hz, so a short
        run still sees the slow part of the turbulence (most of a Kaimal spectrum's energy
        lies below 0.01 Hz) as a slowly drifting speed.
      turbulence_intensity: sigma_u / U of the series; None: the spectrum's own (Kaimal:
        IEC 61400-1 class B, I_ref (0.75 U + 5.6) / U). Given, the spectrum's shape is kept
        and its amplitudes scaled so that the sum's variance sum_k a_k^2 / 2 is (I U)^2.
    """
    check_mean_speed(mean_speed)
    if spectrum not in SPECTRA:
        raise ValueError(f"wind spectrum {spectrum!r} is not one of {', '.join(SPECTRA)}")
    times = np.asarray(times, dtype=float)
    if mean_speed == 0:
        return np.zeros_like(times)
    span = float(times[-1] - times[0]) if times.size > 1 else 1.0
    if df is None:
        df = min(1.0 / max(span, 1e-9), 1.0 / 600.0)
    freqs = np.arange(1, int(np.floor(f_max / df)) + 1) * df
    amplitude = np.sqrt(2.0 * SPECTRA[spectrum](freqs, mean_speed) * df)
    if turbulence_intensity is not None:
        variance = 0.5 * float(np.sum(amplitude**2))
        amplitude = amplitude * (turbulence_intensity * mean_speed / np.sqrt(variance))
    phases = rng.uniform(0.0, 2.0 * np.pi, freqs.size)
    return mean_speed + _sum_of_cosines(times, freqs, amplitude, phases, df)


def _sum_of_cosines(times, freqs, amplitude, phases, df) -> np.ndarray:
    """sum_k amplitude_k cos(2 pi f_k t + phase_k) at the times, with f_k = k df.

    On a uniform time grid whose step divides the period 1/df this is one inverse real FFT
    of length N = 1/(df dt) (the direct sum costs times x frequencies); otherwise the sum is
    evaluated directly. Both give the same series to rounding (tested).
    """
    if times.size > 1:
        dt = float(times[1] - times[0])
        n_period = 1.0 / (df * dt)
        n = int(round(n_period))
        uniform = np.allclose(np.diff(times), dt, rtol=0, atol=1e-9 * max(dt, 1e-12))
        if uniform and abs(n_period - n) < 1e-6 * n and freqs.size < n // 2:
            spectrum = np.zeros(n // 2 + 1, dtype=complex)
            k = np.arange(1, freqs.size + 1)
            shift = 2 * np.pi * freqs * times[0]  # the grid starts at times[0], not 0
            spectrum[k] = 0.5 * n * amplitude * np.exp(1j * (phases + shift))
            # The sum is periodic in 1/df = n steps: longer grids wrap around.
            return np.fft.irfft(spectrum, n)[np.arange(times.size) % n]
    out = np.zeros(times.shape)
    # Blocks of times keep the (times x frequencies) cosine table small.
    for start in range(0, times.size, 4096):
        block = times[start : start + 4096]
        out[start : start + 4096] = np.cos(2 * np.pi * np.outer(block, freqs) + phases) @ amplitude
    return out


def drag_force(speed, direction, area, drag_coefficient: float, density: float = AIR_DENSITY) -> np.ndarray:
    """F = 1/2 rho Cd A |u| u along ``direction`` (a unit vector), N; speed (...,) m/s."""
    speed = np.asarray(speed, dtype=float)
    return (0.5 * density * drag_coefficient * np.asarray(area) * np.abs(speed) * speed)[..., None] * np.asarray(
        direction, dtype=float
    )


def cylinder_projected_area(axis, direction, diameter: float, length: float) -> np.ndarray:
    """Area (m^2) of a cylinder seen along ``direction``: D L |sin t| + pi D^2 / 4 |cos t|."""
    cos_t = np.abs(np.sum(np.asarray(axis) * np.asarray(direction), axis=-1))
    sin_t = np.sqrt(np.clip(1.0 - cos_t**2, 0.0, None))
    return diameter * length * sin_t + np.pi * diameter**2 / 4.0 * cos_t


class BodyWindDrag:
    """Disturbance: drag of a turbulent wind on one body (``data.xfrc_applied``).

    The force acts at the body's centre of mass, along a horizontal world direction given by
    the azimuth it blows *toward* (deg from +x toward +y). ``area`` is a function of the
    physics that returns the body's projected area normal to the wind (m^2), evaluated once
    per tick, so a tilting body sees its true silhouette.
    """

    def __init__(
        self,
        body: str,
        mean_speed: float,
        area: Callable,
        drag_coefficient: float,
        azimuth_deg: float = 0.0,
        spectrum: str = "kaimal",
    ):
        check_mean_speed(mean_speed)
        self.body = body
        self.mean_speed = float(mean_speed)
        self.area = area
        self.drag_coefficient = float(drag_coefficient)
        self.direction = horizontal_direction(azimuth_deg)
        self.spectrum = spectrum
        self.speed = None
        self.force = None
        self._id = None

    def reset(self, physics, times: np.ndarray, rng: np.random.Generator) -> None:
        self.speed = wind_speed_series(times, self.mean_speed, rng, self.spectrum)
        self.force = np.zeros((times.size, 3))
        self._id = physics.model.ptr.body(self.body).id
        self._half_rho_cd = 0.5 * AIR_DENSITY * self.drag_coefficient
        self._xfrc = physics.data.ptr.xfrc_applied[self._id, :3]  # a view: written in place

    def __call__(self, tick: int, physics) -> None:
        # drag_force on scalars (the per-tick cost matters in the loop; the tests compare the
        # logged force with drag_force).
        u = float(self.speed[tick])
        row = self.force[tick]
        np.multiply(self.direction, self._half_rho_cd * self.area(physics) * abs(u) * u, out=row)
        self._xfrc[:] = row


#: Largest |direction| (deg) a wind file may give: one turn either way, as every angle parameter.
MAX_DIRECTION_DEG = ANGLE_LIMIT_DEG


class WindFileError(ValueError):
    """A measured wind file that cannot be read or is not a wind record."""


class MeasuredWind:
    """A measured wind record: times (s), speed (m/s) and optionally the direction it blows
    toward (deg from +x toward +y), from a CSV file of rows ``t, speed[, direction]`` (a header
    line of names is allowed). Resampled to the control ticks by linear interpolation
    (``resample``); the direction is interpolated on the unit circle.

    Raises WindFileError naming the file, the row and the reason: fewer than two rows, times
    not increasing, a speed outside [0, MAX_MEAN_SPEED_M_S], a direction beyond +/-360 deg
    (``MAX_DIRECTION_DEG``: angles are not wrapped), a value that is not a number.
    """

    def __init__(self, path):
        from pathlib import Path

        self.path = Path(path)
        try:
            text = self.path.read_text()
        except (OSError, UnicodeDecodeError) as e:
            raise WindFileError(f"wind file {self.path}: cannot be read ({e.__class__.__name__}: {e})") from None
        rows, header_seen = [], False
        for number, line in enumerate(text.splitlines(), start=1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            cells = [c.strip() for c in line.split(",")]
            try:
                values = [float(c) for c in cells]
            except ValueError:
                if not rows and not header_seen:  # one header line of names before the data
                    header_seen = True
                    continue
                raise WindFileError(
                    f"wind file {self.path} line {number}: {line!r} is not numbers t, speed[, direction]"
                ) from None
            if len(values) not in (2, 3):
                raise WindFileError(
                    f"wind file {self.path} line {number}: {len(values)} columns, not 2 or 3 "
                    "(t s, speed m/s[, direction deg])"
                )
            if rows and len(values) != len(rows[0]):
                raise WindFileError(
                    f"wind file {self.path} line {number}: {len(values)} columns, the first row has {len(rows[0])}"
                )
            if not all(np.isfinite(values)):
                raise WindFileError(f"wind file {self.path} line {number}: {line!r} is not finite")
            if not 0.0 <= values[1] <= MAX_MEAN_SPEED_M_S:
                raise WindFileError(
                    f"wind file {self.path} line {number}: speed {values[1]:g} m/s is outside "
                    f"[0, {MAX_MEAN_SPEED_M_S:g}] m/s (IEC 61400-1 class I)"
                )
            if len(values) == 3 and not -MAX_DIRECTION_DEG <= values[2] <= MAX_DIRECTION_DEG:
                raise WindFileError(
                    f"wind file {self.path} line {number}: direction {values[2]:g} deg is outside "
                    f"[-{MAX_DIRECTION_DEG:g}, {MAX_DIRECTION_DEG:g}] deg (one turn either way; "
                    "angles are not wrapped)"
                )
            if rows and values[0] <= rows[-1][0]:
                raise WindFileError(f"wind file {self.path} line {number}: t = {values[0]:g} s does not increase")
            rows.append(values)
        if len(rows) < 2:
            raise WindFileError(f"wind file {self.path}: {len(rows)} rows of t, speed[, direction]; at least 2")
        table = np.array(rows)
        self.t, self.speed = table[:, 0], table[:, 1]
        self.direction = table[:, 2] if table.shape[1] == 3 else None

    def check_covers(self, duration: float) -> None:
        """A WindFileError unless the record spans the run, t = 0 ... duration."""
        if self.t[0] > 0.0 or self.t[-1] < duration:
            raise WindFileError(
                f"wind file {self.path} spans t = {self.t[0]:g} ... {self.t[-1]:g} s, not the run's "
                f"0 ... {duration:g} s"
            )

    def resample(self, times: np.ndarray):
        """(speed (n,), unit direction (n, 3) or None) at ``times``."""
        speed = np.interp(times, self.t, self.speed)
        if self.direction is None:
            return speed, None
        az = np.radians(self.direction)
        c, s = np.interp(times, self.t, np.cos(az)), np.interp(times, self.t, np.sin(az))
        norm = np.hypot(c, s)
        norm[norm == 0.0] = 1.0
        return speed, np.column_stack([c / norm, s / norm, np.zeros_like(c)])
