"""The loader's drive trains as built (planbench.loader.physics.as_built): each axis's motor,
reducer, friction and encoder against their definitions, the start's static equilibrium
through the reducers, and the plant's errors of the new elements."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from planbench import models, runner, scenarios
from planbench.drives import MOTOR_SUFFIX, TRANSMISSION_SUFFIX
from planbench.loader import physics as loader_physics
from planbench.loader.params import LoaderPlant
from planbench.loader.physics import TRANSMISSIONS, LoaderPhysics
from planbench.params import ParamError
from planbench.planners.errors import LimitError

NAMES = models.loader_spec().names


@pytest.fixture(scope="module")
def as_built():
    return LoaderPhysics.load(drives="as-built")


def test_each_axis_has_its_motor_reducer_and_friction(as_built):
    model, ideal = as_built.model.ptr, models.load("loader")
    for name in NAMES:
        t, actuator, reference = TRANSMISSIONS[name], model.actuator(name), ideal.actuator(name)
        peak, rated_speed = reference.forcerange[1], reference.ctrlrange[1]
        armature = ideal.dof_armature[ideal.joint(name).dofadr[0]]
        if math.isinf(t.stiffness):  # the slide's screw: the motor's inertia and friction on the slide
            with pytest.raises(KeyError):
                model.joint(name + MOTOR_SUFFIX)
            motor = model.joint(name)
        else:
            motor = model.joint(name + MOTOR_SUFFIX)
            tendon = model.tendon(name + TRANSMISSION_SUFFIX).id
            assert model.tendon_stiffness[tendon] == t.stiffness
            np.testing.assert_allclose(model.tendon_lengthspring[tendon], [-t.backlash / 2, t.backlash / 2])
            assert model.dof_armature[model.joint(name).dofadr[0]] == 0.0
        dof = motor.dofadr[0]
        # The rotor reflected (J N^2) is the ideal model's armature, on the motor's dof.
        assert model.dof_armature[dof] == pytest.approx(armature, rel=1e-12)
        assert model.dof_frictionloss[dof] == pytest.approx(0.03 * peak)
        assert model.dof_damping[dof] == pytest.approx(0.03 * peak / rated_speed)
        assert actuator.trnid[0] == motor.id
        np.testing.assert_allclose(actuator.gainprm[0], reference.gainprm[0])
        np.testing.assert_allclose(actuator.forcerange, reference.forcerange)
    # RV reducers with 1 arcmin lost motion on the shoulder and elbow, strain-wave gears without.
    assert TRANSMISSIONS["shoulder"].backlash == pytest.approx(math.radians(1 / 60))
    assert TRANSMISSIONS["wrist_pitch"].backlash == 0.0


def test_a_drive_trains_numbers(as_built):
    """The shoulder's: the motor's speed at the drive's rated 2 rad/s is 120 x 2 = 240 rad/s;
    its rotor J = 10 / 120^2 kg m^2; its peak current K_t I N eta = 8000 N m."""
    drive = loader_physics.joint_drive(models.load("loader"), "shoulder")
    assert drive.max_motor_speed == pytest.approx(240.0)
    assert drive.rotor_inertia == pytest.approx(10.0 / 120.0**2)
    assert drive.peak_force == pytest.approx(8000.0)
    assert drive.encoder_resolution == pytest.approx(2 * math.pi / 2**20 / 120)


@pytest.mark.parametrize("payload", [0.0, 45.0, 90.0])
def test_the_start_holds_the_gravity_load_through_the_reducers(payload):
    """At rest at Table 1's first key point each motor stands off its load by the gravity
    torque over the reducer's stiffness plus half the backlash (tau / k + b/2), and the
    set-point off the motor by tau / kp: 0.2 s with the set-points held move no joint by more
    than 1e-7 rad or m."""
    physics = LoaderPhysics.load(payload, drives="as-built")
    q0 = (
        scenarios.get("loader-supply")
        .build(scenarios.get("loader-supply").resolve(duration=0.01))
        .task.problem.key_points[0]
    )
    physics.set_start(q0)
    model, data = physics.model.ptr, physics.data.ptr
    gravity = data.qfrc_bias[[model.joint(n).dofadr[0] for n in NAMES]].copy()
    for j, name in enumerate(NAMES):
        t = TRANSMISSIONS[name]
        if math.isinf(t.stiffness):
            continue
        standoff = data.qpos[model.joint(name + MOTOR_SUFFIX).qposadr[0]] - q0[j]
        assert standoff == pytest.approx(gravity[j] / t.stiffness + np.sign(gravity[j]) * t.backlash / 2, rel=1e-8)
    assert abs(gravity[1]) > 1000.0  # N m: the shoulder does carry the arm
    mujoco.mj_step(model, data, nstep=400)
    np.testing.assert_allclose(physics.joint_positions(), q0, rtol=0, atol=1e-7)


def test_the_sag_under_a_heavier_shell_is_its_extra_torque_over_the_stiffness():
    """Static sag = F / k: 45 kg more shell at the same pose stands the shoulder's motor off
    by the extra gravity torque over 3.0e6 N m/rad."""
    q0 = np.array([0.05, 0.97, -1.23, 0.35, 0.0, 0.0])
    standoff, torque = [], []
    for payload in (45.0, 90.0):
        physics = LoaderPhysics.load(payload, drives="as-built")
        physics.set_start(q0)
        model, data = physics.model.ptr, physics.data.ptr
        standoff.append(data.qpos[model.joint("shoulder" + MOTOR_SUFFIX).qposadr[0]])
        torque.append(data.qfrc_bias[model.joint("shoulder").dofadr[0]])
    assert torque[1] - torque[0] > 300.0  # N m
    assert standoff[1] - standoff[0] == pytest.approx((torque[1] - torque[0]) / 3.0e6, rel=1e-7)


def test_the_controller_reads_the_motors_encoders_in_counts():
    """The encoders are the motors': each reading is a whole count of 2 pi / (2^20 N) and
    differs from the joint by the reducer's deflection (which the motor encoder cannot see)."""
    scenario = scenarios.get("loader-supply")
    setup = scenario.build(scenario.resolve(duration=0.05))
    spec = next(s for s in setup.task.sensors.specs if s.name == "joint_positions")
    assert "motor" in spec.measures
    episode = runner.start_episode(setup)
    reading = episode.observation["joint_positions"].copy()
    resolution = np.array([loader_physics.joint_drive(models.load("loader"), n).encoder_resolution for n in NAMES])
    counts = reading / resolution
    np.testing.assert_allclose(counts, np.round(counts), rtol=0, atol=1e-6)
    physics = setup.physics
    motor = physics.data.qpos[physics.drive_qpos]
    assert np.all(np.abs(reading - motor) <= resolution)
    shoulder = NAMES.index("shoulder")
    assert abs(reading[shoulder] - physics.joint_positions()[shoulder]) > 1e-4  # rad: the deflection


