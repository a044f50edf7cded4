"""The ``planbench`` command line (ARCHITECTURE.md, "Contracts").

  planbench list
  planbench run NAME [--out DIR] [--seed N] [--wind M_PER_S] [--elevation DEG]
                [--hs M] [--tp S] [--heading DEG] [--imu-rate HZ] [--imu-latency S]
                [--no-prediction] [--wind-direction DEG] [--stewart on|off]
                [--cable-segments N] [--duration S]
                [--controller MODULE:FACTORY] [--planner MODULE:FACTORY]
                [--video FILE] [--camera overview|closeup] [--quiet]
  planbench plan NAME --out DIR
  planbench bench
  planbench demo [--out DIR]

Exit codes: 0 every check passed, 1 a check failed, 2 bad input (one line on stderr).
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import math
import os
import re
import signal
import sys
import threading
from pathlib import Path

import sims  # noqa: F401  (chooses the OpenGL back end before mujoco is imported)

EXIT_OK, EXIT_CHECK_FAILED, EXIT_BAD_INPUT = 0, 1, 2


class BadInput(Exception):
    """Raised for input errors: printed as one line, exit code 2."""


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # argparse takes "-1e3" for an option (its pattern knows only -12 and -1.5), so
        # "--heading -1e3" said "expected one argument" instead of reading the number.
        self._negative_number_matcher = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-inf$|^-nan$",
                                                   re.IGNORECASE)

    def error(self, message):  # one line, exit 2, no usage dump
        raise BadInput(message)


def _finite(kind: str, minimum: float | None = None, strict: bool = False):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{kind} {text!r} is not a number") from None
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"{kind} {text} is not finite")
        if minimum is not None and (value <= minimum if strict else value < minimum):
            raise argparse.ArgumentTypeError(
                f"{kind} {text} must be {'>' if strict else '>='} {minimum:g}"
            )
        return value

    return parse


def _seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"seed {text!r} is not an integer") from None
    if not 0 <= value < 2**63:
        raise argparse.ArgumentTypeError(f"seed {value} must be in [0, 2^63)")
    return value


def _cable_segments(text: str) -> int:
    """2 ... the model's limit (sims.fast.physics.max_cable_segments: 14 at the 2 ms step)."""
    from sims.fast.physics import SEGMENT_OMEGA_DT_LIMIT, max_cable_segments

    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"cable segments {text!r} is not an integer") from None
    most = max_cable_segments()
    if not 2 <= value <= most:
        raise argparse.ArgumentTypeError(
            f"cable segments {value} must be in [2, {most}]: more segments vibrate beyond the "
            f"timestep's limit omega dt <= {SEGMENT_OMEGA_DT_LIMIT:g}; use at most {most} segments")
    return value


def _checked(kind: str, check, minimum: float | None = None, strict: bool = False):
    """A finite number (``_finite``), then ``check(value)`` of the Python API, whose
    ValueError (naming the value, the limit and its source) becomes the parse error: the
    CLI and the API refuse the same values with the same words."""
    number = _finite(kind, minimum, strict)

    def parse(text: str) -> float:
        value = number(text)
        try:
            check(value)
        except ValueError as e:
            raise argparse.ArgumentTypeError(str(e)) from None
        return value

    return parse


