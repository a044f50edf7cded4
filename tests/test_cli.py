"""The planbench command line: outputs, exit codes, one-line errors, atomic writes."""

import json
import subprocess
import sys

import imageio_ffmpeg
import numpy as np
import pytest


def _video(path):
    """(header, frames (n, 480, 640, 3) uint8) of a 640 x 480 video. mediapy's reader does not
    parse this ffmpeg's header; imageio-ffmpeg reads it (its reader is closed while ffmpeg
    still runs: closed after the last frame it leaves ffmpeg's pipes open), and the frames are
    decoded by the same ffmpeg binary."""
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    reader.close()
    raw = subprocess.run(
        [imageio_ffmpeg.get_ffmpeg_exe(), "-v", "error", "-i", str(path), "-f", "rawvideo", "-pix_fmt", "rgb24", "-"],
        capture_output=True,
        check=True,
        timeout=120,
    ).stdout
    return meta, np.frombuffer(raw, np.uint8).reshape(-1, 480, 640, 3)


def planbench(*args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "planbench.cli", *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=300
    )


def in_process(capsys, *args):
    """``planbench ARGS`` run by ``planbench.cli.main`` in this process (the bad-input cases:
    the same parsing and checks, without a Python start each; the process-level contract is
    tested by test_bad_invocations and the cases here that start a process)."""
    from planbench.cli import main

    capsys.readouterr()
    code = main([str(a) for a in args])
    captured = capsys.readouterr()
    return subprocess.CompletedProcess(args, code, captured.out, captured.err)


def assert_one_line_error(proc, *words):
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert "Traceback" not in proc.stderr
    for w in words:
        assert w in lines[0], lines[0]


def test_list_names_every_scenario():
    proc = planbench("list")
    assert proc.returncode == 0
    names = [line.split()[0] for line in proc.stdout.splitlines()]
    # The mechanisms in their folders' name order, each's scenarios in the order it declares them.
    assert names == [
        "antenna-paper-motion",
        "antenna-sea-state",
        "fast-tracking",
        "fast-ra-scan",
        "fast-source-switch",
        "hexapod-sync-move",
        "hexapod-async-move",
        "loader-supply",
        "loader-direct",
    ]


