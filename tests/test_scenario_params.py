"""Scenarios as data: typed parameters declared once, scenario files, reruns.

Every scenario's parameters are one planbench.params class; these tests hold the declarations to
what they promise: valid values build and plan, a value outside its range is refused with its
key, the CLI's help and the README's tables come from them, a scenario file and a run's
summary.json run (the rerun bit for bit), and user parameters reach the physics (a list of
hexapod moves, another source and time for FAST against pyerfa, another ship position for the
antenna against the geostationary formulas).
"""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import erfa
import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from planbench import antenna, fast, hexapod, loader, params, runner, scenarios
from planbench.antenna.ship_motion import GRAVITY, steepness_limit
from planbench.cli import main
from planbench.params import ParamError
from planbench.planners.fast import sky

ROOT = Path(__file__).resolve().parents[1]
#: Scenario files (campaign specs, *_campaign.toml, are tests/test_campaign.py's).
EXAMPLES = sorted(p for p in (ROOT / "examples").glob("*/*.toml") if not p.name.endswith("_campaign.toml"))
#: Shorter runs of the examples for the tests (make demo and users run them whole).
EXAMPLE_DURATION_S = {"crab.toml": 30.0, "measured_wind.toml": 30.0, "indian_ocean.toml": 20.0}
SLOW = settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def _classes():
    seen = {}
    for s in [*scenarios.SCENARIOS.values(), *scenarios.PLANS.values()]:
        seen.setdefault(type(s.params), s)
    return seen


def _plant_classes():
    """{each mechanism's PlantParams class: a scenario declaring it}."""
    seen = {}
    for s in scenarios.SCENARIOS.values():
        seen.setdefault(type(s.plant), s)
    return seen


def _fraction(draw, low, high, inner=1.0):
    mid, half = 0.5 * (low + high), 0.5 * (high - low) * inner
    return draw(st.floats(mid - half, mid + half, allow_nan=False))


# ------------------------------------------------------------------ valid sets build and plan


@st.composite
def loader_params(draw):
    k = draw(st.integers(2, 5))
    rows = [
        tuple(
            _fraction(draw, lo, hi, 0.4) for lo, hi in zip(loader.params._KEY_LOW, loader.params._KEY_HIGH, strict=True)
        )
        for _ in range(k)
    ]
    return loader.LoaderParams(
        key_points=tuple(rows),
        key_interval=draw(st.floats(0.4, 2.0)),
        settle=draw(st.floats(0.0, 1.0)),
        payload_mass=draw(st.floats(0.0, 90.0)),
        seed=draw(st.integers(0, 2**63 - 1)),
    )


@st.composite
def hexapod_params(draw):
    def pose():
        return tuple(
            _fraction(draw, lo, hi, 0.25)
            for lo, hi in zip(hexapod.params._POSE_LOW, hexapod.params._POSE_HIGH, strict=True)
        )

    start = pose()
    moves = tuple(hexapod.HexapodMove(pose(), draw(st.booleans())) for _ in range(draw(st.integers(1, 3))))
    try:  # a move of zero length (no strut length changes) is refused; the rest must build
        return hexapod.HexapodParams(
            start_pose=start,
            moves=moves,
            elevation=draw(st.floats(15.0, 90.0)),
            wind=draw(st.floats(0.0, 50.0)),
            dwell=draw(st.floats(1.0, 3.0)),
        )
    except ParamError as e:
        assume("a move of zero length" not in str(e))
        raise


@st.composite
def antenna_sea_params(draw):
    tp = draw(st.floats(3.0, 20.0))
    hs_max = min(steepness_limit(tp) * GRAVITY * tp**2 / (2 * math.pi), 20.0)
    lat, lon = draw(st.floats(-50.0, 50.0)), draw(st.floats(-180.0, 180.0))
    satellite = {"satellite_lon": (lon + draw(st.floats(-40.0, 40.0)) + 180.0) % 360.0 - 180.0}
    if draw(st.booleans()):
        satellite = {
            "satellite_look": (draw(st.floats(0.0, 360.0)), draw(st.floats(10.0, 85.0)), draw(st.floats(-60.0, 60.0)))
        }
    return antenna.AntennaSeaParams.from_mapping(
        dict(
            hs=draw(st.floats(0.1, 0.95)) * hs_max,
            tp=tp,
            gamma=draw(st.floats(1.0, 7.0)),
            wave_heading=draw(st.floats(-360.0, 360.0)),
            ship_heading=draw(st.floats(-360.0, 360.0)),
            ship_speed=draw(st.floats(0.0, 15.0)),
            ship_lat=lat,
            ship_lon=lon,
            imu=dict(rate_hz=200.0 / draw(st.integers(1, 200)), latency_s=0.005 * draw(st.integers(0, 200))),
            duration=5.0,
            seed=draw(st.integers(0, 2**32)),
            **satellite,
        )
    )


