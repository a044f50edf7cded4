"""A run's log streams to disk in chunks (planbench.logfile): every row arrives, at every chunk
boundary; a log cut short by SIGKILL reads back as its whole chunks, marked incomplete; the
streamed log holds exactly the state MuJoCo had at each tick; two runs write the same bytes;
a log that would not fit on the disk is refused before any work."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from planbench import api, logfile, outputs, run_limits, runner, scenarios
from planbench.cli import main
from planbench.logfile import ChunkWriter, read_log

ROOT = Path(__file__).resolve().parents[1]
SHAPES = {"qpos": (3,), "act": (0,), "mocap_pos": (2, 3)}


def _write(path, n, chunk, history, stop_at=None, block=()):
    """Rows 0..n-1 of known values through a ChunkWriter as the runner records them (a row
    is written when its tick comes; the buffer flushes when a row falls past its end);
    ``block``: the arrays that share one buffer row."""
    times = np.arange(n) * 0.01
    writer = ChunkWriter(path, SHAPES, times, chunk=chunk, history=history, block=block)
    for i in range(n):
        if i == writer.end:
            writer.flush()
        j = i - writer.base
        writer.buffers["qpos"][j] = [i, -i, 0.5 * i]
        writer.buffers["mocap_pos"][j] = np.arange(6).reshape(2, 3) + i
        if history and i >= 1:  # the rows a few ticks back are still there
            k = max(i - history, writer.base, 0)
            assert writer.buffers["qpos"][k - writer.base][0] == k
        if stop_at is not None and i == stop_at:
            return writer
    writer.close(n)
    return writer


def test_a_block_row_is_its_arrays_side_by_side(tmp_path):
    writer = ChunkWriter(tmp_path / "log.arrow", SHAPES, np.zeros(3), chunk=2, block=("mocap_pos", "act", "qpos"))
    assert writer.block.shape == (2, 9)
    writer.block[1] = np.arange(9.0)  # one copy fills every array of the block
    np.testing.assert_array_equal(writer.buffers["mocap_pos"][1], np.arange(6.0).reshape(2, 3))
    np.testing.assert_array_equal(writer.buffers["qpos"][1], [6.0, 7.0, 8.0])
    assert writer.buffers["act"].shape == (2, 0) and not writer.buffers["qpos"][0].any()
    writer.abandon()


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(1, 40),
    chunk=st.integers(1, 9),
    history=st.integers(0, 4),
    block=st.sampled_from([(), ("qpos", "act", "mocap_pos"), ("mocap_pos", "qpos")]),
)
def test_every_row_arrives_at_every_chunk_boundary(tmp_path_factory, n, chunk, history, block):
    path = tmp_path_factory.mktemp("log") / "log.arrow"
    _write(path, n, chunk, history, block=block)
    log = read_log(path)
    assert log.complete and log.n == n
    assert log.rows == [chunk] * (n // chunk) + ([n % chunk] if n % chunk else [])
    np.testing.assert_array_equal(log.column("t"), np.arange(n) * 0.01)
    np.testing.assert_array_equal(log.column("qpos")[:, 0], np.arange(n))
    np.testing.assert_array_equal(log.column("qpos")[:, 2], 0.5 * np.arange(n))
    assert log.column("act").shape == (n, 0) and log.column("mocap_pos").shape == (n, 2, 3)
    np.testing.assert_array_equal(log.column("mocap_pos")[:, 1, 2], 5 + np.arange(n))
    rows = sum(c["qpos"].shape[0] for c in log.chunks())
    assert rows == n


@settings(max_examples=40, deadline=None)
@given(n=st.integers(0, 30), chunk=st.integers(1, 7), start=st.integers(0, 35), length=st.integers(0, 35))
def test_a_temporary_log_s_rows_and_spans(n, chunk, start, length):
    """Rows written through ``row`` (a temporary log) read back; any span of them is the
    whole array's slice; the file is gone once read back."""
    writer = logfile.temporary_writer(SHAPES, np.arange(n) * 0.01, chunk=chunk)
    for i in range(n):
        writer.row("qpos", i)[:] = [i, -i, 0.5 * i]
        writer.row("mocap_pos", i)[:] = np.arange(6).reshape(2, 3) + i
    log = writer.read_back(n)
    assert log.complete and log.n == n and not writer.path.exists()
    for name in ("qpos", "mocap_pos", "act", "t"):
        np.testing.assert_array_equal(log.span(name, start, start + length), log.column(name)[start : start + length])
    np.testing.assert_array_equal(log.column("qpos")[:, 1], -np.arange(n))


