"""Campaign specs: a scenario, its axes, seeds and plant uncertainty as data (README, "Campaigns").

``planbench sweep SPEC.toml`` reads (tomllib)::

    scenario = "fast-tracking"     # a name of ``planbench list``, or a scenario file (.toml)
    planner = "my.py:make"         # optional plug-ins, as in scenario files
    mode = "simulate"              # or "plan": the planner's checks only, no physics
    seed = 2026                    # the campaign's seed: random draws and every run's seed
    seeds = 4                      # runs per point, each with its own seed (or a list of seeds)
    samples = 1                    # random draws per grid point ([random] needs more than 1)
    invalid = "refuse"             # or "skip": a run whose combination breaks a limit between
                                   #   parameters is a row of status "invalid", not an error
    save = []                      # per-run outputs besides summary.json: "timeseries", "video"
    [parameters]                   # fixed values of every run (the scenario's parameters)
    duration = 120.0
    [plant]                        # fixed plant uncertainty of every run
    [grid]                         # values per axis; the runs cover their cartesian product
    wind = [0.0, 4.0, 8.0]
    "moves[0].target[2]" = [1.0, 2.0]   # one element of a vector or table
    [grid.plant]                   # axes of the plant's uncertainty fields
    cable_ea_error = [-0.1, 0.0, 0.1]
    [random]                       # one draw per sample from a named distribution
    hs = { distribution = "uniform", low = 1.0, high = 4.0 }
    [random.plant]
    payload_mass_error = { distribution = "normal", mean = 0.0, std = 0.05, low = -0.15, high = 0.15 }

The runs follow from the spec alone: grid point p (the cartesian product in the order the
axes are written), sample s and replicate r are run ``(p * samples + s) * seeds + r``. Random
draws come from numpy streams seeded by (seed, axis number); a run's seed from (seed, s, r)
only, so every grid point meets the same turbulence and noise (common random numbers: the
differences between points are the axes', not the seeds'). The same spec always gives the same
runs with the same seeds; its fingerprint (a SHA-256 of the spec as parsed, and of the scenario
file it names) tells a resumed campaign from a changed one.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
import re
import tomllib
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from planbench.params import ParamError, Params, _bound, field_types

SPEC_KEYS = (
    "scenario",
    "planner",
    "controller",
    "mode",
    "seed",
    "seeds",
    "samples",
    "invalid",
    "save",
    "timeout",
    "parameters",
    "plant",
    "grid",
    "random",
)
MODES = ("simulate", "plan")
SAVE_CHOICES = ("timeseries", "video")
DISTRIBUTIONS = {
    "uniform": ("low", "high"),
    "normal": ("mean", "std"),  # optional low, high: truncated
    "log-uniform": ("low", "high"),
}
#: Campaigns above this many runs are refused: the table, the seeds and the report are sized
#: for it (10^7 planner checks of one move take hours on one core).
MAX_RUNS = 10_000_000
_PATH = re.compile(r"[A-Za-z_][A-Za-z0-9_]*|\[\d+\]|\.")


def parse_path(key: str) -> tuple:
    """``"moves[0].target[2]"`` -> ("moves", 0, "target", 2); a ParamError if malformed."""
    tokens, pos, out = [], 0, []
    while pos < len(key):
        m = _PATH.match(key, pos)
        if m is None:
            raise ParamError(f"axis {key!r} is not a parameter name (NAME, NAME[i], NAME[i].FIELD)")
        tokens.append(m.group())
        pos = m.end()
    expect_name = True
    for token in tokens:
        if token == ".":
            if expect_name:
                raise ParamError(f"axis {key!r} is not a parameter name (NAME, NAME[i], NAME[i].FIELD)")
            expect_name = True
        elif token.startswith("["):
            if expect_name:
                raise ParamError(f"axis {key!r} is not a parameter name (NAME, NAME[i], NAME[i].FIELD)")
            out.append(int(token[1:-1]))
        else:
            if not expect_name:
                raise ParamError(f"axis {key!r} is not a parameter name (NAME, NAME[i], NAME[i].FIELD)")
            out.append(token)
            expect_name = False
    if not out or expect_name:
        raise ParamError(f"axis {key!r} is not a parameter name (NAME, NAME[i], NAME[i].FIELD)")
    return tuple(out)


@dataclass(frozen=True)
class Leaf:
    """What an axis sets: its declaration, the column of a per-column range, its type."""

    declared: object
    column: int | None
    kind: str  # bool, int, float, str, vector, nested


def leaf_of(cls: type[Params], path: tuple, key: str) -> Leaf:
    """The declaration of the value ``path`` names in ``cls`` (a ParamError if none)."""
    name = path[0]
    types = field_types(cls)
    if name not in types:
        raise ParamError(f"unknown parameter {key!r}; {cls.__name__} has: {', '.join(cls.names())}")
    kind, declared = types[name], cls.__dataclass_fields__[name].metadata["declared"]
    column, depth = None, 0
    rest = list(path[1:])
    while rest:
        step = rest.pop(0)
        if isinstance(step, int):
            if kind.kind != "vector":
                raise ParamError(f"axis {key!r}: {name} is not a list")
            table = kind.item.kind == "vector"
            if not table and isinstance(declared.low, tuple):
                column = step
            elif depth == 1:  # a table's column
                column = step
            depth += 1
            kind = kind.item
        else:
            if kind.kind != "nested":
                raise ParamError(f"axis {key!r}: {name} has no field {step!r}")
            return leaf_of(kind.cls, (step, *rest), key)
    return Leaf(declared, column, kind.kind)


def set_path(data: dict, path: tuple, value, key: str) -> None:
    """Set ``value`` at ``path`` in ``data`` (a Params.to_dict(), changed in place)."""
    node = data
    for depth, step in enumerate(path[:-1]):
        try:
            node = node[step]
        except (IndexError, KeyError, TypeError):
            raise ParamError(
                f"axis {key!r}: {_render(path[: depth + 1])} does not exist in the base "
                "parameters (give it in [parameters] first)"
            ) from None
    last = path[-1]
    if isinstance(last, int) and (not isinstance(node, list) or last >= len(node)):
        raise ParamError(
            f"axis {key!r}: {_render(path)} does not exist in the base parameters (give it in [parameters] first)"
        )
    node[last] = value


def _render(path: tuple) -> str:
    out = ""
    for step in path:
        out += f"[{step}]" if isinstance(step, int) else (f".{step}" if out else step)
    return out


@dataclass(frozen=True)
class Distribution:
    """A named distribution of one axis (scipy.stats), with its support."""

    name: str
    args: dict

    @property
    def support(self) -> tuple[float, float]:
        a = self.args
        if self.name in ("uniform", "log-uniform"):
            return a["low"], a["high"]
        return a.get("low", -math.inf), a.get("high", math.inf)

    def frozen(self):
        from scipy import stats  # (~0.4 s to import: a campaign's workers never draw)

        a = self.args
        if self.name == "uniform":
            return stats.uniform(loc=a["low"], scale=a["high"] - a["low"])
        if self.name == "log-uniform":
            return stats.loguniform(a["low"], a["high"])
        low, high = self.support
        if math.isinf(low) and math.isinf(high):
            return stats.norm(loc=a["mean"], scale=a["std"])
        return stats.truncnorm(
            (low - a["mean"]) / a["std"], (high - a["mean"]) / a["std"], loc=a["mean"], scale=a["std"]
        )

    def draw(self, n: int, rng: np.random.Generator) -> np.ndarray:
        values = self.frozen().rvs(size=n, random_state=rng)
        low, high = self.support  # round-off of the inverse CDF must not leave the support
        return np.clip(np.asarray(values, dtype=float), low, high)

    def text(self) -> str:
        return f"{self.name}({', '.join(f'{k}={v:g}' for k, v in self.args.items())})"


def _distribution(key: str, table) -> Distribution:
    if not isinstance(table, dict):
        raise ParamError(
            f'random.{key} must be a table such as {{ distribution = "uniform", low = 0, high = 1 }}, got {table!r}'
        )
    name = table.get("distribution")
    if name not in DISTRIBUTIONS:
        raise ParamError(f"random.{key}.distribution = {name!r} is not one of {', '.join(DISTRIBUTIONS)}")
    required = DISTRIBUTIONS[name]
    allowed = set(required) | ({"low", "high"} if name == "normal" else set()) | {"distribution"}
    unknown = [k for k in table if k not in allowed]
    if unknown:
        raise ParamError(
            f"random.{key}: unknown key {unknown[0]!r}; {name} takes {', '.join(sorted(allowed - {'distribution'}))}"
        )
    args = {}
    for k in [*required, *(("low", "high") if name == "normal" else ())]:
        if k not in table:
            if k in required:
                raise ParamError(f"random.{key}: {name} needs {k}")
            continue
        v = table[k]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ParamError(f"random.{key}.{k} = {v!r} is not a finite number")
        args[k] = float(v)
    low, high = args.get("low", -math.inf), args.get("high", math.inf)
    if name == "normal" and args["std"] <= 0:
        raise ParamError(f"random.{key}.std = {args['std']:g} must be > 0")
    if not low < high:
        raise ParamError(f"random.{key}: low = {low:g} must be below high = {high:g}")
    if name == "log-uniform" and low <= 0:
        raise ParamError(f"random.{key}: log-uniform needs low > 0, got {low:g}")
    return Distribution(name, args)


@dataclass(frozen=True)
class Axis:
    """One axis: a parameter (or a plant field: ``plant`` True) and its grid values or its
    distribution."""

    key: str
    plant: bool
    path: tuple
    leaf: Leaf
    values: tuple | None = None
    distribution: Distribution | None = None

    @property
    def column(self) -> str:
        """Its column in the results table."""
        return ("plant." if self.plant else "") + self.key

    @property
    def unit(self) -> str:
        from planbench.params import unit_of

        return unit_of(self.leaf.declared, self.leaf.column) if self.leaf.kind in ("float", "int") else ""


@dataclass(frozen=True)
class Run:
    """One run of a campaign: its place (point, sample, replicate), seed and axis values."""

    index: int
    point: int
    sample: int
    replicate: int
    seed: int
    values: tuple  # one per axis, grid axes first (in the spec's order), then random ones


@dataclass
class CampaignSpec:
    """A parsed, validated campaign spec (``load``)."""

    path: Path
    scenario: object
    base_params: Params
    base_plant: Params | None
    plugins: dict
    mode: str
    seed: int
    seeds: tuple  # explicit seeds, or () for ``replicates`` derived ones
    replicates: int
    samples: int
    invalid: str
    save: tuple
    grid: list[Axis]
    random: list[Axis]
    fingerprint: str
    data: dict = field(repr=False, default_factory=dict)
    timeout: float | None = None  # each run's wall-time limit, s (None: planbench.supervise's default)

    @property
    def axes(self) -> list[Axis]:
        return [*self.grid, *self.random]

    @property
    def points(self) -> int:
        return math.prod(len(a.values) for a in self.grid) if self.grid else 1

    @property
    def size(self) -> int:
        return self.points * self.samples * self.replicates

    def grid_values(self, point: int) -> tuple:
        """The grid axes' values of grid point ``point``."""
        out = []
        for axis in reversed(self.grid):
            point, i = divmod(point, len(axis.values))
            out.append(axis.values[i])
        return tuple(reversed(out))

    def draws(self) -> list[np.ndarray]:
        """Every random axis's ``samples`` draws (the same for every grid point)."""
        return [
            axis.distribution.draw(
                self.samples, np.random.default_rng(np.random.SeedSequence(self.seed, spawn_key=(1, i)))
            )
            for i, axis in enumerate(self.random)
        ]

    def run_seed(self, sample: int, replicate: int) -> int:
        if self.seeds:
            return self.seeds[replicate]
        state = np.random.SeedSequence(self.seed, spawn_key=(2, sample, replicate)).generate_state(2, np.uint32)
        return int((int(state[0]) << 31) ^ int(state[1])) & (2**63 - 1)

    def iter_runs(self):
        """Every run, in order of its index, one at a time (a campaign of 10^6 runs is never
        held in memory whole)."""
        draws = self.draws()
        seeds = (
            [[self.run_seed(s, r) for r in range(self.replicates)] for s in range(self.samples)]
            if self.samples * self.replicates <= 100_000
            else None
        )
        index = 0
        for point in range(self.points):
            grid = self.grid_values(point)
            for s in range(self.samples):
                drawn = tuple(float(d[s]) for d in draws)
                for r in range(self.replicates):
                    seed = seeds[s][r] if seeds is not None else self.run_seed(s, r)
                    yield Run(index, point, s, r, seed, grid + drawn)
                    index += 1

    def runs(self) -> list[Run]:
        """Every run, in order of its index."""
        return list(self.iter_runs())

    def columns(self, index: np.ndarray, draws: list[np.ndarray] | None = None) -> dict:
        """The runs ``index`` (an int64 array) as columns, what ``iter_runs`` gives one run at
        a time: "run", "point", "sample", "replicate", "seed" (int64 arrays) and each axis's
        values under its column name (a float64, bool or int64 array, or a list of values
        that are none of those). ``draws``: ``self.draws()``, computed once by the caller."""
        index = np.asarray(index, dtype=np.int64)
        draws = self.draws() if draws is None else draws
        per_point = self.samples * self.replicates
        point, rest = np.divmod(index, per_point)
        sample, replicate = np.divmod(rest, self.replicates)
        if self.seeds:
            seed = np.asarray(self.seeds, dtype=np.int64)[replicate]
        else:
            seed = run_seeds(self.seed, sample, replicate)
        out = {"run": index, "point": point, "sample": sample, "replicate": replicate, "seed": seed}
        if self.grid:
            points, where = np.unique(point, return_inverse=True)
            values = [self.grid_values(int(p)) for p in points]
            for k, axis in enumerate(self.grid):
                column = [v[k] for v in values]
                kind = axis.leaf.kind
                if kind in ("float", "bool", "int") and all(not isinstance(v, (tuple, dict)) for v in column):
                    dtype = {"float": np.float64, "bool": np.bool_, "int": np.int64}[kind]
                    out[axis.column] = np.asarray(column, dtype=dtype)[where]
                else:
                    out[axis.column] = [column[i] for i in where]
        for axis, drawn in zip(self.random, draws, strict=True):
            out[axis.column] = np.asarray(drawn, dtype=np.float64)[sample]
        return out

    def overrides(self, run: Run) -> tuple[dict, dict]:
        """(parameter overrides, plant overrides) of ``run``: the top-level keys its axes
        change, with the run's seed, as mappings for ``from_mapping`` on the base."""
        params, plant = {"seed": run.seed}, {}
        base = {False: None, True: None}
        for axis, value in zip(self.axes, run.values, strict=True):
            target = plant if axis.plant else params
            top = axis.path[0]
            if len(axis.path) == 1:
                target[top] = value
                continue
            if top not in target:
                if base[axis.plant] is None:
                    base[axis.plant] = (self.base_plant if axis.plant else self.base_params).to_dict()
                target[top] = copy.deepcopy(base[axis.plant][top])
            set_path({top: target[top]}, axis.path, value, axis.key)
        return params, plant

    def resolve(self, run: Run) -> tuple[Params, Params | None]:
        """The run's validated parameters and plant (a ParamError names the axis values)."""
        params, plant = self.overrides(run)
        try:
            return (
                type(self.base_params).from_mapping(params, base=self.base_params),
                self.scenario.resolve_plant(plant)
                if self.base_plant is None
                else type(self.base_plant).from_mapping(plant, base=self.base_plant, prefix="plant."),
            )
        except ParamError as e:
            raise ParamError(f"run {run.index} ({self.describe(run)}): {e}") from None

    def describe(self, run: Run) -> str:
        return (
            ", ".join(f"{a.column} = {_show(v)}" for a, v in zip(self.axes, run.values, strict=True))
            + f", seed {run.seed}"
        )


