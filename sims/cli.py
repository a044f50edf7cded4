"""The ``planbench`` command line (README.md, "Command line").

  planbench list
  planbench run NAME|FILE.toml|DIR/summary.json [--PARAMETER VALUE ...] [--set KEY=VALUE ...]
                [--out DIR] [--controller MODULE:FACTORY] [--planner MODULE:FACTORY]
                [--video FILE] [--camera overview|closeup] [--quiet]
  planbench run NAME --help      the scenario's parameters: units, defaults, ranges
  planbench plan NAME|FILE.toml [--PARAMETER VALUE ...] [--set KEY=VALUE ...] --out DIR
  planbench sweep SPEC.toml [--out DIR] [--engine local|ray] [--workers N] [--address ADDR]
                  [--rerun-worst K] [--quiet]
  planbench bench
  planbench demo [--out DIR]

Exit codes: 0 every check passed, 1 a check failed, 2 bad input (one line on stderr).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import re
import signal
import sys
import threading
from pathlib import Path

import planbench  # first: it chooses the OpenGL back end before mujoco is imported

EXIT_OK, EXIT_CHECK_FAILED, EXIT_BAD_INPUT = 0, 1, 2


class BadInput(Exception):
    """Raised for input errors: printed as one line, exit code 2."""


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # argparse takes "-1e3" for an option (its pattern knows only -12 and -1.5), so
        # "--heading -1e3" said "expected one argument" instead of reading the number.
        self._negative_number_matcher = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-inf$|^-nan$", re.IGNORECASE)

    def error(self, message):  # one line, exit 2, no usage dump
        raise BadInput(message)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="planbench", description="MuJoCo testbed for motion planners.")
    parser.add_argument("--version", action="version", version=f"planbench {planbench.__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    sub.add_parser("list", help="list the scenarios")
    sub.add_parser(
        "run", help="simulate a scenario and check it (planbench run NAME --help: its parameters)", add_help=False
    )
    sub.add_parser("plan", help="write a scenario's planned motion, no physics", add_help=False)
    bench = sub.add_parser("bench", help="benchmark table: realtime factors and loop/bare-mj_step ratios")
    bench.add_argument(
        "--six-hours",
        action="store_true",
        help="also measure the peak memory of a 6 h fast-tracking run (minutes of wall time)",
    )
    sweep = sub.add_parser(
        "sweep",
        help="a campaign: many runs from a spec (grids, draws, seeds, plant uncertainty), a results table and a report",
    )
    sweep.add_argument("spec", metavar="SPEC.toml", help='the campaign spec (README, "Campaigns")')
    sweep.add_argument(
        "--out",
        help="campaign directory (default results/SPEC-NAME); the same spec again resumes it, another spec is refused",
    )
    sweep.add_argument("--engine", default="local", help="local (a process pool, the default) or ray")
    sweep.add_argument(
        "--workers",
        type=int,
        default=None,
        help="processes of the local pool, or CPUs of a local Ray instance (default: the cores)",
    )
    sweep.add_argument(
        "--address", default=None, help="Ray cluster address (default RAY_ADDRESS, else a local Ray instance)"
    )
    sweep.add_argument(
        "--rerun-worst",
        type=int,
        default=0,
        metavar="K",
        help="afterwards, simulate the K worst runs again with a video each (DIR/worst/)",
    )
    sweep.add_argument("--quiet", action="store_true", help="no progress bar")
    demo = sub.add_parser("demo", help="run every scenario with a video; one table of checks")
    demo.add_argument(
        "--out", default="results", help="directory of the scenarios' output directories (default results)"
    )
    demo.add_argument("--quiet", action="store_true")
    return parser


#: Options of ``run`` and ``plan`` that are not parameters (no parameter may take these names).
RUN_OPTIONS = ("out", "video", "camera", "quiet", "planner", "controller", "set", "help", "timeout")


def _flag(name: str) -> str:
    return "--" + name.replace("_", "-")


def scenario_parser(command: str, scenario, source: str) -> argparse.ArgumentParser:
    """The parser of ``planbench run|plan SOURCE``: the scenario's own parameters as flags,
    derived from their declarations (planbench.params), and ``--set KEY=VALUE`` for any of them."""
    from planbench.params import describe

    cls = type(scenario.params)
    scalar = [d for d in cls.declarations() if d[1].scalar]
    other = [d for d in cls.declarations() if not d[1].scalar]
    epilog = ""
    if other:
        epilog = (
            "parameters set with --set KEY=VALUE (TOML syntax) or in a scenario file's [parameters]:\n"
            + "\n".join(
                f"  {name}: {describe(kind, declared, getattr(scenario.params, name))}"
                for name, kind, declared, _ in other
            )
        )
    parser = _Parser(
        prog=f"planbench {command} {source}",
        description=f"{scenario.name}: {scenario.summary}",
        epilog=epilog,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    group = parser.add_argument_group(
        f"parameters of {scenario.name} (defaults: this scenario's{', or the file' if source != scenario.name else ''})"
    )
    for name, kind, declared, _ in scalar:
        if name in RUN_OPTIONS:
            raise TypeError(f"parameter {name!r} of {cls.__name__} takes the name of an option")
        metavar = {"bool": "on|off", "int": "N", "float": "X", "str": "NAME"}[kind.kind]
        if declared.choices:
            metavar = "|".join(declared.choices)
        group.add_argument(
            _flag(name),
            dest=f"param_{name}",
            metavar=metavar,
            help=describe(kind, declared, getattr(scenario.params, name)).replace("%", "%%"),
        )
    for old in getattr(cls, "RENAMED", {}):  # a flag of an earlier name: refused with its name now
        parser.add_argument(_flag(old), dest=f"renamed_{old}", help=argparse.SUPPRESS)
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="set any parameter (TOML value syntax: --set 'moves=[{target=[1,0,0,0,0,0]}]'), "
        'or a field of the plant\'s uncertainty: --set plant.KEY=VALUE (README, "Campaigns")',
    )
    if command == "run":
        parser.add_argument(
            "--out", help="output directory (default results/NAME); replaced only if planbench wrote it"
        )
        parser.add_argument(
            "--controller",
            metavar="MODULE:FACTORY",
            help="your controller: FACTORY() in MODULE (an importable module or a .py file) "
            'returns it (README, "Your own planner or controller")',
        )
        parser.add_argument(
            "--planner", metavar="MODULE:FACTORY", help="your planner, the same way (the antenna's: an online planner)"
        )
        parser.add_argument("--video", help="write an H.264 video of the run here (.mp4, .m4v, .mov, .mkv)")
        parser.add_argument("--camera", default=None, help="video camera: overview or closeup")
        parser.add_argument("--quiet", action="store_true", help="no progress bars")
        parser.add_argument(
            "--timeout",
            metavar="SECONDS",
            help="wall-time limit of the run, s (default: 600 s plus the simulated duration); "
            "a run past it is stopped and fails its wall_time check",
        )
    else:
        parser.add_argument("--out", required=True, help="output directory; replaced only if planbench wrote it")
    return parser


SCENARIO_USAGE = (
    "usage: planbench {command} NAME|FILE.toml{rerun} [--set KEY=VALUE ...] [--PARAMETER VALUE ...] {more}\n"
    "\n"
    "NAME is a scenario of `planbench list`; FILE.toml a scenario file (scenario = NAME, [parameters]).\n"
    "`planbench {command} NAME --help` lists that scenario's parameters with units, defaults and ranges.\n"
)


def _resolve_source(command: str, argv: list[str]):
    """(Source, parsed options, resolved params, resolved plant) of ``planbench run|plan
    SOURCE ...``; ``--set plant.KEY=VALUE`` sets a field of the plant's uncertainty."""
    from planbench import scenario_files, scenarios
    from planbench.params import ParamError, set_overrides

    get, names = (
        (scenarios.get, scenarios.KnownNames())
        if command == "run"
        else (scenarios.get_plan, scenarios.KnownNames(plans=True))
    )
    try:
        source = scenario_files.resolve(argv[0], get, names)
    except ValueError as e:  # a ParamError, or an unknown scenario name
        raise BadInput(str(e)) from None
    scenario = source.scenario
    args = scenario_parser(command, scenario, argv[0]).parse_args(argv[1:])
    flags = {k[len("param_") :]: v for k, v in vars(args).items() if k.startswith("param_") and v is not None}
    cls = type(scenario.params)
    for old, new in getattr(cls, "RENAMED", {}).items():
        if getattr(args, f"renamed_{old}", None) is not None:
            raise BadInput(f"{_flag(old)}: the parameter is now {new}: --set {new}=VALUE")
    plant_set = [a[len("plant.") :] for a in args.set if a.startswith("plant.")]
    try:
        overrides = scenario_files.overrides_from_flags(cls, flags, [a for a in args.set if not a.startswith("plant.")])
        params = cls.from_mapping(overrides, base=source.params)
        plant = source.plant
        if plant_set:
            if plant is None:
                raise ParamError(f"--set plant.{plant_set[0]}: {scenario.name} declares no plant uncertainty")
            plant = type(plant).from_mapping(
                set_overrides(type(plant), plant_set, prefix="plant."), base=plant, prefix="plant."
            )
    except ParamError as e:
        raise BadInput(str(e)) from None
    return source, args, params, plant


