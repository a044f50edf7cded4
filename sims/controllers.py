"""Controllers that the runner calls once per control tick."""

from __future__ import annotations

import copy

import mujoco
import numpy as np

from planners.trajectory import TrajectorySample


class ServoFeedforwardController:
    """Set-point interpolation and inverse-dynamics feed-forward for integrator servo drives.

    The drives of a model (MJCF ``general`` actuators with ``dyntype="integrator"`` and an
    affine bias) hold a position set-point ``s`` in their activation and apply
    ``kp (s - q) - kv qdot``, clamped to their force range; ``ctrl`` is the set-point rate.
    Per tick this controller ramps the set-point linearly to its value for the end of the
    tick (the interpolator of a motion controller), so the drive sees no steps:

        s(t) = q_ref(t) + (tau_ff(t) + kv qdot_ref(t)) / kp

    which makes the drive force ``kp (q_ref - q) + kv (qdot_ref - qdot) + tau_ff``: a PD on the
    tracking error plus the torque that the model's inverse dynamics (``mj_inverse``, contacts
    off: the controller knows the arm and payload, not the obstacles) needs to follow the
    reference. The feed-forward for the whole run is computed once in ``reset``.

    Args:
      kp, kv: (nu,) drive gains as in the MJCF (N/m or N m/rad; N s/m or N m s/rad).
      joint_dofs: (nu,) dof index of each actuated joint (qpos = qvel index for 1-dof joints).
      feedforward: False to leave out tau_ff (pure PD on the reference).
    """

    def __init__(self, kp, kv, joint_dofs, feedforward: bool = True):
        self.kp = np.asarray(kp, dtype=float)
        self.kv = np.asarray(kv, dtype=float)
        self.dofs = np.asarray(joint_dofs, dtype=int)
        self.feedforward = feedforward
        self.setpoints = None
        self.tau_ff = None
        self._inv_dt = None

    def reset(self, physics, reference: TrajectorySample, control_dt: float) -> None:
        model, data = physics.model.ptr, physics.data.ptr
        n = reference.t.size
        tau = np.zeros((n, self.dofs.size))
        if self.feedforward:
            # A copy of the model (MjModel's copy is a full mj_copyModel) with contacts
            # disabled, and a scratch MjData: inverse dynamics of the plan in free space.
            inv_model = copy.copy(model)
            inv_model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
            inv_data = mujoco.MjData(inv_model)
            inv_data.qpos[:] = data.qpos
            for i in range(n):
                inv_data.qpos[self.dofs] = reference.position[i]
                inv_data.qvel[:] = 0.0
                inv_data.qvel[self.dofs] = reference.velocity[i]
                inv_data.qacc[:] = 0.0
                inv_data.qacc[self.dofs] = reference.acceleration[i]
                mujoco.mj_inverse(inv_model, inv_data)
                tau[i] = inv_data.qfrc_inverse[self.dofs]
        self.tau_ff = tau
        self.setpoints = reference.position + (tau + self.kv * reference.velocity) / self.kp
        self._inv_dt = 1.0 / control_dt
        data.act[:] = self.setpoints[0]

    def __call__(self, tick: int, physics) -> None:
        data = physics.data.ptr
        target = self.setpoints[min(tick + 1, self.setpoints.shape[0] - 1)]
        data.ctrl[:] = (target - data.act) * self._inv_dt


def demanded_force(kp, kv, act, qpos, qvel) -> np.ndarray:
    """Force/torque the servo drives ask for before their force-range clamp.

    ``kp (act - q) - kv qdot`` on logged arrays (n, nu); compare with the drive limit to see
    saturation (the clamped actuator force can never exceed its limit).
    """
    return kp * (act - qpos) - kv * qvel
