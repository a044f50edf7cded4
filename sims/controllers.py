"""Controllers that the runner calls once per control tick."""

from __future__ import annotations

import copy

import mujoco
import numpy as np

from planbench.drives import load_joint, transmission_stiffness
from planbench.planners.trajectory import TrajectorySample


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
    in ``reset`` by ``feedforward_forces``: here the nominal model's inverse dynamics
    (``mj_inverse``, contacts off: the controller knows the arm and payload, not the
    obstacles); a subclass overrides it (the hexapod's closed loops need statics instead).
    With an integral time T_i, ``z <- z + dt / T_i (q_ref - q)`` each tick, limited so
    ``kp z`` stays inside the force limit.

    It drives every actuator of its command (``ControlContext.actuators``, found in the model
    by name), one per channel of its reference: the trajectory's channels must be those
    actuators, in that order (checked in ``reset``). It reads the task's observation
    (``planbench.task``): ``joint_positions`` (the encoders, for the integral action) and
    ``setpoints`` (the drives' set-points), in that order.

    Args:
      kp, kv: (nu,) drive gains as in the MJCF (N/m or N m/rad; N s/m or N m s/rad); None:
        read from the nominal model in ``reset``.
      feedforward: False to leave out tau_ff (pure PD on the reference).
      integral_time: T_i in s, or None for no integral action.
      force_limit: (nu,) drive force limits, bounding the integral; None: the model's.
    """

    def __init__(
        self, kp=None, kv=None, feedforward: bool = True, integral_time: float | None = None, force_limit=None
    ):
        def as_array(x):
            return None if x is None else np.asarray(x, dtype=float)

        self.kp = as_array(kp)
        self.kv = as_array(kv)
        self.feedforward = feedforward
        self.integral_time = integral_time
        self.force_limit = as_array(force_limit)
        self.setpoints = None
        self.reference = None
        self.tau_ff = None
        self.actuator_ids = None
        self.compliance = None
        self.z = None
        self._inv_dt = None
        self._gain = 0.0

    @staticmethod
    def joint_addresses(model, actuators: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(qpos addresses, dof addresses) of the joints the actuators (indices) finally move:
        through a drive train's compliant transmission, the load's joints
        (``planbench.drives.load_joint``)."""
        joints = np.array([load_joint(model, int(a)) for a in actuators])
        return model.jnt_qposadr[joints].copy(), model.jnt_dofadr[joints].copy()

    def feedforward_forces(self, context) -> np.ndarray:
        """(n, nu) drive forces along the reference: inverse dynamics of the nominal model in
        free space, from its initial configuration. With a drive train as built the motor
        moves with its load (the transmission's deflection is added to the set-points in
        ``reset``): the drive's force is the load's plus the rotor's, at the motor's dof."""
        reference = context.reference
        nu = reference.position.shape[1]
        nominal = context.nominal_physics()
        model = nominal.model.ptr
        qpos_adr, dofs = self.joint_addresses(model, self.actuator_ids)
        motors = model.actuator_trnid[self.actuator_ids, 0]
        # The channels whose motor is a coordinate of its own (a compliant transmission): the
        # motor follows its load, and qfrc_inverse is summed over both dofs.
        own = np.flatnonzero(motors != [load_joint(model, int(a)) for a in self.actuator_ids])
        if own.size:
            qpos_adr = np.concatenate([qpos_adr, model.jnt_qposadr[motors[own]]])
            dofs = np.concatenate([dofs, model.jnt_dofadr[motors[own]]])
            reference = TrajectorySample(
                reference.t,
                *(np.hstack([x, x[:, own]]) for x in (reference.position, reference.velocity, reference.acceleration)),
            )
        n = reference.t.size
        tau = np.zeros((n, nu))
        # A copy of the model (MjModel's copy is a full mj_copyModel) with contacts
        # disabled, and a scratch MjData: inverse dynamics of the plan in free space.
        inv_model = copy.copy(nominal.model.ptr)
        inv_model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
        inv_data = mujoco.MjData(inv_model)
        inv_data.qpos[:] = nominal.data.qpos
        for i in range(n):
            inv_data.qpos[qpos_adr] = reference.position[i]
            inv_data.qvel[:] = 0.0
            inv_data.qvel[dofs] = reference.velocity[i]
            inv_data.qacc[:] = 0.0
            inv_data.qacc[dofs] = reference.acceleration[i]
            mujoco.mj_inverse(inv_model, inv_data)
            forces = inv_data.qfrc_inverse[dofs]
            tau[i] = forces[:nu]
            tau[i, own] += forces[nu:]
        return tau

    def reset(self, context) -> None:
        reference = context.reference
        model = context.model
        nu = reference.position.shape[1]
        actuators = tuple(context.actuators)
        labels = getattr(context.trajectory, "labels", None)
        if nu != len(actuators) or (labels is not None and tuple(labels) != actuators):
            channels = tuple(labels) if labels is not None else f"{nu} unnamed channels"
            raise ValueError(f"the trajectory's channels {channels} are not the commanded actuators {actuators}")
        self.actuator_ids = ids = np.array([model.actuator(name).id for name in actuators])
        if self.kp is None:
            self.kp = model.actuator_gainprm[ids, 0].copy()
        if self.kv is None:
            self.kv = -model.actuator_biasprm[ids, 2].copy()
        if self.force_limit is None and self.integral_time is not None:
            self.force_limit = model.actuator_forcerange[ids, 1].copy()
        n = reference.t.size
        self.tau_ff = self.feedforward_forces(context) if self.feedforward else np.zeros((n, nu))
        self.reference = reference.position
        self.setpoints = reference.position + (self.tau_ff + self.kv * reference.velocity) / self.kp
        # A compliant transmission (as-built drives) deflects by f / k between the motor,
        # which the drive positions, and the load the reference is for.
        stiffness = np.array(
            [transmission_stiffness(model, model.joint(int(j)).name) for j in (load_joint(model, int(a)) for a in ids)]
        )
        self.compliance = None  # m/N or rad/(N m) per drive; None: rigid transmissions
        if np.isfinite(stiffness).any():
            self.compliance = np.where(np.isfinite(stiffness), 1.0 / stiffness, 0.0)
            self.setpoints = self.setpoints + self.tau_ff * self.compliance
        self.z = np.zeros(nu)
        self._gain = 0.0 if self.integral_time is None else context.control_dt / self.integral_time
        if self._gain:
            # The set-point offset that makes the drive's largest force at the load.
            self._bound = (
                self.force_limit / self.kp
                if self.compliance is None
                else self.force_limit * (1.0 / self.kp + self.compliance)
            )
        self._inv_dt = 1.0 / context.control_dt
        self._command = context.command  # written in place every tick
        self._last_tick = self.setpoints.shape[0] - 1
        self._difference = np.empty(nu)
        context.setpoint[:] = self.setpoints[0]

    def __call__(self, tick: int, observation) -> None:
        target = self.setpoints[min(tick + 1, self._last_tick)]
        if self._gain:
            z = self.z + self._gain * (self.reference[tick] - observation["joint_positions"])
            self.z = np.clip(z, -self._bound, self._bound)
            target = target + self.z
        np.multiply(
            np.subtract(target, observation["setpoints"], out=self._difference), self._inv_dt, out=self._command
        )


def demanded_force(kp, kv, act, qpos, qvel) -> np.ndarray:
    """Force/torque the servo drives ask for before their force-range clamp.

    ``kp (act - q) - kv qdot`` on logged arrays (n, nu); compare with the drive limit to see
    saturation (the clamped actuator force can never exceed its limit).
    """
    return kp * (act - qpos) - kv * qvel
