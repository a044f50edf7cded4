"""Run options that are valid numbers but not a run.

Refused up front, before anything is built or written: a duration under one control tick or
whose log would not fit in the free disk space (sims.run_limits), sea states outside the range of the
spectrum and the RAOs (sims.antenna.ship_motion.check_sea_state), angles beyond one turn, winds
beyond IEC 61400-1's classes, IMU rates and latencies the controller does not model, cable
segments beyond the timestep's limit. The CLI says so in one line (exit 2); the Python API
raises a ValueError subclass with the same words. A check that cannot be evaluated fails
with a note and is null (never NaN) in summary.json.
"""

import json
import re

import numpy as np
import pytest

from sims import antenna, fast, hexapod, loader, logfile, run_limits, runner, scenarios, wind
from sims.antenna import ship_motion
from sims.checks import NOT_EVALUATED, Check
from sims.cli import BadInput, _resolve_source, format_checks, main
from sims.fast import controller as fast_controller, measurement as fast_measurement
from sims.fast.loads import CableLoads
from sims.fast.physics import max_cable_segments


def _read(args):
    """The parameters ``planbench run ARGS`` would run with (BadInput as the CLI's)."""
    return _resolve_source("run", list(args))[2]


def _space_limit_words():
    """The limit's words, less its number (the free space changes as the tests write)."""
    return f"B ({run_limits.log_space_limit()[1]})"


def _snapshot(root):
    return sorted((str(p.relative_to(root)), p.stat().st_size if p.is_file() else -1)
                  for p in root.rglob("*"))


def _no_nan(text: str):
    def refuse(constant):
        raise ValueError(f"{constant} in JSON")

    return json.loads(text, parse_constant=refuse)


