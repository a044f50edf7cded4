"""FAST's parameters: the plant's uncertainty (``FastPlant``) and the scenarios' parameters
(``FastParams`` and its sessions: tracking, a motion scan, a source switch), with the source
catalogue and the defaults they declare."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

import models
from planners import fast
from planners.fast import plan as fp
from planners.fast import sky as sky
from sims import run_limits
from sims.fast.loads import CableLoads, ChainCableLoads
from sims.drives import DRIVES
from sims.fast.measurement import SensorOptions, floats_per_tick
from sims.fast.physics import (CABLE_EA, CONTROL_DT, LEG_ACTUATORS, PHYSICS_DT, SEGMENT_OMEGA_DT_LIMIT, _compiled,
                               discretized_spec, max_cable_segments)
from sims.params import ParamError, PlantParams, ScenarioParams, param
from sims.plant import set_inertial
from sims.wind import MEAN_SPEED, SPECTRA, MeasuredWind, WindFileError


# ----------------------------------------------------------------------------- plant uncertainty

#: Everything the cabin carries, 30 091.8 kg (CASPR, REFERENCE.md): the shell and structure,
#: the A-B rotator, the Stewart legs, the feed platform and the receiver (models/fast/README.md).
#: The lumped cable masses (anchor_mass*) belong to the cables.
CABIN_BODIES = ("cabin", "ab_a", "ab_b", *(f"leg{i}_{part}" for i in range(1, 7) for part in ("housing", "rod")),
                "feed_platform", "receiver")
#: What bounds the tower tops' errors (assumed; no public figure): their survey and construction
#: tolerance, the guide pulleys' exit points, the >100 m towers' deflection under the cables'
#: pull (the model's towers are rigid): tens of mm; 0.1 m bounds it.
_TOWER_ERROR = dict(unit="mm", low=-100.0, high=100.0,
                    reason="survey and construction tolerance of the tower tops, the pulleys' exit points and the "
                           "towers' deflection under load: tens of mm (assumed); 0.1 m bounds it")


@dataclass(frozen=True)
class FastPlant(PlantParams):
    """FAST's plant uncertainty: how the real feed support differs from models/fast and the
    planner's FastGeometry, which the controller keeps (models/fast/README.md, "Plant
    uncertainty").

    Where each one acts: the tower tops, the cabin's masses and centre of mass, the lumped
    cable masses (``anchor_mass*``) and the Stewart legs' force limits edit the MJCF (MjSpec)
    before compiling (``spec``); the cables' EA and weight per length are constants of the
    plant's Python-side cable physics (``CableLoads``, ``ChainCableLoads``: the catenary law,
    the applied half cable weights, the chain's springs and node masses). The controller's
    winch feed-forward keeps the nominal EA and weight (``winch_feedforward``), its statics the
    nominal masses (planners.fast.FAST). A perturbed plant starts where its own static
    equilibrium lies under the nominal parked commands (``perturbed_start``).
    """

    cable_ea_error: float = param(
        0.0, f"error of the cables' axial stiffness EA ({CABLE_EA / 1e6:g} MN nominal) as a fraction", "fraction",
        low=-0.35, high=0.10, reason="steel wire rope's effective modulus is 100-160 GPa (REFERENCE.md): -33 % to "
        "+7 % of the nominal 150 GPa, rounded out")
    cable_mass_error: float = param(
        0.0, f"error of the cables' mass per length ({fast.FAST.cable_mass_per_length:g} kg/m nominal) as a fraction",
        "fraction", low=-0.2, high=0.2, reason="46 mm steel wire ropes weigh about 8.5 (six-strand) to 12 kg/m "
        "(locked coil) (rope makers' tables, assumed), +/-20 % of 10 kg/m")
    anchor_radial_error: float = param(
        0.0, "every tower top's cable exit moved outward (away from the dish axis) by this", **_TOWER_ERROR)
    anchor_height_error: float = param(0.0, "every tower top's cable exit moved up by this", **_TOWER_ERROR)
    anchor_errors: tuple[tuple[float, ...], ...] = param(
        ((0.0, 0.0, 0.0),) * 6, "each tower top's cable exit moved by (x east, y north, z up), one row per tower 1-6, "
        "added to anchor_radial_error and anchor_height_error", length=3, min_items=6, max_items=6, **_TOWER_ERROR)
    cabin_mass_error: float = param(
        0.0, "error of the mass and inertia of everything the cabin carries (30 091.8 kg: shell, A-B rotator, "
        "Stewart, feed platform, receiver) as a fraction, every part alike", "fraction", low=-0.1, high=0.1,
        reason="CASPR's 30 091.8 kg against the public '30 t'; receivers and equipment change (assumed +/-10 %)")
    cabin_com_offset: tuple[float, ...] = param(
        (0.0, 0.0, 0.0), "shift of the whole cabin's centre of mass (the shell's moves by the cabin's mass over the "
        "shell's, 1.295 times this), cabin frame (x, y, z)", "m", low=-0.5, high=0.5, length=3,
        reason="its place 1 m below the anchor plane is an assumption (planners.fast); 0.5 m, under a tenth of the "
        "cabin's 7.6 m height and 13 m diameter (assumed)")
    stewart_force_scale: float = param(
        1.0, "the Stewart legs' force limits as a fraction of their +/-30 kN rating", "fraction", low=0.5, high=1.0,
        reason="the rating is what a drive guarantees; derating (heat, supply voltage) only lowers it; half still "
        "carries the legs' largest static load, 12.4 kN (models/fast/README.md)")

    @property
    def cable_ea(self) -> float:
        """The true cables' EA, N."""
        return CABLE_EA * (1.0 + self.cable_ea_error)

    @property
    def cable_mass_per_length(self) -> float:
        """The true cables' mass per length, kg/m."""
        return fast.FAST.cable_mass_per_length * (1.0 + self.cable_mass_error)

    def tower_top_errors(self) -> np.ndarray:
        """(6, 3) how far each tower top's cable exit lies from its design position, m (world):
        radially outward, up, and the per-tower table."""
        radial = fast.FAST.tower_anchors[:, :2] / np.linalg.norm(fast.FAST.tower_anchors[:, :2], axis=1)[:, None]
        error = np.asarray(self.anchor_errors, dtype=float).copy()
        error[:, :2] += self.anchor_radial_error * radial
        error[:, 2] += self.anchor_height_error
        return 1e-3 * error

    def spec(self) -> mujoco.MjSpec:
        """models/fast/scene.xml edited into this plant (MjSpec): site_pos of ``tower{i}_top``
        moved by ``tower_top_errors`` (the towers' bodies are not rotated); body_mass and
        body_inertia of CABIN_BODIES times (1 + cabin_mass_error) (explicit inertials, the
        same centres of mass and principal axes); the shell's (``cabin``) body_ipos moved by
        cabin_com_offset times the cabin's mass over the shell's (the whole cabin's centre
        of mass moves by cabin_com_offset); body_mass of ``anchor_mass1..3`` (a third of two
        cables' mass each) times (1 + cable_mass_error); actuator_forcerange of the legs times
        stewart_force_scale. MuJoCo derives the rest (subtree masses, qM at qpos0, the cable
        tendons' lengths at qpos0) from them."""
        nominal = _compiled(0)
        spec = mujoco.MjSpec.from_file(str(models.scene_path("fast")))
        for i, error in enumerate(self.tower_top_errors(), start=1):
            site = spec.site(f"tower{i}_top")
            site.pos = nominal.site_pos[nominal.site(f"tower{i}_top").id] + error
        ids = [nominal.body(b).id for b in CABIN_BODIES]
        ratio = nominal.body_mass[ids].sum() / nominal.body_mass[nominal.body("cabin").id]
        for body in CABIN_BODIES:
            set_inertial(spec, nominal, body, 1.0 + self.cabin_mass_error,
                         ratio * np.asarray(self.cabin_com_offset) if body == "cabin" else None)
        for i in range(1, 4):
            spec.body(f"anchor_mass{i}").mass = nominal.body_mass[nominal.body(f"anchor_mass{i}").id] * (
                1.0 + self.cable_mass_error)
        for name in LEG_ACTUATORS:
            spec.actuator(name).forcerange = nominal.actuator_forcerange[nominal.actuator(name).id] * \
                self.stewart_force_scale
        return spec

    def model(self, cable_segments: int = 0) -> mujoco.MjModel:
        """The plant's compiled model (``spec``); ``cable_segments`` >= 2: with its cables
        discretized (``discretized_spec``, with this plant's EA and mass per length)."""
        spec = self.spec()
        if cable_segments:
            spec = discretized_spec(cable_segments, spec, self.cable_ea, self.cable_mass_per_length)
        return spec.compile()

    def loads(self, cable_segments: int = 0, **wind) -> "CableLoads":
        """The plant's cable physics and wind (CableLoads, or ChainCableLoads for the
        discretized cables) with this plant's EA and mass per length; ``wind``: CableLoads'
        wind arguments."""
        kind = ChainCableLoads if cable_segments else CableLoads
        return kind(**wind, ea=self.cable_ea, mass_per_length=self.cable_mass_per_length)

    def check_segments(self, cable_segments: int) -> None:
        """A ParamError naming the keys when the plant's stiffer or lighter cables vibrate beyond
        the timestep's limit with ``cable_segments`` segments (``max_cable_segments``)."""
        if cable_segments:
            most = max_cable_segments(ea=self.cable_ea, mass_per_length=self.cable_mass_per_length)
            if cable_segments > most:
                raise ParamError(f"cable_segments = {cable_segments} with plant.cable_ea_error = "
                                 f"{self.cable_ea_error:g} and plant.cable_mass_error = {self.cable_mass_error:g}: "
                                 f"the segments vibrate beyond the timestep's limit omega dt <= "
                                 f"{SEGMENT_OMEGA_DT_LIMIT:g}; use at most {most}")


