"""Data safety of planbench's outputs: nothing of the user's deleted, whole replacement that a
reader never sees missing, one writer at a time, no leftovers after failures, kills and
interrupts (README, "Outputs and interrupts")."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from planbench import outputs
from planbench.cli import main
from planbench.outputs import MANIFEST, OutputDir, OutputError, VideoFile

PLANBENCH = [sys.executable, "-m", "planbench.cli"]
ROOT = Path(__file__).resolve().parents[1]


def planbench(*args, cwd=None, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run(PLANBENCH + [str(a) for a in args], capture_output=True, text=True, cwd=cwd or ROOT, **kwargs)


def snapshot(directory: Path) -> dict:
    """Every entry below ``directory`` with its size and content hash (files) or None (dirs)."""
    out = {}
    for root, dirs, files in os.walk(directory):
        for d in dirs:
            out[os.path.relpath(os.path.join(root, d), directory)] = None
        for f in files:
            p = os.path.join(root, f)
            out[os.path.relpath(p, directory)] = Path(p).read_bytes() if not os.path.islink(p) else "link"
    return out


def write_dummy(target: OutputDir, text: str) -> None:
    with target.staging() as tmp:
        (tmp / "summary.json").write_text(json.dumps({"run": text}))


def run_quick(out, *more, cwd=None):
    return planbench("run", "loader-supply", "--duration", "0.3", "--quiet", "--out", out, *more, cwd=cwd)


def test_user_directory_survives_run_and_plan(tmp_path, capsys):
    mine = tmp_path / "mydata"
    mine.mkdir()
    (mine / "notes.txt").write_text("my thesis")
    before = snapshot(tmp_path)
    for argv in (
        ["run", "loader-supply", "--duration", "0.3", "--quiet", "--out", str(mine)],
        ["plan", "loader-supply", "--out", str(mine)],
    ):
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and str(mine) in err[0] and "did not write it" in err[0]
    assert snapshot(tmp_path) == before


def test_a_file_added_to_a_planbench_directory_protects_it(tmp_path, capsys):
    out = tmp_path / "run"
    write_dummy(OutputDir(out), "first")
    (out / "my-notes.txt").write_text("keep me")
    with pytest.raises(OutputError, match=r"holds files planbench did not write \(my-notes.txt\)"):
        OutputDir(out)
    (out / "my-notes.txt").unlink()
    (out / "sub").mkdir()
    with pytest.raises(OutputError, match=r"\(sub\)"):
        OutputDir(out)
    (out / "sub").rmdir()
    (out / MANIFEST).write_text("{not json")
    with pytest.raises(OutputError, match="planbench did not write it"):
        OutputDir(out)


@pytest.mark.parametrize(
    "raw, why",
    [
        (".", "is the current directory"),
        ("", "is empty"),
        ("/", "root"),
        ("..", "holds the current directory"),
        ("~", "home directory"),
    ],
)
def test_refused_targets(raw, why, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(OutputError, match=why):
        OutputDir(raw)


def test_planbench_directory_is_replaced_whole(tmp_path):
    out = tmp_path / "run"
    proc = run_quick(out, "--video", out / "first.mp4")
    assert proc.returncode == 0, proc.stderr
    first = json.loads((out / "summary.json").read_text())
    assert (out / "first.mp4").exists() and "first.mp4" in json.loads((out / MANIFEST).read_text())["files"]
    proc = run_quick(out, "--seed", "3")
    assert proc.returncode == 0, proc.stderr
    second = json.loads((out / "summary.json").read_text())
    assert first["seed"] == 0 and second["seed"] == 3
    assert not (out / "first.mp4").exists()  # the old output went whole
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]  # no staging, lock or probe left
    manifest = json.loads((out / MANIFEST).read_text())
    assert manifest["written_by"] == "planbench" and manifest["target"] == "run"
    assert sorted(manifest["files"]) == sorted(p.name for p in out.iterdir())


def test_video_outside_replaces_only_planbench_videos(tmp_path):
    video = tmp_path / "clip.mp4"
    proc = run_quick(tmp_path / "a", "--video", video)
    assert proc.returncode == 0, proc.stderr
    assert outputs.is_planbench_video(video)
    stamp = video.stat().st_mtime_ns
    proc = run_quick(tmp_path / "a", "--video", video)
    assert proc.returncode == 0, proc.stderr
    assert video.stat().st_mtime_ns != stamp
    foreign = tmp_path / "holiday.mp4"
    foreign.write_bytes(b"\x00\x00\x00\x18ftypmp42 not ours")
    proc = run_quick(tmp_path / "b", "--video", foreign)
    assert proc.returncode == 2 and "planbench did not write it" in proc.stderr
    assert foreign.read_bytes() == b"\x00\x00\x00\x18ftypmp42 not ours" and not (tmp_path / "b").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a", "clip.mp4", "holiday.mp4"]


@pytest.mark.parametrize("suffix", outputs.VIDEO_SUFFIXES)
def test_every_accepted_video_suffix_is_written_and_tagged(suffix, tmp_path):
    import mujoco

    from planbench.render import render_video
    from planbench.runner import RunLog

    model = mujoco.MjModel.from_xml_string(
        '<mujoco><visual><global offwidth="64" offheight="48"/></visual><worldbody>'
        '<camera name="overview" pos="0 0 1"/><geom size=".1"/></worldbody></mujoco>'
    )
    n = 4
    log = RunLog(
        t=np.arange(n) / 30,
        qpos=np.zeros((n, 0)),
        qvel=np.zeros((n, 0)),
        act=None,
        ctrl=None,
        actuator_force=None,
        sensordata=None,
        mocap_pos=None,
        mocap_quat=None,
        reference=None,
    )
    path = tmp_path / f"v{suffix}"
    assert render_video(model, log, path, width=64, height=48) == n
    assert path.stat().st_size > 0 and outputs.is_planbench_video(path)


def _reader_script(path: Path, seconds: float) -> str:
    return textwrap.dedent(f"""
        import json, time
        misses = reads = 0
        end = time.time() + {seconds}
        while time.time() < end:
            try:
                with open({str(path)!r}) as f:
                    json.loads(f.read())
                reads += 1
            except FileNotFoundError:
                misses += 1
        print(reads, misses)
    """)


@pytest.mark.parametrize("exchange", [True, False], ids=["rename-exchange", "per-file-fallback"])
def test_reader_never_finds_summary_missing(exchange, tmp_path, monkeypatch):
    monkeypatch.setattr(outputs, "USE_EXCHANGE", exchange)
    out = tmp_path / "run"
    write_dummy(OutputDir(out), "0")
    reader = subprocess.Popen(
        [sys.executable, "-c", _reader_script(out / "summary.json", 3.0)], stdout=subprocess.PIPE, text=True
    )
    time.sleep(0.3)  # the reader is polling
    seen = []
    for i in range(1, 21):
        write_dummy(OutputDir(out), str(i))
        seen.append(json.loads((out / "summary.json").read_text())["run"])
    reads, misses = map(int, reader.communicate(timeout=30)[0].split())
    assert seen == [str(i) for i in range(1, 21)]
    assert reads > 100 and misses == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "summary.json"]


def test_second_writer_is_refused_while_the_first_holds_the_target(tmp_path):
    out = tmp_path / "run"
    first = OutputDir(out)
    with first.reserved():
        with pytest.raises(OutputError, match=rf"being written by another planbench run \(pid {os.getpid()}\)"):
            with OutputDir(out).reserved():
                pass
        proc = run_quick(out)
        assert proc.returncode == 2 and "being written by another planbench run" in proc.stderr
        assert proc.stderr.count("\n") == 1 and not out.exists()
    write_dummy(OutputDir(out), "after")  # free again
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]


def test_two_concurrent_cli_runs_do_not_both_succeed(tmp_path):
    out = tmp_path / "run"
    args = PLANBENCH + ["run", "loader-supply", "--quiet", "--out", str(out), "--video", str(out / "v.mp4")]
    a = subprocess.Popen(args, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 60
    while not list(tmp_path.glob(".planbench-lock-*")) and time.time() < deadline:
        time.sleep(0.02)
    b = subprocess.run(args, cwd=ROOT, capture_output=True, text=True)
    a_out, a_err = a.communicate(timeout=300)
    assert a.returncode == 0, a_err
    assert b.returncode == 2 and "being written by another planbench run" in b.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["scenario"] == "loader-supply" and (out / "v.mp4").exists()


def _start_video_run(out: Path) -> subprocess.Popen:
    return subprocess.Popen(
        PLANBENCH + ["run", "loader-supply", "--quiet", "--out", str(out), "--video", str(out / "v.mp4")],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def _wait_for_ffmpeg(proc: subprocess.Popen, timeout: float = 120.0) -> None:
    """Until the run's process group has an ffmpeg child (the video is being written)."""
    deadline = time.time() + timeout
    while time.time() < deadline:
        found = subprocess.run(["pgrep", "-g", str(proc.pid), "ffmpeg"], capture_output=True, text=True)
        if found.stdout.strip():
            time.sleep(0.2)
            return
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.02)
    raise AssertionError("the run never started ffmpeg")


