"""FAST's problems, plans, evaluation and runs: the sessions (tracking, motion scans, source
switches) planned at the FAST site, their checks and timeseries (``FastEvaluation``), the
perturbed plant's start, the build functions that assemble a run, the scenarios and the
dm_control reward."""

from __future__ import annotations

import json
import math
from pathlib import Path

import mujoco
import numpy as np

from planbench import run_limits
from planbench.checks import Check
from planbench.controllers import demanded_force
from planbench.fast.controller import ControllerOptions, FastController, parked_command, winch_feedforward
from planbench.fast.loads import CableLoads, ChainCableLoads, Winches
from planbench.fast.measurement import FusedSensors, SensorOptions, estimate_errors, make_sensors
from planbench.fast.params import (
    DEC_SCAN,
    RA_SCAN,
    FastParams,
    FastPlant,
    FastScanParams,
    FastSwitchParams,
    FastTrackingParams,
    _radec,
    _start,
    _transit,
)
from planbench.fast.physics import CONTROL_DT, STRING_MODE_HZ, FastPhysics
from planbench.logfile import LoggedSeries, temporary_writer
from planbench.params import ParamError
from planbench.planners import fast
from planbench.planners.errors import LimitError
from planbench.planners.fast import plan as fp
from planbench.planners.fast import sky as sky
from planbench.runner import RunLog, Setup
from planbench.scenarios import BENCHMARK, DEMO, Scenario
from planbench.task import Components, Output, Provenance, Task, nominal_copy, plan_checked
from planbench.wind import MeasuredWind, WindFileError

#: Where the feed waits between observations: 10 m above the focal point of the zenith
#: (inside the focal sphere), so a switch starts with the paper's straight line to P_h.
PARK = np.array([0.0, 0.0, -fast.FOCAL_SURFACE_RADIUS + 10.0])
TRACK_STEP_S = 1.0  # s between sky samples of an observation (a spline joins them)


def source_name(source) -> str:
    if isinstance(source, str):
        return source
    return f"RA {np.degrees(source[0]):.4f} Dec {np.degrees(source[1]):+.4f}"


def _observation(source, start_jd, duration: float, name: str, dut1: float = 0.0):
    ra, dec = _radec(source)
    path = sky.track(ra, dec, start_jd, duration, step=TRACK_STEP_S, dut1=dut1)
    angles = sky.parallactic_angle(path.az, path.el)  # the 19-beam rotation follows it
    return fp.observation_segment(path.t, path.directions(), name=name, angles=angles), path


def tracking_plan(
    duration: float = 1200.0, source="3C 286", start_utc: str | None = None, dut1: float = 0.0
) -> fp.FastPlan:
    """Park -> source (switch), start, ``duration`` s of tracking from ``start_utc`` (default
    centred on the transit), termination. ``source``: a catalogue name or (ra, dec) rad;
    ``dut1``: UT1 - UTC, s."""
    obs, path = _observation(
        source, _start(source, start_utc, duration, dut1), duration, f"observation ({source_name(source)})", dut1
    )
    start, stop = fp.start_segment(obs), fp.termination_segment(obs)
    switch, times = fp.switch_segments(PARK, start.start, multifeed1=fp.start_angle(obs, start))
    return fp.FastPlan(
        switch + [start, obs, stop],
        info={
            "source": source_name(source),
            "observation_start_utc": sky.jd_to_iso(path.jd1[0], path.jd2[0]),
            "switch_times_s": times.__dict__,
        },
    )


def source_switch_plan(
    duration: float = 300.0, sources=("3C 286", "3C 295"), start_utc: str | None = None, dut1: float = 0.0
) -> fp.FastPlan:
    """Park -> the first source, track, stop; then for each next source a switch along the
    focal surface, track, stop. The first observation starts at ``start_utc`` (default the
    first source's transit), each next one when the switch to it ends."""
    if start_utc is None:
        jd1, jd2 = _transit(sources[0], dut1)
    else:
        jd1, jd2 = _start(sources[0], start_utc, duration, dut1)
    obs_a, _ = _observation(sources[0], (jd1, jd2), duration, f"observation ({source_name(sources[0])})", dut1)
    start_a, stop_a = fp.start_segment(obs_a), fp.termination_segment(obs_a)
    switch_a, times_a = fp.switch_segments(PARK, start_a.start, multifeed1=fp.start_angle(obs_a, start_a))
    segments, all_times = switch_a + [start_a, obs_a, stop_a], [times_a.__dict__]
    t_end = duration + stop_a.duration  # of the last observation's stop, from the first's start
    for source in sources[1:]:
        # The next observation starts when the last ends plus the switch; plan the switch
        # toward a first guess of the target, then re-plan it for the actual start point.
        p0 = stop_a.evaluate(np.array([stop_a.duration]))[0][0]
        guess = t_end
        for _ in range(3):
            offset = guess + 1.0  # s from the first observation's start
            obs_b, _ = _observation(
                source, (jd1, jd2 + offset / 86400.0), duration, f"observation ({source_name(source)})", dut1
            )
            start_b = fp.start_segment(obs_b)
            switch_b, times_b = fp.switch_segments(
                p0, start_b.start, multifeed0=fp.end_angle(obs_a, stop_a), multifeed1=fp.start_angle(obs_b, start_b)
            )
            guess = t_end + sum(s.duration for s in switch_b) + start_b.duration
        stop_b = fp.termination_segment(obs_b)
        segments += switch_b + [start_b, obs_b, stop_b]
        all_times.append(times_b.__dict__)
        obs_a, stop_a = obs_b, stop_b
        t_end = offset + duration + stop_b.duration
    return fp.FastPlan(segments, info={"sources": [source_name(s) for s in sources], "switch_times_s": all_times})