#: (arguments after "run", words the one line must hold: the key, the value and the limit).
BAD_RUNS = [
    # a duration under one control tick (the scenario's own tick)
    (("fast-tracking", "--duration", "1e-6"), ("duration = 1e-06 s", "[0.02, ...] s", "one control tick (20 ms)")),
    (("loader-supply", "--duration", "0.0049"), ("duration = 0.0049 s", "one control tick (5 ms)")),
    (("hexapod-async-move", "--duration", "0.001"), ("duration = 0.001 s", "(5 ms)")),
    (("antenna-sea-state", "--duration", "0.004"), ("duration = 0.004 s", "[0.005, ...] s")),
    (("fast-ra-scan", "--duration", "0.0199"), ("duration = 0.0199 s", "(20 ms)")),
    (("fast-ra-scan", "--duration", "0.0099", "--set", "control_rate_hz=100"), ("duration = 0.0099 s", "(10 ms)")),
    # a log that would not fit on disk: the estimate and the limit
    (("fast-tracking", "--duration", "1e12"), ("duration 1e+12 s", "PiB of log", "LIMIT")),
    (("antenna-paper-motion", "--duration", "1e12"), ("duration 1e+12 s", "PiB of log", "LIMIT")),
    (("loader-direct", "--duration", "1e9"), ("duration 1e+09 s", "TiB of log", "LIMIT")),
    (("hexapod-sync-move", "--duration", "1e308"), ("duration 1e+308 s", "LIMIT")),
    (("fast-source-switch", "--duration", "1e9", "--cable-segments", "4"), ("duration 1e+09 s", "LIMIT")),
    # sea states the spectrum and the RAOs do not describe
    (("antenna-sea-state", "--tp", "1e-3"), ("tp = 0.001 s", "[1, 30] s", "Munk 1950")),
    (("antenna-sea-state", "--tp", "1e4"), ("tp = 10000 s", "[1, 30] s")),
    (("antenna-sea-state", "--tp", "0.9"), ("tp = 0.9 s", "[1, 30] s")),
    (("antenna-sea-state", "--tp", "31"), ("tp = 31 s", "[1, 30] s")),
    (("antenna-sea-state", "--hs", "1e308"), ("hs = 1e+308 m", "(0, 20] m", "WMO")),
    (("antenna-sea-state", "--hs", "20.5"), ("hs = 20.5 m", "(0, 20] m")),
    (("antenna-sea-state", "--hs", "15", "--tp", "8"), ("hs = 15 m, tp = 8 s", "1/15", "DNV-RP-C205")),
    (("antenna-sea-state", "--hs", "18", "--tp", "12"), ("hs = 18 m, tp = 12 s", "DNV-RP-C205")),
    (("antenna-sea-state", "--hs", "12"), ("hs = 12 m, tp = 10 s", "DNV-RP-C205")),  # default Tp
    (("antenna-sea-state", "--hs", "1", "--tp", "1"), ("hs = 1 m, tp = 1 s", "1/15")),
    # angles: refused beyond one turn, not wrapped
    (("antenna-sea-state", "--wave-heading", "1e308"), ("wave_heading = 1e+308 deg", "[-360, 360] deg")),
    (("antenna-sea-state", "--wave-heading", "-360.5"), ("wave_heading = -360.5 deg", "[-360, 360] deg")),
    (("fast-tracking", "--wind-direction", "1e308"), ("wind_direction = 1e+308 deg", "[-360, 360] deg")),
    (("fast-ra-scan", "--wind-direction", "720"), ("wind_direction = 720 deg", "[-360, 360] deg")),
    (("hexapod-sync-move", "--elevation", "1e308"), ("elevation = 1e+308 deg", "[15, 90] deg")),
    (("hexapod-async-move", "--elevation", "14.9"), ("elevation = 14.9 deg", "[15, 90] deg")),
    (("hexapod-sync-move", "--elevation", "90.01"), ("elevation = 90.01 deg", "[15, 90] deg")),
    # winds beyond the turbulence model's range
    (("fast-tracking", "--wind", "1e308"), ("wind = 1e+308 m/s", "[0, 50] m/s", "IEC 61400-1")),
    (("hexapod-sync-move", "--wind", "50.5"), ("wind = 50.5 m/s", "[0, 50] m/s")),
    # the IMU
    (("antenna-paper-motion", "--set", "imu.rate_hz=1e-300"), ("imu.rate_hz = 1e-300 Hz", "[1, 200] Hz")),
    (("antenna-sea-state", "--set", "imu.rate_hz=0.5"), ("imu.rate_hz = 0.5 Hz", "[1, 200] Hz")),
    (("antenna-paper-motion", "--set", "imu.latency_s=1e9"), ("imu.latency_s = 1e+09 s", "[0, 1] s")),
    (("antenna-sea-state", "--set", "imu.latency_s=1.005"), ("imu.latency_s = 1.005 s", "[0, 1] s")),
    (("antenna-sea-state", "--set", "imu.rate_hz=33"), ("imu.rate_hz", "IMU rate 33 Hz", "whole number")),
    # the IMU's earlier names: refused with the names now
    (("antenna-sea-state", "--imu-rate", "25"), ("--imu-rate", "now imu.rate_hz", "--set imu.rate_hz=VALUE")),
    (("antenna-sea-state", "--set", "imu_latency=0.01"), ("'imu_latency'", "now 'imu.latency_s'")),
    # cable segments: the real limit, from the model
    (("fast-tracking", "--cable-segments", "15"), ("cable_segments = 15", "[0, SEGMENTS]")),
    (("fast-tracking", "--cable-segments", "50"), ("cable_segments = 50", "[0, SEGMENTS]")),
    (("fast-source-switch", "--cable-segments", "1"), ("cable_segments = 1", "2 ... SEGMENTS")),
    (("fast-source-switch", "--cable-segments", "2.5"), ("cable_segments = 2.5", "not an integer")),
    # not numbers, unknown keys, parameters of another scenario
    (("hexapod-sync-move", "--wind", "abc"), ("wind = 'abc' is not a number",)),
    (("hexapod-sync-move", "--set", "hs=5"), ("unknown parameter 'hs'", "HexapodParams has")),
    (("hexapod-sync-move", "--set", "wind"), ("--set 'wind' is not KEY=VALUE",)),
    (("antenna-sea-state", "--stewart", "on"), ("unrecognized arguments: --stewart on",)),
    (("fast-tracking", "--stewart", "maybe"), ("stewart = 'maybe' is not true or false",)),
]


@pytest.mark.parametrize("args, words", BAD_RUNS, ids=[" ".join(a) for a, _ in BAD_RUNS])
def test_bad_run_options_exit_2_with_one_line(tmp_path, capsys, args, words):
    out = tmp_path / "out"
    before = _snapshot(tmp_path)
    code = main(["run", *args, "--out", str(out), "--quiet"])
    captured = capsys.readouterr()
    assert code == 2, captured.err
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, captured.err
    assert "Traceback" not in captured.err and captured.out == ""
    for word in words:
        word = word.replace("LIMIT", _space_limit_words()).replace("SEGMENTS", str(max_cable_segments()))
        assert word in lines[0], lines[0]
    assert not out.exists() and _snapshot(tmp_path) == before
    # Found while the parameters are read, before the scenario is built.
    with pytest.raises(BadInput) as refused:
        _read(args)
    assert str(refused.value) in lines[0]


