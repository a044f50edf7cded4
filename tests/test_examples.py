"""Every example in examples/ run as a user runs it, through ``planbench run ... --controller``
or ``--planner``, with the outcome its README states: where a baseline is worse, the checks
must catch it."""

from __future__ import annotations

import json
from pathlib import Path

from planbench import scenarios
from planbench.cli import main

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def run(tmp_path, scenario, role, spec, *extra):
    out = tmp_path / "out"
    code = main(["run", scenario, f"--{role}", str(EXAMPLES / spec), "--out", str(out), "--quiet", *extra])
    summary = json.loads((out / "summary.json").read_text())
    assert summary["plugins"] == {role: str(EXAMPLES / spec)}
    assert summary["components"][role].endswith("." + spec.rsplit(":", 1)[1])
    checks = {c["name"]: c for c in summary["checks"]}
    assert checks["controller_errors"]["passed"] and checks["simulation_warnings"]["passed"]
    assert code == (0 if summary["passed"] else 1)
    return summary, checks


def failed(checks) -> set:
    return {name for name, c in checks.items() if not c["passed"]}


def test_loader_plain_pd_fails_the_tracking_check(tmp_path):
    _, checks = run(tmp_path, "loader-supply", "controller", "loader/pd_controller.py:PlainPD")
    assert failed(checks) == {"tracking_error", "keypoint_error"}
    assert checks["tracking_error"]["value"] > 1.0  # deg: 2.24 measured, the limit 0.25


def test_loader_quintic_spline_passes(tmp_path):
    summary, checks = run(tmp_path, "loader-supply", "planner", "loader/quintic_planner.py:QuinticPlanner")
    # 0.0296 deg as built (the motors' friction dead band, F_c / kp = 0.0086 deg, and the reducers'
    # compliance), 0.0019 deg on the ideal drives; the limit 0.1 deg.
    assert summary["passed"] and checks["keypoint_error"]["value"] < 0.05


def test_loader_quintic_spline_without_key_points_strikes_the_obstacles(tmp_path):
    _, checks = run(tmp_path, "loader-direct", "planner", "loader/quintic_planner.py:QuinticPlanner")
    assert {"obstacle_contacts", "min_clearance"} <= failed(checks)


def test_hexapod_plain_pd_sags(tmp_path):
    _, checks = run(tmp_path, "hexapod-sync-move", "controller", "hexapod/pd_controller.py:PlainPD")
    # As built the unfed start also drops the rotors into the load: 51.7 kN demanded.
    assert failed(checks) == {"following_error", "pose_error_final", "strut_force"}
    assert checks["pose_error_final"]["value"] > 100.0  # um: 282 measured, the limit 1


def test_hexapod_quintic_move_passes_sync_and_is_not_an_async_move(tmp_path):
    summary, checks = run(tmp_path, "hexapod-sync-move", "planner", "hexapod/smooth_planner.py:QuinticMove")
    assert summary["passed"] and checks["arrival_spread"]["value"] == 0.0
    _, checks = run(tmp_path / "async", "hexapod-async-move", "planner", "hexapod/smooth_planner.py:QuinticMove")
    assert failed(checks) == {"arrival_vs_own_time"}


def test_antenna_pinv_integration_drifts_and_fails_the_attitude_check(tmp_path):
    _, checks = run(
        tmp_path, "antenna-paper-motion", "planner", "antenna/pinv_planner.py:PinvIntegration", "--duration", "10"
    )
    assert "attitude_error_fro_max" in failed(checks)
    assert checks["attitude_error_fro_max"]["value"] > 1e-3  # 0.0133 measured, the limit 1e-6


def test_antenna_sample_and_hold_lags_the_paper_motion_and_holds_the_sea(tmp_path):
    _, checks = run(
        tmp_path, "antenna-paper-motion", "controller", "antenna/hold_controller.py:SampleAndHold", "--duration", "10"
    )
    assert {"pointing_error_max", "polarization_error_max"} <= failed(checks)
    summary, checks = run(
        tmp_path / "sea",
        "antenna-sea-state",
        "controller",
        "antenna/hold_controller.py:SampleAndHold",
        "--duration",
        "30",
    )
    assert summary["passed"] and checks["pointing_error_rms"]["value"] > 0.05  # deg: 0.090, ours 0.040 (as built)


def test_fast_feedforward_alone_is_worse_than_the_stabilized_feed(tmp_path):
    summary, checks = run(
        tmp_path, "fast-tracking", "controller", "fast/feedforward_controller.py:FeedforwardOnly", "--duration", "200"
    )
    # With the measured cable dynamics the cable robot alone misses FAST's 10 mm (11.4 mm
    # measured; the stabilized feed 3.67 mm), as examples/fast/README.md states.
    assert failed(checks) == {"feed_error_rms"}
    assert checks["stewart_stroke"]["value"] < 1.0  # mm: the legs hold nominal


def test_fast_straight_switch_keeps_the_observation(tmp_path):
    summary, checks = run(
        tmp_path, "fast-source-switch", "planner", "fast/straight_switch_planner.py:StraightSwitch", "--duration", "180"
    )
    assert summary["passed"] and summary["metrics"]["observing_s"] > 50.0
    assert summary["components"]["trajectory"] == "planbench.planners.fast.plan.FastPlan"


def test_every_mechanism_has_examples_and_each_plug_in_is_run_here():
    """Each registered mechanism has its examples/<name>/ with a README, and every plug-in
    module there is run by a test of this file (its path appears in it)."""
    text = Path(__file__).read_text()
    for mechanism in scenarios.mechanisms():
        folder = EXAMPLES / mechanism.name
        assert (folder / "README.md").is_file(), folder
        for module in sorted(folder.glob("*.py")):
            assert f'"{mechanism.name}/{module.name}:' in text, module