def _show(value) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    return json.dumps(value) if not isinstance(value, str) else value


def _int(data: dict, key: str, default: int, low: int, high: int) -> int:
    value = data.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int):
        raise ParamError(f"{key} = {value!r} is not an integer")
    if not low <= value <= high:
        raise ParamError(f"{key} = {value} is outside [{low}, {high}]")
    return value


def load(path, get_scenario=None, known_names=None) -> CampaignSpec:
    """Read and validate the campaign spec at ``path``: every key, axis, value and
    distribution is checked here, before any run (a ParamError naming the file and the key)."""
    from planbench import scenario_files, scenarios

    path = Path(path)
    get_scenario = scenarios.get if get_scenario is None else get_scenario
    known_names = scenarios.SCENARIOS if known_names is None else known_names
    if not path.is_file():
        raise ParamError(f"campaign spec {path} does not exist (or is not a file)")
    try:
        text = path.read_text()
        data = tomllib.loads(text)
    except (OSError, UnicodeDecodeError) as e:
        raise ParamError(f"{path}: cannot be read ({e})") from None
    except tomllib.TOMLDecodeError as e:
        raise ParamError(f"{path}: not TOML: {e}") from None
    except RecursionError:
        raise ParamError(
            f"{path}: TOML nested too deep to read (arrays or tables within one another, thousands of levels)"
        ) from None
    try:
        return _parse(path, data, get_scenario, known_names, scenario_files)
    except ParamError as e:
        raise ParamError(f"{path}: {e}") from None


