"""FAST feed support: the plans of ``planbench plan fast-*`` (the MuJoCo model is issue 6).

Plans (planners.fast_plan), all at the FAST site with pyerfa (planners.fast_sky):
  fast-tracking       park -> 3C 286 (source switch: line + focal arc), start, 20 min of
                      tracking centred on its transit, termination
  fast-source-switch  park -> 3C 286, 5 min of tracking, termination, switch (focal arc) to
                      3C 295, start, 5 min of tracking, termination
  fast-ra-scan        the paper's motion scan along RA (legs along Dec, Fig. 8): 4 legs of 1 deg
                      at 15 deg/h with transitions, around 3C 286
  fast-dec-scan       the paper's motion scan along Dec (legs along RA, Fig. 11): 3 legs of
                      0.5 deg at 5 deg/h with transitions
The scans' t2 is the shortest that keeps each transition under A_t-max; segments.json holds
it beside the paper's empirical values (eq. 11-14, 15-20). Units of those fits: mm/s for the
speeds, s for the times, deg/h for V_dec and V_asc (eq. 15-16 print "h/s" for V_asc; its
slope 0.751 mm/s per unit is r x 1 deg/h = 0.786 mm/s times cos 17 deg, so deg/h is meant).
"""

from __future__ import annotations

import numpy as np

from planners import fast
from planners import fast_plan as fp
from planners import fast_sky as sky

#: Calibrators (J2000, NED): 3C 286 13h31m08.29s +30d30m33.0s; 3C 295 14h11m20.5s +52d12m21s.
SOURCES = {
    "3C 286": (np.radians(202.784542), np.radians(30.509167)),
    "3C 295": (np.radians(212.835417), np.radians(52.205833)),
}
OBSERVING_NIGHT = "2026-03-01T00:00:00"  # the transit of 3C 286 nearest to it
#: Where the feed waits between observations: 10 m above the focal point of the zenith
#: (inside the focal sphere), so a switch starts with the paper's straight line to P_h.
PARK = np.array([0.0, 0.0, -fast.FOCAL_SURFACE_RADIUS + 10.0])
TRACK_STEP_S = 1.0  # s between sky samples of an observation (a spline joins them)


def _transit(source: str):
    ra, dec = SOURCES[source]
    return sky.meridian_transit(ra, dec, OBSERVING_NIGHT)


def _observation(source: str, start_jd, duration: float, name: str):
    ra, dec = SOURCES[source]
    path = sky.track(ra, dec, start_jd, duration, step=TRACK_STEP_S)
    angles = sky.parallactic_angle(path.az, path.el)  # the 19-beam rotation follows it
    return fp.observation_segment(path.t, path.directions(), name=name, angles=angles), path


def tracking_plan(duration: float = 1200.0, source: str = "3C 286") -> fp.FastPlan:
    """Park -> source (switch), start, ``duration`` s of tracking centred on the transit,
    termination."""
    jd1, jd2 = _transit(source)
    obs, path = _observation(source, (jd1, jd2 - 0.5 * duration / 86400.0), duration,
                             f"observation ({source})")
    start, stop = fp.start_segment(obs), fp.termination_segment(obs)
    switch, times = fp.switch_segments(PARK, start.start, multifeed1=fp.start_angle(obs, start))
    return fp.FastPlan(switch + [start, obs, stop], info={
        "source": source, "observation_start_utc": sky.jd_to_iso(path.jd1[0], path.jd2[0]),
        "switch_times_s": times.__dict__})


def source_switch_plan(duration: float = 300.0) -> fp.FastPlan:
    """Park -> 3C 286, track, stop, switch along the focal surface to 3C 295, track, stop."""
    jd1, jd2 = _transit("3C 286")
    obs_a, _ = _observation("3C 286", (jd1, jd2), duration, "observation (3C 286)")
    start_a, stop_a = fp.start_segment(obs_a), fp.termination_segment(obs_a)
    switch_a, times_a = fp.switch_segments(PARK, start_a.start, multifeed1=fp.start_angle(obs_a, start_a))
    # The second observation starts when the first ends plus the switch; plan the switch
    # toward a first guess of the target, then re-plan it for the actual start point.
    p0 = stop_a.evaluate(np.array([stop_a.duration]))[0][0]
    t_end_a = duration + stop_a.duration
    guess = t_end_a
    for _ in range(3):
        obs_b, _ = _observation("3C 295", (jd1, jd2 + (guess + 1.0) / 86400.0), duration,
                                "observation (3C 295)")
        start_b = fp.start_segment(obs_b)
        switch_b, times_b = fp.switch_segments(p0, start_b.start, multifeed0=fp.end_angle(obs_a, stop_a),
                                               multifeed1=fp.start_angle(obs_b, start_b))
        guess = t_end_a + sum(s.duration for s in switch_b) + start_b.duration
    segments = switch_a + [start_a, obs_a, stop_a] + switch_b + [start_b, obs_b, fp.termination_segment(obs_b)]
    return fp.FastPlan(segments, info={"sources": ["3C 286", "3C 295"],
                                       "switch_times_s": [times_a.__dict__, times_b.__dict__]})