@pytest.mark.skipif(shutil.which("pgrep") is None, reason="needs pgrep")
def test_sigint_to_the_process_group_while_rendering(tmp_path):
    out = tmp_path / "run"
    write_dummy(OutputDir(out), "old")
    before = snapshot(tmp_path)
    proc = _start_video_run(out)
    _wait_for_ffmpeg(proc)
    os.killpg(proc.pid, signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130
    assert stderr.splitlines() == ["planbench: interrupted by SIGINT; nothing half-written was left"]
    assert snapshot(tmp_path) == before  # the old output untouched, nothing beside it


@pytest.mark.skipif(shutil.which("pgrep") is None, reason="needs pgrep")
def test_sigkill_mid_write_then_a_new_run_cleans_up(tmp_path):
    out = tmp_path / "run"
    proc = _start_video_run(out)
    _wait_for_ffmpeg(proc)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.communicate(timeout=60)
    left = sorted(p.name for p in tmp_path.iterdir())
    assert any(n.startswith(outputs.STAGING_PREFIX) for n in left), left  # the killed run's
    foreign = tmp_path / (outputs.STAGING_PREFIX + "users-own")
    foreign.mkdir()
    (foreign / "data.txt").write_text("not planbench's")
    proc = run_quick(out)
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([foreign.name, "run"])
    assert (foreign / "data.txt").read_text() == "not planbench's"  # not provably ours: kept


def test_failed_write_leaves_old_output_and_nothing_beside_it(tmp_path):
    out = tmp_path / "run"
    write_dummy(OutputDir(out), "old")
    before = snapshot(tmp_path)
    with pytest.raises(RuntimeError):
        with OutputDir(out).staging() as tmp:
            (tmp / "summary.json").write_text("half")
            raise RuntimeError("renderer died")
    assert snapshot(tmp_path) == before


def test_failed_write_removes_the_parents_it_created(tmp_path):
    target = OutputDir(tmp_path / "a" / "b" / "run")
    with pytest.raises(RuntimeError):
        with target.staging():
            raise RuntimeError("died")
    assert list(tmp_path.iterdir()) == []


def _chattr(flag: str, path: Path) -> bool:
    if shutil.which("chattr") is None:
        return False
    return subprocess.run(["chattr", flag, str(path)], capture_output=True).returncode == 0


def test_immutable_directories_are_refused_up_front(tmp_path):
    locked = tmp_path / "locked"
    locked.mkdir()
    if not _chattr("+i", locked):
        if os.geteuid() == 0:
            pytest.skip("chattr +i is not available here")
        locked.chmod(0o555)  # without root a read-only mode is enough
    try:
        with pytest.raises(OutputError, match="nothing can be created in"):
            OutputDir(locked / "run")
        with pytest.raises(OutputError, match="nothing can be created in"):
            VideoFile(locked / "v.mp4")
    finally:
        _chattr("-i", locked)
        locked.chmod(0o755)
    assert list(locked.iterdir()) == []


def test_video_inside_out_may_not_shadow_the_runs_files(tmp_path):
    out = OutputDir(tmp_path / "run")
    for bad in ("summary.json", "report.png/v.mp4", "timeseries.npz/x.mkv", MANIFEST + "/v.mp4"):
        with pytest.raises(OutputError):
            VideoFile(tmp_path / "run" / bad, out)
    assert VideoFile(tmp_path / "run" / "videos" / "v.mp4", out).relative == Path("videos/v.mp4")


def test_a_manifest_listing_paths_outside_is_not_planbenchs(tmp_path):
    out = tmp_path / "run"
    write_dummy(OutputDir(out), "first")
    victim = tmp_path / "victim.txt"
    victim.write_text("outside")
    manifest = json.loads((out / MANIFEST).read_text())
    for bad in ("../victim.txt", str(victim), "sub/../../victim.txt", ""):
        (out / MANIFEST).write_text(json.dumps({**manifest, "files": manifest["files"] + [bad]}))
        with pytest.raises(OutputError, match="planbench did not write it"):
            OutputDir(out)
    assert victim.read_text() == "outside"


def test_files_added_to_the_target_during_the_run_are_kept(tmp_path):
    out = tmp_path / "run"
    write_dummy(OutputDir(out), "old")
    target = OutputDir(out)  # validated: only planbench's files
    with pytest.raises(OutputError, match=r"gained notes.txt during the run; .* output is in .*run\.new-"):
        with target.staging() as tmp:
            (tmp / "summary.json").write_text(json.dumps({"run": "new"}))
            (out / "notes.txt").write_text("written while it ran")
    assert (out / "notes.txt").read_text() == "written while it ran"
    assert json.loads((out / "summary.json").read_text()) == {"run": "old"}
    [kept] = tmp_path.glob("run.new-*")
    assert json.loads((kept / "summary.json").read_text()) == {"run": "new"}
    assert json.loads((kept / MANIFEST).read_text())["target"] == kept.name
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["run", kept.name])


