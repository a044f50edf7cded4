"""The ship-antenna MJCF: deck and antenna kinematics = the paper's, mass properties and statics
by hand, drive design (natural frequencies, deck tracking), IMU, keyframe equilibrium.

The kinematics are written out here from their definitions (REFERENCE.md "Ship antenna"), not
imported from the planner, so the model is checked against the equations themselves.
"""

import itertools

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from planbench import models

G = 9.81
DEG = np.pi / 180
THETA0 = np.array([136.51, -60.0, 0.0, -28.8]) * DEG  # the paper's eq. (15)
AZ0, EL0, POL0 = 223.49 * DEG, 60.0 * DEG, -28.8 * DEG
C0 = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])
DECK_JOINTS = ("heave", "yaw", "pitch", "roll")
ANTENNA_JOINTS = ("azimuth", "elevation", "cross_elevation", "polarization")

# Design numbers of models/antenna/README.md (hand values, not read from the model).
MAST_TOP = 10.0  # pedestal base above the ship's centre of rotation, m
AXES_HEIGHT = 0.65  # axes' intersection O above the pedestal base, m
REFLECTOR_MASS, REFLECTOR_RADIUS, REFLECTOR_HALF_THICKNESS = 12.0, 0.5, 0.005
POL_MASS = 33.0  # polarization body + reflector, kg
POL_COM = np.array([0.002, 0.0, 0.003])  # its centre of mass in the antenna frame, m
MOVING_MASS = {"azimuth": 30.0, "elevation": 20.0, "cross_elevation": 15.0, "polarization": 33.0}
DECK_HZ, ANTENNA_HZ = 25.0, 12.5  # drive natural frequencies on the inertia at home


def rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def ry(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def world_from_deck(yaw, pitch, roll):
    """eTb = (bTe)^T of eq. (1): the transpose of the passive Ry(gamma) Rx(phi) Rz(psi)."""
    return rz(yaw) @ rx(pitch) @ ry(roll)


def f(theta):
    """Antenna frame in the deck frame: Rz(t1) Rx(-t2) Rz(t3) C0 Rz(t4)."""
    t1, t2, t3, t4 = theta
    return rz(t1) @ rx(-t2) @ rz(t3) @ C0 @ rz(t4)


def satellite_attitude(az, el, sigma):
    """eTs of eq. (1) with REFERENCE.md's correction of the first row."""
    ca, sa, ce, se, cs, ss = np.cos(az), np.sin(az), np.cos(el), np.sin(el), np.cos(sigma), np.sin(sigma)
    return np.array(
        [
            [ca * ss - cs * sa * se, ca * cs + sa * se * ss, ce * sa],
            [-sa * ss - ca * cs * se, -cs * sa + ca * se * ss, ca * ce],
            [ce * cs, -ce * ss, se],
        ]
    )


def quat_to_mat(quat):
    mat = np.zeros(9)
    mujoco.mju_quat2Mat(mat, np.asarray(quat, dtype=float))
    return mat.reshape(3, 3)


@pytest.fixture(scope="module")
def model():
    return models.load("antenna")


def _data_at(model, deck, theta):
    data = mujoco.MjData(model)
    data.qpos[:] = np.concatenate([deck, theta])
    mujoco.mj_forward(model, data)
    return data


def _joint_ids(model, names):
    return [model.joint(n).id for n in names]


def _random_data(model, seed):
    """(MjData at a random deck and antenna pose, deck, theta)."""
    deck, theta = _random_pose(np.random.default_rng(seed))
    return _data_at(model, deck, theta), deck, theta


def _random_pose(rng):
    deck = np.array([rng.uniform(-5, 5), rng.uniform(-np.pi, np.pi), *rng.uniform(-1.0, 1.0, 2)])
    theta = np.array(
        [rng.uniform(-np.pi, np.pi), rng.uniform(-3.0, 0.08), rng.uniform(-1.7, 1.7), rng.uniform(-np.pi, np.pi)]
    )
    return deck, theta


def test_structure_names_and_order(model):
    assert model.nq == model.nv == 8 and model.nu == 8 and model.na == 8
    assert [model.joint(i).name for i in range(model.njnt)] == [*DECK_JOINTS, *ANTENNA_JOINTS]
    assert [model.actuator(i).name for i in range(model.nu)] == [*DECK_JOINTS, *ANTENNA_JOINTS]
    chain = [
        "ship",
        "ship_yaw",
        "ship_pitch",
        "deck",
        "pedestal",
        "azimuth",
        "elevation",
        "cross_elevation",
        "polarization",
        "reflector",
    ]
    for parent, child in itertools.pairwise(chain):
        assert model.body(int(model.body(child).parentid[0])).name == parent
    assert model.body("ship").parentid == 0
    # No contacts anywhere.
    assert not model.geom_contype.any() and not model.geom_conaffinity.any()
    sensors = {model.sensor(i).name for i in range(model.nsensor)}
    assert {"imu_gyro", "imu_accel", "imu_quat", "dish_quat"} <= sensors
    assert {f"{j}_pos" for j in ANTENNA_JOINTS} | {f"{j}_torque" for j in ANTENNA_JOINTS} <= sensors


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_world_from_deck_is_rz_rx_ry(model, seed):
    """Deck attitude = Rz(yaw) Rx(pitch) Ry(roll); the deck origin moves with heave only."""
    data, deck, theta = _random_data(model, seed)
    np.testing.assert_allclose(data.body("deck").xmat.reshape(3, 3), world_from_deck(*deck[1:]), atol=1e-12)
    np.testing.assert_allclose(data.body("deck").xpos, [0, 0, deck[0]], atol=1e-12)
    # The mast top (pedestal base) is MAST_TOP above the centre of rotation along the deck's up.
    np.testing.assert_allclose(
        data.body("pedestal").xpos, [0, 0, deck[0]] + world_from_deck(*deck[1:]) @ [0, 0, MAST_TOP], atol=1e-12
    )


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_dish_orientation_in_the_deck_frame_equals_f(model, seed):
    data, deck, theta = _random_data(model, seed)
    r_deck = data.body("deck").xmat.reshape(3, 3)
    r_dish = data.site("dish").xmat.reshape(3, 3)
    np.testing.assert_allclose(r_deck.T @ r_dish, f(theta), atol=1e-12)
    # The dish_quat sensor (world frame) is the same rotation.
    np.testing.assert_allclose(
        quat_to_mat(data.sensor("dish_quat").data), world_from_deck(*deck[1:]) @ f(theta), atol=1e-9
    )
    for name, value in zip(ANTENNA_JOINTS, theta, strict=True):
        assert data.sensor(f"{name}_pos").data[0] == pytest.approx(value, abs=1e-12)


def test_boresight_at_theta0_points_at_the_paper_satellite(model):
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_forward(model, data)
    np.testing.assert_allclose(data.qpos[4:], THETA0, atol=1e-9)
    r_dish = data.site("dish").xmat.reshape(3, 3)
    boresight = np.array([np.cos(EL0) * np.sin(AZ0), np.cos(EL0) * np.cos(AZ0), np.sin(EL0)])
    np.testing.assert_allclose(r_dish[:, 2], boresight, atol=1e-9)
    az = np.arctan2(r_dish[0, 2], r_dish[1, 2]) % (2 * np.pi)
    assert np.degrees(az) == pytest.approx(223.49, abs=1e-7)
    assert np.degrees(np.arcsin(r_dish[2, 2])) == pytest.approx(60.0, abs=1e-7)
    # The whole frame, polarization included, is eq. (1)'s eTs (corrected) at zero ship motion.
    np.testing.assert_allclose(r_dish, satellite_attitude(AZ0, EL0, POL0), atol=1e-9)


def test_reflector_inertia_equals_the_thin_disc_formulas(model):
    body = model.body("reflector")
    m, r, h = REFLECTOR_MASS, REFLECTOR_RADIUS, 2 * REFLECTOR_HALF_THICKNESS
    assert body.mass[0] == pytest.approx(m)
    # Thin disc: I_axis = m R^2 / 2 = 1.5 kg m^2; I_diameter = m R^2 / 4 (+ m h^2 / 12) = 0.7501.
    expected = np.array([m * r * r / 4 + m * h * h / 12, m * r * r / 4 + m * h * h / 12, m * r * r / 2])
    np.testing.assert_allclose(body.inertia, expected, rtol=1e-9)
    assert expected[2] == pytest.approx(1.5) and expected[0] == pytest.approx(0.7501)
    np.testing.assert_allclose(body.ipos, 0, atol=1e-12)
    # At the paraboloid's area centroid: d/2 = R^2 / (8 F) = 0.078125 m in front of the vertex at O.
    np.testing.assert_allclose(body.pos, [0, 0, r * r / (8 * 0.40)], atol=1e-12)


def test_polarization_axis_inertia_by_hand(model):
    """What the polarization drive turns, about the boresight, part by part (README.md):
    reflector disc m R^2/2; coaxial cylinders m r^2/2 (drive, counterweight, feed); RF box
    m (a^2 + b^2)/12 + m x^2; four radial struts m (r1^2 + r1 r2 + r2^2)/3 (+ m r_s^2/2)."""
    reflector = 12 * 0.5**2 / 2
    drive, counterweight, feed = 6 * 0.12**2 / 2, 4 * 0.10**2 / 2, 2 * 0.06**2 / 2
    rf_box = 8 * (0.18**2 + 0.14**2) / 12 + 8 * 0.00825**2
    r1, r2 = 0.06, 0.45
    struts = 4 * 0.25 * ((r1 * r1 + r1 * r2 + r2 * r2) / 3 + 0.01**2 / 2)
    hand = reflector + drive + counterweight + feed + rf_box + struts  # 1.680 kg m^2
    data = _data_at(model, np.zeros(4), THETA0)
    mass = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, mass)
    jid = model.joint("polarization").id
    assert mass[7, 7] - model.dof_armature[model.jnt_dofadr[jid]] == pytest.approx(hand, rel=2e-3)
    assert hand == pytest.approx(1.680, abs=1e-3)