# ----------------------------------------------------------------------------- sources

#: The built-in catalogue: ICRS (J2000) RA and Dec, rad, of calibrators and pulsars FAST
#: observes (NED and ATNF; 3C 286 13h31m08.29s +30d30m33.0s, 3C 295 14h11m20.5s +52d12m21s).
SOURCES = {
    "3C 286": (np.radians(202.784542), np.radians(30.509167)),
    "3C 295": (np.radians(212.835417), np.radians(52.205833)),
    "3C 48": (np.radians(24.422083), np.radians(33.159750)),
    "3C 138": (np.radians(80.291208), np.radians(16.639472)),
    "3C 147": (np.radians(85.650583), np.radians(49.852000)),
    "Crab": (np.radians(83.633083), np.radians(22.014500)),
    "Cyg A": (np.radians(299.868150), np.radians(40.733917)),
    "PSR B0329+54": (np.radians(53.247375), np.radians(54.578778)),
    "PSR B1937+21": (np.radians(294.910667), np.radians(21.583083)),
}
OBSERVING_NIGHT = "2026-03-01T00:00:00"  # the transit of each source nearest to it


def _radec(source) -> tuple[float, float]:
    """A catalogue name, or (ra, dec) in rad."""
    return SOURCES[source] if isinstance(source, str) else (float(source[0]), float(source[1]))


