"""PRR-3R ammunition loading robot: Table 1 key points, the supply plans, forward kinematics.

Paper: Li, Xu, Luo, "Trajectory Planning of Ammunition Loading Robot Based on Cubic-B Spline"
(REFERENCE.md "Papers"). Table 1 gives theta1 (prismatic, read as mm)
and theta2 ... theta6 (degrees) at the start point P2, the obstacle-avoiding key points
M1 ... M4 and the end point P3, at t = 0, 0.5, ... 2.5 s. The mapping of these values onto the
model's joints is in ``models/loader/README.md``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from planbench.models import SerialChainSpec, loader_spec
from planbench.planners.errors import PlanningError
from planbench.planners.loader.bspline import CubicBSplineTrajectory
from planbench.planners.trajectory import check_values

#: Table 1 as printed: rows P2, M1, M2, M3, M4, P3; columns theta1 (mm), theta2..theta6 (deg).
TABLE1 = np.array(
    [
        [50.0, 55.8, -70.6, 20.0, 0.0, 0.0],
        [50.0, 43.4, -49.6, 15.0, 20.0, 10.0],
        [50.0, 58.2, -37.8, 34.3, 30.0, 10.0],
        [50.0, 48.3, -27.2, 42.9, 30.0, 10.0],
        [50.0, 32.8, -18.5, 15.4, 20.0, 0.0],
        [50.0, 52.4, -20.5, 29.6, 0.0, 0.0],
    ]
)
TABLE1_TIMES = np.arange(6) * 0.5  # s

#: How far a joint may be beyond its range and still count as within it, m for the slide and
#: rad for the hinges: 1 nm and 1 nrad, the same for the planner's refusal and for the
#: ``joint_range`` check (``planbench.loader.plan_checks``). The loader's encoders are modelled
#: exact (no figures are published, models/loader/README.md); the finest absolute encoders
#: resolve ~7.5e-7 rad (23 bits a turn) and linear scales ~1e-8 m, so a value this close to a
#: limit is the limit for any machine that measures it. It is also far above the spline's
#: round-off at the loader's magnitudes (64 eps x 3.2 rad = 4.5e-14 rad), so the check's ratio
#: |theta - centre| / half range is above 1 for every value the planner refuses.
JOINT_LIMIT_TOLERANCE = 1e-9


def table1_to_si(rows: np.ndarray) -> np.ndarray:
    """Table 1 units (mm, deg) to joint SI units (m, rad)."""
    rows = np.asarray(rows, dtype=float)
    return np.concatenate([rows[..., :1] * 1e-3, np.deg2rad(rows[..., 1:])], axis=-1)


def si_to_table1(q: np.ndarray) -> np.ndarray:
    """Joint SI units (m, rad) to Table 1 units (mm, deg)."""
    q = np.asarray(q, dtype=float)
    return np.concatenate([q[..., :1] * 1e3, np.rad2deg(q[..., 1:])], axis=-1)


@dataclass(frozen=True)
class LoaderProblem:
    """The loader's planning problem: pass through key points at given times, within limits.

    Attributes:
      key_times: (k,) s, increasing, from 0.
      key_points: (k, 6) joint values theta1 (m) and theta2 ... theta6 (rad) at those times.
      labels: the joint names, in the key points' column order (the trajectory's channels).
      lower, upper: (6,) joint ranges, m and rad.
      rate_limit: (6,) the drives' set-point rate limits, m/s and rad/s.
      force_limit: (6,) the drives' force and torque limits, N and N m.
    """

    key_times: np.ndarray
    key_points: np.ndarray
    labels: tuple
    lower: np.ndarray
    upper: np.ndarray
    rate_limit: np.ndarray
    force_limit: np.ndarray


class CubicBSplinePlanner:
    """The paper's planner: the cubic B-spline through the problem's key points (section 3,
    ``planbench.planners.loader.bspline``), checked against the joint ranges: it refuses (a LimitError)
    key points, or a spline between them, beyond a limit by more than
    ``JOINT_LIMIT_TOLERANCE`` (between key points plus the spline's round-off,
    ``limit_tolerance``)."""

    def plan(self, problem: LoaderProblem) -> CubicBSplineTrajectory:
        return CubicBSplineTrajectory(
            problem.key_times,
            problem.key_points,
            labels=list(problem.labels),
            lower=problem.lower,
            upper=problem.upper,
            margin=JOINT_LIMIT_TOLERANCE,
        )


def supply_plan(spec: SerialChainSpec | None = None) -> CubicBSplineTrajectory:
    """The supply stage of the paper: P2 -> M1 ... M4 -> P3 through the cubic B-spline."""
    spec = spec or loader_spec()
    return CubicBSplineTrajectory(
        TABLE1_TIMES,
        table1_to_si(TABLE1),
        labels=spec.names,
        lower=spec.lower,
        upper=spec.upper,
        margin=JOINT_LIMIT_TOLERANCE,
    )


def direct_plan(spec: SerialChainSpec | None = None) -> CubicBSplineTrajectory:
    """P2 to P3 as one straight joint-space move in the same 2.5 s (no obstacle key points).

    The same spline with only the two end points: every joint follows the cubic with zero end
    velocities, so the path in joint space is the straight segment P2-P3.
    """
    spec = spec or loader_spec()
    q = table1_to_si(TABLE1)
    return CubicBSplineTrajectory(
        TABLE1_TIMES[[0, -1]],
        q[[0, -1]],
        labels=spec.names,
        lower=spec.lower,
        upper=spec.upper,
        margin=JOINT_LIMIT_TOLERANCE,
    )


def _scipy_quat(wxyz: np.ndarray) -> Rotation:
    w, x, y, z = wxyz
    return Rotation.from_quat([x, y, z, w])


def forward_kinematics(q: np.ndarray, sites: list[str] | None = None, spec: SerialChainSpec | None = None) -> dict:
    """World positions of the chain's sites for joint vectors ``q`` (vectorized).

    Composes, from the base, each body's fixed offset (pos, quat) and its joint's motion: a
    translation along the axis (slide) or a rotation about it (hinge).

    Args:
      q: (..., n_joints) joint values, m and rad.
      sites: site names (default: all sites of the chain).

    Returns:
      {site name: (..., 3) world position, m}.
    """
    spec = spec or loader_spec()
    try:
        q = np.asarray(q, dtype=float)
    except (TypeError, ValueError):
        raise PlanningError(f"q must be numbers, got {q!r}") from None
    if q.ndim == 0:
        raise PlanningError(f"q must be (..., {len(spec.joints)}) joint values, got a number")
    batch = q.shape[:-1]
    q = q.reshape(-1, q.shape[-1])
    if q.shape[1] != len(spec.joints):
        raise PlanningError(f"q has {q.shape[1]} joints, the chain has {len(spec.joints)}")
    # Name the joint (and the row of a batch) of a NaN, inf or huge value.
    check_values(q, lambda i: f"q of joint {spec.names[i[1]]}" + (f" in row {i[0]}" if batch else ""))
    wanted = list(spec.sites) if sites is None else list(sites)
    for name in wanted:
        if name not in spec.sites:
            raise PlanningError(f"unknown site {name!r}; chain sites: {', '.join(spec.sites)}")
    n = q.shape[0]
    rot = Rotation.concatenate([_scipy_quat(spec.base_quat)] * n)
    pos = np.broadcast_to(spec.base_pos, (n, 3)).copy()
    body_frames = {}
    for body in spec.bodies:
        pos = pos + rot.apply(body.pos)
        rot = rot * _scipy_quat(body.quat)
        if body.joint is not None:
            joint, qk = spec.joints[body.joint], q[:, body.joint : body.joint + 1]
            if joint.kind == "slide":
                pos = pos + rot.apply(joint.axis) * qk
            else:
                rot = rot * Rotation.from_rotvec(joint.axis[None, :] * qk)
        body_frames[body.name] = (pos, rot)
    out = {}
    for name in wanted:
        body, local = spec.sites[name]
        bpos, brot = body_frames[body]
        out[name] = (bpos + brot.apply(local)).reshape(*batch, 3)
    return out
