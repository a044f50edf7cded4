"""planbench from Python: run a scenario with your own planner or controller objects.

    from planbench import api

    result = api.run("loader-supply", controller=MyController(), params={"seed": 1, "payload_mass": 50.0})
    print(result.passed, [(c.name, c.value, c.limit) for c in result.checks])

What the objects must provide is the Task contract (``planbench.task``): a controller has
``reset(context)`` and ``__call__(tick, observation)``; a planner ``plan(problem)`` returning a
``planbench.planners.trajectory.Trajectory`` (the antenna's: ``reset(problem)`` and
``step(t, attitude)``). ``planbench run NAME --controller MODULE:FACTORY`` does the same from
the command line (``planbench.plugins``).
"""

from __future__ import annotations

from planbench import outputs, pipeline, runner, scenarios
from planbench.task import check_controller, check_planner


def run(scenario: str, *, planner=None, controller=None, params=None, plant=None,
        out=None, video=None, quiet: bool = True) -> runner.RunResult:
    """Run the scenario ``scenario`` and return its ``runner.RunResult``.

    Args:
      scenario: a name of ``planbench list``.
      planner: your planner, None for the paper's.
      controller: your controller, None for ours.
      params: the scenario's parameters: a mapping of overrides (keys of
        ``planbench run NAME --help``), or its Params object; None for its defaults.
      plant: the plant's uncertainty (README, "Campaigns"): a mapping of the mechanism's
        plant fields, or its PlantParams object; None for the nominal plant. Your planner
        and controller still get the nominal model.
      out: an output directory to write (summary.json, timeseries.npz, report.png) as
        ``planbench run --out`` does, or None to write nothing.
      video: a video file to render into (needs ``out``).
      quiet: no progress bars.

    Raises:
      planbench.task.PluginError: a planner or controller that breaks the Task contract (before
        anything runs), planbench.params.ParamError (a ValueError) for bad parameters. A
        controller that raises during the run does not raise here: the run ends and its
        ``controller_errors`` check fails with the message.
    """
    spec = scenarios.get(scenario)
    params = spec.resolve(params) if params is None or isinstance(params, dict) else params
    if type(params) is not type(spec.params):
        raise TypeError(f"params of {spec.name} are {type(spec.params).__name__}, not {type(params).__name__}")
    plant = spec.resolve_plant(plant) if plant is None or isinstance(plant, dict) else plant
    if spec.plant is not None and type(plant) is not type(spec.plant):
        raise TypeError(f"plant of {spec.name} is {type(spec.plant).__name__}, not {type(plant).__name__}")
    if controller is not None:
        check_controller(controller)
    if planner is not None:
        check_planner(planner, online=spec.online_planner)
    if video is not None and out is None:
        raise ValueError("a video needs an output directory: give out= too")
    target = None if out is None else outputs.OutputDir(out)
    video_file = None if video is None else outputs.VideoFile(video, target)

    def execute():
        return pipeline.execute(spec, params, plant, planner=planner, controller=controller, out=target,
                                video=video_file, quiet=quiet)[1]

    if target is None:
        return execute()
    with target.reserved():
        if video_file is None:
            return execute()
        with video_file.reserved():
            return execute()
