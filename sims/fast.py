"""FAST feed support: the plans of ``planbench plan fast-*`` (the MuJoCo model is issue 6).

Plans (planners.fast_plan), all at the FAST site with pyerfa (planners.fast_sky):
  fast-tracking       park -> 3C 286 (source switch: line + focal arc), start, 20 min of
                      tracking centred on its transit, termination
  fast-source-switch  park -> 3C 286, 5 min of tracking, termination, switch (focal arc) to
                      3C 295, start, 5 min of tracking, termination
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
    return fp.observation_segment(path.t, path.directions(), name=name), path


def tracking_plan(duration: float = 1200.0, source: str = "3C 286") -> fp.FastPlan:
    """Park -> source (switch), start, ``duration`` s of tracking centred on the transit,
    termination."""
    jd1, jd2 = _transit(source)
    obs, path = _observation(source, (jd1, jd2 - 0.5 * duration / 86400.0), duration,
                             f"observation ({source})")
    start, stop = fp.start_segment(obs), fp.termination_segment(obs)
    switch, times = fp.switch_segments(PARK, start.start)
    return fp.FastPlan(switch + [start, obs, stop], info={
        "source": source, "observation_start_utc": sky.jd_to_iso(path.jd1[0], path.jd2[0]),
        "switch_times_s": times.__dict__})


def source_switch_plan(duration: float = 300.0) -> fp.FastPlan:
    """Park -> 3C 286, track, stop, switch along the focal surface to 3C 295, track, stop."""
    jd1, jd2 = _transit("3C 286")
    obs_a, _ = _observation("3C 286", (jd1, jd2), duration, "observation (3C 286)")
    start_a, stop_a = fp.start_segment(obs_a), fp.termination_segment(obs_a)
    switch_a, times_a = fp.switch_segments(PARK, start_a.start)
    # The second observation starts when the first ends plus the switch; plan the switch
    # toward a first guess of the target, then re-plan it for the actual start point.
    p0 = stop_a.evaluate(np.array([stop_a.duration]))[0][0]
    t_end_a = duration + stop_a.duration
    guess = t_end_a
    for _ in range(3):
        obs_b, _ = _observation("3C 295", (jd1, jd2 + (guess + 1.0) / 86400.0), duration,
                                "observation (3C 295)")
        start_b = fp.start_segment(obs_b)
        switch_b, times_b = fp.switch_segments(p0, start_b.start)
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