def test_the_torque_check_judges_the_motors_demand_with_the_shell_and_the_rotors():
    """The judged demand is the drive's PD on its motor's coordinates; where it is inside the
    force range it is the actuator's force exactly (so it includes accelerating the rotors,
    which are on the motors' dofs, and the 45 kg shell)."""
    scenario = scenarios.get("loader-supply")
    setup = scenario.build(scenario.resolve(duration=1.0))
    log = runner.simulate(setup)
    q, qd = setup.task.evaluation._joint_log(log)
    demanded = setup.task.evaluation._demanded(log)
    limit = setup.task.evaluation.force_limit
    assert (np.abs(demanded) < limit).all()
    # MuJoCo's own actuator force at logged states (the log's actuator_force is that of the
    # step before, whose state was not logged).
    model, data = setup.physics.model.ptr, mujoco.MjData(setup.physics.model.ptr)
    for i in range(0, log.t.size, 20):
        data.qpos[:], data.qvel[:], data.act[:] = log.qpos[i], log.qvel[i], log.act[i]
        mujoco.mj_forward(model, data)
        np.testing.assert_allclose(demanded[i], data.actuator_force, rtol=1e-9, atol=1e-6)
    # On the load joints the PD would read another value: the deflection counts.
    load_pd = setup.task.evaluation.kp * (log.act - q) - setup.task.evaluation.kv * qd
    assert np.abs(load_pd - demanded).max() > 10.0  # N m


def test_the_plants_drive_train_errors_edit_their_elements():
    nominal = LoaderPhysics.load(drives="as-built").model.ptr
    plant = LoaderPlant(friction_error=1.0, reducer_stiffness_error=-0.3, backlash_error=2.0, torque_constant_error=0.1)
    model = LoaderPhysics.load(plant=plant, drives="as-built").model.ptr
    motor = model.joint("elbow" + MOTOR_SUFFIX).dofadr[0]
    tendon = model.tendon("elbow" + TRANSMISSION_SUFFIX).id
    assert model.dof_frictionloss[motor] == pytest.approx(2.0 * nominal.dof_frictionloss[motor])
    assert model.dof_damping[motor] == pytest.approx(2.0 * nominal.dof_damping[motor])
    assert model.tendon_stiffness[tendon] == pytest.approx(0.7 * nominal.tendon_stiffness[tendon])
    np.testing.assert_allclose(model.tendon_lengthspring[tendon], 3.0 * nominal.tendon_lengthspring[tendon])
    a = model.actuator("elbow").id
    assert model.actuator_gainprm[a, 0] == pytest.approx(1.1 * nominal.actuator_gainprm[a, 0])
    assert model.actuator_biasprm[a, 2] == pytest.approx(1.1 * nominal.actuator_biasprm[a, 2])
    assert model.actuator_forcerange[a, 1] == pytest.approx(1.1 * nominal.actuator_forcerange[a, 1])


def test_the_drive_train_errors_need_the_as_built_drives():
    scenario = scenarios.get("loader-supply")
    with pytest.raises(ParamError, match="plant friction_error = 0.5: an error of the drive trains as built"):
        scenario.build(scenario.resolve(drives="ideal"), plant=LoaderPlant(friction_error=0.5))
    with pytest.raises(LimitError, match="'stiff' is not one of as-built, ideal"):
        LoaderPhysics.load(drives="stiff")
