"""Editing a mechanism's MjSpec for plant uncertainty (planbench.params.PlantParams).

A perturbed plant is the nominal MJCF with some quantities changed before compiling, so that
MuJoCo derives everything else (subtree masses, the mass matrix at qpos0, invweights) from the
changed values as it does for the nominal model. The controller keeps the nominal model.
"""

from __future__ import annotations

import mujoco
import numpy as np


def set_inertial(
    spec: mujoco.MjSpec, nominal: mujoco.MjModel, body: str, mass_factor: float = 1.0, com_shift=None
) -> None:
    """Give ``body`` of ``spec`` an explicit inertial: the compiled ``nominal`` model's mass
    (kg) and inertia about the centre of mass (kg m^2) times ``mass_factor``, the same
    principal axes, the centre of mass moved by ``com_shift`` (3,) m in the body frame.

    A body whose inertia MuJoCo computes from its geoms gets it written out here, so a
    uniform factor scales mass and inertia exactly (same shape and density distribution);
    scaling the geoms' masses instead would re-run the principal-axes decomposition and
    change ``body_iquat`` by rounding where two principal moments are equal.
    """
    i = nominal.body(body).id
    element = spec.body(body)
    element.explicitinertial = True
    element.mass = float(nominal.body_mass[i]) * mass_factor
    element.inertia = nominal.body_inertia[i] * mass_factor
    element.iquat = nominal.body_iquat[i].copy()
    shift = np.zeros(3) if com_shift is None else np.asarray(com_shift, dtype=float)
    element.ipos = nominal.body_ipos[i] + shift
