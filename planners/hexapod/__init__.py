"""Rubin-style hexapod: kinematics and the synchronous/asynchronous trajectory generator.

Paper: the trajectory page of lsst-ts/ts_mthexapod, REFERENCE.md
"Papers" ("the paper" below). Geometry and limits: REFERENCE.md, "Rubin
hexapod" (from ts_mthexapod's ``constants.py``, camera hexapod).

Conventions
-----------
* Pose (x, y, z, rx, ry, rz) in m and rad, in the hexapod frame (the frame of the base pivots).
  The mirror-side (moving) pivots are rotated by R = Rx(rx) Ry(ry) Rz(rz) about the rotation
  pivot and then translated by (x, y, z): m_i' = c + (x, y, z) + R (m_i - c). Note the paper
  orders its vectors (rx, ry, rz, x, y, z); the code uses Rubin's (x, y, z, rx, ry, rz).
* Strut position: the strut's length change from its length at the zero pose, m (what the
  strut encoders read). The stroke limit applies to it.
* Times of the paper are *half-move* times: it plans the first half of a symmetric profile.

The generator (paper, "Trajectory")
-----------------------------------
1. Hexapod-space minimum half time t'_min from the radial, axial, radial-angular and
   axial-angular half displacements, each a triangle velocity profile at that direction's
   maximum speed: t' = 2 d' / v'_max.
2. Per strut, half displacement d_i = |p_cmd - p_now| / 2; threshold d_th = v_max^2 / (2 a_max);
   t_i = (d_i - d_th) / v_max + v_max / a_max if d_i > d_th, else sqrt(2 d_i / a_max).
3. T_i = max(t_i, t'_min); synchronous: every strut gets T_max = max_i T_i.
4. Per strut, the smallest acceleration that covers d_i in T_i: a triangle when
   v_avg = d_i / T_i <= v_max / 2 (a = 2 v_avg / T_i), otherwise a trapezoid that cruises at
   v_max, found by the paper's self-consistent iteration of
       t_accel = v_max / a,  T = t_vmax / 2 + t_accel,  v_avg T = a t_accel^2 / 2 + v_max t_vmax / 2
   under 0 <= a <= a_max (``long_move_iteration``). Its closed form (``long_move_closed_form``):
       t_accel = 2 (T - d / v_max),  a = v_max / t_accel.
5. The controller runs at 200 Hz and commands a constant acceleration per tick. A continuous
   profile whose switching times fall inside a tick would not end exactly on the target, so
   the profile is realized on the tick grid (``realize_on_ticks``): the move takes
   n = ceil(2 T / dt) ticks (one more where the rounding would break a limit), accelerates for
   n_acc whole ticks, cruises and brakes for n_acc ticks, with n_acc the largest count that
   keeps the cruise speed <= v_max (the minimum acceleration, as step 4) and
   a = D / (n_acc (n - n_acc) dt^2). Integrating those accelerations tick by tick ends exactly
   on the target, with |v| <= v_max and |a| <= a_max; synchronous moves share n.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import partial

import numpy as np

from planbench.planners.errors import LimitError, PlanningError
from planbench.planners.legs import component_norm, leg_forces, leg_lengths, leg_vector_components, structure_matrix
from planbench.planners.trajectory import TrajectorySample, check_positive, check_values, sample_times

POSE_LABELS = ("x", "y", "z", "rx", "ry", "rz")
STRUT_LABELS = tuple(f"strut{i}" for i in range(1, 7))
CONTROL_DT = 0.005  # s: the paper's 200 Hz
# The most ticks one move may take: 5.8 days at 200 Hz. ``commanded_acceleration`` holds
# (ticks, 6) doubles, 4.8 GB at this count; a tick of, e.g., 1e-300 s would overflow the count.
MAX_TICKS = 1e8

_UM = 1e-6


class KinematicsError(PlanningError):
    """Forward kinematics did not converge (or met a singular Jacobian)."""


@dataclass(frozen=True)
class HexapodGeometry:
    """Six base pivots, six moving pivots and the rotation pivot, all in the hexapod frame, m.

    ``base_pivots[i]`` and ``platform_pivots[i]`` are the two ends of strut i at the zero pose.
    """

    base_pivots: np.ndarray
    platform_pivots: np.ndarray
    rotation_pivot: np.ndarray
    # Derived in __post_init__: the struts' lengths at the zero pose (m) and the moving
    # pivots relative to the rotation pivot (m).
    nominal_lengths: np.ndarray = field(init=False, repr=False, compare=False)
    platform_local: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        for name in ("base_pivots", "platform_pivots", "rotation_pivot"):
            value = np.array(check_values(getattr(self, name), name, "m"), dtype=float)
            value.setflags(write=False)
            object.__setattr__(self, name, value)
        if self.base_pivots.shape != (6, 3) or self.platform_pivots.shape != (6, 3):
            raise PlanningError(
                f"a hexapod needs (6, 3) base and platform pivots, got "
                f"{self.base_pivots.shape} and {self.platform_pivots.shape}"
            )
        if self.rotation_pivot.shape != (3,):
            raise PlanningError(f"rotation pivot must be (3,), got {self.rotation_pivot.shape}")
        lengths = np.linalg.norm(self.platform_pivots - self.base_pivots, axis=1)
        if not np.all(np.isfinite(lengths)) or np.any(lengths <= 0):
            raise PlanningError(f"strut lengths at the zero pose must be > 0, got {lengths}")
        object.__setattr__(self, "nominal_lengths", lengths)
        # The moving frame's origin is the rotation pivot: its points are m_i - c.
        local = self.platform_pivots - self.rotation_pivot
        local.setflags(write=False)
        object.__setattr__(self, "platform_local", local)


def _pose_label(name: str, index: tuple[int, ...]) -> str:
    """``check_values``'s name of a bad pose value: the pose and its axis."""
    return f"{name} {POSE_LABELS[index[0]]}"


