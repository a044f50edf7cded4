"""Offscreen video of a run: replay the logged states through ``mujoco.Renderer``.

The OpenGL back end is chosen in ``sims/__init__.py`` (EGL, falling back to OSMesa). Videos are
H.264 written by mediapy through the ffmpeg binary that the imageio-ffmpeg package ships, so
no system ffmpeg is needed.
"""

from __future__ import annotations

import imageio_ffmpeg
import mediapy
import mujoco
import numpy as np
from tqdm import tqdm

from planbench.outputs import VIDEO_TAG

mediapy.set_ffmpeg(imageio_ffmpeg.get_ffmpeg_exe())

WIDTH, HEIGHT, FPS = 640, 480, 30
MAX_VIDEO_S = 60.0


def frame_ticks(t: np.ndarray, speed: float, fps: int = FPS) -> np.ndarray:
    """Logged tick shown in each video frame.

    ``speed`` is simulated seconds per video second (0.5 slow motion, 20 time-lapse); it is
    raised so that the video lasts at most MAX_VIDEO_S.
    """
    duration = float(t[-1] - t[0])
    speed = max(speed, duration / MAX_VIDEO_S)
    n_frames = max(1, int(np.floor(duration / speed * fps)) + 1)
    frame_times = t[0] + np.arange(n_frames) * speed / fps
    return np.clip(np.searchsorted(t, frame_times - 1e-9), 0, t.size - 1)


def render_video(
    model: mujoco.MjModel,
    log,
    path,
    camera: str = "overview",
    speed: float = 1.0,
    width: int = WIDTH,
    height: int = HEIGHT,
    fps: int = FPS,
    quiet: bool = True,
    frame_qpos=None,
) -> int:
    """Write the run ``log`` as an H.264 video at ``path``; returns the number of frames.

    ``frame_qpos``: optional (log, ticks) -> (len(ticks), nq) states to show instead of the
    logged ones (``Setup.video_qpos``).
    """
    if camera not in [model.camera(i).name for i in range(model.ncam)]:
        known = ", ".join(model.camera(i).name for i in range(model.ncam))
        raise ValueError(f"unknown camera {camera!r}; this model has: {known}")
    if width > model.vis.global_.offwidth or height > model.vis.global_.offheight:
        raise ValueError(
            f"video {width}x{height} exceeds the model's offscreen buffer "
            f"{model.vis.global_.offwidth}x{model.vis.global_.offheight}"
        )
    data = mujoco.MjData(model)
    ticks = frame_ticks(log.t, speed, fps)
    qpos = log.qpos[ticks] if frame_qpos is None else frame_qpos(log, ticks)
    renderer = mujoco.Renderer(model, height=height, width=width)
    try:
        # The tag is planbench's proof that it may replace this file later (planbench.outputs).
        with mediapy.VideoWriter(
            path, shape=(height, width), fps=fps, codec="h264", qp=20, ffmpeg_args=["-metadata", f"comment={VIDEO_TAG}"]
        ) as writer:
            for frame, i in enumerate(
                tqdm(ticks, unit="frame", disable=quiet, delay=2.0, leave=False, desc="rendering")
            ):
                data.qpos[:] = qpos[frame]
                data.qvel[:] = log.qvel[i]
                if model.nmocap:
                    data.mocap_pos[:] = log.mocap_pos[i]
                    data.mocap_quat[:] = log.mocap_quat[i]
                mujoco.mj_forward(model, data)
                renderer.update_scene(data, camera=camera)
                writer.add_image(renderer.render())
    finally:
        renderer.close()
    return int(ticks.size)
