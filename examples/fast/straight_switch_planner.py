"""A user's planner for FAST: each source switch as one straight line.

Run it:  planbench run fast-source-switch --planner examples/fast/straight_switch_planner.py:StraightSwitch

The paper switches sources along a line to the focal sphere and then an arc on it (section
3.2, eq. 10). Here the feed takes the chord: one straight line from where the switch starts to
where it ends, in the same time, with the paper's speed profile (planbench.planners.profiles) along it.
Everything else (start, observations, termination) is the paper's plan of the session
(``problem.goal``), so the observing windows are kept.
"""

from __future__ import annotations

import numpy as np

from planbench.planners import fast, profiles
from planbench.planners.fast import plan as fp


class StraightSwitch:
    def plan(self, problem) -> fp.FastPlan:
        segments, switch = [], []
        for segment in problem.goal.segments + [None]:
            if segment is not None and segment.name.startswith("switch"):
                switch.append(segment)
                continue
            if switch:  # a run of switch segments ends: one chord instead
                start = switch[0].evaluate(np.array([0.0]))[0][0]
                end = switch[-1].evaluate(np.array([switch[-1].duration]))[0][0]
                duration = sum(s.duration for s in switch)
                profile = profiles.move_in_time(
                    float(np.linalg.norm(end - start)), duration, fast.V_S_MAX, fast.A_S_MAX
                )
                segments.append(fp.LineSegment("switch-chord", 0.0, duration, fast.A_S_MAX, start, end, profile))
                switch = []
            if segment is not None:
                segments.append(segment)
        return fp.FastPlan(segments, problem.goal.geometry, problem.goal.limits, info={"switch": "straight chords"})