def _pose_unit_of_index(index: tuple[int, ...]) -> str:
    return _pose_unit(index[-1])


def _strut_position_label(name: str, rows: bool, index: tuple[int, ...]) -> str:
    """``check_values``'s name of a bad strut position: the strut, and its row of many."""
    return f"{name} {STRUT_LABELS[index[1]]} position" + (f" of row {index[0]}" if rows else "")


@dataclass(frozen=True)
class HexapodLimits:
    """Position limits of the pose, strut stroke and speed/acceleration limits (SI).

    Attributes:
      pose_lower, pose_upper: (6,) limits of (x, y, z, rx, ry, rz), m and rad; each axis is
        limited on its own, as REFERENCE.md lists them.
      stroke: |strut length change| limit, m.
      strut_speed, strut_accel: v_max (m/s) and a_max (m/s^2) of every strut.
      linear_speed, angular_speed: hexapod-space v'_max for the radial and axial directions
        (m/s) and for the radial-angular and axial-angular directions (rad/s).
    """

    pose_lower: np.ndarray
    pose_upper: np.ndarray
    stroke: float
    strut_speed: float
    strut_accel: float
    linear_speed: float
    angular_speed: float

    def __post_init__(self):
        for name in ("pose_lower", "pose_upper"):
            value = np.array(getattr(self, name), dtype=float)
            if value.shape != (6,):
                raise PlanningError(f"{name} must have 6 components (x, y, z, rx, ry, rz), got shape {value.shape}")
            check_values(value, partial(_pose_label, name), _pose_unit_of_index)
            value.setflags(write=False)
            object.__setattr__(self, name, value)
        crossed = np.flatnonzero(self.pose_lower > self.pose_upper)
        if crossed.size:
            axis = int(crossed[0])
            raise PlanningError(
                f"pose_lower {POSE_LABELS[axis]} = {self.pose_lower[axis]:.6g} "
                f"{_pose_unit(axis)} is above pose_upper "
                f"{POSE_LABELS[axis]} = {self.pose_upper[axis]:.6g}"
            )
        for name in ("stroke", "strut_speed", "strut_accel", "linear_speed", "angular_speed"):
            check_positive(getattr(self, name), f"limit {name}")

    @property
    def threshold_distance(self) -> float:
        """d_threshold = v_max^2 / (2 a_max), m: the half distance that just reaches v_max."""
        return self.strut_speed**2 / (2.0 * self.strut_accel)


# REFERENCE.md, "Rubin hexapod": ts_mthexapod constants.py, camera hexapod (um -> m). The
# "±/∓" pairs are expanded in order, which puts the pivots around the circle in sequence.
RUBIN_CAMERA = HexapodGeometry(
    base_pivots=np.array(
        [
            [227_600, 653_800, -525_000],
            [-227_600, 653_800, -525_000],
            [-680_000, -129_700, -525_000],
            [-452_300, -524_000, -525_000],
            [452_300, -524_000, -525_000],
            [680_000, -129_700, -525_000],
        ]
    )
    * _UM,
    platform_pivots=np.array(
        [
            [472_800, 512_200, -121_400],
            [-472_800, 512_200, -121_400],
            [-680_000, 153_300, -121_400],
            [-207_200, -665_500, -121_400],
            [207_200, -665_500, -121_400],
            [680_000, 153_300, -121_400],
        ]
    )
    * _UM,
    rotation_pivot=np.array([0.0, 0.0, -2_758_400 * _UM]),
)

RUBIN_LIMITS = HexapodLimits(
    pose_lower=np.array(
        [-11_400 * _UM, -11_400 * _UM, -13_100 * _UM, np.radians(-0.36), np.radians(-0.36), np.radians(-0.10)]
    ),
    pose_upper=np.array(
        [11_400 * _UM, 11_400 * _UM, 13_100 * _UM, np.radians(0.36), np.radians(0.36), np.radians(0.10)]
    ),
    stroke=14_100 * _UM,
    strut_speed=500 * _UM,
    strut_accel=500 * _UM,
    linear_speed=2_000 * _UM,
    angular_speed=np.radians(0.1146),
)


# --------------------------------------------------------------------------- kinematics


def rotation_matrix(angles) -> np.ndarray:
    """R = Rx(rx) Ry(ry) Rz(rz) for angles (..., 3) in rad -> (..., 3, 3).

    Equal to scipy's ``Rotation.from_euler("XYZ", angles)`` (intrinsic x-y-z); written out so
    the Jacobian below can use its partial derivatives.
    """
    angles = np.asarray(angles, dtype=float)
    cx, cy, cz = np.cos(angles[..., 0]), np.cos(angles[..., 1]), np.cos(angles[..., 2])
    sx, sy, sz = np.sin(angles[..., 0]), np.sin(angles[..., 1]), np.sin(angles[..., 2])
    r = np.empty(angles.shape[:-1] + (3, 3))
    r[..., 0, 0] = cy * cz
    r[..., 0, 1] = -cy * sz
    r[..., 0, 2] = sy
    r[..., 1, 0] = cx * sz + sx * sy * cz
    r[..., 1, 1] = cx * cz - sx * sy * sz
    r[..., 1, 2] = -sx * cy
    r[..., 2, 0] = sx * sz - cx * sy * cz
    r[..., 2, 1] = sx * cz + cx * sy * sz
    r[..., 2, 2] = cx * cy
    return r