@pytest.mark.parametrize("exchange", [True, False], ids=["rename-exchange", "per-file-fallback"])
def test_the_old_output_loses_only_its_listed_files(exchange, tmp_path, monkeypatch):
    """Past every check (a file that appears between the last check and the swap): the old
    output's own files go, anything else is kept where the user can see it."""
    monkeypatch.setattr(outputs, "USE_EXCHANGE", exchange)
    out = tmp_path / "run"
    write_dummy(OutputDir(out), "old")
    (out / "late.txt").write_text("mine")
    new = outputs._new_staging(tmp_path, "run")
    (new / "summary.json").write_text(json.dumps({"run": "new"}))
    (new / MANIFEST).write_text(
        json.dumps({"written_by": "planbench", "target": "run", "files": ["summary.json", MANIFEST]})
    )
    (new / outputs.STAGING_MARKER).unlink()
    outputs.swap_in(new, out)
    assert json.loads((out / "summary.json").read_text()) == {"run": "new"}
    if exchange:
        [kept] = tmp_path.glob("run.kept-*")
        assert sorted(p.name for p in kept.iterdir()) == ["late.txt"]  # no manifest: never ours again
    else:
        assert (out / "late.txt").read_text() == "mine"


def test_a_video_that_appears_during_the_run_is_kept(tmp_path):
    video = VideoFile(tmp_path / "clip.mp4")
    with video.reserved():
        with video.staging() as path:
            path.write_bytes(b"rendered")
        (tmp_path / "clip.mp4").write_bytes(b"someone else's")
        with pytest.raises(OutputError, match=r"appeared during the run .* video is .*clip\.new-.*\.mp4"):
            video.commit()
    assert (tmp_path / "clip.mp4").read_bytes() == b"someone else's"
    [kept] = tmp_path.glob("clip.new-*.mp4")
    assert kept.read_bytes() == b"rendered"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["clip.mp4", kept.name])


