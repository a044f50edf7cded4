"""Scenario files: a scenario and its parameters as data (README, "Scenario files").

``planbench run FILE.toml`` reads a TOML file (Python's tomllib)::

    scenario = "hexapod-sync-move"      # a name of ``planbench list``
    planner = "my_planner.py:make"      # optional plug-ins, as --planner / --controller
    [parameters]                        # any of the scenario's parameters (``--help``)
    elevation = 30.0

``planbench run DIR/summary.json`` reads the same three things from a run's summary, whose
"parameters" hold every value resolved, and repeats that run. Both resolve to a ``Source``.
Every error names the file, the key and the reason (a ParamError: exit 2, one line).
"""

from __future__ import annotations

import json
import tomllib
from dataclasses import dataclass
from pathlib import Path

from sims.params import ParamError, Params, _hints

TOP_LEVEL_KEYS = ("scenario", "planner", "controller", "parameters")


@dataclass(frozen=True)
class Source:
    """What a run was asked to be: the scenario, its parameters, plug-in specs, and where it
    came from (a name, a TOML file, a summary.json) with the versions recorded there."""

    scenario: object
    params: Params
    plugins: dict
    origin: str
    recorded_versions: dict | None = None


def is_file_argument(text: str) -> bool:
    return text.endswith((".toml", ".json")) or "/" in text or Path(text).is_file()


def resolve(argument: str, get_scenario) -> Source:
    """A scenario name, a scenario file (.toml) or a run's summary.json."""
    if not is_file_argument(argument):
        scenario = get_scenario(argument)
        return Source(scenario, scenario.params, {}, argument)
    path = Path(argument)
    if not path.is_file():
        raise ParamError(f"scenario file {path} does not exist (or is not a file)")
    if path.suffix == ".json":
        return _from_summary(path, get_scenario)
    return _from_toml(path, get_scenario)


def _from_toml(path: Path, get_scenario) -> Source:
    try:
        data = tomllib.loads(path.read_text())
    except (OSError, UnicodeDecodeError) as e:
        raise ParamError(f"{path}: cannot be read ({e})") from None
    except tomllib.TOMLDecodeError as e:
        raise ParamError(f"{path}: not TOML: {e}") from None
    return _from_data(path, data, get_scenario, None)


def _from_summary(path: Path, get_scenario) -> Source:
    try:
        data = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError) as e:
        raise ParamError(f"{path}: cannot be read ({e})") from None
    except json.JSONDecodeError as e:
        raise ParamError(f"{path}: not JSON: {e}") from None
    if not isinstance(data, dict) or "parameters" not in data or not isinstance(data.get("parameters"), dict):
        raise ParamError(f"{path}: not a planbench summary.json with resolved \"parameters\" (written by "
                         "planbench run since scenario files exist)")
    plugins = data.get("plugins") or {}
    run = {"scenario": data.get("scenario"), "parameters": _without_none(data["parameters"]), **plugins}
    return _from_data(path, run, get_scenario, data.get("versions"))


def _without_none(mapping: dict) -> dict:
    # JSON writes an unset optional value as null; TOML has none: both mean "not given".
    return {k: v for k, v in mapping.items() if v is not None}


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
            plugins[role] = _relative(path, data[role], plugin=True)
    overrides = data.get("parameters", {})
    if not isinstance(overrides, dict):
        raise ParamError(f"{path}: key 'parameters' must be a table, got {overrides!r}")
    cls = type(scenario.params)
    declared = {n: d for n, _, d, _ in cls.declarations()}
    overrides = {k: (_relative(path, v) if k in declared and declared[k].path and isinstance(v, str) else v)
                 for k, v in overrides.items()}
    try:
        params = scenario.resolve(overrides)
    except ParamError as e:
        raise ParamError(f"{path}: {e}") from None
    return Source(scenario, params, plugins, str(path), versions)


def _relative(path: Path, value: str, plugin: bool = False) -> str:
    """A file named relative to the scenario file: relative to its directory."""
    name, sep, factory = value.rpartition(":") if plugin else (value, "", "")
    if plugin and not sep:
        return value
    if plugin and not name.endswith(".py"):
        return value  # an importable module, not a file
    candidate = Path(name)
    if not candidate.is_absolute():
        candidate = (path.parent / candidate)
    return f"{candidate}{sep}{factory}" if plugin else str(candidate)


def overrides_from_flags(cls, flags: dict, assignments: list[str]) -> dict:
    """The command line's values: ``--KEY VALUE`` flags (text) and ``--set KEY=VALUE``,
    parsed by each field's type (sims.params.parse_value)."""
    from sims.params import parse_value, set_overrides

    hints = _hints(cls)
    out = {key: parse_value(hints[key], text) for key, text in flags.items()}
    out.update(set_overrides(cls, assignments))
    return out