def _pose_unit(axis: int) -> str:
    return "m" if axis < 3 else "rad"


def _as_poses(pose, what: str = "pose") -> np.ndarray:
    """Poses (..., 6) as floats; PlanningError naming the row, axis and value of a NaN, inf or
    |value| > MAX_MAGNITUDE entry (``planbench.planners.trajectory.check_values``)."""
    try:
        pose = np.asarray(pose, dtype=float)
    except (TypeError, ValueError):
        raise PlanningError(f"{what} {pose!r} must be numbers") from None
    if pose.shape[-1:] != (6,):
        raise PlanningError(f"{what} must have 6 components (x, y, z, rx, ry, rz), got shape {pose.shape}")
    flat = pose.reshape(-1, 6)
    check_values(
        flat,
        lambda i: f"{what} {POSE_LABELS[i[1]]}" + (f" of row {i[0]}" if pose.ndim > 1 else ""),
        lambda i: _pose_unit(i[1]),
    )
    return pose


def _um(value: float) -> str:
    """A length in um as the limit messages write it (fixed point unless it is huge)."""
    um = value * 1e6
    return f"{um:.1f}" if abs(um) < 1e9 else f"{um:.6g}"


def _deg(value: float) -> str:
    deg = np.degrees(value)
    return f"{deg:.4f}" if abs(deg) < 1e9 else f"{deg:.6g}"


def platform_frame(pose, geometry: HexapodGeometry = RUBIN_CAMERA):
    """Position of the moving frame (origin at the rotation pivot) and its rotation matrix."""
    pose = _as_poses(pose)
    return geometry.rotation_pivot + pose[..., :3], rotation_matrix(pose[..., 3:])


def pivot_positions(pose, geometry: HexapodGeometry = RUBIN_CAMERA) -> np.ndarray:
    """(..., 6, 3) mirror-side pivot positions at the poses, m: c + (x, y, z) + R (m_i - c)."""
    position, rotation = platform_frame(pose, geometry)
    return position[..., None, :] + np.einsum("...jk,nk->...nj", rotation, geometry.platform_local)


def strut_lengths(pose, geometry: HexapodGeometry = RUBIN_CAMERA) -> np.ndarray:
    """Inverse kinematics: (..., 6) pose -> (..., 6) strut lengths, m."""
    position, rotation = platform_frame(pose, geometry)
    return leg_lengths(geometry.base_pivots, geometry.platform_local, position, rotation)


def strut_positions(pose, geometry: HexapodGeometry = RUBIN_CAMERA) -> np.ndarray:
    """(..., 6) strut length changes from the zero pose, m (the encoder readings)."""
    return strut_lengths(pose, geometry) - geometry.nominal_lengths


def euler_rate_matrix(angles) -> np.ndarray:
    """E with omega = E d(rx, ry, rz)/dt for R = Rx Ry Rz; omega in the fixed frame.

    Columns: e_x, Rx e_y, Rx Ry e_z (the axes of the three successive rotations).
    """
    angles = np.asarray(angles, dtype=float)
    cx, sx = np.cos(angles[..., 0]), np.sin(angles[..., 0])
    cy, sy = np.cos(angles[..., 1]), np.sin(angles[..., 1])
    e = np.zeros(angles.shape[:-1] + (3, 3))
    e[..., 0, 0] = 1.0
    e[..., 1, 1] = cx
    e[..., 2, 1] = sx
    e[..., 0, 2] = sy
    e[..., 1, 2] = -sx * cy
    e[..., 2, 2] = cx * cy
    return e


def jacobian(pose, geometry: HexapodGeometry = RUBIN_CAMERA) -> np.ndarray:
    """(..., 6, 6) dL/d(pose): row i is strut i, columns x, y, z, rx, ry, rz.

    dL_i = u_i . (dp + omega x R b_i) = u_i . dp + (R b_i x u_i) . E d(angles).
    Computed on components (``planbench.planners.legs.leg_vector_components``); E's first column is
    e_x and its (1, 0), (2, 0), (0, 1) entries are zeros, whose products the sum drops.
    """
    pose = _as_poses(pose)
    flat = pose.reshape(-1, 6)
    position, rotation = platform_frame(flat, geometry)
    (lx, ly, lz), (ax, ay, az) = leg_vector_components(
        geometry.base_pivots, geometry.platform_local, position, rotation
    )
    length = component_norm(lx, ly, lz)
    ux, uy, uz = lx / length, ly / length, lz / length
    # Column by column (contiguous writes); the result is the transposed view.
    columns = np.empty(flat.shape[:1] + (6, geometry.base_pivots.shape[0]))
    columns[:, 0], columns[:, 1], columns[:, 2] = ux, uy, uz
    # R b_i x u_i (np.cross's arithmetic), times E.
    cx, cy, cz = ay * uz - az * uy, az * ux - ax * uz, ax * uy - ay * ux
    e = euler_rate_matrix(flat[:, 3:])
    columns[:, 3] = cx
    columns[:, 4] = cy * e[:, 1, 1, None] + cz * e[:, 2, 1, None]
    columns[:, 5] = (cx * e[:, 0, 2, None] + cy * e[:, 1, 2, None]) + cz * e[:, 2, 2, None]
    return columns.swapaxes(-1, -2).reshape(pose.shape[:-1] + (columns.shape[-1], 6))


