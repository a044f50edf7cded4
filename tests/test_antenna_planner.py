"""The ship antenna planner (planners/antenna/__init__.py, planners/antenna/geostationary.py) against the
paper's equations (corrected per REFERENCE.md), scipy/numpy equivalents and its simulation
conditions (section 5.1: dT = 0.01 s, eq. 15-16)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from planbench.antenna.ship_motion import PaperShipMotion
from planbench.planners import antenna as ant
from planbench.planners.antenna.geostationary import look_angles
from planbench.planners.errors import LimitError, PlanningError

DEG = np.pi / 180
angles = st.floats(-np.pi, np.pi, allow_nan=False)
joint_angles = st.lists(st.floats(-3.5, 3.5, allow_nan=False), min_size=4, max_size=4).map(np.array)


def paper_attitudes(duration: float = 60.0, elevation_deg: float | None = None):
    """N(t_n) for the paper's ship motion (eq. 15-16) and satellite, at dT = 0.01 s."""
    t = np.arange(int(round(duration / ant.PAPER_DT)) + 1) * ant.PAPER_DT
    ship = PaperShipMotion().sample(t)
    az, el, pol = np.radians(ant.PAPER_SATELLITE_DEG)
    if elevation_deg is not None:
        el = np.radians(elevation_deg)
    return t, ant.desired_attitude(ship.heading, ship.pitch, ship.roll, az, el, pol)


@pytest.fixture(scope="module")
def paper_paths():
    t, attitudes = paper_attitudes()
    theta0 = np.radians(ant.PAPER_THETA0_DEG)
    return {m: ant.solve_joint_path(attitudes, ant.PAPER_DT, theta0, m) for m in ant.METHODS}


# ---------------------------------------------------------------------------- eq. (1)


@given(angles, st.floats(-1.5, 1.5), angles)
def test_corrected_eq1_is_a_rotation_with_the_boresight_as_third_column(az, el, pol):
    m = ant.satellite_attitude(az, el, pol)
    np.testing.assert_allclose(m @ m.T, np.eye(3), atol=1e-14)
    assert np.linalg.det(m) == pytest.approx(1.0, abs=1e-14)
    boresight = [np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.sin(el)]
    np.testing.assert_allclose(m[:, 2], boresight, atol=1e-15)
    # It factors as Rz(-Az) Rx(El) C0 Rz(sigma): pointing, then a twist about the boresight.
    np.testing.assert_allclose(m, ant.rot_z(-az) @ ant.rot_x(el) @ ant.C0 @ ant.rot_z(pol), atol=1e-14)


def test_printed_eq1_is_not_a_rotation():
    """The erratum is real: with CE_e in (1,1) and (1,2) the matrix is not orthonormal."""
    az, el, pol = np.radians(ant.PAPER_SATELLITE_DEG)
    printed = ant.satellite_attitude(az, el, pol)
    ce, se, sa, cs, ss = np.cos(el), np.sin(el), np.sin(az), np.cos(pol), np.sin(pol)
    printed[0, 0] = ce * ss - cs * sa * se
    printed[0, 1] = ce * cs + sa * se * ss
    assert np.abs(printed @ printed.T - np.eye(3)).max() > 0.1


@given(angles, st.floats(-1.5, 1.5), angles)
def test_ship_attitude_is_the_transpose_of_intrinsic_zxy_euler(heading, pitch, roll):
    expected = Rotation.from_euler("ZXY", [heading, pitch, roll]).as_matrix().T
    np.testing.assert_allclose(ant.ship_attitude(heading, pitch, roll), expected, atol=1e-14)