def cmd_list(args) -> int:
    from planbench.scenarios import SCENARIOS

    width = max(len(n) for n in SCENARIOS)
    for s in SCENARIOS.values():
        print(f"{s.name:<{width}}  {s.summary}")
    return EXIT_OK


def format_checks(rows) -> str:
    """One table of (scenario, check) rows."""
    width = max([len("scenario")] + [len(scenario) for scenario, _ in rows])
    lines = [f"{'scenario':<{width}} {'check':<22} {'value':>12} {'limit':>10} {'unit':<6} result"]
    for scenario, c in rows:
        # A check that could not be evaluated shows "n/a" and its reason, not "nan".
        value = f"{c.value:>12.5g}" if c.evaluated else f"{'n/a':>12}"
        line = (
            f"{scenario:<{width}} {c.name:<22} {value} {c.comparison:>2}{c.limit:>8.4g} "
            f"{c.unit:<6} {'pass' if c.passed else 'FAIL'}"
        )
        lines.append(line if c.evaluated else f"{line} ({c.note})")
    return "\n".join(lines)


def _camera(scenario, requested: str | None) -> str:
    camera = scenario.camera if requested is None else requested
    if camera not in ("overview", "closeup"):
        raise BadInput(f"camera {camera!r} is not one of overview, closeup")
    return camera