def observation_plan(duration: float = 60.0, source: str = "3C 286") -> fp.FastPlan:
    """Start, ``duration`` s of tracking centred on the transit, termination: no switch (the
    tests' short runs start on the source)."""
    jd1, jd2 = _transit(source)
    obs, _ = _observation(source, (jd1, jd2 - 0.5 * duration / 86400.0), duration, f"observation ({source})")
    return fp.FastPlan([fp.start_segment(obs), obs, fp.termination_segment(obs)], info={"source": source})


def plan_kinds() -> list[str]:
    return list(fp.PLAN_KINDS)


def write_figures(plan: fp.FastPlan, out_dir) -> None:
    """figures.png (the paper's Figures 16 and 17: the feed's and one cable's velocity and
    acceleration) and segments.json."""
    from planbench.fast.report import fast_plan_figure  # matplotlib: only when figures are written

    t = np.arange(0.0, plan.duration, 0.1)
    fast_plan_figure(plan, t, Path(out_dir) / "figures.png")
    (Path(out_dir) / "segments.json").write_text(
        json.dumps({"segments": plan.segment_table(), "info": plan.info}, indent=1, default=float)
    )


# ----------------------------------------------------------------------------- motion scans


def _scan_factory(spec: dict, source="3C 286"):
    ra, dec = _radec(source)

    def make(t2: float):
        return sky.MotionScan(
            ra,
            dec,
            spec["legs_along"],
            np.radians(spec["leg_deg"]),
            spec["legs"],
            np.radians(spec["spacing_deg"]),
            spec["speed_deg_h"] * sky.DEG_PER_HOUR,
            t2,
        )

    return make


def _leg_state(segment, at_end: bool):
    tau = np.array([segment.duration if at_end else 0.0])
    return tuple(x[0] for x in segment.evaluate(tau))


def scan_plan(spec: dict, source="3C 286", start_utc: str | None = None, dut1: float = 0.0) -> fp.FastPlan:
    """Park -> the raster's start (switch), start, legs with transitions, termination; the
    raster around ``source`` (a catalogue name or (ra, dec) rad), from ``start_utc`` (default
    centred on its transit).

    t2 is the geometric one (the shortest that keeps every transition under A_t-max);
    ``info`` holds it beside the paper's empirical values (eq. 11-14 or 15-20).
    """
    make = _scan_factory(spec, source)
    first = make(60.0)
    start_jd = _start(source, start_utc, first.duration, dut1)
    t2 = fp.minimum_t2(make, start_jd, dut1=dut1)
    scan = make(t2)
    segments, path, peaks = fp.scan_segments(scan, start_jd, dut1=dut1)
    start, stop = fp.start_segment(segments[0]), fp.termination_segment(segments[-1])
    switch, times = fp.switch_segments(PARK, start.start, multifeed1=fp.start_angle(segments[0], start))
    legs = [s for s in segments if s.name.startswith("leg")]
    transitions = [s for s in segments if s.name.startswith("transition")]
    p_end, v_end, _ = _leg_state(legs[0], True)
    p_next, v_next, _ = _leg_state(legs[1], False) if len(legs) > 1 else (p_end, v_end, None)
    speed = spec["speed_deg_h"]
    geometric = {
        "t2_s": t2,
        "V_m_mm_s": 1e3 * float(np.linalg.norm(v_end)),
        "V_m_inv_mm_s": 1e3 * float(np.linalg.norm(v_next)),
        "p_m": float(v_end[1] / v_end[0]) if v_end[0] else float("inf"),
        "transition_peak_accel_mm_s2": [1e3 * p for p in peaks],
    }
    if transitions:
        tr = transitions[0]
        tau = np.linspace(0.0, tr.duration, 400)
        pos, vel, _ = tr.evaluate(tau)
        length = float(np.sum(np.linalg.norm(np.diff(pos, axis=0), axis=1)))
        chord = pos[-1] - pos[0]
        geometric.update(
            {
                "l_2_mm": 1e3 * length,
                "V_c_mm_s": 1e3 * 2 * length / tr.duration,
                "p_c": float(chord[1] / chord[0]) if chord[0] else float("inf"),
            }
        )
    if spec["legs_along"] == "dec":
        paper = fp.paper_ra_scan_fits(speed, t2)
        name = "motion scan along right ascension (legs along Dec), eq. 11-14"
    else:
        paper = fp.paper_dec_scan_t2(speed)
        v_m, v_inv = geometric["V_m_mm_s"], geometric["V_m_inv_mm_s"]
        geometric["t3_s"] = 2 * v_m / (fast.A_MAX * 1e3) + 2 * v_inv / (fast.A_MAX * 1e3)
        name = "motion scan along declination (legs along RA), eq. 15-20"
    return fp.FastPlan(
        switch + [start] + segments + [stop],
        info={
            "scan": name,
            "speed_deg_h": speed,
            "paper_empirical": paper,
            "geometric": geometric,
            "observation_start_utc": sky.jd_to_iso(path.jd1[0], path.jd2[0]),
            "switch_times_s": times.__dict__,
        },
    )