def test_paper_theta0_gives_the_satellite_attitude_on_a_level_ship():
    """f(Theta0) = N(0) at zero ship motion (eq. 2 and 15)."""
    az, el, pol = np.radians(ant.PAPER_SATELLITE_DEG)
    n0 = ant.desired_attitude(0.0, 0.0, 0.0, az, el, pol)
    theta0 = np.radians(ant.PAPER_THETA0_DEG)
    assert ant.frobenius_error(ant.forward_kinematics(theta0), n0) < 1e-15
    np.testing.assert_allclose(ant.joint_angles_at_rest(az, el, pol), theta0, atol=1e-12)
    # Tilting the ship breaks it: the check is not vacuous.
    n_rolled = ant.desired_attitude(0.0, 0.0, 0.1, az, el, pol)
    assert ant.frobenius_error(ant.forward_kinematics(theta0), n_rolled) > 0.1


@given(joint_angles)
def test_forward_kinematics_is_the_product_of_the_axis_rotations(theta):
    t1, t2, t3, t4 = theta
    expected = ant.rot_z(t1) @ ant.rot_x(-t2) @ ant.rot_z(t3) @ ant.C0 @ ant.rot_z(t4)
    np.testing.assert_allclose(ant.forward_kinematics(theta), expected, atol=1e-14)
    batch = ant.forward_kinematics(np.stack([theta, theta + 0.1]))
    np.testing.assert_allclose(batch[0], expected, atol=1e-14)


@given(joint_angles)
def test_jacobian_equals_finite_differences_of_f(theta):
    h = 1e-6
    f0 = ant.forward_kinematics(theta)
    columns = []
    for i in range(4):
        step = np.zeros(4)
        step[i] = h
        plus = ant.forward_kinematics(theta + step) @ f0.T
        minus = ant.forward_kinematics(theta - step) @ f0.T
        columns.append((ant.rotation_log(plus) - ant.rotation_log(minus)) / (2 * h))
    np.testing.assert_allclose(ant.jacobian(theta), np.stack(columns, 1), atol=1e-8)
    np.testing.assert_allclose(ant.jacobian(np.stack([theta]))[0], ant.jacobian(theta), atol=1e-15)


@given(st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3).map(np.array))
def test_rotation_log_equals_scipy(rotvec):
    m = Rotation.from_rotvec(rotvec).as_matrix()
    np.testing.assert_allclose(ant.rotation_log(m), Rotation.from_matrix(m).as_rotvec(), atol=1e-9)


# ---------------------------------------------------------------------------- eq. (6)


@given(st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3).map(np.array), joint_angles)
def test_angular_velocity_eq6_is_first_order_and_the_log_is_exact(omega, theta):
    dt = 0.02
    n0 = ant.forward_kinematics(theta)
    n1 = Rotation.from_rotvec(omega * dt).as_matrix() @ n0
    np.testing.assert_allclose(ant.angular_velocity_log(n0, n1, dt), omega, atol=1e-12)
    # eq. (6) reads the antisymmetric part: sin(|w| dt) / (|w| dt) of the truth.
    angle = np.linalg.norm(omega) * dt
    eq6 = ant.angular_velocity_eq6(n0, n1, dt)
    np.testing.assert_allclose(eq6, omega * np.sinc(angle / np.pi), atol=1e-12)


# ---------------------------------------------------------------------------- eq. (7)


@given(
    joint_angles,
    st.lists(st.floats(0.1, 20.0), min_size=4, max_size=4).map(np.array),
    st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3).map(np.array),
)
def test_weighted_pseudo_inverse_is_the_weighted_minimum_norm_least_squares(theta, weights, omega):
    jac = ant.jacobian(theta)
    if ant.weighted_singular_value(jac, weights) < 1e-3:
        return  # near a singularity both are ill-conditioned
    rates = ant.weighted_pseudo_inverse(jac, weights) @ omega
    scale = 1.0 / np.sqrt(weights)
    reference = scale * np.linalg.lstsq(jac * scale, omega, rcond=None)[0]
    np.testing.assert_allclose(rates, reference, atol=1e-9)
    np.testing.assert_allclose(jac @ rates, omega, atol=1e-10)