def _output_with_a_linked_folder(tmp_path):
    """A planbench output ``run`` listing videos/v.mp4, whose folder ``videos`` was then
    replaced by a link to the user's folder holding a v.mp4 of their own."""
    out = tmp_path / "run"
    with OutputDir(out).staging() as tmp:
        (tmp / "videos").mkdir()
        (tmp / "videos" / "v.mp4").write_bytes(b"ours")
    shutil.rmtree(out / "videos")
    elsewhere = tmp_path / "my-videos"
    elsewhere.mkdir()
    (elsewhere / "v.mp4").write_bytes(b"the user's")
    (out / "videos").symlink_to(elsewhere)
    return out, elsewhere


def test_a_symbolic_link_in_a_planbench_directory_is_foreign(tmp_path):
    out, elsewhere = _output_with_a_linked_folder(tmp_path)
    with pytest.raises(OutputError, match=r"holds files planbench did not write \(videos"):
        OutputDir(out)


@pytest.mark.parametrize("exchange", [True, False], ids=["rename-exchange", "per-file-fallback"])
def test_deleting_the_old_output_never_follows_a_link(exchange, tmp_path, monkeypatch):
    """Past every check (a link that appears between the last check and the swap): the file
    the link leads to survives."""
    monkeypatch.setattr(outputs, "USE_EXCHANGE", exchange)
    out, elsewhere = _output_with_a_linked_folder(tmp_path)
    new = outputs._new_staging(tmp_path, "run")
    (new / "summary.json").write_text("{}")
    (new / MANIFEST).write_text(
        json.dumps({"written_by": "planbench", "target": "run", "files": ["summary.json", MANIFEST]})
    )
    (new / outputs.STAGING_MARKER).unlink()
    outputs.swap_in(new, out)
    assert (elsewhere / "v.mp4").read_bytes() == b"the user's"
    assert (out / "summary.json").read_text() == "{}"
