"""FAST feed support: geometry, kinematics (eq. 1-9) and cable statics.

Paper: Yao et al. 2020, "A motion planning algorithm for the feed support system of FAST"
(REFERENCE.md "Papers", "the paper"). Numbers: its Table 1
and REFERENCE.md ("FAST feed support system" and "Errata of the papers").

Frames (the paper's section 2)
------------------------------
* Inertial frame O-XYZ: origin at the centre of the reflector sphere (radius R = 300 m), X east,
  Y north, Z up. The reflector's bottom is at z = -R; the focal surface is the concentric sphere
  of radius r = 162.15 m. For a source in the direction s (unit vector from O to the sky) the
  illuminated paraboloid's vertex is at -R s and its focus, the feed, at P_feed = -r s; the
  feed's axis points along s (its receivers look down at the vertex along -s).
* Cabin frame C: origin at the centre of the plane of the three cable anchors on the cabin;
  level and aligned with O-XYZ at zero rotation. Its orientation is the tilt-and-torsion
  rotation R_C = Rz(phi) Ry(theta) Rz(-phi) Rz(omega) (eq. 2), torsion omega = 0 for the cable
  robot (eq. 3). The printed matrices of eq. (2)-(3) have wrong entries (REFERENCE.md); here
  R_C is composed from the rotations and tested against the corrected entries.
* A-B rotator frame AB: origin at the rotator's centre (the cable robot's control point P_AB,
  eq. 9), at ``ab_center`` in the cabin frame. R_AB = Rz(alpha) Ry(theta_A) Rx(theta_B)
  Rz(-alpha) relative to the cabin (eq. 5; alpha is the angle between axis A and Y). Its
  angles for a tilt (phi_AB, theta_AB) follow eq. (7)-(8) with the corrected sign
  (REFERENCE.md): sin theta_B = sin theta_AB sin(alpha - phi_AB),
  sin theta_A cos theta_B = sin theta_AB cos(phi_AB - alpha).
* Stewart frame S: the stabilizer's moving (lower) platform at r_AB-s in the AB frame; the feed
  phase centre at r_s-feed in S. Eq. (4): P_AB-feed = R_AB (r_AB-s + r_s-feed); eq. (1):
  P_feed = P_AB + R_C P_AB-feed; eq. (9): P_AB = P_feed - R_C P_AB-feed.

The feed's tilt from the vertical is the source's zenith angle ZA; it is split between the
cabin (theta_C, 0-14 deg) and the A-B rotator (theta_AB = ZA - theta_C, at most 26.4 deg), in
the same vertical plane (azimuth phi of s): R_C R_AB z = s.

Statics: six cables, six degrees of freedom, so the structure matrix is square and the wrench
balance A t + W = 0 gives the tensions directly (planbench.planners.legs). Cable weight: half of each
cable's weight is lumped at its cabin anchor as a vertical load (REFERENCE.md's common
approximation); the sag's change of the cable direction at the anchor is left out. The A-B
rotator's tilt moves the cabin's centre of mass (``cabin_com_at``): the tilted part (B frame,
Stewart stabilizer, feed platform, receiver: 4.9 t) hangs 2.25 m below the rotator's centre.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from planbench.planners.errors import LimitError, PlanningError
from planbench.planners.legs import leg_forces, leg_lengths, structure_matrix
from planbench.planners.rotations import rot_x, rot_y, rot_z

GRAVITY = 9.81

# Table 1 of the paper.
REFLECTOR_RADIUS = 300.0  # m
FOCAL_SURFACE_RADIUS = 162.15  # m (R - f R = 161.4 m at the focal ratio f = 0.4621; the paper's Table 1 value is used)
MAX_ZENITH_ANGLE = math.radians(40.0)
A_MAX = 0.010  # m/s^2: start, termination, observation
A_T_MAX = 0.015  # m/s^2: observation transition segments
V_S_MAX = 0.400  # m/s: source switching
A_S_MAX = 0.025  # m/s^2: source switching

CABLE_LABELS = tuple(f"cable{i}" for i in range(1, 7))


def _ring(radius: float, angles_deg, z: float) -> np.ndarray:
    a = np.radians(np.asarray(angles_deg, dtype=float))
    return np.column_stack([radius * np.cos(a), radius * np.sin(a), np.full(a.size, z)])


@dataclass(frozen=True)
class FastGeometry:
    """The feed support's geometry (REFERENCE.md: CASPR's FAST model; assumptions marked).

    Attributes:
      tower_anchors: (6, 3) cable exits on the tower tops, inertial frame, m: radius 300 m at
        azimuths 30, 90, ..., 330 deg from +X (east) toward +Y, 270 m above the dish bottom.
      cabin_anchors: (6, 3) cable anchors on the cabin, cabin frame, m: three points on a
        6.5 m radius at 60, 180, 300 deg, each shared by the two neighbouring towers' cables.
      ab_center: the A-B rotator's centre in the cabin frame, m (assumed: 2.0 m below the
        anchor plane of a 7.6 m tall cabin).
      r_ab_s: the Stewart moving platform's centre in the AB frame, m (assumed 3.5 m below).
      r_s_feed: the feed phase centre in the Stewart frame, m (assumed 1.0 m below).
      alpha: angle between the rotator's axis A and Y, rad (not given; assumed 0).
      cabin_mass: kg (CASPR: 30 091.8 kg, the cabin with everything in it).
      cabin_com: the cabin's centre of mass in the cabin frame, m (assumed 1.0 m below the
        anchor ring, which sits at the cabin's widest section; the A-B rotator and the Stewart
        stabilizer hang lower). The statics depend on it: with the centre of mass in the
        anchor plane and massless cables the best split at ZA 40 deg leaves 98 kN at least,
        1 m below 61 kN, 3 m below no feasible split; REFERENCE.md's check (100-107 kN) had it
        in the plane.
      cable_mass_per_length: kg/m (46 mm steel wire rope, ~10 kg/m; REFERENCE.md).
      ab_mass: the part of the cabin mass that the A-B rotator tilts (its B frame, the Stewart
        stabilizer, the feed platform and the receiver), kg (assumed, models/fast/README.md).
        The rotator's A ring is balanced on its axis and is not part of it.
      ab_com: that part's centre of mass in the AB frame, m, at the Stewart's nominal pose.
        ``cabin_com`` is the whole cabin's with the rotator level; tilting the rotator by R_AB
        moves it by (ab_mass / cabin_mass) (R_AB - I) ab_com (``cabin_com_at``).
        models/fast/fast.xml has the same masses (tests/test_fast_model.py).
    """

    tower_anchors: np.ndarray = field(
        default_factory=lambda: _ring(300.0, [30, 90, 150, 210, 270, 330], -REFLECTOR_RADIUS + 270.0)
    )
    cabin_anchors: np.ndarray = field(default_factory=lambda: _ring(6.5, [60, 60, 180, 180, 300, 300], 0.0))
    ab_center: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, -2.0]))
    r_ab_s: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, -3.5]))
    r_s_feed: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, -1.0]))
    alpha: float = 0.0
    cabin_mass: float = 30_091.8
    cabin_com: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, -1.0]))
    cable_mass_per_length: float = 10.0
    ab_mass: float = 4860.0
    ab_com: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, -2.251751]))


@dataclass(frozen=True)
class FastLimits:
    """Tilt and tension limits (REFERENCE.md).

    Attributes:
      cabin_tilt: the cabin's largest tilt, rad (planned 0-14 deg).
      ab_tilt: the A-B rotator's largest tilt, rad (26.4 deg).
      tension_min, tension_max: cable tension limits, N (T_min a parameter, default 60 kN:
        CASPR's 120 kN cannot hold, REFERENCE.md; T_max 1200 kN).
    """

    cabin_tilt: float = math.radians(14.0)
    ab_tilt: float = math.radians(26.4)
    tension_min: float = 60e3
    tension_max: float = 1200e3


FAST = FastGeometry()
FAST_LIMITS = FastLimits()


def _paired_ring(radius: float, centres_deg, half_gap_deg: float, z: float) -> np.ndarray:
    angles = [c + sign * half_gap_deg for c in centres_deg for sign in (-1.0, 1.0)]
    return _ring(radius, angles, z)


@dataclass(frozen=True)
class StewartGeometry:
    """The Stewart stabilizer between the A-B rotator and the feed platform (assumptions).

    Not given by the paper or REFERENCE.md; chosen for a stabilizer inside a 13 m cabin that
    carries the receivers (the 19-beam receiver's cryostat is about 1 t):
      base_anchors: (6, 3) upper joints in the AB frame, m: pairs 30 deg apart around 0, 120,
        240 deg on a 1.6 m radius, 1.5 m below the rotator's centre.
      platform_anchors: (6, 3) lower joints in the S frame, m: pairs 30 deg apart around 60,
        180, 300 deg on a 1.1 m radius, in the platform plane. Leg i joins base anchor i to
        platform anchor (i + 1) mod 6's neighbour so the legs cross in the usual zig-zag.
      stroke: +/- leg length change from nominal, m.
    """

    base_anchors: np.ndarray = field(default_factory=lambda: _paired_ring(1.6, [0, 120, 240], 15.0, -1.5))
    platform_anchors: np.ndarray = field(
        default_factory=lambda: np.roll(_paired_ring(1.1, [60, 180, 300], 15.0, 0.0), 1, axis=0)
    )
    stroke: float = 0.25


STEWART = StewartGeometry()


def stewart_leg_lengths(
    offset=None, rotation=None, geometry: FastGeometry = FAST, stewart: StewartGeometry = STEWART
) -> np.ndarray:
    """(..., 6) Stewart leg lengths, m, for a platform displaced by ``offset`` (..., 3) in the
    AB frame and turned by ``rotation`` (..., 3, 3) from its nominal pose at r_AB-s (the same
    leg formula as the cables and the hexapod, planbench.planners.legs)."""
    position = geometry.r_ab_s if offset is None else geometry.r_ab_s + np.asarray(offset, dtype=float)
    if rotation is None:
        rotation = np.broadcast_to(np.eye(3), np.shape(position)[:-1] + (3, 3))
    return leg_lengths(stewart.base_anchors, stewart.platform_anchors, position, rotation)


# ----------------------------------------------------------------------------- rotations


def tilt_torsion(phi, theta, omega=0.0) -> np.ndarray:
    """R = Rz(phi) Ry(theta) Rz(-phi) Rz(omega) (eq. 2; omega = 0 is eq. 3), (..., 3, 3).

    phi: azimuth of the tilt axis' normal (the direction the z axis tilts toward, from +X),
    theta: tilt of the z axis from the vertical, omega: torsion; rad.
    """
    phi, theta, omega = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (phi, theta, omega)))
    return rot_z(phi) @ rot_y(theta) @ rot_z(omega - phi)


def ab_rotation(theta_a, theta_b, alpha: float = 0.0) -> np.ndarray:
    """R_AB = Rz(alpha) Ry(theta_A) Rx(theta_B) Rz(-alpha) (eq. 5 as REFERENCE.md reads it)."""
    return rot_z(alpha) @ rot_y(theta_a) @ rot_x(theta_b) @ rot_z(-alpha)


def ab_angles(phi_ab, theta_ab, alpha: float = 0.0):
    """(theta_A, theta_B), rad, that tilt the rotator's z axis by theta_ab toward phi_ab.

    Eq. (7)-(8) with the corrected sign (REFERENCE.md):
      sin theta_B = sin theta_AB sin(alpha - phi_AB),
      sin theta_A cos theta_B = sin theta_AB cos(phi_AB - alpha),
    and cos theta_A cos theta_B = cos theta_AB for the branch |theta_A|, |theta_B| < 90 deg.
    """
    phi_ab = np.asarray(phi_ab, dtype=float)
    theta_ab = np.asarray(theta_ab, dtype=float)
    s = np.sin(theta_ab)
    theta_b = np.arcsin(np.clip(s * np.sin(alpha - phi_ab), -1.0, 1.0))
    theta_a = np.arctan2(s * np.cos(phi_ab - alpha), np.cos(theta_ab))
    return theta_a, theta_b


# ----------------------------------------------------------------------------- the sky side


def source_direction(azimuth, elevation) -> np.ndarray:
    """Unit vector(s) toward a source at azimuth (from north through east) and elevation, rad."""
    az, el = np.broadcast_arrays(np.asarray(azimuth, dtype=float), np.asarray(elevation, dtype=float))
    return np.stack([np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.sin(el)], axis=-1)


def zenith_angle(direction) -> np.ndarray:
    """Angle between a direction (..., 3) and the zenith, rad."""
    d = np.asarray(direction, dtype=float)
    return np.arctan2(np.linalg.norm(d[..., :2], axis=-1), d[..., 2])


class ZenithLimitError(LimitError):
    """A direction beyond FAST's zenith-angle limit (40 deg, Table 1): a source out of reach."""


def check_zenith_angle(direction, limit: float = MAX_ZENITH_ANGLE, times=None) -> None:
    """ZenithLimitError naming the first sample whose zenith angle exceeds the limit (40 deg)."""
    za = np.atleast_1d(zenith_angle(direction))
    bad = np.flatnonzero(za > limit + 1e-12)
    if bad.size:
        i = int(bad[0])
        where = f" at t = {float(np.atleast_1d(times)[i]):.3f} s" if times is not None else f" (sample {i})"
        raise ZenithLimitError(
            f"zenith angle {math.degrees(za[i]):.3f} deg{where} is beyond the limit {math.degrees(limit):.1f} deg"
        )


def feed_position(direction, radius: float = FOCAL_SURFACE_RADIUS) -> np.ndarray:
    """The feed on the focal surface for a source direction s: P_feed = -r s, m."""
    return -radius * np.asarray(direction, dtype=float)


def closest_focal_point(point, radius: float = FOCAL_SURFACE_RADIUS) -> np.ndarray:
    """The point of the focal sphere closest to ``point`` (the paper's P_h, section 3.2)."""
    p = np.asarray(point, dtype=float)
    norm = np.linalg.norm(p, axis=-1, keepdims=True)
    if np.any(norm == 0):
        raise PlanningError("the sphere's centre has no closest focal point")
    return radius * p / norm


# ----------------------------------------------------------------------------- kinematics


@dataclass(frozen=True)
class CabinPose:
    """The mechanisms' set-points for feed poses (arrays over leading dimensions).

    Attributes:
      feed: (..., 3) feed phase centre, m.
      axis: (..., 3) feed axis (unit, toward the source).
      phi: (...) azimuth of the tilt plane, rad.
      cabin_tilt, ab_tilt: (...) theta_C and theta_AB, rad.
      theta_a, theta_b: (...) the A-B rotator's angles, rad.
      rotation: (..., 3, 3) R_C.
      ab_point: (..., 3) P_AB, the cable robot's control point, m (eq. 9).
      origin: (..., 3) the cabin frame's origin (anchor-plane centre), m.
    """

    feed: np.ndarray
    axis: np.ndarray
    phi: np.ndarray
    cabin_tilt: np.ndarray
    ab_tilt: np.ndarray
    theta_a: np.ndarray
    theta_b: np.ndarray
    rotation: np.ndarray
    ab_point: np.ndarray
    origin: np.ndarray


def cabin_pose(feed, axis, cabin_tilt, geometry: FastGeometry = FAST) -> CabinPose:
    """Cabin pose and A-B angles that put the feed at ``feed`` looking along ``axis``.

    The cabin tilts by ``cabin_tilt`` toward the azimuth of ``axis`` (R_C = tilt_torsion(phi,
    theta_C), eq. 3) and the A-B rotator by the rest of the zenith angle (eq. 7-8); then
    eq. (4) gives P_AB-feed and eq. (9) the control point P_AB.
    """
    feed = np.asarray(feed, dtype=float)
    axis = np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis, axis=-1, keepdims=True)
    cabin_tilt = np.broadcast_to(np.asarray(cabin_tilt, dtype=float), axis.shape[:-1])
    phi = np.arctan2(axis[..., 1], axis[..., 0])
    za = zenith_angle(axis)
    ab_tilt = za - cabin_tilt
    rotation = tilt_torsion(phi, cabin_tilt)
    theta_a, theta_b = ab_angles(phi, ab_tilt, geometry.alpha)
    r_ab = ab_rotation(theta_a, theta_b, geometry.alpha)
    ab_feed = r_ab @ (geometry.r_ab_s + geometry.r_s_feed)  # eq. (4)
    ab_point = feed - np.einsum("...ij,...j->...i", rotation, ab_feed)  # eq. (9)
    origin = ab_point - np.einsum("...ij,j->...i", rotation, geometry.ab_center)
    return CabinPose(feed, axis, phi, cabin_tilt, ab_tilt, theta_a, theta_b, rotation, ab_point, origin)


def feed_from_cabin(
    origin, rotation, theta_a, theta_b, geometry: FastGeometry = FAST, stewart_offset=None
) -> np.ndarray:
    """Forward kinematics, eq. (1) and (4): the feed from the cabin pose and the A-B angles.

    ``stewart_offset`` (..., 3): a displacement of the Stewart platform in the AB frame
    (its correction), m; None for the nominal platform.
    """
    rotation = np.asarray(rotation, dtype=float)
    r_ab = ab_rotation(theta_a, theta_b, geometry.alpha)
    r_ab_s = geometry.r_ab_s if stewart_offset is None else geometry.r_ab_s + np.asarray(stewart_offset)
    ab_feed = np.einsum("...ij,...j->...i", r_ab, r_ab_s + geometry.r_s_feed)
    ab_point = np.asarray(origin) + np.einsum("...ij,j->...i", rotation, geometry.ab_center)
    return ab_point + np.einsum("...ij,...j->...i", rotation, ab_feed)


def cable_lengths(origin, rotation, geometry: FastGeometry = FAST) -> np.ndarray:
    """(..., 6) straight-line cable lengths from the tower tops to the cabin anchors, m."""
    return leg_lengths(geometry.tower_anchors, geometry.cabin_anchors, origin, rotation)


# ----------------------------------------------------------------------------- statics


def cabin_com_at(ab_rotation=None, geometry: FastGeometry = FAST) -> np.ndarray:
    """(..., 3) the whole cabin's centre of mass in the cabin frame, m, with the A-B rotator
    at ``ab_rotation`` (..., 3, 3) (None: level): cabin_com + (m_AB / m) (R_AB - I) r_AB-com."""
    if ab_rotation is None:
        return geometry.cabin_com
    shift = np.einsum("...ij,j->...i", np.asarray(ab_rotation, dtype=float), geometry.ab_com) - geometry.ab_com
    return geometry.cabin_com + (geometry.ab_mass / geometry.cabin_mass) * shift


def gravity_wrench(origin, rotation, lengths, geometry: FastGeometry = FAST, ab_rotation=None) -> np.ndarray:
    """(..., 6) weight of the cabin and the lumped half cable weights, about the cabin origin.

    Force in N, moment in N m (inertial axes). ``ab_rotation`` (..., 3, 3): R_AB, whose tilt
    moves the cabin's centre of mass (``cabin_com_at``); None for a level rotator.
    """
    rotation = np.asarray(rotation, dtype=float)
    weight = geometry.cabin_mass * GRAVITY
    force = np.zeros(rotation.shape[:-2] + (3,))
    force[..., 2] = -weight
    com_arm = np.einsum("...ij,...j->...i", rotation, cabin_com_at(ab_rotation, geometry))
    moment = np.cross(com_arm, force)
    half_cable = 0.5 * geometry.cable_mass_per_length * GRAVITY * np.asarray(lengths)  # (..., 6)
    anchor_arms = np.einsum("...ij,nj->...ni", rotation, geometry.cabin_anchors)
    cable_force = np.zeros(half_cable.shape + (3,))
    cable_force[..., 2] = -half_cable
    force = force + cable_force.sum(axis=-2)
    moment = moment + np.cross(anchor_arms, cable_force).sum(axis=-2)
    return np.concatenate([force, moment], axis=-1)


def cable_tensions(origin, rotation, geometry: FastGeometry = FAST, extra_wrench=None, ab_rotation=None) -> np.ndarray:
    """(..., 6) static cable tensions, N (positive pulls), from A t + W = 0.

    W: the cabin's weight (its centre of mass moved by the A-B tilt ``ab_rotation``, if
    given) and the lumped cable weights (``gravity_wrench``), plus ``extra_wrench`` (..., 6)
    about the cabin origin (e.g. wind), if given.
    """
    lengths = cable_lengths(origin, rotation, geometry)
    wrench = gravity_wrench(origin, rotation, lengths, geometry, ab_rotation)
    if extra_wrench is not None:
        wrench = wrench + np.asarray(extra_wrench, dtype=float)
    a = structure_matrix(geometry.tower_anchors, geometry.cabin_anchors, origin, rotation)
    return leg_forces(a, wrench)


def pose_tensions(pose: CabinPose, geometry: FastGeometry = FAST) -> np.ndarray:
    """(..., 6) static cable tensions, N, of a ``CabinPose`` (its A-B tilt included)."""
    return cable_tensions(
        pose.origin, pose.rotation, geometry, ab_rotation=ab_rotation(pose.theta_a, pose.theta_b, geometry.alpha)
    )


def _softmin(values: np.ndarray, scale: float) -> np.ndarray:
    """A smooth lower bound of min(values, axis=-1) (log-sum-exp), within scale * ln(n)."""
    lo = values.min(axis=-1, keepdims=True)
    return lo[..., 0] - scale * np.log(np.exp(-(values - lo) / scale).sum(axis=-1))


@dataclass(frozen=True)
class TiltSplit:
    """Result of ``split_tilt``: the chosen cabin tilt and the statics there."""

    pose: CabinPose
    tensions: np.ndarray  # (..., 6) N


def split_tilt(
    feed,
    axis,
    geometry: FastGeometry = FAST,
    limits: FastLimits = FAST_LIMITS,
    iterations: int = 48,
    softness: float = 2e3,
    check: bool = True,
) -> TiltSplit:
    """Split the feed's tilt between the cabin and the A-B rotator (vectorized over poses).

    Among cabin tilts theta_C in [max(0, ZA - ab_tilt), min(cabin_tilt, ZA)] it takes the one
    that maximizes the smallest static cable tension, smoothed (a log-sum-exp soft minimum
    with ``softness`` N, so the choice varies smoothly along a path where the two smallest
    tensions trade places), by golden-section search on every pose at once.
    With ``check``: LimitError when the zenith angle is beyond what the two tilts can make,
    or when the best split leaves a tension outside [tension_min, tension_max], naming the
    first such pose.
    """
    axis = np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis, axis=-1, keepdims=True)
    feed = np.asarray(feed, dtype=float)
    za = zenith_angle(axis)
    lo = np.maximum(0.0, za - limits.ab_tilt)
    hi = np.minimum(limits.cabin_tilt, za)
    if check and np.any(lo > hi + 1e-12):
        i = int(np.flatnonzero((lo > hi + 1e-12).ravel())[0])
        raise ZenithLimitError(
            f"zenith angle {math.degrees(za.ravel()[i]):.3f} deg (pose {i}) is beyond the "
            f"cabin's {math.degrees(limits.cabin_tilt):.1f} deg plus the A-B rotator's "
            f"{math.degrees(limits.ab_tilt):.1f} deg"
        )
    hi = np.maximum(hi, lo)

    def objective(tilt):
        return _softmin(pose_tensions(cabin_pose(feed, axis, tilt, geometry), geometry), softness)

    golden = (math.sqrt(5.0) - 1.0) / 2.0
    a, b = lo.copy(), hi.copy()
    c, d = b - golden * (b - a), a + golden * (b - a)
    fc, fd = objective(c), objective(d)
    for _ in range(iterations):  # maximize; one new evaluation per iteration
        left = fc >= fd  # the maximum lies in [a, d]
        a = np.where(left, a, c)
        b = np.where(left, d, b)
        point = np.where(left, b - golden * (b - a), a + golden * (b - a))
        value = objective(point)
        c, d = np.where(left, point, d), np.where(left, c, point)
        fc, fd = np.where(left, value, fd), np.where(left, fc, value)
    tilt = 0.5 * (a + b)
    pose = cabin_pose(feed, axis, tilt, geometry)
    tensions = pose_tensions(pose, geometry)
    if check:
        check_tensions(tensions, limits)
    return TiltSplit(pose, tensions)