def test_paper_weights_move_the_cheap_axes_most():
    theta = np.radians(ant.PAPER_THETA0_DEG)
    jac = ant.jacobian(theta)
    plain = ant.weighted_pseudo_inverse(jac, np.ones(4)) @ [0, 0, 1.0]
    weighted = ant.weighted_pseudo_inverse(jac) @ [0, 0, 1.0]
    assert abs(weighted[0]) < abs(plain[0])  # azimuth (w = 10) moves less
    assert abs(weighted[3]) > abs(plain[3])  # polarization (w = 1) takes it over


# ------------------------------------------------------------- joint positions (sec. 4-5)


def test_pseudo_inverse_integration_drifts(paper_paths):
    """Section 5.2 / Figure 4: open-loop integration accumulates attitude error."""
    error = paper_paths["pinv"].error_fro
    at_6s, at_60s = error[600], error[-1]
    assert at_60s > 1e-3
    assert at_60s > 3 * at_6s
    # Monotone on average: the last 10 s are worse than the first 10 s.
    assert error[-1000:].mean() > 3 * error[:1000].mean()


def test_crr_holds_the_attitude_below_1e_6(paper_paths):
    """Section 4.2 / Figure 7."""
    path = paper_paths["crr"]
    assert path.error_fro.max() < 1e-6
    assert path.iterations[1:].min() >= 1 and path.iterations.max() <= 5
    assert np.isfinite(path.theta).all()


def test_full_correction_reaches_machine_precision(paper_paths):
    assert paper_paths["crr-full"].error_fro.max() < 1e-10


def test_crr_increment_keeps_the_rk4_rotation_ratio():
    """Eq. (12)-(14): DeltaTheta is parallel to the RK4 average of the eq. (9) rates."""
    t, attitudes = paper_attitudes(0.05)
    theta0 = np.radians(ant.PAPER_THETA0_DEG)
    new, info = ant.crr_step(theta0, attitudes[0], attitudes[1], ant.PAPER_DT)
    omega = ant.angular_velocity_eq6(attitudes[0], attitudes[1], ant.PAPER_DT)

    def rate(th):
        return ant.joint_rates(th, omega)[0]

    dt = ant.PAPER_DT
    k1 = rate(theta0)
    k2 = rate(theta0 + dt / 2 * k1)
    k3 = rate(theta0 + dt / 2 * k2)
    k4 = rate(theta0 + dt * k3)
    average = (k1 + 2 * k2 + 2 * k3 + k4) / 6
    delta = new - theta0
    cosine = delta @ average / (np.linalg.norm(delta) * np.linalg.norm(average))
    assert cosine == pytest.approx(1.0, abs=1e-14)
    assert info.error_fro < 1e-9


def test_crr_with_the_exact_angular_velocity_is_more_accurate():
    t, attitudes = paper_attitudes(10.0)
    theta0 = np.radians(ant.PAPER_THETA0_DEG)
    eq6 = ant.solve_joint_path(attitudes, ant.PAPER_DT, theta0, "crr", omega_method="eq6")
    log = ant.solve_joint_path(attitudes, ant.PAPER_DT, theta0, "crr", omega_method="log")
    assert log.error_fro.max() < eq6.error_fro.max() / 100


def test_joint_path_trajectory_interpolates_the_solution(paper_paths):
    path = paper_paths["crr"]
    trajectory = ant.JointPathTrajectory(path)
    sample = trajectory.sample(path.t[::50])
    np.testing.assert_allclose(sample.position, path.theta[::50], atol=1e-12)
    mid = trajectory.sample(path.t[1:60] - ant.PAPER_DT / 2)
    np.testing.assert_allclose(mid.velocity, path.rates()[:59], rtol=1e-3, atol=1e-6)


# ---------------------------------------------------------------------- singularities