def forward_kinematics(
    lengths, geometry: HexapodGeometry = RUBIN_CAMERA, initial=None, tolerance: float = 1e-12, max_iterations: int = 20
):
    """Forward kinematics by Newton's method on the 6x6 Jacobian.

    Args:
      lengths: (..., 6) strut lengths, m.
      initial: (..., 6) starting poses (default: the zero pose).
      tolerance: the largest strut-length residual accepted, m.
      max_iterations: Newton steps before giving up.

    Returns:
      (pose (..., 6), iterations): the pose and the Newton steps it took.

    Raises:
      KinematicsError naming the residual when a pose does not converge (lengths no hexapod
      can reach, or a singular Jacobian).
    """
    lengths = np.asarray(lengths, dtype=float)
    if lengths.shape[-1:] != (6,) or not np.all(np.isfinite(lengths)):
        raise PlanningError(f"strut lengths must be (..., 6) and finite, got {lengths!r}")
    pose = np.zeros(lengths.shape) if initial is None else np.array(initial, dtype=float)
    pose = np.broadcast_to(pose, lengths.shape).copy()
    residual = strut_lengths(pose, geometry) - lengths
    for iteration in range(max_iterations + 1):
        worst = float(np.max(np.abs(residual))) if residual.size else 0.0
        if worst <= tolerance:
            return pose, iteration
        if iteration == max_iterations:
            break
        try:
            step = np.linalg.solve(jacobian(pose, geometry), residual[..., None])[..., 0]
        except np.linalg.LinAlgError:
            raise KinematicsError(f"forward kinematics met a singular Jacobian at iteration {iteration}") from None
        pose = pose - step
        residual = strut_lengths(pose, geometry) - lengths
        if not np.all(np.isfinite(residual)):
            break
    raise KinematicsError(
        f"forward kinematics did not converge: strut length residual {worst:.3g} m after "
        f"{max_iterations} Newton steps (tolerance {tolerance:g} m); the lengths may be "
        "outside the workspace"
    )


def check_pose_limits(pose, limits: HexapodLimits = RUBIN_LIMITS, what: str = "target") -> None:
    """Raise a LimitError naming the axis and limit if any pose lies outside the limits."""
    pose = _as_poses(pose, what)
    flat = pose.reshape(-1, 6)
    low = flat < limits.pose_lower - 1e-15
    high = flat > limits.pose_upper + 1e-15
    bad = low | high
    if bad.any():
        row, axis = np.argwhere(bad)[0]
        value = flat[row, axis]
        limit = limits.pose_lower[axis] if low[row, axis] else limits.pose_upper[axis]
        name = POSE_LABELS[axis]
        if axis < 3:
            text = f"{_um(value)} um is beyond its limit {_um(limit)} um"
        else:
            text = f"{_deg(value)} deg is beyond its limit {_deg(limit)} deg"
        where = f" (move {row})" if flat.shape[0] > 1 else ""
        raise LimitError(f"{what} {name} = {text}{where}")


def beyond_stroke(positions, limits: HexapodLimits = RUBIN_LIMITS) -> np.ndarray:
    """(..., 6) whether each strut position (m) is beyond the stroke."""
    return np.abs(positions) > limits.stroke + 1e-15


def stroke_messages(positions: np.ndarray, what: str, limits: HexapodLimits = RUBIN_LIMITS) -> list[str]:
    """``check_stroke``'s message for each row of (k, 6) strut positions (m), each with a strut
    beyond the stroke: the first such strut, its length change in mm."""
    strut = np.argmax(beyond_stroke(positions, limits), axis=1)
    change_mm = (positions[np.arange(positions.shape[0]), strut] * 1e3).tolist()
    heads = [f"{what} {label} length change " for label in STRUT_LABELS]
    tail = f" mm is beyond the stroke limit +/-{limits.stroke * 1e3:.4g} mm"
    return [f"{heads[s]}{v:.4f}{tail}" for s, v in zip(strut.tolist(), change_mm, strict=True)]


def check_stroke(positions, limits: HexapodLimits = RUBIN_LIMITS, what: str = "target") -> None:
    """Raise a LimitError naming the strut if a strut position exceeds the stroke."""
    flat = np.asarray(positions, dtype=float).reshape(-1, 6)
    rows = np.flatnonzero(beyond_stroke(flat, limits).any(axis=1))
    if rows.size:
        where = f" (move {rows[0]})" if flat.shape[0] > 1 else ""
        raise LimitError(stroke_messages(flat[rows[:1]], what, limits)[0] + where)


def random_poses(
    n: int, rng: np.random.Generator, geometry: HexapodGeometry = RUBIN_CAMERA, limits: HexapodLimits = RUBIN_LIMITS
) -> np.ndarray:
    """(n, 6) poses drawn uniformly inside the pose limits and the strut stroke (rejection)."""
    found, total = [], 0
    while total < n:
        poses = rng.uniform(limits.pose_lower, limits.pose_upper, size=(max(4 * (n - total), 16), 6))
        inside = np.all(np.abs(strut_positions(poses, geometry)) <= limits.stroke, axis=1)
        found.append(poses[inside])
        total += int(inside.sum())
    return np.vstack(found)[:n]


def static_strut_forces(pose, wrench, geometry: HexapodGeometry = RUBIN_CAMERA) -> np.ndarray:
    """Strut forces (N, tension positive) that hold the platform against an external wrench.

    Args:
      pose: (..., 6) pose.
      wrench: (..., 6) force (N) and moment (N m) on the platform about the rotation pivot's
        current position (the moving frame's origin), in the hexapod frame.

    Virtual work: J^T f = (F, E^T M) in pose coordinates (J = dL/dpose); written with the structure matrix of
    ``planbench.planners.legs`` (the same code FAST's cables use).
    """
    position, rotation = platform_frame(pose, geometry)
    structure = structure_matrix(geometry.base_pivots, geometry.platform_local, position, rotation)
    return leg_forces(structure, wrench)


