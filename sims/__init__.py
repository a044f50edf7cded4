"""planbench's simulation layer: runner, controllers, disturbances, checks, rendering, CLI.

MuJoCo picks its OpenGL back end when it is first imported, so the choice is made here,
before anything imports mujoco: EGL (headless GPU or Mesa) when libEGL is present, else
OSMesa (software). A user's MUJOCO_GL always wins.

BLAS runs on one thread unless the user says otherwise (OPENBLAS_NUM_THREADS, OMP_NUM_THREADS,
MKL_NUM_THREADS), set here before numpy is imported: a threaded BLAS sums in another order on
another thread count, so a run's numbers would depend on the machine's cores (the antenna's
checks differed at 1e-13 between 1 and 2 threads) and a campaign's local and Ray workers would
disagree. planbench's matrices are small (a few per control tick); threads gain nothing there,
and a campaign's workers already use every core.
"""

import ctypes.util
import os


def _default_gl() -> str:
    if ctypes.util.find_library("EGL"):
        return "egl"
    return "osmesa"


os.environ.setdefault("MUJOCO_GL", _default_gl())
for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")