def _parse(path: Path, data: dict, get_scenario, known_names, scenario_files) -> CampaignSpec:
    unknown = [k for k in data if k not in SPEC_KEYS]
    if unknown:
        raise ParamError(f"unknown key {unknown[0]!r}; a campaign spec has {', '.join(SPEC_KEYS)}")
    name = data.get("scenario")
    if not isinstance(name, str) or not name:
        raise ParamError(f"key 'scenario' must name a scenario (planbench list) or a scenario file, got {name!r}")
    fingerprint_extra = ""
    if name in known_names:
        scenario = get_scenario(name)
        base_params, base_plant, plugins = scenario.params, scenario.plant, {}
    else:
        file = Path(name) if Path(name).is_absolute() else path.parent / name
        source = scenario_files.resolve(str(file), get_scenario, known_names)
        scenario, base_params, base_plant, plugins = source.scenario, source.params, source.plant, dict(source.plugins)
        fingerprint_extra = file.read_text() if file.is_file() else ""
    for role in ("planner", "controller"):
        if role in data:
            if not isinstance(data[role], str):
                raise ParamError(f"key {role!r} must be MODULE:FACTORY, got {data[role]!r}")
            from planbench.plugins import is_file, split_spec

            module_name, factory = split_spec(data[role], role)
            if is_file(module_name) and not Path(module_name).is_absolute():
                module_name = str(path.parent / module_name)
            plugins[role] = f"{module_name}:{factory}"
    mode = data.get("mode", "simulate")
    if mode not in MODES:
        raise ParamError(f"mode = {mode!r} is not one of {', '.join(MODES)}")
    if mode == "plan" and getattr(scenario, "judge_plans", None) is None:
        raise ParamError(
            f'mode = "plan": {scenario.name} has no planner-only checks '
            "(the hexapod's and the loader's scenarios have)"
        )
    if mode == "plan" and "controller" in plugins:
        raise ParamError("mode = \"plan\" runs no controller; remove 'controller'")
    seed = _int(data, "seed", 0, 0, 2**63 - 1)
    raw_seeds = data.get("seeds", 1)
    if isinstance(raw_seeds, list):
        if not raw_seeds:
            raise ParamError("seeds = [] is empty; give a count or at least one seed")
        seeds = tuple(_int({"seeds": s}, "seeds", 0, 0, 2**63 - 1) for s in raw_seeds)
        replicates = len(seeds)
    else:
        replicates, seeds = _int(data, "seeds", 1, 1, 100_000), ()
    samples = _int(data, "samples", 1, 1, MAX_RUNS)
    invalid = data.get("invalid", "refuse")
    if invalid not in ("refuse", "skip"):
        raise ParamError(f"invalid = {invalid!r} is not one of refuse, skip")
    save = data.get("save", [])
    if not isinstance(save, list) or any(s not in SAVE_CHOICES for s in save):
        raise ParamError(f"save = {save!r} must be a list of {', '.join(SAVE_CHOICES)}")
    if save and mode == "plan":
        raise ParamError("save: a planner-only campaign writes no per-run outputs")
    timeout = data.get("timeout")
    if timeout is not None:
        if (
            isinstance(timeout, bool)
            or not isinstance(timeout, (int, float))
            or not math.isfinite(timeout)
            or timeout <= 0
        ):
            raise ParamError(
                f"timeout = {timeout!r} must be a finite number of seconds > 0 (each run's wall-time limit)"
            )
        timeout = float(timeout)
    try:
        if "parameters" in data:
            if not isinstance(data["parameters"], dict):
                raise ParamError(f"key 'parameters' must be a table, got {data['parameters']!r}")
            base_params = type(base_params).from_mapping(data["parameters"], base=base_params)
        if "plant" in data:
            if not isinstance(data["plant"], dict):
                raise ParamError(f"key 'plant' must be a table, got {data['plant']!r}")
            if base_plant is None:
                scenario.resolve_plant(data["plant"])  # raises: no plant uncertainty
            base_plant = type(base_plant).from_mapping(data["plant"], base=base_plant, prefix="plant.")
    except ParamError:
        raise
    grid = _axes(data.get("grid", {}), "grid", scenario, base_params, base_plant)
    random = _axes(data.get("random", {}), "random", scenario, base_params, base_plant)
    _check_overlap(grid, random)
    if random and samples < 2 and "samples" not in data:
        raise ParamError("[random] axes need samples = N draws (N >= 1, given explicitly)")
    if not random and samples > 1:
        raise ParamError(f"samples = {samples} draws of nothing: [random] is empty")
    if "seed" in {a.key for a in grid + random if not a.plant}:
        raise ParamError("seed is the campaign's: use seeds = N (or a list) instead of an axis of seed")
    spec = CampaignSpec(
        path,
        scenario,
        base_params,
        base_plant,
        plugins,
        mode,
        seed,
        seeds,
        replicates,
        samples,
        invalid,
        tuple(save),
        grid,
        random,
        "",
        data,
        timeout,
    )
    if spec.size > MAX_RUNS:
        raise ParamError(
            f"{spec.size} runs ({spec.points} points x {samples} samples x {replicates} seeds) is more than {MAX_RUNS}"
        )
    canonical = json.dumps(
        {
            "spec": data,
            "scenario_file": fingerprint_extra,
            "base": base_params.to_dict(),
            "plant": None if base_plant is None else base_plant.to_dict(),
        },
        sort_keys=True,
        default=str,
    )
    spec.fingerprint = hashlib.sha256(canonical.encode()).hexdigest()
    _check_axes(spec)
    return spec


