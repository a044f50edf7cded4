"""Ship-borne 4-axis satellite antenna: attitude chain, weighted pseudo-inverse and the
constant-rotation-ratio (CRR) joint-position algorithm.

Paper: Wu, Chen and Ding, "Joints position approach for satellite antenna attitude
stabilization system based on constant rotation ratio" (REFERENCE.md
"Papers", "the paper" below). Errata and conventions: REFERENCE.md,
"Ship antenna".

Frames and conventions
----------------------
* Earth frame e: East-North-Up. Ship (carrier) frame b: X to starboard, Y to the bow, Z up.
  Antenna frame a: Z_a the boresight (main lobe), Y_a the polarization direction.
* ``satellite_attitude`` is eTs of eq. (1) *corrected*: its printed first row begins two
  entries with cos E where cos A belongs (REFERENCE.md); corrected, eTs is orthonormal and
  its third column is the boresight (cos El sin Az, cos El cos Az, sin El). It factors as
  eTs = Rz(-Az) Rx(El) C0 Rz(sigma) with C0 = [[0,1,0],[0,0,1],[1,0,0]] (tested).
* ``ship_attitude`` is bTe of eq. (1): passive rotations, roll gamma about Y, pitch phi
  about X, heading psi about Z: bTe = Ry(gamma)^T Rx(phi)^T Rz(psi)^T. As printed, psi turns
  the bow counter-clockwise (from north toward west).
* N(t) = bTe eTs: the attitude the antenna frame must have in the ship frame (eq. 1).
* The 4-axis pedestal (four orthogonal axes meeting at one point, the paper's Figure 1):
  azimuth about the deck's Z, elevation about -X of the azimuth frame, cross-elevation about
  Z of the elevation frame, polarization about the boresight:

      f(Theta) = Rz(t1) Rx(-t2) Rz(t3) C0 Rz(t4)

  This is the chain the paper's Theta0 = [136.51, -60, 0, -28.8] deg implies (t1 = -Az,
  t2 = -El, t3 = 0, t4 = sigma; REFERENCE.md): f(Theta0) = N(0) at zero ship motion (tested).
  models/antenna/antenna.xml builds the same chain.
* Angular velocities are in the ship frame (N(t + dt) = Rot N(t), eq. 5 and 8, multiplies on
  the left); the Jacobian's columns are the four joint axes in the ship frame.

Equation (6) as printed divides the whole matrix, identity included, by dt; from its
definition (a differential rotation Rot = I + [w]x dt, second order dropped) it reads
[w]x dt = N(t + dt) N(t)^T - I. ``angular_velocity_eq6`` takes its antisymmetric part (the
symmetric part is the dropped second-order term); ``angular_velocity_log`` is the exact
constant-rate rotation, the matrix logarithm of N(t + dt) N(t)^T over dt.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicSpline

from planbench.planners.errors import LimitError, PlanningError
from planbench.planners.rotations import rot_x, rot_y, rot_z, vee
from planbench.planners.trajectory import TrajectorySample, sample_times

JOINT_LABELS = ("azimuth", "elevation", "cross_elevation", "polarization")
#: The paper's weights, eq. (7): motion of axis 1 costs most, axis 4 least.
PAPER_WEIGHTS = np.array([10.0, 5.0, 2.0, 1.0])
#: The paper's section 5.1: satellite azimuth, elevation, polarization (deg) and Theta0 (deg).
PAPER_SATELLITE_DEG = (223.49, 60.0, -28.8)
PAPER_THETA0_DEG = np.array([136.51, -60.0, 0.0, -28.8])
PAPER_DT = 0.01  # s, the simulation interval of section 5.1

#: Antenna axes at zero joint angles, as columns in the elevation frame: x_a up, y_a to
#: starboard, z_a (boresight) to the bow.
C0 = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])


class SingularityError(PlanningError):
    """The weighted Jacobian is singular and no damping was allowed."""


# --------------------------------------------------------------------------------------
# Rotations


def rotation_log(r) -> np.ndarray:
    """Rotation vector (axis x angle, rad) of rotation matrices r (..., 3, 3): the matrix log.

    Valid for angles below pi - 1e-6 (the attitude steps of a 20-100 Hz update are far
    smaller); equals scipy's ``Rotation.as_rotvec`` there (tested).
    """
    r = np.asarray(r, dtype=float)
    cos_angle = np.clip((np.trace(r, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    angle = np.arccos(cos_angle)
    if np.any(angle > np.pi - 1e-6):
        raise PlanningError(f"rotation of {np.degrees(angle.max()):.4f} deg is too close to 180 deg for its logarithm")
    v = vee(r)  # axis * sin(angle)
    small = angle < 1e-4
    # angle / sin(angle), with its series where sin(angle) is tiny.
    scale = np.where(small, 1.0 + angle**2 / 6.0 + 7.0 * angle**4 / 360.0, angle / np.where(small, 1.0, np.sin(angle)))
    return v * scale[..., None]


def frobenius_error(a, b) -> np.ndarray:
    """||a - b||_F per matrix: the paper's measure of attitude error (section 5.1)."""
    d = np.asarray(a) - np.asarray(b)
    return np.sqrt(np.einsum("...ij,...ij->...", d, d))


# --------------------------------------------------------------------------------------
# The attitude chain (paper, eq. 1)