def test_masses_and_the_residual_imbalance(model):
    data = _data_at(model, np.zeros(4), THETA0)
    for name, mass in MOVING_MASS.items():
        bodies = [name] + (["reflector"] if name == "polarization" else [])
        assert sum(model.body(b).mass[0] for b in bodies) == pytest.approx(mass)
    assert model.body_subtreemass[model.body("azimuth").id] == pytest.approx(98.0)
    assert model.body("pedestal").mass[0] == pytest.approx(25.0)
    # Polarization assembly's centre of mass, in the antenna frame: (2, 0, 3) mm from O.
    r_dish = data.site("dish").xmat.reshape(3, 3)
    com = r_dish.T @ (data.subtree_com[model.body("polarization").id] - data.site("dish").xpos)
    np.testing.assert_allclose(com, POL_COM, atol=1e-12)
    # The frames are balanced: elevation and cross-elevation on O, azimuth on its axis.
    for name in ("elevation", "cross_elevation"):
        np.testing.assert_allclose(data.xipos[model.body(name).id], data.site("dish").xpos, atol=1e-12)
    az_com = data.body("azimuth").xmat.reshape(3, 3).T @ (data.body("azimuth").xipos - data.body("azimuth").xpos)
    np.testing.assert_allclose(az_com[:2], 0, atol=1e-12)
    # Deck structure: 20 t, plus three 1 t drive carriers.
    assert model.body("deck").mass[0] == pytest.approx(20000.0)
    assert model.body_subtreemass[model.body("ship").id] == pytest.approx(23000.0 + 25.0 + 98.0)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_four_axes_meet_at_one_point_and_are_orthogonal_in_sequence(seed):
    model = models.load("antenna")
    rng = np.random.default_rng(seed)
    deck, theta = _random_pose(rng)
    data = _data_at(model, deck, theta)
    ids = _joint_ids(model, ANTENNA_JOINTS)
    anchors = data.xanchor[ids]
    np.testing.assert_allclose(anchors, np.broadcast_to(anchors[0], anchors.shape), atol=1e-12)
    np.testing.assert_allclose(anchors[0], data.site("dish").xpos, atol=1e-12)
    expected_o = [0, 0, deck[0]] + world_from_deck(*deck[1:]) @ [0, 0, MAST_TOP + AXES_HEIGHT]
    np.testing.assert_allclose(anchors[0], expected_o, atol=1e-12)
    axes = data.xaxis[ids]
    for a, b in itertools.pairwise(axes):
        assert abs(a @ b) < 1e-12
    # The polarization axis is the boresight.
    np.testing.assert_allclose(axes[3], data.site("dish").xmat.reshape(3, 3)[:, 2], atol=1e-12)


