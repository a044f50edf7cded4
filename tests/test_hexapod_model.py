"""The hexapod MJCF: Menagerie-style lint, geometry = planner, statics and modes by hand."""

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from planbench import models
from planbench.hexapod import HexapodController, HexapodPhysics, top_end_rotation
from planbench.planners import hexapod
from planbench.planners.hexapod import RUBIN_CAMERA, STRUT_LABELS
from planbench.planners.trajectory import TrajectorySample

G = 9.81


@pytest.fixture(scope="module")
def model():
    return models.load("hexapod")


def test_pivots_and_strut_lengths_equal_the_planner_geometry(model):
    assert model.nu == 6 and model.neq == 6 and model.nv == 24  # 6 + 6 x (2 + 1) dofs
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    for i, name in enumerate(STRUT_LABELS, start=1):
        np.testing.assert_allclose(model.site(f"base_pivot{i}").pos, RUBIN_CAMERA.base_pivots[i - 1], atol=1e-12)
        np.testing.assert_allclose(model.site(f"platform_pivot{i}").pos, RUBIN_CAMERA.platform_local[i - 1], atol=1e-12)
        assert model.body(f"{name}_rod").pos[2] == pytest.approx(RUBIN_CAMERA.nominal_lengths[i - 1], abs=1e-9)
        np.testing.assert_allclose(model.jnt_range[model.joint(name).id], [-0.015, 0.015])
    np.testing.assert_allclose(data.ten_length, RUBIN_CAMERA.nominal_lengths, atol=1e-9)
    # The keyframe closes every loop.
    rows = data.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
    assert np.abs(data.efc_pos[rows]).max() < 1e-9


def test_mass_properties_by_hand():
    physics = HexapodPhysics.load(90.0)
    mass, com = physics.payload_mass_properties()
    assert mass == pytest.approx(3150.0)
    # Camera centre 1.5 m + 2.7584 m above the pivot, ring at 0.1214 m + ... = 2.637 m.
    assert com == pytest.approx([0.0, 0.0, (3000 * 4.2584 + 150 * 2.637) / 3150], abs=1e-9)
    camera = physics.model.ptr.body("camera")
    r, length = 0.825, 3.0
    np.testing.assert_allclose(
        camera.inertia, [3000 * (3 * r * r + length**2) / 12] * 2 + [3000 * r * r / 2], rtol=1e-9
    )


@pytest.mark.parametrize("elevation", [15.0, 45.0, 90.0])
def test_gravity_direction_in_the_hexapod_frame(elevation):
    physics = HexapodPhysics.load(elevation)
    el = np.radians(elevation)
    np.testing.assert_allclose(
        physics.gravity_in_hexapod_frame(), G * np.array([0, -np.cos(el), np.sin(el)]), atol=1e-12
    )
    rotation = top_end_rotation(elevation)
    np.testing.assert_allclose(rotation.T @ rotation, np.eye(3), atol=1e-15)
    assert np.linalg.det(rotation) == pytest.approx(1.0)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([15.0, 60.0, 90.0]))
def test_planner_strut_lengths_equal_mujoco_lengths(seed, elevation):
    """IK of the planner = pivot-to-pivot lengths MuJoCo measures (tendons) at random poses."""
    physics = HexapodPhysics.load(elevation)
    pose = hexapod.random_poses(1, np.random.default_rng(seed))[0]
    physics.set_pose(pose)
    np.testing.assert_allclose(physics.strut_lengths(), hexapod.strut_lengths(pose), atol=1e-12)
    np.testing.assert_allclose(physics.strut_positions(), hexapod.strut_positions(pose), atol=1e-12)
    assert physics.loop_closure_error() < 1e-12
    np.testing.assert_allclose(physics.platform_pose(), pose, atol=1e-12)
    # The pose sensors (pivot in the hexapod frame) agree.
    np.testing.assert_allclose(
        physics.named.data.sensordata["platform_pos"], RUBIN_CAMERA.rotation_pivot + pose[:3], atol=1e-12
    )


