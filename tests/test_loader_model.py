"""The loader MJCF: Menagerie-style lint, statics by hand, and planner/MuJoCo agreement."""

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from planbench import models
from planbench.planners.loader import forward_kinematics

SPEC = models.loader_spec()


@pytest.fixture(scope="module")
def model():
    return models.load("loader")


def test_spec_matches_compiled_model(model):
    for j in SPEC.joints:
        jnt = model.joint(j.name)
        np.testing.assert_allclose(jnt.range, [j.lower, j.upper])
        act = model.actuator(j.name)
        np.testing.assert_allclose(act.forcerange, [-j.force_limit, j.force_limit])
        np.testing.assert_allclose(act.ctrlrange, [-j.rate_limit, j.rate_limit])
        assert act.gainprm[0] == j.kp and act.biasprm[2] == -j.kv
        assert act.trnid[0] == jnt.id
    assert model.opt.timestep == 0.0005


def test_masses_are_the_readme_values(model):
    moving = {
        "carriage": 150.0,
        "upper_arm": 60.0,
        "forearm": 40.0,
        "wrist_pitch_link": 12.0,
        "wrist_yaw_link": 8.0,
        "gripper": 15.0,
        "shell": 45.0,
    }
    for body, mass in moving.items():
        assert model.body(body).mass[0] == pytest.approx(mass), body


def test_static_holding_torques_match_hand_computation(model):
    """At rest at P2, each pitch drive carries sum(m g x_lever) of the bodies beyond it."""
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_step(model, data, nstep=4000)  # 2 s: settle on the drives
    assert np.abs(data.qvel).max() < 1e-6
    g = 9.81
    for joint, sign in (("shoulder", -1.0), ("elbow", -1.0), ("wrist_pitch", 1.0)):
        axis_point = data.xanchor[model.joint(joint).id]
        first = model.joint(joint).bodyid[0]
        beyond = [b for b in range(model.nbody) if _descends(model, b, first)]
        # Torque about the joint axis (+-y) of gravity on every body beyond it:
        # (r x F)_y = r_z F_x - r_x F_z = m g x_lever for F = (0, 0, -m g).
        tau_y = sum(model.body_mass[b] * g * (data.xipos[b, 0] - axis_point[0]) for b in beyond)
        drive = data.actuator_force[model.actuator(joint).id]
        # The drive's torque balances gravity: sign * drive + tau_y = 0 about the +y axis.
        assert sign * drive == pytest.approx(-tau_y, rel=2e-3), joint
    assert abs(data.actuator_force[model.actuator("shoulder").id]) > 1000.0  # kilonewton-metres


def _descends(model, body, ancestor):
    while body > 0:
        if body == ancestor:
            return True
        body = model.body_parentid[body]
    return False


@settings(max_examples=50)
@given(st.lists(st.floats(0.0, 1.0), min_size=6, max_size=6))
def test_planner_kinematics_equal_mujoco_sites(unit):
    model = _model()
    data = mujoco.MjData(model)
    q = SPEC.lower + np.array(unit) * (SPEC.upper - SPEC.lower)
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    fk = forward_kinematics(q)
    for site, pos in fk.items():
        np.testing.assert_allclose(pos, data.site(site).xpos, atol=1e-12)


_CACHE = {}


def _model():
    if "m" not in _CACHE:
        _CACHE["m"] = models.load("loader")
    return _CACHE["m"]


def test_forward_kinematics_is_vectorized():
    q = np.random.default_rng(1).uniform(SPEC.lower, SPEC.upper, (4, 3, 6))
    tip = forward_kinematics(q, ["shell_tip"])["shell_tip"]
    assert tip.shape == (4, 3, 3)
    np.testing.assert_allclose(tip[2, 1], forward_kinematics(q[2, 1], ["shell_tip"])["shell_tip"])
    with pytest.raises(ValueError, match="unknown site"):
        forward_kinematics(q[0, 0], ["nose"])
    with pytest.raises(ValueError, match="5 joints"):
        forward_kinematics(np.zeros(5))
