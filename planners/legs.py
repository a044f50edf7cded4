"""Leg kinematics of parallel robots: a Stewart strut and a cable are the same vector.

Leg i joins a fixed anchor ``a_i`` to a point ``b_i`` of the moving body (given in the moving
body's frame). With the moving body at position ``p`` and orientation ``R``,

    l_i = p + R b_i - a_i,     L_i = |l_i|,     u_i = l_i / L_i

(a cable and a Stewart leg are the same |a - (p + R b)|). This module is the
one implementation of that formula; the hexapod struts, the FAST Stewart stabilizer and the
FAST cables all call it. Every function is vectorized over leading pose dimensions.

A leg that pulls or pushes the moving body with force ``f_i`` along ``-u_i`` (tension
positive for a cable, compression negative) applies to it the wrench

    W = sum_i f_i [-u_i ; -(R b_i) x u_i]   about the point p,

so the structure matrix ``A = [-u ; -(R b) x u]`` (6 x n) maps leg forces to the wrench on the
moving body, and ``A^T`` is the transposed Jacobian: dL = -A^T [dp ; dphi] (virtual work).
"""

from __future__ import annotations

import numpy as np


def leg_vectors(anchors: np.ndarray, points: np.ndarray, position: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """Leg vectors from the fixed anchors to the moving points, l_i = p + R b_i - a_i.

    Args:
      anchors: (n, 3) fixed anchors a_i in the fixed frame, m.
      points: (n, 3) attachment points b_i in the moving body's frame, m.
      position: (..., 3) position p of the moving frame's origin in the fixed frame, m.
      rotation: (..., 3, 3) orientation R of the moving frame.

    Returns:
      (..., n, 3) leg vectors, m.
    """
    anchors = np.asarray(anchors, dtype=float)
    points = np.asarray(points, dtype=float)
    position = np.asarray(position, dtype=float)
    rotation = np.asarray(rotation, dtype=float)
    moved = np.einsum("...jk,nk->...nj", rotation, points)
    return position[..., None, :] + moved - anchors


def leg_vector_components(
    anchors: np.ndarray, points: np.ndarray, position: np.ndarray, rotation: np.ndarray
) -> tuple[tuple, tuple]:
    """``leg_vectors`` of M poses as components: ((l_x, l_y, l_z), (R b_x, R b_y, R b_z)),
    each (M, n), m.

    The same numbers as ``leg_vectors``, bit for bit: R b_i is summed in the order einsum
    sums it, (R_j0 b_i0 + R_j2 b_i2) + R_j1 b_i1, and l = (p + R b) - a. Each component is a
    contiguous (M, n) array, which spares the (M, n, 3) array's strided gathers where a caller
    works on components (the hexapod's batched kinematics: several times faster).

    Args:
      anchors: (n, 3) fixed anchors a_i, m.
      points: (n, 3) attachment points b_i in the moving body's frame, m.
      position: (M, 3) positions p of the moving frame's origin, m.
      rotation: (M, 3, 3) orientations R.
    """
    anchors = np.asarray(anchors, dtype=float)
    points = np.asarray(points, dtype=float)
    position = np.asarray(position, dtype=float)
    rotation = np.asarray(rotation, dtype=float)
    arms = tuple(
        (rotation[:, j, 0, None] * points[:, 0] + rotation[:, j, 2, None] * points[:, 2])
        + rotation[:, j, 1, None] * points[:, 1]
        for j in range(3)
    )
    vectors = tuple((position[:, j, None] + arms[j]) - anchors[:, j] for j in range(3))
    return vectors, arms


def component_norm(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """|(x, y, z)| of component arrays, summed as ``np.linalg.norm`` sums a 3-vector (bit for
    bit)."""
    return np.sqrt((x * x + y * y) + z * z)


def leg_lengths(anchors, points, position, rotation) -> np.ndarray:
    """(..., n) leg lengths |p + R b_i - a_i|, m."""
    return np.linalg.norm(leg_vectors(anchors, points, position, rotation), axis=-1)


def structure_matrix(anchors, points, position, rotation) -> np.ndarray:
    """(..., 6, n) wrench of unit leg forces on the moving body, about its origin p.

    Column i is ``[-u_i ; -(R b_i) x u_i]``: a leg force ``f_i`` (positive = the leg pulls the
    body toward its anchor, a cable's tension; a strut in compression has ``f_i < 0``) gives
    the force and moment ``A f``. Its transpose is minus the Jacobian of the leg lengths,
    dL/d[p, phi] = -A^T, with phi a small rotation vector in the fixed frame.
    """
    anchors = np.asarray(anchors, dtype=float)
    points = np.asarray(points, dtype=float)
    position = np.asarray(position, dtype=float)
    rotation = np.asarray(rotation, dtype=float)
    arms = np.einsum("...jk,nk->...nj", rotation, points)  # R b_i (leg_vectors' own)
    vectors = position[..., None, :] + arms - anchors
    lengths = np.linalg.norm(vectors, axis=-1, keepdims=True)
    units = vectors / lengths
    force = -units
    moment = -cross(arms, units)
    return np.swapaxes(np.concatenate([force, moment], axis=-1), -1, -2)


#: The components that a x b pairs: (a x b)_i = a_NEXT[i] b_LAST[i] - a_LAST[i] b_NEXT[i].
_NEXT, _LAST = np.array([1, 2, 0]), np.array([2, 0, 1])


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b of (..., 3) arrays: np.cross's arithmetic (each component one product less
    another) in four gathers and three ufuncs, a fraction of its cost on a few vectors."""
    return a[..., _NEXT] * b[..., _LAST] - a[..., _LAST] * b[..., _NEXT]


def leg_forces(structure: np.ndarray, wrench: np.ndarray) -> np.ndarray:
    """Leg forces f that balance an external wrench on a 6-leg robot: A f + W = 0.

    Args:
      structure: (..., 6, 6) structure matrix (``structure_matrix``).
      wrench: (..., 6) external force (N) and moment (N m) on the moving body about p.

    Returns:
      (..., 6) leg forces, N; positive pulls the body toward the anchor (tension).

    Raises:
      numpy.linalg.LinAlgError at a singular configuration.
    """
    return np.linalg.solve(structure, -np.asarray(wrench, dtype=float)[..., None])[..., 0]