def test_the_cable_segment_limit_is_the_models():
    """14 at the model's 2 ms timestep, from the one function the run
    checks its cables with; at half the timestep twice as many."""
    assert max_cable_segments() == 14
    assert max_cable_segments(timestep=0.001) in (28, 29)
    # The lumped law's 320 m cables: 14 segments of 22.9 m keep omega dt <= 0.7, 15 do not.
    assert max_cable_segments(320.13646, 0.002) == 14


# ---------------------------------------------------------------- what is still accepted


@pytest.mark.parametrize("args", [
    ("loader-supply", "--duration", "0.005"),  # exactly one tick
    ("fast-tracking", "--duration", "0.02"),  # exactly one tick at the default 50 Hz
    ("fast-tracking", "--duration", "0.01", "--set", "control_rate_hz=100"),
    ("fast-tracking", "--set", "control_rate_hz=500"),
    ("fast-tracking", "--set", "control_rate_hz=10"),
    ("antenna-sea-state", "--hs", "20", "--tp", "30"),
    ("antenna-sea-state", "--hs", "6.6", "--tp", "8"),  # just under 1/15
    ("antenna-sea-state", "--hs", "0.1", "--tp", "1"),
    ("antenna-sea-state", "--wave-heading", "-360"),
    ("antenna-sea-state", "--wave-heading", "360"),
    ("fast-ra-scan", "--wind-direction", "-90", "--wind", "50"),
    ("fast-tracking", "--cable-segments", "14"),
    ("hexapod-sync-move", "--elevation", "15", "--wind", "0"),
    ("antenna-paper-motion", "--set", "imu.rate_hz=1", "--set", "imu.latency_s=1"),
    ("antenna-paper-motion", "--set", "imu.rate_hz=200", "--set", "imu.latency_s=0"),
    ("antenna-sea-state", "--duration", "600"),
])
def test_the_limits_themselves_are_accepted(args):
    params = _read(args)
    assert isinstance(params, type(scenarios.get(args[0]).params))


def test_default_runs_need_little_disk_space():
    """Every registered scenario's default run (what ``make demo`` runs) needs under 1 GiB of
    log; with 14-segment cables FAST's longest under 4 GiB."""
    limit = 4 * 2**30
    durations = {}
    for name, scenario in scenarios.SCENARIOS.items():
        params = scenario.resolve()
        durations[name] = duration = scenario.build(params).task.duration  # the default run's length
        need = (duration / scenario.control_dt + 1) * params.log_bytes_per_tick()
        assert need < limit / 4, (name, run_limits.format_bytes(need))
        run_limits.check_duration(duration, scenario.control_dt, params.log_bytes_per_tick(), (limit, "test"))
    assert durations["fast-tracking"] == pytest.approx(1330.0, abs=1.0)
    longest = (durations["fast-tracking"] / fast.CONTROL_DT + 1) * fast.log_bytes_per_tick(14)
    assert longest < limit


def _held_bytes(*objects, files: dict | None = None, rows: int = 0) -> int:
    """Bytes of the distinct numpy buffers reachable from objects (attributes, slots, lists,
    dicts, dataclasses; not the MuJoCo physics). ``files``: also {path: bytes} of the log files
    they reach (``sims.logfile.LogFile``, ``ChunkWriter``), which take disk space while open
    even once removed; a temporary log still being written is first read back at ``rows``
    rows, as the run's evaluation reads it (its buffered rows are then in its file)."""
    seen, buffers = set(), {}

    def walk(o, depth):
        if id(o) in seen or depth > 6:
            return
        seen.add(id(o))
        if isinstance(o, np.ndarray):
            base = o
            while isinstance(base.base, np.ndarray):
                base = base.base
            buffers[id(base)] = base.nbytes
            return
        if files is not None and isinstance(o, logfile.ChunkWriter) and o.temporary and not o.closed:
            o.read_back(rows)  # (the LogFile read back is then among its attributes)
        if files is not None and isinstance(o, logfile.LogFile):
            files[str(o.path)] = o.source.size()
        if isinstance(o, (list, tuple)):
            for x in o:
                walk(x, depth + 1)
        elif isinstance(o, dict):
            for x in o.values():
                walk(x, depth + 1)
        elif not type(o).__module__.startswith(("numpy", "mujoco", "dm_control", "builtins")):
            fields = getattr(o, "__dict__", None)
            if fields is None and hasattr(o, "__dataclass_fields__"):
                fields = {k: getattr(o, k) for k in o.__dataclass_fields__}
            # Classes with __slots__ (scipy's splines keep their coefficients so).
            slots = [name for cls in type(o).__mro__ for name in getattr(cls, "__slots__", ())
                     if isinstance(name, str) and hasattr(o, name)]
            fields = {**(fields or {}), **{name: getattr(o, name) for name in slots}}
            for key, x in fields.items():
                if key != "physics":
                    walk(x, depth + 1)

    for o in objects:
        walk(o, 0)
    return sum(buffers.values())


