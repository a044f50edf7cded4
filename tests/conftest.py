import os

import pytest

# Offscreen rendering without a display; sims/__init__.py picks EGL or OSMesa. It must run
# before any test module imports mujoco, which fixes its GL back end on import.
os.environ.setdefault("MPLBACKEND", "Agg")
from hypothesis import settings  # noqa: E402

import planbench  # noqa: E402,F401

settings.register_profile("planbench", deadline=None, max_examples=100)
settings.load_profile("planbench")


@pytest.fixture(scope="session")
def written_plan(tmp_path_factory):
    """``planbench plan NAME --out DIR`` (through ``planbench.cli.main``), made once per test
    process for each NAME: the plan outputs that several test files check. Returns a function
    NAME -> (exit code, DIR)."""
    from planbench.cli import main

    made: dict[str, tuple[int, object]] = {}

    def written(name: str):
        if name not in made:
            out = tmp_path_factory.mktemp("plans") / name
            made[name] = (main(["plan", name, "--out", str(out)]), out)
        return made[name]

    return written
