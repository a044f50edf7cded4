"""One run, from its scenario to its files: build, simulate and evaluate, write.

``execute`` is the only place a run is put together: ``planbench run``, ``planbench demo``,
the Python API (``sims.api.run``), a campaign's workers, ``--rerun-worst`` and ``planbench
bench`` all call it. It makes the plug-ins from their ``MODULE:FACTORY`` (``sims.plugins``)
and records them in the run's provenance (summary.json's "plugins").
"""

from __future__ import annotations

from typing import Callable

from sims import runner


def build(scenario, params, plant=None, planner=None, controller=None) -> runner.Setup:
    """``scenario.build`` with the plant passed only when it is perturbed (a mechanism without
    plant uncertainty takes no ``plant``)."""
    extra = {} if plant is None or plant.is_nominal else {"plant": plant}
    return scenario.build(params, planner=planner, controller=controller, **extra)


def execute(scenario, params, plant=None, *, plugins: dict | None = None, planner=None, controller=None,
            out=None, video=None, camera: str | None = None, more_videos: tuple = (), quiet: bool = True,
            profile: bool = False, on_built: Callable | None = None,
            on_judged: Callable | None = None) -> tuple[runner.Setup, runner.RunResult]:
    """Build, run and (with ``out``) write one run of ``scenario``; returns (setup, result).

    Args:
      scenario: a ``sims.scenarios.Scenario``.
      params, plant: its resolved parameters and plant (None: nominal).
      plugins: {role: MODULE:FACTORY} of a user's planner or controller, made here.
      planner, controller: objects instead (the Python API); not with a plug-in of the role.
      out: an output directory (``sims.outputs.OutputDir`` or a path) or None to write nothing.
      video: a video file (``sims.outputs.VideoFile`` or a path), with ``out``.
      camera: of the video (None: the scenario's). more_videos: (file name, camera) pairs.
      profile: time the loop's parts (``runner.simulate``'s ``profile``).
      on_built: (setup) -> None, called after the build, before the first physics step.
      on_judged: (result) -> None, called once the run is judged, before anything is written.
    """
    from sims import outputs, supervise
    from sims import plugins as plugin_module

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
    result = runner.run(scenario.name, setup, quiet=quiet, profile=profile)
    if on_judged is not None:
        on_judged(result)
    if out is not None:
        supervise.phase("writing the outputs (planbench's own code)")
        outputs.write_run(result, setup, out, video=video, camera=camera or scenario.camera, quiet=quiet,
                          more_videos=more_videos)
    return setup, result