def ra_scan_plan() -> fp.FastPlan:
    return scan_plan(RA_SCAN)


def dec_scan_plan() -> fp.FastPlan:
    return scan_plan(DEC_SCAN)


# ----------------------------------------------------------------------------- runs

#: Feed accuracy after the Stewart stabilizer: 10 mm RMS (REFERENCE.md; Adv. Mech. Eng. 2019).
FEED_RMS_LIMIT_MM = 10.0
#: No public figure for the largest feed error: three times the RMS requirement (what a
#: Gaussian error of 10 mm RMS exceeds 0.3 % of the time). Assumed.
FEED_MAX_LIMIT_MM = 30.0
#: The cable robot's own accuracy: no public figure found; assumed 50 mm RMS, a fifth of the
#: Stewart's +/-0.25 m stroke, so that the stabilizer corrects the cabin well inside its range.
CABIN_RMS_LIMIT_MM = 50.0
#: Runs longer than this write timeseries.npz at OUTPUT_RATE_HZ (a 20-min run at 100 Hz would
#: be 190 MB); the checks use every tick.
LONG_RUN_S = 120.0
OUTPUT_RATE_HZ = 10.0


def output_stride(control_dt: float) -> int:
    """Ticks between two rows of a long run's timeseries.npz (OUTPUT_RATE_HZ)."""
    return max(1, int(round(1.0 / (OUTPUT_RATE_HZ * control_dt))))


#: Segments during which the feed must hold its accuracy (names of planbench.planners.fast_plan).
OBSERVING_PREFIXES = ("observation", "leg", "transition")


def observing_mask(plan: fp.FastPlan, segment_index: np.ndarray) -> np.ndarray:
    """(n,) True where the plan's segment is an observing one (OBSERVING_PREFIXES)."""
    observing = np.array([s.name.startswith(OBSERVING_PREFIXES) for s in plan.segments])
    return observing[segment_index]


def _hold_last_every(log, name: str, n: int, stride: int) -> np.ndarray:
    """Rows 0, stride, 2 stride, ... of the first n rows of a per-tick log of the plant's loads
    (a ``planbench.logfile.LogFile`` of n rows), the last one held: the runner applies no loads
    after its last tick."""
    out = log.every(name, stride)
    if (n - 1) % stride == 0:
        out[-1] = log.span(name, max(n - 2, 0), max(n - 2, 0) + 1)[0]
    return out


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if x.size else float("nan")