@settings(max_examples=25, deadline=None)
@given(n=st.integers(1, 30), chunk=st.integers(1, 7), stride=st.integers(1, 5))
def test_a_timeseries_copied_from_the_log_is_savez_s(tmp_path_factory, n, chunk, stride):
    """timeseries.npz with the log's arrays copied a chunk at a time holds what
    np.savez_compressed writes of the whole arrays, in the same order."""
    writer = logfile.temporary_writer(SHAPES, np.arange(n) * 0.01, chunk=chunk)
    for i in range(n):
        writer.row("qpos", i)[:] = [i, -i, 0.5 * i]
        writer.row("mocap_pos", i)[:] = np.arange(6).reshape(2, 3) * i
    log = runner.RunLog(file=writer.read_back(n))
    names = ("t", "qpos", "act", "mocap_pos")
    series = {"names": np.array(["a", "bc"]), "series": np.arange(7.0) / 3}
    _assert_npz_as_savez(
        tmp_path_factory.mktemp("npz"),
        {**{k: logfile.LoggedSeries(log.file, k, stride=stride) for k in names}, **series},
        {**{k: log.file.column(k)[::stride] for k in names}, **series},
    )


def _assert_npz_as_savez(folder, streamed: dict, whole: dict) -> None:
    """``save_timeseries(streamed)`` holds what ``np.savez_compressed(whole)`` does: the same
    arrays, in the same order, of the same types."""
    outputs.save_timeseries(folder / "streamed.npz", streamed)
    np.savez_compressed(folder / "whole.npz", **whole)
    written, expected = np.load(folder / "streamed.npz"), np.load(folder / "whole.npz")
    assert list(written.keys()) == list(expected.keys())
    for key in expected.keys():
        assert written[key].dtype == expected[key].dtype
        np.testing.assert_array_equal(written[key], expected[key])


@settings(max_examples=25, deadline=None)
@given(n=st.integers(1, 40), chunk=st.integers(1, 9), seed=st.integers(0, 2**32 - 1))
def test_a_spooled_series_reads_back_as_the_arrays_it_was_given(tmp_path_factory, n, chunk, seed):
    """A series spooled to a temporary log a chunk at a time (``LoggedSeries``: FAST's 10 Hz
    series) reads back whole, by parts and scaled as the arrays themselves, booleans and
    integers of their own type, and timeseries.npz holds what np.savez_compressed writes."""
    rng = np.random.default_rng(seed)
    arrays = {
        "error": rng.normal(size=n),
        "tension": rng.normal(size=(n, 6)),
        "observing": rng.random(n) < 0.5,
        "segment": rng.integers(0, 9, n).astype(np.int32),
    }
    writer = logfile.temporary_writer({k: v.shape[1:] for k, v in arrays.items()}, np.arange(n) * 0.1, chunk=1)
    for lo in range(0, n, chunk):
        writer.append({k: np.asarray(v[lo : lo + chunk], float) for k, v in arrays.items()})
    spooled = writer.read_back(n)
    assert not writer.path.exists()  # (the open file keeps the data)
    series = {k: logfile.LoggedSeries(spooled, k, v.dtype) for k, v in arrays.items()}
    for key, value in arrays.items():
        read = np.asarray(series[key])
        assert read.dtype == value.dtype and series[key].shape == value.shape and len(series[key]) == n
        np.testing.assert_array_equal(read, value)
        np.testing.assert_array_equal(np.concatenate(list(series[key].parts())), value)
        np.testing.assert_array_equal(series[key][-1], value[-1])
    np.testing.assert_array_equal(np.asarray(1e3 * series["tension"]), 1e3 * arrays["tension"])
    with pytest.raises(TypeError):
        1e3 * series["observing"]  # scaling is for float series
    _assert_npz_as_savez(
        tmp_path_factory.mktemp("npz"),
        {**series, "mm": 1e3 * series["error"]},
        {**arrays, "mm": 1e3 * arrays["error"]},
    )


