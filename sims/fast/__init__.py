"""FAST feed support: plans, scenarios and checks (``planbench run|plan fast-*``).

Runs (sims/fast/physics.py, loads.py and controller.py: the model's cables, wind and controller), each with ``--wind``
(mean wind, default 4 m/s, Kaimal turbulence, drag on the cabin and the cables),
``--wind-direction`` and ``--stewart on|off``:
  fast-tracking       the plan below: switch, start, 20 min of tracking, termination
  fast-ra-scan        the motion scan along RA with its transitions
  fast-source-switch  two observations and the focal-arc switch between them
Checks over the observing segments (observations, scan legs and their transitions):
feed_error_rms (<= 10 mm, REFERENCE.md), feed_error_max, cabin_error_rms; over the whole run:
cable_tension_min (>= T_min, a slack cable fails), cable_tension_max (<= T_max),
stewart_stroke, stewart_force.

Plans (planbench.planners.fast_plan), all at the FAST site with pyerfa (planbench.planners.fast_sky):
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

from planbench.fast.controller import (
    ControllerOptions,
    FastController,
    ab_gravity_torque,
    parked_command,
    winch_feedforward,
)
from planbench.fast.loads import CableLoads, ChainCableLoads
from planbench.fast.measurement import FusedSensors, IdealSensors, SensorOptions, make_sensors
from planbench.fast.params import (
    DEC_SCAN,
    DEFAULT_CABLE_SEGMENTS,
    DEFAULT_WIND_M_S,
    OBSERVING_NIGHT,
    PER_TICK_FLOATS,
    RA_SCAN,
    SOURCES,
    WIND_AZIMUTH_DEG,
    FastParams,
    FastPlant,
    FastScanParams,
    FastSourceParams,
    FastSwitchParams,
    FastTrackingParams,
    log_bytes_per_tick,
)
from planbench.fast.physics import CONTROL_DT, PHYSICS_DT, SEGMENT_OMEGA_DT_LIMIT, FastPhysics, max_cable_segments
from planbench.fast.task import (
    CABIN_RMS_LIMIT_MM,
    FEED_MAX_LIMIT_MM,
    FEED_RMS_LIMIT_MM,
    LONG_RUN_S,
    OBSERVING_PREFIXES,
    OUTPUT_RATE_HZ,
    PARK,
    PLANS,
    SCENARIOS,
    TRACK_STEP_S,
    FastEvaluation,
    build,
    build_scenario,
    dec_scan_plan,
    environment_reward,
    goal_plan,
    observation_plan,
    observing_mask,
    output_stride,
    perturbed_start,
    plan_kinds,
    problem,
    ra_scan_plan,
    scan_plan,
    source_name,
    source_switch_plan,
    static_equilibrium,
    tracking_plan,
    write_figures,
)
from planbench.scenarios import Mechanism

MECHANISM = Mechanism("fast", SCENARIOS, environment_reward, plans=PLANS, benchmark_runs=2)

__all__ = [
    "CABIN_RMS_LIMIT_MM",
    "CONTROL_DT",
    "CableLoads",
    "ChainCableLoads",
    "ControllerOptions",
    "DEC_SCAN",
    "DEFAULT_CABLE_SEGMENTS",
    "DEFAULT_WIND_M_S",
    "FEED_MAX_LIMIT_MM",
    "FEED_RMS_LIMIT_MM",
    "FastController",
    "FastEvaluation",
    "FastParams",
    "FastPhysics",
    "FastPlant",
    "FastScanParams",
    "FastSourceParams",
    "FastSwitchParams",
    "FastTrackingParams",
    "FusedSensors",
    "IdealSensors",
    "LONG_RUN_S",
    "MECHANISM",
    "OBSERVING_NIGHT",
    "OBSERVING_PREFIXES",
    "OUTPUT_RATE_HZ",
    "PARK",
    "PER_TICK_FLOATS",
    "PHYSICS_DT",
    "PLANS",
    "RA_SCAN",
    "SCENARIOS",
    "SEGMENT_OMEGA_DT_LIMIT",
    "SOURCES",
    "SensorOptions",
    "TRACK_STEP_S",
    "WIND_AZIMUTH_DEG",
    "ab_gravity_torque",
    "build",
    "build_scenario",
    "dec_scan_plan",
    "environment_reward",
    "goal_plan",
    "log_bytes_per_tick",
    "make_sensors",
    "max_cable_segments",
    "observation_plan",
    "observing_mask",
    "output_stride",
    "parked_command",
    "perturbed_start",
    "plan_kinds",
    "problem",
    "ra_scan_plan",
    "scan_plan",
    "source_name",
    "source_switch_plan",
    "static_equilibrium",
    "tracking_plan",
    "winch_feedforward",
    "write_figures",
]