class FastEvaluation:
    """Checks, timeseries and report of a FAST run: ``physics`` is the plant (its log is
    judged); ``planned_tower_tops`` (6, 3) m, the nominal model's cable exits from which the
    plan's unstretched lengths are computed (default the plant's: the nominal plant)."""

    def __init__(
        self,
        physics: FastPhysics,
        problem: fp.FastProblem,
        loads: CableLoads,
        description: dict,
        planned_tower_tops: np.ndarray | None = None,
        sensors=None,
        stride: int = 1,
    ):
        self.physics, self.problem, self.loads = physics, problem, loads
        self.sensors = sensors  # the fused system's estimates are judged against the truth
        self.planned_tower_tops = planned_tower_tops
        self.goal = problem.goal
        self.description = description
        self.stride = stride  # timeseries and report: every stride-th tick (Output.output_stride)
        self._summary = (None, None)  # (log, its summary): checks, timeseries and report share it

    def summary(self, log: RunLog) -> dict:
        """What the checks, the timeseries and the report need, computed once per log, one
        chunk of the log at a time (``_reduce``)."""
        if self._summary[0] is not log:
            self._summary = (log, self._reduce(log))
        return self._summary[1]

    def _rows_series(self, rows: dict, reference, start: int, n: int) -> dict:
        """The series of the checks for the log's rows ``start`` on (``rows``: their t,
        sensordata, qpos, qvel, act, ctrl, actuator_force; ``reference``: the reference at
        them) of a log of ``n`` rows: the goal (``problem.goal``'s feed and segments), the
        returned trajectory (the reference, and the cabin pose and tensions that go with it)
        and the run (its sensors, actuators and the plant's catenary tensions)."""
        p = self.physics
        m = rows["t"].shape[0]
        state = fp.reference_state(reference)  # what the returned trajectory asks of the cabin
        segment, goal_feed, _, _ = self.goal.feed(rows["t"])
        feed = rows["sensordata"][:, p.sensor_block("feed_pos")]
        cabin = rows["sensordata"][:, p.sensor_block("cabin_pos")]
        legs = rows["qpos"][:, p.leg_qpos]
        kp, kv = p.drive_gains(p.leg_ids)
        # The plan's unstretched lengths on the nominal geometry (what the winch feed-forward
        # commands; the plant's tower tops may differ).
        towers = p.tower_tops if self.planned_tower_tops is None else self.planned_tower_tops
        unstretched = winch_feedforward(state, towers)
        loads = self.loads.log(n)
        law = loads.span("tension", start, start + m)
        if start + m == n:  # the runner applies no loads after its last tick: the last one held
            law[m - 1] = loads.span("tension", max(n - 2, 0), max(n - 2, 0) + 1)[0]
        return {
            "feed_goal": goal_feed,
            "feed_planned": reference.position[:, :3],
            "feed_actual": feed,
            "feed_error": np.linalg.norm(feed - goal_feed, axis=1),
            "cabin_planned": state.cabin_origin,
            "cabin_actual": cabin,
            "cabin_error": np.linalg.norm(cabin - state.cabin_origin, axis=1),
            "cable_tension": -rows["actuator_force"][:, p.cable_ids],
            "cable_tension_law": law,
            "cable_tension_planned": state.tension,
            "cable_length": rows["sensordata"][:, p.sensor_columns([f"cable{i}_length" for i in range(1, 7)])],
            "cable_unstretched": rows["ctrl"][:, p.cable_ids],
            "cable_unstretched_planned": unstretched,
            "ab_planned": np.column_stack([state.theta_a, state.theta_b]),
            "ab_actual": rows["qpos"][:, p.ab_qpos],
            "stewart_leg": legs,
            "stewart_setpoint": rows["act"][:, p.leg_act],
            "stewart_force_demanded": demanded_force(
                kp, kv, rows["act"][:, p.leg_act], legs, rows["qvel"][:, p.leg_dofs]
            ),
            "segment": segment,
            "observing": observing_mask(self.goal, segment),
        }

    def _reduce(self, log: RunLog) -> dict:
        """One pass over the log's chunks: the per-tick errors, segments and observing flags
        whole (one number a tick, in arrays of the log's length), the extremes of the wide
        series (tensions, legs, forces, angles; max and min, exact in any order), and every
        ``stride``-th row of each series (the timeseries and the report), spooled to a
        temporary log as the chunks are read (``logfile.LoggedSeries``): memory does not grow
        with them however long the run."""
        n = log.n
        r = log.reference
        scalars = {
            "feed_error": np.empty(n),
            "cabin_error": np.empty(n),
            "segment": np.empty(n, np.int32),
            "observing": np.empty(n, bool),
        }
        t_every = log.every("t", self.stride)
        spool, dtypes = None, {}
        ext = {}

        def extreme(key, value, where, better):
            if key not in ext or better(value, ext[key][0]):
                ext[key] = (value, where)

        for start, rows in log.chunks(("t", "sensordata", "qpos", "qvel", "act", "ctrl", "actuator_force")):
            m = rows["t"].shape[0]
            s = self._rows_series(rows, r.rows(start, start + m), start, n)
            for key, whole in scalars.items():
                whole[start : start + m] = s[key]
            kept = {key: value[-start % self.stride :: self.stride] for key, value in s.items()}
            if spool is None:
                dtypes = {key: value.dtype for key, value in kept.items()}
                spool = temporary_writer(
                    {key: value.shape[1:] for key, value in kept.items()}, t_every, chunk=1, prefix="planbench-series-"
                )
            if next(iter(kept.values())).shape[0]:
                spool.append({key: np.asarray(value, float) for key, value in kept.items()})
            tension, law = s["cable_tension"], s["cable_tension_law"]
            low = np.unravel_index(np.argmin(tension), tension.shape)
            high = np.unravel_index(np.argmax(law), law.shape)
            extreme("tension_min", tension[low], (start + low[0], low[1]), lambda a, b: a < b)
            extreme("tension_max", tension.max(), None, lambda a, b: a > b)
            extreme("law_max", law[high], (start + high[0], high[1]), lambda a, b: a > b)
            extreme("planned_min", s["cable_tension_planned"].min(), None, lambda a, b: a < b)
            extreme("planned_max", s["cable_tension_planned"].max(), None, lambda a, b: a > b)
            extreme("leg_abs", np.abs(s["stewart_leg"]).max(initial=0.0), None, lambda a, b: a > b)
            extreme("setpoint_abs", np.abs(s["stewart_setpoint"]).max(initial=0.0), None, lambda a, b: a > b)
            extreme("force_abs", np.abs(s["stewart_force_demanded"]).max(), None, lambda a, b: a > b)
            extreme(
                "feedback_abs",
                np.abs(s["cable_unstretched"] - s["cable_unstretched_planned"]).max(),
                None,
                lambda a, b: a > b,
            )
            ab = np.abs(s["ab_actual"] - s["ab_planned"]).max(axis=0)
            ext["ab_abs"] = (ab if "ab_abs" not in ext else np.maximum(ext["ab_abs"][0], ab), None)
        out = self._errors(scalars, log)  # (the per-tick arrays are dropped here)
        out["extremes"] = {key: value for key, value in ext.items()}
        every = spool.read_back(t_every.size)
        out["every"] = {key: LoggedSeries(every, key, dtype) for key, dtype in dtypes.items()}
        out["t_every"] = t_every
        return out

    def _errors(self, scalars: dict, log: RunLog) -> dict:
        """The feed's and the cabin's error statistics of the checks and metrics, from the
        per-tick errors (m), segments and observing flags of ``_reduce``: over the observing
        segments (the whole run when it has none), per segment, and over the whole run."""
        observing = scalars["observing"]
        window = observing if observing.any() else np.ones(log.n, bool)
        feed_mm, cabin_mm = 1e3 * scalars["feed_error"], 1e3 * scalars["cabin_error"]
        segments = {}
        for k, seg in enumerate(self.goal.segments):
            mask = scalars["segment"] == k
            if mask.any():
                segments[seg.name] = segments.get(seg.name, []) + [
                    {
                        "t0_s": seg.t0,
                        "feed_error_rms_mm": _rms(feed_mm[mask]),
                        "feed_error_max_mm": float(feed_mm[mask].max()),
                        "cabin_error_rms_mm": _rms(cabin_mm[mask]),
                    }
                ]
        return {
            "observing_any": bool(observing.any()),
            "observing_ticks": int(observing.sum()),
            "feed_rms_mm": _rms(feed_mm[window]),
            "feed_max_mm": float(feed_mm[window].max()),
            "cabin_rms_mm": _rms(cabin_mm[window]),
            "cabin_max_mm": float(cabin_mm[window].max()),
            "feed_rms_all_mm": _rms(feed_mm),
            "feed_max_all_mm": float(feed_mm.max()),
            "segments": segments,
        }

    def evaluate(self, log: RunLog):
        p = self.physics
        n = log.n
        s = self.summary(log)
        ext = s["extremes"]
        where = (
            "over the observing segments"
            if s["observing_any"]
            else "no observing segment in this run: over the whole run"
        )
        t_min = fast.FAST_LIMITS.tension_min
        tension_min, low = ext["tension_min"]
        law_max, high = ext["law_max"]
        stroke = np.maximum(ext["leg_abs"][0], ext["setpoint_abs"][0])
        force_limit = float(p.force_limit(p.leg_ids).min())
        stewart = self.description.get("stewart")

        def time_of(row: int) -> float:
            return float(log.t[row])

        checks = [
            Check(
                "feed_error_rms",
                s["feed_rms_mm"],
                FEED_RMS_LIMIT_MM,
                "mm",
                note=(f"Stewart {stewart}; " if stewart else "") + f"against the goal feed path; {where}",
            ),
            Check("feed_error_max", s["feed_max_mm"], FEED_MAX_LIMIT_MM, "mm", note=where),
            Check("cabin_error_rms", s["cabin_rms_mm"], CABIN_RMS_LIMIT_MM, "mm", note=f"cabin origin; {where}"),
            Check(
                "cable_tension_min",
                float(tension_min) / 1e3,
                t_min / 1e3,
                "kN",
                ">=",
                note=f"cable{low[1] + 1} at t = {time_of(low[0]):.2f} s; a slack cable fails",
            ),
            Check(
                "cable_tension_max",
                float(law_max) / 1e3,
                p.tension_max / 1e3,
                "kN",
                note=f"cable{high[1] + 1} at t = {time_of(high[0]):.2f} s (catenary law, before the winch's clamp)",
            ),
            Check(
                "stewart_stroke",
                1e3 * float(stroke),
                1e3 * fast.STEWART.stroke,
                "mm",
                note="largest leg change, measured or its drive's set-point",
            ),
            Check("stewart_force", float(ext["force_abs"][0]) / 1e3, force_limit / 1e3, "kN", note="demanded"),
        ]
        ab_error = np.degrees(ext["ab_abs"][0]) * 3600.0
        metrics = dict(self.description)
        metrics.update(
            {
                "cables": (
                    f"{p.cable_segments} segments each" if p.cable_segments else "straight, lumped catenary law"
                ),
                "wind_mean_m_s": self.loads.mean_speed,
                "wind_toward_deg": float(np.degrees(np.arctan2(self.loads.direction[1], self.loads.direction[0]))),
                "feed_error_rms_all_mm": s["feed_rms_all_mm"],
                "feed_error_max_all_mm": s["feed_max_all_mm"],
                "cabin_error_max_mm": s["cabin_max_mm"],
                "observing_s": float(s["observing_ticks"] * (log.t[1] - log.t[0])) if n > 1 else 0.0,
                "segments": s["segments"],
                "cable_tension_range_kN": [float(tension_min) / 1e3, float(ext["tension_max"][0]) / 1e3],
                "planned_tension_range_kN": [float(ext["planned_min"][0]) / 1e3, float(ext["planned_max"][0]) / 1e3],
                # The winch commands less the unstretched lengths the plan implies: the feedback.
                "cable_feedback_max_mm": 1e3 * float(ext["feedback_abs"][0]),
                "ab_error_max_arcsec": ab_error.round(2).tolist(),
                "stewart_leg_max_mm": 1e3 * float(ext["leg_abs"][0]),
            }
        )
        if isinstance(self.sensors, FusedSensors):
            metrics["measurement_error_rms"] = estimate_errors(self.sensors, p, log)
        if self.loads.mean_speed > 0:
            wind = self.loads.speed[:n]
            peak = max(
                float(np.linalg.norm(part["force"], axis=1).max(initial=0.0))
                for part in self.loads.log(n).chunks(["force"])
            )  # (the max of the chunks' maxima)
            metrics.update({"wind_speed_std_m_s": float(np.std(wind)), "wind_force_peak_N": peak})
        return checks, metrics

    def timeseries(self, log: RunLog) -> dict:
        """The series at every ``stride``-th tick (every tick for a run written whole)."""
        s = self.summary(log)["every"]
        n = log.n
        out = {
            "cable_names": np.array(fast.CABLE_LABELS),
            "feed_pos_planned": s["feed_planned"],
            "feed_pos_actual": s["feed_actual"],
            "feed_error_mm": 1e3 * s["feed_error"],
            "cabin_pos_planned": s["cabin_planned"],
            "cabin_pos_actual": s["cabin_actual"],
            "cable_tension": s["cable_tension"],
            "cable_tension_planned": s["cable_tension_planned"],
            "cable_length": s["cable_length"],
            "cable_unstretched": s["cable_unstretched"],
            "ab_planned": s["ab_planned"],
            "ab_actual": s["ab_actual"],
            "feed_pos_goal": s["feed_goal"],
            "stewart_leg": s["stewart_leg"],
            "stewart_setpoint": s["stewart_setpoint"],
            "stewart_force_demanded": s["stewart_force_demanded"],
            "observing": s["observing"],
        }
        if self.loads.mean_speed > 0:
            out["wind_speed"] = self.loads.speed[:n][:: self.stride]
            out["wind_force"] = _hold_last_every(self.loads.log(n), "force", n, self.stride)
        return out

    def report(self, log: RunLog, checks, path) -> None:
        from planbench.fast.report import fast_report

        fast_report(self.timeseries(log), self.summary(log)["t_every"], checks, path, fast.FAST_LIMITS.tension_min)