#: Knobs that change what a run keeps per tick, beside every scenario at its defaults.
_LOG_KNOBS = [
    ("hexapod-async-move", {"wind": 0.0}),  # no wind series
    ("antenna-paper-motion", {"imu": {"rate_hz": 25.0}}),  # fewer IMU samples
    ("fast-source-switch", {"cable_segments": 3}),  # cables of beads
]


@pytest.mark.parametrize("name, extra", [(name, {}) for name in scenarios.SCENARIOS] + _LOG_KNOBS)
def test_log_estimate_matches_the_arrays_a_run_holds(tmp_path, monkeypatch, name, extra):
    """The parameters' per-tick estimate (``ScenarioParams.log_bytes_per_tick``) against what two
    short runs write and hold after the loop (the log file and the temporary logs of their
    reference, sensors and loads, read back as the evaluation reads them; the arrays of the
    controller, sensors, planner, disturbance, trajectory): the difference of their bytes over
    the difference of their ticks. Within 10 %, never below. What a run makes a block of ticks
    at a time (FAST's plan and IMU errors) it holds one block of, whatever its length: the runs
    make small blocks (the plan's rows of the next 11 ticks, loaded every 10 ticks; the IMU
    errors 10 ticks at a time), so that both hold blocks of the same size and only what grows
    per tick differs."""
    monkeypatch.setattr(fast_controller, "PLAN_BLOCK_TICKS", 11)
    monkeypatch.setattr(fast_controller, "PLAN_HISTORY_TICKS", 5)
    monkeypatch.setattr(fast_measurement, "IMU_BLOCK_TICKS", 10)
    scenario = scenarios.get(name)
    held = []
    for ticks in (20, 140):  # 120 ticks apart: whole periods of the sensors' samples (4, 5, 6 ticks, ...)
        params = scenario.resolve(duration=ticks * scenario.control_dt, **extra)
        setup = scenario.build(params)
        path = tmp_path / f"{ticks}.arrow"
        log = runner.simulate(setup, log_path=path)
        files = {}
        memory = _held_bytes(log, setup.components.controller, setup.task.sensors, setup.components.planner,
                             setup.task.disturbance, setup.components.trajectory, files=files, rows=log.n)
        files[str(path)] = path.stat().st_size
        held.append((log.n, memory + sum(files.values())))
    (n1, b1), (n2, b2) = held
    measured = (b2 - b1) / (n2 - n1)
    estimate = params.log_bytes_per_tick()
    assert measured <= estimate <= 1.1 * measured, (measured, estimate)


# ---------------------------------------------------------------- the Python API


@pytest.mark.parametrize("name", list(scenarios.SCENARIOS))
def test_build_refuses_a_duration_under_one_tick(name):
    scenario = scenarios.get(name)
    with pytest.raises(ValueError, match=rf"duration = {0.5 * scenario.control_dt:g} s is outside .*one control tick "
                                         rf"\({scenario.control_dt * 1e3:g} ms\)"):
        scenario.resolve(duration=0.5 * scenario.control_dt)
    with pytest.raises(run_limits.RunLimitError, match="of log, more than the limit of"):
        scenario.resolve(duration=1e12)