def satellite_attitude(azimuth, elevation, polarization) -> np.ndarray:
    """eTs of eq. (1), corrected (REFERENCE.md): the satellite frame in East-North-Up.

    Args:
      azimuth: rad, clockwise from north (the paper's A_e).
      elevation: rad above the horizon (E_e).
      polarization: rad (sigma_e).
    Returns (..., 3, 3): columns X_s, Y_s (polarization), Z_s (the boresight toward the
    satellite) in East-North-Up.
    """
    a, e, s = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (azimuth, elevation, polarization)))
    ca, sa, ce, se, cs, ss = np.cos(a), np.sin(a), np.cos(e), np.sin(e), np.cos(s), np.sin(s)
    return np.stack(
        [
            # Row 1: the printed CE_e of (1,1) and (1,2) corrected to CA_e.
            np.stack([ca * ss - cs * sa * se, ca * cs + sa * se * ss, ce * sa], -1),
            np.stack([-sa * ss - ca * cs * se, -cs * sa + ca * se * ss, ca * ce], -1),
            np.stack([ce * cs, -ce * ss, se], -1),
        ],
        -2,
    )


def ship_attitude(heading, pitch, roll) -> np.ndarray:
    """bTe of eq. (1): Earth (ENU) coordinates to ship coordinates, (..., 3, 3).

    bTe = Ry(roll)^T Rx(pitch)^T Rz(heading)^T (the printed passive matrices); its transpose
    eTb = Rz(heading) Rx(pitch) Ry(roll) is the ship's attitude in the Earth frame.
    """
    return np.swapaxes(rot_z(heading) @ rot_x(pitch) @ rot_y(roll), -1, -2)


def desired_attitude(heading, pitch, roll, azimuth, elevation, polarization) -> np.ndarray:
    """N(t) = bTe eTs (eq. 1): the antenna attitude to hold, in the ship frame, (..., 3, 3)."""
    return ship_attitude(heading, pitch, roll) @ satellite_attitude(azimuth, elevation, polarization)


def forward_kinematics(theta) -> np.ndarray:
    """f(Theta) of eq. (2): the antenna frame in the ship frame, (..., 3, 3).

    f = Rz(t1) Rx(-t2) Rz(t3) C0 Rz(t4) for joint angles theta (..., 4) in rad, written out
    (a Z-X-Z product; C0 permutes its columns; Rz(t4) mixes the first two); tested against
    the product of the rotation matrices.
    """
    theta = np.asarray(theta, dtype=float)
    if theta.shape == (4,):  # one pose: plain floats are 10x faster than 0-d arrays
        c = [math.cos(v) for v in theta.tolist()]
        s = [math.sin(v) for v in theta.tolist()]
    else:
        c = np.moveaxis(np.cos(theta), -1, 0)
        s = np.moveaxis(np.sin(theta), -1, 0)
    c1, c2, c3, c4 = c
    s1, s2, s3, s4 = s
    m2 = (-s1 * s2, c1 * s2, c2)  # column 2 of M = Rz(t1) Rx(-t2) Rz(t3)
    if theta.shape == (4,):
        m0 = (c1 * c3 - s1 * c2 * s3, s1 * c3 + c1 * c2 * s3, -s2 * s3)
        m1 = (-c1 * s3 - s1 * c2 * c3, -s1 * s3 + c1 * c2 * c3, -s2 * c3)
        return np.array([[c4 * m2[r] + s4 * m0[r], -s4 * m2[r] + c4 * m0[r], m1[r]] for r in range(3)])
    m = np.empty(theta.shape[:-1] + (3, 3))
    # M = Rz(t1) Rx(-t2) Rz(t3); A = M C0 has columns (M_2, M_0, M_1).
    m0 = (c1 * c3 - s1 * c2 * s3, s1 * c3 + c1 * c2 * s3, -s2 * s3)  # M column 0
    m1 = (-c1 * s3 - s1 * c2 * c3, -s1 * s3 + c1 * c2 * c3, -s2 * c3)  # M column 1
    for row in range(3):
        m[..., row, 0] = c4 * m2[row] + s4 * m0[row]
        m[..., row, 1] = -s4 * m2[row] + c4 * m0[row]
        m[..., row, 2] = m1[row]
    return m


def jacobian(theta) -> np.ndarray:
    """J(Theta) of eq. (4), (..., 3, 4): the four joint axes in the ship frame.

    The antenna's angular velocity in the ship frame is J(Theta) dTheta/dt.
    """
    theta = np.asarray(theta, dtype=float)
    if theta.shape == (4,):
        c1, s1 = math.cos(theta[0]), math.sin(theta[0])
        c2, s2 = math.cos(theta[1]), math.sin(theta[1])
        a4 = forward_kinematics(theta)[:, 2]
        return np.array([[0.0, -c1, -s1 * s2, a4[0]], [0.0, -s1, c1 * s2, a4[1]], [1.0, 0.0, c2, a4[2]]])
    t1, t2 = theta[..., 0], theta[..., 1]
    c1, s1, c2, s2 = np.cos(t1), np.sin(t1), np.cos(t2), np.sin(t2)
    zero, one = np.zeros_like(c1), np.ones_like(c1)
    a1 = np.stack([zero, zero, one], -1)
    a2 = np.stack([-c1, -s1, zero], -1)  # Rz(t1) (-X)
    a3 = np.stack([-s1 * s2, c1 * s2, c2], -1)  # Rz(t1) Rx(-t2) Z
    a4 = forward_kinematics(theta)[..., :, 2]  # the boresight
    return np.stack([a1, a2, a3, a4], -1)


def joint_angles_at_rest(azimuth, elevation, polarization) -> np.ndarray:
    """Theta with f(Theta) = eTs on a level ship at heading 0: (-Az, -El, 0, sigma) (eq. 15).

    Azimuth is wrapped to (-180, 180] deg, so the paper's Az 223.49 deg gives 136.51 deg.
    """
    t1 = np.angle(np.exp(-1j * np.asarray(azimuth, dtype=float)))
    return np.stack(
        np.broadcast_arrays(t1, -np.asarray(elevation, dtype=float), 0.0 * t1, np.asarray(polarization, dtype=float)),
        -1,
    )


# --------------------------------------------------------------------------------------
# Angular velocity (eq. 6) and the weighted pseudo-inverse (eq. 7)


