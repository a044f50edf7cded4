import os

# Offscreen rendering without a display; sims/__init__.py picks EGL or OSMesa. It must run
# before any test module imports mujoco, which fixes its GL back end on import.
os.environ.setdefault("MPLBACKEND", "Agg")
from hypothesis import settings  # noqa: E402

import planbench  # noqa: E402,F401

settings.register_profile("planbench", deadline=None, max_examples=100)
settings.load_profile("planbench")
