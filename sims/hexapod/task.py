"""The hexapod's task: the moves (``problems``, ``plan_moves``), the wind on the camera, the
evaluation (``HexapodEvaluation``: checks, metrics, timeseries), ``build`` (a run's
``planbench.runner.Setup``) and the dm_control reward.
"""

from __future__ import annotations

import math

import numpy as np

from planbench import run_limits
from planbench.checks import Check
from planbench.controllers import demanded_force
from planbench.envs import joint_tracking_reward
from planbench.hexapod.controller import HexapodController
from planbench.hexapod.params import CONTROL_DT, SETTLE_S, HexapodParams, HexapodPlant, pose_si
from planbench.hexapod.physics import HexapodPhysics, magnified_qpos
from planbench.hexapod.sensors import sensors
from planbench.planners import hexapod as hexapod_planner
from planbench.planners.errors import PlanningError
from planbench.planners.hexapod import RUBIN_CAMERA, RUBIN_LIMITS, STRUT_LABELS
from planbench.planners.trajectory import PiecewiseTrajectory, TrajectorySample
from planbench.runner import RunLog, Setup
from planbench.task import Components, Output, Provenance, Task, nominal_copy, plan_checked
from planbench.wind import BodyWindDrag, horizontal_direction

SETTLE_WINDOW_S = 0.25  # s: pose_error_final is the worst over the run's last 0.25 s

#: Check limits (REFERENCE.md, "Rubin hexapod"): following error up to 40 um during a move,
#: ~1 um at its end.
FOLLOWING_LIMIT_UM = 40.0
POSE_FINAL_LIMIT_UM = 1.0
#: Synchronous moves end within one tick.
ARRIVAL_SPREAD_LIMIT_S = CONTROL_DT
#: Asynchronous moves: each strut ends no later than two ticks after its minimum time.
OWN_TIME_LIMIT_S = 2 * CONTROL_DT

#: Rest and arrival (README.md, "How the hexapod is judged"). Rubin's strut encoders count
#: 0.1 um (10 counts/um, ts_mthexapod). A strut whose commanded length changes by less than
#: STRUT_MOVE_THRESHOLD_M (1/100 of a count) is idle in the arrival checks; a strut has
#: arrived from the first tick after which its commanded position stays within its tolerance
#: of its target and its commanded speed within the tolerance per tick: 1e-9 of its move
#: (at most 28 pm, 1/3500 of a count, on the longest move the stroke allows), at least
#: ARRIVAL_ULPS units in the last place of its position (a planner's own round-off).
ENCODER_COUNT_M = 0.1e-6
STRUT_MOVE_THRESHOLD_M = 1e-2 * ENCODER_COUNT_M
ARRIVAL_TOLERANCE = 1e-9
ARRIVAL_ULPS = 4
#: The measured struts have settled once every encoder stays within this of its target, m
#: (the 1 um end-of-move limit, per strut): reported per move, ``encoder_settle_s``.
ENCODER_SETTLE_M = 1e-6

#: Drag of the camera (a cylinder, 1.65 m x 3 m): Cd = 1.0 for a circular cylinder in cross
#: flow (subcritical, ~1.0-1.2), applied to its silhouette across the wind (README.md).
CAMERA_DRAG_COEFFICIENT = 1.0
#: The wind blows toward world +x, across the elevation axis's normal plane, so the camera
#: shows its full side (D x L) at every elevation: the worst case.
WIND_AZIMUTH_DEG = 0.0
#: The moves are millimetres on a 6 m assembly: the video shows the platform's motion (pose
#: change from the start) magnified this many times, like a deformation plot.
VIDEO_MAGNIFICATION = 100.0


# ----------------------------------------------------------------------------- evaluation


def hexapod_speed_check(peaks, what: str) -> Check:
    """hexapod_speed from the peak ratios (4,) of the radial, axial, radial-angular and
    axial-angular pose speeds to Rubin's hexapod-space limits (``hexapod_speed_ratios``)."""
    peaks = np.asarray(peaks, dtype=float)
    worst = int(np.argmax(peaks))
    names = hexapod_planner.HEXAPOD_SPEED_LABELS
    return Check(
        "hexapod_speed",
        float(peaks[worst]),
        1.0,
        "ratio",
        note=f"{what} pose speed over the hexapod-space limit, peak of each: "
        + ", ".join(f"{n} {v:.3f}" for n, v in zip(names, peaks, strict=True))
        + f" (worst {names[worst]})",
    )


