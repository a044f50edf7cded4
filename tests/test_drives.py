"""The drive-train elements of ``planbench.drives`` against first principles, on a one-axis model: a
load of mass M on a slide, driven through a motor, a compliant transmission with backlash,
friction and the drive's PD loops."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from planbench import drives
from planbench.task import JointEncoders

LOAD_MASS = 50.0  # kg
DT = 0.0005  # s

AXIS = """
<mujoco>
  <option timestep="{dt}" integrator="implicitfast" gravity="0 0 0"/>
  <worldbody>
    <body name="carriage">
      <joint name="axis" type="slide" axis="1 0 0"/>
      <geom type="box" size="0.1 0.1 0.1" mass="{mass}"/>
    </body>
  </worldbody>
  <actuator>
    <general name="axis" joint="axis" dyntype="integrator" biastype="affine" gainprm="1" biasprm="0 -1 0"
             ctrlrange="-1 1"/>
  </actuator>
</mujoco>
"""


def drive(**changes) -> drives.DriveTrain:
    base = dict(
        ratio=2 * math.pi / 0.01,
        rotor_inertia=1e-4,
        torque_constant=0.5,
        peak_current=20.0,
        continuous_current=8.0,
        max_motor_speed=300.0,
        kp=2e6,
        kv=2e4,
        efficiency=0.9,
        stiffness=5e7,
    )
    base.update(changes)
    return drives.DriveTrain(**base)


def axis_model(train: drives.DriveTrain) -> mujoco.MjModel:
    spec = mujoco.MjSpec.from_string(AXIS.format(dt=DT, mass=LOAD_MASS))
    drives.add_drive_train(spec, "axis", "axis", train)
    return spec.compile()


def test_the_rotor_is_reflected_through_the_ratio_and_the_force_clamped_at_the_peak():
    train = drive()
    model = axis_model(train)
    motor = model.joint("axis_motor")
    assert model.dof_armature[motor.dofadr[0]] == pytest.approx(1e-4 * (2 * math.pi / 0.01) ** 2)  # 39.48 kg
    assert model.dof_armature[model.joint("axis").dofadr[0]] == 0.0
    peak = 0.5 * 20.0 * (2 * math.pi / 0.01) * 0.9  # K_t I N eta = 5655 N
    np.testing.assert_allclose(model.actuator_forcerange[0], [-peak, peak])
    assert model.actuator_trnid[0, 0] == motor.id
    assert drives.load_joint(model, 0) == model.joint("axis").id
    assert train.max_speed == pytest.approx(300.0 * 0.01 / (2 * math.pi))  # m/s


def test_a_rigid_drive_stays_on_its_joint():
    model = axis_model(drive(stiffness=math.inf, coulomb_friction=7.0, viscous_friction=3.0))
    assert model.njnt == 1 and model.ntendon == 0
    assert model.dof_armature[0] == pytest.approx(drive().reflected_inertia)
    assert model.dof_frictionloss[0] == 7.0 and model.dof_damping[0] == 3.0
    assert drives.transmission_stiffness(model, "axis") == math.inf


def test_static_sag_under_a_load_is_force_over_stiffness():
    """A constant force F on the load, the drive holding its motor: the load stands off the
    motor by F / k."""
    train = drive(stiffness=5e7)
    model = axis_model(train)
    data = mujoco.MjData(model)
    load = model.joint("axis").dofadr[0]
    force = 2000.0
    data.qfrc_applied[load] = force
    mujoco.mj_step(model, data, nstep=int(2.0 / DT))
    deflection = data.qpos[model.joint("axis").qposadr[0]] - data.qpos[model.joint("axis_motor").qposadr[0]]
    assert deflection == pytest.approx(force / 5e7, rel=1e-3)  # 40 um
    # and the load drags the motor off its set-point by F / kp
    assert data.qpos[model.joint("axis_motor").qposadr[0]] == pytest.approx(force / train.kp, rel=1e-3)


def test_friction_holds_below_its_breakaway_force_and_slips_above():
    """Coulomb friction F_c on the motor: a force of 0.8 F_c (the drive off) leaves the axis at
    rest; 1.5 F_c accelerates it at (F - F_c) / (M + J N^2)."""
    coulomb = 400.0
    train = drive(stiffness=math.inf, coulomb_friction=coulomb, kp=0.0, kv=0.0)
    model = axis_model(train)
    model.dof_solref[0] = [2 * DT, 1.0]  # a stiff friction constraint, for a sharp breakaway
    for factor, moving in ((0.8, False), (1.5, True)):
        data = mujoco.MjData(model)
        data.qfrc_applied[0] = factor * coulomb
        mujoco.mj_step(model, data, nstep=int(0.2 / DT))
        mass = LOAD_MASS + train.reflected_inertia
        if moving:
            assert data.qvel[0] == pytest.approx((factor - 1.0) * coulomb / mass * 0.2, rel=0.02)
        else:
            assert abs(data.qvel[0]) < 1e-3 * (0.5 * coulomb / mass * 0.2)


def test_backlash_is_a_dead_band_of_the_transmission():
    """With backlash b the motor moves b/2 either way before the load feels any force."""
    b = 1e-4
    model = axis_model(drive(backlash=b))
    data = mujoco.MjData(model)
    load = model.joint("axis").qposadr[0]
    tendon = model.tendon("axis_transmission").id
    np.testing.assert_allclose(model.tendon_lengthspring[tendon], [-b / 2, b / 2])
    for offset, force in ((0.4 * b, 0.0), (-0.4 * b, 0.0), (0.6 * b, -5e7 * 0.1 * b), (-0.6 * b, 5e7 * 0.1 * b)):
        data.qpos[:] = 0.0
        data.qpos[load] = offset  # load - motor = offset
        mujoco.mj_forward(model, data)
        assert data.qfrc_passive[model.joint("axis").dofadr[0]] == pytest.approx(force, abs=1e-6)


def test_the_position_loop_has_its_design_bandwidth():
    """kp = m w^2, kv = 2 zeta m w on a rigid axis of inertia m: a small step of the set-point
    rises as a second-order system of that frequency and damping (overshoot
    exp(-pi zeta / sqrt(1 - zeta^2)) = 4.6 % at zeta 0.7; peak at pi / (w sqrt(1 - zeta^2)))."""
    inertia = LOAD_MASS + drive().reflected_inertia
    kp, kv = drives.servo_gains(inertia, 20.0, 0.7)
    model = axis_model(drive(stiffness=math.inf, kp=kp, kv=kv))
    data = mujoco.MjData(model)
    data.act[0] = 1e-4  # a 0.1 mm step of the set-point
    n = int(0.2 / DT)
    q = np.empty(n)
    for i in range(n):
        mujoco.mj_step(model, data)
        q[i] = data.qpos[0]
    overshoot = q.max() / 1e-4 - 1.0
    assert overshoot == pytest.approx(math.exp(-math.pi * 0.7 / math.sqrt(1 - 0.49)), abs=0.01)
    peak_time = (np.argmax(q) + 1) * DT
    assert peak_time == pytest.approx(math.pi / (2 * math.pi * 20.0 * math.sqrt(1 - 0.49)), rel=0.05)


@settings(max_examples=50, deadline=None)
@given(st.floats(-0.02, 0.02), st.sampled_from([1e-9, 5e-8, 1e-6]))
@example(-1e-5, 1e-6)  # a whole count: (-10) x 1e-6 rounds to one ulp above -1e-5
def test_an_encoder_reads_whole_counts(position, resolution):
    """The reading is floor(x (1/r)) r: a whole count, at most one count below the position,
    and above it by no more than the product's round-off (a few ulps of x)."""
    model = mujoco.MjModel.from_xml_string(AXIS.format(dt=DT, mass=LOAD_MASS))
    data = mujoco.MjData(model)
    data.qpos[0] = position
    physics = type("P", (), {"data": type("D", (), {"ptr": data})()})()
    encoders = JointEncoders([0], [0], [0], "axis", "m", 0.005, resolution=resolution)
    reading = encoders.reset(physics, np.zeros(1), 0)["joint_positions"][0]
    count = reading / resolution
    assert count == pytest.approx(round(count), abs=1e-6)
    assert reading == math.floor(position * (1.0 / resolution)) * resolution
    assert -4 * np.spacing(abs(position)) <= position - reading < resolution * (1 + 1e-9)


