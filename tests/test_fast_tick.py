"""The FAST loop's per-tick arithmetic in Python floats (sims/fast/measurement.py) against the
vectorized numpy forms it replaced: the same numbers.

Where the scalar code sums a matrix-vector product in the order numpy's einsum sums it on
this machine (``EINSUM_PAIRS``), the two agree to the bit; on a numpy whose einsum sums in
another order they agree to round-off (1e-15 of the terms). A fix's correction sums in
another order than its numpy form (the fit in the body frame, Phi^k K in one product): the
two agree to round-off (1e-12 of each quantity's scale)."""

from __future__ import annotations

import mujoco
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from planbench import runner
from planbench.fast import FastTrackingParams, build_scenario
from planbench.fast.measurement import FusedPoses
from planbench.fast.physics import _LEVI_CIVITA, index_view
from planbench.planners.legs import cross, leg_vectors, structure_matrix


def _einsum_pairs_first_and_third() -> bool:
    """Whether numpy's einsum sums R v ("bij,bj->bi", 3 terms) as (p0 + p2) + p1, the order the
    scalar code follows: products that differ in their roundings tell."""
    r = np.array([[[1.0, 1e-16, 1.0]] * 3] * 2)
    v = np.array([[1.0, 1.0, -1.0]] * 2)  # (1 - 1) + 1e-16 = 1e-16; (1 + 1e-16) - 1 = 0
    return bool(np.einsum("bij,bj->bi", r, v)[0, 0] == 1e-16)


EINSUM_PAIRS = _einsum_pairs_first_and_third()


def assert_same(ours, theirs, scale):
    """Bit for bit where einsum sums as the scalar code does, else within 1e-15 of ``scale``."""
    ours, theirs = np.asarray(ours, float), np.asarray(theirs, float)
    if EINSUM_PAIRS:
        np.testing.assert_array_equal(ours, theirs)
    else:
        np.testing.assert_allclose(ours, theirs, rtol=0.0, atol=1e-15 * scale)


def _vectorized_propagate(state: dict, dt: float, gravity, specific_force, rate) -> None:
    """The strapdown tick on (B, ...) arrays (the earlier implementation)."""
    r = state["rotation"]
    acceleration = np.einsum("bij,bj->bi", r, specific_force - state["accel_bias"]) + gravity
    state["position"] += (state["velocity"] + (0.5 * dt) * acceleration) * dt
    state["velocity"] += acceleration * dt
    state["rotation"] = r - np.einsum("bik,kjl,bl->bij", r, _LEVI_CIVITA, (rate - state["gyro_bias"]) * dt)


def _filters(offsets: np.ndarray) -> FusedPoses:
    points = [np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, -1.0, 0.2]])] * 2
    noise = dict(
        accel_white=1e-3, accel_walk=1e-4, gyro_white=1e-5, gyro_walk=1e-7, every=5, fix_white=1e-3, fix_drift=1e-3
    )
    return FusedPoses(points, offsets, [noise, noise], 0.02, np.array([0.0, 0.0, -9.81]), 12)


vectors = arrays(float, (2, 3), elements=st.floats(-20.0, 20.0))


@settings(max_examples=80, deadline=None)
@given(
    arrays(float, (2, 3), elements=st.floats(-3.0, 3.0)),
    arrays(float, (2, 3), elements=st.floats(-300.0, 300.0)),
    st.lists(st.tuples(vectors, arrays(float, (2, 3), elements=st.floats(-0.5, 0.5))), min_size=1, max_size=8),
    arrays(float, (2, 3), elements=st.floats(-0.05, 0.05)),
    arrays(float, (2, 3), elements=st.floats(-1e-3, 1e-3)),
)
def test_the_scalar_strapdown_tick_is_the_vectorized_one(angles, positions, readings, accel_bias, gyro_bias):
    """Ticks of FusedPoses.propagate from any pose, with any biases: positions, velocities,
    rotations and the bodies' origins as the (B, 3) einsum form gives them."""
    from scipy.spatial.transform import Rotation

    offsets = np.array([[0.3, -1.2, 2.5], [-0.7, 0.4, -1.9]])
    rotations = Rotation.from_rotvec(angles).as_matrix()
    f = _filters(offsets)
    f.reset(positions, rotations)
    f._accel_bias, f._gyro_bias = accel_bias.tolist(), gyro_bias.tolist()
    state = {
        "rotation": rotations.copy(),
        "velocity": np.zeros((2, 3)),
        "accel_bias": accel_bias,
        "gyro_bias": gyro_bias,
        "position": positions + np.einsum("bij,bj->bi", rotations, offsets),
    }
    for force, rate in readings:
        f.propagate(force, rate)
        _vectorized_propagate(state, f.dt, f.gravity, force, rate)
        assert_same(f.position, state["position"], 400.0)
        assert_same(f.velocity, state["velocity"], 20.0)
        assert_same(f.rotation, state["rotation"], 1.0)
        origins = state["position"] - np.einsum("bij,bj->bi", state["rotation"], offsets)
        assert_same(f.body_poses()[0], origins, 400.0)
    assert f.tick == len(readings)


