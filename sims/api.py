"""planbench from Python: run a scenario with your own planner or controller objects.

    from sims import api
    from sims.scenarios import RunOptions

    result = api.run("loader-supply", controller=MyController(), options=RunOptions(seed=1))
    print(result.passed, [(c.name, c.value, c.limit) for c in result.checks])

What the objects must provide is the Task contract (``sims.task``): a controller has
``reset(context)`` and ``__call__(tick, observation)``; a planner ``plan(problem)`` returning a
``planners.trajectory.Trajectory`` (the antenna's: ``reset(problem)`` and
``step(t, attitude)``). ``planbench run NAME --controller MODULE:FACTORY`` does the same from
the command line (``sims.plugins``).
"""

from __future__ import annotations

from sims import outputs, runner, scenarios
from sims.task import check_controller, check_planner


def run(scenario: str, *, planner=None, controller=None, options: scenarios.RunOptions | None = None,
        out=None, video=None, quiet: bool = True) -> runner.RunResult:
    """Run the scenario ``scenario`` and return its ``runner.RunResult``.

    Args:
      scenario: a name of ``planbench list``.
      planner: your planner, None for the paper's.
      controller: your controller, None for ours.
      options: seed, duration and the scenario's options (``scenarios.RunOptions``).
      out: an output directory to write (summary.json, timeseries.npz, report.png) as
        ``planbench run --out`` does, or None to write nothing.
      video: a video file to render into (needs ``out``).
      quiet: no progress bars.

    Raises:
      sims.task.PluginError: a planner or controller that breaks the Task contract (before
        anything runs), planners.errors.PlanningError and ValueError for bad options. A
        controller that raises during the run does not raise here: the run ends and its
        ``controller_errors`` check fails with the message.
    """
    spec = scenarios.get(scenario)
    options = scenarios.RunOptions() if options is None else options
    if controller is not None:
        check_controller(controller)
    if planner is not None:
        check_planner(planner, online=spec.online_planner)
    if video is not None and out is None:
        raise ValueError("a video needs an output directory: give out= too")
    spec.validate(options)
    target = None if out is None else outputs.OutputDir(out)
    video_file = None if video is None else outputs.VideoFile(video, target)
    if target is None:
        return runner.run(spec.name, spec.build(options, planner=planner, controller=controller), quiet=quiet)
    with target.reserved():
        if video_file is None:
            return _run_and_write(spec, options, planner, controller, target, None, quiet)
        with video_file.reserved():
            return _run_and_write(spec, options, planner, controller, target, video_file, quiet)


def _run_and_write(spec, options, planner, controller, target, video, quiet):
    setup = spec.build(options, planner=planner, controller=controller)
    result = runner.run(spec.name, setup, quiet=quiet)
    outputs.write_run(result, setup, target, video=video, camera=spec.camera, quiet=quiet)
    return result