def _scenario_help(command: str, argv: list[str]) -> int | None:
    """Usage of ``planbench run|plan`` without a scenario; None when a scenario is given."""
    if argv and not argv[0].startswith("-"):
        return None
    if argv and argv[0] not in ("-h", "--help"):
        raise BadInput(f"{command}: give a scenario NAME or FILE.toml first, not {argv[0]!r}")
    more = (
        "[--out DIR] [--video FILE] [--camera overview|closeup] [--quiet] [--controller MODULE:FACTORY] "
        "[--planner MODULE:FACTORY]"
        if command == "run"
        else "--out DIR"
    )
    print(SCENARIO_USAGE.format(command=command, rerun="|DIR/summary.json" if command == "run" else "", more=more))
    if not argv:
        raise BadInput(f"{command}: give a scenario NAME or FILE.toml (planbench list)")
    return EXIT_OK


def _timeout(raw: str | None) -> float | None:
    """``--timeout SECONDS``: a finite number > 0 (None: the default, planbench.supervise)."""
    if raw is None:
        return None
    try:
        value = float(raw)
    except ValueError:
        raise BadInput(f"--timeout {raw!r} is not a number of seconds") from None
    if not value > 0 or value == float("inf"):
        raise BadInput(f"--timeout {raw} s must be a finite number of seconds > 0")
    return value


