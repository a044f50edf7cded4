"""planbench: a MuJoCo testbed for the motion planners of FAST, a Rubin-style hexapod, a ship
antenna and a PRR-3R loader.

The public API is what ``__all__`` names (README, "Python API"); a plug-in needs nothing else:

    import planbench

    result = planbench.run("loader-supply", controller=MyController(), params={"seed": 1})
    print(result.passed, [(c.name, c.value, c.limit) for c in result.checks])

Entry points: ``run`` (one run, as ``planbench run``), ``plan`` (the planned motion alone, as
``planbench plan``), ``sweep`` (a campaign, as ``planbench sweep``), ``environment`` (a
dm_control Environment of a scenario), ``scenario_names``. A plug-in implements ``Controller``
(given a ``ControlContext``), ``Planner`` or ``OnlinePlanner``, returns a ``Trajectory`` (or a
``PiecewiseTrajectory``) sampled as ``TrajectorySample``, for the problems ``LoaderProblem``,
``MoveProblem``, ``FastProblem`` and ``AntennaProblem``, and raises ``PlanningError`` (or
``LimitError``) for a problem it cannot solve. planbench raises ``PluginError`` for a plug-in
that breaks the contract and ``ParamError`` for bad parameters. Everything else, the
subpackages included (``planbench.planners``, ``planbench.models``, the mechanisms' packages),
is internal: it may change between releases.

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


__version__ = "0.2.0"

# name -> module that defines it; imported on first use (PEP 562), so that importing
# planbench.planners (pure numpy) does not import MuJoCo.
_PUBLIC = {
    "run": "planbench.api",
    "plan": "planbench.api",
    "sweep": "planbench.api",
    "environment": "planbench.api",
    "scenario_names": "planbench.api",
    "RunResult": "planbench.runner",
    "Check": "planbench.checks",
    "Controller": "planbench.task",
    "Planner": "planbench.task",
    "OnlinePlanner": "planbench.task",
    "ControlContext": "planbench.task",
    "PluginError": "planbench.task",
    "ParamError": "planbench.params",
    "Trajectory": "planbench.planners.trajectory",
    "TrajectorySample": "planbench.planners.trajectory",
    "PiecewiseTrajectory": "planbench.planners.trajectory",
    "PlanningError": "planbench.planners.errors",
    "LimitError": "planbench.planners.errors",
    "LoaderProblem": "planbench.planners.loader",
    "MoveProblem": "planbench.planners.hexapod",
    "FastProblem": "planbench.planners.fast.plan",
    "AntennaProblem": "planbench.planners.antenna",
}

__all__ = ["__version__", *_PUBLIC]


def __getattr__(name: str):
    module = _PUBLIC.get(name)
    if module is None:
        raise AttributeError(f"module 'planbench' has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_PUBLIC))