def _transit(source, dut1: float = 0.0):
    ra, dec = _radec(source)
    return sky.meridian_transit(ra, dec, OBSERVING_NIGHT, dut1=dut1)


def _start(source, start_utc: str | None, duration: float, dut1: float = 0.0):
    """(jd1, jd2) of an observation's start: ``start_utc``, or centred on the transit."""
    if start_utc is not None:
        jd1, jd2 = sky.as_utc_jd(start_utc)
        return float(np.ravel(jd1)[0]), float(np.ravel(jd2)[0])
    jd1, jd2 = _transit(source, dut1)
    return jd1, jd2 - 0.5 * duration / 86400.0


# ----------------------------------------------------------------------------- scenario defaults

#: The paper's "motion scan along right ascension" (Fig. 8): legs along declination at
#: V_dec = 15 deg/h (0.25 arcmin/s), 1 deg long, 4 legs 3 arcmin apart in RA, around 3C 286.
RA_SCAN = {"legs_along": "dec", "speed_deg_h": 15.0, "leg_deg": 1.0, "legs": 4, "spacing_deg": 0.05}
#: The paper's "motion scan along declination" (Fig. 11): legs along RA at V_asc = 5 deg/h,
#: 0.5 deg long, 3 legs 3 arcmin apart in Dec.
DEC_SCAN = {"legs_along": "ra", "speed_deg_h": 5.0, "leg_deg": 0.5, "legs": 3, "spacing_deg": 0.05}