@st.composite
def antenna_paper_params(draw):
    return antenna.AntennaPaperParams(
        heading_amplitude=draw(st.floats(0.0, 180.0)),
        heading_period=draw(st.floats(1.0, 3600.0)),
        turn_rate=draw(st.floats(-10.0, 10.0)),
        pitch_amplitude=draw(st.floats(0.0, 60.0)),
        pitch_period=draw(st.floats(1.0, 60.0)),
        roll_amplitude=draw(st.floats(0.0, 60.0)),
        roll_period=draw(st.floats(1.0, 60.0)),
        ship_heading=draw(st.floats(-360.0, 360.0)),
        duration=5.0,
    )


@st.composite
def fast_tracking_params(draw):
    return fast.FastTrackingParams(
        source=draw(st.sampled_from(sorted(fast.SOURCES))),
        tracking=draw(st.floats(10.0, 1800.0)),
        wind=draw(st.floats(0.0, 50.0)),
        wind_direction=draw(st.floats(-360.0, 360.0)),
        turbulence_intensity=draw(st.none() | st.floats(0.0, 0.5)),
        wind_spectrum=draw(st.sampled_from(("kaimal", "davenport"))),
        stewart=draw(st.booleans()),
    )


@given(loader_params())
@SLOW
def test_any_valid_loader_parameters_build_and_plan(p):
    scenario = scenarios.get("loader-supply")
    assert scenario.plan(p).duration == pytest.approx((len(p.key_points) - 1) * p.key_interval)
    setup = scenario.build(p)
    np.testing.assert_allclose(setup.physics.joint_positions(), setup.task.problem.key_points[0], atol=1e-12)
    model = setup.physics.model.ptr
    # A shell under a milligram is none (planbench.loader.physics.MIN_PAYLOAD_KG).
    from planbench.loader.physics import MIN_PAYLOAD_KG

    carried = p.payload_mass if p.payload_mass >= MIN_PAYLOAD_KG else 0.0
    assert model.body_mass[model.body("shell").id] == pytest.approx(carried, abs=1e-9)


@given(hexapod_params())
@SLOW
def test_any_valid_hexapod_parameters_build_and_plan(p):
    scenario = scenarios.get("hexapod-sync-move")
    trajectory = scenario.plan(p)
    setup = scenario.build(p)
    assert setup.task.duration == pytest.approx(trajectory.duration + hexapod.SETTLE_S)
    np.testing.assert_allclose(
        setup.physics.poses_from_qpos(setup.physics.data.qpos)[0], hexapod.pose_si(p.start_pose), atol=1e-9
    )


@given(antenna_sea_params())
@SLOW
def test_any_valid_antenna_sea_parameters_build_and_plan(p):
    scenario = scenarios.get("antenna-sea-state")
    assert scenario.plan(p).duration >= p.duration
    scenario.build(p)


@given(antenna_paper_params())
@SLOW
def test_any_valid_antenna_paper_parameters_build_and_plan(p):
    scenario = scenarios.get("antenna-paper-motion")
    assert scenario.plan(p).duration >= p.duration
    scenario.build(p)


@given(fast_tracking_params())
@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_any_valid_fast_tracking_parameters_plan(p):
    plan = fast.goal_plan(p)
    observation = next(s for s in plan.segments if s.name.startswith("observation"))
    assert observation.duration == pytest.approx(p.tracking, abs=1.0)


def test_fast_scans_and_switches_of_other_sizes_plan():
    scan = fast.FastScanParams(legs=2, leg_length=0.3, scan_speed=10.0, leg_spacing=0.1, source="3C 295")
    legs = [s for s in fast.goal_plan(scan).segments if s.name.startswith("leg")]
    assert len(legs) == 2
    switch = fast.FastSwitchParams(sources=("3C 286", "3C 295", "3C 286"), tracking=60.0)
    plan = fast.goal_plan(switch)
    assert [s.name for s in plan.segments if s.name.startswith("observation")] == [
        "observation (3C 286)",
        "observation (3C 295)",
        "observation (3C 286)",
    ]
    setup = scenarios.get("fast-source-switch").build(switch.replace(duration=0.5))
    assert setup.components.trajectory.duration == pytest.approx(plan.duration)