def test_exact_singularity_is_damped_and_bounded():
    """theta2 = 0, theta3 = 90 deg: axes 1 and 3 and axes 2 and 4 coincide (rank 2)."""
    theta = np.array([0.3, 0.0, np.pi / 2, 0.2])
    jac = ant.jacobian(theta)
    assert ant.weighted_singular_value(jac) < 1e-12
    lost = np.cross(jac[:, 0], jac[:, 1])  # the direction no joint can turn about
    lost /= np.linalg.norm(lost)
    omega = 0.2 * lost + 0.1 * jac[:, 0]
    limits = ant.AntennaLimits(rate=np.full(4, np.radians(60.0)))
    rates, damped, limited = ant.joint_rates(theta, omega, limits=limits)
    assert damped and np.isfinite(rates).all()
    assert np.all(np.abs(rates) <= limits.rate * (1 + 1e-12))
    # The motion the axes can make is made (damping costs a little of it); the lost
    # component cannot be, by any rates.
    reachable = omega - (omega @ lost) * lost
    np.testing.assert_allclose(jac @ rates, reachable, atol=0.02 * np.linalg.norm(reachable))


def test_near_zenith_the_redundant_axis_keeps_rates_bounded():
    """The keyhole: as the satellite nears the deck's zenith, azimuth and polarization align.

    A 3-axis az-el-pol mount (cross-elevation locked) needs an azimuth rate that grows like
    1/cos(El) to follow a sideways motion of the satellite; the 4-axis weighted solution
    gives the motion to the cross-elevation axis and stays bounded.
    """
    omega = np.array([1.0, 0.0, 0.0]) * np.radians(10.0)  # pitching, sideways to the beam
    rates_4, rates_3 = [], []
    for el_deg in (80.0, 89.0, 89.9, 89.99):
        theta = np.array([np.pi / 2, -np.radians(el_deg), 0.0, 0.0])  # boresight along y-z
        jac = ant.jacobian(theta)
        rates_4.append(np.abs(ant.weighted_pseudo_inverse(jac) @ omega).max())
        three = jac[:, [0, 1, 3]]
        rates_3.append(np.abs(np.linalg.solve(three, omega)).max())
    assert max(rates_4) < np.radians(15.0)
    assert rates_3[-1] > 100 * rates_3[0]


def test_crr_through_the_zenith_stays_finite_and_within_rate_limits():
    """The paper's ship motion with the satellite at 89.5 deg: the boresight sweeps across
    the deck's zenith; with limits the solution stays finite and inside the rates."""
    t, attitudes = paper_attitudes(20.0, elevation_deg=89.5)
    theta0 = ant.joint_angles_at_rest(np.radians(223.49), np.radians(89.5), np.radians(-28.8))
    limits = ant.AntennaLimits(rate=np.radians([60.0, 60.0, 60.0, 90.0]))
    path = ant.solve_joint_path(attitudes, ant.PAPER_DT, theta0, "crr", limits=limits)
    assert np.isfinite(path.theta).all()
    assert np.all(np.abs(path.rates()) <= limits.rate * (1 + 1e-9))
    assert path.error_fro.max() < 1e-3


# ---------------------------------------------------------------------------- bad input


def test_bad_input_is_named():
    t, attitudes = paper_attitudes(0.05)
    theta0 = np.radians(ant.PAPER_THETA0_DEG)
    with pytest.raises(PlanningError, match="method 'newton'"):
        ant.solve_joint_path(attitudes, 0.01, theta0, "newton")
    with pytest.raises(PlanningError, match="dt = 0"):
        ant.solve_joint_path(attitudes, 0.0, theta0)
    bad = attitudes.copy()
    bad[2, 0, 0] = np.nan
    with pytest.raises(PlanningError, match="NaN"):
        ant.solve_joint_path(bad, 0.01, theta0)
    with pytest.raises(PlanningError, match=r"shape \(n, 3, 3\)"):
        ant.solve_joint_path(attitudes[:, :2], 0.01, theta0)
    with pytest.raises(PlanningError, match="Theta0"):
        ant.solve_joint_path(attitudes, 0.01, theta0[:3])
    limits = ant.AntennaLimits(rate=np.radians([60.0, 60.0, 60.0, 90.0]))
    with pytest.raises(LimitError, match="elevation rate 70.00 deg/s is beyond its limit 60.00 deg/s"):
        ant.check_rates(np.radians([[0.0, 70.0, 0.0, 0.0]]), limits)


# -------------------------------------------------------------------- geostationary