def strut_tolerances(start, target) -> tuple[np.ndarray, np.ndarray]:
    """(tolerance (..., 6) m, moving (..., 6) bool) of the struts of moves from ``start`` to
    ``target`` (strut positions, m): a moving strut's tolerance is ARRIVAL_TOLERANCE of its
    move, at least ARRIVAL_ULPS ulps of its position; an idle strut's (a move of at most
    STRUT_MOVE_THRESHOLD_M) is that threshold."""
    start, target = np.asarray(start, dtype=float), np.asarray(target, dtype=float)
    distance = np.abs(target - start)
    moving = distance > STRUT_MOVE_THRESHOLD_M
    round_off = ARRIVAL_ULPS * np.spacing(np.maximum(np.abs(start), np.abs(target)))
    tolerance = np.where(moving, np.maximum(ARRIVAL_TOLERANCE * distance, round_off), STRUT_MOVE_THRESHOLD_M)
    return tolerance, moving


def arrival_times(reference: TrajectorySample, target, tolerance, dt: float) -> np.ndarray:
    """(6,) each strut's arrival in the sample's times, s: the first sample after which its
    position stays within ``tolerance`` (m, per strut) of ``target`` and its speed within
    ``tolerance / dt``; NaN for a strut not at rest on its target at the last sample."""
    off = (np.abs(reference.position - target) > tolerance) | (np.abs(reference.velocity) * dt > tolerance)
    n = off.shape[0]
    last_off = np.where(off.any(axis=0), n - 1 - np.argmax(off[::-1], axis=0), -1)
    index = np.minimum(last_off + 1, n - 1)
    return np.where(last_off < n - 1, reference.t[index], np.nan)


