"""The loader's reference controller: the drives' PD with inverse-dynamics feed-forward."""

from __future__ import annotations

from planbench import models
from planbench.controllers import ServoFeedforwardController


def reference_controller() -> ServoFeedforwardController:
    """Our controller: the drives' PD with the nominal model's inverse dynamics as
    feed-forward (``ServoFeedforwardController``)."""
    spec = models.loader_spec()
    return ServoFeedforwardController(spec.kp, spec.kv)