def test_the_sensors_tick_reads_what_the_vectorized_one_did():
    """A run's IMU readings, estimates and encoders every tick against the vectorized
    formulas on the same MuJoCo data: the specific force from the velocity increment (world
    velocity R v, then R^T of the force), the rates, the estimates' origins and the B frame's
    rotation in the cabin frame."""
    setup = build_scenario(FastTrackingParams(duration=3.0))
    task, sensors = setup.task, setup.task.sensors
    physics = setup.physics
    data = physics.data.ptr
    seen = {"ticks": 0, "last": None}
    observe = task.observe

    def checked(tick, phys):
        rotation = data.site_xmat[sensors._imu_sites].reshape(2, 3, 3)
        velocity = np.einsum("kij,kj->ki", rotation, data.sensordata[sensors._vel_columns])
        gyro = data.sensordata[sensors._gyro_columns] + sensors.gyro_error[tick]
        observe(tick, phys)
        force = (
            (velocity - seen["last"]) / sensors.dt - sensors.gravity
            if tick
            else -np.broadcast_to(sensors.gravity, (2, 3))
        )
        accel = np.einsum("kji,kj->ki", rotation, force) + sensors.accel_error[tick]
        seen["last"] = velocity
        obs = sensors.observation
        assert_same(np.stack([obs["cabin_imu_accel"], obs["platform_imu_accel"]]), accel, 10.0)
        np.testing.assert_array_equal(np.stack([obs["cabin_imu_gyro"], obs["platform_imu_gyro"]]), gyro)
        f = sensors.filters
        origins = f.position - np.einsum("bij,bj->bi", f.rotation, f.imu_offsets)
        assert_same(sensors.estimates.row("estimate", tick)[:, :3], origins, 400.0)
        np.testing.assert_array_equal(sensors.estimates.row("estimate", tick)[:, 3:], f.rotation.reshape(2, 9))
        np.testing.assert_array_equal(obs["cabin_estimate_position"], sensors.estimates.row("estimate", tick)[0, :3])
        np.testing.assert_array_equal(
            obs["platform_estimate_rotation"].ravel(), sensors.estimates.row("estimate", tick)[1, 3:]
        )
        np.testing.assert_array_equal(obs["platform_estimate_velocity"], f.velocity[1])
        np.testing.assert_array_equal(obs["ab_angles"], data.qpos[physics.ab_qpos])
        np.testing.assert_array_equal(obs["leg_positions"], data.qpos[physics.leg_qpos])
        np.testing.assert_array_equal(obs["leg_setpoints"], data.act[physics.leg_act])
        np.testing.assert_array_equal(
            obs["ab_rotation"],
            data.xmat[physics.cabin_body].reshape(3, 3).T @ data.xmat[physics.ab_b_body].reshape(3, 3),
        )
        seen["ticks"] += 1

    task.observe = checked
    log = runner.simulate(setup)
    assert seen["ticks"] == log.t.size - 1 and int(sensors.observation["cabin_rtk_count"][0]) > 20


@settings(max_examples=200, deadline=None)
@given(st.lists(st.integers(0, 40), min_size=0, max_size=8), st.integers(0, 30), st.integers(-3, 5), st.integers(1, 8))
def test_an_index_view_indexes_the_elements_of_its_indices(scattered, start, step, size):
    """index_view: a slice (a view) for indices that step evenly upward, the indices
    otherwise; either way the same elements, and a view writes through."""
    a = np.arange(200.0) * 1.5
    for ids in (np.array(scattered, dtype=int), start + 20 + step * np.arange(size)):
        view = index_view(ids)
        np.testing.assert_array_equal(a[view], a[ids])
        if isinstance(view, slice):
            b = a.copy()
            b[view] = -1.0
            assert np.all(b[ids] == -1.0) and np.count_nonzero(b == -1.0) == np.unique(ids).size
    assert isinstance(index_view(np.array([3, 4, 5])), slice)
    assert isinstance(index_view(np.array([11, 14, 17])), slice)
    assert not isinstance(index_view(np.array([5, 4, 3])), slice)
    assert not isinstance(index_view(np.array([-1, 0, 1])), slice)  # -1: the last element