DEFAULT_WIND_M_S = 4.0  # the observing case (REFERENCE.md); 8 m/s is the stress case
#: The wind blows toward +x (east) by default (--wind-direction): across the cables of towers
#: 1, 3, 4 and 6.
WIND_AZIMUTH_DEG = 0.0
#: The default cables: chains of two segments, the fewest that carry the cables' first string mode
#: and with it the cabin-cable mode the telescope shows at 0.12-0.2 Hz (REFERENCE.md; the
#: lumped straight cables have their lowest at 0.30 Hz). models/fast/README.md, "The cables".
DEFAULT_CABLE_SEGMENTS = 2

#: Doubles per tick that a FAST run keeps besides the runner's log and its sensors' records: the
#: plant's wind speed (1, in memory), the tick's time, wind force and catenary tensions (1 + 3 +
#: 6, streamed to a file of their own: sims.fast.loads.CableLoads.log). (The controller holds its
#: plan's per-tick arrays a block of ticks at a time: sims.fast.controller.PLAN_BLOCK_TICKS.)
PER_TICK_FLOATS = 11


def log_bytes_per_tick(cable_segments: int = DEFAULT_CABLE_SEGMENTS, sensors: SensorOptions = SensorOptions(),
                       control_dt: float = CONTROL_DT) -> float:
    """Bytes a FAST run keeps per control tick, in memory or on disk: the runner's log of the compiled model
    (13 planned channels; the discretized cables add their nodes' joints), PER_TICK_FLOATS and
    the sensors' (``sims.fast.measurement.floats_per_tick``)."""
    return run_limits.floats(run_limits.runlog_floats_per_tick(_compiled(cable_segments), len(fp.PLAN_LABELS))
                             + PER_TICK_FLOATS + floats_per_tick(sensors, control_dt))


# ----------------------------------------------------------------------------- parameters

_ANGLE = run_limits.ANGLE
_UTC = dict(unit="UTC", reason="ISO 8601, e.g. 2026-03-01T14:30:00; years 1972-2099, where UTC has its leap seconds")


