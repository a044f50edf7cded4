"""One run, from its scenario to its files: build, simulate and evaluate, write.

``execute`` is the only place a run is put together: ``planbench run``, ``planbench demo``,
the Python API (``planbench.api.run``), a campaign's workers, ``--rerun-worst`` and ``planbench
bench`` all call it. It makes the plug-ins from their ``MODULE:FACTORY`` (``planbench.plugins``)
and records them in the run's provenance (summary.json's "plugins").
"""

from __future__ import annotations

import contextlib
import tempfile
from collections.abc import Callable

from planbench import run_limits, runner
from planbench.logfile import LOG_FILE


def build(scenario, params, plant=None, planner=None, controller=None) -> runner.Setup:
    """``scenario.build`` with the plant passed only when it is perturbed (a mechanism without
    plant uncertainty takes no ``plant``)."""
    extra = {} if plant is None or plant.is_nominal else {"plant": plant}
    return scenario.build(params, planner=planner, controller=controller, **extra)


def execute(
    scenario,
    params,
    plant=None,
    *,
    plugins: dict | None = None,
    planner=None,
    controller=None,
    out=None,
    video=None,
    camera: str | None = None,
    more_videos: tuple = (),
    quiet: bool = True,
    profile: bool = False,
    on_built: Callable | None = None,
    on_judged: Callable | None = None,
) -> tuple[runner.Setup, runner.RunResult]:
    """Build, run and (with ``out``) write one run of ``scenario``; returns (setup, result).

    Args:
      scenario: a ``planbench.scenarios.Scenario``.
      params, plant: its resolved parameters and plant (None: nominal).
      plugins: {role: MODULE:FACTORY} of a user's planner or controller, made here.
      planner, controller: objects instead (the Python API); not with a plug-in of the role.
      out: an output directory (``planbench.outputs.OutputDir`` or a path) or None to write nothing.
      video: a video file (``planbench.outputs.VideoFile`` or a path), with ``out``.
      camera: of the video (None: the scenario's). more_videos: (file name, camera) pairs.
      profile: time the loop's parts (``runner.simulate``'s ``profile``).
      on_built: (setup) -> None, called after the build, before the first physics step.
      on_judged: (result) -> None, called once the run is judged, before anything is written.
    """
    from planbench import outputs, supervise
    from planbench import plugins as plugin_module

    plugins = dict(plugins or {})
    given = {"planner": planner, "controller": controller}
    for role, spec in plugins.items():
        if given.get(role) is not None:
            raise ValueError(f"a {role} object and a {role} plug-in ({spec}) were both given")
        given[role] = plugin_module.make(spec, role, online_planner=scenario.online_planner)
    setup = build(scenario, params, plant, **given)
    setup.provenance.plugins = plugins
    if on_built is not None:
        on_built(setup)
    if out is None:
        check_log_space(setup, params, None)
        result = runner.run(scenario.name, setup, quiet=quiet, profile=profile)
        if on_judged is not None:
            on_judged(result)
        return setup, result
    target = out if isinstance(out, outputs.OutputDir) else outputs.OutputDir(out)
    check_log_space(setup, params, target.path)
    with contextlib.ExitStack() as stack:
        if not target.is_reserved:
            stack.enter_context(target.reserved())
        # The log streams into the output's staging directory, swapped in with the rest.
        tmp = stack.enter_context(target.staging({"scenario": scenario.name}))
        result = runner.run(scenario.name, setup, quiet=quiet, profile=profile, log_path=tmp / LOG_FILE)
        if on_judged is not None:
            on_judged(result)
        supervise.phase("writing the outputs (planbench's own code)")
        outputs.write_run(
            result,
            setup,
            target,
            video=video,
            camera=camera or scenario.camera,
            quiet=quiet,
            more_videos=more_videos,
            staging=tmp,
        )
    return setup, result


def check_log_space(setup: runner.Setup, params, directory) -> None:
    """A RunLimitError (bad input) before the first physics step if the run's log would not
    fit in the free space where it streams: ``directory`` (the output directory's place) or,
    None, the temporary directory (``planbench.run_limits.log_space_limit``)."""
    per_tick = getattr(params, "log_bytes_per_tick", None)
    if per_tick is None:
        return
    try:
        bytes_per_tick = per_tick()
    except NotImplementedError:
        return
    task = setup.task
    where = tempfile.gettempdir() if directory is None else directory
    run_limits.check_duration(float(task.duration), task.control_dt, bytes_per_tick, run_limits.log_space_limit(where))
