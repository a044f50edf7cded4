"""Typed scenario parameters, declared once.

The user's view: README.md, "Scenario parameters, scenario files and reruns".

Each scenario's parameters are one frozen dataclass, a subclass of ``Params``. Every field is
declared with ``param``: its default, unit, valid range and the reason for the range, and a
one-line help. The declaration is the only place a parameter exists. The rest is derived from it:
  * validation: ``Params.__post_init__`` converts and checks every field, then the class's
    own ``check`` (limits between fields: a sea no sea has, a source that sets during the run);
  * ``planbench run NAME --help``, the CLI's flags and ``--set KEY=VALUE`` (sims/cli.py);
  * scenario files (TOML, ``from_mapping``) and the resolved parameters in summary.json
    (``to_dict``), from which a run is repeated;
  * the README's parameter tables (``markdown_table``; a test keeps them equal).

Values are SI-like in the units each field states (deg for angles, as users write them).
Vectors and tables are tuples (the dataclass stays frozen and hashable); a list of moves is a
tuple of a nested ``Params`` class. Every error is a ``ParamError`` naming the key, the value
and the range: exit 2 and one line on the command line.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
import types
import typing
from dataclasses import dataclass, field
from typing import Any, ClassVar

from planbench.planners.errors import LimitError


class ParamError(LimitError):
    """A parameter that is unknown, of the wrong type or outside its range."""


def override(cls, name: str, default):
    """The field ``name`` of the Params class ``cls`` with another default, for a subclass
    (a scenario's own default of a shared declaration)."""
    return field(default=default, metadata=cls.__dataclass_fields__[name].metadata)


@dataclass(frozen=True)
class Declared:
    """What ``param`` declares about a field (``dataclasses.Field.metadata["declared"]``).

    Attributes:
      help: one line.
      unit: "m", "deg", "s", "m/s", "Hz", ... ("" for numbers without unit, names, switches).
      low, high: inclusive range of a number, or of every element of a vector (a tuple gives
        one bound per column of a table); None: unbounded on that side.
      reason: why the range is what it is (a stroke, a standard, the model's validity).
      choices: the allowed values of a name.
      length: exact number of elements of a vector, or of each row of a table.
      min_items, max_items: number of elements (rows) of a list (table).
      excludes: fields that this one replaces when a user sets it and not them (the satellite
        by orbital longitude or by look angles: setting one clears the other).
      path: the value is a file name.
      low_open, high_open: the bound is excluded (a scalar's range only).
    """

    help: str
    unit: Any = ""
    low: Any = None
    high: Any = None
    reason: str = ""
    choices: tuple | None = None
    length: int | None = None
    min_items: int | None = None
    max_items: int | None = None
    excludes: tuple = ()
    path: bool = False
    low_open: bool = False
    high_open: bool = False


def param(
    default,
    help: str,
    unit="",
    low=None,
    high=None,
    reason: str = "",
    choices=None,
    length: int | None = None,
    min_items: int | None = None,
    max_items: int | None = None,
    excludes: tuple = (),
    path: bool = False,
    low_open: bool = False,
    high_open: bool = False,
):
    """A declared field of a ``Params`` dataclass (see ``Declared``; ``path``: a file name,
    which a scenario file's relative value names from the file's own directory;
    ``low_open``, ``high_open``: the bound itself is outside, as for a period that must be > 0)."""
    declared = Declared(
        help,
        unit,
        low,
        high,
        reason,
        None if choices is None else tuple(choices),
        length,
        min_items,
        max_items,
        tuple(excludes),
        path,
        low_open,
        high_open,
    )
    return field(default=default, metadata={"declared": declared})


def _format(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, tuple):
        return "[" + ", ".join(_format(v) for v in value) + "]"
    if isinstance(value, Params):
        return "{" + ", ".join(f"{k} = {_format(v)}" for k, v in value.to_dict().items()) + "}"
    return str(value)


def _bound(bound, column: int | None):
    if isinstance(bound, tuple):
        return None if column is None else bound[column]
    return bound


def range_text(declared: Declared, column: int | None = None) -> str:
    """ "[lo, hi] unit", "one of a, b", "" for the help and the errors."""
    if declared.choices is not None:
        return "one of " + ", ".join(str(c) for c in declared.choices)
    low, high = _bound(declared.low, column), _bound(declared.high, column)
    if isinstance(declared.low, tuple) and column is None:
        units = declared.unit if isinstance(declared.unit, tuple) else (declared.unit,) * len(declared.low)
        return "per column " + ", ".join(
            f"[{_g(lo)}, {_g(hi)}]" + (f" {u}" if u else "")
            for lo, hi, u in zip(declared.low, declared.high, units, strict=True)
        )
    if low is None and high is None:
        return ""
    unit = f" {unit_of(declared, column)}" if unit_of(declared, column) else ""
    return f"{_interval(declared, low, high)}{unit}"


def _interval(declared: Declared, low, high) -> str:
    return f"{'(' if declared.low_open else '['}{_g(low)}, {_g(high)}{')' if declared.high_open else ']'}"


def _g(bound) -> str:
    if bound is None:
        return "..."
    return str(bound) if isinstance(bound, int) else f"{bound:g}"


class _Type:
    """One field's annotation, parsed: kind in bool, int, float, str, nested (a Params
    class), vector (of ``item``), with ``optional``."""

    def __init__(self, annotation):
        self.optional = False
        # Set by kind: item for a vector (its element's _Type), cls for a nested table.
        self.item: Any = None
        self.cls: Any = None
        args = typing.get_args(annotation)
        origin = typing.get_origin(annotation)
        if origin in (typing.Union, types.UnionType):
            rest = [a for a in args if a is not type(None)]
            if len(rest) != 1:
                raise TypeError(f"unsupported parameter type {annotation!r}")
            self.optional = True
            annotation = rest[0]
            args, origin = typing.get_args(annotation), typing.get_origin(annotation)
        if origin is tuple:
            self.kind, self.item = "vector", _Type(args[0])
        elif annotation in (bool, int, float, str):
            self.kind, self.item = annotation.__name__, None
        elif isinstance(annotation, type) and issubclass(annotation, Params):
            self.kind, self.item, self.cls = "nested", None, annotation
        else:
            raise TypeError(f"unsupported parameter type {annotation!r}")

    @property
    def scalar(self) -> bool:
        return self.kind in ("bool", "int", "float", "str")

    def name(self) -> str:
        if self.kind == "vector":
            inner = self.item.name()
            return f"list of {inner}" if self.item.kind != "vector" else f"table ({inner.replace('list of ', '')} rows)"
        if self.kind == "nested":
            return f"table {self.cls.__name__}"
        return {"float": "number", "int": "integer", "bool": "true/false", "str": "name"}[self.kind]


@typing.no_type_check
def _convert(kind: _Type, value, key: str, declared: Declared, column: int | None = None):
    if value is None:
        if kind.optional:
            return None
        raise ParamError(f"{key} must be given ({kind.name()})")
    if kind.kind == "bool":
        if isinstance(value, bool):
            return value
        raise ParamError(f"{key} = {value!r} is not true or false")
    if kind.kind == "int":
        if isinstance(value, bool) or not isinstance(value, int):
            if isinstance(value, float) and value.is_integer():
                value = int(value)
            else:
                raise ParamError(f"{key} = {value!r} is not an integer")
        return _in_range(int(value), key, declared, column)
    if kind.kind == "float":
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ParamError(f"{key} = {value!r} is not a number")
        value = float(value)
        if not math.isfinite(value):
            raise ParamError(f"{key} = {value} is not finite")
        return _in_range(value, key, declared, column)
    if kind.kind == "str":
        if not isinstance(value, str):
            raise ParamError(f"{key} = {value!r} is not a name (a string)")
        if declared.choices is not None and value not in declared.choices:
            unset = ""
            if kind.optional and value.strip().lower() in ("none", "null"):
                # A typed value (a scenario file's) is never parsed: "none" is the flag syntax.
                unset = (
                    f"; to leave {key} unset, omit it from the file"
                    + (f" (and give {', '.join(declared.excludes)})" if declared.excludes else "")
                    + f" or pass --set {key}=none"
                )
            raise ParamError(f"{key} = {value!r} is not {range_text(declared)}{unset}")
        return value
    if kind.kind == "nested":
        if isinstance(value, kind.cls):
            return value
        if not isinstance(value, dict):
            raise ParamError(f"{key} = {value!r} is not a table of {', '.join(kind.cls.names())}")
        return kind.cls.from_mapping(value, prefix=f"{key}.")
    # A list: of numbers (``length`` of them), of names or tables (``min_items`` ...
    # ``max_items``), or a table of rows (that many rows of ``length`` numbers each).
    table = kind.item.kind == "vector"
    items = _as_list(value, key, "a list")
    if declared.length is not None and not table:
        if len(items) != declared.length:
            raise ParamError(f"{key} has {len(items)} values, not {declared.length}")
    else:
        noun = "rows" if table else "items"
        if declared.min_items is not None and len(items) < declared.min_items:
            raise ParamError(f"{key} has {len(items)} {noun}, fewer than {declared.min_items}")
        if declared.max_items is not None and len(items) > declared.max_items:
            raise ParamError(f"{key} has {len(items)} {noun}, more than {declared.max_items}")
    out = []
    for i, item in enumerate(items):
        name = f"{key}[{i}]"
        if table:
            row = _as_list(item, name, "a row (a list)")
            if declared.length is not None and len(row) != declared.length:
                raise ParamError(f"{name} has {len(row)} values, not {declared.length}")
            out.append(tuple(_convert(kind.item.item, v, f"{name}[{j}]", declared, j) for j, v in enumerate(row)))
        else:
            out.append(_convert(kind.item, item, name, declared, i if isinstance(declared.low, tuple) else None))
    return tuple(out)


def _as_list(value, key: str, what: str) -> list:
    if isinstance(value, (str, bytes, dict)) or not isinstance(value, (list, tuple)):
        raise ParamError(f"{key} = {value!r} is not {what}")
    return list(value)


def unit_of(declared: Declared, column: int | None = None) -> str:
    """The unit of a field, or of one column of a table whose columns differ (a pose: mm and deg)."""
    if isinstance(declared.unit, tuple):
        return "/".join(declared.unit) if column is None else declared.unit[column]
    return declared.unit


def _in_range(value, key: str, declared: Declared, column: int | None):
    low, high = _bound(declared.low, column), _bound(declared.high, column)
    below = low is not None and (value <= low if declared.low_open else value < low)
    above = high is not None and (value >= high if declared.high_open else value > high)
    if below or above:
        unit = f" {unit_of(declared, column)}" if unit_of(declared, column) else ""
        reason = f": {declared.reason}" if declared.reason else ""
        raise ParamError(f"{key} = {_g(value)}{unit} is outside {_interval(declared, low, high)}{unit}{reason}")
    return value


@dataclass(frozen=True)
class Params:
    """Typed, ranged, validated fields (a scenario's, or a row of a list such as a move).

    Every subclass is a frozen dataclass whose fields are all ``param``s. Construction converts
    and checks every field (a ParamError names the first bad one), then calls ``check`` for the
    limits between fields.
    """

    def __post_init__(self):
        hints = field_types(type(self))
        for f in dataclasses.fields(self):
            declared = f.metadata.get("declared")
            if declared is None:
                raise TypeError(f"{type(self).__name__}.{f.name} is not declared with planbench.params.param")
            object.__setattr__(self, f.name, _convert(hints[f.name], getattr(self, f.name), f.name, declared))
        self.check()

    def check(self) -> None:
        """Limits between fields (and ones that need computing): a ParamError naming the key,
        the value and the limit. Subclasses extend it."""

    # ------------------------------------------------------------------ declarations

    @classmethod
    def names(cls) -> list[str]:
        return [f.name for f in dataclasses.fields(cls)]

    @classmethod
    def declarations(cls) -> list[tuple[str, _Type, Declared, Any]]:
        """(name, type, declaration, default) of every field, in order."""
        hints = field_types(cls)
        out = []
        for f in dataclasses.fields(cls):
            default = f.default if f.default_factory is dataclasses.MISSING else f.default_factory()
            out.append((f.name, hints[f.name], f.metadata["declared"], default))
        return out

    # ------------------------------------------------------------------ values

    def to_dict(self) -> dict:
        """Every field, JSON- and TOML-ready (tuples as lists, nested tables as dicts; None
        stays None in JSON and is left out of TOML)."""

        def plain(v):
            if isinstance(v, Params):
                return v.to_dict()
            if isinstance(v, tuple):
                return [plain(x) for x in v]
            return v

        return {f.name: plain(getattr(self, f.name)) for f in dataclasses.fields(self)}

    #: Parameters that had another name: {old name: its name now} (an old name in a file or
    #: on the command line is refused with the new name).
    RENAMED: ClassVar[dict[str, str]] = {}  # a ClassVar: no dataclass field

    @classmethod
    def from_mapping(cls, mapping: dict, base: Params | None = None, prefix: str = "") -> Params:
        """``base`` (default: the declared defaults) with the keys of ``mapping`` replaced.

        An unknown key, a value of the wrong type or out of its range is a ParamError naming
        it. A key whose declaration ``excludes`` others clears them when they are not given too.
        """
        if not isinstance(mapping, dict):
            raise ParamError(f"{prefix.rstrip('.') or 'parameters'} must be a table, got {mapping!r}")
        names = cls.names()
        unknown = [k for k in mapping if k not in names]
        if unknown:
            raise ParamError(
                f"unknown parameter '{prefix}{unknown[0]}'{_renamed(cls, unknown[0])}; "
                f"{cls.__name__} has: {', '.join(names)}"
            )
        values = {} if base is None else {n: getattr(base, n) for n in names}
        declared = {n: d for n, _, d, _ in cls.declarations()}
        kinds = {n: k for n, k, _, _ in cls.declarations()}
        for key, value in mapping.items():
            current = values.get(key)
            if kinds[key].kind == "nested" and isinstance(value, dict) and isinstance(current, Params):
                # A table changes the fields it names of the base's table, not all of them.
                value = type(current).from_mapping(value, base=current, prefix=f"{prefix}{key}.")
            values[key] = value
            for other in declared[key].excludes:
                if other not in mapping:
                    values[other] = None
        try:
            return cls(**values)
        except ParamError as e:
            if prefix:
                raise ParamError(f"{prefix}{e}") from None
            raise

    def replace(self, **changes) -> Params:
        """A copy with ``changes`` (as ``from_mapping``: validated, exclusions applied)."""
        return type(self).from_mapping(changes, base=self)


@dataclass(frozen=True)
class ScenarioParams(Params):
    """The parameters of a run: the seed, then each mechanism's and scenario's fields."""

    seed: int = param(
        0,
        "seed of every random process of the run (disturbances, noise)",
        low=0,
        high=2**63 - 1,
        reason="numpy's SeedSequence takes non-negative 64-bit integers",
    )

    def log_bytes_per_tick(self) -> float:
        """Bytes a run of these parameters holds per control tick: the runner's log and what
        the task's sensors, disturbance and reference controller keep per tick. The check of
        the run's length (``planbench.run_limits.check_duration``) multiplies it by the ticks; each
        mechanism's scenario parameters define it."""
        raise NotImplementedError(f"{type(self).__name__} does not say its log's bytes per control tick")


@dataclass(frozen=True)
class PlantParams(Params):
    """How the simulated machine differs from its nominal model: a mechanism's plant
    uncertainty (masses, stiffness, geometry, sensor errors, actuator limits), for campaigns.

    Every field's default is the nominal plant, so ``Cls()`` is the machine as modelled. Only
    the plant is perturbed (its MjSpec edited before compiling, its sensors' true errors): the
    planner and the controller keep the nominal model (``ControlContext.model`` and
    ``nominal_physics``), as a real controller knows only its design values. A mechanism
    declares its fields in a subclass and its ``build`` takes ``plant=``.
    """

    #: The fields that are errors of the drive trains as built (friction, stiffness, backlash,
    #: torque constant): the ideal drives have none of those elements.
    AS_BUILT_FIELDS: ClassVar[tuple[str, ...]] = ()

    @property
    def is_nominal(self) -> bool:
        """True when every field has its nominal (default) value."""
        return self == type(self)()

    def check_drives(self, drives: str) -> None:
        """A ParamError, before any work, if ``drives`` is "ideal" and a field of
        ``AS_BUILT_FIELDS`` is off nominal: an error of an element the ideal drives lack would
        be silently ignored."""
        if drives != "ideal":
            return
        nominal = type(self)()
        given = [
            f"{name} = {getattr(self, name)!r}"
            for name in self.AS_BUILT_FIELDS
            if getattr(self, name) != getattr(nominal, name)
        ]
        if given:
            raise ParamError(
                f"plant {', '.join(given)}: an error of the drive trains as built; "
                "the ideal drives have none (drives = as-built)"
            )


@typing.no_type_check
def field_types(cls) -> dict:
    """{field name: its parsed type} of a Params class (cached on the class)."""
    cache = cls.__dict__.get("_parsed_hints")
    if cache is None:
        fields = {f.name for f in dataclasses.fields(cls)}
        cache = {
            name: _Type(t)
            for name, t in typing.get_type_hints(cls).items()
            if name in fields and not name.startswith("_")
        }
        cls._parsed_hints = cache
    return cache


# ---------------------------------------------------------------------- text forms


def _one_toml_value(text: str, shown: str):
    """``text`` as one TOML value; a TOMLDecodeError if it is none. A value that ends its line
    and goes on with more ("5", a line break, "seed = 3": TOML reads a second key) is refused,
    naming it, and so is one nested deeper than the parser's recursion allows."""
    try:
        document = tomllib.loads(f"v = {text}")
    except RecursionError:
        raise ParamError(
            f"{shown}: a value nested too deep to read (lists or tables within one another, thousands of levels)"
        ) from None
    if len(document) > 1:
        extra = next(k for k in document if k != "v")
        raise ParamError(
            f"{shown} = {text!r} holds a line break and then {extra!r}: give one value per "
            "option (a second key needs its own --set)"
        )
    return document["v"]


def parse_value(kind: _Type, text: str, shown: str = "value"):
    """A command-line value: TOML's syntax for numbers, booleans, lists and tables
    (``--set moves=[{target=[1,0,0,0,0,0]}]``); on/off, yes/no for switches; "none" for an
    optional value; anything else as a name. ``shown``: how the option was written, for the
    errors ("--duration", "--set duration"). An empty value is refused (write "none" to unset
    an optional one), and so is a line break that is not inside one TOML value."""
    stripped = text.strip()
    if stripped == "":
        unset = " (none unsets it)" if kind.optional else ""
        raise ParamError(f"{shown} is empty: give a {kind.name()}{unset}")
    if "\n" in stripped or "\r" in stripped:
        try:
            _one_toml_value(stripped, shown)
        except tomllib.TOMLDecodeError:
            raise ParamError(f"{shown} = {text!r} holds a line break: give one value per option") from None
    if kind.optional and stripped.lower() in ("none", "null"):
        return None
    if kind.kind == "bool" and stripped.lower() in ("on", "off", "yes", "no", "true", "false", "1", "0"):
        return stripped.lower() in ("on", "yes", "true", "1")
    if kind.kind == "str":
        try:
            value = _one_toml_value(stripped, shown)
            return value if isinstance(value, str) else stripped
        except tomllib.TOMLDecodeError:
            return stripped
    if kind.kind == "int":
        try:
            return int(stripped)  # beyond TOML's 64 bits too, so the range names the value
        except ValueError:
            pass
    try:
        return _one_toml_value(stripped, shown)
    except tomllib.TOMLDecodeError:
        # Python's spellings of numbers TOML lacks (1e3 is TOML; .5, 5., inf are not).
        try:
            return float(stripped)
        except ValueError:
            return stripped


def set_overrides(cls: type[Params], assignments: list[str], prefix: str = "") -> dict:
    """``--set KEY=VALUE`` (repeatable) as a mapping for ``from_mapping`` (``prefix``: how
    the keys were written, for the errors: "plant.")."""
    hints = field_types(cls)
    out: dict[str, Any] = {}
    for text in assignments:
        key, sep, value = text.partition("=")
        key = key.strip()
        if not sep or not key:
            raise ParamError(f"--set {prefix}{text!r} is not KEY=VALUE")
        head, dot, rest = key.partition(".")
        nested = {n: k.cls for n, k, _, _ in cls.declarations() if k.kind == "nested"}
        if dot and head in nested:  # a field of a nested table: --set sensors.ts_latency_s=0.15
            inner = set_overrides(nested[head], [f"{rest}={value}"], prefix=f"{prefix}{head}.")
            out.setdefault(head, {}).update(inner)
            continue
        if key not in hints:
            raise ParamError(
                f"--set: unknown parameter {prefix + key!r}{_renamed(cls, key)}; "
                f"{cls.__name__} has: {', '.join(cls.names())}"
            )
        out[key] = parse_value(hints[key], value, f"--set {prefix}{key}")
    return out


def _range_and_length(declared: Declared) -> str:
    rng = range_text(declared)
    if declared.length is None:
        return rng
    return f"{declared.length} values" + (f", {rng}" if rng else "")


def describe(kind: _Type, declared: Declared, default) -> str:
    """One parameter's line of help: what it is, its unit, default and range."""
    parts = [declared.help]
    unit = unit_of(declared)
    text = f"{kind.name()}" + (f", {unit}" if unit else "")
    parts.append(f"[{text}; default {_format(default) if default is not None else 'none'}")
    rng = _range_and_length(declared)
    parts[-1] += (f"; {rng}" if rng else "") + "]"
    if declared.reason:
        parts.append(f"({declared.reason})")
    return " ".join(parts)


def _renamed(cls, key: str) -> str:
    """ ", now NEW" for a parameter that was renamed (``Params.RENAMED``), else ""."""
    new = getattr(cls, "RENAMED", {}).get(key)
    return f" (its name is now {new!r})" if new else ""


def markdown_table(cls: type[Params]) -> str:
    """The README's table of ``cls``'s parameters: key, unit, default, range, meaning."""
    lines = ["| key | unit | default | range | meaning |", "|---|---|---|---|---|"]
    for name, kind, declared, default in cls.declarations():
        rng = _range_and_length(declared)
        meaning = declared.help + (f" ({declared.reason})" if declared.reason else "")
        if kind.kind == "nested" and default is not None:
            default_text = f"{type(default).__name__}()"  # its own table follows (readme_tables)
        else:
            default_text = "none" if default is None else _format(default)
        lines.append(f"| `{name}` | {unit_of(declared)} | `{default_text}` | {rng} | {meaning} |".replace("  ", " "))
    return "\n".join(lines)


def readme_tables() -> str:
    """The README's parameter tables, one per Params class of the registered scenarios
    (``python -m planbench.params`` prints them; tests/test_scenario_params.py keeps the README equal)."""
    from planbench import scenarios

    by_class: dict[Any, list[str]] = {}  # Params class -> scenario names
    for s in [*scenarios.SCENARIOS.values(), *scenarios.PLANS.values()]:
        by_class.setdefault(type(s.params), []).append(s.name)
    parts = []
    for cls, names in by_class.items():
        nested = [k.item.cls for _, k, _, _ in cls.declarations() if k.kind == "vector" and k.item.kind == "nested"]
        tables = [(name, k.cls) for name, k, _, _ in cls.declarations() if k.kind == "nested"]
        parts.append(f"#### `{cls.__name__}`: {', '.join(f'`{n}`' for n in names)}\n\n{markdown_table(cls)}")
        parts += [f"Each of `{cls.__name__}`'s list items, `{c.__name__}`:\n\n{markdown_table(c)}" for c in nested]
        parts += [
            f"`{cls.__name__}`'s table `{key}`, `{c.__name__}` (`--set {key}.KEY=VALUE`):\n\n{markdown_table(c)}"
            for key, c in tables
            if f"`{c.__name__}`" not in "\n".join(parts)
        ]
    return "\n\n".join(parts)


if __name__ == "__main__":
    from planbench.params import readme_tables as tables  # the module's own classes, not __main__'s

    print(tables())