class _Still:
    """A trajectory that holds the struts at ``start`` (6,) for ``duration`` s."""

    labels = STRUT_LABELS

    def __init__(self, start, duration):
        self.start, self.duration = np.asarray(start), float(duration)

    def sample(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        zeros = np.zeros((t.size, 6))
        return TrajectorySample(t, np.broadcast_to(self.start, (t.size, 6)).copy(), zeros, zeros)


def _hold(physics, seconds):
    """HexapodController holding the start for ``seconds``, run by the runner."""
    from planbench import hexapod as hexapod_sim
    from planbench import runner
    from planbench.task import Components, Task

    controller = HexapodController()
    task = Task(problem=None, sensors=hexapod_sim.sensors(physics), evaluation=None, control_dt=0.005, duration=seconds)
    setup = runner.Setup(
        physics,
        task,
        Components(planner=None, trajectory=_Still(physics.strut_positions(), seconds), controller=controller),
    )
    runner.simulate(setup)
    return controller


@pytest.mark.parametrize("elevation", [15.0, 90.0])
def test_static_strut_forces_equal_hand_statics(elevation):
    """Held at rest, MuJoCo's drive forces equal the statics of the weights (planner's J^-T)."""
    physics = HexapodPhysics.load(elevation)
    controller = _hold(physics, 1.0)
    measured = physics.strut_drive_forces()
    expected = controller.f_ff[-1]
    np.testing.assert_allclose(measured, expected, rtol=2e-3, atol=5.0)
    # Independent: the six struts and the weights balance. The vertical (gravity-direction)
    # component of the strut forces on the platform carries the platform's weight plus what the
    # struts hang on it.
    mass, _ = physics.payload_mass_properties()
    g_hat = physics.gravity_in_hexapod_frame() / G
    units = hexapod.pivot_positions(np.zeros(6)) - RUBIN_CAMERA.base_pivots
    units /= np.linalg.norm(units, axis=1, keepdims=True)
    along_gravity = measured @ (units @ g_hat)  # a push f acts on the platform along +u
    model = physics.model.ptr
    strut_mass = sum(model.body_mass[model.body(f"{n}_{part}").id] for n in STRUT_LABELS for part in ("housing", "rod"))
    # The struts' own weight hangs partly on the platform pivots: at most half of it.
    assert along_gravity == pytest.approx(-mass * G, abs=0.5 * strut_mass * G)
    if elevation == 90.0:
        # At the zenith the camera hangs: every strut pulls (negative drive force), ~6.3 kN.
        assert np.all(measured < 0)
        np.testing.assert_allclose(-measured, 6290.0, rtol=0.03)


def test_lowest_modes_match_the_rigid_body_hand_computation():
    """Free vibration (no gravity, no damping) of the platform on six kp springs.

    Hand model: K = J^T kp J in pose coordinates, M = the payload's rigid-body mass matrix about
    the pivot plus the struts' reflected inertia J^T (armature + rod) J; the two lowest modes
    are the camera's rocking at ~12 Hz. MuJoCo's response is read from an FFT.
    """
    physics = HexapodPhysics.load(90.0)
    model, data = physics.model.ptr, physics.data.ptr
    model.opt.gravity[:] = 0.0
    model.actuator_biasprm[:6, 2] = 0.0
    physics.set_pose(np.zeros(6))
    data.qvel[model.joint("platform").dofadr[0] + 3] = 1e-4  # small spin about world x
    n, dt = 8000, model.opt.timestep * 2
    rx = np.empty(n)
    for k in range(n):
        mujoco.mj_step(model, data, nstep=2)
        rx[k] = physics.platform_pose()[3]
    spectrum = np.abs(np.fft.rfft(rx - rx.mean()))
    freqs = np.fft.rfftfreq(n, dt)
    measured = freqs[np.argmax(spectrum[1:]) + 1]

    J = hexapod.jacobian(np.zeros(6))
    kp = physics.kp[0]
    mass_matrix = np.zeros((6, 6))
    for body, com_z in (("camera", 4.2584), ("platform", 2.637)):
        b = model.body(body)
        m = b.mass[0]
        x = np.array([[0, -com_z, 0], [com_z, 0, 0], [0, 0, 0]])
        mass_matrix[:3, :3] += m * np.eye(3)
        mass_matrix[:3, 3:] += -m * x
        mass_matrix[3:, :3] += m * x
        mass_matrix[3:, 3:] += np.diag(b.inertia) - m * x @ x
    strut_inertia = model.dof_armature[physics.strut_dofs][0] + physics.strut_rod_masses()[0]
    mass_matrix += strut_inertia * J.T @ J
    from scipy.linalg import eigh

    hand = np.sqrt(eigh(kp * J.T @ J, mass_matrix, eigvals_only=True)) / (2 * np.pi)
    assert 10.0 < hand[0] < 14.0
    assert measured == pytest.approx(hand[0], rel=0.06)