def plan_kinds() -> list[str]:
    return list(fp.PLAN_KINDS)


def write_figures(plan: fp.FastPlan, out_dir) -> None:
    """figures.png (the paper's Figures 16 and 17: the feed's and one cable's velocity and
    acceleration) and segments.json."""
    import json
    from pathlib import Path

    from sims.report import fast_plan_figure

    t = np.arange(0.0, plan.duration, 0.1)
    fast_plan_figure(plan, t, Path(out_dir) / "figures.png")
    (Path(out_dir) / "segments.json").write_text(json.dumps(
        {"segments": plan.segment_table(), "info": plan.info}, indent=1, default=float))


# ----------------------------------------------------------------------------- motion scans

#: The paper's "motion scan along right ascension" (Fig. 8): legs along declination at
#: V_dec = 15 deg/h (0.25 arcmin/s), 1 deg long, 4 legs 3 arcmin apart in RA, around 3C 286.
RA_SCAN = {"legs_along": "dec", "speed_deg_h": 15.0, "leg_deg": 1.0, "legs": 4, "spacing_deg": 0.05}
#: The paper's "motion scan along declination" (Fig. 11): legs along RA at V_asc = 5 deg/h,
#: 0.5 deg long, 3 legs 3 arcmin apart in Dec.
DEC_SCAN = {"legs_along": "ra", "speed_deg_h": 5.0, "leg_deg": 0.5, "legs": 3, "spacing_deg": 0.05}


def _scan_factory(spec: dict, source: str = "3C 286"):
    ra, dec = SOURCES[source]

    def make(t2: float):
        return sky.MotionScan(ra, dec, spec["legs_along"], np.radians(spec["leg_deg"]), spec["legs"],
                              np.radians(spec["spacing_deg"]), spec["speed_deg_h"] * sky.DEG_PER_HOUR, t2)
    return make


def _leg_state(segment, at_end: bool):
    tau = np.array([segment.duration if at_end else 0.0])
    return tuple(x[0] for x in segment.evaluate(tau))


def scan_plan(spec: dict) -> fp.FastPlan:
    """Park -> the raster's start (switch), start, legs with transitions, termination.

    t2 is the geometric one (the shortest that keeps every transition under A_t-max);
    ``info`` holds it beside the paper's empirical values (eq. 11-14 or 15-20).
    """
    make = _scan_factory(spec)
    jd1, jd2 = _transit("3C 286")
    first = make(60.0)
    start_jd = (jd1, jd2 - 0.5 * first.duration / 86400.0)
    t2 = fp.minimum_t2(make, start_jd)
    scan = make(t2)
    segments, path, peaks = fp.scan_segments(scan, start_jd)
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
        geometric.update({"l_2_mm": 1e3 * length, "V_c_mm_s": 1e3 * 2 * length / tr.duration,
                          "p_c": float(chord[1] / chord[0]) if chord[0] else float("inf")})
    if spec["legs_along"] == "dec":
        paper = fp.paper_ra_scan_fits(speed, t2)
        name = "motion scan along right ascension (legs along Dec), eq. 11-14"
    else:
        paper = fp.paper_dec_scan_t2(speed)
        v_m, v_inv = geometric["V_m_mm_s"], geometric["V_m_inv_mm_s"]
        geometric["t3_s"] = 2 * v_m / (fast.A_MAX * 1e3) + 2 * v_inv / (fast.A_MAX * 1e3)
        name = "motion scan along declination (legs along RA), eq. 15-20"
    return fp.FastPlan(switch + [start] + segments + [stop], info={
        "scan": name, "speed_deg_h": speed, "paper_empirical": paper, "geometric": geometric,
        "observation_start_utc": sky.jd_to_iso(path.jd1[0], path.jd2[0]),
        "switch_times_s": times.__dict__})


def ra_scan_plan() -> fp.FastPlan:
    return scan_plan(RA_SCAN)


def dec_scan_plan() -> fp.FastPlan:
    return scan_plan(DEC_SCAN)