def test_home_keyframe_holds_still(model):
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    q0 = data.qpos.copy()
    data.ctrl[:] = 0.0
    mujoco.mj_step(model, data, nstep=1000)  # 1 s
    drift = np.abs(data.qpos - q0)
    assert drift[4:].max() < 1e-6, drift  # antenna joints, rad
    assert drift[:4].max() < 1e-6, drift  # deck: heave m, angles rad
    # Without the gravity offsets in act the same start sags by tau_g / kp: the keyframe's act
    # is what holds it (and the elevation/cross-elevation offsets are the imbalance's).
    data2 = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data2, model.key("home").id)
    data2.act[:] = data2.qpos
    mujoco.mj_step(model, data2, nstep=1000)
    assert np.abs(data2.qpos - q0).max() > 1e-5


def test_drive_gains_give_the_design_natural_frequencies(model):
    """kp = I w^2 and kv = 2 I w (critical damping) on the inertia each axis sees at home."""
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_forward(model, data)
    mass = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, mass)
    inertia = np.diag(mass)  # joint-space inertia, armature included
    kp = model.actuator_gainprm[:, 0]
    kv = -model.actuator_biasprm[:, 2]
    np.testing.assert_allclose(-model.actuator_biasprm[:, 1], kp)
    hz = np.sqrt(kp / inertia) / (2 * np.pi)
    zeta = kv / (2 * np.sqrt(kp * inertia))
    np.testing.assert_allclose(hz[:4], DECK_HZ, rtol=0.01)
    np.testing.assert_allclose(hz[4:], ANTENNA_HZ, rtol=0.01)
    np.testing.assert_allclose(zeta, 1.0, rtol=0.01)
    # Every drive is the set-point integrator kind with a rate (ctrl) and a force limit.
    assert (model.actuator_dyntype == mujoco.mjtDyn.mjDYN_INTEGRATOR).all()
    assert model.actuator_ctrllimited.all() and model.actuator_forcelimited.all()


def test_rate_and_torque_limits_cover_the_papers_extreme_motion(model):
    """Rated speeds >= 1.4 x the paper's peak joint rates (25/31/41/31 deg/s, CRR path under
    eq. (15)-(16)); deck set-point rates >= the ship's peak rates; torque limits >= 2 x the
    README's conservative bound I (alpha_ship + alpha_rel) + m e a_base."""
    rate_deg = np.degrees(model.actuator_ctrlrange[4:, 1])
    assert (rate_deg >= 1.4 * np.array([25.4, 31.0, 40.6, 30.5])).all()
    deck_rate = model.actuator_ctrlrange[:4, 1]
    assert deck_rate[0] >= 2 * 3.0  # heave m/s
    assert deck_rate[1] >= 5 * 2 * DEG  # yaw, rad/s
    assert deck_rate[2] >= 1.5 * 40 * DEG * 2 * np.pi / 8  # pitch 40 deg at 8 s: 31 deg/s
    assert deck_rate[3] >= 1.5 * 45 * DEG * 2 * np.pi / 10  # roll 45 deg at 10 s: 28 deg/s
    inertia_max = np.array([11.64, 2.96, 2.03, 1.78])  # max of M_jj over the paper's path
    pitch_amp, pitch_w = 40 * DEG, 2 * np.pi / 8
    roll_amp, roll_w = 45 * DEG, 2 * np.pi / 10
    alpha_ship = pitch_amp * pitch_w**2 + roll_amp * roll_w**2  # 0.431 + 0.310 rad/s^2
    alpha = alpha_ship + 30 * DEG  # + the joints' own peak, ~30 deg/s^2
    omega2 = (pitch_amp * pitch_w) ** 2 + (roll_amp * roll_w) ** 2  # centripetal, 1/s^2
    a_base = G + (MAST_TOP + AXES_HEIGHT) * (alpha_ship + omega2)  # 23.5 m/s^2 at O
    lever = np.array([np.linalg.norm(POL_COM)] * 3 + [POL_COM[0]])
    bound = inertia_max * alpha + POL_MASS * lever * a_base
    assert (model.actuator_forcerange[4:, 1] >= 2 * bound).all(), (model.actuator_forcerange[4:, 1], bound)