class HexapodEvaluation:
    """Checks and outputs of a hexapod run: one move, or a list of moves one after another.

    Everything is counted in control ticks (log row k is tick k). Move i starts on tick
    ``start_ticks[i]`` (``plan_moves``). Its arrival is judged on the ticks from there to the
    tick before the next move's start (the last move's: to the run's end): each strut's
    commanded position must come to rest on the target within its tolerance
    (``strut_tolerances``, ``arrival_times``). Its following error is judged from its start
    to its last strut's arrival; its pose error over the SETTLE_WINDOW_S up to the next
    move's start tick (at that tick the next move has not acted yet; the last move's: the
    run's end), once SETTLE_S have passed after the arrival. A check reports the worst move.
    """

    def __init__(self, physics: HexapodPhysics, moves, starts, durations, wind: BodyWindDrag | None):
        self.physics = physics
        self.moves = list(moves)
        self.starts = np.asarray(starts, dtype=float)
        self.start_ticks = np.rint(self.starts / CONTROL_DT).astype(np.int64)
        self.planned = np.asarray(durations, dtype=float)  # of each trajectory the planner returned
        self.wind = wind
        self.own_times = [hexapod_planner.own_move_times(m) for m in self.moves]
        self.strut_starts = [hexapod_planner.strut_positions(np.asarray(m.start_pose, dtype=float)) for m in self.moves]
        self.strut_targets = [
            hexapod_planner.strut_positions(np.asarray(m.target_pose, dtype=float)) for m in self.moves
        ]

    def _demanded(self, log: RunLog) -> np.ndarray:
        """(n, 6) the drives' demanded forces, N: their loops on the coordinate they read (the
        motor's as built), before the force clamp."""
        p = self.physics
        return demanded_force(
            p.kp, p.kv, log.act[:, p.strut_act], p.drive_positions(log.qpos[:, p.drive_qpos]), log.qvel[:, p.drive_dofs]
        )

    def _strut_log(self, log: RunLog):
        p = self.physics
        return log.qpos[:, p.strut_qpos], log.qvel[:, p.strut_dofs]

    def closure_mismatch(self, log: RunLog) -> np.ndarray:
        """(n,) largest |pivot-to-pivot length - (nominal + encoder)|, m: the compliance of
        MuJoCo's soft loop constraints (sensors of one physics step, so they agree)."""
        model = self.physics.model.ptr
        length = np.column_stack([log.sensordata[:, model.sensor(f"{n}_length").adr[0]] for n in STRUT_LABELS])
        encoder = np.column_stack([log.sensordata[:, model.sensor(f"{n}_encoder").adr[0]] for n in STRUT_LABELS])
        return np.abs(length - RUBIN_CAMERA.nominal_lengths - encoder).max(axis=1)

    def pivot_errors_um(self, log: RunLog, target_pose) -> np.ndarray:
        """(n,) largest displacement of the six mirror-side pivots from the target pose, um."""
        poses = self.physics.poses_from_qpos(log.qpos)
        actual = hexapod_planner.pivot_positions(poses)
        wanted = hexapod_planner.pivot_positions(np.asarray(target_pose))
        return 1e6 * np.linalg.norm(actual - wanted, axis=-1).max(axis=-1)

    def move_index(self, n: int) -> np.ndarray:
        """(n,) the move each of the ticks 0 ... n - 1 belongs to (from its start tick on)."""
        return np.searchsorted(self.start_ticks, np.arange(n), side="right") - 1

    def targets(self, n: int) -> np.ndarray:
        """(n, 6) the target pose of the move each of the ticks 0 ... n - 1 belongs to."""
        return np.array([m.target_pose for m in self.moves])[self.move_index(n)]

    def _not_arrived_reason(self, log: RunLog, i: int, arrivals: np.ndarray, end: int) -> str:
        several = len(self.moves) > 1
        which = f" of move {i}" if several else ""
        planned_end = self.starts[i] + self.planned[i]
        if end == log.t.size and log.t[-1] < planned_end - 1e-9:
            return (
                f"the run ended at t = {log.t[-1]:.3f} s, before the commanded motion{which} "
                f"(planned to t = {planned_end:.3f} s) came to rest"
            )
        ref = log.reference
        strut = int(np.flatnonzero(np.isnan(arrivals))[0])
        off = ref.position[end - 1, strut] - self.strut_targets[i][strut]
        return (
            f"the commanded motion{which} does not come to rest on its target by t = {log.t[end - 1]:.3f} s: "
            f"{STRUT_LABELS[strut]} {off:.3g} m off at {ref.velocity[end - 1, strut]:.3g} m/s"
        )

    def _judge_move(self, log: RunLog, i: int, q, poses) -> dict:
        """One move's arrival, following error and settled pose error (class docstring)."""
        n = log.t.size
        lo = int(self.start_ticks[i])
        nxt = int(self.start_ticks[i + 1]) if i + 1 < len(self.moves) else n
        end = min(nxt, n)  # arrival ticks lo ... end - 1
        last = min(nxt, n - 1)  # the pose's settling window ends on this tick
        settle_ticks = end_tick(SETTLE_S)
        if lo >= n:  # the run ended before this move began
            return {
                "arrived": False,
                "ended": False,
                "arrivals": np.full(6, np.nan),
                "spread": 0.0,
                "late": 0.0,
                "move_end": self.planned[i],
                "during": np.arange(0),
                "following": np.zeros(6),
                "pose_error": float("nan"),
                "encoder_settle": None,
                "settled_at": self.starts[i] + self.planned[i] + SETTLE_S,
                "reason": f"the run ended at t = {log.t[-1]:.3f} s, before move {i} began (t = {self.starts[i]:.3f} s)",
            }
        ref = log.reference
        rows = np.arange(lo, end)
        local = TrajectorySample(
            (rows - lo) * CONTROL_DT, ref.position[rows], ref.velocity[rows], ref.acceleration[rows]
        )
        target = self.strut_targets[i]
        tolerance, moving = strut_tolerances(self.strut_starts[i], target)
        arrivals = arrival_times(local, target, tolerance, CONTROL_DT)
        arrived = bool(np.all(np.isfinite(arrivals)))
        own = self.own_times[i]
        if arrived:
            arrival_tick = int(np.rint(arrivals.max() / CONTROL_DT))
            spread = float(arrivals[moving].max() - arrivals[moving].min()) if moving.any() else 0.0
            late = float((arrivals - own)[moving].max()) if moving.any() else 0.0
        else:
            arrival_tick, spread, late = end - lo - 1, 0.0, 0.0
        move_end = arrival_tick * CONTROL_DT
        during = rows[: arrival_tick + 1]
        settled = np.arange(max(lo, last - end_tick(SETTLE_WINDOW_S)), last + 1)
        # Against this move's own target (the window's last tick is the next move's first).
        wanted = hexapod_planner.pivot_positions(np.asarray(self.moves[i].target_pose))
        pivots = 1e6 * np.linalg.norm(hexapod_planner.pivot_positions(poses[settled]) - wanted, axis=-1).max(axis=-1)
        # The measured struts: from the arrival on, when every encoder (what the drives read,
        # with the plant's bias) stays within ENCODER_SETTLE_M of its target.
        encoder_settle = None
        if arrived:
            after = np.arange(lo + arrival_tick, last + 1)
            off = (np.abs(self.physics.drive_positions(q[after]) - target) > ENCODER_SETTLE_M).any(axis=1)
            if not off[-1]:
                encoder_settle = float((np.flatnonzero(off)[-1] + 1 if off.any() else 0) * CONTROL_DT)
        return {
            "arrived": arrived,
            "ended": arrived and last - lo >= arrival_tick + settle_ticks,
            "arrivals": arrivals,
            "spread": spread,
            "late": late,
            "move_end": move_end,
            "during": during,
            "following": 1e6 * np.abs(q - ref.position)[during].max(axis=0) if during.size else np.zeros(6),
            "pose_error": float(pivots.max()),
            "encoder_settle": encoder_settle,
            "settled_at": (lo + arrival_tick + settle_ticks) * CONTROL_DT,
            "reason": None if arrived else self._not_arrived_reason(log, i, arrivals, end),
        }

    def evaluate(self, log: RunLog):
        p = self.physics
        ref = log.reference
        q, qd = self._strut_log(log)
        limits = RUBIN_LIMITS
        poses = p.poses_from_qpos(log.qpos)
        judged = [self._judge_move(log, i, q, poses) for i in range(len(self.moves))]
        several = len(self.moves) > 1
        demanded = self._demanded(log)
        force = np.abs(demanded).max()
        stroke = np.abs(q).max()
        v_cmd = np.abs(ref.velocity).max()
        a_cmd = np.abs(ref.acceleration).max()
        checks = []

        def per_move(key, fmt=".3g"):
            return "; per move " + ", ".join(f"{j[key]:{fmt}}" for j in judged) if several else ""

        # Arrivals exist only where the commanded motion of every move comes to rest on its
        # target inside its window (a short run's last tick would pass for every arrival);
        # the settling window only comes after them.
        late_move = next((i for i, j in enumerate(judged) if not j["arrived"]), None)
        arrived = late_move is None
        short = "" if arrived else judged[late_move]["reason"]
        sync = [i for i, m in enumerate(self.moves) if m.synchronous]
        asyn = [i for i, m in enumerate(self.moves) if not m.synchronous]
        if sync:
            checks.append(
                Check(
                    "arrival_spread",
                    max(judged[i]["spread"] for i in sync),
                    ARRIVAL_SPREAD_LIMIT_S,
                    "s",
                    note="last minus first strut arrival of the commanded motion" + per_move("spread"),
                )
                if arrived
                else Check.not_evaluated("arrival_spread", ARRIVAL_SPREAD_LIMIT_S, "s", reason=short)
            )
        if asyn:
            spread_text = ", ".join(f"{judged[i]['spread']:.3f}" for i in asyn)
            checks.append(
                Check(
                    "arrival_vs_own_time",
                    max(judged[i]["late"] for i in asyn),
                    OWN_TIME_LIMIT_S,
                    "s",
                    note=f"each strut's arrival minus its minimum time 2 max(t_i, t'_min) (early is "
                    f"negative); arrival spread {spread_text} s",
                )
                if arrived
                else Check.not_evaluated("arrival_vs_own_time", OWN_TIME_LIMIT_S, "s", reason=short)
            )
        ended_all = all(j["ended"] for j in judged)
        unsettled = next((i for i, j in enumerate(judged) if not j["ended"]), len(judged) - 1)
        settled_at = judged[unsettled]["settled_at"]
        last = judged[-1]
        move_end = last["move_end"]
        following = max(float(j["following"].max()) for j in judged)
        checks += [
            Check(
                "strut_velocity",
                1e6 * v_cmd,
                1e6 * limits.strut_speed,
                "um/s",
                note=f"commanded; measured peak {1e6 * np.abs(qd).max():.1f} um/s",
            ),
            Check(
                "strut_accel",
                1e6 * a_cmd,
                1e6 * limits.strut_accel,
                "um/s2",
                note="commanded by the generator, per tick",
            ),
            self._hexapod_speed(ref, poses),
            Check(
                "following_error",
                following,
                FOLLOWING_LIMIT_UM,
                "um",
                note=(
                    f"encoder minus reference, t <= {move_end:.3f} s"
                    if not several
                    else "encoder minus reference during each move" + per_move("move_end", fmt=".3f") + " s"
                ),
            ),
            Check(
                "pose_error_final",
                max(j["pose_error"] for j in judged),
                POSE_FINAL_LIMIT_UM,
                "um",
                note=(
                    f"largest mirror-side pivot displacement over the last {SETTLE_WINDOW_S} s"
                    + (" before each next move and of the run" + per_move("pose_error") if several else "")
                ),
            )
            if ended_all
            else Check.not_evaluated(
                "pose_error_final",
                POSE_FINAL_LIMIT_UM,
                "um",
                reason=f"the run ended at t = {log.t[-1]:.3f} s, before the move"
                + (f" {unsettled}" if several else "")
                + " plus "
                f"{SETTLE_S:g} s of settling (t = {settled_at:.3f} s)",
            ),
            Check(
                "strut_force",
                float(force),
                float(p.force_limit.min()),
                "N",
                note=f"demanded, peak on {STRUT_LABELS[int(np.argmax(np.abs(demanded).max(0)))]}",
            ),
            Check("stroke", 1e3 * float(stroke), 1e3 * limits.stroke, "mm"),
        ]
        final_pose = poses[-1]
        pose_diff = final_pose - np.asarray(self.moves[-1].target_pose)
        arrivals, during = last["arrivals"], last["during"]
        window = log.t >= log.t[-1] - SETTLE_WINDOW_S - 1e-9
        metrics = {
            "elevation_deg": p.elevation_deg,
            "move_duration_s": move_end,
            "arrival_times_s": dict(
                zip(STRUT_LABELS, [None if np.isnan(a) else a for a in arrivals.round(4).tolist()], strict=True)
            ),
            "arrival_spread_s": last["spread"],
            "final_translation_error_um": (1e6 * pose_diff[:3]).round(4).tolist(),
            "final_rotation_error_urad": (1e6 * pose_diff[3:]).round(4).tolist(),
            "following_error_um_per_strut": dict(
                zip(
                    STRUT_LABELS,
                    (1e6 * np.abs(q - ref.position)[during].max(0)).round(3).tolist() if during.size else [0.0] * 6,
                    strict=True,
                )
            ),
            "peak_drive_force_N": dict(zip(STRUT_LABELS, np.abs(demanded).max(0).round(1).tolist(), strict=True)),
            "static_drive_force_start_N": dict(zip(STRUT_LABELS, demanded[0].round(1).tolist(), strict=True)),
            "encoder_settle_s": last["encoder_settle"],
            "measured_peak_strut_speed_um_s": float(1e6 * np.abs(qd).max()),
            "loop_closure_um": float(1e6 * self.closure_mismatch(log)[window].max()),
        }
        if several:
            metrics["moves"] = [
                {
                    "start_s": float(self.starts[i]),
                    "synchronous": bool(m.synchronous),
                    "target_pose_mm_deg": [
                        *(1e3 * m.target_pose[:3]).round(6).tolist(),
                        *np.degrees(m.target_pose[3:]).round(6).tolist(),
                    ],
                    "arrived": j["arrived"],
                    "move_duration_s": j["move_end"],
                    "arrival_spread_s": j["spread"],
                    "arrival_vs_own_time_s": None if m.synchronous else j["late"],
                    "following_error_um": float(j["following"].max()),
                    "pose_error_um": j["pose_error"] if j["ended"] else None,
                    "encoder_settle_s": j["encoder_settle"],
                }
                for i, (m, j) in enumerate(zip(self.moves, judged, strict=True))
            ]
        if self.wind is not None and self.wind.speed is not None:
            n = log.t.size
            metrics["wind_mean_m_s"] = self.wind.mean_speed
            metrics["wind_speed_std_m_s"] = float(np.std(self.wind.speed[:n]))
            metrics["wind_force_peak_N"] = float(np.linalg.norm(self.wind.force[:n], axis=1).max())
        return checks, metrics

    def _hexapod_speed(self, ref: TrajectorySample, poses: np.ndarray) -> Check:
        """The commanded pose's peak hexapod-space speeds against Rubin's (``HEXAPOD_SPEED``):
        the pose of the commanded struts by forward kinematics (from the measured pose), its
        rate from the commanded strut speeds (``hexapod_speed_ratios``)."""
        try:
            commanded, _ = hexapod_planner.forward_kinematics(
                ref.position + RUBIN_CAMERA.nominal_lengths, initial=poses, tolerance=1e-12
            )
        except PlanningError as e:
            return Check.not_evaluated("hexapod_speed", 1.0, "ratio", reason=f"the commanded pose: {e}")
        return hexapod_speed_check(
            hexapod_planner.hexapod_speed_ratios(commanded, ref.velocity).max(axis=0), "commanded"
        )

    def timeseries(self, log: RunLog) -> dict:
        p = self.physics
        q, qd = self._strut_log(log)
        out = {
            "strut_names": np.array(STRUT_LABELS),
            "strut_position_planned": log.reference.position,
            "strut_velocity_planned": log.reference.velocity,
            "strut_accel_planned": log.reference.acceleration,
            "strut_position_actual": q,
            "strut_velocity_actual": qd,
            "setpoint": log.act[:, p.strut_act],
            "drive_force": log.actuator_force[:, p.strut_actuators],
            "drive_force_demanded": self._demanded(log),
            "drive_force_limit": p.force_limit,
            "pose_actual": p.poses_from_qpos(log.qpos),
            "target_pose": (
                np.asarray(self.moves[0].target_pose)
                if len(self.moves) == 1
                else np.array([m.target_pose for m in self.moves])
            ),
            "move_start": self.starts,
            "pivot_error_um": self._pivot_errors_per_move(log),
        }
        if self.wind is not None and self.wind.speed is not None:
            out["wind_speed"] = self.wind.speed[: log.t.size]
            out["wind_force"] = self.wind.force[: log.t.size]
        return out

    def _pivot_errors_per_move(self, log: RunLog) -> np.ndarray:
        if len(self.moves) == 1:
            return self.pivot_errors_um(log, self.moves[0].target_pose)
        poses = self.physics.poses_from_qpos(log.qpos)
        wanted = hexapod_planner.pivot_positions(self.targets(log.t.size))
        return 1e6 * np.linalg.norm(hexapod_planner.pivot_positions(poses) - wanted, axis=-1).max(axis=-1)

    def report(self, log: RunLog, checks, path) -> None:
        from planbench.hexapod.report import hexapod_report

        hexapod_report(self.timeseries(log), log.t, checks, path)


