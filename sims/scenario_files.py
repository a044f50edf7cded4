"""Scenario files: a scenario and its parameters as data (README, "Scenario files").

``planbench run FILE.toml`` reads a TOML file (Python's tomllib)::

    scenario = "hexapod-sync-move"      # a name of ``planbench list``
    planner = "my_planner.py:make"      # optional plug-ins, as --planner / --controller
    [parameters]                        # any of the scenario's parameters (``--help``)
    elevation = 30.0
    [plant]                             # optional: the plant's uncertainty (README, "Campaigns")
    payload_mass_error = 0.1

``planbench run DIR/summary.json`` reads the same three things from a run's summary, whose
"parameters" hold every value resolved, and repeats that run. Both resolve to a ``Source``.
Every error names the file, the key and the reason (a ParamError: exit 2, one line).
"""

from __future__ import annotations

import json
import tomllib
from dataclasses import dataclass
from pathlib import Path

from planbench.params import ParamError, Params, field_types, parse_value, set_overrides
from planbench.plugins import is_file, split_spec

TOP_LEVEL_KEYS = ("scenario", "planner", "controller", "parameters", "plant")


@dataclass(frozen=True)
class Source:
    """What a run was asked to be: the scenario, its parameters, plug-in specs, and where it
    came from (a name, a TOML file, a summary.json) with the versions recorded there."""

    scenario: object
    params: Params
    plugins: dict
    origin: str
    recorded_versions: dict | None = None
    plant: object = None


def resolve(argument: str, get_scenario, known_names) -> Source:
    """A scenario name (``known_names`` win, so a file called like a scenario does not
    shadow it), a scenario file (.toml) or a run's summary.json."""
    if argument in known_names or not (
        argument.endswith((".toml", ".json")) or "/" in argument or Path(argument).is_file()
    ):
        scenario = get_scenario(argument)
        return Source(scenario, scenario.params, {}, argument, plant=scenario.plant)
    path = Path(argument)
    if not path.is_file():
        raise ParamError(f"scenario file {path} does not exist (or is not a file)")
    if path.suffix == ".json":
        data = _read(path, json.loads, json.JSONDecodeError, "JSON")
        if not isinstance(data, dict) or not isinstance(data.get("parameters"), dict):
            raise ParamError(
                f'{path}: not a planbench summary.json with resolved "parameters" (written by '
                "planbench run since scenario files exist)"
            )
        # Every value as it ran (null: an optional value unset); plug-ins as they were given.
        plugins = data.get("plugins") or {}
        if not isinstance(plugins, dict) or any(
            role not in ("planner", "controller") or not isinstance(spec, str) for role, spec in plugins.items()
        ):
            raise ParamError(
                f'{path}: "plugins" must be a table of planner and controller, each '
                f'"MODULE:FACTORY", got {_shown(plugins)}'
            )
        seed = data["parameters"].get("seed")
        if "seed" in data and (data["seed"] != seed or type(data["seed"]) is not type(seed)):
            raise ParamError(
                f'{path}: "seed" = {_shown(data["seed"])} disagrees with the run\'s '
                f"parameters.seed = {_shown(seed)}; the file was changed after the run"
            )
        run = {"scenario": data.get("scenario"), "parameters": data["parameters"], **plugins}
        if data.get("plant") is not None:
            run["plant"] = data["plant"]
        return _from_data(path, run, get_scenario, data.get("versions"))
    return _from_data(path, _read(path, tomllib.loads, tomllib.TOMLDecodeError, "TOML"), get_scenario, None)


def _read(path: Path, parse, parse_error, kind: str):
    try:
        return parse(path.read_text())
    except (OSError, UnicodeDecodeError) as e:
        raise ParamError(f"{path}: cannot be read ({e})") from None
    except parse_error as e:
        raise ParamError(f"{path}: not {kind}: {e}") from None
    except RecursionError:
        raise ParamError(
            f"{path}: {kind} nested too deep to read (arrays or tables within one another, thousands of levels)"
        ) from None


def _shown(value) -> str:
    """A value of a file in an error: its repr, cut to 60 characters."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _from_data(path: Path, data: dict, get_scenario, versions) -> Source:
    unknown = [k for k in data if k not in TOP_LEVEL_KEYS]
    if unknown:
        raise ParamError(f"{path}: unknown key {unknown[0]!r}; a scenario file has {', '.join(TOP_LEVEL_KEYS)}")
    name = data.get("scenario")
    if not isinstance(name, str):
        raise ParamError(f"{path}: key 'scenario' must name a scenario (planbench list), got {name!r}")
    try:
        scenario = get_scenario(name)
    except ValueError as e:
        raise ParamError(f"{path}: scenario: {e}") from None
    plugins = {}
    for role in ("planner", "controller"):
        if role in data:
            if not isinstance(data[role], str):
                raise ParamError(f"{path}: key {role!r} must be MODULE:FACTORY, got {data[role]!r}")
            module_name, factory = split_spec(data[role], role)
            plugins[role] = f"{_beside(path, module_name) if is_file(module_name) else module_name}:{factory}"
    overrides = data.get("parameters", {})
    if not isinstance(overrides, dict):
        raise ParamError(f"{path}: key 'parameters' must be a table, got {overrides!r}")
    declared = {n: d for n, _, d, _ in type(scenario.params).declarations()}
    overrides = {
        k: (_beside(path, v) if k in declared and declared[k].path and isinstance(v, str) else v)
        for k, v in overrides.items()
    }
    plant = data.get("plant", {})
    if not isinstance(plant, dict):
        raise ParamError(f"{path}: key 'plant' must be a table, got {plant!r}")
    try:
        params = scenario.resolve(overrides)
        plant = scenario.resolve_plant(plant)
    except ParamError as e:
        raise ParamError(f"{path}: {e}") from None
    return Source(scenario, params, plugins, str(path), versions, plant)


def _beside(path: Path, name: str) -> str:
    """A file the scenario file names: a relative name is relative to the file's directory."""
    candidate = Path(name).expanduser()
    return str(candidate if candidate.is_absolute() else path.parent / candidate)


def overrides_from_flags(cls, flags: dict, assignments: list[str]) -> dict:
    """The command line's values: ``--KEY VALUE`` flags (text) and ``--set KEY=VALUE``,
    parsed by each field's type (planbench.params.parse_value)."""
    types = field_types(cls)
    out = {key: parse_value(types[key], text, "--" + key.replace("_", "-")) for key, text in flags.items()}
    out.update(set_overrides(cls, assignments))
    return out