def angular_velocity_eq6(n_now, n_next, dt: float) -> np.ndarray:
    """Angular velocity (rad/s, ship frame) between two attitudes by eq. (6).

    From its definition: [w]x dt = N(t + dt) N(t)^T - I to first order; the antisymmetric
    part is read (the printed equation divides the identity by dt too: an erratum).
    """
    return vee(np.asarray(n_next) @ np.swapaxes(n_now, -1, -2)) / dt


def angular_velocity_log(n_now, n_next, dt: float) -> np.ndarray:
    """The constant angular velocity (rad/s, ship frame) that turns N(t) into N(t + dt)."""
    return rotation_log(np.asarray(n_next) @ np.swapaxes(n_now, -1, -2)) / dt


def weighted_pseudo_inverse(jac, weights=PAPER_WEIGHTS, damping: float = 0.0) -> np.ndarray:
    """W^-1 J^T (J W^-1 J^T + damping^2 I)^-1, (..., 4, 3) (eq. 7; damped when damping > 0).

    ``weights`` are the diagonal of W: the solution minimizes sum_i w_i thetadot_i^2 among
    the joint rates that give the angular velocity. Raises SingularityError when
    J W^-1 J^T is singular and damping is 0.
    """
    jac = np.asarray(jac, dtype=float)
    w_inv = 1.0 / np.asarray(weights, dtype=float)
    jw = jac * w_inv[..., None, :]
    gram = jw @ np.swapaxes(jac, -1, -2) + damping**2 * np.eye(3)
    try:
        return np.swapaxes(jw, -1, -2) @ np.linalg.inv(gram)
    except np.linalg.LinAlgError:
        raise SingularityError("J W^-1 J^T is singular: the four axes span less than 3 dimensions") from None


def weighted_singular_value(jac, weights=PAPER_WEIGHTS) -> np.ndarray:
    """Smallest singular value of J W^-1/2 (rad/s of antenna per unit weighted joint rate)."""
    jac = np.asarray(jac, dtype=float)
    return np.linalg.svd(jac / np.sqrt(np.asarray(weights, dtype=float)), compute_uv=False)[..., -1]


@dataclass(frozen=True)
class AntennaLimits:
    """What the joint-rate solution must respect.

    Attributes:
      rate: (4,) joint rate limits, rad/s.
      singular_threshold: below this smallest singular value of J W^-1/2 the solution is
        damped (Nakamura and Hanafusa's variable damping), rad/s per weighted rad/s.
      max_damping: damping at an exact singularity (same units).
    """

    rate: np.ndarray = field(default_factory=lambda: np.full(4, np.inf))
    singular_threshold: float = 0.05
    max_damping: float = 0.05


def _damping(gram: np.ndarray, limits: AntennaLimits) -> float:
    """Variable damping from the smallest eigenvalue of J W^-1 J^T (= sigma_min^2).

    The eigenvalues are only computed when the cheap bound lambda_min >= 4 det / trace^2
    (lambda_mid lambda_max <= (trace / 2)^2) cannot rule the singularity out.
    """
    threshold2 = limits.singular_threshold**2
    trace = gram[0, 0] + gram[1, 1] + gram[2, 2]
    if 4.0 * np.linalg.det(gram) >= threshold2 * trace * trace:
        return 0.0
    sigma2 = max(float(np.linalg.eigvalsh(gram)[0]), 0.0)
    if sigma2 >= threshold2:
        return 0.0
    return limits.max_damping * math.sqrt(1.0 - sigma2 / threshold2)


def _solve_rates(jac, w_inv, omega, damping: float = 0.0):
    """W^-1 J^T (J W^-1 J^T + damping^2 I)^-1 omega for one pose, and the undamped gram."""
    jw = jac * w_inv
    gram = jw @ jac.T
    system = gram + damping * damping * np.eye(3) if damping else gram
    return jw.T @ np.linalg.solve(system, omega), gram


def joint_rates(theta, omega, weights=PAPER_WEIGHTS, limits: AntennaLimits | None = None):
    """Joint rates for an antenna angular velocity (eq. 7/9), with the safeguards.

    Without ``limits``: exactly eq. (7). With ``limits``: damped near a singularity, and
    limit-aware: a joint whose rate would exceed its limit gets its weight raised by
    (rate / limit)^2 and the rates are solved again (up to 4 times; the other axes take the
    motion over), then, if still over, all rates are scaled down together (the direction is
    kept; the attitude then lags and the next updates catch up).
    Returns (rates (4,), damped: bool, rate_limited: bool).
    """
    jac = jacobian(theta)
    w_inv = 1.0 / np.asarray(weights, dtype=float)
    try:
        rates, gram = _solve_rates(jac, w_inv, omega)
    except np.linalg.LinAlgError:
        if limits is None:
            raise SingularityError("J W^-1 J^T is singular: the four axes span less than 3 dimensions") from None
        rates, gram = None, (jac * w_inv) @ jac.T
    if limits is None:
        return rates, False, False
    damping = _damping(gram, limits)
    if damping:
        rates = _solve_rates(jac, w_inv, omega, damping)[0]
    elif rates is None:  # singular, and limits whose max_damping is 0 allow no damping
        raise SingularityError("J W^-1 J^T is singular and the limits' max_damping is 0")
    limited = False
    for _ in range(4):
        ratio = np.abs(rates) / limits.rate
        if ratio.max() <= 1.0:
            break
        limited = True
        w_inv = w_inv / np.maximum(ratio, 1.0) ** 2
        rates = _solve_rates(jac, w_inv, omega, damping)[0]
    ratio = (np.abs(rates) / limits.rate).max()
    if ratio > 1.0:
        limited = True
        rates = rates / ratio
    return rates, damping > 0.0, limited


# --------------------------------------------------------------------------------------
# Joint positions: the baseline (section 5.2), CRR (section 4.2) and full correction