def _axes(table, section: str, scenario, base_params, base_plant) -> list[Axis]:
    if not isinstance(table, dict):
        raise ParamError(f"[{section}] must be a table of axes, got {table!r}")
    out = []
    for key, value in table.items():
        if key == "plant" and isinstance(value, dict):
            if base_plant is None:
                raise ParamError(f"{section}.plant: {scenario.name} declares no plant uncertainty")
            for plant_key, plant_value in value.items():
                out.append(_axis(section, plant_key, plant_value, True, type(base_plant)))
            continue
        out.append(_axis(section, key, value, False, type(base_params)))
    columns = [a.column for a in out]
    for c in columns:
        if columns.count(c) > 1:
            raise ParamError(f"axis {c!r} is given twice")
    return out


def _check_overlap(grid: list[Axis], random: list[Axis]) -> None:
    """No value set by two axes: the same key in [grid] and [random], or one axis inside
    another's (``key_points`` and ``key_points[1][0]``), would let one silently override the
    other."""
    axes = [("grid", a) for a in grid] + [("random", a) for a in random]
    for i, (section_a, a) in enumerate(axes):
        for section_b, b in axes[i + 1 :]:
            if a.plant != b.plant:
                continue
            short, long = (a, b) if len(a.path) <= len(b.path) else (b, a)
            if long.path[: len(short.path)] == short.path:
                where = "[grid] and [random]" if section_a != section_b else f"[{section_a}]"
                what = (
                    f"axis {a.column!r} is in both {where}"
                    if section_a != section_b and a.path == b.path
                    else f"axes {a.column!r} and {b.column!r} of {where} set the same value"
                )
                raise ParamError(f"{what}; a value may have one axis only")