@settings(max_examples=30, deadline=None)
@given(st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3), st.sampled_from([1e-6, 2 * math.pi / 2**17]))
def test_counted_encoders_read_straight_from_the_buffer_as_from_a_copy(positions, resolution):
    """Noiseless counted encoders on a run of joints read floor(x (1/r)) r from the live
    buffer; on other joints (not a run) from a copy: the same numbers, tick after tick."""
    data = type("D", (), {"qpos": np.zeros(4), "qvel": np.zeros(4), "act": np.zeros(4)})()
    physics = type("P", (), {"data": type("Ptr", (), {"ptr": data})()})()
    resolutions = [resolution, 2 * resolution, 3 * resolution]
    run = JointEncoders([1, 2, 3], [1, 2, 3], [1, 2, 3], "axes", "rad", 0.005, resolution=resolutions)
    scattered = JointEncoders(
        [3, 1, 2],
        [3, 1, 2],
        [3, 1, 2],
        "axes",
        "rad",
        0.005,
        resolution=[resolutions[2], resolutions[0], resolutions[1]],
    )
    a, b = run.reset(physics, np.zeros(3), 0), scattered.reset(physics, np.zeros(3), 0)
    assert run._counted_run is not None and scattered._counted_run is None
    for tick, shift in enumerate([0.0, 1e-7, -0.3]):
        data.qpos[1:] = np.array(positions) + shift
        run(tick, physics)
        scattered(tick, physics)
        np.testing.assert_array_equal(a["joint_positions"], b["joint_positions"][[1, 2, 0]])
        counts = a["joint_positions"] / resolutions
        np.testing.assert_allclose(counts, np.round(counts), rtol=0, atol=1e-6)