# --------------------------------------------------------------------------- generator


def hexapod_space_min_time(displacement, limits: HexapodLimits = RUBIN_LIMITS) -> np.ndarray:
    """t'_min, the hexapod-space minimum *half* time of a move, s (paper).

    Args:
      displacement: (..., 6) pose change (dx, dy, dz, drx, dry, drz), m and rad.

    d'_radial = |(dx, dy)| / 2, d'_axial = |dz| / 2, d'_theta,radial = |(drx, dry)| / 2,
    d'_theta,axial = |drz| / 2; each t' = 2 d' / v'_max (a triangle profile); t'_min the max.
    """
    d = np.asarray(displacement, dtype=float)
    half = np.stack(
        [
            np.hypot(d[..., 0], d[..., 1]) / 2.0,
            np.abs(d[..., 2]) / 2.0,
            np.hypot(d[..., 3], d[..., 4]) / 2.0,
            np.abs(d[..., 5]) / 2.0,
        ],
        axis=-1,
    )
    speeds = np.array([limits.linear_speed, limits.linear_speed, limits.angular_speed, limits.angular_speed])
    return np.max(2.0 * half / speeds, axis=-1)


#: The four hexapod-space speeds of ``hexapod_space_min_time`` and ``hexapod_speed_ratios``.
HEXAPOD_SPEED_LABELS = ("radial", "axial", "radial-angular", "axial-angular")


def hexapod_speed_ratios(
    pose, strut_velocity, limits: HexapodLimits = RUBIN_LIMITS, geometry: HexapodGeometry = RUBIN_CAMERA
) -> np.ndarray:
    """(..., 4) the pose's hexapod-space speeds over their limits v'_max (paper, step 1).

    The pose rate is J(pose)^-1 times the strut speeds (``jacobian``: x, y, z and the rates of
    rx, ry, rz, the coordinates ``hexapod_space_min_time`` measures a move in); the four
    speeds are |(vx, vy)| and |vz| over ``linear_speed``, |(d rx, d ry)| and |d rz| over
    ``angular_speed``, in the order of HEXAPOD_SPEED_LABELS.

    Args:
      pose: (..., 6) poses, m and rad.
      strut_velocity: (..., 6) strut speeds there, m/s.
    """
    rate = np.linalg.solve(jacobian(pose, geometry), np.asarray(strut_velocity, dtype=float)[..., None])[..., 0]
    return np.stack(
        [
            np.hypot(rate[..., 0], rate[..., 1]) / limits.linear_speed,
            np.abs(rate[..., 2]) / limits.linear_speed,
            np.hypot(rate[..., 3], rate[..., 4]) / limits.angular_speed,
            np.abs(rate[..., 5]) / limits.angular_speed,
        ],
        axis=-1,
    )


def strut_min_time(half_distance, limits: HexapodLimits = RUBIN_LIMITS) -> np.ndarray:
    """t_i,max: minimum half time of a strut's half distance d_i under v_max, a_max (paper)."""
    d = np.asarray(half_distance, dtype=float)
    v, a = limits.strut_speed, limits.strut_accel
    threshold = limits.threshold_distance
    long = (d - threshold) / v + v / a
    short = np.sqrt(2.0 * np.maximum(d, 0.0) / a)
    return np.where(d > threshold, long, short)


def long_move_closed_form(half_distance, half_time, strut_speed: float) -> np.ndarray:
    """a_cmd of a trapezoid cruising at v_max that covers d in the half time T (closed form).

    From the paper's three equations with t_accel = v_max / a:
    d = v_max T - v_max t_accel / 2, so t_accel = 2 (T - d / v_max) and a = v_max / t_accel.
    """
    d = np.asarray(half_distance, dtype=float)
    t = np.asarray(half_time, dtype=float)
    return strut_speed / (2.0 * (t - d / strut_speed))


def long_move_iteration(
    half_distance,
    half_time,
    strut_speed: float,
    strut_accel: float,
    tolerance: float = 1e-15,
    max_iterations: int = 200,
):
    """a_cmd of the long-move case by the paper's self-consistent iteration.

    The paper solves t_accel = v_max / a, T = t_vmax / 2 + t_accel and
    v_avg,new T = a t_accel^2 / 2 + v_max t_vmax / 2 for a, t_accel, t_vmax (three equations,
    four unknowns with v_avg,new) by iterating until v_avg,new equals v_avg = d / T, keeping
    0 <= a <= a_max. It does not print its update rule; here each iteration evaluates the three
    equations at a guess a and keeps the half of the bracket [v_max / T, a_max] that holds the
    solution (v_avg,new grows with a; at a = v_max / T the profile is the triangle with
    v_avg = v_max / 2, at a_max it is the strut's fastest). Vectorized over moves.

    Returns:
      (a_cmd, iterations): the acceleration, m/s^2, and the iterations it took.
    """
    d = np.asarray(half_distance, dtype=float)
    t = np.asarray(half_time, dtype=float)
    v = strut_speed
    v_avg = d / t
    low = np.minimum(v / t, strut_accel)
    high = np.full(np.broadcast(d, t).shape, float(strut_accel))
    a = high.copy()
    for iteration in range(1, max_iterations + 1):
        t_accel = v / a
        t_vmax = 2.0 * (t - t_accel)
        v_new = (0.5 * a * t_accel**2 + 0.5 * v * t_vmax) / t
        too_slow = v_new < v_avg
        low = np.where(too_slow, a, low)
        high = np.where(too_slow, high, a)
        if np.all(np.abs(v_new - v_avg) <= tolerance * v) or np.all(high - low <= 4 * np.spacing(high)):
            return a, iteration
        a = 0.5 * (low + high)
    return a, max_iterations


