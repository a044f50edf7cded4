"""Outputs of a run, written atomically: a temporary directory beside the target, renamed.

A failed or interrupted write leaves no half-written directory or video behind.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np


class OutputError(ValueError):
    """The output location cannot be written."""


def check_writable(path: Path, what: str) -> None:
    """Fail early, before simulating, if ``path`` (a file or directory) cannot be created.

    Its nearest existing ancestor must be a writable directory and ``path`` itself must not
    be an existing entry of the wrong kind.
    """
    path = Path(path)
    parent = path.parent
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise OutputError(f"{what} {path}: {parent} is not a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputError(f"{what} {path}: directory {parent} is not writable")
    if what == "output dir" and path.exists() and not path.is_dir():
        raise OutputError(f"{what} {path} exists and is not a directory")
    if what == "video" and path.is_dir():
        raise OutputError(f"{what} {path} is a directory")


def summary_dict(result) -> dict:
    return {
        "scenario": result.scenario,
        "passed": result.passed,
        "seed": result.seed,
        "sim_time_s": result.sim_time_s,
        "wall_time_s": round(result.wall_time_s, 4),
        "realtime_factor": round(result.sim_time_s / result.wall_time_s, 3) if result.wall_time_s > 0 else None,
        "checks": [c.to_json() for c in result.checks],
        "metrics": result.metrics,
    }


def _usual_mode(path: Path, mode: int) -> None:
    """mkdtemp/mkstemp make private entries (0700/0600); give ``path`` ``mode`` less the umask."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(path, mode & ~umask)


def replace_dir(tmp: Path, target: Path) -> None:
    """Rename ``tmp`` to ``target``, replacing an existing ``target`` directory."""
    _usual_mode(tmp, 0o777)
    if target.exists():
        old = Path(tempfile.mkdtemp(prefix=f".{target.name}.old-", dir=target.parent))
        os.rename(target, old / target.name)
        os.rename(tmp, target)
        shutil.rmtree(old, ignore_errors=True)
    else:
        os.rename(tmp, target)


@contextlib.contextmanager
def atomic_dir(out_dir: Path):
    """Yield a temporary directory beside ``out_dir`` that replaces it on success.

    On any exception (or interrupt) the temporary directory is removed and ``out_dir`` is
    left as it was.
    """
    out_dir = Path(out_dir).absolute()
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.tmp-", dir=out_dir.parent))
    try:
        yield tmp
        replace_dir(tmp, out_dir)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def write_run(result, setup, out_dir: Path, video: Path | None = None, camera: str = "overview",
              quiet: bool = True, more_videos: tuple = ()) -> dict:
    """Write summary.json, timeseries.npz, report.png (and the video) of ``result``.

    The video goes into the same temporary directory when it lies inside ``out_dir``, else
    into a temporary file beside it; both are renamed into place only when everything is
    written. ``more_videos``: (file name, camera) pairs of further videos inside ``out_dir``
    (the demo's close-ups). Returns the summary.
    """
    from sims.render import render_video

    out_dir = Path(out_dir).absolute()
    video_tmp = None
    try:
        with atomic_dir(out_dir) as tmp:
            summary = summary_dict(result)
            log = result.log
            arrays = {"t": log.t, "qpos": log.qpos, "qvel": log.qvel, "ctrl": log.ctrl,
                      "act": log.act, "actuator_force": log.actuator_force,
                      "sensordata": log.sensordata}
            arrays.update(setup.timeseries(log))
            if setup.output_stride > 1:  # every stride-th tick of the per-tick arrays
                n = log.t.size
                arrays = {k: v[::setup.output_stride] if np.ndim(v) and np.shape(v)[0] == n else v
                          for k, v in arrays.items()}
                summary["timeseries_every_s"] = float(log.t[setup.output_stride] - log.t[0]) if n > setup.output_stride else None
            np.savez_compressed(tmp / "timeseries.npz", **arrays)
            setup.report(log, result.checks, tmp / "report.png")
            if video is not None:
                video = Path(video).absolute()
                if video.is_relative_to(out_dir):
                    target = tmp / video.relative_to(out_dir)
                    target.parent.mkdir(parents=True, exist_ok=True)
                else:
                    video.parent.mkdir(parents=True, exist_ok=True)
                    fd, name = tempfile.mkstemp(prefix=f".{video.stem}.tmp-", suffix=video.suffix,
                                                dir=video.parent)
                    os.close(fd)
                    video_tmp = target = Path(name)
                frames = render_video(setup.physics.model.ptr, log, target, camera=camera,
                                      speed=setup.video_speed, quiet=quiet,
                                      frame_qpos=setup.video_qpos)
                summary["video"] = {"path": str(video), "frames": frames, "camera": camera}
                if setup.video_note:
                    summary["video"]["shows"] = setup.video_note
            for name, extra_camera in more_videos:
                frames = render_video(setup.physics.model.ptr, log, tmp / name, camera=extra_camera,
                                      speed=setup.video_speed, quiet=quiet, frame_qpos=setup.video_qpos)
                summary.setdefault("more_videos", []).append(
                    {"path": str(out_dir / name), "frames": frames, "camera": extra_camera})
            (tmp / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
        if video_tmp is not None:
            _usual_mode(video_tmp, 0o666)
            os.replace(video_tmp, video)
        return summary
    except BaseException:
        if video_tmp is not None and video_tmp.exists():
            video_tmp.unlink()
        raise
