"""Contacts and clearances between a mechanism and its obstacles, from a run's log."""

from __future__ import annotations

import mujoco
import numpy as np


def geoms_by_contype(model: mujoco.MjModel, contype: int) -> np.ndarray:
    """Ids of the geoms whose contype has the given bit(s) set."""
    return np.flatnonzero(model.geom_contype & contype)


def obstacle_contact_pairs(contacts, robot: np.ndarray, obstacles: np.ndarray) -> dict:
    """Robot-obstacle pairs that touched, from ``RunLog.contacts``.

    Returns {(robot geom id, obstacle geom id): (first tick, ticks in contact, deepest
    penetration in m as a positive number)}.
    """
    robot_set, obstacle_set = set(robot.tolist()), set(obstacles.tolist())
    pairs: dict = {}
    for tick, g1, g2, dist in contacts:
        if g1 in obstacle_set and g2 in robot_set:
            g1, g2 = g2, g1
        if g1 in robot_set and g2 in obstacle_set:
            first, count, depth = pairs.get((g1, g2), (tick, 0, 0.0))
            pairs[(g1, g2)] = (first, count + 1, max(depth, -dist))
    return pairs


def clearance(
    model: mujoco.MjModel,
    qpos: np.ndarray,
    robot: np.ndarray,
    obstacles: np.ndarray,
    distmax: float = 0.5,
) -> tuple[np.ndarray, np.ndarray]:
    """Smallest signed distance (m) between robot and obstacle geoms at each logged pose.

    Uses ``mujoco.mj_geomDistance`` after ``mj_kinematics`` of each pose (negative when the
    geoms overlap). Distances beyond ``distmax`` are reported as ``distmax``.

    Returns:
      (n,) clearance and (n, 2) the closest (robot, obstacle) geom ids at each pose.
    """
    data = mujoco.MjData(model)
    n = qpos.shape[0]
    out = np.full(n, distmax)
    closest = np.full((n, 2), -1, dtype=int)
    fromto = np.zeros(6)
    for i in range(n):
        data.qpos[:] = qpos[i]
        mujoco.mj_kinematics(model, data)
        best = distmax
        for r in robot:
            for o in obstacles:
                d = mujoco.mj_geomDistance(model, data, int(r), int(o), best, fromto)
                if d < best:
                    best = d
                    closest[i] = (r, o)
        out[i] = best
    return out, closest