def problem(plan: fp.FastPlan) -> fp.FastProblem:
    """The session whose goal is ``plan``: its observing windows are the segments named
    OBSERVING_PREFIXES (observations, scan legs and their transitions)."""
    return fp.problem_of(plan, OBSERVING_PREFIXES)


def build(
    plan: fp.FastPlan | fp.FastProblem,
    params: FastParams,
    controller_options: ControllerOptions | None = None,
    planner=None,
    controller=None,
    sensor_options: SensorOptions | None = None,
    plant: FastPlant | None = None,
) -> Setup:
    """A run of a session (``plan``: its goal plan, or the problem): ``planner`` (default the
    paper's, whose plan is the goal) plans it, ``controller`` (default ``FastController`` with
    ``controller_options``, else the stabilizer as ``params.stewart`` says) follows it, with
    the physics at the trajectory's first pose (at rest, in equilibrium), the cables
    (``params.cable_segments`` >= 2: discretized, planbench.fast.physics.discretized_spec), the wind
    of ``params`` and the sensors (``sensor_options``, default ``params.sensors``).

    ``plant`` (None or nominal: the model as it is) perturbs the simulated machine only
    (``FastPlant``): the planner, the controller (``nominal_physics``) and the parked winch
    lengths keep the nominal model; the plant starts where its own static equilibrium under
    those commands lies (``perturbed_start``)."""
    session = plan if isinstance(plan, fp.FastProblem) else problem(plan)
    planner = fp.PaperPlanner() if planner is None else planner
    trajectory = plan_checked(planner, session, fp.PLAN_LABELS)
    duration = trajectory.duration if params.duration is None else params.duration
    segments = params.cable_segments
    perturbed = plant is not None and not plant.is_nominal
    if perturbed:
        plant.check_segments(segments)
    control_dt = params.control_dt
    run_limits.check_duration(duration, control_dt, params.log_bytes_per_tick())
    measured = None
    if params.wind_file is not None:
        measured = MeasuredWind(params.wind_file)
        try:
            measured.check_covers(duration)
        except WindFileError as e:
            raise ParamError(f"wind_file: {e}") from None
    # The nominal model (the controller's) at the start; the plant is it, or a perturbed copy.
    nominal = FastPhysics.load(segments)
    s0 = fp.reference_state(trajectory.sample(np.array([0.0])))
    nominal.set_configuration(s0.cabin_origin[0], s0.cabin_rotation[0], s0.theta_a[0], s0.theta_b[0], s0.multifeed[0])
    nominal.data.ctrl[:] = parked_command(nominal, s0)  # parked: the winches hold the start
    physics = nominal
    if perturbed:
        physics = FastPhysics.load(segments, plant)
        physics.set_configuration(
            s0.cabin_origin[0], s0.cabin_rotation[0], s0.theta_a[0], s0.theta_b[0], s0.multifeed[0]
        )
        physics.data.ctrl[:] = nominal.data.ctrl  # the operator parks it with the nominal model's lengths
        perturbed_start(physics, nominal, plant)
    description = {}
    if controller is None:
        if controller_options is None:
            controller_options = ControllerOptions(stewart=params.stewart)
        controller = FastController(controller_options)
        description["stewart"] = "on" if controller_options.stewart else "off"
    wind = dict(
        wind_speed=params.wind,
        wind_azimuth_deg=params.wind_direction,
        spectrum=params.wind_spectrum,
        turbulence_intensity=params.turbulence_intensity,
        measured=measured,
        winches=Winches() if params.drives == "as-built" else None,
    )
    if perturbed:
        loads = plant.loads(segments, **wind)  # the true cables' EA and weight
    else:
        loads = (ChainCableLoads if segments else CableLoads)(**wind)
    sensors = make_sensors(physics, params.sensors if sensor_options is None else sensor_options, control_dt)
    stride = output_stride(control_dt) if duration > LONG_RUN_S else 1
    evaluation = FastEvaluation(
        physics, session, loads, description, planned_tower_tops=nominal.tower_tops, sensors=sensors, stride=stride
    )
    task = Task(
        problem=session,
        sensors=sensors,
        evaluation=evaluation,
        control_dt=control_dt,
        duration=duration,
        disturbance=loads,
        nominal_physics=nominal_copy(nominal) if perturbed else None,
    )  # None: a copy
    return Setup(
        physics,
        task,
        Components(planner=planner, trajectory=trajectory, controller=controller),
        Output(output_stride=stride),
        Provenance(seed=params.seed, params=params, plant=plant if plant is not None else FastPlant()),
    )