def _hold(model, deck, theta, seconds):
    """Start at (deck, theta) with every set-point at its joint, the deck's offset by its
    static load (so only the antenna sags under its imbalance), and run with ctrl = 0."""
    data = _data_at(model, deck, theta)
    kp = model.actuator_gainprm[:, 0]
    data.act[:] = data.qpos
    data.act[:4] += data.qfrc_bias[:4] / kp[:4]
    mujoco.mj_step(model, data, nstep=round(seconds / model.opt.timestep))
    return data


@pytest.mark.parametrize(
    "deck, theta_deg",
    [
        ((0.0, 0.7, 0.35, -0.5), (136.51, -60.0, 0.0, -28.8)),
        ((0.0, -1.2, -0.2, 0.6), (30.0, -120.0, 40.0, 75.0)),
        ((0.0, 0.0, 0.0, 0.0), (-60.0, -20.0, -70.0, 150.0)),
    ],
)
def test_static_holding_torques_equal_the_hand_imbalance_torque(model, deck, theta_deg):
    """At rest on a tilted deck each antenna drive holds the weight of the polarization
    assembly acting at its 3.6 mm offset: tau_j = -(r x m g) . a_j, r = R_wa (2, 0, 3) mm.
    The other frames are balanced on their axes and add nothing."""
    theta = np.radians(theta_deg)
    data = _hold(model, np.array(deck), theta, 1.0)
    r_wd = world_from_deck(*deck[1:])
    r_wa = r_wd @ f(theta)
    lever = r_wa @ POL_COM
    weight = POL_MASS * np.array([0.0, 0.0, -G])
    # World joint axes from the chain (hand): z, -x of Rz(t1), z of Rz(t1) Rx(-t2), boresight.
    t1, t2 = theta[:2]
    axes = r_wd @ np.column_stack([[0, 0, 1], rz(t1) @ [-1, 0, 0], rz(t1) @ rx(-t2) @ [0, 0, 1], f(theta)[:, 2]])
    expected = -(np.cross(lever, weight) @ axes)
    measured = np.array([data.sensor(f"{name}_torque").data[0] for name in ANTENNA_JOINTS])
    scale = POL_MASS * G * np.linalg.norm(POL_COM)  # 1.17 N m, the largest possible
    np.testing.assert_allclose(measured, expected, rtol=0.02, atol=0.01 * scale)
    assert np.abs(measured).max() > 0.2 * scale  # not a trivially zero case
    # The set-point lag is that torque over kp (the drives are ideal springs at rest).
    kp = model.actuator_gainprm[4:, 0]
    np.testing.assert_allclose(data.act[4:] - data.qpos[4:], measured / kp, atol=1e-9)
    assert np.abs(data.qvel).max() < 1e-6


