"""Planner-only checks of loader runs: the planned joint trajectory judged without physics.

``judge_plans(params_list)`` builds each run's planning problem as a run does
(``planbench.loader.task.problem``: the key points at uniform times, the model's joint limits) and
returns, per run, the checks that judge the trajectory the paper's planner (the cubic
B-spline, ``planbench.planners.loader.CubicBSplinePlanner``) returns for it. Where a run's check of the
same name measures the machine (the encoders, the logged poses), the planned quantity's name
begins with ``plan_``.

===================  =====  ====================  ================================================
check                unit   passes when           what
===================  =====  ====================  ================================================
plan_keypoint_error  deg    <= 0.1                largest |theta_j(t_k) - M_k,j| of the planned
                            (KEYPOINT_LIMIT_DEG)  theta2 ... theta6 at the key times (eq. 7: the
                                                  spline interpolates the key points); the slide's
                                                  in mm in the note. The run's ``keypoint_error``
                                                  is the encoders'
joint_range          ratio  <= 1                  largest |theta_j - centre| / half range of any
                                                  joint, at the key points and between them (at
                                                  the spline's extrema, eq. 10), a value within
                                                  JOINT_LIMIT_TOLERANCE of a limit counting as
                                                  on it; > 1: the planner refuses the key points
                                                  (a LimitError, named in the note), the value
                                                  says by how much
joint_rate           ratio  <= 1                  largest |dtheta_j/dt| / the drive's rate limit
                                                  (models.loader_spec().rate_limit), at the
                                                  velocity's extrema
plan_min_clearance   m      > 0                   smallest signed distance between the robot's
                                                  collision geoms and the obstacles (breechblock,
                                                  seat ring, floor) over the planned path at the
                                                  control ticks (the run's ``min_clearance`` is
                                                  of the logged poses)
===================  =====  ====================  ================================================

Limits are the run's (``planbench.loader.task``) and the model's (``models.loader_spec``), never
loosened. ``joint_range`` judges as the planner does, with its numbers and its one tolerance,
``planbench.planners.loader.JOINT_LIMIT_TOLERANCE`` (1e-9 m on the slide, 1e-9 rad on the hinges):
a key point beyond a limit by no more than it, or the spline between key points (at the
planner's own ``CubicBSplineTrajectory.extrema``) by no more than it plus the spline's
round-off (``limit_tolerance``), counts as on the limit (ratio at most 1); anything beyond is
above 1, however little. So it passes exactly when the planner accepts the key points (tested
on random key points and on key points on, near and just inside the limits, down to 1e-88). A run has no
``joint_rate`` check (its ``joint_torque`` is the drives' demanded torque, from physics): the
rate limit is the drives' set-point rate, which a planned trajectory should respect, and the
paper's spline does not respect it by construction.

How it is fast
--------------
* The spline. Its control points are one banded solve with the key points as right-hand side
  (eq. 9); sets of the same size share the matrix, and sets that also share the key times
  share the whole trajectory but for their values. So runs are grouped by (number of key
  points, key interval) and each group is *one* ``CubicBSplineTrajectory`` with the sets side
  by side as its channels (6 per set), built and sampled by the planner's own code: each
  channel's numbers are those of the set's own trajectory, bit for bit (tested).
* The extrema. Per segment a joint is a cubic in t (``segment_polynomials``): its range is
  checked at the roots of its derivative (as the planner's own overshoot check), its rate at
  the root of the second derivative, both exactly.
* The clearance. The run's measure, ``planbench.loader.collision.clearance`` (MuJoCo's
  ``mj_geomDistance`` over every robot-obstacle pair after ``mj_kinematics``, capped at
  0.5 m), at the control ticks, as a run samples the plan for its controller (the shell moves
  up to ~1 cm between two ticks at the supply stage's speeds, so this is the ticks' minimum,
  as the run's ``min_clearance`` is). At every tick it costs 0.2-0.5 ms; the smallest value
  over the ticks is found evaluating a fifth of them or fewer, exactly:

  - Branch and bound over the ticks. Between ticks a and b the clearance cannot fall below
    (d_a + d_b - S_ab) / 2, S_ab an upper bound of the distance any point of a robot
    collision geom travels from a to b: per tick step, the sum over the joints of the joint's
    speed (the larger of the step's ends, plus half the step times the spline's largest
    acceleration) times the largest distance of a geom point from the joint's anchor (from the
    model, by the triangle inequality). Obstacles are static, so the clearance changes no
    faster. Intervals whose bound is above the smallest value found (by more than
    ``BOUND_SLACK_M``) hold no smaller tick and are never looked at; the others are bisected.
  - Bounds before distances. A tick looked at gets each pair's lower bound first: its bounding
    spheres' distance, and for pairs near the closest, the distance between capsules around
    the two geoms (``_capsules``; the floor: a capsule's lowest end). A tick whose smallest
    bound is above the smallest value found cannot be the minimum and is not evaluated; its
    bound stands in for its value in its intervals' bounds, which stay lower bounds.
  - An evaluated tick calls ``mj_geomDistance`` for its pairs in the order of their bounds,
    each with the smallest distance so far as its distmax, until the next bound exceeds it.
    Where the robot clears the obstacles this is ``clearance``'s value, bit for bit (tested);
    where geoms overlap, MuJoCo's penetration depth depends on the distmax it is given, so a
    negative value can differ from ``clearance``'s by millimetres (up to 2 cm in deep random
    overlaps; tested: same sign).
  - The runs of a group go through the levels of the bisection in lockstep, so each level's
    bounds are computed for all of them at once; each run's decisions depend on its own values
    only, so a run judged alone gives the same checks, bit for bit (tested).

Throughput (one core of the 2-core development machine, with other jobs on it; the campaign
examples/loader/random_keypoints_campaign.toml measures it end to end): 6 key points at 0.5 s, uniform in the
joint ranges
(almost all strike something, most leave the ranges): 300 runs/s, 10^5 in about 6 min; Table 1's
key points each moved by up to +/-3 deg (+/-15 mm), paths that pass the obstacles within
centimetres: 150 runs/s, 10^5 in about 11 min. The clearance is nine tenths of it. Building
10^4 ``LoaderParams`` takes about 1 s.

Example::

    >>> from planbench.loader import LoaderParams
    >>> from planbench.loader.plan_checks import judge_plans
    >>> [checks] = judge_plans([LoaderParams()])    # Table 1's key points
    >>> [(c.name, c.passed) for c in checks]
    [('plan_keypoint_error', True), ('joint_range', True), ('joint_rate', True), ('plan_min_clearance', True)]
"""