# ------------------------------------------------------------------ one bad field: refused by name


def _out_of_range(declared, column=None):
    low, high = params._bound(declared.low, column), params._bound(declared.high, column)
    if high is not None:
        return high + max(1.0, abs(high))
    return low - max(1.0, abs(low))


@pytest.mark.parametrize("cls", [*_classes(), *_plant_classes()], ids=lambda c: c.__name__)
def test_every_single_out_of_range_field_is_refused_with_its_name(cls):
    scenario = {**_classes(), **_plant_classes()}[cls]
    plant = cls in _plant_classes()
    base = scenario.plant if plant else scenario.params
    checked = 0
    for name, kind, declared, _default in cls.declarations():
        if declared.low is None and declared.high is None and declared.choices is None:
            continue
        if kind.kind in ("int", "float"):
            bad = _out_of_range(declared)
            bad = int(bad) if kind.kind == "int" else bad
        elif kind.kind == "str":
            bad = "no such " + name
        elif kind.kind == "vector" and kind.item.kind == "float":
            bad = list(getattr(base, name) or [0.0] * declared.length)
            bad[0] = _out_of_range(declared, 0)
        elif kind.kind == "vector" and kind.item.kind == "vector":
            bad = [list(row) for row in getattr(base, name)]
            bad[0][0] = _out_of_range(declared, 0)
        elif kind.kind == "vector" and kind.item.kind == "str":
            bad = ["no such source"] * (declared.min_items or 1)
        else:
            continue
        with pytest.raises(ParamError) as refused:
            base.replace(**{name: bad})
        assert str(refused.value).startswith(name), (name, str(refused.value))
        if plant:  # through a scenario file's, a campaign's or --set's [plant]: named as plant.KEY
            with pytest.raises(ParamError, match=rf"^plant\.{name}"):
                scenario.resolve_plant({name: bad})
        checked += 1
    assert checked >= 3


@given(st.sampled_from(["wind", "elevation", "dwell"]), st.floats(1.0, 1e300))
@settings(max_examples=40, deadline=None)
def test_out_of_range_by_any_amount_names_the_key_value_and_range(key, excess):
    declared = {n: d for n, _, d, _ in hexapod.HexapodParams.declarations()}[key]
    value = declared.high + excess
    with pytest.raises(ParamError, match=rf"^{key} = .* is outside \[{declared.low:g}, {declared.high:g}\]"):
        scenarios.get("hexapod-sync-move").resolve(**{key: value})


def test_wrong_types_and_unknown_keys_are_named():
    spec = scenarios.get("hexapod-sync-move")
    for overrides, words in [
        ({"wind": "strong"}, "wind = 'strong' is not a number"),
        ({"moves": [{"target": [1, 2]}]}, "moves[0].target has 2 values, not 6"),
        ({"moves": [{"targte": [0] * 6}]}, "unknown parameter 'moves[0].targte'"),
        ({"moves": []}, "moves has 0 items, fewer than 1"),
        ({"start_pose": [20, 0, 0, 0, 0, 0]}, "start_pose[0] = 20 mm is outside [-11.4, 11.4] mm"),
        ({"moves": [{"target": [0] * 6}]}, "moves[0].target equals the pose before it"),
        ({"hs": 3.0}, "unknown parameter 'hs'"),
    ]:
        with pytest.raises(ParamError) as refused:
            spec.resolve(overrides)
        assert words in str(refused.value), str(refused.value)


# ------------------------------------------------------------------ the CLI and the README


def _help(capsys, name):
    assert main(["run", name, "--help"]) == 0
    return capsys.readouterr().out


@pytest.mark.parametrize("name", list(scenarios.SCENARIOS))
def test_the_help_of_a_scenario_names_its_parameters_and_no_others(capsys, name):
    text = _help(capsys, name)
    cls = type(scenarios.get(name).params)
    mine = set(cls.names())
    for other_name in {n for c in _classes() for n in c.names()} - mine:
        assert f"--{other_name.replace('_', '-')} " not in text and f"  {other_name}:" not in text, other_name
    for key, kind, declared, _default in cls.declarations():
        line = f"--{key.replace('_', '-')} " if kind.scalar else f"  {key}:"
        assert line in text, key
        assert declared.help.split(";")[0][:40] in " ".join(text.split()), key
        if declared.unit and not isinstance(declared.unit, tuple):
            assert declared.unit in text


