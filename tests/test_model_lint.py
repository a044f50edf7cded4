"""Menagerie-style lint of every model: compiles, named elements, random controls are safe."""

import mujoco
import numpy as np
import pytest

from planbench import models
from planbench.runner import warning_counts


@pytest.fixture(scope="module", params=models.MECHANISMS)
def model(request):
    return models.load(request.param)


def test_compiles_with_home_keyframe_and_cameras(model):
    assert model.key("home").id == 0
    cameras = {model.camera(i).name for i in range(model.ncam)}
    assert {"overview", "closeup"} <= cameras


def test_every_element_is_named(model):
    kinds = {
        "body": (model.nbody, model.body),
        "joint": (model.njnt, model.joint),
        "geom": (model.ngeom, model.geom),
        "site": (model.nsite, model.site),
        "actuator": (model.nu, model.actuator),
        "sensor": (model.nsensor, model.sensor),
        "camera": (model.ncam, model.camera),
        "light": (model.nlight, model.light),
        "equality": (model.neq, model.equality),
        "tendon": (model.ntendon, model.tendon),
    }
    for kind, (count, get) in kinds.items():
        start = 1 if kind == "body" else 0  # body 0 is the world
        unnamed = [i for i in range(start, count) if not get(i).name]
        assert not unnamed, f"unnamed {kind}s: {unnamed}"


def test_random_in_range_controls_raise_no_warning(model):
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    act0, qpos0 = data.act.copy(), data.qpos.copy()
    rng = np.random.default_rng(0)
    lo, hi = model.actuator_ctrlrange.T
    assert np.all(hi > lo), "every actuator needs a control range"
    for _ in range(200):  # 2 s, new random controls every 10 ms
        data.ctrl[:] = rng.uniform(lo, hi)
        mujoco.mj_step(model, data, nstep=20)
    assert not warning_counts(data)
    assert np.isfinite(data.qpos).all()
    # The controls really acted: on the drives' set-points, or (no activations) on the joints.
    if model.na:
        assert np.abs(data.act - act0).max() > 1e-4
    else:
        assert np.abs(data.qpos - qpos0).max() > 1e-4
