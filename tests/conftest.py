import os

# Offscreen rendering without a display; sims/__init__ picks EGL or OSMesa.
os.environ.setdefault("MPLBACKEND", "Agg")

from hypothesis import settings  # noqa: E402

settings.register_profile("planbench", deadline=None, max_examples=100)
settings.load_profile("planbench")