def test_the_servo_feedforward_through_a_drive_train_is_the_load_s_plus_the_rotor_s():
    """Inverse dynamics on a model with a drive train as built: the motor moves with its load,
    so the feed-forward is (M + J N^2) a, not a force stretching the transmission."""
    from planbench.controllers import ServoFeedforwardController
    from planbench.planners.trajectory import TrajectorySample
    from planbench.task import ControlContext

    train = drive()
    model = axis_model(train)
    physics = type(
        "P", (), {"model": type("M", (), {"ptr": model})(), "data": type("D", (), {"ptr": mujoco.MjData(model)})()}
    )()
    physics.data.qpos = physics.data.ptr.qpos
    n = 5
    t = np.arange(n) * 0.005
    a = np.full((n, 1), 2.0)  # m/s^2
    reference = TrajectorySample(t, 0.5 * a * t[:, None] ** 2, a * t[:, None], a)
    context = ControlContext(
        model=model,
        nominal_physics=lambda: physics,
        problem=None,
        trajectory=None,
        reference=reference,
        control_dt=0.005,
        command=np.zeros(1),
        setpoint=np.zeros(1),
        actuators=("axis",),
        observation={},
    )
    servo = ServoFeedforwardController()
    servo.reset(context)
    mass = LOAD_MASS + train.reflected_inertia + drives.ROTOR_BODY_MASS  # the rotor body moves too
    np.testing.assert_allclose(servo.tau_ff[:, 0], mass * 2.0, rtol=1e-9)


def test_a_motor_stands_off_its_load_by_the_deflection_and_half_the_backlash():
    """At rest with F on the load, held through the transmission: q_m - q = F / k + sign(F) b / 2
    (the teeth in contact), the value ``transmission_deflection`` gives; nothing through a
    rigid drive."""
    backlash = 2e-4
    model = axis_model(drive(stiffness=5e7, backlash=backlash))
    data = mujoco.MjData(model)
    load, motor = model.joint("axis").dofadr[0], model.joint("axis_motor").dofadr[0]
    for force in (-3000.0, 1500.0):
        standoff = drives.transmission_deflection(model, ["axis"], np.array([force]))[0]
        assert standoff == pytest.approx(force / 5e7 + math.copysign(backlash / 2, force), rel=1e-12)
        data.qpos[:] = 0.0
        data.qpos[model.joint("axis_motor").qposadr[0]] = standoff
        mujoco.mj_forward(model, data)
        # The tendon's force on the load is what holds F: qfrc_passive = -F.
        assert data.qfrc_passive[load] == pytest.approx(force, rel=1e-9)
        assert data.qfrc_passive[motor] == pytest.approx(-force, rel=1e-9)
    rigid = axis_model(drive(stiffness=math.inf))
    assert drives.transmission_deflection(rigid, ["axis"], np.array([1000.0]))[0] == 0.0


def test_the_keyframe_puts_each_motor_at_its_load():
    spec = mujoco.MjSpec.from_string(
        AXIS.format(dt=DT, mass=LOAD_MASS).replace(
            "</worldbody>", "</worldbody><keyframe><key name='home' qpos='0.25' act='0.25'/></keyframe>"
        )
    )
    nominal = spec.compile()
    drives.add_drive_train(spec, "axis", "axis", drive())
    drives.keyframe_with_motors(spec, nominal)
    model = spec.compile()
    np.testing.assert_array_equal(
        model.key_qpos[0][[model.joint("axis").qposadr[0], model.joint("axis_motor").qposadr[0]]], [0.25, 0.25]
    )
    np.testing.assert_array_equal(model.key_act[0], [0.25])
    qpos, dofs = drives.drive_coordinates(model, ["axis"])
    assert qpos.tolist() == [model.joint("axis_motor").qposadr[0]] and dofs.tolist() == [
        model.joint("axis_motor").dofadr[0]
    ]


def test_an_unknown_drive_option_is_refused():
    assert drives.check_option("ideal") == "ideal"
    with pytest.raises(ValueError, match="drives = 'geared' is not one of as-built, ideal"):
        drives.check_option("geared")