from __future__ import annotations

import functools
from collections.abc import Sequence

import mujoco
import numpy as np

from planbench import models
from planbench.checks import Check
from planbench.loader.collision import clearance, geoms_by_contype
from planbench.loader.params import CONTROL_DT, LoaderParams
from planbench.loader.physics import OBSTACLE_CONTYPE, ROBOT_CONTYPE
from planbench.loader.task import KEYPOINT_LIMIT_DEG, problem
from planbench.planners.errors import PlanningError
from planbench.planners.loader import JOINT_LIMIT_TOLERANCE, TABLE1, CubicBSplinePlanner, LoaderProblem, si_to_table1
from planbench.planners.loader.bspline import CubicBSplineTrajectory
from planbench.planners.trajectory import control_ticks
from planbench.task import plan_checked

#: ``planbench.loader.collision.clearance``'s cap: distances beyond it are reported as it, m.
DISTMAX_M = 0.5
#: Slack on the branch and bound's lower bounds, m: an interval is skipped only when its bound
#: exceeds the smallest clearance found by this much, so MuJoCo's distance approximations
#: (its convex solver's tolerance, 1e-6 by default) cannot make it skip a smaller tick.
BOUND_SLACK_M = 1e-4
#: Capsule bounds are computed for the pairs whose bounding spheres are within this of a pose's
#: closest pair's, m (any valid lower bound keeps the result exact; tighter ones save calls).
CAPSULE_MARGIN_M = 0.1
#: Ticks between the first evaluations of the branch and bound (a coarse grid).
COARSE_TICKS = 16
#: Runs whose trajectory is built and sampled at once (about 70 kB per run of 2.5 s) ...
CHUNK_RUNS = 512
#: ... and at most this many of their ticks together (about 150 bytes each), which bounds the
#: memory for long runs (a run may last 200 key points of 60 s: 2.4e6 ticks).
CHUNK_TICKS = 500_000


# --------------------------------------------------------------------------- the model


def _capsules(model: mujoco.MjModel, geoms: np.ndarray):
    """A capsule around each geom: (axis index in the geom's frame, half length m, radius m).

    A box holds within the capsule along its longest axis with the radius of its other two
    half sizes' hypotenuse; a cylinder or capsule within the one of its own axis and radius;
    an ellipsoid within the one along its longest axis with its next largest radius; anything
    else within its bounding sphere (a capsule of length 0). Planes are handled apart."""
    axis, half, radius = [], [], []
    for g in geoms:
        kind, size = int(model.geom_type[g]), model.geom_size[g]
        if kind == int(mujoco.mjtGeom.mjGEOM_BOX):
            k = int(np.argmax(size))
            axis.append(k), half.append(size[k]), radius.append(float(np.hypot(*np.delete(size, k))))
        elif kind in (int(mujoco.mjtGeom.mjGEOM_CYLINDER), int(mujoco.mjtGeom.mjGEOM_CAPSULE)):
            axis.append(2), half.append(size[1]), radius.append(size[0])
        elif kind == int(mujoco.mjtGeom.mjGEOM_ELLIPSOID):
            k = int(np.argmax(size))
            axis.append(k), half.append(size[k]), radius.append(float(np.delete(size, k).max()))
        else:
            axis.append(0), half.append(0.0), radius.append(model.geom_rbound[g])
    return np.array(axis), np.array(half, dtype=float), np.array(radius, dtype=float)


