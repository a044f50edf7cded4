"""FAST feed support: the complete motion plan (the paper's section 3).

Paper: Yao et al. 2020 (REFERENCE.md "Papers"). A plan is a
sequence of feed segments (Figure 5): source switching P0 -> Ph (a straight line to the closest
focal-surface point) -> P1 (along the focal surface), start planning P1 -> Ps, the observation
Ps -> Pt (tracking, or a motion scan with transition segments), termination planning Pt -> P2.
Every segment's speed along its path is a profile of ``planbench.planners.profiles`` (first-degree
acceleration, Figure 6) except the observation, which follows the sky.

From the feed position the rest follows (planbench.planners.fast): the feed axis points along the
focal-sphere radius (P_feed = -r s), the tilt is split between the cabin and the A-B rotator
by the smooth tilt law (``fast.tilt_law``: the max-min-tension split tabulated over the sky),
eq. (3)-(9) give the cabin pose and the A-B angles, the cable lengths and
static tensions follow, and the Stewart stabilizer sits at its nominal pose (its corrections
are the controller's).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.interpolate import CubicHermiteSpline, CubicSpline

from planbench.planners import fast
from planbench.planners import profiles as prof
from planbench.planners.errors import LimitError, PlanningError
from planbench.planners.trajectory import TrajectorySample, check_values, sample_times

R_FOCAL = fast.FOCAL_SURFACE_RADIUS
MIN_LENGTH = 1e-6  # m: shorter lines and arcs are left out of a switch
BEAM_SYMMETRY = math.pi / 3  # rad: the 19-beam receiver's hexagonal symmetry


@dataclass(frozen=True)
class MechanismLimits:
    """Speed and acceleration limits of the angular mechanisms for eq. (10).

    Not given by the paper or REFERENCE.md; assumptions for mechanisms that carry a 30 t cabin
    (the cabin's tilt through its cables) and the rotators inside it, a few times slower than
    the feed's switching motion in angle:
      cabin: the cable robot's tilt, rad/s and rad/s^2 (0.2 deg/s, 0.02 deg/s^2);
      ab: the A-B rotator's axes (0.5 deg/s, 0.05 deg/s^2);
      multifeed: the 19-beam receiver's rotation (1 deg/s, 0.1 deg/s^2).
    """

    cabin_rate: float = math.radians(0.2)
    cabin_accel: float = math.radians(0.02)
    ab_rate: float = math.radians(0.5)
    ab_accel: float = math.radians(0.05)
    multifeed_rate: float = math.radians(1.0)
    multifeed_accel: float = math.radians(0.1)


MECHANISM_LIMITS = MechanismLimits()


# ----------------------------------------------------------------------------- segments


@dataclass
class Segment:
    """One piece of the feed's path, at absolute times [t0, t0 + duration].

    ``accel_limit`` is the paper's acceleration limit of this kind of segment (Table 1).
    ``evaluate(tau)`` gives position, velocity, acceleration (n, 3) at local times tau.
    """

    name: str
    t0: float
    duration: float
    accel_limit: float
    # The multi-feed angle that FastPlan gives a segment without angles of its own (``angle``):
    # None until it does.
    angle_profile: Any = field(default=None, init=False, repr=False)
    angle_start: float = field(default=0.0, init=False, repr=False)

    def evaluate(self, tau):  # pragma: no cover - abstract
        raise NotImplementedError

    def angle(self, tau):
        """(multi-feed angle, rate), rad and rad/s, at local times tau: the angle profile
        that FastPlan gives the segment (``angle_start`` + ``angle_profile``)."""
        p = self.angle_profile.evaluate(np.clip(tau, 0.0, self.angle_profile.duration))
        return self.angle_start + p.position, p.velocity

    @property
    def t1(self) -> float:
        return self.t0 + self.duration


@dataclass
class LineSegment(Segment):
    """A straight line from ``start`` to ``end`` with a speed profile along it."""

    start: np.ndarray
    end: np.ndarray
    profile: prof.Profile

    def evaluate(self, tau):
        d = self.end - self.start
        length = float(np.linalg.norm(d))
        unit = d / length if length > 0 else np.zeros(3)
        p = self.profile.evaluate(tau)
        return (self.start + p.position[:, None] * unit, p.velocity[:, None] * unit, p.acceleration[:, None] * unit)


@dataclass
class ArcSegment(Segment):
    """A great-circle arc of the focal sphere from ``start`` toward ``direction`` (unit tangent
    at the start), with a speed profile in arc length (m)."""

    start: np.ndarray
    direction: np.ndarray
    profile: prof.Profile
    radius: float = R_FOCAL

    def evaluate(self, tau):
        a = self.start / np.linalg.norm(self.start)
        c = self.direction / np.linalg.norm(self.direction)
        p = self.profile.evaluate(tau)
        angle = p.position / self.radius
        cos, sin = np.cos(angle)[:, None], np.sin(angle)[:, None]
        radial = cos * a + sin * c
        tangent = -sin * a + cos * c
        pos = self.radius * radial
        vel = p.velocity[:, None] * tangent
        acc = p.acceleration[:, None] * tangent - (p.velocity**2 / self.radius)[:, None] * radial
        return pos, vel, acc


@dataclass
class SampledSegment(Segment):
    """A path given by samples (the observation, the transitions): a C2 cubic spline (scipy)
    through feed positions at local times; velocity and acceleration are its derivatives."""

    spline: CubicSpline
    angles: CubicSpline | None = None  # the multi-feed angle along an observation

    def evaluate(self, tau):
        s = self.spline
        return s(tau), s(tau, 1), s(tau, 2)

    def angle(self, tau):
        if self.angles is None:
            return super().angle(tau)
        return self.angles(tau), self.angles(tau, 1)


def tangential_limit(a_max: float, v_max: float, radius: float = R_FOCAL) -> float:
    """The along-path acceleration limit on a focal arc: |a|^2 = a_t^2 + (v^2 / r)^2 must stay
    under a_max^2 at speeds up to v_max (at 400 mm/s the centripetal part is 0.99 mm/s^2)."""
    centripetal = v_max * v_max / radius
    if centripetal >= a_max:
        raise LimitError(
            f"speed {v_max:g} m/s on the focal sphere needs {centripetal:g} m/s^2 "
            f"of centripetal acceleration, beyond the limit {a_max:g} m/s^2"
        )
    return math.sqrt(a_max * a_max - centripetal * centripetal)


def _point(name: str, value, unit: str = "m") -> np.ndarray:
    """A (3,) vector, finite and within +/-MAX_MAGNITUDE (a PlanningError names the entry)."""
    v = check_values(value, lambda i: f"{name} {'xyz'[i[0]] if len(i) == 1 else list(i)}", unit)
    if v.shape != (3,):
        raise PlanningError(f"{name} must be a 3-vector, got shape {v.shape}")
    return v


def _arc_between(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, float]:
    """(unit tangent at a toward b, arc length on the focal sphere)."""
    ua, ub = a / np.linalg.norm(a), b / np.linalg.norm(b)
    angle = math.atan2(np.linalg.norm(np.cross(ua, ub)), float(ua @ ub))
    tangent = ub - (ua @ ub) * ua
    norm = np.linalg.norm(tangent)
    if norm < 1e-15:
        return np.zeros(3), 0.0
    return tangent / norm, R_FOCAL * angle


# ----------------------------------------------------------------------------- switching


@dataclass(frozen=True)
class SwitchTimes:
    """Eq. (10) and its parts, s."""

    t_p_line: float
    t_cable_line: float
    t_ab_line: float
    t_multifeed_line: float
    t_line: float
    t_focal: float
    t_ab: float
    t_multifeed: float


def _tilt_state(point: np.ndarray, geometry, limits):
    """(cabin tilt, (theta_A, theta_B)) at a feed point, the axis along the focal radius."""
    axis = -point / np.linalg.norm(point)
    pose = fast.cabin_pose(point, axis, fast.tilt_law(geometry, limits)(axis), geometry)
    return float(pose.cabin_tilt), (float(pose.theta_a), float(pose.theta_b))


def switch_times(
    p0,
    p1,
    multifeed0: float = 0.0,
    multifeed1: float = 0.0,
    mechanisms: MechanismLimits = MECHANISM_LIMITS,
    geometry: fast.FastGeometry = fast.FAST,
    limits: fast.FastLimits = fast.FAST_LIMITS,
) -> SwitchTimes:
    """Segment times of a source switch P0 -> Ph -> P1 (section 3.2, eq. 10).

    T_focal: the feed's minimum time along the focal arc Ph -> P1 (V_s-max, A_s-max).
    T_line = max(T_p-line, T_cable-line, T_AB-line, T_multifeed-line): the feed's time on the
    line P0 -> Ph; the cable robot's tilt change on the line; the A-B rotator's whole switching
    time T_AB (its larger angle change P0 -> P1) less T_focal; the same for the multi-feed
    rotation.
    """
    p0, p1 = _point("P0", p0), _point("P1", p1)
    multifeed0 = float(check_values(multifeed0, "multifeed0", "rad"))
    multifeed1 = float(check_values(multifeed1, "multifeed1", "rad"))
    ph = fast.closest_focal_point(p0)
    _, arc = _arc_between(ph, p1)
    a_arc = tangential_limit(fast.A_S_MAX, fast.V_S_MAX)
    t_focal = prof.min_move_time(arc, fast.V_S_MAX, a_arc) if arc > MIN_LENGTH else 0.0
    line = float(np.linalg.norm(ph - p0))
    t_p_line = prof.min_move_time(line, fast.V_S_MAX, fast.A_S_MAX) if line > MIN_LENGTH else 0.0
    tilt0, ab0 = _tilt_state(p0, geometry, limits)
    tilt_h, _ = _tilt_state(ph, geometry, limits)
    _, ab1 = _tilt_state(p1, geometry, limits)
    d_tilt = abs(tilt_h - tilt0)
    t_cable = prof.min_move_time(d_tilt, mechanisms.cabin_rate, mechanisms.cabin_accel) if d_tilt > 0 else 0.0
    d_ab = max(abs(ab1[0] - ab0[0]), abs(ab1[1] - ab0[1]))
    t_ab = prof.min_move_time(d_ab, mechanisms.ab_rate, mechanisms.ab_accel) if d_ab > 0 else 0.0
    d_mf = abs(multifeed1 - multifeed0)
    t_mf = prof.min_move_time(d_mf, mechanisms.multifeed_rate, mechanisms.multifeed_accel) if d_mf > 0 else 0.0
    t_ab_line = max(t_ab - t_focal, 0.0)
    t_mf_line = max(t_mf - t_focal, 0.0)
    t_line = max(t_p_line, t_cable, t_ab_line, t_mf_line)
    return SwitchTimes(t_p_line, t_cable, t_ab_line, t_mf_line, t_line, t_focal, t_ab, t_mf)


def switch_segments(p0, p1, t0: float = 0.0, **kwargs) -> tuple[list[Segment], SwitchTimes]:
    """The source switch P0 -> Ph (line) -> P1 (focal arc), each from rest to rest."""
    p0, p1 = np.asarray(p0, dtype=float), np.asarray(p1, dtype=float)
    times = switch_times(p0, p1, **kwargs)
    ph = fast.closest_focal_point(p0)
    segments: list[Segment] = []
    line = float(np.linalg.norm(ph - p0))
    if line > MIN_LENGTH:
        profile = prof.move_in_time(line, times.t_line, fast.V_S_MAX, fast.A_S_MAX)
        segments.append(LineSegment("switch-line", t0, times.t_line, fast.A_S_MAX, p0, ph, profile))
        t0 += times.t_line
    direction, arc = _arc_between(ph, p1)
    if arc > MIN_LENGTH:
        profile = prof.move_min_time(arc, fast.V_S_MAX, tangential_limit(fast.A_S_MAX, fast.V_S_MAX))
        segments.append(ArcSegment("switch-focal", t0, profile.duration, fast.A_S_MAX, ph, direction, profile))
    return segments, times


# ----------------------------------------------------------------------------- start, stop


def start_segment(observation: Segment, a_max: float = fast.A_MAX) -> ArcSegment:
    """Start planning (section 3.1): from rest at P1 along the focal sphere to the
    observation's first point Ps, arriving with its velocity (one pulse of peak A_max)."""
    ps, vs, _ = (x[0] for x in observation.evaluate(np.array([0.0])))
    speed = float(np.linalg.norm(vs))
    if speed == 0.0:
        raise PlanningError("the observation starts at rest: no start segment is needed")
    profile = prof.velocity_change(0.0, speed, tangential_limit(a_max, speed))
    length = profile.end_position
    # Back along the great circle through Ps tangent to the observation's velocity.
    tangent = vs / speed
    angle = length / R_FOCAL
    a = ps / np.linalg.norm(ps)
    p1 = R_FOCAL * (math.cos(angle) * a - math.sin(angle) * tangent)
    direction = math.cos(angle) * tangent + math.sin(angle) * a  # the arc's tangent at P1
    return ArcSegment("start", observation.t0 - profile.duration, profile.duration, a_max, p1, direction, profile)


def start_angle(observation: Segment, start: Segment) -> float:
    """The multi-feed angle at the start segment's beginning (see FastPlan._plan_angles): the
    observation's first angle less q_dot T / 2 of the rate ramp; for eq. (10)'s switch."""
    if not isinstance(observation, SampledSegment) or observation.angles is None:
        return 0.0
    q, qd = (float(x[0]) for x in observation.angle(np.array([0.0])))
    return q - 0.5 * qd * start.duration


def end_angle(observation: Segment, termination: Segment) -> float:
    """The multi-feed angle at a termination's end: the observation's last angle plus the
    q_dot T / 2 of the ramp to rest."""
    if not isinstance(observation, SampledSegment) or observation.angles is None:
        return 0.0
    q, qd = (float(x[0]) for x in observation.angle(np.array([observation.duration])))
    return q + 0.5 * qd * termination.duration


def termination_segment(observation: Segment, a_max: float = fast.A_MAX) -> ArcSegment:
    """Termination planning (section 3.1): from the observation's end Pt with its velocity
    along the focal sphere to rest at P2."""
    pt, vt, _ = (x[0] for x in observation.evaluate(np.array([observation.duration])))
    speed = float(np.linalg.norm(vt))
    if speed == 0.0:
        raise PlanningError("the observation ends at rest: no termination segment is needed")
    profile = prof.velocity_change(speed, 0.0, tangential_limit(a_max, speed))
    return ArcSegment("termination", observation.t1, profile.duration, a_max, pt, vt / speed, profile)


# ----------------------------------------------------------------------------- observation


def observation_segment(
    times, directions, t0: float = 0.0, name: str = "observation", a_max: float = fast.A_MAX, angles=None
) -> SampledSegment:
    """The feed following a sky path: P_feed = -r s(t) through a cubic spline in time;
    ``angles`` (rad, at the same times): the multi-feed rotation along it (e.g. the
    parallactic angle, so the 19 beams keep their pattern on the sky)."""
    times = check_values(times, lambda i: f"observation time t[{i[0]}]", "s")
    directions = check_values(directions, lambda i: f"observation direction[{', '.join(map(str, i))}]")
    if angles is not None:
        angles = check_values(angles, lambda i: f"observation angle[{i[0]}]", "rad")
    points = fast.feed_position(directions)
    spline = CubicSpline(times - times[0], points, axis=0)
    angle_spline: CubicSpline | None = None
    if angles is not None:
        angles = np.unwrap(np.asarray(angles, dtype=float))
        # The 19 beams sit on a hexagon: a turn by 60 deg maps the pattern onto itself, so the
        # rotator starts within +/-30 deg of its zero and follows the angle from there.
        angles = angles - BEAM_SYMMETRY * np.round(angles[0] / BEAM_SYMMETRY)
        angle_spline = CubicSpline(times - times[0], angles)
    return SampledSegment(name, t0, float(times[-1] - times[0]), a_max, spline, angle_spline)


def transition_segment(
    p0, v0, p1, v1, duration: float, t0: float, a_limit: float = fast.A_T_MAX, name: str = "transition"
) -> SampledSegment:
    """A transition between two observation legs (section 3.3): the cubic Hermite curve from
    (P, V) at one leg's end to (P, V) at the next leg's start in ``duration``, projected on the
    focal sphere, as a spline on a 0.5 s grid."""
    n = max(int(math.ceil(duration / 0.5)), 4) + 1
    tau = np.linspace(0.0, duration, n)
    hermite = CubicHermiteSpline([0.0, duration], np.stack([p0, p1]), np.stack([v0, v1]), axis=0)
    points = hermite(tau)
    points = R_FOCAL * points / np.linalg.norm(points, axis=1, keepdims=True)
    spline = CubicSpline(tau, points, axis=0, bc_type=((1, np.asarray(v0)), (1, np.asarray(v1))))
    return SampledSegment(name, t0, duration, a_limit, spline)


def hermite_peak_acceleration(p0, v0, p1, v1, duration: float) -> float:
    """Largest |acceleration| of the cubic Hermite between two states (its ends: linear a)."""
    p0, v0, p1, v1 = (np.asarray(x, dtype=float) for x in (p0, v0, p1, v1))
    T = duration
    a0 = (6 * (p1 - p0) - T * (4 * v0 + 2 * v1)) / T**2
    a1 = (-6 * (p1 - p0) + T * (2 * v0 + 4 * v1)) / T**2
    return float(max(np.linalg.norm(a0), np.linalg.norm(a1)))


def transition_time(p0, v0, p1, v1, a_limit: float = fast.A_T_MAX) -> float:
    """The shortest transition time whose Hermite curve keeps |a| <= a_limit (bisection)."""
    p0, p1 = _point("transition P0", p0), _point("transition P1", p1)
    v0, v1 = _point("transition V0", v0, "m/s"), _point("transition V1", v1, "m/s")
    a_limit = float(check_values(a_limit, "a_limit", "m/s^2"))
    if a_limit <= 0:
        raise PlanningError(f"a_limit = {a_limit!r} m/s^2 must be > 0")
    lo, hi = 1e-3, 1.0
    while hermite_peak_acceleration(p0, v0, p1, v1, hi) > a_limit:
        hi *= 2.0
        if hi > 1e5:
            raise LimitError(f"no transition within 1e5 s keeps the acceleration under {a_limit * 1e3:.1f} mm/s^2")
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if hermite_peak_acceleration(p0, v0, p1, v1, mid) > a_limit:
            lo = mid
        else:
            hi = mid
    return hi


# ----------------------------------------------------------------------------- the paper's fits


def paper_ra_scan_fits(v_dec_deg_h: float, t2: float) -> dict:
    """Eq. (11)-(14), the motion scan along right ascension: units as printed.

    V_m = 0.008 V_dec^2 + 0.292 V_dec + 10.19 (mm/s, V_dec in deg/h), p_m = 0.079 V_dec -
    0.0133, V_c = -0.71 * 60 / t2 + 10.68 (mm/s, t2 in s), l_2 = 0.5 t2 V_c (mm).
    """
    v_m = 0.008 * v_dec_deg_h**2 + 0.292 * v_dec_deg_h + 10.19
    p_m = 0.079 * v_dec_deg_h - 0.0133
    v_c = -0.71 * 60.0 / t2 + 10.68
    return {"V_m_mm_s": v_m, "p_m": p_m, "V_c_mm_s": v_c, "l_2_mm": 0.5 * t2 * v_c}


def paper_dec_scan_t2(
    v_asc: float, a_max_mm_s2: float = fast.A_MAX * 1e3, a_s_max_mm_s2: float = fast.A_S_MAX * 1e3
) -> dict:
    """Eq. (15)-(20), the motion scan along declination; units as printed (mm/s, s, deg/h).

    V_m = -0.751 V_asc + 11.3, V_m-inv = 0.751 V_asc + 11.3, t3 = 2 V_m / A_max +
    2 V_m-inv / A_max, V_dec = 60 / t3, V_D = 0.008 V_dec^2 + 0.292 V_dec + 10.19 and
    t2 = ((2 A t3 + 8 V_D) + sqrt((2 A t3 + 8 V_D)^2 - 4 (A t3)^2)) / (2 A) with A = A_Smax.
    """
    v_m = -0.751 * v_asc + 11.3
    v_m_inv = 0.751 * v_asc + 11.3
    t3 = 2 * v_m / a_max_mm_s2 + 2 * v_m_inv / a_max_mm_s2
    v_dec = 60.0 / t3
    v_d = 0.008 * v_dec**2 + 0.292 * v_dec + 10.19
    a = a_s_max_mm_s2
    b = 2 * a * t3 + 8 * v_d
    t2 = (b + math.sqrt(b * b - 4 * (a * t3) ** 2)) / (2 * a)
    return {"V_m_mm_s": v_m, "V_m_inv_mm_s": v_m_inv, "t3_s": t3, "V_dec_deg_h": v_dec, "V_D_mm_s": v_d, "t2_s": t2}


# ----------------------------------------------------------------------------- the plan

PLAN_LABELS = ("feed_x", "feed_y", "feed_z", "cabin_tilt", "theta_a", "theta_b", "multifeed", *fast.CABLE_LABELS)
PLAN_KINDS = ("slide",) * 3 + ("hinge",) * 4 + ("slide",) * 6
RATE_STEP = 0.01  # s: central differences of the derived channels' rates


@dataclass(frozen=True)
class FastPlanSample:
    """Everything a plan commands at the times t (arrays over t).

    feed, feed_velocity, feed_acceleration: (n, 3) m, m/s, m/s^2; axis: (n, 3) unit;
    zenith_angle, cabin_tilt, ab_tilt, phi, theta_a, theta_b, multifeed: (n,) rad;
    cabin_rotation: (n, 3, 3); ab_point, cabin_origin: (n, 3) m; cable_length, tension,
    stewart_leg: (n, 6) m, N, m; segment: (n,) index of the segment.
    """

    t: np.ndarray
    segment: np.ndarray
    feed: np.ndarray
    feed_velocity: np.ndarray
    feed_acceleration: np.ndarray
    axis: np.ndarray
    zenith_angle: np.ndarray
    cabin_tilt: np.ndarray
    ab_tilt: np.ndarray
    phi: np.ndarray
    theta_a: np.ndarray
    theta_b: np.ndarray
    multifeed: np.ndarray
    cabin_rotation: np.ndarray
    ab_point: np.ndarray
    cabin_origin: np.ndarray
    cable_length: np.ndarray
    tension: np.ndarray
    stewart_leg: np.ndarray


def feed_state(
    t,
    feed,
    feed_velocity,
    feed_acceleration,
    multifeed,
    segment=None,
    geometry: fast.FastGeometry = fast.FAST,
    limits: fast.FastLimits = fast.FAST_LIMITS,
) -> FastPlanSample:
    """Everything the mechanism must do to put the feed at ``feed`` (n, 3) m: the focal axis,
    the tilt law, the cabin pose, the A-B angles, the cable lengths and the static tensions
    (planbench.planners.fast), at the times ``t`` (n,) s. ``segment``: (n,) segment indices, or None
    (-1: a trajectory without segments, e.g. a user's)."""
    axis = -feed / np.linalg.norm(feed, axis=1, keepdims=True)
    tilt = fast.tilt_law(geometry, limits)(axis)
    p = fast.cabin_pose(feed, axis, tilt, geometry)
    lengths = fast.cable_lengths(p.origin, p.rotation, geometry)
    tensions = fast.pose_tensions(p, geometry)
    stewart = np.broadcast_to(fast.stewart_leg_lengths(), (t.size, 6))
    segment = np.full(t.size, -1) if segment is None else segment
    return FastPlanSample(
        t,
        segment,
        feed,
        feed_velocity,
        feed_acceleration,
        axis,
        fast.zenith_angle(axis),
        p.cabin_tilt,
        p.ab_tilt,
        p.phi,
        p.theta_a,
        p.theta_b,
        multifeed,
        p.rotation,
        p.ab_point,
        p.origin,
        lengths,
        tensions,
        stewart.copy(),
    )


def reference_state(reference) -> FastPlanSample:
    """``feed_state`` of a sampled FAST trajectory (its channels PLAN_LABELS: the feed position
    and the multi-feed angle are used; the rest follows from them)."""
    return feed_state(
        reference.t,
        reference.position[:, :3],
        reference.velocity[:, :3],
        reference.acceleration[:, :3],
        reference.position[:, PLAN_LABELS.index("multifeed")],
    )


@dataclass
class FastPlan:
    """A complete plan: segments end to end from t = 0, and the multi-feed rotation.

    ``sample(t)`` follows the repo's Trajectory contract with the channels PLAN_LABELS (feed
    position, cabin tilt, A-B angles, multi-feed angle, six cable lengths); ``state(t)`` gives
    everything (FastPlanSample). The feed's velocity and acceleration are the segments'
    derivatives; those of the derived channels are central differences over RATE_STEP.
    """

    segments: list
    geometry: fast.FastGeometry = fast.FAST
    limits: fast.FastLimits = fast.FAST_LIMITS
    info: dict = field(default_factory=dict)
    labels: tuple = PLAN_LABELS

    def __post_init__(self):
        t = 0.0
        for seg in self.segments:
            seg.t0 = t
            t += seg.duration
        self._breaks = np.array([s.t0 for s in self.segments] + [t])
        self._plan_angles()

    def _plan_angles(self) -> None:
        """The multi-feed rotation of every segment, C1 along the plan.

        Observations carry their own angle (or hold 0). A transition between two legs is the
        cubic Hermite curve between their angles and rates. A start segment ramps the rate
        from rest to the observation's with one pulse over its duration (so it starts
        q_dot T / 2 before the observation's first angle); a termination ramps it back to
        rest. The segments of a switch move rest to rest from the angle before them to the
        angle after them in their total time (``move_in_time``; eq. (10) made that time long
        enough for the rotator's limits).
        """
        segs = self.segments
        for seg in segs:
            if isinstance(seg, SampledSegment) and seg.angles is None and not seg.name.startswith("transition"):
                seg.angles = CubicSpline([0.0, max(seg.duration, 1e-9)], [0.0, 0.0])
        for k, seg in enumerate(segs):
            if isinstance(seg, SampledSegment) and seg.angles is None:  # a transition
                q0, qd0 = (float(x[0]) for x in segs[k - 1].angle(np.array([segs[k - 1].duration])))
                q1, qd1 = (float(x[0]) for x in segs[k + 1].angle(np.array([0.0])))
                seg.angles = CubicHermiteSpline([0.0, seg.duration], [q0, q1], [qd0, qd1])
        for k, seg in enumerate(segs):
            if seg.name == "start" and k + 1 < len(segs):
                q, qd = (float(x[0]) for x in segs[k + 1].angle(np.array([0.0])))
                seg.angle_profile = _rate_ramp(0.0, qd, seg.duration)
                seg.angle_start = q - seg.angle_profile.end_position
            elif seg.name == "termination" and k > 0:
                q, qd = (float(x[0]) for x in segs[k - 1].angle(np.array([segs[k - 1].duration])))
                seg.angle_profile = _rate_ramp(qd, 0.0, seg.duration)
                seg.angle_start = q

        def has_angle(seg):
            return isinstance(seg, SampledSegment) or seg.angle_profile is not None

        k = 0
        while k < len(segs):
            if has_angle(segs[k]):
                k += 1
                continue
            run = [k]
            while run[-1] + 1 < len(segs) and not has_angle(segs[run[-1] + 1]):
                run.append(run[-1] + 1)
            first, last = run[0], run[-1]
            before = float(segs[first - 1].angle(np.array([segs[first - 1].duration]))[0][0]) if first > 0 else 0.0
            after = float(segs[last + 1].angle(np.array([0.0]))[0][0]) if last + 1 < len(segs) else before
            total = sum(segs[i].duration for i in run)
            move = prof.move_in_time(
                after - before, total, MECHANISM_LIMITS.multifeed_rate, MECHANISM_LIMITS.multifeed_accel
            )
            offset = 0.0
            for i in run:
                segs[i].angle_profile = _Window(move, offset, segs[i].duration)
                segs[i].angle_start = before
                offset += segs[i].duration
            k = last + 1

    @property
    def duration(self) -> float:
        return float(self._breaks[-1])

    def segment_table(self) -> list[dict]:
        return [
            {"name": s.name, "t0": s.t0, "duration": s.duration, "accel_limit": s.accel_limit} for s in self.segments
        ]

    def feed(self, t):
        """(index, position, velocity, acceleration) of the feed at times t (s)."""
        t = sample_times(t)  # a number or 1-D array of finite times
        index = np.clip(np.searchsorted(self._breaks, t, side="right") - 1, 0, len(self.segments) - 1)
        pos, vel, acc = np.empty((t.size, 3)), np.empty((t.size, 3)), np.empty((t.size, 3))
        for k in np.unique(index):
            seg = self.segments[k]
            mask = index == k
            tau = np.clip(t[mask] - seg.t0, 0.0, seg.duration)
            pos[mask], vel[mask], acc[mask] = seg.evaluate(tau)
            outside = (t[mask] < seg.t0) | (t[mask] > seg.t1)
            if outside.any():  # before the plan or after it: at rest
                vel[np.flatnonzero(mask)[outside]] = 0.0
                acc[np.flatnonzero(mask)[outside]] = 0.0
        return index, pos, vel, acc

    def _multifeed(self, t):
        index = np.clip(np.searchsorted(self._breaks, t, side="right") - 1, 0, len(self.segments) - 1)
        out = np.empty(t.size)
        for k in np.unique(index):
            seg, mask = self.segments[k], index == k
            out[mask] = seg.angle(np.clip(t[mask] - seg.t0, 0.0, seg.duration))[0]
        return out

    def state(self, t) -> FastPlanSample:
        t = sample_times(t)  # a number or 1-D array of finite times
        index, pos, vel, acc = self.feed(t)
        return feed_state(t, pos, vel, acc, self._multifeed(t), index, self.geometry, self.limits)

    def _channels(self, t) -> np.ndarray:
        s = self.state(t)
        return np.column_stack([s.feed, s.cabin_tilt, s.theta_a, s.theta_b, s.multifeed, s.cable_length])

    def sample(self, t) -> TrajectorySample:
        t = sample_times(t)  # a number or 1-D array of finite times
        h = RATE_STEP
        mid, plus, minus = self._channels(t), self._channels(t + h), self._channels(t - h)
        velocity = (plus - minus) / (2 * h)
        acceleration = (plus - 2 * mid + minus) / (h * h)
        _, _, vel, acc = self.feed(t)
        velocity[:, :3], acceleration[:, :3] = vel, acc
        return TrajectorySample(t, mid, velocity, acceleration)

    def check(self, t=None, dt: float = 0.01) -> None:
        """LimitError if the plan breaks a limit at its samples (default every 10 ms):
        zenith angle, tensions, tilts, each segment's feed acceleration limit."""
        t = np.arange(0.0, self.duration + 1e-9, dt) if t is None else np.asarray(t)
        s = self.state(t)
        fast.check_zenith_angle(s.axis, times=t)
        fast.check_tensions(s.tension, self.limits, times=t)
        acc = np.linalg.norm(s.feed_acceleration, axis=1)
        limit = np.array([self.segments[k].accel_limit for k in s.segment])
        bad = np.flatnonzero(acc > limit * (1 + 1e-6))
        if bad.size:
            i = int(bad[0])
            raise LimitError(
                f"feed acceleration {acc[i] * 1e3:.3f} mm/s^2 at t = {t[i]:.2f} s on the "
                f"{self.segments[s.segment[i]].name} segment is beyond its limit "
                f"{limit[i] * 1e3:.1f} mm/s^2"
            )


# ----------------------------------------------------------------------------- motion scans


def scan_segments(scan, start, step: float = 1.0, a_limit: float = fast.A_T_MAX, dut1: float = 0.0):
    """Observation legs and transitions of a motion scan (section 3.3).

    ``scan``: a planbench.planners.fast.sky.MotionScan; ``start``: its start UTC. Each leg follows the
    sky (``observation_segment``); between legs a transition of the scan's t2 joins the end
    state of one leg to the start state of the next (``transition_segment``). Raises
    LimitError when a transition would need more than ``a_limit`` (A_t-max). ``dut1``: UT1 -
    UTC, s.
    """
    from planbench.planners.fast.sky import parallactic_angle

    path = scan.path(start, step=step, dut1=dut1)
    directions = path.directions()
    angles = parallactic_angle(path.az, path.el)
    legs = []
    for k in range(scan.n_legs):
        mask = (path.t >= scan.leg_start[k] - 1e-9) & (path.t <= scan.leg_end[k] + 1e-9)
        legs.append(observation_segment(path.t[mask], directions[mask], name=f"leg {k + 1}", angles=angles[mask]))
    segments = [legs[0]]
    peaks = []
    for k in range(1, scan.n_legs):
        a, b = legs[k - 1], legs[k]
        p0, v0, _ = (x[0] for x in a.evaluate(np.array([a.duration])))
        p1, v1, _ = (x[0] for x in b.evaluate(np.array([0.0])))
        peak = hermite_peak_acceleration(p0, v0, p1, v1, scan.t2)
        peaks.append(peak)
        if peak > a_limit:
            need = transition_time(p0, v0, p1, v1, a_limit)
            raise LimitError(
                f"transition {k} needs {peak * 1e3:.2f} mm/s^2 in t2 = {scan.t2:.1f} s, "
                f"beyond A_t-max {a_limit * 1e3:.1f} mm/s^2; t2 >= {need:.1f} s keeps it"
            )
        segments += [transition_segment(p0, v0, p1, v1, scan.t2, 0.0, a_limit, f"transition {k}"), b]
    return segments, path, peaks


def _transition_peaks(scan, start, step: float, dut1: float = 0.0) -> list[float]:
    """Peak Hermite accelerations of a scan's transitions (m/s^2)."""
    path = scan.path(start, step=step, dut1=dut1)
    directions = path.directions()
    legs = []
    for k in range(scan.n_legs):
        mask = (path.t >= scan.leg_start[k] - 1e-9) & (path.t <= scan.leg_end[k] + 1e-9)
        legs.append(observation_segment(path.t[mask], directions[mask]))
    peaks = []
    for a, b in itertools.pairwise(legs):
        p0, v0, _ = (x[0] for x in a.evaluate(np.array([a.duration])))
        p1, v1, _ = (x[0] for x in b.evaluate(np.array([0.0])))
        peaks.append(hermite_peak_acceleration(p0, v0, p1, v1, scan.t2))
    return peaks


def minimum_t2(
    make_scan, start, step: float = 1.0, a_limit: float = fast.A_T_MAX, tolerance: float = 0.01, dut1: float = 0.0
) -> float:
    """The shortest t2 (to ``tolerance`` s) whose transitions all keep |a| <= A_t-max: the
    geometric t2. ``make_scan(t2)`` builds the MotionScan; the sky turns during t2, so the
    legs' end states depend on it and every trial rebuilds the raster (bisection)."""

    def feasible(t2):
        return max(_transition_peaks(make_scan(t2), start, step, dut1), default=0.0) <= a_limit

    lo, hi = 0.0, 1.0
    while not feasible(hi):
        lo, hi = hi, 2.0 * hi
        if hi > 1e4:
            raise LimitError(f"no transition time up to 1e4 s keeps the acceleration under {a_limit * 1e3:.1f} mm/s^2")
    while hi - lo > tolerance:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if feasible(mid) else (mid, hi)
    return hi


def _rate_ramp(v0: float, v1: float, duration: float) -> prof.Profile:
    """One triangular acceleration pulse from rate v0 to v1 over exactly ``duration``."""
    if duration <= 0 or v0 == v1:
        return prof.cruise(v0, max(duration, 0.0))
    peak = 2.0 * (v1 - v0) / duration
    return prof.Profile(np.array([duration / 2, duration / 2]), np.array([0.0, peak, 0.0]), 0.0, v0)


class _Window:
    """A profile seen through the time window [offset, offset + duration] (one segment of a
    switch shares the switch's profile)."""

    def __init__(self, profile: prof.Profile, offset: float, duration: float):
        self.profile, self.offset, self.duration = profile, offset, duration

    def evaluate(self, tau):
        return self.profile.evaluate(np.asarray(tau) + self.offset)


# ----------------------------------------------------------------------------- the planning problem


@dataclass(frozen=True)
class ObservingWindow:
    """A time span of the run during which the feed must be on its goal path.

    Attributes:
      name: the goal plan's segment (e.g. "observation (3C 286)", "leg 2", "transition 1").
      t_start, t_end: s from the start of the run.
    """

    name: str
    t_start: float
    t_end: float


@dataclass(frozen=True)
class FastProblem:
    """FAST's planning problem: the sources and times of an observing session.

    Attributes:
      park: (3,) the feed's position at the start, m (at rest).
      windows: the observing windows, in time order.
      goal: the paper's plan of the session (``FastPlan``): during the windows its feed path
        is the goal, the sources' focal points (observations, scan legs) and the scans'
        transitions; a planner may reuse its segments.
      info: the session in words and numbers (sources, UTC, scan parameters).
      geometry, limits: the mechanism (planbench.planners.fast).
    A planner returns a Trajectory with the channels PLAN_LABELS; the task judges its feed
    against ``goal`` during the windows, and its cable tensions everywhere.
    """

    park: np.ndarray
    windows: tuple
    goal: FastPlan
    info: dict = field(default_factory=dict)
    geometry: fast.FastGeometry = fast.FAST
    limits: fast.FastLimits = fast.FAST_LIMITS

    @property
    def duration(self) -> float:
        """The session's length, s: the goal plan's."""
        return self.goal.duration


class PaperPlanner:
    """The paper's planner (sections 3.1-3.3): its plan of the session is the goal itself."""

    def plan(self, problem: FastProblem) -> FastPlan:
        return problem.goal


def problem_of(plan: FastPlan, observing_prefixes: tuple, park=None) -> FastProblem:
    """The problem whose goal is ``plan``: its windows are the segments whose names start with
    ``observing_prefixes``; the park position is the plan's first feed position."""
    windows = tuple(
        ObservingWindow(s.name, float(s.t0), float(s.t0 + s.duration))
        for s in plan.segments
        if s.name.startswith(observing_prefixes)
    )
    start = plan.feed(np.array([0.0]))[1][0] if park is None else np.asarray(park, dtype=float)
    return FastProblem(start, windows, plan, dict(plan.info), plan.geometry, plan.limits)