def _structure_matrix_with_np_cross(anchors, points, position, rotation):
    """planbench.planners.legs.structure_matrix as it was written first: np.cross, leg_vectors."""
    vectors = leg_vectors(anchors, points, position, rotation)
    units = vectors / np.linalg.norm(vectors, axis=-1, keepdims=True)
    arms = np.einsum("...jk,nk->...nj", np.asarray(rotation, dtype=float), np.asarray(points, dtype=float))
    return np.swapaxes(np.concatenate([-units, -np.cross(arms, units)], axis=-1), -1, -2)


@settings(max_examples=100, deadline=None)
@given(
    arrays(float, (6, 3), elements=st.floats(-300.0, 300.0)),
    arrays(float, (6, 3), elements=st.floats(-10.0, 10.0)),
    st.integers(0, 3),
    arrays(float, (3, 3), elements=st.floats(-1.0, 1.0)),
    st.floats(-1.0, 1.0),
)
def test_the_structure_matrix_and_cross_are_np_cross_s_arithmetic(anchors, points, batch, angles, scale):
    """structure_matrix with planbench.planners.legs.cross: the same matrix, to the bit and in the same
    memory layout (its transpose feeds matmul), for one pose and for a batch; cross itself
    against np.cross."""
    from scipy.spatial.transform import Rotation

    rotations = Rotation.from_rotvec(angles * scale).as_matrix()
    positions = anchors[:3] * 0.5 + 1.0 + angles
    for position, rotation in ((positions[0], rotations[0]), (positions[:batch], rotations[:batch])):
        ours = structure_matrix(anchors, points, position, rotation)
        theirs = _structure_matrix_with_np_cross(anchors, points, position, rotation)
        np.testing.assert_array_equal(ours, theirs)
        assert ours.strides == theirs.strides and ours.shape == theirs.shape
    np.testing.assert_array_equal(cross(anchors, points), np.cross(anchors, points))
    np.testing.assert_array_equal(cross(anchors[None], points[:1]), np.cross(anchors[None], points[:1]))


def test_the_chain_loads_write_through_views_what_they_wrote_by_index():
    """ChainCableLoads with its views (the runs of FastPhysics' indices) and with them off
    (indexing, as before): after ticks of winch commands moving and wind, the same actuator
    laws, spring rest lengths, stiffnesses and dampings, node and anchor masses, node damping,
    applied forces and tensions, to the bit."""
    from planbench.fast import ChainCableLoads, FastPhysics

    times = np.arange(40) * 0.02
    runs = []
    for views in (True, False):
        physics = FastPhysics.load(2)
        loads = ChainCableLoads(wind_speed=6.0)
        data, model = physics.data.ptr, physics.model.ptr
        loads.reset(physics, times, np.random.default_rng(3))
        if not views:
            loads._passive_rest = loads._first_lengths = loads._node_xfrc = None
            loads._node_force = np.empty_like(loads._node_drag)
            loads._node_mass_view = loads._node_damping_view = loads._anchor_mass_view = loads._law_views = None
            loads._ropes, loads._rope_ctrl = physics.cable_ids, None
        else:
            assert loads._law_views is not None and loads._node_xfrc is not None
            assert loads._passive_rest is not None and loads._node_mass_view is not None
        start = data.ctrl[physics.cable_ids].copy()
        for tick in range(times.size):
            data.ctrl[physics.cable_ids] = start + 1e-3 * tick * np.arange(1, 7)
            loads(tick, physics)
            mujoco.mj_step(model, data, nstep=10)
        runs.append(
            [
                model.actuator_gainprm[:, :3].copy(),
                model.actuator_biasprm[:, :3].copy(),
                model.tendon_lengthspring.copy(),
                model.tendon_stiffness.copy(),
                model.tendon_damping.copy(),
                model.body_mass.copy(),
                model.dof_damping.copy(),
                data.xfrc_applied.copy(),
                loads.log(times.size).column("tension"),
                loads.log(times.size).column("force"),
                data.qpos.copy(),
            ]
        )
    for ours, theirs in zip(*runs, strict=True):
        np.testing.assert_array_equal(ours, theirs)