def goal_plan(params: FastParams) -> fp.FastPlan:
    """The session a scenario's parameters describe: tracking, a scan or a switch. A source
    that leaves FAST's 40 deg zenith-angle range during it is a ParamError naming the keys."""
    try:
        if isinstance(params, FastTrackingParams):
            return tracking_plan(params.tracking, params.source_of(), params.start_utc, params.dut1)
        if isinstance(params, FastScanParams):
            spec = {
                "legs_along": params.legs_along,
                "speed_deg_h": params.scan_speed,
                "leg_deg": params.leg_length,
                "legs": params.legs,
                "spacing_deg": params.leg_spacing,
            }
            return scan_plan(spec, params.source_of(), params.start_utc, params.dut1)
        if isinstance(params, FastSwitchParams):
            return source_switch_plan(params.tracking, params.sources, params.start_utc, params.dut1)
    except fast.ZenithLimitError as e:
        keys = "sources, start_utc" if isinstance(params, FastSwitchParams) else "source, start_utc"
        raise ParamError(f"{keys}: {e} (FAST observes within 40 deg of the zenith, Table 1)") from None
    except LimitError as e:  # a scan whose transitions no t2 can keep under A_t-max
        if isinstance(params, FastScanParams):
            raise ParamError(f"legs_along, legs, leg_length, scan_speed, leg_spacing: {e}") from None
        raise
    raise TypeError(f"no session for {type(params).__name__}")