def test_the_readme_tables_are_the_declarations():
    readme = (ROOT / "README.md").read_text()
    for cls in _classes():
        assert params.markdown_table(cls) in readme, (
            f"README's table of {cls.__name__} differs: regenerate it with planbench.params.markdown_table"
        )
    # and the nested tables (a scenario's ``sensors``, list items): the whole generated section
    assert params.readme_tables().rstrip("\n") in readme, "README's parameter tables differ: python -m planbench.params"


# ------------------------------------------------------------------ scenario files


def _run(capsys, *argv):
    code = main(["run", *map(str, argv), "--quiet"])
    captured = capsys.readouterr()
    return code, captured


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_every_example_scenario_file_runs_through_the_cli(tmp_path, capsys, path):
    extra = [] if path.name not in EXAMPLE_DURATION_S else ["--duration", EXAMPLE_DURATION_S[path.name]]
    code, captured = _run(capsys, path, "--out", tmp_path / "out", *extra)
    assert code == 0, captured.out + captured.err
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    data = tomllib.loads(path.read_text())
    assert summary["scenario"] == data["scenario"]
    for key, value in data["parameters"].items():
        if key == "wind_file":
            assert Path(summary["parameters"][key]) == path.parent / value
        elif isinstance(value, dict):  # a nested table: the keys the file gives, the rest defaults
            assert {k: summary["parameters"][key][k] for k in value} == value, key
        elif key != "duration" or not extra:
            assert summary["parameters"][key] == value, key


def test_a_hexapod_list_of_three_moves_checks_each_arrival(tmp_path, capsys):
    code, captured = _run(
        capsys, EXAMPLES[[p.name for p in EXAMPLES].index("three_moves.toml")], "--out", tmp_path / "three"
    )
    assert code == 0, captured.out + captured.err
    summary = json.loads((tmp_path / "three" / "summary.json").read_text())
    moves = summary["metrics"]["moves"]
    assert [m["synchronous"] for m in moves] == [True, False, True]
    for m in moves:
        assert m["arrived"] and m["pose_error_um"] < hexapod.POSE_FINAL_LIMIT_UM
        if m["synchronous"]:
            assert m["arrival_spread_s"] <= hexapod.ARRIVAL_SPREAD_LIMIT_S
        else:
            assert m["arrival_vs_own_time_s"] <= 2 * hexapod.CONTROL_DT
    checks = {c["name"]: c for c in summary["checks"]}
    assert checks["pose_error_final"]["value"] == pytest.approx(max(m["pose_error_um"] for m in moves))
    assert "per move" in checks["pose_error_final"]["note"]
    starts = [m["start_s"] for m in moves]
    assert np.all(np.diff(starts) > 1.5)  # each after the one before plus the 1.5 s dwell


def test_a_short_list_of_moves_does_not_claim_the_later_arrivals():
    spec = scenarios.get("hexapod-async-move")
    p = spec.resolve(
        {
            "moves": [
                {"target": [1, 0, 0, 0, 0, 0], "synchronous": False},
                {"target": [0, 1, 0, 0, 0, 0], "synchronous": True},
            ],
            "wind": 0.0,
        }
    )
    first = spec.plan(p).pieces[0].duration
    result = runner.run("short", spec.build(p.replace(duration=first + 1.2)))
    by_name = {c.name: c for c in result.checks}
    assert not by_name["arrival_spread"].evaluated and "move 1" in by_name["arrival_spread"].note
    assert not by_name["pose_error_final"].passed