# ----------------------------------------------------------------------------- scenarios


def camera_area(physics: HexapodPhysics):
    """(physics) -> silhouette of the camera across the wind, m^2; the geom is looked up once."""
    geom = physics.model.ptr.geom("camera_body")
    diameter, length, gid = 2 * geom.size[0], 2 * geom.size[1], geom.id
    dx, dy, _ = horizontal_direction(WIND_AZIMUTH_DEG)
    side, end = diameter * length, np.pi * diameter**2 / 4.0

    def area(physics) -> float:
        # cylinder_projected_area in scalars: the cylinder's z axis is column 2 of its xmat.
        xmat = physics.data.ptr.geom_xmat[gid]
        cos_t = min(abs(xmat[2] * dx + xmat[5] * dy), 1.0)
        return side * math.sqrt(1.0 - cos_t * cos_t) + end * cos_t

    return area


def problems(params: HexapodParams) -> list[hexapod_planner.MoveProblem]:
    """The run's moves, each from the pose the one before reached (the first from the start)."""
    out, pose = [], pose_si(params.start_pose)
    for move in params.moves:
        target = pose_si(move.target)
        out.append(hexapod_planner.MoveProblem(pose, target, move.synchronous))
        pose = target
    return out


def plan_moves(params: HexapodParams, planner=None):
    """(trajectory, moves, starts, durations): every move planned by ``planner`` (default the
    paper's generator), each starting on the first control tick at least ``params.dwell`` s
    after the tick on which the trajectory before it ended (``end_tick``); one move is its
    own trajectory. ``starts`` are those ticks times the control period, s."""
    planner = hexapod_planner.PaperMovePlanner() if planner is None else planner
    moves = problems(params)
    pieces = [plan_checked(planner, move, STRUT_LABELS) for move in moves]
    durations = [piece.duration for piece in pieces]
    ticks = [0]
    for d in durations[:-1]:
        ticks.append(ticks[-1] + end_tick(d) + end_tick(params.dwell))
    starts = np.array(ticks) * CONTROL_DT
    trajectory = pieces[0] if len(pieces) == 1 else PiecewiseTrajectory(pieces, starts)
    return trajectory, moves, starts, durations