@pytest.mark.parametrize("name", list(scenarios.SCENARIOS))
def test_build_checks_before_any_work(monkeypatch, name):
    """The refusal comes before any model file is opened (every mechanism's physics loads its
    scene through ``models.scene_path``), and so before the work proportional to the duration
    that follows it (the antenna's ideal path)."""
    import models

    def must_not_run(*args, **kwargs):
        raise AssertionError(f"{name}: a model was loaded before the duration was checked")

    monkeypatch.setattr(models, "scene_path", must_not_run)
    scenario = scenarios.get(name)
    with pytest.raises(run_limits.RunLimitError, match="duration 1e\\+12 s needs"):
        scenario.build(scenario.resolve(duration=1e12))
    # A Params object made without the checks (as a careless caller could) is refused by build.
    unchecked = object.__new__(type(scenario.params))
    for key, value in vars(scenario.params).items():
        object.__setattr__(unchecked, key, value)
    object.__setattr__(unchecked, "duration", 1e12)
    with pytest.raises(run_limits.RunLimitError, match="duration 1e\\+12 s needs"):
        scenario.build(unchecked)


def test_disk_rule_is_stated_and_follows_the_free_space(monkeypatch, tmp_path):
    import shutil

    limit, why = run_limits.log_space_limit(tmp_path / "not" / "yet")
    assert why == f"the free space on the file system of {tmp_path}"
    assert limit == pytest.approx(shutil.disk_usage(tmp_path).free, rel=0.01)
    monkeypatch.setattr(run_limits, "free_bytes", lambda directory: 4 * 2**30)
    with pytest.raises(run_limits.RunLimitError,
                       match=r"duration 1e\+12 s needs ~1\.4 PiB of log, more than the limit of 4 GiB \(the free "):
        run_limits.check_duration(1e12, 0.005, 8.0)  # 2e14 ticks x 8 B = 1.42 PiB
    run_limits.check_duration(1e5, 0.005, 8.0)  # 160 MB: fits
    assert run_limits.format_bytes(12 * 2**30) == "12 GiB" and run_limits.format_bytes(512) == "512 B"


@pytest.mark.parametrize("hs, tp, words", [
    (5.0, 1e-3, "tp = 0.001 s is outside [1, 30] s"),
    (5.0, 1e4, "tp = 10000 s is outside [1, 30] s"),
    (1e308, 10.0, "hs = 1e+308 m is above 20 m"),
    (0.0, 10.0, "hs = 0 m must be > 0"),
    (float("nan"), 10.0, "hs = nan m must be finite"),
    (15.0, 8.0, "hs = 15 m, tp = 8 s is steeper than waves can be"),
    (15.0, 15.0, r"tp = 15 s is steeper than waves can be: 2 pi Hs / \(g Tp\^2\) = 1/23.4 > 1/25"),
])
def test_sea_states_outside_the_models_range_are_named(hs, tp, words):
    with pytest.raises(ship_motion.ShipMotionError, match=words if "\\" in words else re.escape(words)):
        ship_motion.check_sea_state(hs, tp)
    with pytest.raises(ValueError):
        antenna.AntennaSeaParams(hs=hs, tp=tp)


def test_sea_state_limits_hold_the_default_and_the_steepness_rule():
    assert ship_motion.check_sea_state(antenna.SEA_HS_M, antenna.SEA_TP_S) == (5.0, 10.0)
    assert ship_motion.steepness_limit(5.0) == pytest.approx(1 / 15)
    assert ship_motion.steepness_limit(20.0) == pytest.approx(1 / 25)
    assert ship_motion.steepness_limit(11.5) == pytest.approx(0.5 * (1 / 15 + 1 / 25))
    # The limit is Hs = Sp g Tp^2 / (2 pi): 6.66 m at 8 s is in, 6.7 m out.
    ship_motion.check_sea_state(6.66, 8.0)
    with pytest.raises(ship_motion.ShipMotionError):
        ship_motion.check_sea_state(6.7, 8.0)