def build_parser() -> argparse.ArgumentParser:
    from sims.run_limits import check_angle
    from sims.antenna.ship_motion import check_peak_period, check_wave_height
    from sims.wind import check_mean_speed

    parser = _Parser(prog="planbench", description="MuJoCo testbed for motion planners.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    sub.add_parser("list", help="list the scenarios")
    run = sub.add_parser("run", help="simulate a scenario and check it")
    run.add_argument("name")
    run.add_argument("--out", help="output directory (default results/NAME); replaced only if "
                     "planbench wrote it")
    run.add_argument("--seed", type=_seed, default=0)
    run.add_argument("--wind", type=_checked("wind speed", check_mean_speed, 0.0),
                     help="mean wind, m/s (0 ... 50: IEC 61400-1 class I, the Kaimal model's range)")
    run.add_argument("--elevation", type=_finite("elevation"),
                     help="telescope elevation, deg (hexapod scenarios: 15 ... 90)")
    run.add_argument("--hs", type=_checked("significant wave height", check_wave_height, 0.0, strict=True),
                     help="significant wave height, m (sea-state scenarios; 0 < Hs <= 20, and no steeper "
                          "than 2 pi Hs / (g Tp^2) = 1/15 at Tp <= 8 s ... 1/25 at Tp >= 15 s, DNV-RP-C205)")
    run.add_argument("--tp", type=_checked("peak period", check_peak_period, 0.0, strict=True),
                     help="spectral peak period, s (sea-state scenarios; 1 ... 30, wind seas and swell)")
    run.add_argument("--heading", type=_checked("wave heading", functools.partial(check_angle, "wave heading")),
                     help="wave heading off the bow, deg: 180 head seas, 90 beam seas from starboard "
                          "(sea-state scenarios; -360 ... 360, refused beyond, not wrapped)")
    run.add_argument("--imu-rate", type=_finite("IMU rate", 0.0, strict=True),
                     help="antenna IMU samples per second, Hz (200 / a whole number, 1 ... 200: "
                          "20, 25, 40, 50 are the paper's range)")
    run.add_argument("--imu-latency", type=_finite("IMU latency", 0.0),
                     help="antenna IMU latency, s (a multiple of 5 ms, at most 1 s)")
    run.add_argument("--no-prediction", action="store_true",
                     help="antenna controller: use each IMU sample as it is, no gyro prediction")
    run.add_argument("--wind-direction", type=_checked("wind direction", functools.partial(check_angle, "wind direction")),
                     help="azimuth the wind blows toward, deg from east toward north (FAST scenarios; "
                          "default 0; -360 ... 360, refused beyond, not wrapped)")
    run.add_argument("--cable-segments", type=_cable_segments,
                     help="FAST: each cable as a chain of N elastic segments (2-14 at the 2 ms timestep; "
                          "default: straight cables with the lumped catenary law)")
    run.add_argument("--stewart", choices=("on", "off"),
                     help="FAST's Stewart stabilizer: on (default) or off (FAST scenarios)")
    run.add_argument("--duration", type=_finite("duration", 0.0, strict=True),
                     help="simulated time, s (at least one control tick; refused if its log would "
                          "take more than a quarter of this machine's memory)")
    run.add_argument("--controller", metavar="MODULE:FACTORY",
                     help="your controller: FACTORY() in MODULE (an importable module or a .py file) "
                          "returns it (README, \"Your own planner or controller\")")
    run.add_argument("--planner", metavar="MODULE:FACTORY",
                     help="your planner, the same way (the antenna's: an online planner)")
    run.add_argument("--video", help="write an H.264 video of the run here (.mp4, .m4v, .mov, .mkv)")
    run.add_argument("--camera", default=None, help="video camera: overview or closeup")
    run.add_argument("--quiet", action="store_true", help="no progress bars")
    plan = sub.add_parser("plan", help="write a scenario's planned motion, no physics")
    plan.add_argument("name")
    plan.add_argument("--out", required=True, help="output directory; replaced only if planbench wrote it")
    sub.add_parser("bench", help="benchmark table: realtime factors and loop/bare-mj_step ratios")
    demo = sub.add_parser("demo", help="run every scenario with a video; one table of checks")
    demo.add_argument("--out", default="results",
                      help="directory of the scenarios' output directories (default results)")
    demo.add_argument("--quiet", action="store_true")
    return parser


def _options(scenario, args):
    from sims.scenarios import RunOptions

    if args.wind is not None and "wind" not in scenario.options:
        raise BadInput(f"scenario {scenario.name} has no wind model; --wind is not accepted")
    if args.elevation is not None and "elevation" not in scenario.options:
        raise BadInput(f"scenario {scenario.name} has no elevation; --elevation is not accepted")
    for option in ("hs", "tp", "heading"):
        if getattr(args, option) is not None and option not in scenario.options:
            raise BadInput(f"scenario {scenario.name} has no sea state; --{option} is not accepted")
    imu_given = args.imu_rate is not None or args.imu_latency is not None or args.no_prediction
    if imu_given and "imu" not in scenario.options:
        raise BadInput(f"scenario {scenario.name} has no IMU; --imu-rate, --imu-latency and "
                       "--no-prediction are not accepted")
    if args.wind_direction is not None and "wind_direction" not in scenario.options:
        raise BadInput(f"scenario {scenario.name} has no wind direction; --wind-direction is not accepted")
    if args.cable_segments is not None and "cables" not in scenario.options:
        raise BadInput(f"scenario {scenario.name} has no cables; --cable-segments is not accepted")
    if args.stewart is not None and "stewart" not in scenario.options:
        raise BadInput(f"scenario {scenario.name} has no Stewart stabilizer; --stewart is not accepted")
    options = RunOptions(seed=args.seed, duration=args.duration, wind=args.wind,
                         elevation=args.elevation, hs=args.hs, tp=args.tp, heading=args.heading,
                         imu_rate=args.imu_rate, imu_latency=args.imu_latency,
                         predict=not args.no_prediction,
                         stewart=None if args.stewart is None else args.stewart == "on",
                         wind_direction=args.wind_direction, cable_segments=args.cable_segments)
    # Valid numbers that are not a run (a duration under one tick or too long for memory, a
    # sea no sea has, ...): the scenario's own checks, the ones its build makes again.
    try:
        scenario.validate(options)
    except ValueError as e:
        raise BadInput(str(e)) from None
    return options


def cmd_list(args) -> int:
    from sims.scenarios import SCENARIOS

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
        line = (f"{scenario:<{width}} {c.name:<22} {value} {c.comparison:>2}{c.limit:>8.4g} "
                f"{c.unit:<6} {'pass' if c.passed else 'FAIL'}")
        lines.append(line if c.evaluated else f"{line} ({c.note})")
    return "\n".join(lines)


def _camera(scenario, requested: str | None) -> str:
    camera = scenario.camera if requested is None else requested
    if camera not in ("overview", "closeup"):
        raise BadInput(f"camera {camera!r} is not one of overview, closeup")
    return camera


def cmd_run(args) -> int:
    from sims import outputs, runner, scenarios
    from sims import plugins as plugins_module

    try:
        scenario = scenarios.get(args.name)
    except ValueError as e:
        raise BadInput(str(e)) from None
    options = _options(scenario, args)
    camera = _camera(scenario, args.camera)
    plugins = {role: plugin_spec for role, plugin_spec in (("planner", args.planner), ("controller", args.controller))
               if plugin_spec is not None}
    made = {role: plugins_module.make(plugin_spec, role, online_planner=scenario.online_planner)
            for role, plugin_spec in plugins.items()}
    out = outputs.OutputDir(Path("results") / scenario.name if args.out is None else args.out)
    video = None if args.video is None else outputs.VideoFile(args.video, out)
    with contextlib.ExitStack() as reserved:  # lock before simulating: a second run is refused
        reserved.enter_context(out.reserved())
        if video is not None:
            reserved.enter_context(video.reserved())
        setup = scenario.build(options, **made)
        result = runner.run(scenario.name, setup, quiet=args.quiet)
        result.plugins = plugins
        outputs.write_run(result, setup, out, video=video, camera=camera, quiet=args.quiet)
    print(format_checks([(scenario.name, c) for c in result.checks]))
    print(f"{'PASSED' if result.passed else 'FAILED'}: {scenario.name}, "
          f"{result.sim_time_s:.2f} s simulated in {result.wall_time_s:.2f} s; outputs in {out}")
    return EXIT_OK if result.passed else EXIT_CHECK_FAILED


def cmd_plan(args) -> int:
    from sims import outputs, plans, scenarios

    try:
        scenario = scenarios.get_plan(args.name)
    except ValueError as e:
        raise BadInput(str(e)) from None
    out = outputs.OutputDir(args.out, kind="plan")
    with out.reserved():
        plans.write_plan(scenario, out)
    print(f"plan of {scenario.name} written to {out}")
    return EXIT_OK


def cmd_bench(args) -> int:
    from sims import bench

    print(bench.format_table(bench.run_all()))
    for text in bench.planner_benchmarks():
        print()
        print(text)
    return EXIT_OK


def _demo_root(raw: str) -> Path:
    """The demo's directory: created if missing, never replaced itself (only the scenarios'
    directories inside it are)."""
    from sims.outputs import OutputError

    if raw.strip() == "":
        raise BadInput("demo --out '' is empty; give it a directory")
    root = Path(raw)
    if os.path.lexists(root) and not root.is_dir():
        raise OutputError(f"demo --out {root} exists and is not a directory")
    return root


def cmd_demo(args) -> int:
    from sims import outputs, runner, scenarios

    root = _demo_root(args.out)
    targets = {name: outputs.OutputDir(root / name, option="demo --out")
               for name in scenarios.SCENARIOS}  # every one validated before the first run
    rows, unexpected = [], []
    with contextlib.ExitStack() as reserved:
        for target in targets.values():
            reserved.enter_context(target.reserved())
        for scenario in scenarios.SCENARIOS.values():
            out = targets[scenario.name]
            setup = scenario.build(scenarios.RunOptions())
            result = runner.run(scenario.name, setup, quiet=args.quiet)
            outputs.write_run(result, setup, out, video=outputs.VideoFile(out.path / f"{scenario.name}.mp4", out),
                              camera=scenario.camera, quiet=args.quiet,
                              more_videos=[(f"{scenario.name}-{c}.mp4", c) for c in scenario.demo_cameras])
            rows += [(scenario.name, c) for c in result.checks]
            verdict = "passed" if result.passed else "failed"
            expected = "as expected" if result.passed == scenario.expect_pass else "UNEXPECTEDLY"
            if result.passed != scenario.expect_pass:
                unexpected.append(scenario.name)
            print(f"{scenario.name}: {verdict} {expected} ({result.sim_time_s:.1f} s simulated in "
                  f"{result.wall_time_s:.1f} s) -> {out}", flush=True)
    print()
    print(format_checks(rows))
    if unexpected:
        print(f"\nunexpected outcome: {', '.join(unexpected)}")
        return EXIT_CHECK_FAILED
    print(f"\nall {len(scenarios.SCENARIOS)} scenarios behaved as expected "
          "(loader-direct is meant to fail its obstacle check)")
    return EXIT_OK


COMMANDS = {"list": cmd_list, "run": cmd_run, "plan": cmd_plan, "bench": cmd_bench, "demo": cmd_demo}


class _Interrupt:
    """SIGINT, SIGTERM and SIGHUP become one KeyboardInterrupt (the first only: a second
    Ctrl-C must not break the clean-up of the first); ``signum`` remembers which came."""

    def __init__(self):
        self.signum = None
        self._old = {}

    def __enter__(self):
        from sims.outputs import INTERRUPT_SIGNALS  # the ones its clean-ups defer

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
    from planners.errors import PlanningError
    from sims.outputs import OutputError
    from sims.task import PluginError

    with _Interrupt() as interrupt:
        try:
            args = build_parser().parse_args(argv)
            return COMMANDS[args.command](args)
        except BaseException as e:
            # An interrupt also kills ffmpeg (the terminal signals the whole process group),
            # so whatever was raised after it is its consequence: one line, no traceback.
            if interrupt.signum is not None or isinstance(e, KeyboardInterrupt):
                signum = interrupt.signum or signal.SIGINT
                print(f"planbench: interrupted by {signal.Signals(signum).name}; nothing "
                      "half-written was left", file=sys.stderr)
                return 128 + int(signum)
            if isinstance(e, (BadInput, PlanningError, OutputError, PluginError)):
                print(f"planbench: error: {e}", file=sys.stderr)
                return EXIT_BAD_INPUT
            raise


if __name__ == "__main__":
    sys.exit(main())