def build_scenario(params: FastParams, planner=None, controller=None, plant: FastPlant | None = None) -> Setup:
    """A FAST scenario's run: its session (``goal_plan``) built with ``build``; ``plant``: the
    plant's uncertainty (None: nominal)."""
    return build(goal_plan(params), params, planner=planner, controller=controller, plant=plant)


# ----------------------------------------------------------------------------- a perturbed start

#: Settling a plant into its static equilibrium (``static_equilibrium``): extra damping
#: 2 omega M_ii on the cabin's six degrees of freedom, omega at its lowest mode (heave,
#: 0.30 Hz, models/fast/README.md), and on the discretized cables' nodes at their string mode
#: (STRING_MODE_HZ), M_ii the mass matrix's diagonal: every mode then decays at least as
#: exp(-omega t). Damping acts on velocities only, so the plant comes to rest where it would
#: without it. It is at rest when no joint moves faster than SETTLE_SPEED (m/s, rad/s: 1 um/s
#: is a micrometre of creep per second), within SETTLE_MAX_S.
SETTLE_CABIN_HZ = 0.30
SETTLE_SPEED = 1e-6
SETTLE_MAX_S = 60.0
SETTLE_DT = (
    0.01  # s: the loads' tick while settling (the earlier control tick; the settled state does not depend on it)
)