@settings(max_examples=50, deadline=None)
@given(n=st.integers(1, 200), span=st.integers(1, 30), seed=st.integers(0, 2**32 - 1))
def test_a_long_reports_envelope_keeps_every_span_s_extremes(n, span, seed):
    """report.png draws a long run as envelopes: each span's smallest and largest value at the
    span's first and middle time, so that no peak of the series is lost to the thinning."""
    from planbench.fast.report import envelope, envelope_of_parts, envelope_times

    rng = np.random.default_rng(seed)
    values, t = rng.normal(size=(n, 3)), np.cumsum(rng.random(n))
    drawn, times = envelope(values, span), envelope_times(t, span)
    # The same, made a part at a time (a spooled series' chunks), however the parts fall.
    cuts = np.sort(rng.integers(0, n + 1, rng.integers(0, 6)))
    np.testing.assert_array_equal(envelope_of_parts(np.split(values, cuts), span), drawn)
    m = -(-n // span)
    assert drawn.shape == (2 * m, 3) and times.shape == (2 * m,)
    for k in range(m):
        part = values[k * span : (k + 1) * span]
        np.testing.assert_array_equal(drawn[2 * k], part.min(axis=0))
        np.testing.assert_array_equal(drawn[2 * k + 1], part.max(axis=0))
        assert times[2 * k] == t[k * span] <= times[2 * k + 1] <= t[min(n, (k + 1) * span) - 1]
    np.testing.assert_array_equal(drawn.max(axis=0), values.max(axis=0))
    np.testing.assert_array_equal(drawn.min(axis=0), values.min(axis=0))
    assert np.all(np.diff(times) >= 0)


@pytest.mark.parametrize("n, chunk", [(1, 4), (4, 4), (8, 4), (9, 4)])
def test_one_tick_one_chunk_and_chunk_multiples(tmp_path, n, chunk):
    _write(tmp_path / "log.arrow", n, chunk, 2)
    log = read_log(tmp_path)
    assert log.complete and log.n == n and log.num_chunks == -(-n // chunk)


KILLED = textwrap.dedent("""
    import os, signal, sys
    sys.path.insert(0, sys.argv[2])
    import tests.test_logfile as t
    t._write(sys.argv[1], 100, 8, 3, stop_at=int(sys.argv[3]))
    os.kill(os.getpid(), signal.SIGKILL)
""")


@pytest.mark.parametrize("stop_at", [0, 5, 8, 21, 40])
def test_a_killed_writer_leaves_its_whole_chunks_marked_incomplete(tmp_path, stop_at):
    path = tmp_path / "log.arrow"
    proc = subprocess.run([sys.executable, "-c", KILLED, str(path), str(ROOT), str(stop_at)])
    assert proc.returncode == -signal.SIGKILL
    log = read_log(path)
    assert not log.complete
    assert log.n == (stop_at // 8) * 8  # the chunks flushed before the kill, not the buffer
    np.testing.assert_array_equal(log.column("qpos")[:, 0], np.arange(log.n))


def test_a_file_that_is_no_log_is_named(tmp_path):
    (tmp_path / "log.arrow").write_bytes(b"not arrow at all")
    with pytest.raises(ValueError, match="is not a planbench log"):
        read_log(tmp_path)


def _setup(name="loader-supply", duration=0.4, **params):
    scenario = scenarios.get(name)
    return scenario.build(scenario.resolve(duration=duration, **params))


@pytest.mark.parametrize("name", ["loader-supply", "hexapod-sync-move"])
@pytest.mark.parametrize("chunk", [1, 7, 80, 81, 4096])
def test_the_streamed_log_is_the_state_at_every_tick(monkeypatch, tmp_path, name, chunk):
    """Each row of the file against MuJoCo's state copied right after each mj_step (the
    runner's step: one call per control tick), and against the runner's own defaults."""
    seen = []
    step = mujoco.mj_step

    def stepping(model, data, nstep=1):
        step(model, data, nstep=nstep)
        seen.append(
            (
                data.qpos.copy(),
                data.qvel.copy(),
                data.act.copy(),
                data.actuator_force.copy(),
                data.sensordata.copy(),
                data.ctrl.copy(),
            )
        )

    setup = _setup(name, duration=0.405)  # 81 ticks after the start (5 ms ticks)
    monkeypatch.setattr(runner.mujoco, "mj_step", stepping)
    log = runner.simulate(setup, log_path=tmp_path / "log.arrow", chunk_ticks=chunk)
    monkeypatch.undo()
    n = log.n
    assert n == len(seen) + 1 == 82 and log.file.complete
    for k, name_ in enumerate(("qpos", "qvel", "act", "actuator_force", "sensordata")):
        np.testing.assert_array_equal(getattr(log, name_)[1:], np.array([s[k] for s in seen]))
    np.testing.assert_array_equal(log.ctrl[:-1], np.array([s[5] for s in seen]))  # applied over each step
    np.testing.assert_array_equal(log.t, setup.task.times()[:n])
    other = runner.simulate(_setup(name, duration=0.405), chunk_ticks=4096)
    for key in ("t", *logfile.ARRAYS):
        np.testing.assert_array_equal(getattr(log, key), getattr(other, key), err_msg=key)


def test_a_run_ended_by_its_controller_mid_chunk_keeps_the_rows_up_to_it(tmp_path):
    setup = _setup()
    controller = setup.components.controller
    calls = []

    class Failing:
        def reset(self, context):
            controller.reset(context)

        def __call__(self, tick, observation):
            calls.append(tick)
            if tick == 30:
                raise RuntimeError("boom")
            return controller(tick, observation)

    setup.components.controller = Failing()
    log = runner.simulate(setup, log_path=tmp_path / "log.arrow", chunk_ticks=8)
    assert log.controller_error is not None and log.n == 31 and log.file.complete
    np.testing.assert_array_equal(log.ctrl[30], log.ctrl[29])  # the last good command, held
    assert log.t[-1] == pytest.approx(30 * 0.005)


def test_two_runs_write_the_same_bytes(tmp_path):
    for k in (1, 2):
        runner.simulate(_setup(duration=0.3), log_path=tmp_path / f"{k}.arrow", chunk_ticks=16)
    assert (tmp_path / "1.arrow").read_bytes() == (tmp_path / "2.arrow").read_bytes()


def test_a_written_run_holds_its_log(tmp_path):
    result = api.run("loader-supply", params={"duration": 0.3}, out=tmp_path / "out")
    log = read_log(tmp_path / "out")
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert log.complete and summary["log"] == {"path": "log.arrow", "ticks": 61, "complete": True, "chunks": 1}
    np.testing.assert_array_equal(log.column("qpos"), result.log.qpos)
    assert "log.arrow" in outputs.read_manifest(tmp_path / "out")["files"]


def test_a_run_without_outputs_leaves_no_log_behind(tmp_path, monkeypatch):
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", None)
    log = runner.simulate(_setup(duration=0.3))
    assert log.qpos.shape[0] == 61
    assert list(tmp_path.iterdir()) == []  # removed once written; the log keeps it open


# ---------------------------------------------------------------- a killed run, end to end


def _staged_log(parent: Path):
    for entry in parent.glob(outputs.STAGING_PREFIX + "*"):
        if (entry / "log.arrow").is_file():
            return entry
    return None


def _signal_mid_run(tmp_path: Path, out: Path, whom: str, signum: int):
    """Start ``planbench run loader-supply`` (200 s) into ``out`` and, once its streamed log
    holds a whole chunk, send ``signum`` to the simulating child (``whom`` "child") or to
    planbench itself ("planbench"). Returns (the child's pid or None if the run ended first,
    stdout, stderr, exit code)."""
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "planbench.cli",
            "run",
            "loader-supply",
            "--duration",
            "200",
            "--out",
            str(out),
            "--quiet",
        ],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        child = None
        while proc.poll() is None:
            staged = _staged_log(tmp_path)
            if staged is not None:
                try:
                    if read_log(staged / "log.arrow").n >= logfile.CHUNK_TICKS:
                        child = json.loads((staged / outputs.STAGING_MARKER).read_text())["pid"]
                        os.kill(child if whom == "child" else proc.pid, signum)
                        break
                except (ValueError, OSError):
                    pass
            time.sleep(0.05)
        stdout, stderr = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    return child, stdout, stderr, proc.returncode


def test_a_killed_run_leaves_its_log_so_far_in_its_output(tmp_path):
    """``planbench run`` whose simulating process is killed (SIGKILL) mid-run: the output
    holds summary.json (completed false) and log.arrow, its whole chunks, incomplete, equal
    to the first rows of the same run completed."""
    out = tmp_path / "out"
    child, stdout, stderr, returncode = _signal_mid_run(tmp_path, out, "child", signal.SIGKILL)
    assert child is not None, (stdout, stderr)  # the run was still going at its first chunk
    assert returncode == 1, stderr
    assert "killed by SIGKILL" in stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["completed"] is False and summary["log"]["complete"] is False
    log = read_log(out / "log.arrow")
    assert not log.complete and log.n >= logfile.CHUNK_TICKS and log.n % logfile.CHUNK_TICKS == 0
    assert summary["log"]["ticks"] == log.n
    assert _staged_log(tmp_path) is None  # nothing left beside the output
    full = runner.simulate(_setup(duration=log.n * 0.005))
    np.testing.assert_array_equal(log.column("qpos"), full.qpos[: log.n])
    np.testing.assert_array_equal(log.column("ctrl"), full.ctrl[: log.n])


def test_an_interrupted_run_leaves_nothing(tmp_path):
    """SIGTERM to planbench itself mid-run (a user's interrupt, not the time limit): exit
    128 + 15, and nothing in the output's folder, neither the output nor a staging directory
    with the log so far."""
    child, _, stderr, returncode = _signal_mid_run(tmp_path, tmp_path / "out", "planbench", signal.SIGTERM)
    assert child is not None, stderr  # the run was still going at its first chunk
    assert returncode == 128 + signal.SIGTERM and "interrupted by SIGTERM" in stderr, stderr
    assert list(tmp_path.iterdir()) == []


#: A controller that hangs at tick HANG_TICK: the time limit then finds the run in its loop,
#: with two whole chunks written, however long the machine takes to get there.
HANG_TICK = 2 * logfile.CHUNK_TICKS + 7
HANGING_CONTROLLER = textwrap.dedent(f"""
    import time
    from planbench.loader import reference_controller

    class Controller:
        def reset(self, context):
            self.inner = reference_controller()
            return self.inner.reset(context)

        def __call__(self, tick, observation):
            if tick == {HANG_TICK}:
                time.sleep(3600)
            return self.inner(tick, observation)
""")


def test_a_run_past_its_time_limit_leaves_its_log_so_far_in_its_output(tmp_path):
    """``planbench run --timeout``: the simulating process stopped at the limit (SIGTERM, then
    its clean-up) leaves summary.json (completed false) and log.arrow, its whole chunks,
    readable, incomplete, equal to the first rows of the same run completed."""
    out = tmp_path / "out"
    (tmp_path / "hang.py").write_text(HANGING_CONTROLLER)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "planbench.cli",
            "run",
            "loader-supply",
            "--duration",
            "300",
            "--controller",
            "hang.py:Controller",
            "--timeout",
            "10",
            "--out",
            str(out),
            "--quiet",
        ],
        env=env,
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert proc.returncode == 1, proc.stderr
    assert "passed its time limit" in proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["completed"] is False and summary["log"]["complete"] is False
    log = read_log(out / "log.arrow")
    assert not log.complete and log.n == 2 * logfile.CHUNK_TICKS  # the whole chunks before the hang
    assert summary["log"]["ticks"] == log.n
    assert _staged_log(tmp_path) is None  # nothing left beside the output
    full = runner.simulate(_setup(duration=log.n * 0.005))
    np.testing.assert_array_equal(log.column("qpos"), full.qpos[: log.n])


# ---------------------------------------------------------------- the disk-space refusal


def test_a_log_beyond_the_free_space_is_refused_with_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(run_limits, "free_bytes", lambda directory: 10 * 2**20)
    code = main(["run", "loader-supply", "--duration", "100", "--out", str(tmp_path / "out"), "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1
    assert "duration 100 s needs ~" in err[0] and "of log, more than the limit of 10 MiB (the free space" in err[0]
    assert not (tmp_path / "out").exists()
    main(["run", "loader-supply", "--duration", "1", "--out", str(tmp_path / "out"), "--quiet"])
    assert read_log(tmp_path / "out").complete


def test_the_output_location_is_checked_before_the_first_step(tmp_path, monkeypatch):
    """The parameters pass against the current directory; the output's file system is full."""
    small = tmp_path / "small"
    small.mkdir()
    monkeypatch.setattr(run_limits, "free_bytes", lambda directory: 2**20 if Path(directory) == small else 2**40)
    monkeypatch.setattr(runner, "simulate", lambda *a, **k: pytest.fail("simulated"))
    with pytest.raises(
        run_limits.RunLimitError,
        match=rf"more than the limit of 1 MiB \(the free space on the file "
        rf"system of {small}\)",
    ):
        api.run("loader-supply", params={"duration": 20}, out=small / "out")
    assert list(small.iterdir()) == []


# ---------------------------------------------------------------- evaluation by chunks


def test_fast_checks_do_not_depend_on_the_chunks(tmp_path, monkeypatch):
    """FAST's evaluation reads the log a chunk at a time: with 7-tick chunks and every 3rd row
    kept it gives the very check values, metrics and timeseries that the same log held
    whole (one chunk) gives, and the values the whole arrays give directly."""
    scenario = scenarios.get("fast-source-switch")
    setup = scenario.build(scenario.resolve(duration=1.0))
    evaluation = setup.task.evaluation
    evaluation.stride = 3
    log = runner.simulate(setup, log_path=tmp_path / "log.arrow", chunk_ticks=7)
    assert log.file.num_chunks == 8  # 51 ticks
    chunked = evaluation.evaluate(log)
    series = evaluation.timeseries(log)
    assert not any(log.held(name) for name in logfile.ARRAYS)  # never read whole
    # The 10 Hz series are spooled to disk as the chunks are read, not held.
    assert all(isinstance(v, logfile.LoggedSeries) for v in evaluation.summary(log)["every"].values())
    whole = runner.RunLog(**{name: log.file.column(name) for name in ("t", *logfile.ARRAYS)}, reference=log.reference)
    held = evaluation.evaluate(whole)
    assert [c.to_json() for c in chunked[0]] == [c.to_json() for c in held[0]]
    assert json.dumps(chunked[1], sort_keys=True) == json.dumps(held[1], sort_keys=True)
    for key, value in evaluation.timeseries(whole).items():
        np.testing.assert_array_equal(series[key], value, err_msg=key)
    p = evaluation.physics
    tension = -whole.actuator_force[:, p.cable_ids]
    row, cable = np.unravel_index(np.argmin(tension), tension.shape)
    check = {c.name: c for c in chunked[0]}["cable_tension_min"]
    assert check.value == float(tension.min()) / 1e3
    assert f"cable{cable + 1} at t = {whole.t[row]:.2f} s" in check.note
    np.testing.assert_array_equal(series["cable_tension"], tension[::3])
    np.testing.assert_array_equal(series["stewart_leg"], whole.qpos[::3, p.leg_qpos])
    # Past REPORT_POINTS rows the report draws envelopes of the spooled series.
    from planbench.fast import report

    for points, name in ((10, "envelopes.png"), (10**6, "every-row.png")):
        monkeypatch.setattr(report, "REPORT_POINTS", points)
        evaluation.report(log, chunked[0], tmp_path / name)
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_run_written_after_the_fact_gets_a_copy_of_its_log(tmp_path):
    """write_run of a result whose log streamed to a temporary file (no staging directory
    given) copies it in, chunk by chunk, complete."""
    setup = _setup(duration=0.3)
    result = runner.run("loader-supply", setup)
    outputs.write_run(result, setup, tmp_path / "out")
    log = read_log(tmp_path / "out")
    assert log.complete and log.n == result.log.n == 61
    np.testing.assert_array_equal(log.column("sensordata"), result.log.sensordata)