def test_fast_tracks_another_source_at_another_time_as_pyerfa_says():
    """The Crab from 2026-12-01T15:00 UTC: the goal plan's feed direction during the
    observation against pyerfa's ICRS -> observed (atco13, no refraction) at FAST's site."""
    p = fast.FastTrackingParams(source="Crab", start_utc="2026-12-01T15:00:00", tracking=600.0)
    plan = fast.goal_plan(p)
    observation = next(s for s in plan.segments if s.name.startswith("observation"))
    assert plan.info["observation_start_utc"].startswith("2026-12-01T15:00:00")
    tau = np.linspace(0.0, observation.duration, 7)
    _, feed, _, _ = plan.feed(observation.t0 + tau)
    d = -feed / np.linalg.norm(feed, axis=1, keepdims=True)  # the focal axis, toward the source
    az_plan = np.arctan2(d[:, 0], d[:, 1]) % (2 * np.pi)
    el_plan = np.arcsin(d[:, 2])
    jd1, jd2 = sky.utc_jd("2026-12-01T15:00:00", tau)
    ra, dec = fast.SOURCES["Crab"]
    site = sky.FAST_SITE
    aob, zob, *_ = erfa.atco13(
        ra,
        dec,
        0.0,
        0.0,
        0.0,
        0.0,
        jd1,
        jd2,
        0.0,
        site.longitude,
        site.latitude,
        site.height,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
    )
    arcsec = np.radians(1 / 3600)
    assert np.abs((az_plan - aob + np.pi) % (2 * np.pi) - np.pi).max() * np.cos(el_plan).max() < 30 * arcsec
    assert np.abs(el_plan - (np.pi / 2 - zob)).max() < 30 * arcsec
    # Another time is another place in the sky: an hour later the Crab has moved 15 deg in HA.
    later = fast.goal_plan(p.replace(start_utc="2026-12-01T16:00:00"))
    obs_later = next(s for s in later.segments if s.name.startswith("observation"))
    _, feed_later, _, _ = later.feed(np.array([obs_later.t0]))
    assert np.degrees(np.arccos(np.clip(-feed_later[0] / np.linalg.norm(feed_later[0]) @ d[0], -1, 1))) > 5.0


def test_a_source_that_leaves_fasts_sky_is_refused_with_its_keys(tmp_path, capsys):
    code, captured = _run(
        capsys, "fast-tracking", "--source", "Crab", "--start-utc", "2026-12-01T06:00:00", "--out", tmp_path / "out"
    )
    assert code == 2 and "source, start_utc, tracking" in captured.err and "40" in captured.err
    assert not (tmp_path / "out").exists()


def test_the_antenna_elsewhere_points_as_the_geostationary_formulas_say(tmp_path, capsys):
    """A ship at 15 N 62 E, a satellite at 64.2 E: the run's look angles against the
    spherical-Earth geostationary formulas (Pratt & Bostian; WGS84 differs by < 0.2 deg)."""
    lat, lon, sat = 15.0, 62.0, 64.2
    code, captured = _run(
        capsys,
        "antenna-sea-state",
        "--ship-lat",
        lat,
        "--ship-lon",
        lon,
        "--satellite-lon",
        sat,
        "--duration",
        3,
        "--out",
        tmp_path / "a",
    )
    assert code in (0, 1), captured.err
    az, el, _ = json.loads((tmp_path / "a" / "summary.json").read_text())["metrics"]["satellite_az_el_pol_deg"]
    phi, dl = np.radians(lat), np.radians(sat - lon)
    ratio = 6378.137 / 42164.0
    cos_gamma = np.cos(phi) * np.cos(dl)
    el_formula = np.degrees(np.arctan((cos_gamma - ratio) / np.sqrt(1 - cos_gamma**2)))
    az_formula = (180.0 - np.degrees(np.arctan2(np.tan(dl), np.sin(phi)))) % 360.0  # northern hemisphere
    assert el == pytest.approx(el_formula, abs=0.2) and az == pytest.approx(az_formula, abs=0.2)
    assert el > 60.0 and 90.0 < az < 180.0  # high in the south-east: just east of the ship's meridian


def test_a_resolved_summary_reruns_bit_identically(tmp_path, capsys):
    first, again = tmp_path / "first", tmp_path / "again"
    code, captured = _run(capsys, "antenna-sea-state", "--duration", 3, "--seed", 11, "--hs", 4, "--out", first)
    assert code in (0, 1), captured.err
    summary = json.loads((first / "summary.json").read_text())
    cls = antenna.AntennaSeaParams
    assert set(summary["parameters"]) == set(cls.names()) and summary["seed"] == 11
    assert set(summary["versions"]) >= {"planbench", "mujoco", "numpy", "scipy"}
    rerun, captured = _run(capsys, first / "summary.json", "--out", again)
    assert rerun == code, captured.err
    a, b = np.load(first / "timeseries.npz"), np.load(again / "timeseries.npz")
    assert set(a.files) == set(b.files)
    for key in a.files:
        assert a[key].tobytes() == b[key].tobytes(), key
    assert json.loads((again / "summary.json").read_text())["parameters"] == summary["parameters"]
    # A changed seed is another sea: the test can fail.
    code, _ = _run(capsys, first / "summary.json", "--seed", 12, "--out", tmp_path / "other")
    assert np.load(tmp_path / "other" / "timeseries.npz")["qpos"].tobytes() != a["qpos"].tobytes()