def _vectorized_correct(f: FusedPoses, body: int, measured: np.ndarray, at_tick: int) -> None:
    """A fix's correction on numpy arrays (the earlier implementation): the fit by
    small_rotation_fit in the world frame, K y, then Phi^k of it."""
    from planbench.fast.measurement import BA, BG, TH, P, V, _orthonormal, small_rotation_fit
    from planbench.planners.rotations import skew

    samples = f._samples[body]
    _, position, estimated = samples.popleft()
    position, estimated = np.array(position), np.array(estimated).reshape(3, 3)
    centre = measured.mean(axis=0)
    theta = small_rotation_fit(
        measured - centre, f._local_points[body] @ estimated.T, estimated @ f._inverse_inertia[body] @ estimated.T
    )
    imu_fix = centre + (np.eye(3) + skew(theta)) @ (estimated @ f._local_imu[body])
    dx = f.gains[body] @ np.concatenate([imu_fix - position, theta])
    for k, (tick, later_position, later_rotation) in enumerate(samples):
        later = f._powers[tick - at_tick] @ dx
        turned = (np.eye(3) + skew(later[TH])) @ np.array(later_rotation).reshape(3, 3)
        samples[k] = (tick, (np.array(later_position) + later[P]).tolist(), turned.ravel().tolist())
    now = f._powers[f.tick - at_tick] @ dx
    f._position[body] = (np.array(f._position[body]) + now[P]).tolist()
    f._velocity[body] = (np.array(f._velocity[body]) + now[V]).tolist()
    rotation = _orthonormal((np.eye(3) + skew(now[TH])) @ np.array(f._rotation[body]).reshape(3, 3))
    f._rotation[body] = rotation.ravel().tolist()
    f._accel_bias[body] = (np.array(f._accel_bias[body]) + rotation.T @ now[BA]).tolist()
    f._gyro_bias[body] = (np.array(f._gyro_bias[body]) + rotation.T @ now[BG]).tolist()


@settings(max_examples=80, deadline=None)
@given(
    arrays(float, (2, 3), elements=st.floats(-3.0, 3.0)),
    arrays(float, (2, 3), elements=st.floats(-300.0, 300.0)),
    st.lists(st.tuples(vectors, arrays(float, (2, 3), elements=st.floats(-0.5, 0.5))), min_size=1, max_size=6),
    arrays(float, (3, 3), elements=st.floats(-0.05, 0.05)),
    st.integers(0, 1),
    st.integers(1, 3),
)
def test_the_scalar_fix_correction_is_the_vectorized_one(angles, positions, readings, errors, body, pending):
    """A fix of a body's points (its estimate's points moved by up to 5 cm) taken some ticks
    ago, with later fixes still pending: the corrected estimates (position, velocity,
    rotation, biases) and the kept samples as the numpy form gives them, to round-off (1e-12
    of each quantity's scale: the scalar fit and Phi^k K y sum in another order)."""
    import copy

    from scipy.spatial.transform import Rotation

    offsets = np.array([[0.3, -1.2, 2.5], [-0.7, 0.4, -1.9]])
    rotations = Rotation.from_rotvec(angles).as_matrix()
    f = _filters(offsets)
    f.reset(positions, rotations)
    for k, (force, rate) in enumerate(readings):  # samples at the first ticks, the fix of the first
        if k < pending:
            f.sample(body)
        f.propagate(force, rate)
    if len(readings) < pending:
        f.sample(body)
    measured = positions[body] + f.points[body] @ rotations[body].T + errors
    reference = copy.deepcopy(f)
    f.correct(body, measured, 0)
    _vectorized_correct(reference, body, measured, 0)
    for name, scale in (
        ("position", 400.0),
        ("velocity", 20.0),
        ("rotation", 1.0),
        ("accel_bias", 1.0),
        ("gyro_bias", 1.0),
    ):
        np.testing.assert_allclose(
            getattr(f, name), getattr(reference, name), rtol=0.0, atol=1e-12 * scale, err_msg=name
        )
    assert len(f._samples[body]) == len(reference._samples[body])
    for (tick, position, rotation), (tick_ref, position_ref, rotation_ref) in zip(
        f._samples[body], reference._samples[body], strict=True
    ):
        assert tick == tick_ref
        np.testing.assert_allclose(position, position_ref, rtol=0.0, atol=400e-12)
        np.testing.assert_allclose(rotation, rotation_ref, rtol=0.0, atol=1e-12)