SITES = [(40, -20, -15), (19.2, 0, -17.34), (-30, 10, 30), (45, 0, 0), (10, 100, 90), (-60, -70, -100)]


def _spherical_formulas(lat, lon, sat):
    """Maral & Bousquet, spherical Earth: cos(gamma) = cos(lat) cos(dLambda) gives the
    elevation; azimuth by spherical trigonometry; skew tan(psi) = sin(dLambda) / tan(lat)."""
    dl, la = (sat - lon) * DEG, lat * DEG
    cos_gamma = np.cos(la) * np.cos(dl)
    gamma = np.arccos(cos_gamma)
    elevation = np.arctan((cos_gamma - 6378137.0 / 42164172.0) / np.sin(gamma))
    azimuth = np.arctan2(np.sin(dl), -np.sin(la) * np.cos(dl)) % (2 * np.pi)
    return azimuth, elevation, np.arctan(np.sin(dl) / np.tan(la))


@pytest.mark.parametrize("lat, lon, sat", SITES)
def test_look_angles_on_a_sphere_equal_the_spherical_formulas(lat, lon, sat, monkeypatch):
    import erfa

    def sphere(n, lon_, lat_, h):
        return 6378137.0 * np.array([np.cos(lat_) * np.cos(lon_), np.cos(lat_) * np.sin(lon_), np.sin(lat_)])

    monkeypatch.setattr(erfa, "gd2gc", sphere)
    az, el, pol = look_angles(sat * DEG, lat * DEG, lon * DEG)
    az_s, el_s, skew = _spherical_formulas(lat, lon, sat)
    assert el == pytest.approx(el_s, abs=1e-12)
    assert az == pytest.approx(az_s, abs=1e-12)
    # The skew formula leaves out the parallax between the ship and the Earth's centre
    # as seen from the satellite: a few tenths of a degree at most.
    assert pol == pytest.approx(-skew, abs=0.2 * DEG)


@pytest.mark.parametrize("lat, lon, sat", SITES)
def test_look_angles_on_wgs84(lat, lon, sat):
    """WGS84 versus a sphere moves the angles by a few hundredths of a degree; the
    polarization axis Y_s of eq. (1) lies along the received E-field."""
    az, el, pol = look_angles(sat * DEG, lat * DEG, lon * DEG)
    az_s, el_s, skew = _spherical_formulas(lat, lon, sat)
    assert el == pytest.approx(el_s, abs=0.05 * DEG)
    assert az == pytest.approx(az_s, abs=0.05 * DEG)
    assert pol == pytest.approx(-skew, abs=0.3 * DEG)
    frame = ant.satellite_attitude(az, el, pol)
    lat_r, lon_r, sat_r = lat * DEG, lon * DEG, sat * DEG
    east = np.array([-np.sin(lon_r), np.cos(lon_r), 0.0])
    north = np.array([-np.sin(lat_r) * np.cos(lon_r), -np.sin(lat_r) * np.sin(lon_r), np.cos(lat_r)])
    up = np.cross(east, north)
    field_ecef = np.array([-np.sin(sat_r), np.cos(sat_r), 0.0])  # horizontal polarization
    field = np.array([east @ field_ecef, north @ field_ecef, up @ field_ecef])
    field -= (field @ frame[:, 2]) * frame[:, 2]
    assert abs(frame[:, 1] @ field) / np.linalg.norm(field) == pytest.approx(1.0, abs=1e-12)


def test_vertical_polarization_is_90_deg_from_horizontal():
    h = look_angles(-15 * DEG, 40 * DEG, -20 * DEG, polarization="horizontal")[2]
    v = look_angles(-15 * DEG, 40 * DEG, -20 * DEG, polarization="vertical")[2]
    # Both E-fields are perpendicular to the satellite's nadir, not to the slant path to
    # the ship, so their projections on the aperture are 90 deg apart only to ~0.1 deg.
    assert abs(abs(v - h) - np.pi / 2) < 0.1 * DEG
    assert abs(abs(v - h) - np.pi / 2) > 1e-6