@dataclass(frozen=True)
class StrutProfiles:
    """The paper's continuous profiles, arrays (..., 6).

    half_distance d (m), half_time T (s), accel a_cmd (m/s^2), t_accel (s), t_vmax (s: the
    whole cruise; the half profile has t_vmax / 2), short (bool: the triangle case).
    """

    half_distance: np.ndarray
    half_time: np.ndarray
    accel: np.ndarray
    t_accel: np.ndarray
    t_vmax: np.ndarray
    short: np.ndarray


def solve_profiles(
    half_distance, half_time, limits: HexapodLimits = RUBIN_LIMITS, method: str = "iteration"
) -> StrutProfiles:
    """Step 4 of the generator: a_cmd, t_accel, t_vmax of every strut for its half time.

    ``method`` "iteration" (the paper's) or "closed" (the closed form); they agree (tested).
    """
    d = np.asarray(half_distance, dtype=float)
    t = np.broadcast_to(np.asarray(half_time, dtype=float), d.shape)
    v = limits.strut_speed
    moving = d > 0
    safe_t = np.where(moving, t, 1.0)
    v_avg = np.where(moving, d / safe_t, 0.0)
    short = v_avg <= v / 2.0
    a_short = 2.0 * v_avg / safe_t
    if method == "iteration":
        a_long, _ = long_move_iteration(np.where(short, 0.75 * v * safe_t, d), safe_t, v, limits.strut_accel)
    elif method == "closed":
        a_long = long_move_closed_form(np.where(short, 0.75 * v * safe_t, d), safe_t, v)
    else:
        raise PlanningError(f"method {method!r} is not 'iteration' or 'closed'")
    accel = np.where(short, a_short, a_long)
    t_accel = np.where(short, t, v / np.where(short, 1.0, a_long))
    t_vmax = np.where(short, 0.0, 2.0 * (t - t_accel))
    accel = np.where(moving, accel, 0.0)
    t_accel = np.where(moving, t_accel, 0.0)
    t_vmax = np.where(moving, t_vmax, 0.0)
    return StrutProfiles(d, t, accel, t_accel, t_vmax, short & moving)


