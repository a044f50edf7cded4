"""Planner-only campaigns of the hexapod as columns: a chunk of runs validated and judged on
arrays (planbench.campaign's columnar path, README "Campaigns").

A campaign's runs differ in their axes only. Where every axis is a component of the start
pose or of a move's target, or a move's ``synchronous`` (``supports``), the runs of a chunk
are arrays: ``validate`` applies ``HexapodParams``' checks to all of them at once, in the
order ``HexapodParams.from_mapping`` applies them, and gives the same message for the
common failure (a strut beyond its stroke at a move's target or at the start pose); a run
with any rarer finding (a value outside its declared range or the pose limits, a move of
zero length) is marked ``unsure`` and validated by ``from_mapping`` itself (the campaign's
worker does that). ``judge`` gives the checks of ``planbench.hexapod.plan_checks.judge_plans`` as
columns: the same per-move quantities (``judge_moves``) and, for runs of one move, the
same values, limits and verdicts computed on arrays; runs of several moves go through
``checks_of_runs``.
"""

from __future__ import annotations

import numpy as np

from planbench.hexapod import plan_checks
from planbench.hexapod.params import HexapodMove, HexapodParams, pose_si
from planbench.hexapod.task import ARRIVAL_SPREAD_LIMIT_S, OWN_TIME_LIMIT_S, POSE_FINAL_LIMIT_UM
from planbench.params import _bound
from planbench.planners import hexapod as hexapod_planner
from planbench.planners.hexapod import RUBIN_LIMITS


def supports(base: HexapodParams, paths) -> bool:
    """Whether runs that differ from ``base`` in the axes ``paths`` (parsed keys, as
    ``planbench.campaign.spec.parse_path`` gives) can be validated and judged as columns."""
    moves = len(base.moves)
    for path in paths:
        if len(path) == 2 and path[0] == "start_pose" and isinstance(path[1], int) and path[1] < 6:
            continue
        if path[0] == "moves" and len(path) >= 3 and isinstance(path[1], int) and path[1] < moves:
            if len(path) == 4 and path[2] == "target" and isinstance(path[3], int) and path[3] < 6:
                continue
            if len(path) == 3 and path[2] == "synchronous":
                continue
        return False
    return True


def _outside_range(values: np.ndarray, declared) -> np.ndarray:
    """(n,) whether any component of (n, 6) ``values`` is outside its declared range."""
    out = np.zeros(values.shape[0], dtype=bool)
    for column in range(values.shape[1]):
        low, high = _bound(declared.low, column), _bound(declared.high, column)
        v = values[:, column]
        if low is not None:
            out |= (v <= low) if declared.low_open else (v < low)
        if high is not None:
            out |= (v >= high) if declared.high_open else (v > high)
    return out


def _outside_pose_limits(si: np.ndarray) -> np.ndarray:
    limits = RUBIN_LIMITS
    return ((si < limits.pose_lower - 1e-15) | (si > limits.pose_upper + 1e-15)).any(axis=-1)