@dataclass(frozen=True)
class FastParams(ScenarioParams):
    """What every FAST run shares: the wind, the cables, the stabilizer."""

    wind: float = param(DEFAULT_WIND_M_S, "mean wind at the cabin", **MEAN_SPEED)
    wind_direction: float = param(WIND_AZIMUTH_DEG, "azimuth the wind blows toward, from east toward north", **_ANGLE)
    turbulence_intensity: float | None = param(
        None, "sigma_u / U of the turbulence; none: the spectrum's own (Kaimal: IEC class B)", "", low=0.0, high=0.5,
        reason="beyond 0.5 a one-point Gaussian turbulence model does not hold")
    wind_spectrum: str = param("kaimal", "turbulence spectrum", choices=tuple(SPECTRA))
    wind_file: str | None = param(
        None, "measured wind instead of the model: CSV rows t (s), speed (m/s)[, direction (deg)], covering the "
        "run; resampled to the control ticks (a relative path is the scenario file's directory's)", path=True)
    stewart: bool = param(True, "the Stewart stabilizer in the cabin on (off: the feed rides the A-B rotator)")
    drives: str = param("as-built", "the winches: as-built (each rope within its drive's speed and acceleration, "
                        "0.5 m/s and 0.05 m/s^2; models/fast/README.md) or ideal (each rope at its command every "
                        "tick)", choices=DRIVES)
    sensors: SensorOptions = param(SensorOptions(), "the measurement system (sims.fast.measurement.SensorOptions: "
                                   "fused, FAST's, or ideal; its rates, latencies, noises and biases)")
    cable_segments: int = param(DEFAULT_CABLE_SEGMENTS, "each cable as a chain of this many elastic segments (2: "
                                "the measured 0.19 Hz cabin-cable mode, models/fast/README.md); 0: straight cables "
                                "with the lumped catenary law (faster, lowest mode 0.30 Hz)", low=0,
                                high=max_cable_segments(),
                                reason="more segments vibrate beyond the 2 ms timestep's limit omega dt <= "
                                       f"{SEGMENT_OMEGA_DT_LIMIT:g}")
    duration: float | None = param(None, "simulated time; none: the whole session", "s", low=0.0, low_open=True,
                                   reason="at least one control tick (checked against control_rate_hz: 20 ms at "
                                          "the default 50 Hz)")
    control_rate_hz: float = param(1.0 / CONTROL_DT, "the control loop's rate: the sensors are read and the "
                                   "controller called once per tick (FAST's own rates are not public: assumed, "
                                   "sims/fast/physics.py CONTROL_DT; 100 Hz gives the earlier figures)", "Hz",
                                   low=10.0, high=1.0 / PHYSICS_DT,
                                   reason="the 2 ms physics step divided by a whole number (500, 250, 166.7, "
                                          "125, 100, 83.3, 71.4, 62.5, 55.6, 50, ... 10 Hz)")
    dut1: float = param(0.0, "UT1 - UTC of the observing day (the IERS Bulletin A's value; 0: UTC taken for UT1, "
                        "at most 0.9 s = 13.5 arcsec of hour angle off)", "s", low=-sky.MAX_DUT1, high=sky.MAX_DUT1,
                        low_open=True, high_open=True, reason="UTC keeps UT1 - UTC within 0.9 s, by its definition")

    def check(self) -> None:
        # The start time first: later checks (the source's zenith angle) compute with it.
        start = getattr(self, "start_utc", None)
        if start is not None:
            try:
                jd1, jd2 = sky.as_utc_jd(start)
                year = int(sky.jd_to_iso(np.ravel(jd1)[0], np.ravel(jd2)[0])[:4])
            except (ValueError, TypeError) as e:
                raise ParamError(f"start_utc = {start!r} is not a UTC time ({_UTC['reason']}): {e}") from None
            if not 1972 <= year <= 2099:
                raise ParamError(f"start_utc = {start!r} is outside the years 1972-2099, where UTC has its leap "
                                 "seconds")
        if self.cable_segments == 1:
            raise ParamError("cable_segments = 1 is not a chain: 0 (lumped cables) or 2 ... "
                             f"{max_cable_segments()}")
        if self.wind_file is not None:
            try:
                MeasuredWind(self.wind_file)
            except WindFileError as e:
                raise ParamError(f"wind_file: {e}") from None
        steps = 1.0 / (self.control_rate_hz * PHYSICS_DT)
        if abs(steps - round(steps)) > 1e-6:
            raise ParamError(f"control_rate_hz = {self.control_rate_hz:g} Hz is not the 2 ms physics step divided "
                             f"by a whole number (it would be {steps:.3g} steps a tick): 500 / k Hz, e.g. 50 or 100")
        self.sensors.check_rates(self.control_rate_hz)
        if self.duration is not None and self.duration < self.control_dt * (1.0 - 1e-9):
            raise ParamError(f"duration = {self.duration:g} s is outside [{self.control_dt:g}, ...] s: at least one "
                             f"control tick ({self.control_dt * 1e3:g} ms) at control_rate_hz = "
                             f"{self.control_rate_hz:g} Hz")
        if self.duration is not None:
            run_limits.check_duration(self.duration, self.control_dt, self.log_bytes_per_tick())

    def log_bytes_per_tick(self) -> float:
        return log_bytes_per_tick(self.cable_segments, self.sensors, self.control_dt)

    @property
    def control_dt(self) -> float:
        """The control period, s: a whole number of physics steps."""
        return round(1.0 / (self.control_rate_hz * PHYSICS_DT)) * PHYSICS_DT


