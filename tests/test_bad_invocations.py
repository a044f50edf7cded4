"""The CLI contract on bad input, table-driven over ``run``, ``plan``, ``demo``, ``bench`` and
``list``: exit 2, exactly one line on stderr that names the value and the limit, no
traceback, and nothing changed on disk (a snapshot of the directory around the outputs, which
is also the working directory, before and after).

``{tmp}`` in an argument is the test's directory; the fixture ``scene`` lays out what some
cases need there: a directory of the user's, a planbench output with a file added, a file, a
symbolic link, a foreign video and a directory named like a video.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from planbench.cli import main
from planbench.outputs import MANIFEST
from tests.test_outputs import _chattr, snapshot

LONG_NAME = "n" * 300
DEEP = "/".join(["d" * 200] * 21)  # 4221 bytes: over PATH_MAX

# (argv, substrings the one stderr line must contain)
CASES = [
    # -- output directories (run) ---------------------------------------------------------
    (["run", "loader-supply", "--out", "{tmp}/mydata"], ["{tmp}/mydata", "did not write it"]),
    (["run", "loader-supply", "--out", "."], ["{tmp}", "current directory"]),
    (["run", "loader-supply", "--out", ""], ["''", "empty"]),
    (["run", "loader-supply", "--out", "   "], ["empty"]),
    (["run", "loader-supply", "--out", "/"], ["output dir /", "root"]),
    (["run", "loader-supply", "--out", ".."], ["holds the current directory"]),
    (["run", "loader-supply", "--out", "{tmp}/sub/.."], ["{tmp}", "current directory"]),
    (["run", "loader-supply", "--out", "~"], ["home directory"]),
    (["run", "loader-supply", "--out", "{tmp}/notes.txt"], ["notes.txt", "not a directory"]),
    (["run", "loader-supply", "--out", "{tmp}/notes.txt/run"], ["notes.txt", "is not a directory"]),
    (["run", "loader-supply", "--out", "{tmp}/link"], ["link", "symbolic link"]),
    (["run", "loader-supply", "--out", "{tmp}/added"], ["added", "mine.txt", "did not write"]),
    (["run", "loader-supply", "--out", "/proc/planbench"], ["/proc", "nothing can be created"]),
    (["run", "loader-supply", "--out", "/sys/planbench/run"], ["/sys", "nothing can be created"]),
    (["run", "loader-supply", "--out", "/proc/self/planbench"], ["/proc/self", "nothing can be created"]),
    (["run", "loader-supply", "--out", "{tmp}/locked/run"], ["locked", "nothing can be created"]),
    (
        ["run", "loader-supply", "--out", "{tmp}/r", "--video", "{tmp}/locked/v.mp4"],
        ["locked", "nothing can be created"],
    ),
    (["plan", "loader-supply", "--out", "{tmp}/locked/p"], ["locked", "nothing can be created"]),
    (["run", "loader-supply", "--out", "{tmp}/" + LONG_NAME], ["300 bytes", "limit of 255"]),
    (["run", "loader-supply", "--out", "{tmp}/" + DEEP], ["bytes", "limit of 4095"]),
    # -- videos ---------------------------------------------------------------------------
    (["run", "loader-supply", "--out", "{tmp}/r", "--video", "{tmp}/v.webm"], ["v.webm", "'.webm'", ".mp4"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--video", "{tmp}/v.gif"], ["'.gif'", ".mkv"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--video", "{tmp}/video"], ["(none)", ".mp4"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--video", ""], ["''", "empty"]),
    (
        ["run", "loader-supply", "--out", "{tmp}/r", "--video", "{tmp}/r/report.png/v.mp4"],
        ["report.png", "would overwrite"],
    ),
    (
        ["run", "loader-supply", "--out", "{tmp}/r", "--video", "{tmp}/r/summary.json/v.mp4"],
        ["summary.json", "would overwrite"],
    ),
    (
        ["run", "loader-supply", "--out", "{tmp}/r", "--video", "{tmp}/r/" + MANIFEST + "/v.mp4"],
        [MANIFEST, "would overwrite"],
    ),
    (["run", "loader-supply", "--out", "{tmp}/r.mp4", "--video", "{tmp}/r.mp4"], ["r.mp4", "output directory itself"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--video", "{tmp}/holiday.mp4"], ["holiday.mp4", "did not write it"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--video", "{tmp}/clips.mp4"], ["clips.mp4", "is a directory"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--video", "{tmp}/vlink.mp4"], ["vlink.mp4", "symbolic link"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--video", "/proc/v.mp4"], ["/proc", "nothing can be created"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--video", "{tmp}/" + LONG_NAME + ".mp4"], ["304 bytes", "255"]),
    (
        ["run", "loader-supply", "--out", "{tmp}/r", "--video", "{tmp}/notes.txt/v.mp4"],
        ["notes.txt", "not a directory"],
    ),
    (["run", "loader-supply", "--out", "{tmp}/r", "--camera", ""], ["camera ''", "overview, closeup"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--camera", "top"], ["camera 'top'", "overview, closeup"]),
    # -- scenario and options -------------------------------------------------------------
    (["run", "nope", "--out", "{tmp}/r"], ["'nope'", "loader-supply"]),
    (["run", "", "--out", "{tmp}/r"], ["''", "known"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--seed", "-1"], ["seed = -1", "[0, 9223372036854775807]"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--seed", "1.5"], ["seed = 1.5", "not an integer"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--seed", str(2**63)], [str(2**63), "[0, 9223372036854775807]"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--duration", "0"], ["duration = 0 s", "[0.005, ...] s"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--duration", "-3"], ["duration = -3 s", "[0.005, ...] s"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--duration", "nan"], ["duration = nan", "not finite"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--duration", "inf"], ["duration = inf", "not finite"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--duration", "ten"], ["duration = 'ten'", "not a number"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--wind", "3"], ["unrecognized arguments", "--wind"]),
    (["run", "hexapod-sync-move", "--out", "{tmp}/r", "--wind", "-1"], ["wind = -1 m/s", "[0, 50] m/s"]),
    (["run", "hexapod-sync-move", "--out", "{tmp}/r", "--elevation", "10"], ["elevation = 10 deg", "[15, 90]"]),
    (["run", "hexapod-sync-move", "--out", "{tmp}/r", "--elevation", "95"], ["elevation = 95 deg", "[15, 90]"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--elevation", "45"], ["unrecognized arguments", "--elevation"]),
    (["run", "antenna-sea-state", "--out", "{tmp}/r", "--hs", "0"], ["hs = 0 m", "(0, 20] m"]),
    (["run", "antenna-sea-state", "--out", "{tmp}/r", "--tp", "-2"], ["tp = -2 s", "[1, 30] s"]),
    (["run", "antenna-paper-motion", "--out", "{tmp}/r", "--hs", "3"], ["unrecognized arguments", "--hs"]),
    (["run", "antenna-paper-motion", "--out", "{tmp}/r", "--set", "imu.rate_hz=30"], ["30", "200"]),
    (
        ["run", "antenna-paper-motion", "--out", "{tmp}/r", "--set", "imu.rate_hz=0"],
        ["imu.rate_hz = 0 Hz", "[1, 200] Hz"],
    ),
    (["run", "antenna-paper-motion", "--out", "{tmp}/r", "--set", "imu.latency_s=0.0123"], ["0.0123", "5 ms"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--prediction", "off"], ["unrecognized arguments", "--prediction"]),
    (["run", "fast-tracking", "--out", "{tmp}/r", "--stewart", "maybe"], ["stewart = 'maybe'", "not true or false"]),
    (["run", "fast-tracking", "--out", "{tmp}/r", "--cable-segments", "1"], ["cable_segments = 1", "14"]),
    (["run", "fast-tracking", "--out", "{tmp}/r", "--cable-segments", "x"], ["cable_segments = 'x'", "not an integer"]),
    (["run", "hexapod-sync-move", "--out", "{tmp}/r", "--stewart", "on"], ["unrecognized arguments", "--stewart"]),
    (
        ["run", "loader-supply", "--out", "{tmp}/r", "--cable-segments", "4"],
        ["unrecognized arguments", "--cable-segments"],
    ),
    # valid numbers that are not a run
    (
        ["run", "fast-tracking", "--out", "{tmp}/r", "--duration", "1e-6"],
        ["duration = 1e-06 s", "one control tick (20 ms)"],
    ),
    (
        ["run", "loader-supply", "--out", "{tmp}/r", "--duration", "0.004"],
        ["duration = 0.004 s", "one control tick (5 ms)"],
    ),
    (
        ["run", "fast-tracking", "--out", "{tmp}/r", "--duration", "1e12"],
        ["duration 1e+12 s", "PiB of log", "limit of"],
    ),
    (
        ["run", "hexapod-sync-move", "--out", "{tmp}/r", "--duration", "1e15"],
        ["duration 1e+15 s", "of log", "limit of"],
    ),
    (["run", "antenna-sea-state", "--out", "{tmp}/r", "--tp", "1e-3"], ["0.001 s", "[1, 30] s", "Munk"]),
    (["run", "antenna-sea-state", "--out", "{tmp}/r", "--tp", "1e4"], ["10000 s", "[1, 30] s", "Munk"]),
    (["run", "antenna-sea-state", "--out", "{tmp}/r", "--hs", "25"], ["hs = 25 m", "(0, 20] m"]),
    (
        ["run", "antenna-sea-state", "--out", "{tmp}/r", "--hs", "10", "--tp", "5"],
        ["hs = 10 m", "tp = 5 s", "DNV-RP-C205"],
    ),
    (
        ["run", "antenna-sea-state", "--out", "{tmp}/r", "--wave-heading", "1e308"],
        ["wave_heading = 1e+308 deg", "[-360, 360]", "not wrapped"],
    ),
    (["run", "fast-tracking", "--out", "{tmp}/r", "--wind-direction", "-1e308"], ["-1e+308 deg", "[-360, 360]"]),
    (["run", "fast-tracking", "--out", "{tmp}/r", "--cable-segments", "15"], ["cable_segments = 15", "[0, 14]"]),
    (["run", "fast-tracking", "--out", "{tmp}/r", "--cable-segments", "50"], ["cable_segments = 50", "[0, 14]"]),
    (["run", "fast-tracking", "--out", "{tmp}/r", "--wind", "1e308"], ["wind = 1e+308 m/s", "[0, 50] m/s"]),
    (["run", "antenna-paper-motion", "--out", "{tmp}/r", "--set", "imu.latency_s=1e9"], ["1e+09 s", "1 s"]),
    (["run", "antenna-paper-motion", "--out", "{tmp}/r", "--set", "imu.rate_hz=1e-300"], ["1e-300 Hz", "[1, 200] Hz"]),
    (["run", "loader-supply", "--out", "{tmp}/r", "--bogus"], ["--bogus"]),
    (["run"], ["give a scenario NAME"]),
    # -- plan -----------------------------------------------------------------------------
    (["plan", "nope", "--out", "{tmp}/p"], ["'nope'", "fast-dec-scan"]),
    (["plan", "loader-supply"], ["--out"]),
    (["plan", "loader-supply", "--out", "{tmp}/mydata"], ["mydata", "did not write it"]),
    (["plan", "loader-supply", "--out", ""], ["''", "empty"]),
    (["plan", "loader-supply", "--out", "."], ["current directory"]),
    (["plan", "loader-supply", "--out", "/"], ["root"]),
    (["plan", "loader-supply", "--out", "{tmp}/notes.txt"], ["notes.txt", "not a directory"]),
    (["plan", "loader-supply", "--out", "/proc/plan"], ["/proc", "nothing can be created"]),
    (["plan", "fast-dec-scan", "--out", "{tmp}/p", "--bogus", "1"], ["--bogus"]),
    # -- demo -----------------------------------------------------------------------------
    (["demo", "--out", ""], ["''", "empty"]),
    (["demo", "--out", "{tmp}/notes.txt"], ["notes.txt", "not a directory"]),
    (["demo", "--out", "{tmp}/results"], ["results/loader-supply", "did not write it"]),
    (["demo", "--out", "/proc/demo"], ["/proc", "nothing can be created"]),
    (["demo", "--out", "{tmp}/" + LONG_NAME], ["300 bytes", "255"]),
    (["demo", "--bogus"], ["--bogus"]),
    # -- bench, list, the command itself --------------------------------------------------
    (["bench", "--out", "{tmp}/b"], ["--out"]),
    (["bench", "extra"], ["extra"]),
    (["list", "extra"], ["extra"]),
    (["list", "--all"], ["--all"]),
    ([], ["command"]),
    (["frobnicate"], ["'frobnicate'", "choose from"]),
]


@pytest.fixture
def scene(tmp_path, monkeypatch):
    """The test's directory (also the working directory), laid out for the cases; ``locked``
    is an immutable directory (chattr +i; read-only mode bits where not root, since root
    writes through them)."""
    monkeypatch.chdir(tmp_path)
    locked = tmp_path / "locked"
    locked.mkdir()
    if not _chattr("+i", locked) and os.geteuid() != 0:
        locked.chmod(0o555)
    yield _lay_out(tmp_path)
    _chattr("-i", locked)
    locked.chmod(0o755)


def _lay_out(tmp_path):
    (tmp_path / "mydata").mkdir()
    (tmp_path / "mydata" / "thesis.tex").write_text("years of work")
    (tmp_path / "notes.txt").write_text("notes")
    (tmp_path / "sub").mkdir()
    (tmp_path / "target").mkdir()
    (tmp_path / "link").symlink_to(tmp_path / "target")
    added = tmp_path / "added"
    added.mkdir()
    (added / "summary.json").write_text("{}")
    (added / MANIFEST).write_text(
        json.dumps({"written_by": "planbench", "target": "added", "files": ["summary.json", MANIFEST]})
    )
    (added / "mine.txt").write_text("mine")
    (tmp_path / "holiday.mp4").write_bytes(b"\x00\x00\x00\x18ftypmp42 someone's video")
    (tmp_path / "clips.mp4").mkdir()
    (tmp_path / "vlink.mp4").symlink_to(tmp_path / "holiday.mp4")
    (tmp_path / "results" / "loader-supply").mkdir(parents=True)
    (tmp_path / "results" / "loader-supply" / "plot.png").write_bytes(b"the user's plot")
    return tmp_path


def test_the_table_is_large_enough():
    commands = {argv[0] for argv, _ in CASES if argv}
    assert len(CASES) >= 60 and commands == {"run", "plan", "demo", "bench", "list", "frobnicate"}


@pytest.mark.parametrize("argv, expected", CASES, ids=[" ".join(a)[:60] or "(none)" for a, _ in CASES])
def test_bad_invocation(argv, expected, scene, capsys):
    tmp = str(scene)
    if "{tmp}/locked" in " ".join(argv) and os.access(scene / "locked", os.W_OK):
        pytest.skip("no immutable or read-only directory can be made here")
    argv = [a.replace("{tmp}", tmp) for a in argv]
    before = snapshot(scene)
    code = main(argv)
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert code == 2, (code, captured.out, captured.err)
    assert len(lines) == 1, lines
    assert "Traceback" not in captured.err and lines[0].startswith("planbench: error: ")
    for text in expected:
        assert text.replace("{tmp}", tmp) in lines[0], (text, lines[0])
    assert snapshot(scene) == before


@pytest.mark.parametrize(
    "argv",
    [
        ["run", "loader-supply", "--out", "{tmp}/mydata"],
        ["run", "loader-supply", "--out", "{tmp}/r", "--duration", "nan"],
        ["demo", "--out", "{tmp}/results"],
    ],
)
def test_bad_invocation_as_a_process(argv, scene):
    """The same contract seen from the shell: no traceback reaches the terminal."""
    argv = [a.replace("{tmp}", str(scene)) for a in argv]
    before = snapshot(scene)
    root = Path(__file__).resolve().parents[1]
    proc = subprocess.run(
        [sys.executable, "-m", "planbench.cli", *argv],
        capture_output=True,
        text=True,
        cwd=scene,
        env={**os.environ, "PYTHONPATH": str(root)},
    )
    assert proc.returncode == 2 and len(proc.stderr.splitlines()) == 1, proc.stderr
    assert "Traceback" not in proc.stderr and proc.stdout == ""
    assert snapshot(scene) == before