def test_imu_reads_the_deck_attitude_and_gravity_at_rest(model):
    deck = np.array([0.0, 0.4, -0.3, 0.5])
    data = _hold(model, deck, THETA0, 0.3)
    r_wd = world_from_deck(*deck[1:])
    # framequat of the IMU = the deck's orientation (the IMU is fixed to the deck, unrotated).
    np.testing.assert_allclose(quat_to_mat(data.sensor("imu_quat").data), r_wd, atol=1e-6)
    np.testing.assert_allclose(
        quat_to_mat(data.sensor("imu_quat").data), quat_to_mat(data.body("deck").xquat), atol=1e-12
    )
    # An accelerometer at rest reads the specific force: +g up, in its own frame.
    np.testing.assert_allclose(data.sensor("imu_accel").data, r_wd.T @ [0, 0, G], atol=1e-3)
    np.testing.assert_allclose(data.sensor("imu_gyro").data, 0, atol=1e-6)


@pytest.mark.parametrize("joint, rate", [("roll", 0.3), ("pitch", -0.25), ("yaw", 0.1)])
def test_gyro_reads_the_body_frame_rate_of_a_driven_deck_axis(model, joint, rate):
    """Drive one deck axis at a constant set-point rate: once the drive has caught up the
    gyro reads that rate about the axis, expressed in the deck frame: roll (0, w, 0); pitch
    Ry(roll)^T (w, 0, 0); yaw (Rx(pitch) Ry(roll))^T (0, 0, w)."""
    deck = np.array([0.0, 0.2, 0.15, -0.1])
    data = _data_at(model, deck, THETA0)
    kp = model.actuator_gainprm[:, 0]
    data.act[:] = data.qpos
    data.act[:4] += data.qfrc_bias[:4] / kp[:4]
    data.ctrl[:] = 0.0
    data.ctrl[model.actuator(joint).id] = rate
    mujoco.mj_step(model, data, nstep=300)  # 0.3 s >> the 6 ms time constant of the drive
    _, pitch, roll = data.qpos[1:4]
    # The joint runs at the set-point rate, less the slow change of its gravity lag
    # (d tau_g/dt / kp ~ 2e-5 rad/s for the 20 t deck).
    w = data.qvel[model.joint(joint).id]
    assert w == pytest.approx(rate, rel=2e-4)
    others = np.delete(data.qvel[:4], model.joint(joint).id)
    assert np.abs(others).max() < 1e-4 * abs(rate)
    expected = {
        "roll": np.array([0, w, 0]),
        "pitch": ry(roll).T @ [w, 0, 0],
        "yaw": (rx(pitch) @ ry(roll)).T @ [0, 0, w],
    }[joint]
    np.testing.assert_allclose(data.sensor("imu_gyro").data, expected, atol=1e-4 * abs(rate))


