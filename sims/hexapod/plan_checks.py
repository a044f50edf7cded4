"""Planner-only checks of hexapod runs: the planned moves judged without physics.

``judge_plans(params_list)`` plans every move of every run as a run does
(``planbench.hexapod.problems``: each move from the pose the one before reached, the paper's
generator) and returns, per run, the checks that judge the trajectory the planner returned.
Where the run has a check of the same quantity it has the run's name, limit and unit; where
the run's check of that name measures the machine (the encoders, the platform's pose), the
planned quantity's name begins with ``plan_``. A check reports the worst move of its run, as
``HexapodEvaluation`` does.

=====================  =====  ===========================  =========================================
check                  unit   passes when                  what
=====================  =====  ===========================  =========================================
arrival_spread         s      <= ARRIVAL_SPREAD_LIMIT_S    synchronous moves: last minus first arrival
                              (one tick, 5 ms)             of the moving struts (paper, "all struts
                                                           should arrive ... at the same time")
arrival_vs_own_time    s      <= 2 CONTROL_DT (10 ms)      asynchronous moves: largest arrival - 2 T_i
                                                           (one-sided: early is negative), T_i =
                                                           max(t_i,max, t'_min) (paper, steps 1-3;
                                                           ``own_move_times``)
strut_velocity         um/s   <= v_max (500)               peak planned strut speed
strut_accel            um/s2  <= a_max (500)               peak planned strut acceleration
hexapod_speed          ratio  <= 1                         peak planned pose speed of the four
                                                           hexapod-space speeds over v'_max
                                                           (``hexapod_speed_ratios``)
plan_stroke            mm     <= stroke (14.1)             peak |planned strut length change| (the
                                                           run's ``stroke`` is the encoders')
pose_limits            ratio  <= 1                         largest |pose - centre| / half range of any
                                                           axis along the planned path, the pose by
                                                           forward kinematics of the planned struts
plan_pose_error_final  um     <= POSE_FINAL_LIMIT_UM (1)   largest mirror-side pivot displacement of the
                                                           forward kinematics of the planned end
                                                           lengths from the target pose (the run's
                                                           ``pose_error_final`` is the platform's)
=====================  =====  ===========================  =========================================

Limits are the run's constants (``planbench.hexapod``) and Rubin's (``planbench.planners.hexapod.RUBIN_LIMITS``,
REFERENCE.md "Rubin hexapod"), never loosened. ``pose_limits`` has no counterpart in a run:
the generator plans in strut space and checks the pose limits at the start and the target
only, so a path between two poses inside the limits can leave them (the struts' profiles
differ in shape, and asynchronous struts arrive one after another).

How the paper's plans are judged fast (``judge_plans`` without a planner)
------------------------------------------------------------------------
The moves of all runs are planned together, grouped by mode, by ``planbench.planners.hexapod.plan_moves``
(the closed-form long-move acceleration; the tick realization, the motion itself, depends only
on the distances and the half times, so it equals ``PaperMovePlanner``'s, which uses the
iteration). On the tick grid a strut accelerates for ``n_accel`` ticks, cruises and brakes; its
motion is piecewise quadratic between its *switching ticks* 0, n_accel, n - n_accel, n (all
ticks). Between two consecutive switching ticks of the six struts (a *piece*) every strut
position is one quadratic in t, so

* the speed is linear in t and the acceleration constant: their peaks over all ticks are at
  switching ticks; a strut's position is monotone, its peak magnitude at its start or end;
* the arrivals are the ticks n_i (the planned motion rests exactly on the target after them,
  and one tick earlier a moving strut is at least D_i / (2 n_a (n - n_a)) > 1e-8 D_i from it,
  beyond the arrival tolerance of ``planbench.hexapod.strut_tolerances``);
* the hexapod-space speeds (``hexapod_speed_ratios``: norms of the pose rate J^-1 qdot) are
  taken at the switching ticks and at each piece's midpoint. The Jacobian is not constant over
  a move, so a speed need not peak at a switching tick: in 6000 random moves the axial speed
  peaked at a midpoint up to 3 % above its switching ticks' (never the worst of the four
  there). Against every control tick of 800 random moves the check's value agreed to 3e-10
  (relative) and each of the four speeds, as its note prints them, exactly;
* the pose, the forward kinematics of six quadratics, is smooth inside a piece: its largest
  excursion is at a piece's end or at an interior extreme of one axis. The pose is computed
  exactly (forward kinematics) at every switching tick and at each piece's midpoint; each axis
  inside each piece is the quadratic through those three values, whose vertex predicts where
  an interior extreme lies; the two largest predicted extremes of each move are computed
  exactly too (``VERTICES_EVALUATED``). The value reported is the largest of these exact
  samples, so the quadratics only choose where to look. The path is judged in continuous
  time: between two ticks the pose moves less than 1e-4 of a half range. Against the forward
  kinematics of every control tick of 300 random moves (half of them leaving the limits) it
  differed by -1.3e-6 ... +7.3e-7 of a half range (the test allows 1e-5).

Every strut sample comes from ``StrutMove.sample`` itself, the planner's own evaluation: one
``StrutMove`` whose fields are (rows, 6) arrays, one row per (move, time), samples each row
at its own time (its formulas are elementwise). Struts often share a switching tick (about a
third of a move's samples repeat the time before them): such a time is sampled, solved and
given its speeds once, and its copies take those numbers. The forward kinematics iterates
each pose on its own until its strut-length residual is below ``FK_TOLERANCE_M``, so no
result depends on the others in its batch: judging runs together gives, bit for bit, what
judging each alone does (tested).

A planner of your own (``judge_plans(..., planner=...)``) is judged by sampling the
trajectories it returns at the control ticks (``judge_trajectories``): slower, the same
checks, the pose at every tick.

Throughput (the 2-core development machine; ``planbench bench`` runs the campaign
examples/hexapod/random_moves_campaign.toml end to end): ``judge_plans`` of 10^5 single-move
runs, start and target uniform in the limits, took 26 s of CPU (3800-4300 runs/s), and building
their ``HexapodParams`` 40 s more. A campaign's columnar path (``planbench.hexapod.plan_columns``)
builds none: it validates the runs' poses as arrays and judges the valid ones through
``judge_moves``, the same per-move quantities, at 50 000-58 000 runs/s of one core's CPU
(about 30 % of the drawn moves valid, 50-60 us a valid move), and the example's 10^6 moves on
two workers at about 73 000 runs/s.

Example::

    >>> from planbench.hexapod import HexapodMove, HexapodParams
    >>> from planbench.hexapod.plan_checks import judge_plans
    >>> params = HexapodParams(moves=(HexapodMove((1.5, -1.0, 0.8, 0.1, -0.05, 0.03)),))
    >>> [checks] = judge_plans([params])
    >>> [(c.name, c.passed) for c in checks][:3]
    [('arrival_spread', True), ('strut_velocity', True), ('strut_accel', True)]
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from planbench.checks import Check
from planbench.hexapod.params import HexapodParams
from planbench.hexapod.task import (
    ARRIVAL_SPREAD_LIMIT_S,
    OWN_TIME_LIMIT_S,
    POSE_FINAL_LIMIT_UM,
    arrival_times,
    hexapod_speed_check,
    plan_moves,
    problems,
    strut_tolerances,
)
from planbench.planners import hexapod as hexapod_planner
from planbench.planners.errors import PlanningError
from planbench.planners.hexapod import POSE_LABELS, RUBIN_CAMERA, RUBIN_LIMITS, STRUT_LABELS, StrutMove
from planbench.planners.legs import component_norm, leg_vector_components
from planbench.planners.trajectory import PiecewiseTrajectory, TrajectorySample, control_ticks

#: Forward kinematics stops for a pose once its largest strut-length residual is below this,
#: m (0.1 nm: 1e-8 of the smallest pose limit, 1e-4 of the 1 um end-pose limit).
FK_TOLERANCE_M = 1e-10
#: Iterations after which a pose that has not converged is reported as not evaluated.
FK_MAX_ITERATIONS = 40
#: Moves planned and judged at once: bounds the memory (about 25 kB per move, 50 MB a chunk).
CHUNK_MOVES = 2048
#: Points whose strut samples and Jacobians are computed at once: their arrays stay in the
#: cache (sampling 40 000 points 2048 at a time is 3.6 times as fast as all at once; the
#: numbers do not depend on it).
KINEMATICS_BLOCK = 2048

_LOWER, _UPPER = RUBIN_LIMITS.pose_lower, RUBIN_LIMITS.pose_upper
_CENTRE, _HALF = (_UPPER + _LOWER) / 2.0, (_UPPER - _LOWER) / 2.0
_AXIS_SCALE = np.array([1e3, 1e3, 1e3, *(3 * [np.degrees(1.0)])])  # m, rad -> mm, deg
_AXIS_UNIT = ("mm",) * 3 + ("deg",) * 3


# --------------------------------------------------------------------------- kinematics


def _max_last(values: np.ndarray) -> np.ndarray:
    """``values.max(axis=-1)`` of a short last axis, its columns compared one after another
    (the same numbers, NaN included; numpy's reduction over a short contiguous axis is several
    times slower)."""
    out = values[..., 0].copy()
    for column in range(1, values.shape[-1]):
        np.maximum(out, values[..., column], out=out)
    return out


def _strut_lengths(pose: np.ndarray) -> np.ndarray:
    """``planbench.planners.hexapod.strut_lengths`` without its input check (the poses here are the
    kinematics' own iterates, finite by construction), on components (the same numbers),
    (M, 6) -> (M, 6) m."""
    vectors, _ = leg_vector_components(
        RUBIN_CAMERA.base_pivots,
        RUBIN_CAMERA.platform_local,
        RUBIN_CAMERA.rotation_pivot + pose[:, :3],
        hexapod_planner.rotation_matrix(pose[:, 3:]),
    )
    return component_norm(*vectors)


def poses_of_lengths(
    lengths: np.ndarray, guess: np.ndarray, inverse_jacobian: np.ndarray, which: np.ndarray | None = None
):
    """Forward kinematics of many strut-length sets, each on its own.

    The chord method: pose <- pose - J0^-1 (L(pose) - lengths) with a fixed J0 per row near
    the solution (``planbench.planners.hexapod.forward_kinematics`` is Newton's method, but it stops when
    the worst row of its batch has converged, so a row's result would depend on the batch).
    Each row stops when its own residual is below FK_TOLERANCE_M.

    Args:
      lengths: (M, 6) strut lengths, m.
      guess: (M, 6) starting poses (m, rad).
      inverse_jacobian: (K, 6, 6) inverses of dL/dpose near the solutions; row r uses
        ``inverse_jacobian[which[r]]`` (``which`` None: K = M, row r its own).

    Returns:
      (poses (M, 6), residual (M,) m): rows whose residual is above FK_TOLERANCE_M after
      FK_MAX_ITERATIONS did not converge.
    """
    pose = np.array(guess, dtype=float)
    inverse = inverse_jacobian if which is None else inverse_jacobian[np.asarray(which)]  # (M, 6, 6)
    residual = _strut_lengths(pose) - lengths
    worst = _max_last(np.abs(residual))
    active = np.flatnonzero(worst > FK_TOLERANCE_M)
    for _ in range(FK_MAX_ITERATIONS):
        if active.size == 0:
            break
        if active.size == pose.shape[0]:  # every row (often the first step): no gathers
            pose -= np.einsum("nij,nj->ni", inverse, residual)
            residual = _strut_lengths(pose) - lengths
            worst = _max_last(np.abs(residual))
            active = np.flatnonzero(worst > FK_TOLERANCE_M)
            continue
        step = np.einsum("nij,nj->ni", inverse[active], residual[active])
        pose[active] -= step
        res = _strut_lengths(pose[active]) - lengths[active]
        residual[active] = res
        worst[active] = _max_last(np.abs(res))
        active = active[worst[active] > FK_TOLERANCE_M]
    return pose, worst


def _inverse_jacobians(poses: np.ndarray) -> np.ndarray:
    """(M, 6, 6) inverses of dL/dpose at the poses (``planbench.planners.hexapod.jacobian``)."""
    return np.linalg.inv(hexapod_planner.jacobian(poses))


def pivot_error_um(poses: np.ndarray, target_poses: np.ndarray) -> np.ndarray:
    """(M,) largest displacement of the six mirror-side pivots between poses and targets, um
    (the measure of the run's ``pose_error_final``)."""
    actual = hexapod_planner.pivot_positions(poses)
    wanted = hexapod_planner.pivot_positions(target_poses)
    return 1e6 * np.linalg.norm(actual - wanted, axis=-1).max(axis=-1)


def pose_ratio(poses: np.ndarray) -> np.ndarray:
    """(..., 6) (pose - centre) / half range per axis: within the pose limits is [-1, 1]."""
    return (poses - _CENTRE) / _HALF


# --------------------------------------------------------------------------- the paper's moves


def _switching_ticks(moves: hexapod_planner.StrutMoves) -> np.ndarray:
    """(N, B) sorted switching ticks of every strut of every move (module docstring); B = 14
    for synchronous moves (one shared end), 19 otherwise."""
    n, k = moves.n_ticks, moves.n_accel
    zero = np.zeros((n.shape[0], 1), dtype=n.dtype)
    ends = n[:, :1] if moves.synchronous else n
    return np.sort(np.concatenate([zero, k, n - k, ends], axis=1), axis=1)


def _sample_rows(moves: hexapod_planner.StrutMoves, rows: np.ndarray, t: np.ndarray) -> TrajectorySample:
    """The planner's own ``StrutMove.sample`` of move ``rows[r]`` at time ``t[r]`` for every r,
    KINEMATICS_BLOCK rows at a time (the sample is elementwise: the same numbers)."""
    parts = []
    for lo in range(0, rows.size, KINEMATICS_BLOCK):
        block = rows[lo : lo + KINEMATICS_BLOCK]
        batch = StrutMove(
            moves.start[block],
            moves.target[block],
            moves.n_ticks[block],
            moves.n_accel[block],
            moves.accel[block],
            moves.dt,
            None,
            moves.synchronous,
        )
        parts.append(batch.sample(t[lo : lo + KINEMATICS_BLOCK]))
    if len(parts) == 1:
        return parts[0]
    return TrajectorySample(
        *(np.concatenate([getattr(p, f) for p in parts]) for f in ("t", "position", "velocity", "acceleration"))
    )


class _Anchors:
    """Where the kinematics of a batch of moves is linearized: for each move its start pose,
    the pose halfway between start and target, and its target pose, with the inverse
    Jacobians there. A planned strut position takes the anchor nearest to it in strut space
    (every planned position is within a quarter of its move of one)."""

    def __init__(self, moves: hexapod_planner.StrutMoves):
        middle = 0.5 * (moves.start_pose + moves.target_pose)
        self.poses = np.stack([moves.start_pose, middle, moves.target_pose], axis=1)  # (N, 3, 6)
        self.struts = np.stack([moves.start, hexapod_planner.strut_positions(middle), moves.target], axis=1)
        self.inverse = _inverse_jacobians(self.poses.reshape(-1, 6))  # (3N, 6, 6)

    def nearest(self, rows: np.ndarray, position: np.ndarray) -> np.ndarray:
        """(R,) the row of ``inverse`` of the anchor nearest to each position (R, 6) of move
        ``rows``."""
        # argmin of the three distances (the first of equal ones; positions are finite).
        best = _max_last(np.abs(position - self.struts[rows, 0]))
        choice = np.zeros(rows.shape[0], dtype=np.intp)
        for anchor in (1, 2):
            distance = _max_last(np.abs(position - self.struts[rows, anchor]))
            closer = distance < best
            choice[closer] = anchor
            best = np.where(closer, distance, best)
        return 3 * rows + choice


def _poses_along(anchors: _Anchors, position: np.ndarray, fresh: np.ndarray):
    """Forward kinematics of the planned strut positions (N, P, 6) of N moves, each move's P
    points in time order (the first its start, the last its end): point k starts from point
    k - 1's pose, moved by the nearest anchor's linearization, the end from the target pose
    itself (an exact plan ends exactly there). A point that is not ``fresh`` (N, P) repeats
    the one before it (the same time) and takes its pose: the pose its own iteration would
    reach, since it would start there already converged. Returns (poses (N, P, 6), residual
    (N, P) m)."""
    count, points = position.shape[:2]
    # Point by point, each point's rows contiguous.
    along = np.ascontiguousarray(position.transpose(1, 0, 2))  # (P, N, 6)
    poses = np.empty(along.shape)
    residual = np.empty((points, count))
    previous_pose, previous_position = anchors.poses[:, 0], anchors.struts[:, 0]
    for k in range(points):
        if k == points - 1 or fresh[:, k].all():
            rows = slice(None)
            inverse = anchors.inverse[anchors.nearest(np.arange(count), along[k])]
            if k == points - 1:
                guess = anchors.poses[:, 2]
            else:
                guess = previous_pose + np.einsum("nij,nj->ni", inverse, along[k] - previous_position)
        else:
            poses[k], residual[k] = poses[k - 1], residual[k - 1]
            rows = np.flatnonzero(fresh[:, k])
            inverse = anchors.inverse[anchors.nearest(rows, along[k, rows])]
            guess = previous_pose[rows] + np.einsum("nij,nj->ni", inverse, along[k, rows] - previous_position[rows])
        poses[k, rows], residual[k, rows] = poses_of_lengths(
            along[k, rows] + RUBIN_CAMERA.nominal_lengths, guess, inverse
        )
        previous_pose, previous_position = poses[k], along[k]
    return np.ascontiguousarray(poses.transpose(1, 0, 2)), np.ascontiguousarray(residual.T)


def _max_by_move(values: np.ndarray, first: np.ndarray, points: int) -> np.ndarray:
    """(N, C) the largest of ``values`` (F, C) of each move's points, row r of ``values``
    being flat point ``first[r]`` (sorted; every move has at least one)."""
    starts = np.flatnonzero(np.diff(first // points, prepend=-1))
    return np.maximum.reduceat(values, starts, axis=0)


#: Interior extremes of the pose inside the pieces evaluated exactly per move (the largest
#: ones the quadratics predict): two, so that a near tie between two pieces is decided by the
#: exact values, not by the quadratics' error (<= 3e-4 of a half range on long pieces).
VERTICES_EVALUATED = 2


def _judge_strut_moves(moves: hexapod_planner.StrutMoves) -> dict:
    """Per move (arrays (N,)) the planned quantities of the checks, for moves the paper's
    generator planned (``plan_moves``); see the module docstring for how."""
    count = len(moves)
    dt = moves.dt
    index = np.arange(count)
    ticks = _switching_ticks(moves)  # (N, B)
    b = ticks.shape[1]
    # Sample times per move: switching ticks and the midpoints between them, interleaved.
    times = np.empty((count, 2 * b - 1))
    times[:, 0::2] = ticks * dt
    times[:, 1::2] = 0.5 * (ticks[:, :-1] + ticks[:, 1:]) * dt
    points = times.shape[1]
    # Switching ticks shared by several struts repeat a time: such a point is sampled and
    # solved once, and its copies take its values (the same numbers).
    fresh = np.ones((count, points), dtype=bool)
    fresh[:, 1:] = times[:, 1:] != times[:, :-1]
    first = np.flatnonzero(fresh.ravel())
    # Flat point -> the row among ``first`` of the fresh point at or before it (its own, or
    # the one it repeats).
    rank = np.cumsum(fresh.ravel()) - 1
    sample = _sample_rows(moves, first // points, times.ravel()[first])
    position = sample.position[rank].reshape(count, points, 6)
    speed = _max_by_move(np.abs(sample.velocity), first, points)  # (N, 6)
    accel = _max_by_move(np.abs(sample.acceleration), first, points)
    stroke = np.abs(position).max(axis=1)

    anchors = _Anchors(moves)
    poses, residual = _poses_along(anchors, position, fresh)
    converged = (residual <= FK_TOLERANCE_M).all(axis=1)

    # Exact samples: the largest |ratio| of any axis at a switching tick or a midpoint.
    u = pose_ratio(poses)
    exact = np.abs(u).reshape(count, -1)
    best = np.argmax(exact, axis=1)
    ratio = exact[index, best]
    point, axis = np.divmod(best, 6)
    value = poses[index, point, axis]
    when = times[index, point]
    # Inside each piece, each axis as the quadratic q(s), s in [0, 1], through its ends and
    # midpoint: its vertex, where inside, is a candidate extreme, evaluated exactly.
    fa, fm, fb = u[:, 0:-1:2], u[:, 1::2], u[:, 2::2]  # (N, B-1, 6)
    lin = -3.0 * fa + 4.0 * fm - fb
    quad = 2.0 * fa - 4.0 * fm + 2.0 * fb
    with np.errstate(divide="ignore", invalid="ignore"):
        s_vertex = -lin / (2.0 * quad)
    inside = (quad != 0.0) & (s_vertex > 0.0) & (s_vertex < 1.0)
    s_vertex = np.where(inside, s_vertex, 0.0)
    predicted = np.where(inside, np.abs(fa + s_vertex * (lin + s_vertex * quad)), -1.0).reshape(count, -1)
    top = np.argsort(-predicted, axis=1, kind="stable")[:, :VERTICES_EVALUATED]  # (N, V)
    piece = top // 6
    t_a, t_b = times[index[:, None], 2 * piece], times[index[:, None], 2 * piece + 2]
    t_vertex = t_a + s_vertex.reshape(count, -1)[index[:, None], top] * (t_b - t_a)
    has_vertex = predicted[index[:, None], top] >= 0.0
    t_vertex = np.where(has_vertex, t_vertex, 0.0)  # no vertex: the start again (no new value)
    vrows = np.repeat(index, VERTICES_EVALUATED)
    vposition = _sample_rows(moves, vrows, t_vertex.ravel()).position
    # From the exact pose at the piece's sample nearest in time (its start, midpoint or end).
    nearest = (
        2 * piece + np.rint(2.0 * np.clip((t_vertex - t_a) / np.where(t_b > t_a, t_b - t_a, 1.0), 0, 1)).astype(np.intp)
    ).ravel()
    which = anchors.nearest(vrows, vposition)
    guess = poses[vrows, nearest] + np.einsum(
        "nij,nj->ni", anchors.inverse[which], vposition - position[vrows, nearest]
    )
    vposes, vresidual = poses_of_lengths(vposition + RUBIN_CAMERA.nominal_lengths, guess, anchors.inverse, which)
    converged &= (vresidual <= FK_TOLERANCE_M).reshape(count, -1).all(axis=1)
    vu = np.abs(pose_ratio(vposes)).reshape(count, -1)  # (N, V * 6)
    vbest = np.argmax(vu, axis=1)
    better = vu[index, vbest] > ratio
    vpoint, vaxis = np.divmod(vbest, 6)
    ratio = np.where(better, vu[index, vbest], ratio)
    value = np.where(better, vposes.reshape(count, -1, 6)[index, vpoint, vaxis], value)
    axis = np.where(better, vaxis, axis)
    when = np.where(better, t_vertex[index, vpoint], when)

    # Hexapod-space speeds at every sample (module docstring: the switching ticks alone would
    # miss a midpoint's peak of a smaller speed).
    fresh_poses = poses.reshape(-1, 6)[first]
    hex_speed = _max_by_move(
        np.concatenate(
            [
                hexapod_planner.hexapod_speed_ratios(
                    fresh_poses[lo : lo + KINEMATICS_BLOCK], sample.velocity[lo : lo + KINEMATICS_BLOCK]
                )
                for lo in range(0, first.size, KINEMATICS_BLOCK)
            ]
        ),
        first,
        points,
    )
    _, moving = strut_tolerances(moves.start, moves.target)
    arrival = moves.n_ticks * dt
    own = _own_times(moves)
    big, small = np.where(moving, arrival, -np.inf).max(1), np.where(moving, arrival, np.inf).min(1)
    return {
        "spread": np.where(moving.any(axis=1), big - small, 0.0),
        "late": np.where(moving.any(axis=1), np.where(moving, arrival - own, -np.inf).max(axis=1), 0.0),
        **{key: np.where(converged, hex_speed[:, k], np.nan) for k, key in enumerate(_HEX_KEYS)},
        "speed": speed.max(axis=1),
        "speed_strut": speed.argmax(axis=1),
        "accel": accel.max(axis=1),
        "stroke": stroke.max(axis=1),
        "stroke_strut": stroke.argmax(axis=1),
        "ratio": np.where(converged, ratio, np.nan),
        "ratio_axis": axis,
        "ratio_value": value,
        "ratio_time": when,
        "end_error": np.where(converged, pivot_error_um(poses[:, -1], moves.target_pose), np.nan),
    }


def _own_times(moves: hexapod_planner.StrutMoves) -> np.ndarray:
    """(N, 6) each strut's own minimum move time 2 T_i, s: ``own_move_times`` for many moves,
    from the same planner functions (paper, steps 1-3)."""
    half = np.abs(moves.target - moves.start) / 2.0
    t_hex = hexapod_planner.hexapod_space_min_time(moves.target_pose - moves.start_pose, RUBIN_LIMITS)
    return 2.0 * np.maximum(hexapod_planner.strut_min_time(half, RUBIN_LIMITS), t_hex[:, None])


def _plan_group(start: np.ndarray, target: np.ndarray, synchronous: bool):
    """Plan and judge moves of one mode, CHUNK_MOVES at a time; a chunk the planner refuses as a
    whole is planned move by move, and a refused move's entry is its error message."""
    results, failures = [], {}
    for lo in range(0, start.shape[0], CHUNK_MOVES):
        hi = min(lo + CHUNK_MOVES, start.shape[0])
        try:
            results.append(
                _judge_strut_moves(
                    hexapod_planner.plan_moves(start[lo:hi], target[lo:hi], synchronous=synchronous, method="closed")
                )
            )
            continue
        except PlanningError:
            pass
        for k in range(lo, hi):
            try:
                results.append(
                    _judge_strut_moves(
                        hexapod_planner.plan_moves(
                            start[k : k + 1], target[k : k + 1], synchronous=synchronous, method="closed"
                        )
                    )
                )
            except PlanningError as e:
                failures[k] = f"{type(e).__name__}: {e}"
                results.append(None)
    out = {key: np.concatenate([r[key] if r is not None else np.full(1, np.nan) for r in results]) for key in _KEYS}
    return out, failures


# --------------------------------------------------------------------------- checks

#: The per-move quantities a run's checks are made of (``_judge_strut_moves``).
_HEX_KEYS = ("hex_radial", "hex_axial", "hex_radial_angular", "hex_axial_angular")
_KEYS = (
    "spread",
    "late",
    "speed",
    "speed_strut",
    "accel",
    "stroke",
    "stroke_strut",
    "ratio",
    "ratio_axis",
    "ratio_value",
    "ratio_time",
    "end_error",
    *_HEX_KEYS,
)


def _worst(values: np.ndarray) -> int:
    """Index of the worst of a run's moves: the largest value, or the first NaN (a move whose
    quantity could not be evaluated: the run's check is then not evaluated either)."""
    nan = np.isnan(values)
    return int(np.argmax(nan)) if nan.any() else int(np.argmax(values))


def _run_checks(m: dict, synchronous: np.ndarray, lo: int, hi: int) -> list[Check]:
    """The checks of the run whose moves are ``lo:hi`` of the per-move arrays ``m`` (SI): each
    the worst of its moves, as ``HexapodEvaluation`` reports a run."""
    limits = RUBIN_LIMITS
    several = hi - lo > 1
    sync = synchronous[lo:hi]
    checks = []
    if sync.any():
        checks.append(
            Check(
                "arrival_spread",
                float(m["spread"][lo:hi][sync].max()),
                ARRIVAL_SPREAD_LIMIT_S,
                "s",
                note="last minus first strut arrival of the planned motion",
            )
        )
    if not sync.all():
        checks.append(
            Check(
                "arrival_vs_own_time",
                float(m["late"][lo:hi][~sync].max()),
                OWN_TIME_LIMIT_S,
                "s",
                note="each planned strut's arrival minus its minimum time 2 max(t_i, t'_min) (early is negative)",
            )
        )
    if several:
        ws, wv, wr, we = (lo + _worst(m[k][lo:hi]) for k in ("speed", "stroke", "ratio", "end_error"))
    else:
        ws = wv = wr = we = lo
    move = f" (move {wr - lo})" if several else ""
    axis = int(m["ratio_axis"][wr])
    ratio, end = float(m["ratio"][wr]), float(m["end_error"][we])
    no_fk = (
        "not evaluated: forward kinematics of the planned strut lengths did not converge to "
        f"{FK_TOLERANCE_M:g} m" + (f" (move {we - lo})" if several else "")
    )
    checks += [
        Check(
            "strut_velocity",
            1e6 * float(m["speed"][ws]),
            1e6 * limits.strut_speed,
            "um/s",
            note=f"planned, peak on {STRUT_LABELS[int(m['speed_strut'][ws])]}",
        ),
        Check(
            "strut_accel",
            1e6 * float(m["accel"][lo:hi].max()),
            1e6 * limits.strut_accel,
            "um/s2",
            note="planned, per tick",
        ),
        _hex_speed(m, lo, hi, no_fk),
        Check(
            "plan_stroke",
            1e3 * float(m["stroke"][wv]),
            1e3 * limits.stroke,
            "mm",
            note=f"planned strut length change, peak on {STRUT_LABELS[int(m['stroke_strut'][wv])]}",
        ),
        Check(
            "pose_limits",
            ratio,
            1.0,
            "ratio",
            note=f"|pose - centre| / half range of the worst axis along the planned path: "
            f"{POSE_LABELS[axis]} = {_AXIS_SCALE[axis] * float(m['ratio_value'][wr]):.5g} "
            f"{_AXIS_UNIT[axis]} (limits +/-{_AXIS_SCALE[axis] * _HALF[axis]:.4g}) at "
            f"t = {float(m['ratio_time'][wr]):.3f} s{move}"
            if np.isfinite(ratio)
            else no_fk,
        ),
        Check(
            "plan_pose_error_final",
            end,
            POSE_FINAL_LIMIT_UM,
            "um",
            note="mirror-side pivots at the forward kinematics of the planned end strut lengths "
            "against the target pose" + (", worst move" if several else "")
            if np.isfinite(end)
            else no_fk,
        ),
    ]
    return checks


def _hex_speed(m: dict, lo: int, hi: int, no_fk: str) -> Check:
    peaks = np.array([m[key][lo:hi].max() for key in _HEX_KEYS])
    if np.isnan(peaks).any():
        return Check.not_evaluated("hexapod_speed", 1.0, "ratio", reason=no_fk)
    return hexapod_speed_check(peaks, "planned")


def _refused_checks(synchronous: np.ndarray, move: int, message: str, several: bool) -> list[Check]:
    """Every check of a run not evaluated: the planner refused its move ``move``."""
    reason = f"the planner refused {'move ' + str(move) if several else 'the move'}: {message}"
    limits = RUBIN_LIMITS
    checks = []
    if synchronous.any():
        checks.append(Check.not_evaluated("arrival_spread", ARRIVAL_SPREAD_LIMIT_S, "s", reason=reason))
    if not synchronous.all():
        checks.append(Check.not_evaluated("arrival_vs_own_time", OWN_TIME_LIMIT_S, "s", reason=reason))
    for name, limit, unit in (
        ("strut_velocity", 1e6 * limits.strut_speed, "um/s"),
        ("strut_accel", 1e6 * limits.strut_accel, "um/s2"),
        ("hexapod_speed", 1.0, "ratio"),
        ("plan_stroke", 1e3 * limits.stroke, "mm"),
        ("pose_limits", 1.0, "ratio"),
        ("plan_pose_error_final", POSE_FINAL_LIMIT_UM, "um"),
    ):
        checks.append(Check.not_evaluated(name, limit, unit, reason=reason))
    return checks


def judge_plans(params_list: Sequence[HexapodParams], planner=None) -> list[list[Check]]:
    """The planner checks of each run (module docstring), without physics.

    Args:
      params_list: validated ``HexapodParams``, one per run. Only the start pose and the moves
        matter: elevation, wind, dwell and duration act on the machine, not on the plan.
      planner: None for the paper's generator (the moves of all runs judged together, fast),
        or a planner of your own with ``plan(MoveProblem) -> Trajectory``: each run planned
        by ``planbench.hexapod.plan_moves`` and judged at its control ticks
        (``judge_trajectories``); a ``PlanningError`` it raises propagates, as in a run.

    Returns:
      One list of ``Check`` per run, in the order of ``params_list``. A run one of whose
      moves the paper's generator refuses (a PlanningError; validated parameters give none)
      gets its checks as not evaluated, naming the error.
    """
    params_list = list(params_list)
    if planner is not None:
        out = []
        for params in params_list:
            trajectory, moves, _, _ = plan_moves(params, planner)
            pieces = trajectory.pieces if isinstance(trajectory, PiecewiseTrajectory) else [trajectory]
            out.append(judge_trajectories(moves, pieces))
        return out
    runs = [problems(p) for p in params_list]
    offsets = np.concatenate([[0], np.cumsum([len(moves) for moves in runs])]).astype(int)
    flat = [m for moves in runs for m in moves]
    synchronous = np.array([m.synchronous for m in flat], dtype=bool)
    start = np.array([m.start_pose for m in flat], dtype=float).reshape(-1, 6)
    target = np.array([m.target_pose for m in flat], dtype=float).reshape(-1, 6)
    per_move, refused = judge_moves(start, target, synchronous)
    return checks_of_runs(per_move, refused, synchronous, offsets)


def judge_moves(start: np.ndarray, target: np.ndarray, synchronous: np.ndarray) -> tuple[dict, dict]:
    """(per-move quantities, {move: the planner's refusal}) of the moves ``start`` -> ``target``
    ((N, 6) SI poses, each move on its own), planned together by mode (``_plan_group``)."""
    per_move = {k: np.full(len(synchronous), np.nan) for k in _KEYS}
    refused: dict[int, str] = {}
    for mode in (True, False):
        index = np.flatnonzero(synchronous == mode)
        if index.size:
            judged, failures = _plan_group(start[index], target[index], mode)
            for k in _KEYS:
                per_move[k][index] = judged[k]
            refused.update({int(index[i]): text for i, text in failures.items()})
    return per_move, refused


def checks_of_runs(per_move: dict, refused: dict, synchronous: np.ndarray, offsets) -> list[list[Check]]:
    """Each run's checks, its moves ``offsets[r]:offsets[r + 1]`` of the per-move arrays."""
    out = []
    for r in range(len(offsets) - 1):
        lo, hi = int(offsets[r]), int(offsets[r + 1])
        bad = [i for i in refused if lo <= i < hi] if refused else []
        if bad:
            first = min(bad)
            out.append(_refused_checks(synchronous[lo:hi], first - lo, refused[first], hi - lo > 1))
        else:
            out.append(_run_checks(per_move, synchronous, lo, hi))
    return out


# --------------------------------------------------------------------------- any planner's trajectories


def judge_trajectories(moves: Sequence[hexapod_planner.MoveProblem], trajectories: Sequence) -> list[Check]:
    """The planner checks of one run from the trajectory planned for each of its moves.

    Each trajectory (channels STRUT_LABELS, strut length changes in m, from t = 0) is sampled
    at its control ticks 0, dt, ... up to its duration (``planbench.planners.trajectory.control_ticks``,
    as a run samples it); its arrivals are ``planbench.hexapod.arrival_times`` of that sample, its
    peaks those of the samples, its pose the forward kinematics of every tick. This is what
    ``judge_plans`` computes for the paper's generator, without its shortcuts, for any
    planner's trajectories (and a hand-made bad one).

    Args:
      moves: the run's ``MoveProblem``s (``planbench.hexapod.problems``).
      trajectories: what the planner returned for each.
    """
    if len(moves) != len(trajectories) or not moves:
        raise ValueError(f"{len(moves)} moves and {len(trajectories)} trajectories: give one per move")
    m = {k: np.zeros(len(moves)) for k in _KEYS}
    not_resting = None
    for i, (problem, trajectory) in enumerate(zip(moves, trajectories, strict=True)):
        t = control_ticks(float(trajectory.duration), problem.dt)
        ref = trajectory.sample(t)
        position = np.asarray(ref.position, dtype=float)
        start = hexapod_planner.strut_positions(problem.start_pose)
        target = hexapod_planner.strut_positions(problem.target_pose)
        tolerance, moving = strut_tolerances(start, target)
        arrivals = arrival_times(ref, target, tolerance, problem.dt)
        if not_resting is None and np.isnan(arrivals).any():
            not_resting = i
        own = hexapod_planner.own_move_times(problem)
        # Forward kinematics of every tick, linearized at the nearer end of the move.
        near_target = (np.abs(position - target).max(axis=1) < np.abs(position - start).max(axis=1))[:, None]
        anchor = np.where(near_target, problem.target_pose, problem.start_pose)
        jinv = _inverse_jacobians(anchor)
        guess = anchor + np.einsum("nij,nj->ni", jinv, position - np.where(near_target, target, start))
        poses, residual = poses_of_lengths(position + RUBIN_CAMERA.nominal_lengths, guess, jinv)
        ok = bool(np.all(residual <= FK_TOLERANCE_M))
        u = np.abs(pose_ratio(poses))
        tick, axis = np.unravel_index(int(np.argmax(u)), u.shape)
        speed, stroke = np.abs(ref.velocity).max(axis=0), np.abs(position).max(axis=0)
        hex_speed = hexapod_planner.hexapod_speed_ratios(poses, ref.velocity).max(axis=0)
        m["spread"][i] = arrivals[moving].max() - arrivals[moving].min() if moving.any() else 0.0
        m["late"][i] = (arrivals - own)[moving].max() if moving.any() else 0.0
        m["speed"][i], m["speed_strut"][i] = speed.max(), speed.argmax()
        m["accel"][i] = np.abs(ref.acceleration).max()
        m["stroke"][i], m["stroke_strut"][i] = stroke.max(), stroke.argmax()
        m["ratio"][i] = u[tick, axis] if ok else np.nan
        m["ratio_axis"][i], m["ratio_value"][i], m["ratio_time"][i] = axis, poses[tick, axis], t[tick]
        m["end_error"][i] = pivot_error_um(poses[-1:], np.asarray(problem.target_pose)[None])[0] if ok else np.nan
        for k, key in enumerate(_HEX_KEYS):
            m[key][i] = hex_speed[k] if ok else np.nan
    synchronous = np.array([p.synchronous for p in moves], dtype=bool)
    checks = _run_checks(m, synchronous, 0, len(moves))
    if not_resting is not None:
        # As in a run: arrivals exist only where the planned motion comes to rest on its target.
        reason = (
            "the planned move"
            + (f" {not_resting}" if len(moves) > 1 else "")
            + " does not come to rest on its target at its end (arrival_times' tolerance)"
        )
        checks = [
            Check.not_evaluated(c.name, c.limit, c.unit, reason=reason)
            if c.name in ("arrival_spread", "arrival_vs_own_time")
            else c
            for c in checks
        ]
    return checks