def _segment_distance(p1, d1, p2, d2, e) -> np.ndarray:
    """Distance between the segments p1 + s d1 and p2 + t d2, s, t in [0, 1] (arrays (..., 3),
    broadcast; ``e`` = d2 . d2 > 0, precomputed), m: the closest points by Ericson's clamping
    ("Real-Time Collision Detection", 5.1.9), exact for segments of any length (d1 may be 0)."""
    r = p1 - p2
    a = (d1 * d1).sum(-1)
    f = (d2 * r).sum(-1)
    c = (d1 * r).sum(-1)
    b = (d1 * d2).sum(-1)
    denom = a * e - b * b
    safe_a = np.where(a > 0, a, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(denom > 1e-12 * a * e, np.clip((b * f - c * e) / np.where(denom > 0, denom, 1.0), 0.0, 1.0), 0.0)
    t = (b * s + f) / e
    s = np.where(t < 0, np.clip(-c / safe_a, 0.0, 1.0), np.where(t > 1, np.clip((b - c) / safe_a, 0.0, 1.0), s))
    s = np.where(a > 0, s, 0.0)
    t = np.clip(t, 0.0, 1.0)
    gap = r + d1 * s[..., None] - d2 * t[..., None]
    return np.sqrt((gap * gap).sum(-1))


class _Collision:
    """The loader scene's robot and obstacle collision geoms (``planbench.loader.physics``'s contypes), and
    ``clearance`` at many poses with what makes it cheap (module docstring)."""

    def __init__(self):
        self.model = models.load("loader")
        model = self.model
        self.robot = geoms_by_contype(model, ROBOT_CONTYPE)
        self.obstacles = geoms_by_contype(model, OBSTACLE_CONTYPE)
        self.pairs = [(int(r), int(o)) for r in self.robot for o in self.obstacles]
        names = models.loader_spec().names
        self.qpos = np.array([model.joint(n).qposadr[0] for n in names])
        self.data = mujoco.MjData(model)
        data = self.data
        mujoco.mj_kinematics(model, data)
        # Views into the scratch data's buffers (MjData's arrays are its memory).
        self._qpos, self._xpos, self._xmat = data.qpos, data.geom_xpos, data.geom_xmat
        # Obstacles do not move: their capsules (and the floor's plane) once.
        self.plane = model.geom_type[self.obstacles] == int(mujoco.mjtGeom.mjGEOM_PLANE)
        axis, half, self.obstacle_radius = _capsules(model, self.obstacles)
        frames = data.geom_xmat[self.obstacles].reshape(-1, 3, 3)
        direction = frames[np.arange(axis.size), :, axis] * half[:, None]
        centres = data.geom_xpos[self.obstacles]
        solid = ~self.plane
        self.solid = np.flatnonzero(solid)
        self.solid_index = np.cumsum(solid) - 1  # obstacle -> its row among the solid ones
        self.centres = centres.copy()
        self.obstacle_sphere = np.where(self.plane, 0.0, model.geom_rbound[self.obstacles])
        # Capsule segments of the solid obstacles, start and direction (p2, d2, d2 . d2).
        self.obstacle_start = (centres - direction)[solid]
        self.obstacle_direction = 2.0 * direction[solid]
        self.obstacle_length2 = np.maximum((self.obstacle_direction**2).sum(-1), 1e-300)
        self.normals = frames[:, :, 2]
        self.offsets = np.einsum("ok,ok->o", centres, self.normals)
        axis, half, self.robot_radius = _capsules(model, self.robot)
        self.robot_sphere = model.geom_rbound[self.robot].copy()
        self.robot_half_axis = np.zeros((self.robot.size, 3))  # the capsule's half axis, geom frame
        self.robot_half_axis[np.arange(self.robot.size), axis] = half
        self.reach = self._reach(names)
        self.fromto = np.zeros(6)

    def _reach(self, names) -> np.ndarray:
        """(6, robot geoms) the largest speed of a point of each robot geom per unit speed of
        each joint: 1 for the slide (m/s per m/s), and for a hinge (m/s per rad/s) an upper
        bound of the point's distance from the joint's anchor: |anchor offset| + the offsets
        of the bodies between + |geom centre offset| + the geom's bounding radius (triangle
        inequality; constant over all poses)."""
        model = self.model
        reach = np.zeros((len(names), self.robot.size))
        for j, name in enumerate(names):
            joint = model.joint(name)
            body = int(joint.bodyid[0])
            for g, geom in enumerate(self.robot):
                chain, b = [], int(model.geom_bodyid[geom])
                while b > 0 and b != body:
                    chain.append(b)
                    b = int(model.body_parentid[b])
                if b != body:
                    continue  # the geom is not moved by this joint
                if model.jnt_type[joint.id] == mujoco.mjtJoint.mjJNT_SLIDE:
                    reach[j, g] = 1.0
                    continue
                reach[j, g] = (
                    np.linalg.norm(model.jnt_pos[joint.id])
                    + np.linalg.norm(model.geom_pos[geom])
                    + sum(np.linalg.norm(model.body_pos[k]) for k in chain)
                    + model.geom_rbound[geom]
                )
        return reach

    def _pose(self, q: np.ndarray) -> None:
        """The scratch data at joint vector q (6,) (m, rad), kinematics only."""
        self._qpos[self.qpos] = q  # the loader's joints are its scene's only ones
        mujoco.mj_kinematics(self.model, self.data)

    def bounds(self, q: np.ndarray, threshold) -> np.ndarray:
        """Lower bounds (K, pairs) of every robot-obstacle pair's distance at joint vectors
        q (K, 6) (m, rad), pairs in ``clearance``'s order. A pair's bound is its bounding
        spheres' distance and, where that is below ``threshold`` (m, a number or one per pose),
        the larger distance of the capsules around its geoms (``_capsules``; for the floor, a
        capsule's lowest end above its plane), less their radii."""
        k = q.shape[0]
        every_xpos = np.empty((k,) + self._xpos.shape)
        every_xmat = np.empty((k,) + self._xmat.shape)
        model, data, qpos, geom_xpos, geom_xmat = self.model, self.data, self._qpos, self._xpos, self._xmat
        full = np.zeros((k, model.nq))
        full[:, self.qpos] = q
        for i in range(k):
            qpos[:] = full[i]
            mujoco.mj_kinematics(model, data)
            every_xpos[i] = geom_xpos
            every_xmat[i] = geom_xmat
        xpos, xmat = every_xpos[:, self.robot], every_xmat[:, self.robot]
        # Spheres: centre distance less both bounding radii; the floor: centre height less one.
        centre_gap = np.sqrt(((xpos[:, :, None, :] - self.centres) ** 2).sum(-1))
        height = xpos @ self.normals.T - self.offsets
        bound = np.where(self.plane, height, centre_gap - self.obstacle_sphere) - self.robot_sphere[:, None]
        # Capsules only for pairs whose spheres are within CAPSULE_MARGIN_M of the pose's
        # closest pair's: the others' sphere bounds are valid, if loose, and seldom matter.
        threshold = np.minimum(np.asarray(threshold, dtype=float), bound.min(axis=(1, 2)) + CAPSULE_MARGIN_M)
        close = np.nonzero(bound < threshold[:, None, None])  # (tick, robot, obstacle)
        if close[0].size:
            t, r, o = close
            half_axis = np.einsum("nij,nj->ni", xmat[t, r].reshape(-1, 3, 3), self.robot_half_axis[r])
            start = xpos[t, r] - half_axis
            capsule = np.empty(t.size)
            plane = self.plane[o]
            if (~plane).any():
                w = ~plane
                j = self.solid_index[o[w]]
                capsule[w] = (
                    _segment_distance(
                        start[w],
                        2.0 * half_axis[w],
                        self.obstacle_start[j],
                        self.obstacle_direction[j],
                        self.obstacle_length2[j],
                    )
                    - self.obstacle_radius[o[w]]
                )
            if plane.any():
                normal, offset = self.normals[o[plane]], self.offsets[o[plane]]
                ends = np.minimum((start[plane] * normal).sum(-1), ((start + 2.0 * half_axis)[plane] * normal).sum(-1))
                capsule[plane] = ends - offset
            capsule -= self.robot_radius[r]
            bound[t, r, o] = np.maximum(bound[t, r, o], capsule)
        return bound.reshape(k, -1) - 1e-9  # round-off of the bound itself

    def exact(self, q: np.ndarray, bound: np.ndarray, order: np.ndarray | None = None):
        """``clearance`` at joint vector q (6,) given its pairs' lower bounds (pairs,): (distance
        m, robot geom, obstacle geom; -1, -1 when nothing is within DISTMAX_M).

        ``mj_geomDistance`` of the pairs in the order of their bounds, each with the best
        distance so far as its distmax, until the next pair's bound exceeds it: the pairs left
        out are farther apart than the minimum. Where the geoms are apart this is
        ``clearance``'s value exactly; where they overlap, MuJoCo's penetration depth depends
        on the distmax it is given, so the two can differ there (by millimetres; the sign of a
        path's minimum agreed in every test).
        ``order``: the pairs sorted by their bounds (stable), if known."""
        self._pose(q)
        model, data, pairs, fromto = self.model, self.data, self.pairs, self.fromto
        order = np.argsort(bound, kind="stable") if order is None else order
        best, pair = DISTMAX_M, -1
        for lower, index in zip(bound[order].tolist(), order.tolist(), strict=True):
            if lower > best:
                break
            r, o = pairs[index]
            d = mujoco.mj_geomDistance(model, data, r, o, best, fromto)
            if d < best:
                best, pair = d, index
        r, o = pairs[pair] if pair >= 0 else (-1, -1)
        return best, r, o

    def name(self, geom: int) -> str:
        return self.model.geom(int(geom)).name


@functools.lru_cache(maxsize=1)
def _collision() -> _Collision:
    return _Collision()


#: Poses whose bounds are computed at once (bounds the memory of a round, ~4 kB a pose).
ROUND_POSES = 4096


def min_clearances(q: np.ndarray, travel: np.ndarray):
    """The smallest ``clearance`` over each path's ticks, by branch and bound.

    Args:
      q: (G, T, 6) G paths' joint positions at the ticks (m, rad).
      travel: (G, T - 1) an upper bound of the distance any point of a robot collision geom
        moves between tick k and k + 1 of each path, m.

    Returns:
      Arrays (G,): clearance m, its tick, robot geom, obstacle geom (-1: nothing within
      DISTMAX_M), ticks evaluated exactly; each the smallest of ``_Collision.exact`` over all
      of the path's ticks (module docstring).

    Every path's ticks are bisected level by level, every interval whose lower bound is below
    that path's best value so far at once; the paths go in lockstep, so that the bounds of a
    level are computed for all of them together, while each path's decisions depend on its own
    values only (a path judged alone gives the same result, bit for bit). A new tick gets its
    pairs' bounds first and is evaluated exactly only if the smallest is below the path's best
    (plus BOUND_SLACK_M); a midpoint whose two ends' cones already put it above the best gets
    no kinematics at all. Either way the bound stands in for its value in its intervals'
    bounds, which stay lower bounds.
    """
    collision = _collision()
    g, n = q.shape[:2]
    arc = np.concatenate([np.zeros((g, 1)), np.cumsum(travel, axis=1)], axis=1)
    low = np.full((g, n), np.nan)  # a lower bound of each visited tick (exact where evaluated)
    exact = np.zeros((g, n), dtype=bool)
    pair = np.full((g, n, 2), -1)
    best = np.full(g, np.inf)

    def visit(paths: np.ndarray, ticks: np.ndarray) -> None:
        for lo in range(0, paths.size, ROUND_POSES):
            p, k = paths[lo : lo + ROUND_POSES], ticks[lo : lo + ROUND_POSES]
            bounds = collision.bounds(q[p, k], np.minimum(best[p], DISTMAX_M) + BOUND_SLACK_M)
            least = np.minimum(bounds.min(axis=1), DISTMAX_M)
            low[p, k] = least
            # Each path's new ticks from its lowest bound up, its best improving as they go.
            orders = None
            for i in np.lexsort((least, p)).tolist():
                path = p[i]
                if least[i] >= best[path] + BOUND_SLACK_M:
                    continue
                if orders is None:
                    orders = np.argsort(bounds, axis=1, kind="stable")
                d, r, o = collision.exact(q[path, k[i]], bounds[i], orders[i])
                low[path, k[i]], exact[path, k[i]], pair[path, k[i]] = d, True, (r, o)
                best[path] = min(best[path], d)

    grid = np.unique(np.concatenate([np.arange(0, n, COARSE_TICKS), [n - 1]]))
    visit(np.repeat(np.arange(g), grid.size), np.tile(grid, g))
    s, a, b = np.repeat(np.arange(g), grid.size - 1), np.tile(grid[:-1], g), np.tile(grid[1:], g)
    while s.size:
        bound = 0.5 * (low[s, a] + low[s, b] - (arc[s, b] - arc[s, a]))
        keep = (b - a > 1) & (bound < best[s] + BOUND_SLACK_M)
        s, a, b = s[keep], a[keep], b[keep]
        if not s.size:
            break
        c = (a + b) // 2
        cone = np.maximum(low[s, a] - (arc[s, c] - arc[s, a]), low[s, b] - (arc[s, b] - arc[s, c]))
        far = cone >= best[s] + BOUND_SLACK_M
        low[s[far], c[far]] = cone[far]
        visit(s[~far], c[~far])
        s, a, b = np.concatenate([s, s]), np.concatenate([a, c]), np.concatenate([c, b])
    value = np.where(exact, low, np.inf)
    tick = np.argmin(value, axis=1)
    rows = np.arange(g)
    return (value[rows, tick], tick, pair[rows, tick, 0], pair[rows, tick, 1], exact.sum(axis=1))


# --------------------------------------------------------------------------- one group of runs


def _extremes(poly: np.ndarray, h: float):
    """Per channel, the spline's extreme values and speeds over its segments.

    Args:
      poly: (segments, 4, m) ``segment_polynomials``: a3, a2, a1, a0 of each segment in
        (t - t_i), t - t_i in [0, h].

    Returns:
      ((candidates, m) positions at every segment's ends and derivative roots,
       (candidates, m) their times from t_0,
       (candidates, m) speeds at every segment's ends and the acceleration's root,
       (candidates, m) their times).
    """
    a3, a2, a1, a0 = poly[:, 0], poly[:, 1], poly[:, 2], poly[:, 3]
    start = np.arange(poly.shape[0])[:, None] * h
    # Roots of 3 a3 x^2 + 2 a2 x + a1, without cancellation (the planner's _check_overshoot).
    qa, qb, qc = 3.0 * a3, 2.0 * a2, a1
    disc = qb**2 - 4.0 * qa * qc
    with np.errstate(divide="ignore", invalid="ignore"):
        root = np.sqrt(np.where(disc >= 0, disc, np.nan))
        q = -0.5 * (qb + np.where(qb >= 0, 1.0, -1.0) * root)
        r1 = np.where(q != 0, q / qa, np.nan)
        r2 = np.where(q != 0, qc / q, np.nan)
        r3 = np.where(a3 != 0, -a2 / (3.0 * a3), np.nan)  # the speed's extreme
    xs = [np.zeros_like(a3), np.full_like(a3, h)]
    xs += [np.where(np.isfinite(r) & (r > 0) & (r < h), r, 0.0) for r in (r1, r2)]
    positions = np.concatenate([((a3 * x + a2) * x + a1) * x + a0 for x in xs])
    position_t = np.concatenate([start + x for x in xs])
    vs = xs[:2] + [np.where(np.isfinite(r3) & (r3 > 0) & (r3 < h), r3, 0.0)]
    speeds = np.concatenate([np.abs((3.0 * a3 * x + 2.0 * a2) * x + a1) for x in vs])
    speed_t = np.concatenate([start + x for x in vs])
    return positions, position_t, speeds, speed_t


def _judge_group(tasks: Sequence[LoaderProblem]) -> list[dict]:
    """The checks' quantities of runs whose problems share their key times (and so their
    number of key points), judged as one trajectory with the runs' joints side by side."""
    first = tasks[0]
    m = len(first.labels)
    g = len(tasks)
    points = np.concatenate([t.key_points for t in tasks], axis=1)  # (k, m g)
    stacked = CubicBSplineTrajectory(first.key_times, points, margin=JOINT_LIMIT_TOLERANCE)
    lower, upper = np.tile(first.lower, g), np.tile(first.upper, g)
    rate = np.tile(first.rate_limit, g)
    # Key points: the planned motion at the key times.
    at_keys = stacked.sample(first.key_times).position - points
    key_deg = np.degrees(np.abs(at_keys)).reshape(-1, g, m)
    key_slide_mm = 1e3 * np.abs(at_keys).reshape(-1, g, m)[:, :, 0].max(axis=0)
    # Range and rate at their extrema (exact per segment).
    h = (first.key_times[-1] - first.key_times[0]) / (first.key_times.size - 1)
    _, _, speeds, speed_t = _extremes(stacked.segment_polynomials(), h)
    # The range as the planner judges it, with its numbers: the key points and the values at
    # the spline's extrema (``extrema``, the planner's own arithmetic, channel by channel).
    positions, position_t = stacked.extrema()
    range_ratio = np.concatenate(
        [
            range_ratio_of(points, lower, upper, stacked.margin),
            range_ratio_of(positions, lower, upper, stacked.limit_tolerance),
        ]
    )  # (c, m g)
    positions = np.concatenate([points, positions])
    position_t = np.concatenate([np.broadcast_to(first.key_times[:, None], points.shape), position_t])
    rate_ratio = speeds / rate
    # The path at the control ticks (and its end), and how far a geom point moves between.
    duration = float(stacked.duration)
    ticks = control_ticks(duration, CONTROL_DT)
    if ticks[-1] < duration - 1e-9:
        ticks = np.append(ticks, duration)
    sample = stacked.sample(ticks)
    q = sample.position.reshape(-1, g, m)
    # |theta_j'| between two ticks <= its larger end value + half the step times max |theta_j''|
    # (the acceleration is linear per segment: its largest magnitude is at a segment's end).
    poly = stacked.segment_polynomials()
    acc_ends = np.concatenate([np.abs(2.0 * poly[:, 1]), np.abs(6.0 * poly[:, 0] * h + 2.0 * poly[:, 1])])
    acc_max = acc_ends.max(axis=0)  # (m g,)
    speed = np.abs(sample.velocity)
    step = np.diff(ticks)[:, None]
    between = np.maximum(speed[:-1], speed[1:]) + 0.5 * step * acc_max  # (T-1, m g)
    reach = _collision().reach  # (m, geoms)
    travel = np.einsum("tgj,jr->tgr", between.reshape(-1, g, m), reach).max(axis=-1) * step  # (T-1, g)
    clearances = min_clearances(np.moveaxis(q, 1, 0), travel.T)
    out = []
    labels = first.labels
    for i in range(len(tasks)):
        cols = slice(i * m, (i + 1) * m)
        worst_key = np.unravel_index(int(np.argmax(key_deg[:, i, 1:])), key_deg[:, i, 1:].shape)
        rr, rt = range_ratio[:, cols], rate_ratio[:, cols]
        kr, jr = np.unravel_index(int(np.argmax(rr)), rr.shape)
        kt, jt = np.unravel_index(int(np.argmax(rt)), rt.shape)
        d, tick, robot, obstacle, evaluated = (v[i] for v in clearances)
        out.append(
            {
                "key_deg": float(key_deg[:, i, 1:].max()),
                "key_point": int(worst_key[0]),
                "key_joint": labels[1 + int(worst_key[1])],
                "key_slide_mm": float(key_slide_mm[i]),
                "range": float(rr[kr, jr]),
                "range_joint": labels[jr],
                "range_t": float(position_t[kr, cols][jr]),
                "range_value": float(positions[kr, cols][jr]),
                "rate": float(rt[kt, jt]),
                "rate_joint": labels[jt],
                "rate_t": float(speed_t[kt, cols][jt]),
                "rate_value": float(speeds[kt, cols][jt]),
                "clearance": float(d),
                "clearance_t": float(ticks[tick]),
                "pair": (robot, obstacle),
                "ticks_evaluated": evaluated,
                "ticks": ticks.size,
            }
        )
    return out


def range_ratio_of(values: np.ndarray, lower: np.ndarray, upper: np.ndarray, allowed: np.ndarray) -> np.ndarray:
    """``joint_range``'s ratio |theta - centre| / half range of each value (..., m), with the
    planner's rule (``CubicBSplineTrajectory``): a value beyond a limit by no more than
    ``allowed`` (m,) (the key points' ``margin``, the spline's ``limit_tolerance``) counts as
    on it, at most 1; one beyond by more is above 1, however little (the planner refuses it).
    So the check passes exactly when the planner accepts, whatever the rounding of the
    ratio."""
    excess = np.maximum(values - upper, -(values - lower))  # the planner's sign (v - l)
    ratio = np.abs(values - (upper + lower) / 2.0) / ((upper - lower) / 2.0)
    within = excess <= allowed
    return np.where(within, np.minimum(ratio, 1.0), np.maximum(ratio, np.nextafter(1.0, 2.0)))


def _refusal(task: LoaderProblem) -> str:
    """Why the paper's planner refuses ``task``, or "" (it accepts)."""
    try:
        CubicBSplinePlanner().plan(task)
    except PlanningError as e:
        return f"{type(e).__name__}: {e}"
    return ""


def _checks(j: dict, refusal: str = "") -> list[Check]:
    """The checks of one run from its judged quantities."""
    collision = _collision()
    robot, obstacle = j["pair"]
    slide = models.loader_spec().names[0]  # the prismatic theta1, m; the others rad
    range_unit = "m" if j["range_joint"] == slide else "rad"
    rate_unit = "m/s" if j["rate_joint"] == slide else "rad/s"
    return [
        Check(
            "plan_keypoint_error",
            j["key_deg"],
            KEYPOINT_LIMIT_DEG,
            "deg",
            note=f"planned minus key point, worst {j['key_joint']} at key point {j['key_point']}; "
            f"slide {j['key_slide_mm']:.3g} mm",
        ),
        Check(
            "joint_range",
            j["range"],
            1.0,
            "ratio",
            note=f"|theta - centre| / half range, worst {j['range_joint']} = {j['range_value']:.6g} "
            f"{range_unit} at t = {j['range_t']:.3f} s" + (f"; {refusal}" if refusal else ""),
        ),
        Check(
            "joint_rate",
            j["rate"],
            1.0,
            "ratio",
            note=f"|planned rate| / rate limit, worst {j['rate_joint']} {j['rate_value']:.4g} {rate_unit} "
            f"at t = {j['rate_t']:.3f} s",
        ),
        Check(
            "plan_min_clearance",
            j["clearance"],
            0.0,
            "m",
            ">",
            note=(
                f"{collision.name(robot)}/{collision.name(obstacle)} at t = {j['clearance_t']:.3f} s"
                if robot >= 0
                else f"nothing within {DISTMAX_M:g} m"
            )
            + f"; {j['ticks_evaluated']} of {j['ticks']} ticks evaluated (branch and bound)",
        ),
    ]


def judge_plans(params_list: Sequence[LoaderParams], planner=None) -> list[list[Check]]:
    """The planner checks of each run (module docstring), without physics.

    Args:
      params_list: validated ``LoaderParams``, one per run. Only the key points and the key
        interval matter: payload, settle time and duration act on the machine, not on the
        plan.
      planner: None for the paper's cubic B-spline (runs with equal key times judged
        together, fast), or a planner of your own with ``plan(LoaderProblem) -> Trajectory``:
        each run's trajectory judged at its control ticks (``judge_trajectory``); a
        ``PlanningError`` it raises propagates, as in a run.

    Returns:
      One list of ``Check`` per run, in the order of ``params_list``. Key points whose spline
      leaves the joint ranges, which the paper's planner refuses, are judged all the same
      (the spline it would return, without its range check): their ``joint_range`` fails and
      its note gives the planner's error.
    """
    params_list = list(params_list)
    tasks = [problem(p) for p in params_list]
    if planner is not None:
        return [judge_trajectory(task, plan_checked(planner, task, task.labels)) for task in tasks]
    groups: dict[tuple, list[int]] = {}
    for i, task in enumerate(tasks):
        groups.setdefault(task.key_times.tobytes(), []).append(i)
    out: list = [None] * len(tasks)
    for members in groups.values():
        ticks = float(tasks[members[0]].key_times[-1]) / CONTROL_DT + 2
        size = int(min(CHUNK_RUNS, max(1, CHUNK_TICKS // ticks)))
        for lo in range(0, len(members), size):
            chunk = members[lo : lo + size]
            for i, judged in zip(chunk, _judge_group([tasks[i] for i in chunk]), strict=True):
                out[i] = _checks(judged, _refusal(tasks[i]) if judged["range"] > 1.0 else "")
    return out


# --------------------------------------------------------------------------- any planner's trajectory


def judge_trajectory(task: LoaderProblem, trajectory) -> list[Check]:
    """The planner checks of one run from the trajectory planned for its problem, sampled at
    the control ticks (and its end) as a run samples it: the key points at the key times, the
    range and the rate at the ticks, ``clearance`` at every tick. What ``judge_plans``
    computes for the paper's spline, without its shortcuts, for any planner's trajectory."""
    duration = float(trajectory.duration)
    ticks = control_ticks(duration, CONTROL_DT)
    if ticks[-1] < duration - 1e-9:
        ticks = np.append(ticks, duration)
    sample = trajectory.sample(ticks)
    q = np.asarray(sample.position, dtype=float)
    at_keys = np.asarray(trajectory.sample(task.key_times).position, dtype=float) - task.key_points
    key_deg = np.degrees(np.abs(at_keys[:, 1:]))
    k, jk = np.unravel_index(int(np.argmax(key_deg)), key_deg.shape)
    rr = range_ratio_of(q, task.lower, task.upper, np.full(q.shape[1], JOINT_LIMIT_TOLERANCE))
    kr, jr = np.unravel_index(int(np.argmax(rr)), rr.shape)
    rt = np.abs(np.asarray(sample.velocity, dtype=float)) / task.rate_limit
    kt, jt = np.unravel_index(int(np.argmax(rt)), rt.shape)
    collision = _collision()
    full = np.zeros((q.shape[0], collision.model.nq))
    full[:, collision.qpos] = q
    values, pairs = clearance(collision.model, full, collision.robot, collision.obstacles)
    i = int(np.argmin(values))
    labels = task.labels
    return _checks(
        {
            "key_deg": float(key_deg.max()),
            "key_point": int(k),
            "key_joint": labels[1 + int(jk)],
            "key_slide_mm": float(1e3 * np.abs(at_keys[:, 0]).max()),
            "range": float(rr[kr, jr]),
            "range_joint": labels[jr],
            "range_t": float(ticks[kr]),
            "range_value": float(q[kr, jr]),
            "rate": float(rt[kt, jt]),
            "rate_joint": labels[jt],
            "rate_t": float(ticks[kt]),
            "rate_value": float(np.abs(sample.velocity[kt, jt])),
            "clearance": float(values[i]),
            "clearance_t": float(ticks[i]),
            "pair": (int(pairs[i, 0]), int(pairs[i, 1])),
            "ticks_evaluated": ticks.size,
            "ticks": ticks.size,
        }
    )


# --------------------------------------------------------------------------- throughput


def random_key_points(n: int, rng: np.random.Generator, keys: int = 6, spread_deg: float | None = None):
    """``n`` key-point sets (Table 1's units: mm, deg), drawn for the tests: uniform in the
    joint ranges (``spread_deg`` None), or Table 1's points with each value moved by a uniform
    +/- spread_deg (deg; the slide by that many mm times 5), clipped to the ranges."""
    spec = models.loader_spec()
    low, high = si_to_table1(spec.lower), si_to_table1(spec.upper)
    if spread_deg is None:
        return rng.uniform(low, high, size=(n, keys, 6))
    scale = np.array([5.0, 1, 1, 1, 1, 1]) * spread_deg
    base = TABLE1[np.linspace(0, len(TABLE1) - 1, keys).round().astype(int)]
    return np.clip(base + rng.uniform(-1, 1, size=(n, keys, 6)) * scale, low, high)