def test_deck_tracks_the_papers_ship_motion_with_feed_forward(model):
    """The stiff deck drives impose the ship motion of eq. (15)-(16) (heading with its turn,
    pitch 40 deg / 8 s, roll 45 deg / 10 s) to better than 0.001 deg when the set-point carries
    the inverse-dynamics feed-forward: act = q_d + (tau_id + kv qdot_d) / kp."""
    w_yaw, w_pitch, w_roll = 2 * np.pi / 300, 2 * np.pi / 8, 2 * np.pi / 10
    turn = 1.0 * DEG  # 0.01 deg per 0.01 s sample

    def ship(t):
        q = np.array(
            [
                0.0,
                40 * DEG * np.sin(w_yaw * t) + turn * t,
                40 * DEG * np.sin(w_pitch * t),
                45 * DEG * np.sin(w_roll * t),
            ]
        )
        qd = np.array(
            [
                0.0,
                40 * DEG * w_yaw * np.cos(w_yaw * t) + turn,
                40 * DEG * w_pitch * np.cos(w_pitch * t),
                45 * DEG * w_roll * np.cos(w_roll * t),
            ]
        )
        qdd = np.array(
            [
                0.0,
                -40 * DEG * w_yaw**2 * np.sin(w_yaw * t),
                -40 * DEG * w_pitch**2 * np.sin(w_pitch * t),
                -45 * DEG * w_roll**2 * np.sin(w_roll * t),
            ]
        )
        return q, qd, qdd

    kp = model.actuator_gainprm[:4, 0]
    kv = -model.actuator_biasprm[:4, 2]
    inverse = mujoco.MjData(model)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)

    def setpoint(t):
        q, qd, qdd = ship(t)
        inverse.qpos[:] = np.concatenate([q, data.qpos[4:]])
        inverse.qvel[:] = np.concatenate([qd, data.qvel[4:]])
        inverse.qacc[:] = np.concatenate([qdd, np.zeros(4)])
        mujoco.mj_inverse(model, inverse)
        return q + (inverse.qfrc_inverse[:4] + kv * qd) / kp

    q, qd, _ = ship(0.0)
    data.qpos[:4], data.qvel[:4] = q, qd
    data.act[:4] = setpoint(0.0)
    dt = model.opt.timestep
    errors, antenna_torque, deck_force = [], [], []
    for k in range(3000):  # 3 s, the largest pitch and roll rates included
        data.ctrl[:4] = (setpoint((k + 1) * dt) - data.act[:4]) / dt
        assert (np.abs(data.ctrl[:4]) <= model.actuator_ctrlrange[:4, 1]).all()
        mujoco.mj_step(model, data)
        errors.append(data.qpos[:4] - ship(data.time)[0])
        antenna_torque.append(data.actuator_force[4:].copy())
        deck_force.append(data.actuator_force[:4].copy())
    errors = np.abs(np.array(errors[200:]))  # after the start transient
    assert np.degrees(errors[:, 1:].max()) < 1e-3, np.degrees(errors.max(0))
    assert errors[:, 0].max() < 1e-5  # heave, m
    # The antenna feels the motion: its drives now carry inertial torques well above the
    # ~0.3 N m static imbalance at home.
    assert np.abs(np.array(antenna_torque)).max() > 0.5
    assert np.abs(np.array(deck_force)).max(axis=0)[1:].max() < model.actuator_forcerange[2, 1]


def test_antenna_spec_matches_the_compiled_model(model):
    spec = models.antenna_spec()
    assert spec.names == list(ANTENNA_JOINTS) and spec.frame == "deck"
    np.testing.assert_allclose(spec.base_pos, [0, 0, MAST_TOP])
    for _i, joint in enumerate(spec.joints):
        jid = model.joint(joint.name).id
        aid = model.actuator(joint.name).id
        np.testing.assert_allclose(joint.axis, model.jnt_axis[jid], atol=1e-12)
        assert bool(model.jnt_limited[jid]) == np.isfinite(joint.lower)
        if model.jnt_limited[jid]:
            np.testing.assert_allclose([joint.lower, joint.upper], model.jnt_range[jid])
        assert joint.kp == model.actuator_gainprm[aid, 0] and joint.kv == -model.actuator_biasprm[aid, 2]
        assert joint.force_limit == model.actuator_forcerange[aid, 1]
        assert joint.rate_limit == model.actuator_ctrlrange[aid, 1]
    # Unlimited: azimuth (slip ring) and polarization; stops on elevation and cross-elevation.
    assert np.isinf(spec.lower[[0, 3]]).all()
    np.testing.assert_allclose(np.degrees(spec.lower[1:3]), [-175, -100])
    np.testing.assert_allclose(np.degrees(spec.upper[1:3]), [5, 100])
    # The spec's bodies, composed, give f(Theta) and O.
    rng = np.random.default_rng(7)
    for _ in range(5):
        theta = rng.uniform(-np.pi, np.pi, 4)
        rot, pos = quat_to_mat(spec.base_quat), spec.base_pos.copy()
        for body in spec.bodies:
            pos = pos + rot @ body.pos
            rot = rot @ quat_to_mat(body.quat)
            if body.joint is not None:
                axis = spec.joints[body.joint].axis
                rotvec = np.zeros(4)
                mujoco.mju_axisAngle2Quat(rotvec, axis, theta[body.joint])
                rot = rot @ quat_to_mat(rotvec)
            if body.name == "polarization":
                np.testing.assert_allclose(rot, f(theta), atol=1e-12)
                np.testing.assert_allclose(pos, [0, 0, MAST_TOP + AXES_HEIGHT], atol=1e-12)
