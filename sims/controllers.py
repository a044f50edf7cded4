"""Controllers that the runner calls once per control tick."""

from __future__ import annotations

import copy

import mujoco
import numpy as np

from planners.trajectory import TrajectorySample


class ServoFeedforwardController:
    """Set-point interpolation, feed-forward and optional integral action for servo drives.

    The drives of a model (MJCF ``general`` actuators with ``dyntype="integrator"`` and an
    affine bias) hold a position set-point ``s`` in their activation and apply
    ``kp (s - q) - kv qdot``, clamped to their force range; ``ctrl`` is the set-point rate.
    Per tick this controller ramps the set-point linearly to its value for the end of the
    tick (the interpolator of a motion controller), so the drive sees no steps:

        s(t) = q_ref(t) + (tau_ff(t) + kv qdot_ref(t)) / kp + z

    which makes the drive force ``kp (q_ref - q) + kv (qdot_ref - qdot) + tau_ff + kp z``: a PD
    on the tracking error plus the feed-forward. ``tau_ff`` for the whole run is computed once
    in ``reset`` by ``feedforward_forces``: here the model's inverse dynamics (``mj_inverse``,
    contacts off: the controller knows the arm and payload, not the obstacles); a subclass
    overrides it (the hexapod's closed loops need statics instead). With an integral time
    T_i, ``z <- z + dt / T_i (q_ref - q)`` each tick, limited so ``kp z`` stays inside the
    force limit.

    Args:
      kp, kv: (nu,) drive gains as in the MJCF (N/m or N m/rad; N s/m or N m s/rad).
      joint_dofs: (nu,) dof index of each actuated joint.
      feedforward: False to leave out tau_ff (pure PD on the reference).
      integral_time: T_i in s, or None for no integral action.
      force_limit: (nu,) drive force limits, bounding the integral (needed with T_i).
      joint_qpos: (nu,) qpos index of each actuated joint (default: joint_dofs, which holds
        for 1-dof joints in a tree without free or ball joints).
    A subclass may pass None for kp, kv, joint_dofs and set them in ``reset`` from the model.
    """

    def __init__(self, kp, kv, joint_dofs, feedforward: bool = True,
                 integral_time: float | None = None, force_limit=None, joint_qpos=None):
        as_array = lambda x, dtype: None if x is None else np.asarray(x, dtype=dtype)
        self.kp = as_array(kp, float)
        self.kv = as_array(kv, float)
        self.dofs = as_array(joint_dofs, int)
        self.qpos_adr = self.dofs if joint_qpos is None else as_array(joint_qpos, int)
        self.feedforward = feedforward
        self.integral_time = integral_time
        self.force_limit = as_array(force_limit, float)
        self.setpoints = None
        self.reference = None
        self.tau_ff = None
        self.z = None
        self._inv_dt = None
        self._gain = 0.0

    def feedforward_forces(self, physics, reference: TrajectorySample) -> np.ndarray:
        """(n, nu) drive forces along the reference: inverse dynamics in free space."""
        model, data = physics.model.ptr, physics.data.ptr
        n = reference.t.size
        tau = np.zeros((n, self.dofs.size))
        # A copy of the model (MjModel's copy is a full mj_copyModel) with contacts
        # disabled, and a scratch MjData: inverse dynamics of the plan in free space.
        inv_model = copy.copy(model)
        inv_model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
        inv_data = mujoco.MjData(inv_model)
        inv_data.qpos[:] = data.qpos
        for i in range(n):
            inv_data.qpos[self.qpos_adr] = reference.position[i]
            inv_data.qvel[:] = 0.0
            inv_data.qvel[self.dofs] = reference.velocity[i]
            inv_data.qacc[:] = 0.0
            inv_data.qacc[self.dofs] = reference.acceleration[i]
            mujoco.mj_inverse(inv_model, inv_data)
            tau[i] = inv_data.qfrc_inverse[self.dofs]
        return tau

    def reset(self, physics, reference: TrajectorySample, control_dt: float) -> None:
        if self.integral_time is not None and self.force_limit is None:
            raise ValueError("integral action needs the drives' force limit for its anti-windup")
        data = physics.data.ptr
        n = reference.t.size
        self.tau_ff = (self.feedforward_forces(physics, reference) if self.feedforward
                       else np.zeros((n, self.dofs.size)))
        self.reference = reference.position
        self.setpoints = reference.position + (self.tau_ff + self.kv * reference.velocity) / self.kp
        self.z = np.zeros(self.dofs.size)
        self._gain = 0.0 if self.integral_time is None else control_dt / self.integral_time
        self._inv_dt = 1.0 / control_dt
        data.act[: self.dofs.size] = self.setpoints[0]

    def __call__(self, tick: int, physics) -> None:
        data = physics.data.ptr
        nu = self.dofs.size
        target = self.setpoints[min(tick + 1, self.setpoints.shape[0] - 1)]
        if self._gain:
            z = self.z + self._gain * (self.reference[tick] - data.qpos[self.qpos_adr])
            bound = self.force_limit / self.kp
            self.z = np.clip(z, -bound, bound)
            target = target + self.z
        data.ctrl[:nu] = (target - data.act[:nu]) * self._inv_dt


def demanded_force(kp, kv, act, qpos, qvel) -> np.ndarray:
    """Force/torque the servo drives ask for before their force-range clamp.

    ``kp (act - q) - kv qdot`` on logged arrays (n, nu); compare with the drive limit to see
    saturation (the clamped actuator force can never exceed its limit).
    """
    return kp * (act - qpos) - kv * qvel