def poses_of(base: HexapodParams, paths, values, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(start (n, 6), targets (n, M, 6) in mm and deg, synchronous (n, M)) of the runs."""
    start = np.tile(np.asarray(base.start_pose, dtype=float), (n, 1))
    targets = np.tile(np.asarray([m.target for m in base.moves], dtype=float), (n, 1, 1))
    synchronous = np.tile(np.asarray([m.synchronous for m in base.moves], dtype=bool), (n, 1))
    for path, column in zip(paths, values, strict=True):
        column = np.asarray(column)
        if path[0] == "start_pose":
            start[:, path[1]] = column
        elif path[2] == "target":
            targets[:, path[1], path[3]] = column
        else:
            synchronous[:, path[1]] = column
    return start, targets, synchronous


def validate(base: HexapodParams, paths, values, n: int):
    """(messages, unsure, poses) of ``n`` runs, ``values`` one array per axis of ``paths``.

    ``messages[i]`` is the ParamError text ``HexapodParams.from_mapping`` gives run i (None:
    valid), for runs that are not ``unsure[i]``; an unsure run must be validated one at a
    time. ``poses`` = (start, targets (n, M, 6) SI, synchronous (n, M)) for ``judge``.
    """
    start_mm, targets_mm, synchronous = poses_of(base, paths, values, n)
    moves = targets_mm.shape[1]
    start, targets = pose_si(start_mm), pose_si(targets_mm)
    unsure = _outside_range(start_mm, HexapodParams.__dataclass_fields__["start_pose"].metadata["declared"])
    target_declared = HexapodMove.__dataclass_fields__["target"].metadata["declared"]
    for k in range(moves):
        unsure |= _outside_range(targets_mm[:, k], target_declared)
    unsure |= _outside_pose_limits(start) | _outside_pose_limits(targets).any(axis=1)
    # The strut positions of each pose (computed row by row, as one pose at a time gives them).
    struts = hexapod_planner.strut_positions(np.concatenate([start[:, None], targets], axis=1).reshape(-1, 6))
    struts = struts.reshape(n, moves + 1, 6)
    beyond = hexapod_planner.beyond_stroke(struts).any(axis=2)  # (n, M + 1)
    # A move of zero length (no strut changes) is rare: the run is validated on its own.
    unsure |= (struts[:, 1:] == struts[:, :-1]).all(axis=2).any(axis=1)
    messages = [None] * n
    # from_mapping's order: each move's target (converting ``moves``), then the start pose
    # (``HexapodParams.check``).
    order = [(k + 1, f"moves[{k}].target") for k in range(moves)] + [(0, "start_pose")]
    decided = unsure.copy()
    for column, what in order:
        rows = np.flatnonzero(beyond[:, column] & ~decided)
        if rows.size:
            texts = hexapod_planner.stroke_messages(struts[rows, column], what)
            for row, text in zip(rows.tolist(), texts, strict=True):
                messages[row] = text
            decided[rows] = True
    return messages, unsure, (start, targets, synchronous)


_SINGLE = (
    ("strut_velocity", "speed", 1e6, 1e6 * RUBIN_LIMITS.strut_speed, "um/s"),
    ("strut_accel", "accel", 1e6, 1e6 * RUBIN_LIMITS.strut_accel, "um/s2"),
    ("hexapod_speed", None, None, 1.0, "ratio"),
    ("plan_stroke", "stroke", 1e3, 1e3 * RUBIN_LIMITS.stroke, "mm"),
    ("pose_limits", "ratio", None, 1.0, "ratio"),
    ("plan_pose_error_final", "end_error", None, POSE_FINAL_LIMIT_UM, "um"),
)


def judge(poses) -> list[tuple]:
    """The checks of ``judge_plans`` of the runs ``poses`` (``validate``'s, of the valid runs)
    as columns: [(name, unit, comparison, limit, values (n,), present (n,), passed (n,))] in
    the order the runs' check lists have them (a check a run lacks: not present)."""
    start, targets, synchronous = poses
    n, moves = targets.shape[0], targets.shape[1]
    if n == 0:
        return []
    starts = np.concatenate([start[:, None], targets[:, :-1]], axis=1).reshape(-1, 6)
    flat_sync = synchronous.reshape(-1)
    per_move, refused = plan_checks.judge_moves(starts, targets.reshape(-1, 6), flat_sync)
    if moves > 1:
        return _columns_of_checks(plan_checks.checks_of_runs(per_move, refused, flat_sync, np.arange(n + 1) * moves))
    # One move per run: _run_checks' values on arrays (a refused move's quantities are NaN,
    # as are the checks _refused_checks gives it).
    out = [
        ("arrival_spread", "s", "<=", ARRIVAL_SPREAD_LIMIT_S, per_move["spread"], flat_sync),
        ("arrival_vs_own_time", "s", "<=", OWN_TIME_LIMIT_S, per_move["late"], ~flat_sync),
    ]
    for name, key, scale, limit, unit in _SINGLE:
        if key is None:
            value = np.max(np.stack([per_move[k] for k in plan_checks._HEX_KEYS], axis=1), axis=1)
        else:
            value = per_move[key] * scale if scale is not None else per_move[key]
        out.append((name, unit, "<=", float(limit), value, np.ones(n, dtype=bool)))
    # The order the checks first appear in the runs' lists: the first run's arrival check,
    # the others, then the other arrival check (of a later run of the other mode).
    if not flat_sync[0]:
        out[0], out[1] = out[1], out[0]
    out = [out[0], *out[2:], out[1]]
    return [
        (name, unit, comparison, limit, value, present, value <= limit)
        for name, unit, comparison, limit, value, present in out
        if present.any()
    ]


def _columns_of_checks(checks: list[list]) -> list[tuple]:
    n = len(checks)
    names: dict = {}
    for run in checks:
        for c in run:
            names.setdefault(c.name, (c.unit, c.comparison))
    out = []
    for name, (unit, comparison) in names.items():
        value, limit = np.full(n, np.nan), np.full(n, np.nan)
        present, passed = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
        for i, run in enumerate(checks):
            for c in run:
                if c.name == name:
                    value[i], limit[i], present[i], passed[i] = float(c.value), float(c.limit), True, c.passed
        out.append((name, unit, comparison, limit, value, present, passed))
    return out
