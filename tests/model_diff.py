"""What differs between two compiled models: for the plant-uncertainty tests (a perturbation
changes what it should and nothing else)."""

from __future__ import annotations

import mujoco
import numpy as np


def _array_fields(model: mujoco.MjModel) -> list[str]:
    names = []
    for name in dir(model):
        if name.startswith("_"):
            continue
        try:
            value = getattr(model, name)
        except Exception:  # noqa: BLE001  (some attributes raise on models without them)
            continue
        if isinstance(value, np.ndarray):
            names.append(name)
    return names


def changed_fields(model_a: mujoco.MjModel, model_b: mujoco.MjModel) -> dict[str, np.ndarray]:
    """{field: indices of the rows that differ} of every MjModel array (and opt) that differs
    between ``model_a`` and ``model_b`` (compared bit for bit; NaN equals NaN)."""
    out = {}
    for name in _array_fields(model_a):
        a, b = np.asarray(getattr(model_a, name)), np.asarray(getattr(model_b, name))
        if a.shape != b.shape:
            out[name] = np.arange(max(a.shape[0] if a.ndim else 1, b.shape[0] if b.ndim else 1))
            continue
        if a.dtype.kind in "fc":
            same = (a == b) | (np.isnan(a) & np.isnan(b))
        else:
            same = a == b
        if not np.all(same):
            rows = np.nonzero(~same.reshape(a.shape[0], -1).all(axis=1))[0] if a.ndim else np.array([0])
            out[name] = rows
    for name in ("timestep", "gravity", "wind", "density", "viscosity"):
        if not np.array_equal(np.asarray(getattr(model_a.opt, name)), np.asarray(getattr(model_b.opt, name))):
            out[f"opt.{name}"] = np.array([0])
    return out