def end_tick(duration: float) -> int:
    """The first control tick at or after ``duration`` s (to 1e-9 of a tick)."""
    return int(math.ceil(duration / CONTROL_DT - 1e-9))


def default_duration(starts, durations) -> float:
    """The run's simulated time when none is given, s: to the tick of the last trajectory's
    end plus SETTLE_S, every move's arrival and its settling inside the run."""
    return (int(round(starts[-1] / CONTROL_DT)) + end_tick(durations[-1]) + end_tick(SETTLE_S)) * CONTROL_DT


def plan(params: HexapodParams):
    """The run's moves as the paper's generator plans them (``planbench plan``)."""
    return plan_moves(params)[0]


def build(params: HexapodParams, planner=None, controller=None, plant: HexapodPlant | None = None) -> Setup:
    """A hexapod run of the moves: ``planner`` (default the paper's generator) plans each,
    ``controller`` (default ``HexapodController()``) follows them from the start pose at rest;
    the checks judge every move's arrival and target pose and the limits on the trajectory the
    planner returned.

    ``plant`` (None: the nominal plant) perturbs the simulated machine only: the planner and
    the controller keep the nominal model (``Task.nominal_physics``, at the start pose). The
    plant starts at rest where its encoders read the start pose's strut positions (the
    nominal kinematics'), as a previous move commanded by the same controller would have left
    it: its struts at those minus the encoder bias, its platform wherever its own pivots put
    it. The controller sees only the encoders; the checks judge the platform's true pose.
    """
    plant = HexapodPlant() if plant is None else plant
    plant.check_drives(params.drives)
    trajectory, moves, starts, durations = plan_moves(params, planner)
    duration = params.duration if params.duration is not None else default_duration(starts, durations)
    run_limits.check_duration(duration, CONTROL_DT, params.log_bytes_per_tick())
    physics = HexapodPhysics.load(params.elevation, plant, params.drives)
    start = moves[0].start_pose
    nominal_physics = None  # the nominal plant: a copy of the physics, as it is now
    if plant.is_nominal:
        physics.set_pose(start)
    else:
        readings = hexapod_planner.strut_positions(np.asarray(start, dtype=float))
        physics.set_struts(readings - physics.encoder_bias, guess=start)
        nominal = HexapodPhysics.load(params.elevation, drives=params.drives)
        nominal.set_pose(start)
        nominal_physics = nominal_copy(nominal)
    wind = None
    if params.wind > 0:
        wind = BodyWindDrag("camera", params.wind, camera_area(physics), CAMERA_DRAG_COEFFICIENT, WIND_AZIMUTH_DEG)
    evaluation = HexapodEvaluation(physics, moves, starts, durations, wind)
    return Setup(
        physics,
        Task(
            problem=moves[0] if len(moves) == 1 else tuple(moves),
            sensors=sensors(physics),
            evaluation=evaluation,
            control_dt=CONTROL_DT,
            duration=duration,
            disturbance=wind,
            nominal_physics=nominal_physics,
        ),
        Components(
            planner=planner if planner is not None else hexapod_planner.PaperMovePlanner(),
            trajectory=trajectory,
            controller=controller if controller is not None else HexapodController(),
        ),
        Output(
            video_qpos=magnified_qpos(physics, VIDEO_MAGNIFICATION),
            video_note=f"platform motion magnified {VIDEO_MAGNIFICATION:g}x (pose change from the start)",
        ),
        Provenance(seed=params.seed, params=params, plant=plant),
    )


def strut_kinds() -> list[str]:
    return ["slide"] * 6


def environment_reward(setup: Setup):
    """The dm_control reward: exp(-max strut tracking error / 10 um)."""
    return joint_tracking_reward(setup.task.sensors.qpos, 10e-6)
