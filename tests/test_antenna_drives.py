"""The ship antenna's pedestal as built (planbench.antenna.params.as_built): each axis's drive train,
the mast's bending mode and the axis encoders against their definitions."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from planbench import models, scenarios
from planbench.antenna import params as antenna_params
from planbench.antenna.physics import AntennaPhysics

JOINTS = antenna_params.JOINTS


@pytest.fixture(scope="module")
def as_built():
    return AntennaPhysics.load(drives="as-built")


def test_each_axis_has_its_motor_transmission_and_friction(as_built):
    model, ideal = as_built.model.ptr, models.load("antenna")
    for name in JOINTS:
        motor, axis = model.joint(name + "_motor"), model.joint(name)
        # The rotor reflected (J N^2) is the ideal model's armature, now on the motor.
        assert model.dof_armature[motor.dofadr[0]] == pytest.approx(ideal.dof_armature[ideal.joint(name).dofadr[0]])
        assert model.dof_armature[axis.dofadr[0]] == 0.0
        assert model.dof_frictionloss[motor.dofadr[0]] == antenna_params.AXIS_FRICTION
        tendon = model.tendon(name + "_transmission").id
        belt = name == "azimuth"
        assert model.tendon_stiffness[tendon] == (
            antenna_params.BELT_STIFFNESS if belt else antenna_params.GEAR_STIFFNESS
        )
        b = 0.0 if belt else antenna_params.GEAR_BACKLASH  # 3 arcmin = 0.873 mrad on the geared axes
        np.testing.assert_allclose(model.tendon_lengthspring[tendon], [-b / 2, b / 2])
        # The drive's loop and torque limit are the ideal model's, on the motor.
        actuator, reference = model.actuator(name), ideal.actuator(name)
        assert actuator.trnid[0] == motor.id
        np.testing.assert_allclose(actuator.gainprm[0], reference.gainprm[0])
        np.testing.assert_allclose(actuator.forcerange, reference.forcerange)


def test_the_mast_bends_at_its_30_hz():
    """The mast hinges' stiffness over the antenna's inertia about them, at qpos0: (2 pi 30)^2."""
    model = antenna_params._model("as-built")
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    inertia = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, inertia)
    for name in antenna_params.MAST_JOINTS:
        joint = model.joint(name)
        i = joint.dofadr[0]
        frequency = math.sqrt(model.jnt_stiffness[joint.id] / inertia[i, i]) / (2 * math.pi)
        assert frequency == pytest.approx(antenna_params.MAST_MODE_HZ, rel=1e-9)
        assert model.dof_damping[i] == pytest.approx(2 * 0.02 * inertia[i, i] * 2 * math.pi * 30)


def test_the_start_is_at_rest_with_the_motors_on_their_axes():
    scenario = scenarios.get("antenna-sea-state")
    setup = scenario.build(scenario.resolve(duration=0.1))
    physics = setup.physics
    np.testing.assert_array_equal(physics.data.qpos[physics.drive_qpos], physics.data.qpos[physics.antenna_qpos])
    np.testing.assert_array_equal(physics.data.qvel[physics.drive_dofs], physics.data.qvel[physics.antenna_dofs])


def test_the_controller_reads_17_bit_axis_encoders():
    scenario = scenarios.get("antenna-sea-state")
    setup = scenario.build(scenario.resolve(duration=0.1))
    spec = next(s for s in setup.task.sensors.specs if s.name == "joint_positions")
    assert spec.resolution == pytest.approx(2 * math.pi / 2**17)
    from planbench import runner

    episode = runner.start_episode(setup)
    counts = episode.observation["joint_positions"] / spec.resolution
    np.testing.assert_allclose(counts, np.round(counts), atol=1e-6)


def test_the_plants_drive_train_errors_edit_their_elements():
    """transmission_stiffness_error scales the belt's and the gears' stiffness,
    gear_backlash_error the gears' dead band (not the belt's: it has none), and
    torque_constant_error every force the drive makes: its loop gains (the peak current stays,
    so the torque limit scales too)."""
    from planbench.antenna.params import AntennaPlant

    nominal = AntennaPhysics.load(drives="as-built").model.ptr
    model = AntennaPhysics.load(
        AntennaPlant(transmission_stiffness_error=-0.3, gear_backlash_error=2.0, torque_constant_error=0.1),
        drives="as-built",
    ).model.ptr
    for name in JOINTS:
        tendon = model.tendon(name + "_transmission").id
        assert model.tendon_stiffness[tendon] == pytest.approx(0.7 * nominal.tendon_stiffness[tendon])
        np.testing.assert_allclose(model.tendon_lengthspring[tendon], 3.0 * nominal.tendon_lengthspring[tendon])
        a = model.actuator(name).id
        assert model.actuator_gainprm[a, 0] == pytest.approx(1.1 * nominal.actuator_gainprm[a, 0])
        assert model.actuator_biasprm[a, 2] == pytest.approx(1.1 * nominal.actuator_biasprm[a, 2])
        assert model.actuator_forcerange[a, 1] == pytest.approx(1.1 * nominal.actuator_forcerange[a, 1])
    assert model.tendon_lengthspring[model.tendon("azimuth_transmission").id].tolist() == [0.0, 0.0]