def test_satellite_below_the_horizon_is_a_limit_error():
    with pytest.raises(LimitError, match="below the horizon"):
        look_angles(100 * DEG, 40 * DEG, -20 * DEG)
    with pytest.raises(PlanningError, match="latitude"):
        look_angles(0.0, 2.0, 0.0)
    with pytest.raises(PlanningError, match="polarization 'circular'"):
        look_angles(0.0, 0.5, 0.0, polarization="circular")


@settings(max_examples=60, deadline=None)
@given(joint_angles, st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3).map(np.array), st.floats(0.005, 0.05))
def test_crr_step_properties(theta, omega, dt):
    """One update from an exact attitude: CRR leaves a residual of higher order in the step
    (only a 1-D family of increments is searched), the full correction none; eq. (6) loses
    to the exact angular velocity."""
    jac = ant.jacobian(theta)
    if ant.weighted_singular_value(jac) < 0.2:
        return  # near the singular set the first-order increments are ill-conditioned
    n0 = ant.forward_kinematics(theta)
    n1 = Rotation.from_rotvec(omega * dt).as_matrix() @ n0
    step = np.linalg.norm(omega) * dt  # rad
    _, log = ant.crr_step(theta, n0, n1, dt, omega_method="log")
    _, eq6 = ant.crr_step(theta, n0, n1, dt, omega_method="eq6")
    _, full = ant.crr_step(theta, n0, n1, dt, full_correction=True)
    assert log.error_fro <= 2e-3 * step**2 + 1e-14
    assert eq6.error_fro <= 0.2 * step**3 + 2e-3 * step**2 + 1e-14
    assert full.error_fro < 1e-13
    # Without an update the error would be the whole step: ||R - I||_F = 2 sqrt(2) sin(a / 2).
    assert log.error_fro < 2e-3 * 2 * np.sqrt(2) * np.sin(step / 2) + 1e-14


# ------------------------------------------------------- the one-pose fast path (floats)

rotvecs = st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3).map(np.array)
limit_sets = st.one_of(
    st.none(), st.lists(st.floats(0.05, 2.0), min_size=4, max_size=4).map(lambda r: ant.AntennaLimits(rate=np.array(r)))
)
weight_sets = st.lists(st.floats(0.5, 20.0), min_size=4, max_size=4).map(np.array)


@given(joint_angles)
def test_scalar_kinematics_are_those_of_the_vectorized_functions(theta):
    """Eq. (2) and (4) in floats: the same arithmetic as the (4,) path, to the bit."""
    np.testing.assert_array_equal(np.reshape(ant._fk_floats(*theta), (3, 3)), ant.forward_kinematics(theta))
    np.testing.assert_array_equal(np.array(ant._jacobian_rows(*theta[:3])), ant.jacobian(theta))
    a, b = ant.forward_kinematics(theta), ant.forward_kinematics(theta[::-1])
    np.testing.assert_allclose(
        np.reshape(ant._relative_floats(a.ravel(), b.ravel()), (3, 3)), a @ b.T, rtol=0, atol=1e-15
    )


@given(st.one_of(rotvecs, rotvecs.map(lambda v: v * 1e-5), rotvecs.map(lambda v: v * 1.8)))
def test_scalar_rotation_log_equals_rotation_log(rotvec):
    r = Rotation.from_rotvec(rotvec).as_matrix()
    expected = ant.rotation_log(r)
    np.testing.assert_allclose(
        ant._log_floats(r.ravel().tolist()), expected, rtol=0, atol=1e-14 * np.linalg.norm(expected) + 1e-300
    )


def test_scalar_rotation_log_refuses_a_half_turn():
    r = Rotation.from_rotvec([0.0, np.pi - 1e-7, 0.0]).as_matrix()
    with pytest.raises(PlanningError, match="too close to 180 deg"):
        ant._log_floats(r.ravel().tolist())