def _axis(section: str, key: str, value, plant: bool, cls) -> Axis:
    path = parse_path(key)
    shown = ("plant." if plant else "") + key
    leaf = leaf_of(cls, path, shown)
    if section == "grid":
        if not isinstance(value, list):
            raise ParamError(f"grid.{shown} = {value!r} must be a list of values")
        if not value:
            raise ParamError(f"grid.{shown} is empty: give at least one value")
        return Axis(key, plant, path, leaf, values=tuple(_freeze(v) for v in value))
    if leaf.kind != "float":
        raise ParamError(f"random.{shown}: draws are for numbers; {key} is a {leaf.kind} (use a grid)")
    distribution = _distribution(shown, value)
    declared, column = leaf.declared, leaf.column
    low, high = _bound(declared.low, column), _bound(declared.high, column)
    s_low, s_high = distribution.support
    outside = (low is not None and (s_low < low or (declared.low_open and s_low <= low))) or (
        high is not None and (s_high > high or (declared.high_open and s_high >= high))
    )
    if outside:
        from planbench.params import range_text

        hint = " (truncate it with low and high)" if distribution.name == "normal" else ""
        raise ParamError(
            f"random.{shown} = {distribution.text()} reaches [{s_low:g}, {s_high:g}], outside "
            f"{shown}'s range {range_text(declared, column)}{hint}"
        )
    return Axis(key, plant, path, leaf, distribution=distribution)