@dataclass(frozen=True)
class FastSourceParams(FastParams):
    """A session on one source: by catalogue name or by RA/Dec, from a start time."""

    source: str | None = param("3C 286", "the source, from the built-in catalogue (sims.fast.SOURCES); for "
                               "source_radec instead leave it out (a scenario file: giving source_radec clears "
                               "it) or --set source=none", choices=tuple(SOURCES), excludes=("source_radec",))
    source_radec: tuple[float, ...] | None = param(
        None, "the source's ICRS (J2000) right ascension and declination; none: source", unit=("deg", "deg"),
        low=(0.0, -90.0), high=(360.0, 90.0), reason="RA and Dec", length=2, excludes=("source",))
    start_utc: str | None = param(None, "the observation's start; none: centred on the source's transit nearest "
                                  f"{OBSERVING_NIGHT}", **_UTC)

    def source_of(self):
        """A catalogue name, or (ra, dec) in rad."""
        return self.source if self.source is not None else tuple(np.radians(self.source_radec))

    def check(self) -> None:
        super().check()
        if self.source is not None and self.source_radec is not None:
            raise ParamError(f"source = {self.source!r} and source_radec = {list(self.source_radec)} are both given: "
                             "give one (leave source out to observe at source_radec)")
        if self.source is None and self.source_radec is None:
            raise ParamError("source and source_radec are both none: give one (a catalogue name or [RA, Dec] deg)")


@dataclass(frozen=True)
class FastTrackingParams(FastSourceParams):
    """Park -> the source, start, tracking, termination."""

    tracking: float = param(1200.0, "time on the source", "s", low=10.0, high=6 * 3600.0,
                            reason="10 s to 6 h (a source stays within 40 deg of FAST's zenith for at most 5.9 h: at "
                                   "Dec = latitude, cos H = (cos 40 - sin^2 lat) / cos^2 lat, H = 44.6 deg)")

    def check(self) -> None:
        super().check()
        ra, dec = _radec(self.source_of())
        start = _start(self.source_of(), self.start_utc, self.tracking, self.dut1)
        try:
            sky.track(ra, dec, start, self.tracking, step=max(self.tracking / 100.0, 1.0), dut1=self.dut1)
        except fast.ZenithLimitError as e:
            raise ParamError(f"source, start_utc, tracking: {e} (FAST observes within 40 deg of the zenith, "
                             "Table 1)") from None


@dataclass(frozen=True)
class FastScanParams(FastSourceParams):
    """The paper's motion scan: legs along RA or Dec around the source, with transitions."""

    legs_along: str = param("dec", "the legs run along Dec (the paper's scan along RA, Fig. 8) or along RA "
                            "(Fig. 11)", choices=("dec", "ra"))
    legs: int = param(RA_SCAN["legs"], "number of legs", low=1, high=50, reason="a raster of 1 to 50 legs")
    leg_length: float = param(RA_SCAN["leg_deg"], "length of a leg on the sky", "deg", low=0.01, high=10.0,
                              reason="36 arcsec to 10 deg")
    scan_speed: float = param(RA_SCAN["speed_deg_h"], "scan speed along a leg", "deg/h", low=0.1, high=60.0,
                              reason="the paper's 5-15 deg/h; 60 deg/h is FAST's fastest scan")
    leg_spacing: float = param(RA_SCAN["spacing_deg"], "spacing of the legs", "deg", low=0.001, high=1.0,
                               reason="3.6 arcsec to 1 deg (the paper: 3 arcmin)")


@dataclass(frozen=True)
class FastSwitchParams(FastParams):
    """Tracking one source after another, with focal-surface switches between."""

    sources: tuple[str, ...] = param(("3C 286", "3C 295"), "the sources, in order, from the catalogue",
                                     choices=tuple(SOURCES), min_items=2, max_items=10,
                                     reason="a switch needs two; ten fill a night")
    tracking: float = param(300.0, "time on each source", "s", low=10.0, high=3600.0, reason="10 s to an hour")
    start_utc: str | None = param(None, "the first observation's start; none: the first source's transit "
                                  f"nearest {OBSERVING_NIGHT}", **_UTC)