def _worst_condition(theta, omega, weights, limits) -> float:
    """How much ``joint_rates`` may amplify round-off: the condition number of J W^-1 J^T,
    or with the safeguards, the product of those of the systems solved (damped, and with
    each round of rate-aware weights: a round's weights come from the last round's rates, so
    their errors compound)."""
    jac = ant.jacobian(theta)
    w_inv = 1.0 / weights
    gram = (jac * w_inv) @ jac.T
    conditions = [np.linalg.cond(gram)]
    if limits is not None:
        damping = ant._damping(gram, limits)
        for _ in range(5):
            system = (jac * w_inv) @ jac.T + damping**2 * np.eye(3)
            conditions.append(np.linalg.cond(system))
            rates = (jac * w_inv).T @ np.linalg.solve(system, omega)
            ratio = np.abs(rates) / limits.rate
            if ratio.max() <= 1.0:
                break
            w_inv = w_inv / np.maximum(ratio, 1.0) ** 2
    return conditions[0] if limits is None else float(np.prod(conditions[1:]))


@settings(max_examples=300, deadline=None)
@given(joint_angles, rotvecs, weight_sets, limit_sets)
def test_scalar_joint_rates_equal_joint_rates(theta, omega, weights, limits):
    """Eq. (7)/(9) with the safeguards (damping, rate-aware weights, scaling) in floats:
    the rates to round-off (relative to the system's condition) and the same flags."""
    jac = ant.jacobian(theta)
    if limits is None and ant.weighted_singular_value(jac, weights) < 1e-3:
        return  # undamped near the singular set the solution itself is ill-conditioned
    try:
        expected, damped, limited = ant.joint_rates(theta, omega, weights, limits)
    except ant.SingularityError:
        with pytest.raises(ant.SingularityError):
            ant.joint_rates_scalar(theta, omega, weights, limits)
        return
    rates, damped_f, limited_f = ant.joint_rates_scalar(theta, omega, weights, limits)
    scale = np.abs(expected).max() + np.linalg.norm(omega)
    tolerance = 1e-14 * _worst_condition(theta, omega, weights, limits)
    np.testing.assert_allclose(rates, expected, rtol=0, atol=tolerance * scale + 1e-300)
    assert damped_f == damped
    if limited_f != limited:  # only where a rate is at its limit to round-off (ratio 1 +- 1e-12)
        assert np.abs(np.abs(expected) / limits.rate - 1.0).min() < 1e-12


@settings(max_examples=150, deadline=None)
@given(joint_angles, rotvecs, st.floats(0.005, 0.05), st.sampled_from(["eq6", "log"]), st.booleans(), st.booleans())
def test_scalar_crr_step_equals_crr_step(theta, omega, dt, omega_method, full_correction, limited):
    """One CRR update (eq. 6, 9, 11-14, 10, the cap and the full correction) in floats: the
    same angles to round-off, the same flags and residual."""
    if ant.weighted_singular_value(ant.jacobian(theta)) < 0.05:
        return  # near the singular set round-off is amplified by the solution itself
    limits = ant.AntennaLimits(rate=np.radians([60.0, 60.0, 60.0, 90.0])) if limited else None
    n0 = ant.forward_kinematics(theta)
    n1 = Rotation.from_rotvec(omega * dt).as_matrix() @ n0
    kwargs = dict(limits=limits, omega_method=omega_method, full_correction=full_correction)
    expected, info = ant.crr_step(theta, n0, n1, dt, **kwargs)
    new, info_f = ant.crr_step_scalar(theta, n0, n1, dt, **kwargs)
    np.testing.assert_allclose(new, expected, rtol=0, atol=1e-12)
    assert (info_f.damped, info_f.rate_limited) == (info.damped, info.rate_limited)
    # (Newton's stop rule, |step| dt < 1e-15, is a test at round-off: its count of
    # iterations may differ where the steps end in round-off; the paper path's test below
    # counts them.)
    assert info_f.error_fro == pytest.approx(info.error_fro, rel=1e-12, abs=1e-14)