def _freeze(value):
    """TOML lists as tuples (hashable); tables as they are."""
    if isinstance(value, list):
        return tuple(_freeze(v) for v in value)
    return value


def _thaw(value):
    if isinstance(value, tuple):
        return [_thaw(v) for v in value]
    return value


def _check_axes(spec: CampaignSpec) -> None:
    """Each grid value on the base alone: a value of the wrong type or out of its range is
    refused here, naming the axis. With invalid = "skip" only the field itself is checked
    (its combination with the base may break a limit that the runs' own values do not); a
    distribution's support is checked against the range where it is parsed (``_axis``), and
    the runs' combinations by ``CampaignSpec.resolve``."""
    for axis in spec.grid:
        for value in axis.values:
            _try(spec, axis, _thaw(value), whole=spec.invalid == "refuse")


def _try(spec: CampaignSpec, axis: Axis, value, whole: bool) -> None:
    base = spec.base_plant if axis.plant else spec.base_params
    data = {axis.path[0]: copy.deepcopy(base.to_dict()[axis.path[0]])}
    if len(axis.path) == 1:
        data[axis.path[0]] = value
    else:
        set_path(data, axis.path, value, axis.column)
    section = "grid" if axis.values is not None else "random"
    try:
        if whole:
            type(base).from_mapping(data, base=base, prefix="plant." if axis.plant else "")
        else:
            from planbench.params import _convert

            name = axis.path[0]
            declared = type(base).__dataclass_fields__[name].metadata["declared"]
            _convert(field_types(type(base))[name], data[name], ("plant." if axis.plant else "") + name, declared)
    except ParamError as e:
        raise ParamError(f"{section}.{axis.column} = {_show(value)}: {e}") from None