def static_equilibrium(physics: FastPhysics, loads: CableLoads, max_duration: float = SETTLE_MAX_S) -> np.ndarray:
    """The qpos (nq,) where ``physics`` comes to rest from its present state under its present
    commands (ctrl, act) and the cable physics of ``loads`` (made without wind): a copy of it
    (``physics`` is not changed) stepped with the damping above until at rest. A LimitError
    when it does not come to rest within ``max_duration`` s (a cable gone slack, a drive at
    its limit)."""
    scratch = nominal_copy(physics)()
    model, data = scratch.model.ptr, scratch.data.ptr
    n = int(round(max_duration / SETTLE_DT))
    steps = int(round(SETTLE_DT / model.opt.timestep))
    loads.reset(scratch, np.arange(n + 1) * SETTLE_DT, np.random.default_rng(0))  # sets the nodes' masses
    mujoco.mj_forward(model, data)
    dense = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, dense)
    diagonal = np.diag(dense).copy()
    cabin = model.jnt_dofadr[model.joint("cabin").id] + np.arange(6)
    model.dof_damping[cabin] += 2 * (2 * math.pi * SETTLE_CABIN_HZ) * diagonal[cabin]
    if physics.cable_segments:  # the loads write the nodes' damping with their masses, from the first tick on
        nodes = model.body_dofadr[scratch.node_bodies][..., None] + np.arange(3)
        loads.settling_damping = 2 * (2 * math.pi * STRING_MODE_HZ) * diagonal[nodes]
    for tick in range(n):
        loads(tick, scratch)
        mujoco.mj_step(model, data, nstep=steps)
        if tick % 100 == 99 and float(np.abs(data.qvel).max()) < SETTLE_SPEED:
            return data.qpos.copy()
    raise LimitError(
        f"the plant does not come to rest within {max_duration:g} s under the parked commands "
        f"(joint speeds up to {float(np.abs(data.qvel).max()):.3g}, more than {SETTLE_SPEED:g} m/s or "
        "rad/s): a cable slack or a drive at its limit"
    )


def perturbed_start(physics: FastPhysics, nominal: FastPhysics, plant: FastPlant) -> None:
    """Move the perturbed plant ``physics``, put at ``nominal``'s state and commands (the
    plan's first pose at rest, the parked winch lengths of the nominal model), to where its
    perturbation moves that state's static equilibrium, at rest: qpos = the nominal start +
    (the plant's equilibrium - the nominal model's), both under the same commands
    (``static_equilibrium``; free joints composed, mj_differentiatePos / mj_integratePos).
    A machine parked under the operator's nominal winch lengths stands there: a heavier cabin
    lower, one on softer cables lower still. Released from the nominal pose it would instead
    ring at its 0.3-0.65 Hz modes with a swing twice the offset, a start no real run has. The
    difference, not the plant's own equilibrium, so that the start tends to the nominal one as
    the perturbation vanishes (the discretized cables start off theirs by the chain's sag
    error, ``discretized_spec``)."""
    segments = physics.cable_segments
    at_rest_nominal = static_equilibrium(nominal, FastPlant().loads(segments))
    at_rest_plant = static_equilibrium(physics, plant.loads(segments))
    model, data = physics.model.ptr, physics.data.ptr
    shift = np.zeros(model.nv)
    mujoco.mj_differentiatePos(model, shift, 1.0, at_rest_nominal, at_rest_plant)
    mujoco.mj_integratePos(model, data.qpos, shift, 1.0)
    data.qvel[:] = 0.0
    mujoco.mj_forward(model, data)


# ----------------------------------------------------------------------------- scenarios

#: What the FAST runs share: plan plots and the paper's figures.
_RUN = dict(
    build=build_scenario,
    plan=goal_plan,
    kinds=plan_kinds,
    plan_extras=write_figures,
    control_dt=CONTROL_DT,
    plant=FastPlant(),
)

SCENARIOS = (
    Scenario(
        "fast-tracking",
        "FAST feed support: park -> 3C 286 (line + focal arc), start, 20 min of tracking across its "
        "transit, termination; cables, A-B rotator, Stewart stabilizer under wind",
        FastTrackingParams(),
        **_RUN,
        demo_cameras=("closeup",),
        tags=(DEMO, BENCHMARK),
    ),
    Scenario(
        "fast-ra-scan",
        "FAST feed support: the paper's motion scan along RA around 3C 286 (4 legs along Dec at 15 "
        "deg/h, transitions of the shortest t2 under A_t-max) under wind",
        FastScanParams(),
        **_RUN,
    ),
    Scenario(
        "fast-source-switch",
        "FAST feed support: park -> 3C 286, 5 min of tracking, focal-arc switch to 3C 295, 5 min of "
        "tracking, under wind",
        FastSwitchParams(),
        **_RUN,
    ),
)
#: Plans with no run of their own (``planbench plan`` only).
PLANS = (
    Scenario(
        "fast-dec-scan",
        "FAST feed: the paper's motion scan along Dec around 3C 286: 3 legs along RA at 5 deg/h, "
        "transitions, beside the paper's eq. 15-20",
        FastScanParams(
            legs_along="ra",
            legs=DEC_SCAN["legs"],
            leg_length=DEC_SCAN["leg_deg"],
            scan_speed=DEC_SCAN["speed_deg_h"],
            leg_spacing=DEC_SCAN["spacing_deg"],
        ),
        None,
        goal_plan,
        kinds=plan_kinds,
        plan_extras=write_figures,
    ),
)


def environment_reward(setup: Setup):
    """The dm_control reward: exp(-|feed - its goal path| / 10 mm)."""
    goal = setup.task.problem.goal

    def reward(physics, tick, adapter, scale=0.01):
        _, feed, _, _ = goal.feed(np.array([adapter.reference.t[tick]]))
        return float(np.exp(-np.linalg.norm(physics.feed_position() - feed[0]) / scale))

    return reward