def test_angles_winds_and_the_imu_are_refused_in_the_python_api():
    with pytest.raises(ValueError, match=r"wave_heading = 1e\+308 deg is outside \[-360, 360\] deg"):
        antenna.AntennaSeaParams(wave_heading=1e308)
    with pytest.raises(ValueError, match=r"wind_direction = 400 deg is outside \[-360, 360\] deg"):
        fast.FastParams(wind_direction=400.0)
    with pytest.raises(ValueError, match=r"elevation = 1e\+308 deg is outside"):
        hexapod.HexapodParams(elevation=1e308)
    for make in (lambda: CableLoads(1e308), lambda: wind.check_mean_speed(60.0),
                 lambda: wind.wind_speed_series(np.arange(3.0), 51.0, np.random.default_rng(0))):
        with pytest.raises(ValueError, match=r"above 50 m/s"):
            make()
    with pytest.raises(ValueError, match=r"rate_hz = 1e-300 Hz is outside \[1, 200\] Hz"):
        antenna.ImuModel(rate_hz=1e-300)
    with pytest.raises(ValueError, match=r"latency_s = 1e\+09 s is outside \[0, 1\] s"):
        antenna.AntennaPaperParams(imu=antenna.ImuModel(latency_s=1e9))
    with pytest.raises(ValueError, match=r"cable_segments = 20 is outside \[0, 14\]"):
        fast.FastParams(cable_segments=20)
    with pytest.raises(ValueError, match=r"cable_segments = 2\.5 is not an integer"):
        fast.FastParams(cable_segments=2.5)


# ---------------------------------------------------------------- checks not evaluated


def test_a_nan_check_fails_with_a_note_and_is_null_in_json():
    c = Check.not_evaluated("settled", 1.0, "um", reason="the run ended early")
    assert not c.passed and not c.evaluated
    assert c.note == f"{NOT_EVALUATED}: the run ended early"
    j = _no_nan(json.dumps(c.to_json()))
    assert j["value"] is None and j["passed"] is False and j["note"].startswith(NOT_EVALUATED)
    bare = Check("bare", float("nan"), 1.0, "m")  # an evaluation that forgot the reason
    assert bare.note.startswith(NOT_EVALUATED) and "no reason" in bare.note
    assert _no_nan(json.dumps(bare.to_json()))["value"] is None
    assert _no_nan(json.dumps(Check("inf", float("inf"), 1.0, "m").to_json()))["value"] == "inf"
    ok = Check("fine", 0.5, 1.0, "m")
    assert ok.passed and ok.evaluated and ok.note == "" and "note" not in ok.to_json()
    table = format_checks([("s", c), ("s", ok)])
    assert "nan" not in table.lower().replace("not evaluated", "")
    assert "n/a" in table.splitlines()[1] and "the run ended early" in table.splitlines()[1]
    assert "n/a" not in table.splitlines()[2]


@pytest.mark.parametrize("name, check", [("hexapod-sync-move", "arrival_spread"),
                                         ("hexapod-async-move", "arrival_vs_own_time")])
def test_short_hexapod_run_cannot_claim_its_arrival_or_settling(name, check):
    result = runner.run(name, scenarios.get(name).build(scenarios.get(name).resolve(duration=1.0, wind=0.0)))
    by_name = {c.name: c for c in result.checks}
    for key in (check, "pose_error_final"):
        assert not by_name[key].evaluated and not by_name[key].passed
        assert by_name[key].note.startswith(NOT_EVALUATED), by_name[key].note
    assert "settling" in by_name["pose_error_final"].note
    assert "came to rest" in by_name[check].note
    assert by_name["following_error"].evaluated  # what was seen is still checked


def test_short_hexapod_run_writes_a_failed_check_with_a_note_and_no_nan(tmp_path, capsys):
    out = tmp_path / "short"
    code = main(["run", "hexapod-sync-move", "--duration", "0.5", "--wind", "0", "--out", str(out),
                 "--quiet"])
    captured = capsys.readouterr()
    assert code == 1, captured.err
    summary = _no_nan((out / "summary.json").read_text())
    entry = next(c for c in summary["checks"] if c["name"] == "pose_error_final")
    assert entry["value"] is None and entry["passed"] is False
    assert entry["note"].startswith(NOT_EVALUATED) and "settling" in entry["note"]
    assert summary["passed"] is False
    row = next(line for line in captured.out.splitlines() if "pose_error_final" in line)
    assert "n/a" in row and "FAIL" in row and "nan" not in row


def test_no_nan_in_any_short_run():
    """One tick and a few ticks of every scenario: every check is a number or carries the
    reason it is not, and the checks and metrics serialize without NaN."""
    for name, scenario in scenarios.SCENARIOS.items():
        for ticks in (1, 3):
            result = runner.run(name, scenario.build(scenario.resolve(duration=ticks * scenario.control_dt)))
            for c in result.checks:
                assert c.evaluated or c.note.startswith(NOT_EVALUATED), (name, c)
                assert c.evaluated or not c.passed
            text = json.dumps({"checks": [c.to_json() for c in result.checks],
                               "metrics": result.metrics}, default=float)
            _no_nan(text)