@dataclass
class StepInfo:
    """What one joint-position update did (for summaries and plots)."""

    error_fro: float = 0.0  # ||f(Theta_{n+1}) - N(t_{n+1})||_F
    iterations: int = 0  # Newton iterations
    damped: bool = False
    rate_limited: bool = False


def _angular_velocity(n_now, n_next, dt, method):
    if method == "eq6":
        return angular_velocity_eq6(n_now, n_next, dt)
    if method == "log":
        return angular_velocity_log(n_now, n_next, dt)
    raise PlanningError(f"angular velocity method {method!r} is not 'eq6' or 'log'")


def pinv_integration_step(theta, n_now, n_next, dt: float, weights=PAPER_WEIGHTS, omega_method: str = "eq6"):
    """The paper's baseline (section 5.2): Theta_{n+1} = Theta_n + Thetadot_n dt, eq. (6)-(7).

    Open-loop integration of the joint rates; its attitude error accumulates (Figure 4).
    Returns (Theta_{n+1}, StepInfo).
    """
    omega = _angular_velocity(n_now, n_next, dt, omega_method)
    rates, _, _ = joint_rates(theta, omega, weights)
    new = theta + rates * dt
    return new, StepInfo(float(frobenius_error(forward_kinematics(new), n_next)))


def crr_step(
    theta,
    n_now,
    n_next,
    dt: float,
    weights=PAPER_WEIGHTS,
    *,
    limits: AntennaLimits | None = None,
    omega_method: str = "eq6",
    full_correction: bool = False,
    tol: float = 1e-15,
    max_iter: int = 20,
):
    """One update of the constant-rotation-ratio algorithm (section 4.2, steps 3-7).

    Step 3: the average angular velocity over the update, eq. (6) (``omega_method="log"``:
    the exact one). Step 4: joint rates by the weighted pseudo-inverse, eq. (9). Step 5: RK4
    (eq. 11) of dTheta/dt = W^-1 J(Theta)^T (J W^-1 J^T)^-1 w over dt gives the average joint
    velocity K. Step 6: its direction k = K / |K| is the constant rotation ratio (eq. 12-14):
    DeltaTheta = k xi dt. Step 7: Newton's method for the base speed xi (starting at |K|) on
    f(Theta_n + k xi dt) = N(t_{n+1}) (eq. 10), in the least-squares sense: one scalar xi
    cannot match three rotation components exactly, so Gauss-Newton drives the rotation
    residual log(N f^T) orthogonal to J k; it stops when the xi step moves the joints less
    than ``tol`` rad.

    ``full_correction``: then Newton steps on the whole attitude with the weighted
    minimum-norm inverse, Theta += W^-1 J^T (J W^-1 J^T)^-1 log(N f^T), to machine precision.
    ``limits``: damping near singularities and rate limits (see ``joint_rates``); the
    increment is also capped at the rate limits.
    Returns (Theta_{n+1} (4,), StepInfo).
    """
    theta = np.asarray(theta, dtype=float)
    omega = _angular_velocity(n_now, n_next, dt, omega_method)
    info = StepInfo()

    def rate(th):
        r, damped, limited = joint_rates(th, omega, weights, limits)
        info.damped |= damped
        info.rate_limited |= limited
        return r

    k1 = rate(theta)
    k2 = rate(theta + 0.5 * dt * k1)
    k3 = rate(theta + 0.5 * dt * k2)
    k4 = rate(theta + dt * k3)
    average = (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0  # eq. (11)
    speed = float(np.linalg.norm(average))
    new = theta
    if speed > 0.0:
        ratio = average / speed  # k of eq. (12)-(14)
        xi = speed
        for iteration in range(1, max_iter + 1):
            new = theta + ratio * (xi * dt)
            residual = rotation_log(n_next @ forward_kinematics(new).T)
            slope = jacobian(new) @ ratio * dt  # d(rotation)/d(xi)
            step = float(slope @ residual / (slope @ slope))
            xi += step
            info.iterations = iteration
            if abs(step) * dt < tol:
                break
        if limits is not None:
            cap = float(np.min(limits.rate / np.maximum(np.abs(ratio), 1e-300)))
            if abs(xi) > cap:
                xi = np.sign(xi) * cap
                info.rate_limited = True
        new = theta + ratio * (xi * dt)
    if full_correction:
        w_corr = np.asarray(weights, dtype=float)
        for _ in range(max_iter):
            residual = rotation_log(n_next @ forward_kinematics(new).T)
            if np.abs(residual).max() < 1e-15:
                break
            jac = jacobian(new)
            damping = 0.0 if limits is None else _damping((jac / w_corr) @ jac.T, limits)
            new = new + _solve_rates(jac, 1.0 / w_corr, residual, damping)[0]
            info.iterations += 1
    info.error_fro = float(frobenius_error(forward_kinematics(new), n_next))
    return new, info


# --------------------------------------------------------------------------------------
# One pose in plain floats: the online planner's fast path
#
# The same equations as the functions above, written out for a single pose in Python floats
# (the math module), because numpy's per-call cost dominates on 3 x 3 and 3 x 4 matrices. The
# results agree with the vectorized functions to round-off (tested): the 3 x 3 solve is
# Cramer's rule, the sums run in another order than LAPACK's and BLAS's.


def _fk_floats(t1: float, t2: float, t3: float, t4: float) -> tuple:
    """f(Theta) of eq. (2) as 9 floats, row by row (``forward_kinematics``'s arithmetic)."""
    c1, s1 = math.cos(t1), math.sin(t1)
    c2, s2 = math.cos(t2), math.sin(t2)
    c3, s3 = math.cos(t3), math.sin(t3)
    c4, s4 = math.cos(t4), math.sin(t4)
    m20, m21, m22 = -s1 * s2, c1 * s2, c2  # column 2 of M = Rz(t1) Rx(-t2) Rz(t3)
    m00, m01, m02 = c1 * c3 - s1 * c2 * s3, s1 * c3 + c1 * c2 * s3, -s2 * s3  # column 0
    m10, m11, m12 = -c1 * s3 - s1 * c2 * c3, -s1 * s3 + c1 * c2 * c3, -s2 * c3  # column 1
    return (
        c4 * m20 + s4 * m00,
        -s4 * m20 + c4 * m00,
        m10,
        c4 * m21 + s4 * m01,
        -s4 * m21 + c4 * m01,
        m11,
        c4 * m22 + s4 * m02,
        -s4 * m22 + c4 * m02,
        m12,
    )


def _jacobian_rows(t1: float, t2: float, t3: float) -> tuple:
    """J(Theta) of eq. (4) as three rows of 4 floats (``jacobian``'s arithmetic); the
    polarization axis is the boresight, column 2 of f, which does not depend on t4."""
    c1, s1 = math.cos(t1), math.sin(t1)
    c2, s2 = math.cos(t2), math.sin(t2)
    c3, s3 = math.cos(t3), math.sin(t3)
    return (
        (0.0, -c1, -s1 * s2, -c1 * s3 - s1 * c2 * c3),
        (0.0, -s1, c1 * s2, -s1 * s3 + c1 * c2 * c3),
        (1.0, 0.0, c2, -s2 * c3),
    )


def _relative_floats(a, b) -> tuple:
    """A B^T of two 3 x 3 matrices given as 9 floats each, row by row."""
    a0, a1, a2, a3, a4, a5, a6, a7, a8 = a
    b0, b1, b2, b3, b4, b5, b6, b7, b8 = b
    return (
        a0 * b0 + a1 * b1 + a2 * b2,
        a0 * b3 + a1 * b4 + a2 * b5,
        a0 * b6 + a1 * b7 + a2 * b8,
        a3 * b0 + a4 * b1 + a5 * b2,
        a3 * b3 + a4 * b4 + a5 * b5,
        a3 * b6 + a4 * b7 + a5 * b8,
        a6 * b0 + a7 * b1 + a8 * b2,
        a6 * b3 + a7 * b4 + a8 * b5,
        a6 * b6 + a7 * b7 + a8 * b8,
    )


def _log_floats(r) -> tuple:
    """``rotation_log`` of one rotation given as 9 floats: its rotation vector."""
    cos_angle = min(max((r[0] + r[4] + r[8] - 1.0) / 2.0, -1.0), 1.0)
    angle = math.acos(cos_angle)
    if angle > math.pi - 1e-6:
        raise PlanningError(f"rotation of {math.degrees(angle):.4f} deg is too close to 180 deg for its logarithm")
    if angle < 1e-4:
        a2 = angle * angle
        scale = 1.0 + a2 / 6.0 + 7.0 * (a2 * a2) / 360.0
    else:
        scale = angle / math.sin(angle)
    return (0.5 * (r[7] - r[5]) * scale, 0.5 * (r[2] - r[6]) * scale, 0.5 * (r[3] - r[1]) * scale)


def _gram_floats(jac, w_inv) -> tuple:
    """(J W^-1 (3 rows of 4), J W^-1 J^T as its 6 distinct entries g00 g01 g02 g11 g12 g22).

    J's structural zeros (the azimuth axis is Z: J[0][0] = J[1][0] = 0; the elevation axis
    is horizontal: J[2][1] = 0) are left out of the sums (their terms are zeros)."""
    (_, a1, a2, a3), (_, b1, b2, b3), (c0, _, c2, c3) = jac
    w0, w1, w2, w3 = w_inv
    ja1, ja2, ja3 = a1 * w1, a2 * w2, a3 * w3
    jb1, jb2, jb3 = b1 * w1, b2 * w2, b3 * w3
    jc0, jc2, jc3 = c0 * w0, c2 * w2, c3 * w3
    gram = (
        ja1 * a1 + ja2 * a2 + ja3 * a3,
        ja1 * b1 + ja2 * b2 + ja3 * b3,
        ja2 * c2 + ja3 * c3,
        jb1 * b1 + jb2 * b2 + jb3 * b3,
        jb2 * c2 + jb3 * c3,
        jc0 * c0 + jc2 * c2 + jc3 * c3,
    )
    return ((0.0, ja1, ja2, ja3), (0.0, jb1, jb2, jb3), (jc0, 0.0, jc2, jc3)), gram


def _det_floats(g) -> float:
    """det of the symmetric 3 x 3 matrix with distinct entries g (``_gram_floats``)."""
    g00, g01, g02, g11, g12, g22 = g
    return g00 * (g11 * g22 - g12 * g12) - g01 * (g01 * g22 - g12 * g02) + g02 * (g01 * g12 - g11 * g02)


def _solve_floats(jw, g, omega, damping: float = 0.0) -> list:
    """``_solve_rates`` for one pose: W^-1 J^T (J W^-1 J^T + damping^2 I)^-1 omega, with the
    symmetric 3 x 3 system solved by Cramer's rule. Raises LinAlgError when it is singular."""
    g00, g01, g02, g11, g12, g22 = g
    if damping:
        d2 = damping * damping
        g00, g11, g22 = g00 + d2, g11 + d2, g22 + d2
    # The adjugate (symmetric) and the determinant.
    k00, k01, k02 = g11 * g22 - g12 * g12, g02 * g12 - g01 * g22, g01 * g12 - g02 * g11
    k11, k12, k22 = g00 * g22 - g02 * g02, g01 * g02 - g00 * g12, g00 * g11 - g01 * g01
    det = g00 * k00 + g01 * k01 + g02 * k02
    if det == 0.0 or not math.isfinite(det):
        raise np.linalg.LinAlgError("Singular matrix")
    o0, o1, o2 = omega
    x0 = (k00 * o0 + k01 * o1 + k02 * o2) / det
    x1 = (k01 * o0 + k11 * o1 + k12 * o2) / det
    x2 = (k02 * o0 + k12 * o1 + k22 * o2) / det
    (_, ja1, ja2, ja3), (_, jb1, jb2, jb3), (jc0, _, jc2, jc3) = jw
    return [jc0 * x2, ja1 * x0 + jb1 * x1, ja2 * x0 + jb2 * x1 + jc2 * x2, ja3 * x0 + jb3 * x1 + jc3 * x2]


def _damping_floats(g, limits: AntennaLimits) -> float:
    """``_damping`` of the gram given as its 6 distinct entries."""
    threshold2 = limits.singular_threshold**2
    trace = g[0] + g[3] + g[5]
    if 4.0 * _det_floats(g) >= threshold2 * trace * trace:
        return 0.0
    g00, g01, g02, g11, g12, g22 = g
    matrix = np.array([[g00, g01, g02], [g01, g11, g12], [g02, g12, g22]])
    sigma2 = max(float(np.linalg.eigvalsh(matrix)[0]), 0.0)
    if sigma2 >= threshold2:
        return 0.0
    return limits.max_damping * math.sqrt(1.0 - sigma2 / threshold2)


def _joint_rates_floats(theta, omega, w_inv, limits: AntennaLimits | None, rate_limits=None):
    """``joint_rates`` for one pose in floats: (rates [4], damped, rate_limited); ``w_inv``
    the inverse weights (4 floats), ``rate_limits`` those of ``limits`` as floats."""
    jac = _jacobian_rows(theta[0], theta[1], theta[2])
    jw, gram = _gram_floats(jac, w_inv)
    try:
        rates = _solve_floats(jw, gram, omega)
    except np.linalg.LinAlgError:
        if limits is None:
            raise SingularityError("J W^-1 J^T is singular: the four axes span less than 3 dimensions") from None
        rates = None
    if limits is None:
        return rates, False, False
    if rate_limits is None:
        rate_limits = [float(v) for v in limits.rate]
    damping = _damping_floats(gram, limits)
    if damping:
        rates = _solve_floats(jw, gram, omega, damping)
    elif rates is None:  # singular, and limits whose max_damping is 0 allow no damping
        raise SingularityError("J W^-1 J^T is singular and the limits' max_damping is 0")
    limited = False
    l0, l1, l2, l3 = rate_limits
    for _ in range(4):
        r0, r1, r2, r3 = rates
        q0, q1, q2, q3 = abs(r0) / l0, abs(r1) / l1, abs(r2) / l2, abs(r3) / l3
        if max(q0, q1, q2, q3) <= 1.0:
            return rates, damping > 0.0, limited
        limited = True
        q0, q1, q2, q3 = max(q0, 1.0), max(q1, 1.0), max(q2, 1.0), max(q3, 1.0)
        w0, w1, w2, w3 = w_inv
        w_inv = (w0 / (q0 * q0), w1 / (q1 * q1), w2 / (q2 * q2), w3 / (q3 * q3))
        jw, weighted = _gram_floats(jac, w_inv)
        rates = _solve_floats(jw, weighted, omega, damping)
    r0, r1, r2, r3 = rates
    ratio = max(abs(r0) / l0, abs(r1) / l1, abs(r2) / l2, abs(r3) / l3)
    if ratio > 1.0:
        limited = True
        rates = [r0 / ratio, r1 / ratio, r2 / ratio, r3 / ratio]
    return rates, damping > 0.0, limited


def joint_rates_scalar(theta, omega, weights=PAPER_WEIGHTS, limits: AntennaLimits | None = None):
    """``joint_rates`` (eq. 7/9 with the same safeguards) for one pose, in plain floats: the
    online path's fast version. theta (4,), omega (3,); returns (rates (4,), damped,
    rate_limited), equal to ``joint_rates`` to round-off (tested)."""
    w_inv = [1.0 / float(w) for w in weights]
    rates, damped, limited = _joint_rates_floats([float(v) for v in theta], [float(v) for v in omega], w_inv, limits)
    return np.array(rates), damped, limited


def crr_step_scalar(
    theta,
    n_now,
    n_next,
    dt: float,
    weights=PAPER_WEIGHTS,
    *,
    limits: AntennaLimits | None = None,
    omega_method: str = "eq6",
    full_correction: bool = False,
    tol: float = 1e-15,
    max_iter: int = 20,
):
    """``crr_step`` for one pose in plain floats: the same update (section 4.2, steps 3-7:
    the angular velocity of eq. 6 or its exact log, the weighted pseudo-inverse of eq. 9 with
    the safeguards of ``joint_rates``, RK4 of eq. 11, the rotation ratio of eq. 12-14, Newton
    on eq. 10 with the same stop rule, the cap at the rate limits and the optional full
    correction), equal to ``crr_step`` to round-off (tested). theta (4,), n_now and n_next
    (3, 3). Returns (Theta_{n+1} (4,), StepInfo)."""
    if omega_method not in ("eq6", "log"):
        raise PlanningError(f"angular velocity method {omega_method!r} is not 'eq6' or 'log'")
    th = tuple(np.asarray(theta, dtype=float).reshape(4).tolist())
    target = np.asarray(n_next, dtype=float).reshape(9).tolist()
    relative = _relative_floats(target, np.asarray(n_now, dtype=float).reshape(9).tolist())
    if omega_method == "log":
        rotvec = _log_floats(relative)
        omega = (rotvec[0] / dt, rotvec[1] / dt, rotvec[2] / dt)
    else:  # vee(N(t + dt) N(t)^T) / dt
        omega = (
            0.5 * (relative[7] - relative[5]) / dt,
            0.5 * (relative[2] - relative[6]) / dt,
            0.5 * (relative[3] - relative[1]) / dt,
        )
    w_inv = [1.0 / float(w) for w in weights]
    rate_limits = None if limits is None else [float(v) for v in limits.rate]
    info = StepInfo()

    def rate(t):
        r, damped, limited = _joint_rates_floats(t, omega, w_inv, limits, rate_limits)
        info.damped |= damped
        info.rate_limited |= limited
        return r

    half = 0.5 * dt
    t0, t1, t2, t3 = th
    a0, a1, a2, a3 = rate(th)
    b0, b1, b2, b3 = rate((t0 + half * a0, t1 + half * a1, t2 + half * a2, t3 + half * a3))
    c0, c1, c2, c3 = rate((t0 + half * b0, t1 + half * b1, t2 + half * b2, t3 + half * b3))
    d0, d1, d2, d3 = rate((t0 + dt * c0, t1 + dt * c1, t2 + dt * c2, t3 + dt * c3))
    # eq. (11)
    m0, m1 = (a0 + 2.0 * b0 + 2.0 * c0 + d0) / 6.0, (a1 + 2.0 * b1 + 2.0 * c1 + d1) / 6.0
    m2, m3 = (a2 + 2.0 * b2 + 2.0 * c2 + d2) / 6.0, (a3 + 2.0 * b3 + 2.0 * c3 + d3) / 6.0
    speed = math.sqrt(m0 * m0 + m1 * m1 + m2 * m2 + m3 * m3)
    new = th
    if speed > 0.0:
        q0, q1, q2, q3 = m0 / speed, m1 / speed, m2 / speed, m3 / speed  # k of eq. (12)-(14)
        xi = speed
        for iteration in range(1, max_iter + 1):
            h = xi * dt
            new = (t0 + q0 * h, t1 + q1 * h, t2 + q2 * h, t3 + q3 * h)
            e0, e1, e2 = _log_floats(_relative_floats(target, _fk_floats(*new)))
            (_, j01, j02, j03), (_, j11, j12, j13), (j20, _, j22, j23) = _jacobian_rows(new[0], new[1], new[2])
            # d(rotation)/d(xi) = J k dt (J's structural zeros left out)
            s0 = (j01 * q1 + j02 * q2 + j03 * q3) * dt
            s1 = (j11 * q1 + j12 * q2 + j13 * q3) * dt
            s2 = (j20 * q0 + j22 * q2 + j23 * q3) * dt
            step = (s0 * e0 + s1 * e1 + s2 * e2) / (s0 * s0 + s1 * s1 + s2 * s2)
            xi += step
            info.iterations = iteration
            if abs(step) * dt < tol:
                break
        if rate_limits is not None:  # (given with the limits)
            l0, l1, l2, l3 = rate_limits
            cap = min(
                l0 / max(abs(q0), 1e-300),
                l1 / max(abs(q1), 1e-300),
                l2 / max(abs(q2), 1e-300),
                l3 / max(abs(q3), 1e-300),
            )
            if abs(xi) > cap:
                xi = math.copysign(cap, xi)
                info.rate_limited = True
        h = xi * dt
        new = (t0 + q0 * h, t1 + q1 * h, t2 + q2 * h, t3 + q3 * h)
    if full_correction:
        w_corr = [1.0 / float(w) for w in weights]
        for _ in range(max_iter):
            residual = _log_floats(_relative_floats(target, _fk_floats(*new)))
            if max(abs(residual[0]), abs(residual[1]), abs(residual[2])) < 1e-15:
                break
            jac = _jacobian_rows(new[0], new[1], new[2])
            jw, gram = _gram_floats(jac, w_corr)
            damping = 0.0 if limits is None else _damping_floats(gram, limits)
            delta = _solve_floats(jw, gram, residual, damping)
            new = (new[0] + delta[0], new[1] + delta[1], new[2] + delta[2], new[3] + delta[3])
            info.iterations += 1
    f = _fk_floats(*new)
    info.error_fro = math.sqrt(sum((a - b) * (a - b) for a, b in zip(f, target, strict=True)))
    return np.array(new), info


METHODS = ("pinv", "crr", "crr-full")


@dataclass
class JointPath:
    """Joint positions for an attitude sequence, with per-update diagnostics.

    Attributes:
      t: (n,) times, s.
      theta: (n, 4) joint angles, rad; row 0 is the start.
      error_fro: (n,) ||f(Theta_n) - N(t_n)||_F (the paper's Figures 4 and 7).
      iterations: (n,) Newton iterations per update (0 for the start and for "pinv").
      damped, rate_limited: (n,) bool, the safeguards of ``joint_rates`` were active.
      method: "pinv", "crr" or "crr-full".
    """

    t: np.ndarray
    theta: np.ndarray
    error_fro: np.ndarray
    iterations: np.ndarray
    damped: np.ndarray
    rate_limited: np.ndarray
    method: str

    def rates(self) -> np.ndarray:
        """(n - 1, 4) average joint rates between updates, rad/s (the paper's Figure 8)."""
        return np.diff(self.theta, axis=0) / np.diff(self.t)[:, None]


def solve_joint_path(
    attitudes,
    dt: float,
    theta0,
    method: str = "crr",
    weights=PAPER_WEIGHTS,
    limits: AntennaLimits | None = None,
    omega_method: str = "eq6",
    t0: float = 0.0,
    scalar: bool = False,
) -> JointPath:
    """Joint angles that hold the attitudes N(t0 + n dt) (n, 3, 3), from Theta0.

    method: "pinv" (the paper's baseline, section 5.2), "crr" (section 4.2) or "crr-full"
    (CRR then a full weighted Newton correction). ``scalar``: the CRR updates by
    ``crr_step_scalar`` (the online planner's one-pose path in floats; equal to round-off).
    """
    if method not in METHODS:
        raise PlanningError(f"joint-position method {method!r} is not one of {', '.join(METHODS)}")
    attitudes = np.asarray(attitudes, dtype=float)
    if attitudes.ndim != 3 or attitudes.shape[1:] != (3, 3):
        raise PlanningError(f"attitudes must have shape (n, 3, 3), not {attitudes.shape}")
    if not np.isfinite(attitudes).all():
        raise PlanningError("attitudes contain NaN or inf")
    if not np.isfinite(dt) or dt <= 0:
        raise PlanningError(f"update interval dt = {dt!r} s must be > 0")
    theta0 = np.asarray(theta0, dtype=float)
    if theta0.shape != (4,) or not np.isfinite(theta0).all():
        raise PlanningError(f"Theta0 must be 4 finite angles, not {theta0!r}")
    n = attitudes.shape[0]
    theta = np.empty((n, 4))
    theta[0] = theta0
    error = np.empty(n)
    error[0] = frobenius_error(forward_kinematics(theta0), attitudes[0])
    iterations = np.zeros(n, dtype=int)
    damped = np.zeros(n, dtype=bool)
    limited = np.zeros(n, dtype=bool)
    for i in range(n - 1):
        if method == "pinv":
            theta[i + 1], info = pinv_integration_step(
                theta[i], attitudes[i], attitudes[i + 1], dt, weights, omega_method
            )
        else:
            theta[i + 1], info = (crr_step_scalar if scalar else crr_step)(
                theta[i],
                attitudes[i],
                attitudes[i + 1],
                dt,
                weights,
                limits=limits,
                omega_method=omega_method,
                full_correction=method == "crr-full",
            )
        error[i + 1] = info.error_fro
        iterations[i + 1] = info.iterations
        damped[i + 1] = info.damped
        limited[i + 1] = info.rate_limited
    return JointPath(t0 + dt * np.arange(n), theta, error, iterations, damped, limited, method)


class JointPathTrajectory:
    """A JointPath as a Trajectory: a C2 cubic spline through the joint angles (scipy)."""

    labels: Sequence[str] = JOINT_LABELS

    def __init__(self, path: JointPath):
        self.path = path
        self._spline = CubicSpline(path.t, path.theta, axis=0)

    @property
    def duration(self) -> float:
        return float(self.path.t[-1] - self.path.t[0])

    def sample(self, t) -> TrajectorySample:
        t = sample_times(t)  # a number or 1-D array of finite times
        s = self._spline
        return TrajectorySample(t, s(t), s(t, 1), s(t, 2))


def check_rates(rates, limits: AntennaLimits, where: str = "") -> None:
    """Raise LimitError naming the joint whose rate (rad/s, (n, 4)) breaks its limit."""
    rates = np.atleast_2d(rates)
    peak = np.abs(rates).max(axis=0)
    for name, value, limit in zip(JOINT_LABELS, peak, limits.rate, strict=True):
        if value > limit:
            raise LimitError(
                f"{name} rate {np.degrees(value):.2f} deg/s is beyond its limit {np.degrees(limit):.2f} deg/s{where}"
            )


# --------------------------------------------------------------------------------------
# The planning problem and the online planners


@dataclass(frozen=True)
class AntennaProblem:
    """The antenna's planning problem: hold a satellite while the ship moves.

    Attributes:
      satellite: eTs (3, 3), the satellite frame in East-North-Up (its z: the direction to
        the satellite; its x, y: the polarization).
      azimuth, elevation, polarization: the same as look angles from the level ship, rad.
      theta0: (4,) the joint angles at the start, rad.
      limits: the joint rate limits and the singularity damping.
      weights: (4,) the joint weights of the weighted pseudo-inverse (paper, eq. 9).
      update_dt: the interval between two attitude samples (the IMU's period), s.
    The online planner gets, per sample, N = bTe eTs (paper, eq. 1) and returns Theta.
    """

    satellite: np.ndarray
    azimuth: float
    elevation: float
    polarization: float
    theta0: np.ndarray
    limits: AntennaLimits
    weights: np.ndarray = field(default_factory=lambda: PAPER_WEIGHTS.copy())
    update_dt: float = 0.02


class CrrPlanner:
    """The paper's online planner: one CRR update per attitude sample (section 4.2).

    ``step(t, N)`` runs ``crr_step`` from the last solution to N over t - t_last (the first
    from the problem's theta0 and its attitude at t = 0), in its one-pose form in plain floats
    (``crr_step_scalar``: the same update to round-off, about ten times faster).

    Args:
      method: "crr" (the paper's) or "crr-full" (CRR with Newton steps on the whole attitude).
      omega_method: the angular velocity of step 3: "log" (exact) or "eq6" (the paper's
        first-order reading).
    """

    def __init__(self, method: str = "crr", omega_method: str = "log"):
        if method not in ("crr", "crr-full"):
            raise PlanningError(f"planner method {method!r} is not 'crr' or 'crr-full'")
        if omega_method not in ("log", "eq6"):
            raise PlanningError(f"angular velocity method {omega_method!r} is not 'log' or 'eq6'")
        self.method = method
        self.omega_method = omega_method
        self.last_info = None

    def reset(self, problem: AntennaProblem) -> None:
        self.problem = problem
        self.theta = np.asarray(problem.theta0, dtype=float).copy()
        self.attitude = forward_kinematics(self.theta)
        self.t = 0.0

    def step(self, t: float, attitude: np.ndarray) -> np.ndarray:
        """Joint angles for ``attitude`` at ``t`` (s), after the previous step (or reset, t = 0)."""
        if not t > self.t:
            raise PlanningError(
                f"CRR step at t = {t:.6g} s does not come after the previous one at {self.t:.6g} s: "
                "the angular velocity (eq. 6) needs an interval > 0"
            )
        p = self.problem
        theta, info = crr_step_scalar(
            self.theta,
            self.attitude,
            attitude,
            t - self.t,
            p.weights,
            limits=p.limits,
            omega_method=self.omega_method,
            full_correction=self.method == "crr-full",
        )
        self.theta, self.attitude, self.t, self.last_info = theta, attitude, t, info
        return theta
