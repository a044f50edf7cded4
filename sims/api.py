"""planbench from Python: the entry points that ``planbench`` re-exports (``run``, ``plan``,
``sweep``, ``environment``, ``scenario_names``).

    import planbench

    result = planbench.run("loader-supply", controller=MyController(), params={"seed": 1, "payload_mass": 50.0})
    print(result.passed, [(c.name, c.value, c.limit) for c in result.checks])

What the objects must provide is the Task contract (``planbench.task``): a controller has
``reset(context)`` and ``__call__(tick, observation)``; a planner ``plan(problem)`` returning a
``planbench.planners.trajectory.Trajectory`` (the antenna's: ``reset(problem)`` and
``step(t, attitude)``). ``planbench run NAME --controller MODULE:FACTORY`` does the same from
the command line (``planbench.plugins``).
"""

from __future__ import annotations

from planbench import outputs, pipeline, runner, scenarios
from planbench.task import PluginError, check_controller, check_planner


def run(
    scenario: str, *, planner=None, controller=None, params=None, plant=None, out=None, video=None, quiet: bool = True
) -> runner.RunResult:
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
        return pipeline.execute(
            spec, params, plant, planner=planner, controller=controller, out=target, video=video_file, quiet=quiet
        )[1]

    if target is None:
        return execute()
    with target.reserved():
        if video_file is None:
            return execute()
        with video_file.reserved():
            return execute()


def plan(scenario: str, *, planner=None, params=None):
    """The planned motion of the scenario ``scenario`` (``planbench plan``, no physics): the
    ``Trajectory`` its planner returns for its problem.

    Args:
      scenario: a name of ``planbench list`` (or a plan-only entry of ``planbench plan``).
      planner: your planner (``plan(problem)``), None for the paper's. Your planner gets the
        problem the scenario's run would give it (the model is compiled for that, not
        stepped).
      params: overrides of the scenario's parameters (a mapping), or its Params object.

    Raises:
      planbench.PluginError: a planner that breaks the contract, or an online planner (the
        antenna's plans one attitude at a time, during a run: use ``run``).
      planbench.PlanningError: a problem the planner cannot solve.
    """
    spec = scenarios.get_plan(scenario) if planner is None else scenarios.get(scenario)
    params = spec.resolve(params) if params is None or isinstance(params, dict) else params
    if planner is None:
        return spec.plan(params)
    if spec.online_planner:
        raise PluginError(
            f"{spec.name}'s planner is online (reset and step during the run): "
            "planbench.run judges it, plan has no trajectory to give"
        )
    check_planner(planner, online=False)
    return spec.build(params, planner=planner).components.trajectory


def sweep(
    spec, out, *, engine: str = "local", workers: int | None = None, address: str | None = None, quiet: bool = True
):
    """Run (or resume) the campaign of the TOML file ``spec`` into the directory ``out``, as
    ``planbench sweep`` does (README, "Campaigns"); returns its ``Outcome`` (summary, the
    runs run now, the results table, the worst runs).

    Raises:
      planbench.ParamError: a bad spec or option, before any run starts.
    """
    from planbench import campaign

    return campaign.sweep(
        spec,
        out,
        engine=engine,
        workers=workers,
        address=address,
        quiet=quiet,
        echo=(lambda *args, **kwargs: None) if quiet else print,
    )


def environment(scenario: str, random=None, **params):
    """The dm_control ``Environment`` of the scenario ``scenario``: its task built with
    ``params`` (keys of ``planbench run NAME --help``), the action the commands of the
    actuators a controller drives, the observation the sensors' readings and the reference.
    ``random``: the episodes' random state (None: from the ``seed`` parameter)."""
    from planbench import envs

    return envs.make(scenario, random=random, **params)


def scenario_names(tag: str | None = None) -> tuple[str, ...]:
    """The runnable scenarios' names (``planbench list``), in registry order; ``tag``: only
    those tagged "demo" or "benchmark"."""
    if tag is None:
        return tuple(scenarios.SCENARIOS)
    return tuple(s.name for s in scenarios.tagged(tag))