@pytest.mark.parametrize("omega_method", ["eq6", "log"])
@pytest.mark.parametrize("limited", [False, True])
def test_scalar_crr_follows_the_paper_path(omega_method, limited):
    """Section 5.1 (eq. 15-16, dT = 0.01 s), 10 s: each update of the fast path from the
    vectorized path's angles, and the whole path from Theta0, agree to round-off."""
    t, attitudes = paper_attitudes(10.0)
    theta0 = np.radians(ant.PAPER_THETA0_DEG)
    limits = ant.AntennaLimits(rate=np.radians([60.0, 60.0, 60.0, 90.0])) if limited else None
    path = ant.solve_joint_path(attitudes, ant.PAPER_DT, theta0, "crr", limits=limits, omega_method=omega_method)
    iterations = []
    for i in range(t.size - 1):
        new, info = ant.crr_step_scalar(
            path.theta[i], attitudes[i], attitudes[i + 1], ant.PAPER_DT, limits=limits, omega_method=omega_method
        )
        np.testing.assert_allclose(new, path.theta[i + 1], rtol=0, atol=1e-14)
        iterations.append(info.iterations)
    # The Newton stop rule (a step under 1e-15 rad) sits at round-off: the two paths may stop
    # one iteration apart, never more (their angles agree to 1e-14 above).
    assert np.abs(np.array(iterations) - path.iterations[1:]).max() <= 1
    planner = ant.CrrPlanner(omega_method=omega_method)
    problem = ant.AntennaProblem(
        attitudes[0],
        0.0,
        0.0,
        0.0,
        theta0,
        limits if limits is not None else ant.AntennaLimits(),
        update_dt=ant.PAPER_DT,
    )
    planner.reset(problem)
    planner.attitude = attitudes[0]
    online = np.array([planner.step(ti, n) for ti, n in zip(t[1:], attitudes[1:], strict=True)])
    reference = ant.solve_joint_path(
        attitudes, ant.PAPER_DT, theta0, "crr", limits=problem.limits, omega_method=omega_method
    )
    np.testing.assert_allclose(online, reference.theta[1:], rtol=0, atol=1e-12)


def test_scalar_joint_rates_at_the_exact_singularity():
    """theta2 = 0, theta3 = 90 deg (rank 2): damped in both paths, the same rates."""
    theta = np.array([0.3, 0.0, np.pi / 2, 0.2])
    omega = np.array([0.05, -0.2, 0.1])
    limits = ant.AntennaLimits(rate=np.full(4, np.radians(60.0)))
    expected = ant.joint_rates(theta, omega, limits=limits)
    rates, damped, limited = ant.joint_rates_scalar(theta, omega, limits=limits)
    assert damped and expected[1]
    assert limited == expected[2]
    np.testing.assert_allclose(rates, expected[0], rtol=0, atol=1e-12)
    with pytest.raises(ant.SingularityError):
        ant.joint_rates_scalar(theta, omega)


def test_the_exact_singularity_with_no_damping_allowed_is_a_singularity_error(monkeypatch):
    """Limits whose max_damping is 0 give the solve nothing to damp with where J W^-1 J^T is
    exactly singular (the undamped solve raising LinAlgError, as it does at rank 2 in exact
    arithmetic): both paths raise SingularityError, not a TypeError from the missing solution."""
    theta = np.array([0.3, 0.0, np.pi / 2, 0.2])
    omega = np.array([0.05, -0.2, 0.1])
    limits = ant.AntennaLimits(rate=np.full(4, np.radians(60.0)), max_damping=0.0)

    def singular(solve):
        def solve_or_raise(*args, **kwargs):
            if not (args[3:] or kwargs.get("damping")):
                raise np.linalg.LinAlgError("singular matrix")
            return solve(*args, **kwargs)

        return solve_or_raise

    monkeypatch.setattr(ant, "_solve_rates", singular(ant._solve_rates))
    monkeypatch.setattr(ant, "_solve_floats", singular(ant._solve_floats))
    for rates in (ant.joint_rates, ant.joint_rates_scalar):
        with pytest.raises(ant.SingularityError, match="max_damping is 0"):
            rates(theta, omega, limits=limits)