def iter_chunks(runs: Iterable[Run], size: int):
    """``runs`` in consecutive chunks of at most ``size``."""
    it = iter(runs)
    while chunk := list(itertools.islice(it, size)):
        yield chunk


# ------------------------------------------------------------------ columns (planner-only campaigns)

_M32 = np.uint64(0xFFFFFFFF)
_INIT_A, _MULT_A, _INIT_B, _MULT_B = 0x43B0D7E5, 0x931E8875, 0x8B51F9DD, 0x58F38DED
_MIX_L, _MIX_R, _POOL = 0xCA01F9DD, 0x4973F715, 4


def _words(n: int) -> list[int]:
    """``n`` as numpy's SeedSequence takes an int: little-endian 32-bit words (0: one word)."""
    out = [n & 0xFFFFFFFF]
    n >>= 32
    while n:
        out.append(n & 0xFFFFFFFF)
        n >>= 32
    return out


def run_seeds(seed: int, samples: np.ndarray, replicates: np.ndarray) -> np.ndarray:
    """``CampaignSpec.run_seed`` of every (sample, replicate), at once: numpy's SeedSequence
    (its entropy mixing and generate_state, in 32-bit arithmetic) on arrays, bit for bit
    what ``np.random.SeedSequence(seed, spawn_key=(2, s, r)).generate_state(2, np.uint32)``
    gives (tested), without a Python object per run."""
    samples = np.asarray(samples, dtype=np.int64)
    replicates = np.asarray(replicates, dtype=np.int64)
    if samples.size and (samples.max(initial=0) >= 2**32 or replicates.max(initial=0) >= 2**32):
        raise ValueError("samples and replicates above 2**32 have two words each")
    n = samples.shape[0]
    run = _words(seed)
    run += [0] * max(0, _POOL - len(run))
    entropy = [np.full(n, w, np.uint64) for w in run] + [
        np.full(n, 2, np.uint64),
        samples.astype(np.uint64),
        replicates.astype(np.uint64),
    ]
    const = [_INIT_A]

    def hashmix(value):
        value = value ^ np.uint64(const[0])
        const[0] = (const[0] * _MULT_A) & 0xFFFFFFFF
        value = (value * np.uint64(const[0])) & _M32
        return value ^ (value >> np.uint64(16))

    def mix(x, y):
        result = (np.uint64(_MIX_L) * x - np.uint64(_MIX_R) * y) & _M32
        return result ^ (result >> np.uint64(16))

    pool = [hashmix(entropy[i]) for i in range(_POOL)]
    for src in range(_POOL):
        for dst in range(_POOL):
            if src != dst:
                pool[dst] = mix(pool[dst], hashmix(pool[src]))
    for src in range(_POOL, len(entropy)):
        for dst in range(_POOL):
            pool[dst] = mix(pool[dst], hashmix(entropy[src]))
    state, hash_const = [], _INIT_B
    for i in range(2):
        value = pool[i] ^ np.uint64(hash_const)
        hash_const = (hash_const * _MULT_B) & 0xFFFFFFFF
        value = (value * np.uint64(hash_const)) & _M32
        state.append(value ^ (value >> np.uint64(16)))
    return (((state[0] << np.uint64(31)) ^ state[1]) & np.uint64(2**63 - 1)).astype(np.int64)
