"""Elementary rotation matrices, vectorized: the building blocks of the papers' attitude
chains (the antenna's eq. 1, FAST's eq. 2-5). Active rotations; tested against scipy's
``Rotation.from_euler``. Also the cross-product matrix and its inverse (skew, vee) and MuJoCo's
(w, x, y, z) quaternion of a rotation matrix."""

from __future__ import annotations

import numpy as np


def _rotation(axis: int, angle) -> np.ndarray:
    angle = np.asarray(angle, dtype=float)
    c, s = np.cos(angle), np.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m = np.zeros(angle.shape + (3, 3))
    m[..., axis, axis] = 1.0
    m[..., i, i] = c
    m[..., j, j] = c
    m[..., i, j] = -s
    m[..., j, i] = s
    return m


def rot_x(angle) -> np.ndarray:
    """Active rotation matrices about X, (..., 3, 3), for angles (...) in rad."""
    return _rotation(0, angle)


def rot_y(angle) -> np.ndarray:
    """Active rotation matrices about Y, (..., 3, 3)."""
    return _rotation(1, angle)


def rot_z(angle) -> np.ndarray:
    """Active rotation matrices about Z, (..., 3, 3)."""
    return _rotation(2, angle)


def skew(v) -> np.ndarray:
    """[v]x, (..., 3, 3), such that [v]x u = v x u."""
    v = np.asarray(v, dtype=float)
    z = np.zeros(v.shape[:-1])
    x, y, w = v[..., 0], v[..., 1], v[..., 2]
    return np.stack([np.stack([z, -w, y], -1), np.stack([w, z, -x], -1),
                     np.stack([-y, x, z], -1)], -2)


def vee(m) -> np.ndarray:
    """The vector of the antisymmetric part of m: vee((M - M^T) / 2), (..., 3). For a small
    rotation R = I + [w]x + O(w^2), vee(R) = w to first order."""
    m = np.asarray(m, dtype=float)
    return 0.5 * np.stack([m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0],
                           m[..., 1, 0] - m[..., 0, 1]], -1)


def wxyz(rotation) -> np.ndarray:
    """(..., 4) unit quaternions (w, x, y, z), MuJoCo's order, of rotation matrices (..., 3, 3)."""
    from scipy.spatial.transform import Rotation

    rotation = np.asarray(rotation, dtype=float)
    xyzw = Rotation.from_matrix(rotation.reshape(-1, 3, 3)).as_quat()
    return np.roll(xyzw, 1, axis=-1).reshape(rotation.shape[:-2] + (4,))