def _plugin_names(plugins: dict) -> str:
    return ", ".join(f"--{role} {spec}" for role, spec in plugins.items()) or "planbench's own components"


def _write_unfinished(out, scenario, params, plugins: dict, check, partial=None) -> None:
    """summary.json of a run that did not complete (it hung or its process ended): passed
    false, the one check that says why; no timeseries. ``partial``: the log the run had
    streamed when it ended (``planbench.outputs.partial_log``), moved in as log.arrow: it has
    no footer and reads as incomplete (``planbench.logfile.read_log``)."""
    import json

    from planbench.logfile import LOG_FILE, read_log
    from planbench.outputs import software_versions

    summary = {
        "scenario": scenario.name,
        "passed": False,
        "seed": getattr(params, "seed", None),
        "completed": False,
        "parameters": params.to_dict(),
        "versions": software_versions(),
        "plugins": plugins,
        "checks": [check.to_json()],
        "metrics": {},
    }
    log = None
    if partial is not None:
        try:
            log = read_log(partial)
        except (OSError, ValueError):  # killed before its first bytes: nothing to keep
            partial = None
    if log is not None:
        summary["log"] = {"path": LOG_FILE, "ticks": log.n, "complete": log.complete, "chunks": log.num_chunks}
        del log  # (closed before it moves)
    with out.staging({"scenario": scenario.name}) as tmp:
        if partial is not None:
            os.rename(partial, tmp / LOG_FILE)
        (tmp / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")


def cmd_run(argv: list[str]) -> int:
    from planbench import outputs, pipeline, supervise
    from planbench import plugins as plugins_module
    from planbench.checks import Check

    shown = _scenario_help("run", argv)
    if shown is not None:
        return shown
    source, args, params, plant = _resolve_source("run", argv)
    scenario = source.scenario
    camera = _camera(scenario, args.camera)
    timeout = _timeout(args.timeout)
    plugins = dict(source.plugins)
    plugins.update(
        {role: spec for role, spec in (("planner", args.planner), ("controller", args.controller)) if spec is not None}
    )
    for role, spec in plugins.items():  # the spec's form, before anything is reserved
        plugins_module.split_spec(spec, role)
    if source.recorded_versions:
        now = outputs.software_versions()
        differ = {k: (v, now.get(k)) for k, v in source.recorded_versions.items() if now.get(k) != v}
        if differ:
            print(
                "planbench: note: "
                + source.origin
                + " was written with "
                + ", ".join(f"{k} {old} (now {new})" for k, (old, new) in differ.items())
                + "; the rerun may differ",
                file=sys.stderr,
            )
    out = outputs.OutputDir(Path("results") / scenario.name if args.out is None else args.out)
    video = None if args.video is None else outputs.VideoFile(args.video, out)

    def work():
        # In the supervised child: the plug-ins' code runs here only.
        _, result = pipeline.execute(
            scenario,
            params,
            plant,
            plugins=plugins,
            out=out,
            video=video,
            camera=camera,
            quiet=args.quiet,
            on_built=lambda setup: supervise.report_duration(setup.task.duration),
        )
        return ([(scenario.name, c) for c in result.checks], result.passed, result.sim_time_s, result.wall_time_s)

    with contextlib.ExitStack() as reserved:  # lock before simulating: a second run is refused
        reserved.enter_context(out.reserved())
        if video is not None:
            reserved.enter_context(video.reserved())
        try:
            rows, passed, sim_time_s, wall_time_s = supervise.run_supervised(work, timeout)
        except KeyboardInterrupt:
            # Stopped by its user: the child, told to stop as at its time limit, kept the log
            # streamed so far for an unfinished run's summary, which an interrupt does not write.
            outputs.remove_leftovers(out.path)
            raise
        except supervise.Fault as fault:
            ended = fault.ended
            partial = outputs.partial_log(out.path)  # the log the child streamed, if any
            if video is not None:
                outputs.remove_leftovers(video.path)
            who = _plugin_names(plugins)
            if not ended.timed_out and not ended.phase.startswith(supervise.AFTER_FIRST_STEP):
                outputs.remove_leftovers(out.path)  # the child's staging directory, if any
                raise BadInput(
                    f"the run ended in {ended.phase} ({who}) before any physics step, without "
                    f"completing: {ended.how}; nothing was written"
                ) from None
            if ended.timed_out:
                check = Check(
                    "wall_time",
                    round(ended.elapsed_s, 3),
                    ended.limit_s,
                    "s",
                    note=f"the run passed its time limit in {ended.phase} ({who}) and was stopped",
                )
            else:
                check = Check(
                    "run_completed",
                    0.0,
                    1.0,
                    "count",
                    "==",
                    note=f"the run ended in {ended.phase} ({who}): {ended.how}",
                )
            _write_unfinished(out, scenario, params, plugins, check, partial)
            outputs.remove_leftovers(out.path)  # the rest of the child's staging directory
            print(format_checks([(scenario.name, check)]))
            print(f"planbench: error: {scenario.name}: {check.note}", file=sys.stderr)
            print(f"FAILED: {scenario.name} did not complete; summary in {out}")
            return EXIT_CHECK_FAILED
    print(format_checks(rows))
    print(
        f"{'PASSED' if passed else 'FAILED'}: {scenario.name}, "
        f"{sim_time_s:.2f} s simulated in {wall_time_s:.2f} s; outputs in {out}"
    )
    return EXIT_OK if passed else EXIT_CHECK_FAILED


def cmd_plan(argv: list[str]) -> int:
    from planbench import outputs, plans

    shown = _scenario_help("plan", argv)
    if shown is not None:
        return shown
    source, args, params, _ = _resolve_source("plan", argv)
    out = outputs.OutputDir(args.out, kind="plan")
    with out.reserved():
        plans.write_plan(source.scenario, out, params)
    print(f"plan of {source.scenario.name} written to {out}")
    return EXIT_OK


def cmd_bench(args) -> int:
    from planbench import bench

    print(bench.format_table(bench.run_all()))
    for text in bench.planner_benchmarks():
        print()
        print(text)
    print()
    print(bench.format_campaign(bench.campaign_throughput()))
    print(bench.format_planner_only(bench.planner_only_throughput()))
    print()
    print(bench.format_memory(bench.memory_by_run_length(six_hours=args.six_hours)))
    return EXIT_OK


def cmd_sweep(args) -> int:
    from planbench import campaign
    from planbench.params import ParamError

    out = args.out if args.out is not None else Path("results") / Path(args.spec).stem
    try:
        outcome = campaign.sweep(
            args.spec,
            out,
            engine=args.engine,
            workers=args.workers,
            address=args.address,
            rerun_worst=args.rerun_worst,
            quiet=args.quiet,
        )
    except ParamError as e:
        raise BadInput(str(e)) from None
    from planbench.campaign.report import format_summary

    print(format_summary(outcome.summary))
    o = outcome.summary["overall"]
    print(
        f"{'PASSED' if o['passed'] == o['counted'] else 'NOT ALL PASSED'}: {o['passed']} of {o['counted']} runs "
        f"passed ({outcome.ran} run now, {outcome.skipped} resumed); table {Path(out) / 'results.parquet'}, "
        f"report {Path(out) / 'campaign.png'}"
    )
    return EXIT_OK if o["passed"] == o["counted"] else EXIT_CHECK_FAILED


def _demo_root(raw: str) -> Path:
    """The demo's directory: validated as a run's output is (planbench.outputs.OutputRoot: never
    the root, the current or the home directory, nor one holding files planbench did not
    write), created if missing, never replaced itself (only the scenarios' directories
    inside it are)."""
    from planbench import outputs, scenarios

    return outputs.OutputRoot(raw, "demo --out", inner=tuple(s.name for s in scenarios.tagged(scenarios.DEMO))).path


def cmd_demo(args) -> int:
    from planbench import outputs, pipeline, scenarios

    root = _demo_root(args.out)
    demo = scenarios.tagged(scenarios.DEMO)
    targets = {
        s.name: outputs.OutputDir(root / s.name, option="demo --out") for s in demo
    }  # every one validated before the first run
    rows, unexpected = [], []
    with contextlib.ExitStack() as reserved:
        for target in targets.values():
            reserved.enter_context(target.reserved())
        for scenario in demo:
            out = targets[scenario.name]
            _, result = pipeline.execute(
                scenario,
                scenario.params,
                out=out,
                video=outputs.VideoFile(out.path / f"{scenario.name}.mp4", out),
                quiet=args.quiet,
                more_videos=tuple((f"{scenario.name}-{c}.mp4", c) for c in scenario.demo_cameras),
            )
            rows += [(scenario.name, c) for c in result.checks]
            verdict = "passed" if result.passed else "failed"
            expected = "as expected" if result.passed == scenario.expect_pass else "UNEXPECTEDLY"
            if result.passed != scenario.expect_pass:
                unexpected.append(scenario.name)
            print(
                f"{scenario.name}: {verdict} {expected} ({result.sim_time_s:.1f} s simulated in "
                f"{result.wall_time_s:.1f} s) -> {out}",
                flush=True,
            )
    print()
    print(format_checks(rows))
    if unexpected:
        print(f"\nunexpected outcome: {', '.join(unexpected)}")
        return EXIT_CHECK_FAILED
    print(f"\nall {len(demo)} scenarios behaved as expected (loader-direct is meant to fail its obstacle check)")
    return EXIT_OK


COMMANDS = {
    "list": cmd_list,
    "run": cmd_run,
    "plan": cmd_plan,
    "bench": cmd_bench,
    "demo": cmd_demo,
    "sweep": cmd_sweep,
}


class _Interrupt:
    """SIGINT, SIGTERM and SIGHUP become one KeyboardInterrupt (the first only: a second
    Ctrl-C must not break the clean-up of the first); ``signum`` remembers which came."""

    def __init__(self):
        self.signum = None
        self._old = {}

    def __enter__(self):
        from planbench.outputs import INTERRUPT_SIGNALS  # the ones its clean-ups defer

        if threading.current_thread() is threading.main_thread():
            self._old = {s: signal.signal(s, self._handle) for s in INTERRUPT_SIGNALS}
        return self

    def __exit__(self, *exc):
        for s, handler in self._old.items():
            signal.signal(s, handler)
        return False

    def _handle(self, signum, frame):
        if self.signum is None:
            self.signum = signum
            raise KeyboardInterrupt


def main(argv=None) -> int:
    """Run the CLI; returns the exit code (0, 1, 2, or 130 / 128 + signal on an interrupt)."""
    from planbench.outputs import OutputError
    from planbench.planners.errors import PlanningError
    from planbench.task import PluginError

    with _Interrupt() as interrupt:
        try:
            argv = sys.argv[1:] if argv is None else list(argv)
            if argv and argv[0] in ("run", "plan"):  # their options depend on the scenario
                return COMMANDS[argv[0]](argv[1:])
            args = build_parser().parse_args(argv)
            return COMMANDS[args.command](args)
        except SystemExit as e:  # argparse's --help
            if interrupt.signum is None:
                return int(e.code or 0)
            raise
        except BaseException as e:
            # An interrupt also kills ffmpeg (the terminal signals the whole process group),
            # so whatever was raised after it is its consequence: one line, no traceback.
            if interrupt.signum is not None or isinstance(e, KeyboardInterrupt):
                signum = interrupt.signum or signal.SIGINT
                print(
                    f"planbench: interrupted by {signal.Signals(signum).name}; nothing half-written was left",
                    file=sys.stderr,
                )
                return 128 + int(signum)
            if isinstance(e, (BadInput, PlanningError, OutputError, PluginError)):
                print(f"planbench: error: {e}", file=sys.stderr)
                return EXIT_BAD_INPUT
            raise


if __name__ == "__main__":
    sys.exit(main())