def check_tensions(tensions, limits: FastLimits = FAST_LIMITS, times=None) -> None:
    """LimitError naming the first cable tension outside [tension_min, tension_max]."""
    t = np.asarray(tensions, dtype=float).reshape(-1, 6)
    for bad, limit, word in (
        (t < limits.tension_min, limits.tension_min, "below the minimum"),
        (t > limits.tension_max, limits.tension_max, "above the maximum"),
    ):
        if bad.any():
            i, j = np.argwhere(bad)[0]
            where = f" at t = {float(np.ravel(times)[i]):.3f} s" if times is not None else f" (pose {i})"
            raise LimitError(
                f"{CABLE_LABELS[j]} tension {t[i, j] / 1e3:.1f} kN{where} is {word} "
                f"{limit / 1e3:.0f} kN: no cabin tilt keeps the cables in range"
            )


# ----------------------------------------------------------------------------- tilt law

_TILT_LAWS: dict = {}


class TiltLaw:
    """The cabin tilt as a smooth function of the feed axis, for plans.

    ``split_tilt`` on every sample of a plan would cost a golden-section search per sample and
    its round-off would show in the rates. Instead the best split is computed once on a grid
    of axis directions over the focal sphere (u, v) = (s_x, s_y), |(u, v)| = sin ZA, up to the
    40 deg zenith angle (49 x 49 points; outside the limit the radially clamped value), and a
    bicubic spline (scipy RectBivariateSpline) interpolates it, clipped to each pose's
    admissible interval [max(0, ZA - ab_tilt), min(cabin_tilt, ZA)]. Tensions are always
    computed for the actual pose.
    """

    def __init__(self, geometry: FastGeometry = FAST, limits: FastLimits = FAST_LIMITS, points: int = 49):
        from scipy.interpolate import RectBivariateSpline

        self.geometry, self.limits = geometry, limits
        edge = math.sin(MAX_ZENITH_ANGLE)
        grid = np.linspace(-edge, edge, points)
        u, v = np.meshgrid(grid, grid, indexing="ij")
        rho = np.minimum(np.hypot(u, v), edge)
        scale = np.where(np.hypot(u, v) > 0, rho / np.maximum(np.hypot(u, v), 1e-300), 1.0)
        uu, vv = u * scale, v * scale
        axis = np.stack([uu, vv, np.sqrt(1.0 - uu**2 - vv**2)], axis=-1)
        split = split_tilt(-FOCAL_SURFACE_RADIUS * axis, axis, geometry, limits, check=False)
        self._spline = RectBivariateSpline(grid, grid, split.pose.cabin_tilt, kx=3, ky=3)

    def __call__(self, axis) -> np.ndarray:
        axis = np.asarray(axis, dtype=float)
        axis = axis / np.linalg.norm(axis, axis=-1, keepdims=True)
        tilt = self._spline(axis[..., 0].ravel(), axis[..., 1].ravel(), grid=False).reshape(axis.shape[:-1])
        za = zenith_angle(axis)
        lo = np.maximum(0.0, za - self.limits.ab_tilt)
        hi = np.maximum(np.minimum(self.limits.cabin_tilt, za), lo)
        return np.clip(tilt, lo, hi)


def tilt_law(geometry: FastGeometry = FAST, limits: FastLimits = FAST_LIMITS) -> TiltLaw:
    """The TiltLaw of a geometry and limits, built once per pair of objects."""
    key = (id(geometry), id(limits))
    if key not in _TILT_LAWS:
        _TILT_LAWS[key] = (TiltLaw(geometry, limits), geometry, limits)  # keep them alive
    return _TILT_LAWS[key][0]
