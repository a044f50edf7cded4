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


#: [v]x has v_k at (_ROW[k], _COL[k]) and -v_k at the transposed place. Fancy indexing with
#: these is a few microseconds for one vector (the FAST controller calls both every tick).
_ROW, _COL = np.array([2, 0, 1]), np.array([1, 2, 0])


def skew(v) -> np.ndarray:
    """[v]x, (..., 3, 3), such that [v]x u = v x u."""
    v = np.asarray(v, dtype=float)
    m = np.zeros(v.shape + (3,))
    m[..., _ROW, _COL] = v
    m[..., _COL, _ROW] = -v
    return m


def vee(m) -> np.ndarray:
    """The vector of the antisymmetric part of m: vee((M - M^T) / 2), (..., 3). For a small
    rotation R = I + [w]x + O(w^2), vee(R) = w to first order."""
    m = np.asarray(m, dtype=float)
    return 0.5 * (m[..., _ROW, _COL] - m[..., _COL, _ROW])


def wxyz(rotation) -> np.ndarray:
    """(..., 4) unit quaternions (w, x, y, z), MuJoCo's order, of rotation matrices (..., 3, 3)."""
    from scipy.spatial.transform import Rotation

    rotation = np.asarray(rotation, dtype=float)
    xyzw = Rotation.from_matrix(rotation.reshape(-1, 3, 3)).as_quat()
    return np.roll(xyzw, 1, axis=-1).reshape(rotation.shape[:-2] + (4,))
