"""planbench's simulation layer: runner, controllers, disturbances, checks, rendering, CLI.

MuJoCo picks its OpenGL back end when it is first imported, so the choice is made here,
before anything imports mujoco: EGL (headless GPU or Mesa) when libEGL is present, else
OSMesa (software). A user's MUJOCO_GL always wins.
"""

import ctypes.util
import os


def _default_gl() -> str:
    if ctypes.util.find_library("EGL"):
        return "egl"
    return "osmesa"


os.environ.setdefault("MUJOCO_GL", _default_gl())