def realize_on_ticks(
    distance,
    total_time,
    synchronous: bool,
    limits: HexapodLimits = RUBIN_LIMITS,
    dt: float = CONTROL_DT,
    max_extra_ticks: int = 1000,
):
    """Step 5: the tick-grid profile of every strut (vectorized over moves).

    Args:
      distance: (N, 6) whole strut distances |p_cmd - p_now|, m.
      total_time: (N, 6) whole move times 2 T_i, s (synchronous: equal along a row).
      synchronous: every strut of a move shares the tick count.

    Returns:
      (n_ticks, n_accel, accel): int (N, 6), int (N, 6), (N, 6) m/s^2. The strut accelerates at
      ``accel`` for n_accel ticks, cruises, and brakes for n_accel ticks; it is at rest on its
      target after n_ticks ticks. Idle struts have n_accel = 0 and accel = 0.
    """
    D = np.asarray(distance, dtype=float)
    v, a_max = limits.strut_speed, limits.strut_accel
    n = np.ceil(np.asarray(total_time, dtype=float) / dt - 1e-9).astype(np.int64)
    if synchronous:
        n = np.broadcast_to(n.max(axis=-1, keepdims=True), D.shape).copy()
    else:
        n = np.where(D > 0, n, 0)
    moving = D > 0
    for _ in range(max_extra_ticks + 1):
        n_accel = np.minimum(n // 2, np.floor(n - D / (v * dt) + 1e-12).astype(np.int64))
        n_accel = np.where(moving, n_accel, 0)
        valid = n_accel >= 1
        denom = np.where(valid, n_accel * (n - n_accel), 1) * dt * dt
        accel = np.where(moving & valid, D / denom, 0.0)
        peak = accel * n_accel * dt
        ok = ~moving | (valid & (accel <= a_max) & (peak <= v))
        if synchronous:
            ok = np.broadcast_to(ok.all(axis=-1, keepdims=True), ok.shape)
        if ok.all():
            return n, n_accel, accel
        n = np.where(ok, n, n + 1)
    raise PlanningError(f"no tick profile within {max_extra_ticks} extra ticks (distances {D})")


@dataclass(frozen=True)
class StrutMove:
    """One planned move of the six struts on the 200 Hz tick grid (a Trajectory).

    Positions are strut length changes from the zero pose (m). ``sample(t)`` evaluates the
    exact piecewise-quadratic motion that the tick accelerations produce; after a strut's
    last tick it rests exactly on its target.

    Attributes:
      start, target: (6,) strut positions, m.
      n_ticks, n_accel: (6,) ints (see ``realize_on_ticks``).
      accel: (6,) acceleration magnitude, m/s^2.
      dt: tick, s.
      profiles: the paper's continuous profiles of this move (half times etc.).
      synchronous: the mode.
      start_pose, target_pose: (6,) poses, when planned from poses.
    """

    start: np.ndarray
    target: np.ndarray
    n_ticks: np.ndarray
    n_accel: np.ndarray
    accel: np.ndarray
    dt: float
    profiles: StrutProfiles
    synchronous: bool
    start_pose: np.ndarray | None = None
    target_pose: np.ndarray | None = None
    labels: Sequence[str] = field(default=STRUT_LABELS)

    @property
    def direction(self) -> np.ndarray:
        return np.sign(self.target - self.start)

    @property
    def end_times(self) -> np.ndarray:
        """(6,) time at which each strut comes to rest on its target, s."""
        return self.n_ticks * self.dt

    @property
    def duration(self) -> float:
        return float(self.end_times.max()) if self.end_times.size else 0.0

    def commanded_acceleration(self) -> np.ndarray:
        """(n, 6) the acceleration commanded in each tick, m/s^2 (the paper's output)."""
        n = int(self.n_ticks.max())
        k = np.arange(n)[:, None]
        sign = np.where(k < self.n_accel, 1.0, np.where(k >= self.n_ticks - self.n_accel, -1.0, 0.0))
        sign = np.where(k < self.n_ticks, sign, 0.0)
        return sign * self.accel * self.direction

    def integrate(self):
        """Strut positions and velocities at the ticks by integrating the commanded accelerations.

        Returns (positions (n+1, 6), velocities (n+1, 6)): p_{k+1} = p_k + v_k dt + a_k dt^2/2,
        v_{k+1} = v_k + a_k dt, exact for a constant acceleration per tick.
        """
        acc = self.commanded_acceleration()
        dt = self.dt
        velocity = np.vstack([np.zeros((1, 6)), np.cumsum(acc * dt, axis=0)])
        steps = velocity[:-1] * dt + 0.5 * acc * dt * dt
        position = np.vstack([self.start[None, :], self.start + np.cumsum(steps, axis=0)])
        return position, velocity

    def sample(self, t) -> TrajectorySample:
        """Strut positions, velocities, accelerations at the times t (a number or a 1-D
        array of finite times, ``planbench.planners.trajectory.sample_times``)."""
        t = sample_times(t)
        tau = np.maximum(t, 0.0)[:, None]  # at rest on the start before t = 0
        a = self.accel
        t1 = self.n_accel * self.dt
        t_end = self.n_ticks * self.dt
        t2 = t_end - t1
        D = np.abs(self.target - self.start)
        s = self.direction
        accelerating = tau < t1
        braking = (tau >= t2) & (tau < t_end)
        done = tau >= t_end
        dist = np.where(
            accelerating,
            0.5 * a * tau**2,
            np.where(
                braking | done, D - 0.5 * a * np.clip(t_end - tau, 0, None) ** 2, 0.5 * a * t1**2 + a * t1 * (tau - t1)
            ),
        )
        vel = np.where(accelerating, a * tau, np.where(braking, a * (t_end - tau), np.where(done, 0.0, a * t1)))
        acc = np.where(accelerating & (t[:, None] >= 0), a, np.where(braking, -a, 0.0))
        position = np.where(done, self.target, self.start + s * dist)
        return TrajectorySample(t, position, s * vel, s * acc)


@dataclass(frozen=True)
class StrutMoves:
    """N moves planned at once (``plan_moves``); arrays are (N, 6). ``move(k)`` is one move."""

    start: np.ndarray
    target: np.ndarray
    n_ticks: np.ndarray
    n_accel: np.ndarray
    accel: np.ndarray
    dt: float
    profiles: StrutProfiles
    hexapod_half_time: np.ndarray
    synchronous: bool
    start_pose: np.ndarray | None = None
    target_pose: np.ndarray | None = None

    def __len__(self) -> int:
        return self.start.shape[0]

    @property
    def durations(self) -> np.ndarray:
        """(N,) time of each move, s."""
        return self.n_ticks.max(axis=-1) * self.dt

    def move(self, k: int) -> StrutMove:
        p = self.profiles
        prof = StrutProfiles(
            *(
                np.asarray(getattr(p, f))[k]
                for f in ("half_distance", "half_time", "accel", "t_accel", "t_vmax", "short")
            )
        )
        return StrutMove(
            self.start[k],
            self.target[k],
            self.n_ticks[k],
            self.n_accel[k],
            self.accel[k],
            self.dt,
            prof,
            self.synchronous,
            None if self.start_pose is None else self.start_pose[k],
            None if self.target_pose is None else self.target_pose[k],
        )


def plan_strut_moves(
    start,
    target,
    pose_displacement=None,
    synchronous: bool = True,
    limits: HexapodLimits = RUBIN_LIMITS,
    dt: float = CONTROL_DT,
    method: str = "closed",
) -> StrutMoves:
    """The generator on strut positions: (N, 6) current and target strut positions, m.

    Args:
      pose_displacement: (N, 6) pose change of each move for the hexapod-space limit, or None
        to plan in strut space only.
      synchronous: the paper's ControlCommands_cmdSynchronousMove (all struts arrive together).
      method: "closed" or "iteration" for the long-move acceleration (they agree; the batch
        default is the closed form for speed).

    Raises:
      LimitError naming the strut when a position is beyond the stroke.
    """
    start = np.atleast_2d(np.asarray(start, dtype=float))
    target = np.atleast_2d(np.asarray(target, dtype=float))
    if start.shape != target.shape or start.shape[-1] != 6 or start.ndim != 2:
        raise PlanningError(f"start {start.shape} and target {target.shape} must both be (N, 6)")
    if pose_displacement is not None:
        pose_displacement = np.atleast_2d(np.asarray(pose_displacement, dtype=float))
        if pose_displacement.shape != start.shape:
            raise PlanningError(f"pose displacement {pose_displacement.shape} must be {start.shape}, one per move")
    for name, value in (("start", start), ("target", target)):
        check_values(value, partial(_strut_position_label, name, value.shape[0] > 1), "m")
        check_stroke(value, limits, what=name)
    check_positive(dt, "tick", "s")
    distance = np.abs(target - start)
    half = distance / 2.0
    t_hex = np.zeros(start.shape[0])
    if pose_displacement is not None:
        t_hex = hexapod_space_min_time(pose_displacement, limits)
    t_strut = strut_min_time(half, limits)
    half_time = np.maximum(t_strut, t_hex[:, None])  # T_i,max
    if synchronous:
        half_time = np.broadcast_to(half_time.max(axis=-1, keepdims=True), half.shape)
    longest = 2.0 * float(np.max(half_time, initial=0.0))
    if longest / dt > MAX_TICKS:
        raise PlanningError(
            f"tick {dt!r} s is too short: the longest move ({longest:.6g} s) "
            f"would take {longest / dt:.3g} ticks, more than the {MAX_TICKS:g} "
            f"a plan holds"
        )
    profiles = solve_profiles(half, half_time, limits, method=method)
    n_ticks, n_accel, accel = realize_on_ticks(distance, 2.0 * np.asarray(half_time), synchronous, limits, dt)
    return StrutMoves(start, target, n_ticks, n_accel, accel, dt, profiles, t_hex, synchronous)


def plan_moves(
    start_pose,
    target_pose,
    synchronous: bool = True,
    geometry: HexapodGeometry = RUBIN_CAMERA,
    limits: HexapodLimits = RUBIN_LIMITS,
    dt: float = CONTROL_DT,
    method: str = "closed",
) -> StrutMoves:
    """Plan N pose-to-pose moves at once: inverse kinematics, limits, the generator.

    Args:
      start_pose, target_pose: (N, 6) or (6,) poses (x, y, z, rx, ry, rz), m and rad.

    Raises:
      LimitError naming the axis (pose limits) or the strut (stroke) and the limit.
    """
    start_pose = np.atleast_2d(_as_poses(start_pose, "start pose"))
    target_pose = np.atleast_2d(_as_poses(target_pose, "target pose"))
    if start_pose.ndim != 2 or target_pose.ndim != 2:
        raise PlanningError(f"poses must be (6,) or (N, 6), got {start_pose.shape} and {target_pose.shape}")
    if start_pose.shape[0] != target_pose.shape[0] and 1 not in (start_pose.shape[0], target_pose.shape[0]):
        raise PlanningError(
            f"{start_pose.shape[0]} start poses and {target_pose.shape[0]} "
            "target poses: give one of each per move (or one start for all)"
        )
    start_pose, target_pose = np.broadcast_arrays(start_pose, target_pose)
    check_pose_limits(start_pose, limits, "start")
    check_pose_limits(target_pose, limits, "target")
    moves = plan_strut_moves(
        strut_positions(start_pose, geometry),
        strut_positions(target_pose, geometry),
        target_pose - start_pose,
        synchronous,
        limits,
        dt,
        method,
    )
    return StrutMoves(**{**moves.__dict__, "start_pose": start_pose, "target_pose": target_pose})


def plan_move(
    start_pose,
    target_pose,
    synchronous: bool = True,
    geometry: HexapodGeometry = RUBIN_CAMERA,
    limits: HexapodLimits = RUBIN_LIMITS,
    dt: float = CONTROL_DT,
) -> StrutMove:
    """One pose-to-pose move (the paper's iteration for the long-move acceleration)."""
    return plan_moves(start_pose, target_pose, synchronous, geometry, limits, dt, method="iteration").move(0)


@dataclass(frozen=True)
class MoveProblem:
    """The hexapod's planning problem: one pose-to-pose move within the limits.

    Attributes:
      start_pose, target_pose: (6,) poses (x, y, z, rx, ry, rz) of the mirror-side pivot
        frame, m and rad (the paper's hexapod coordinates).
      synchronous: all six struts must arrive on the same tick (else each at its own time).
      limits: pose limits, stroke, strut speed and acceleration, hexapod-space speeds.
      geometry: the pivots and nominal strut lengths.
      dt: the controller's tick, s: the trajectory is sampled at it.
    The trajectory's channels are the six strut length changes STRUT_LABELS, m.
    """

    start_pose: np.ndarray
    target_pose: np.ndarray
    synchronous: bool = True
    limits: HexapodLimits = RUBIN_LIMITS
    geometry: HexapodGeometry = RUBIN_CAMERA
    dt: float = CONTROL_DT


class PaperMovePlanner:
    """The paper's move generator (``plan_move``): synchronous or asynchronous as the problem
    says, the long-move acceleration by the paper's iteration."""

    def plan(self, problem: MoveProblem) -> StrutMove:
        return plan_move(
            problem.start_pose, problem.target_pose, problem.synchronous, problem.geometry, problem.limits, problem.dt
        )


def own_move_times(problem: MoveProblem) -> np.ndarray:
    """(6,) each strut's own minimum move time for the problem, s: twice the larger of its
    strut-space half time under v_max and a_max and the move's hexapod-space time
    (``strut_min_time``, ``hexapod_space_min_time``), before any tick rounding. What the
    asynchronous check compares each strut's arrival with, from the problem alone."""
    start = strut_positions(np.atleast_2d(problem.start_pose), problem.geometry)
    target = strut_positions(np.atleast_2d(problem.target_pose), problem.geometry)
    half = np.abs(target - start) / 2.0
    t_hex = hexapod_space_min_time(np.atleast_2d(problem.target_pose - problem.start_pose), problem.limits)
    return 2.0 * np.maximum(strut_min_time(half, problem.limits), t_hex[:, None])[0]