def test_scenario_file_errors_name_the_file_and_the_key(tmp_path, capsys):
    cases = [
        ('scenario = "hexapod-sync-move"\n[parameters]\nwnid = 3\n', "unknown parameter 'wnid'"),
        ('scenario = "hexapod-sync-move"\n[parameters]\nwind = "calm"\n', "wind = 'calm' is not a number"),
        ('scenario = "hexapod-sync-move"\n[parameters]\nwind = 80\n', "wind = 80 m/s is outside [0, 50] m/s"),
        ('scenario = "nope"\n', "unknown scenario 'nope'"),
        ('senario = "loader-supply"\n', "unknown key 'senario'"),
        ('scenario = "loader-supply"\n[parameters\n', "not TOML"),
    ]
    for i, (text, words) in enumerate(cases):
        path = tmp_path / f"bad{i}.toml"
        path.write_text(text)
        code, captured = _run(capsys, path, "--out", tmp_path / f"out{i}")
        assert code == 2 and len(captured.err.strip().splitlines()) == 1, captured.err
        assert str(path) in captured.err and words in captured.err, captured.err
        assert not (tmp_path / f"out{i}").exists()


def test_plan_takes_the_same_files_and_overrides(tmp_path, capsys):
    path = EXAMPLES[[p.name for p in EXAMPLES].index("three_moves.toml")]
    assert main(["plan", str(path), "--out", str(tmp_path / "p"), "--set", "dwell=2.0"]) == 0
    capsys.readouterr()
    plan = np.load(tmp_path / "p" / "plan.npz")
    spec = scenarios.get("hexapod-sync-move")
    expected = spec.plan(spec.resolve({**tomllib.loads(path.read_text())["parameters"], "dwell": 2.0}))
    assert plan["t"][-1] == pytest.approx(expected.duration, abs=2e-3)


def test_measured_wind_is_validated_and_resampled(tmp_path):
    from planbench.wind import MeasuredWind, WindFileError

    good = tmp_path / "w.csv"
    good.write_text("t,speed,direction\n0,4,0\n10,6,90\n")
    record = MeasuredWind(good)
    speed, direction = record.resample(np.array([0.0, 5.0, 10.0]))
    np.testing.assert_allclose(speed, [4.0, 5.0, 6.0])
    np.testing.assert_allclose(direction[1], [np.sqrt(0.5), np.sqrt(0.5), 0.0])
    for text, words in [
        ("0,4\n0,5\n", "does not increase"),
        ("0,4\n", "at least 2"),
        ("0,60\n1,4\n", "speed 60"),
        ("0,4\n1,x\n", "not numbers"),
        ("0,4,1\n1,5\n", "columns"),
    ]:
        bad = tmp_path / "bad.csv"
        bad.write_text(text)
        with pytest.raises(WindFileError, match=words):
            MeasuredWind(bad)
    with pytest.raises(ParamError, match="wind_file: .* spans t = 0 ... 10 s, not the run's 0 ... 20 s"):
        scenarios.get("fast-tracking").build(fast.FastTrackingParams(wind_file=str(good), duration=20.0))


def test_a_file_called_like_a_scenario_does_not_shadow_it(tmp_path, monkeypatch):
    from planbench.cli import _resolve_source

    monkeypatch.chdir(tmp_path)
    (tmp_path / "loader-supply").write_text("not a scenario file")
    source, _, params, _ = _resolve_source("run", ["loader-supply"])
    assert source.scenario.name == "loader-supply" and params == source.scenario.params


def test_a_scan_out_of_fasts_sky_names_the_source_keys():
    with pytest.raises(ParamError, match=r"^source, start_utc: .*zenith angle .*Table 1"):
        fast.goal_plan(fast.FastScanParams().replace(source_radec=(10.0, 80.0)))
