"""Users' planners and controllers: ``MODULE:FACTORY`` from the command line, objects from Python.

``planbench run NAME --controller MODULE:FACTORY --planner MODULE:FACTORY``: ``MODULE`` is an
importable module (``my_package.controllers``) or a path to a ``.py`` file
(``examples/loader/pd_controller.py``); ``FACTORY`` a callable in it (a class or a function, dots for
nested attributes) that takes no arguments and returns the controller or the planner. What a
controller and a planner must provide is the Task contract (``planbench.task``); a plug-in that
breaks it is refused with one line (``PluginError``) before the run starts.
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import sys
from pathlib import Path

from planbench import supervise
from planbench.task import PluginError, _callable_with, check_controller, check_planner, fault_text

#: The top-level names planbench's modules had before they moved under ``planbench`` (0.2.0),
#: with their names now: a plug-in that imports an old name is told the new one in one line.
#: To be dropped in the release after 0.2.0.
OLD_NAMES = {"sims": "planbench", "planners": "planbench.planners", "models": "planbench.models"}


def _old_name_text(error: ModuleNotFoundError) -> str | None:
    """What to write instead, if ``error`` is a missing old top-level name of planbench's."""
    top = (error.name or "").partition(".")[0]
    if top not in OLD_NAMES:
        return None
    new = OLD_NAMES[top]
    return (
        f"it imports {error.name!r}, a name of planbench's modules before 0.2.0: import "
        f"{new!r} instead ({top}.X is {new}.X)"
    )


def is_file(module_name: str) -> bool:
    """``MODULE`` of a spec names a .py file (else an importable module)."""
    return module_name.endswith(".py") or "/" in module_name or "\\" in module_name


def split_spec(spec: str, role: str) -> tuple[str, str]:
    """(MODULE, FACTORY) of ``MODULE:FACTORY``; PluginError otherwise."""
    module_name, sep, attribute = spec.rpartition(":")
    if not sep or not module_name or not attribute:
        raise PluginError(
            f"--{role} {spec!r} must be MODULE:FACTORY (a module or .py file, a colon, "
            "and the callable that makes the object)"
        )
    return module_name, attribute


def _module(name: str, role: str):
    """The module ``name``: a path to a .py file, or an importable module."""
    if is_file(name):
        path = Path(name).expanduser()
        if not path.is_file():
            raise PluginError(f"--{role} {name}: no such file")
        # One module per file, named after its resolved path so two files called the same
        # do not collide, and a relative import of the file's own folder works.
        key = "planbench_plugin_" + hashlib.sha1(str(path.resolve()).encode()).hexdigest()[:12]
        if key in sys.modules:
            return sys.modules[key]
        spec = importlib.util.spec_from_file_location(key, path)
        if spec is None or spec.loader is None:
            raise PluginError(f"--{role} {name}: not a Python file")
        module = importlib.util.module_from_spec(spec)
        sys.modules[key] = module
        supervise.phase(f"importing --{role} {name}")
        try:
            spec.loader.exec_module(module)
        except (Exception, SystemExit) as e:
            del sys.modules[key]
            old = _old_name_text(e) if isinstance(e, ModuleNotFoundError) else None
            raise PluginError(f"--{role} {name}: {old or 'importing it raised ' + fault_text(e)}") from None
        return module
    supervise.phase(f"importing --{role} {name}")
    try:
        return importlib.import_module(name)
    except ModuleNotFoundError as e:
        old = _old_name_text(e)
        if old:
            raise PluginError(f"--{role} {name}: {old}") from None
        raise PluginError(
            f"--{role} {name}: no module named {e.name!r} (give an importable module or a path to a .py file)"
        ) from None
    except (Exception, SystemExit) as e:
        raise PluginError(f"--{role} {name}: importing it raised {fault_text(e)}") from None


def load_factory(spec: str, role: str):
    """The callable that ``spec`` (``MODULE:FACTORY``) names; PluginError naming what is
    missing otherwise. ``role``: "controller" or "planner" (for the messages)."""
    module_name, attribute = split_spec(spec, role)
    obj = _module(module_name, role)
    for part in attribute.split("."):
        if not hasattr(obj, part):
            raise PluginError(f"--{role} {spec}: {module_name} has no attribute {attribute!r}")
        obj = getattr(obj, part)
    if not callable(obj):
        raise PluginError(f"--{role} {spec}: {attribute} is a {type(obj).__name__}, not a callable factory")
    return obj


def make(spec: str, role: str, online_planner: bool = False):
    """The controller or planner that ``spec`` makes, checked against the Task contract
    (``online_planner``: the antenna's planner, ``reset(problem)`` and ``step(t, attitude)``)."""
    factory = load_factory(spec, role)
    _callable_with(factory, 0, f"--{role} {spec}: the factory")
    supervise.phase(f"the factory of --{role} {spec}")
    try:
        obj = factory()
    except (Exception, SystemExit) as e:
        raise PluginError(f"--{role} {spec}: the factory raised {fault_text(e)}") from None
    if role == "controller":
        check_controller(obj)
    else:
        check_planner(obj, online=online_planner)
    return obj
