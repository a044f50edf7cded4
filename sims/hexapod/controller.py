"""The hexapod's reference controller: the strut servo with static-load feed-forward and
integral action (``HexapodController``)."""

from __future__ import annotations

import numpy as np

from planners import hexapod as hexapod_planner
from planners.hexapod import RUBIN_CAMERA, STRUT_LABELS
from sims.controllers import ServoFeedforwardController
from sims.hexapod.physics import HexapodPhysics

INTEGRAL_TIME_S = 0.1  # integral action's time constant; the lowest mode is ~12 Hz


class HexapodController(ServoFeedforwardController):
    """Strut servo: reference tracking with static-load feed-forward and integral action.

    ``sims.controllers.ServoFeedforwardController`` (set-point interpolation, feed-forward in
    the set-point, integral action on the encoder error) with its feed-forward replaced:
    inverse dynamics does not apply to the closed loops, so f_ff is the set of drive forces
    that hold the payload in static equilibrium at the reference pose, what a real hexapod's
    gravity table supplies (``static_drive_forces``). The integral action takes what the
    model leaves out (wind, the constraint compliance, the payload's tiny inertial forces).
    Gains and force limits are read from the nominal model in ``reset``; the statics use the
    nominal model at the start pose (``ControlContext.nominal_physics``).

    Args:
      feedforward: include f_ff (False: PD + integral only).
      integral_time: T_i in s; None for no integral action.
    """

    def __init__(self, feedforward: bool = True, integral_time: float | None = INTEGRAL_TIME_S):
        super().__init__(None, None, feedforward, integral_time)

    @property
    def f_ff(self) -> np.ndarray:
        """(n, 6) the static drive forces along the reference, N (push positive)."""
        return self.tau_ff

    def static_drive_forces(self, physics: HexapodPhysics, strut_positions: np.ndarray) -> np.ndarray:
        """(n, 6) drive forces (N, push positive) that hold the reference poses statically.

        Exact statics of the model: the payload's weight, and each strut's own weight. A
        strut's housing and rod hang on its base universal joint; the moment of their weights
        about it, M = sum_k r_k x m_k g (r_k along the strut), is held by a transverse force
        at the top pivot, F_t = (l x M) / |l|^2, whose reaction loads the platform. The rod's
        weight along the strut is the drive's own. Tensions from
        ``planners.hexapod.static_strut_forces`` of the total wrench on the platform.
        """
        model = physics.model.ptr
        lengths = strut_positions + RUBIN_CAMERA.nominal_lengths
        poses, _ = hexapod_planner.forward_kinematics(lengths)
        mass, com_local = physics.payload_mass_properties()
        gravity = physics.gravity_in_hexapod_frame()
        origin, rotation = hexapod_planner.platform_frame(poses)
        force = np.broadcast_to(mass * gravity, poses[:, :3].shape).copy()
        moment = np.cross(rotation @ com_local, force)
        pivots = hexapod_planner.pivot_positions(poses)
        legs = pivots - RUBIN_CAMERA.base_pivots
        leg_length = np.linalg.norm(legs, axis=-1, keepdims=True)
        units = legs / leg_length
        housing = np.array([model.body(f"{n}_housing").id for n in STRUT_LABELS])
        rod = np.array([model.body(f"{n}_rod").id for n in STRUT_LABELS])
        # Centres of mass along the strut from its base pivot, m (rod frame origin = tip).
        housing_arm = model.body_ipos[housing, 2]
        rod_arm = leg_length[..., 0] + model.body_ipos[rod, 2]
        weight_moment = (model.body_mass[housing] * housing_arm + model.body_mass[rod] * rod_arm)
        strut_moment = np.cross(units * weight_moment[..., None], gravity)
        tip_force = np.cross(legs, strut_moment) / leg_length**2
        force -= tip_force.sum(axis=1)
        moment -= np.cross(pivots - origin[:, None, :], tip_force).sum(axis=1)
        tension = hexapod_planner.static_strut_forces(poses, np.hstack([force, moment]))
        rod_weight = model.body_mass[rod] * (units @ gravity)
        return -tension - rod_weight

    def feedforward_forces(self, context) -> np.ndarray:
        return self.static_drive_forces(context.nominal_physics(), context.reference.position)
