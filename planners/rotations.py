"""Elementary rotation matrices, vectorized: the building blocks of the papers' attitude
chains (the antenna's eq. 1, FAST's eq. 2-5). Active rotations; tested against scipy's
``Rotation.from_euler``."""

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