def test_run_writes_summary_timeseries_report_and_video(tmp_path):
    out = tmp_path / "run"
    proc = planbench("run", "loader-supply", "--out", out, "--video", out / "loader.mp4", "--quiet")
    assert proc.returncode == 0, proc.stderr
    assert {p.name for p in out.iterdir()} == {
        "summary.json",
        "timeseries.npz",
        "report.png",
        "loader.mp4",
        "log.arrow",
        "planbench-manifest.json",
    }
    summary = json.loads((out / "summary.json").read_text())
    assert summary["scenario"] == "loader-supply" and summary["passed"] is True
    assert summary["sim_time_s"] == pytest.approx(3.0) and summary["realtime_factor"] > 0
    assert {c["name"] for c in summary["checks"]} >= {"keypoint_error", "obstacle_contacts"}
    ts = np.load(out / "timeseries.npz")
    assert ts["t"].shape[0] == ts["q_actual"].shape[0] == 601
    meta, frames = _video(out / "loader.mp4")
    assert tuple(meta["size"]) == (640, 480) and meta["fps"] == 30 and meta["codec"] == "h264"
    assert len(frames) >= 85  # 3 s at 30 fps
    assert frames[len(frames) // 2].std() > 10  # frames show something, not a blank buffer
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temp dirs left


def test_video_outside_the_output_dir(tmp_path):
    video = tmp_path / "videos" / "short.mp4"
    proc = planbench(
        "run",
        "loader-supply",
        "--out",
        tmp_path / "r",
        "--video",
        video,
        "--duration",
        "0.5",
        "--camera",
        "closeup",
        "--quiet",
    )
    assert proc.returncode == 0, proc.stderr
    assert imageio_ffmpeg.count_frames_and_secs(str(video))[0] == 16  # 0.5 s at 30 fps
    assert json.loads((tmp_path / "r" / "summary.json").read_text())["video"]["camera"] == "closeup"
    assert [p.name for p in video.parent.iterdir()] == ["short.mp4"]  # no temp file left


def test_failing_check_exits_1(tmp_path):
    proc = planbench("run", "loader-direct", "--out", tmp_path / "d", "--quiet", "--camera", "closeup")
    assert proc.returncode == 1, proc.stderr
    assert "obstacle_contacts" in proc.stdout and "FAIL" in proc.stdout
    assert json.loads((tmp_path / "d" / "summary.json").read_text())["passed"] is False


def test_unknown_scenario_exits_2(tmp_path):
    assert_one_line_error(
        planbench("run", "loader-teleport", "--out", tmp_path / "x"), "loader-teleport", "loader-supply"
    )
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize("duration", ["-1", "0", "nan", "abc"])
def test_bad_duration_exits_2(tmp_path, duration, capsys):
    assert_one_line_error(
        in_process(capsys, "run", "loader-supply", "--out", tmp_path / "x", f"--duration={duration}"), "duration"
    )
    assert not (tmp_path / "x").exists()


def test_unwritable_output_dir_exits_2(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("not a directory")
    assert_one_line_error(
        in_process(capsys, "run", "loader-supply", "--out", blocker / "out"), str(blocker), "not a directory"
    )
    assert_one_line_error(in_process(capsys, "run", "loader-supply", "--out", blocker), "not a directory")
    assert blocker.read_text() == "not a directory"


def test_other_bad_options_exit_2(tmp_path, capsys):
    assert_one_line_error(in_process(capsys, "run", "loader-supply", "--wind", "4"), "unrecognized arguments: --wind 4")
    assert_one_line_error(in_process(capsys, "run", "loader-supply", "--seed", "-3"), "seed")
    assert_one_line_error(
        in_process(capsys, "run", "loader-supply", "--camera", "top", "--out", tmp_path / "c"), "camera"
    )
    assert_one_line_error(in_process(capsys, "frobnicate"), "invalid choice")


def test_plan_writes_npz_and_plot(tmp_path):
    proc = planbench("plan", "loader-supply", "--out", tmp_path / "p")
    assert proc.returncode == 0, proc.stderr
    plan = np.load(tmp_path / "p" / "plan.npz")
    assert list(plan["labels"]) == ["slide", "shoulder", "elbow", "wrist_pitch", "wrist_yaw", "wrist_roll"]
    assert plan["t"][-1] == pytest.approx(2.5)
    assert plan["position"].shape == plan["velocity"].shape == plan["acceleration"].shape
    np.testing.assert_allclose(plan["position"][::500], plan["key_points"], atol=1e-12)
    assert (tmp_path / "p" / "plan.png").stat().st_size > 10_000
    assert_one_line_error(planbench("plan", "nope", "--out", tmp_path / "q"), "nope")


def test_hexapod_run_with_elevation_and_wind(tmp_path):
    out = tmp_path / "hx"
    proc = planbench(
        "run",
        "hexapod-async-move",
        "--elevation",
        "20",
        "--wind",
        "8",
        "--duration",
        "2",  # (options and outputs; whole runs under wind: test_campaign's local campaign)
        "--out",
        out,
        "--video",
        out / "hexapod.mp4",
        "--camera",
        "closeup",
        "--quiet",
    )
    # Cut short at 2 s, the 7.45 s move cannot arrive: the run fails exactly the checks that
    # need its end, as not evaluated; every other check is judged and passes.
    assert proc.returncode == 1, proc.stdout + proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    failed = {c["name"]: c["note"] for c in summary["checks"] if not c["passed"]}
    assert set(failed) == {"arrival_vs_own_time", "pose_error_final"}, failed
    assert all(note.startswith("not evaluated: the run ended at t = 2.000 s") for note in failed.values()), failed
    assert summary["metrics"]["elevation_deg"] == 20.0 and summary["metrics"]["wind_mean_m_s"] == 8.0
    assert {c["name"] for c in summary["checks"]} >= {"following_error", "pose_error_final", "stroke"}
    assert "magnified" in summary["video"]["shows"]
    ts = np.load(out / "timeseries.npz")
    assert ts["strut_position_actual"].shape == ts["strut_position_planned"].shape == (ts["t"].size, 6)
    assert ts["wind_force"].shape == (ts["t"].size, 3)
    frames = imageio_ffmpeg.count_frames_and_secs(str(out / "hexapod.mp4"))[0]
    assert frames == int(np.floor(summary["sim_time_s"] * 30)) + 1


def test_hexapod_bad_elevation_exits_2(tmp_path, capsys):
    assert_one_line_error(
        in_process(capsys, "run", "hexapod-sync-move", "--elevation", "10", "--out", tmp_path / "x"),
        "elevation = 10 deg",
        "[15, 90]",
    )
    assert_one_line_error(
        in_process(capsys, "run", "loader-supply", "--elevation", "45"), "unrecognized arguments: --elevation"
    )
    assert not (tmp_path / "x").exists()


def test_hexapod_plan(tmp_path):
    proc = planbench("plan", "hexapod-sync-move", "--out", tmp_path / "p")
    assert proc.returncode == 0, proc.stderr
    plan = np.load(tmp_path / "p" / "plan.npz")
    assert list(plan["labels"]) == [f"strut{i}" for i in range(1, 7)]
    assert np.abs(plan["velocity"]).max() <= 500e-6 and np.abs(plan["acceleration"]).max() <= 500e-6


def test_antenna_sea_state_run_with_sea_options(tmp_path):
    out = tmp_path / "sea"
    proc = planbench(
        "run",
        "antenna-sea-state",
        "--hs",
        "3",
        "--tp",
        "8",
        "--wave-heading",
        "90",
        "--duration",
        "4",
        "--out",
        out,
        "--video",
        out / "sea.mp4",
        "--quiet",
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert "Hs 3 m, Tp 8 s" in summary["metrics"]["ship_motion"]
    assert "90 deg off the bow" in summary["metrics"]["ship_motion"]
    assert {c["name"] for c in summary["checks"]} >= {
        "pointing_error_max",
        "pointing_error_rms",
        "polarization_error_max",
        "attitude_error_fro_max",
        "joint_rate",
        "joint_torque",
    }
    ts = np.load(out / "timeseries.npz")
    n = ts["t"].size
    assert ts["theta_actual"].shape == ts["theta_planned"].shape == (n, 4)
    assert ts["pointing_error_deg"].shape == (n,) and ts["update_t"].size == 199  # targets 0.04 ... 4.00 s
    assert imageio_ffmpeg.count_frames_and_secs(str(out / "sea.mp4"))[0] == 4 * 30 + 1


@pytest.mark.parametrize(
    "args, words",
    [
        (("antenna-sea-state", "--hs", "-2"), ("hs = -2 m", "(0, 20] m")),
        (("antenna-sea-state", "--tp", "nan"), ("tp = nan", "not finite")),
        (("antenna-paper-motion", "--hs", "4"), ("unrecognized arguments", "--hs")),
        (("hexapod-sync-move", "--wave-heading", "90"), ("unrecognized arguments", "--wave-heading")),
        (("antenna-sea-state", "--wind", "5"), ("unrecognized arguments", "--wind")),
        (("antenna-sea-state", "--set", "imu.rate_hz=30"), ("IMU rate 30 Hz", "whole number")),
        (("antenna-paper-motion", "--set", "imu.latency_s=0.012"), ("IMU latency 0.012 s", "5 ms")),
        (("loader-supply", "--prediction", "off"), ("unrecognized arguments", "--prediction")),
    ],
)
def test_antenna_bad_options_exit_2(tmp_path, args, words, capsys):
    assert_one_line_error(in_process(capsys, "run", *args, "--out", tmp_path / "x"), *words)
    assert not (tmp_path / "x").exists()


def test_antenna_plan(tmp_path):
    proc = planbench("plan", "antenna-paper-motion", "--out", tmp_path / "p")
    assert proc.returncode == 0, proc.stderr
    plan = np.load(tmp_path / "p" / "plan.npz")
    assert list(plan["labels"]) == ["azimuth", "elevation", "cross_elevation", "polarization"]
    assert plan["t"][-1] == pytest.approx(60.0)
    np.testing.assert_allclose(np.degrees(plan["position"][0]), [136.51, -60.0, 0.0, -28.8], atol=1e-9)
    methods = np.load(tmp_path / "p" / "methods.npz")
    assert methods["error_fro_pinv"][-1] > 1e-3  # the drift of section 5.2
    assert methods["error_fro_crr"].max() < 1e-6 and methods["error_fro_crr_full"].max() < 1e-10
    assert (tmp_path / "p" / "methods.png").stat().st_size > 10_000


def test_antenna_without_prediction_fails_the_paper_motion(tmp_path):
    """--prediction off: the 20 ms IMU latency and the 20 ms update interval become lag."""
    proc = planbench(
        "run",
        "antenna-paper-motion",
        "--prediction",
        "off",
        "--set",
        "imu.rate_hz=25",
        "--set",
        "imu.latency_s=0.04",
        "--duration",
        "3",
        "--out",
        tmp_path / "np",
        "--quiet",
    )
    assert proc.returncode == 1, proc.stdout + proc.stderr
    summary = json.loads((tmp_path / "np" / "summary.json").read_text())
    metrics = summary["metrics"]
    assert metrics["prediction"] is False and metrics["imu_rate_hz"] == 25.0
    assert metrics["imu_latency_s"] == 0.04 and metrics["planner_updates"] == 3 * 25 - 1
    failed = {c["name"] for c in summary["checks"] if not c["passed"]}
    assert "pointing_error_max" in failed


@pytest.mark.parametrize("name", ["fast-tracking", "fast-source-switch", "fast-ra-scan", "fast-dec-scan"])
def test_fast_plans(written_plan, name):
    code, out = written_plan(name)
    assert code == 0
    assert {p.name for p in out.iterdir()} == {
        "plan.npz",
        "plan.png",
        "figures.png",
        "segments.json",
        "planbench-manifest.json",
    }
    plan = np.load(out / "plan.npz")
    assert list(plan["labels"][:3]) == ["feed_x", "feed_y", "feed_z"] and plan["position"].shape[1] == 13
    assert np.linalg.norm(plan["velocity"][:, :3], axis=1).max() <= 0.4 + 1e-12
    segments = json.loads((out / "segments.json").read_text())["segments"]
    assert segments[0]["name"] == "switch-line" and any(s["name"] == "termination" for s in segments)


def test_fast_dec_scan_is_a_plan_only(tmp_path):
    assert_one_line_error(planbench("run", "fast-dec-scan", "--out", tmp_path / "x"), "unknown scenario")


def test_fast_run_outputs_and_stewart_option(tmp_path):
    out = tmp_path / "fast"
    proc = planbench(
        "run",
        "fast-tracking",
        "--duration",
        "3",
        "--stewart",
        "off",
        "--wind",
        "6",
        "--wind-direction",
        "90",
        "--out",
        out,
        "--video",
        out / "closeup.mp4",
        "--camera",
        "closeup",
        "--quiet",
    )
    assert proc.returncode in (0, 1), proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["metrics"]["stewart"] == "off" and summary["metrics"]["wind_mean_m_s"] == 6.0
    assert summary["metrics"]["wind_toward_deg"] == pytest.approx(90.0)
    names = {c["name"] for c in summary["checks"]}
    assert {
        "feed_error_rms",
        "feed_error_max",
        "cabin_error_rms",
        "cable_tension_min",
        "cable_tension_max",
        "stewart_stroke",
        "stewart_force",
    } <= names
    # 3 s lie in the switch: no observing segment, so the feed checks cover the whole run.
    assert "no observing segment" in next(c for c in summary["checks"] if c["name"] == "feed_error_rms")["note"]
    ts = np.load(out / "timeseries.npz")
    n = ts["t"].size
    assert n == 151  # 3 s of 20 ms ticks and the start
    for key in ("feed_pos_planned", "feed_pos_actual", "cabin_pos_actual"):
        assert ts[key].shape == (n, 3)
    assert ts["cable_tension"].shape == (n, 6) and ts["cable_tension"].min() > 100e3  # N
    assert np.abs(ts["stewart_leg"]).max() < 1e-3  # off: the legs hold nominal
    meta, frames = _video(out / "closeup.mp4")
    assert tuple(meta["size"]) == (640, 480)
    assert len(frames) >= 85 and frames[-1].std() > 10


def test_fast_bad_stewart_option(tmp_path, capsys):
    assert_one_line_error(
        in_process(capsys, "run", "fast-tracking", "--stewart", "maybe", "--out", tmp_path / "x"),
        "stewart = 'maybe' is not true or false",
    )
    assert_one_line_error(
        in_process(capsys, "run", "loader-supply", "--stewart", "on", "--out", tmp_path / "x"),
        "unrecognized arguments: --stewart on",
    )
    assert_one_line_error(in_process(capsys, "run", "fast-ra-scan", "--wind", "-1", "--out", tmp_path / "x"), "wind")
    assert_one_line_error(
        in_process(capsys, "run", "fast-ra-scan", "--wind-direction", "inf", "--out", tmp_path / "x"),
        "wind_direction = inf is not finite",
    )
    assert_one_line_error(
        in_process(capsys, "run", "hexapod-sync-move", "--wind-direction", "30", "--out", tmp_path / "x"),
        "unrecognized arguments: --wind-direction 30",
    )
    assert_one_line_error(
        in_process(capsys, "run", "fast-tracking", "--cable-segments", "1", "--out", tmp_path / "x"),
        "cable_segments = 1 is not a chain",
        "2 ... 14",
    )
    assert_one_line_error(
        in_process(capsys, "run", "fast-tracking", "--cable-segments", "20", "--out", tmp_path / "x"),
        "cable_segments = 20 is outside [0, 14]",
        "omega dt <= 0.7",
    )
    assert_one_line_error(
        in_process(capsys, "run", "loader-supply", "--cable-segments", "4", "--out", tmp_path / "x"),
        "unrecognized arguments: --cable-segments 4",
    )
    assert not (tmp_path / "x").exists()
