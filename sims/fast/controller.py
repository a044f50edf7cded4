"""FAST's reference controller, run once per control tick (the scenarios' control_rate_hz).

* ``FastController``: winch commands (planned cable lengths less the elastic stretch and the
  sag under the planned tensions, plus feedback on the cabin pose: integral only by
  default), the A-B rotator servo (gravity feed-forward and integral action), the multi-beam
  rotation, and the Stewart stabilizer. With FAST's fused measurement system
  (planbench.fast.measurement, the default) the cable loop reads the cabin's fused estimate at
  each GPS/RTK fix, and the stabilizer is an integral loop every tick on the platform's fused
  estimate (its planned pose less the estimate, through the legs' Jacobian, added to the
  legs' planned lengths). With the idealized sensors (``system = "ideal"``) it reads the
  10 Hz total-station fix with 150 ms latency, and the stabilizer leads an alpha-beta
  estimate of the cabin pose by its latency and the legs' lag into the inverse kinematics
  from the base to the planned feed pose.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from planbench.fast.physics import PHYSICS_DT, FastPhysics, index_view, unstretched_length
from planbench.params import ParamError, Params, param
from planbench.planners import fast
from planbench.planners.fast import plan as fast_plan
from planbench.planners.legs import leg_lengths, structure_matrix
from planbench.planners.rotations import rot_y, rot_z, skew, vee


@dataclass(frozen=True)
class ControllerOptions(Params):
    """The FAST controller's settings (typed and ranged as planbench.params declares).

    Why the defaults: the stabilizer's estimator is an alpha-beta tracker (critically damped)
    of the 100 Hz cabin pose measurement's deviation from the planned pose and of its rate;
    the command leads by the latency plus the leg servo's lag kv/kp. Unfiltered, the white
    noise moves the 2 t platform every tick and its reaction shakes the cabin's lightly damped
    0.3-0.65 Hz modes until the legs reach their stroke. The cable loop is integral only:
    with the 150 ms latency, proportional and derivative action destabilize those modes (kp
    0.2 with the stabilizer on at the zenith, kd 0.1 at zenith angle 40 deg: found in
    simulation), and the slow integral (0.02/s, 50 s) removes the drift the stabilizer would
    otherwise carry. With the fused measurement system the stabilizer is an integral loop
    on the platform's fused estimate (platform_bandwidth_hz, 2 Hz: the cabin's 0.17-0.6 Hz
    motion is well inside it, and the 35 ms of tick and servo lag at 50 Hz, 20 ms + kv/kp =
    15 ms, leave 65 deg of phase margin); its estimate's 3 mm error passes to the feed below
    that bandwidth.
    """

    stewart: bool = param(True, "the Stewart stabilizer corrects the feed (false: its legs hold nominal)")
    stewart_bandwidth_hz: float = param(
        3.0,
        "bandwidth of the stabilizer's pose estimator",
        "Hz",
        low=0.0,
        low_open=True,
        high=0.5 / PHYSICS_DT,
        high_open=True,
        reason="below half the control rate (checked against the run's at the start)",
    )
    kp: float = param(
        0.0, "cable-loop proportional gain on the cabin pose error", "", low=0.0, reason="a gain, not a sign change"
    )
    kd: float = param(0.0, "cable-loop derivative gain", "s", low=0.0, reason="a gain, not a sign change")
    ki: float = param(
        0.02,
        "cable-loop integral gain (the pose correction is kp e + kd de/dt + ki int e, mapped "
        "to cable lengths by the Jacobian)",
        "1/s",
        low=0.0,
        reason="a gain, not a sign change",
    )
    derivative_filter_s: float = param(
        0.05, "time constant of the first-order filter on de/dt", "s", low=0.0, reason="a time constant"
    )
    ab_integral_s: float = param(
        1.0,
        "the A-B servo's integral time (removes what the gravity feed-forward leaves)",
        "s",
        low=0.0,
        low_open=True,
        reason="an integral time",
    )
    platform_bandwidth_hz: float = param(
        2.0,
        "with the fused measurement system: bandwidth of the stabilizer's "
        "integral loop on the platform's fused pose estimate",
        "Hz",
        low=0.0,
        low_open=True,
        high=0.5 / PHYSICS_DT,
        high_open=True,
        reason="below half the control rate (checked against the run's at the start)",
    )
    leg_integral_s: float = param(
        0.2,
        "the Stewart legs' integral time on their encoder error (removes the servo "
        "droop under the platform's weight, 0.2-0.7 mm at kp = 2e7 N/m)",
        "s",
        low=0.0,
        low_open=True,
        reason="an integral time",
    )


def ab_gravity_torque(state, geometry: fast.FastGeometry = fast.FAST) -> np.ndarray:
    """(n, 2) gravity's torque about the A and B axes, N m, along a plan's states.

    The tilted part (``ab_mass`` at ``ab_com`` in the AB frame; the A ring is balanced) hangs
    at R_C R_AB ab_com from the rotator's centre; the torque about an axis is the axis' component
    of r x (m g). Axis A is Rz(alpha) e_y in the cabin frame, axis B Rz(alpha) Ry(theta_A) e_x.
    The servo's set-point leads by -torque / kp so that it holds the angle without droop.
    """
    rot_c = state.cabin_rotation
    r_ab = fast.ab_rotation(state.theta_a, state.theta_b, geometry.alpha)
    arm = np.einsum("nij,njk,k->ni", rot_c, r_ab, geometry.ab_com)
    weight = np.array([0.0, 0.0, -geometry.ab_mass * fast.GRAVITY])
    moment = np.cross(arm, weight)
    z_alpha = rot_z(np.full(state.theta_a.shape, geometry.alpha))
    axis_a = np.einsum("nij,njk,k->ni", rot_c, z_alpha, [0.0, 1.0, 0.0])
    axis_b = np.einsum("nij,njk,nkl,l->ni", rot_c, z_alpha, rot_y(state.theta_a), [1.0, 0.0, 0.0])
    return np.column_stack([np.einsum("ni,ni->n", axis_a, moment), np.einsum("ni,ni->n", axis_b, moment)])


def winch_feedforward(state, tower_tops: np.ndarray, geometry: fast.FastGeometry = fast.FAST) -> np.ndarray:
    """(n, 6) the winches' unstretched lengths that give a plan's chords under its tensions
    (elastic stretch and sag, ``unstretched_length``), m; ``state``: a FastPlanSample,
    ``tower_tops``: (6, 3) the cables' exits, m."""
    anchors = state.cabin_origin[:, None, :] + np.einsum("nij,kj->nki", state.cabin_rotation, geometry.cabin_anchors)
    vectors = anchors - tower_tops
    span = np.hypot(vectors[..., 0], vectors[..., 1])
    return unstretched_length(state.cable_length, state.tension, span)


def parked_command(physics: FastPhysics, state) -> np.ndarray:
    """(nu,) the actuator commands that hold the feed support at rest at the first row of
    ``state`` (a FastPlanSample): the winches' lengths (``winch_feedforward``), the A-B
    set-points less their gravity droop, the legs still, the multi-beam angle. The task's
    initial commands, which a controller may change in its reset."""
    command = np.zeros(physics.model.nu)
    command[physics.cable_ids] = winch_feedforward(state, physics.tower_tops)[0]
    kp_ab, _ = physics.drive_gains(physics.ab_ids)
    command[physics.ab_ids] = np.array([state.theta_a[0], state.theta_b[0]]) - ab_gravity_torque(state)[0] / kp_ab
    command[physics.multifeed_id] = state.multifeed[0]
    return command


#: Ticks of the plan's per-tick arrays the controller computes at a time (FastController
#: holds one such block, whatever the run's length).
PLAN_BLOCK_TICKS = 4096
#: Ticks before the present one a block keeps: a fix's time lies a few ticks back.
PLAN_HISTORY_TICKS = 256


@dataclass
class PlanRows:
    """The controller's plan at the ticks ``start`` on (``FastController._plan_rows``)."""

    start: int
    state: object  # planbench.planners.fast.plan.FastPlanSample
    l0_ff: np.ndarray
    r_platform: np.ndarray
    p_platform: np.ndarray
    ab_reference: np.ndarray
    ab_setpoint: np.ndarray
    legs_plan: np.ndarray | None


class FastController:
    """Winches, A-B rotator, multi-beam rotation and Stewart stabilizer (see the module doc).

    It follows the reference's feed and multi-beam channels (planbench.planners.fast.plan.PLAN_LABELS);
    the cabin pose, the A-B angles, the cable lengths and the tensions that go with them come
    from the planners' kinematics and statics (``planbench.planners.fast.plan.reference_state``), so
    any FAST trajectory can be followed. It reads the task's observation: with the fused
    measurement system (``planbench.fast.measurement.FusedSensors``) the cabin's estimate for the
    cable loop and the platform's for the stabilizer; with the idealized one
    (``IdealSensors``) the total stations' fix and the 100 Hz pose; the encoders; rates and
    latencies from the sensors' specs.

    Args:
      options: ControllerOptions.
    """

    def __init__(self, options: ControllerOptions = ControllerOptions()):
        self.options = options

    def reset(self, context) -> None:
        o = self.options
        control_dt = context.control_dt
        for name in ("stewart_bandwidth_hz", "platform_bandwidth_hz"):
            if getattr(o, name) >= 0.5 / control_dt:
                raise ParamError(
                    f"ControllerOptions.{name} = {getattr(o, name):g} Hz is not below half the "
                    f"control rate, {0.5 / control_dt:g} Hz"
                )
        nominal = context.nominal_physics()
        self.reference = context.reference
        self.tower_tops = nominal.tower_tops
        specs = {s.name: s for s in context.sensors}
        self.nominal_legs = fast.stewart_leg_lengths()
        # s between two total-station fixes (a whole number of ticks)
        fused = "platform_estimate" in specs
        if not fused:
            self.pose_dt = max(1, int(round(1.0 / (specs["cabin_pose_ts"].rate_hz * control_dt)))) * control_dt
        self.seen = -1
        self.correction = np.zeros(6)  # commanded pose correction, m and rad
        self.length_correction = np.zeros(6)  # its cable lengths, m
        self.integral = np.zeros(6)
        self.derivative = np.zeros(6)
        self.last_error = None
        # Alpha-beta tracker of the cabin's deviation from its plan (critically damped at the
        # bandwidth w: alpha = 1 - r^2, beta = (1 - r)^2 with r = exp(-w dt)).
        r = math.exp(-2 * math.pi * o.stewart_bandwidth_hz * control_dt)
        self._tracker_gains = (1.0 - r * r, (1.0 - r) ** 2 / control_dt)
        self.stewart_deviation = np.zeros(6)
        self.stewart_rate = np.zeros(6)
        self.cable_ids, self.ab_ids = nominal.cable_ids, nominal.ab_ids
        self.leg_ids, self.multifeed_id = nominal.leg_ids, nominal.multifeed_id
        kp_leg, kv_leg = nominal.drive_gains(self.leg_ids)
        if not fused:
            self.stewart_lead = specs["cabin_pose"].latency_s + float(np.mean(kv_leg / kp_leg))
        self.ab_integral = np.zeros(2)
        self._ab_gain = control_dt / o.ab_integral_s
        self.leg_integral = np.zeros(6)
        self._leg_gain = control_dt / o.leg_integral_s
        self._leg_target = np.zeros(6)
        self.dt = control_dt
        self._kp_ab, _ = nominal.drive_gains(self.ab_ids)
        # The fused measurement system (planbench.fast.measurement.FusedSensors): the cable loop on
        # the cabin's fused estimate at its fixes' rate, the stabilizer closed on the
        # platform's; otherwise the idealized pair of cabin-pose measurements.
        self.fused = fused
        if fused:
            self._setup_fused(specs, control_dt)
        self.command = command = context.command
        # The tick's writes through views where the actuators are runs (FastPhysics' are).
        self._cables, self._ab, self._legs = (
            index_view(self.cable_ids),
            index_view(self.ab_ids),
            index_view(self.leg_ids),
        )
        self._last_row = self.reference.t.shape[0] - 1
        self._count_key = "cabin_rtk_count" if fused else "cabin_pose_ts_count"
        self._load_plan(0)
        command[self.cable_ids] = self.l0_ff[0]
        command[self.ab_ids] = self.ab_setpoint[0]
        command[self.leg_ids] = 0.0
        command[self.multifeed_id] = self.state.multifeed[0]

    def _plan_rows(self, start: int, stop: int) -> PlanRows:
        """The plan's per-tick arrays at the ticks ``start`` to ``stop`` (exclusive): the
        reference's state (the cabin pose, A-B angles, tensions that go with it), the winch
        feed-forward (the unstretched lengths that give the planned chords under the planned
        tensions: stretch and sag), the platform's planned pose, the A-B angles and their
        servo set-points (less the gravity droop), the legs' planned lengths (fused path)."""
        g = fast.FAST
        state = fast_plan.reference_state(self.reference.rows(start, stop))
        r_platform = np.einsum(
            "nij,njk->nik", state.cabin_rotation, fast.ab_rotation(state.theta_a, state.theta_b, g.alpha)
        )
        p_platform = state.feed - np.einsum("nij,j->ni", r_platform, g.r_s_feed)
        ab_reference = np.column_stack([state.theta_a, state.theta_b])
        legs_plan = None
        if self.fused:
            r_base = r_platform  # the base (AB) frame's planned rotation is the platform's
            p_base = state.cabin_origin + np.einsum("nij,j->ni", state.cabin_rotation, g.ab_center)
            position = np.einsum("nji,nj->ni", r_base, p_platform - p_base)
            rotation = np.einsum("nji,njk->nik", r_base, r_platform)
            legs_plan = (
                leg_lengths(fast.STEWART.base_anchors, fast.STEWART.platform_anchors, position, rotation)
                - self.nominal_legs
            )
        return PlanRows(
            start,
            state,
            winch_feedforward(state, self.tower_tops),
            r_platform,
            p_platform,
            ab_reference,
            ab_reference - ab_gravity_torque(state) / self._kp_ab,
            legs_plan,
        )

    def _load_plan(self, tick: int) -> None:
        """Hold the plan's rows from PLAN_HISTORY_TICKS before ``tick`` to PLAN_BLOCK_TICKS
        after it (the run's last row at most): the arrays the ticks index (``state``,
        ``l0_ff``, ...) are these rows, tick ``i`` at row ``i - plan_start``."""
        start = max(0, tick - PLAN_HISTORY_TICKS)
        rows = self._plan_rows(start, min(tick + PLAN_BLOCK_TICKS, self._last_row + 1))
        self.plan_start, self._plan_end = rows.start, rows.start + rows.l0_ff.shape[0]
        self.state, self.l0_ff = rows.state, rows.l0_ff
        self.r_platform, self.p_platform = rows.r_platform, rows.p_platform
        self.ab_reference, self.ab_setpoint, self.legs_plan = rows.ab_reference, rows.ab_setpoint, rows.legs_plan

    def _planned_cabin(self, tick: int):
        """(origin (3,), rotation (3, 3)) of the planned cabin pose at ``tick``, which may lie
        before the rows held (an old fix's time): then from the plan's row computed alone."""
        row = tick - self.plan_start
        if row >= 0:
            s = self.state
            return s.cabin_origin[row], s.cabin_rotation[row]
        s = self._plan_rows(tick, tick + 1).state
        return s.cabin_origin[0], s.cabin_rotation[0]

    def _cable_feedback(self, obs) -> None:
        origin, rotation = self._planned_cabin(int(round(obs["cabin_pose_ts_time"][0] / self.dt)))
        pos, rot = obs["cabin_pose_ts_position"], obs["cabin_pose_ts_rotation"]
        # Rotation error: the small rotation that turns the measured attitude to the planned one.
        self._pid(np.concatenate([origin - pos, vee(rotation @ rot.T)]), self.pose_dt)

    def _pid(self, error: np.ndarray, dt: float) -> None:
        """The cable loop's pose correction from the cabin's pose error (6,) (planned less
        measured: m and rad) of a fix ``dt`` s after the last: kp e + kd de/dt (first-order
        filtered) + ki int e."""
        o = self.options
        if self.last_error is not None:
            alpha = dt / (o.derivative_filter_s + dt)
            self.derivative += alpha * ((error - self.last_error) / dt - self.derivative)
        self.last_error = error
        self.integral += error * dt
        self.correction = o.kp * error + o.kd * self.derivative + o.ki * self.integral

    def _setup_fused(self, specs, control_dt: float) -> None:
        """The fused path's gains (its plan, the legs' planned lengths: ``_plan_rows``): the
        legs' Jacobian at the nominal pose, dl = J dx for a platform motion dx = (dp, dtheta) in
        the base frame (J = -A^T, A the structure matrix, planbench.planners.legs), and the
        integral gain 2 pi f dt."""
        g = fast.FAST
        self.platform_jacobian = -structure_matrix(
            fast.STEWART.base_anchors, fast.STEWART.platform_anchors, g.r_ab_s, np.eye(3)
        ).T
        self._platform_gain = 2 * math.pi * self.options.platform_bandwidth_hz * control_dt
        self.platform_correction = np.zeros(6)
        self.cabin_fix_dt = max(1, int(round(1.0 / (specs["cabin_rtk"].rate_hz * control_dt)))) * control_dt

    def _fused_cable_feedback(self, obs, tick: int) -> None:
        """Integral (and optional proportional-derivative) action on the cabin's fused
        estimate, at each GPS/RTK fix's arrival: the estimate of the present tick."""
        s, row = self.state, tick - self.plan_start
        pos, rot = obs["cabin_estimate_position"], obs["cabin_estimate_rotation"]
        self._pid(np.concatenate([s.cabin_origin[row] - pos, vee(s.cabin_rotation[row] @ rot.T)]), self.cabin_fix_dt)

    def _fused_stewart_legs(self, obs, nxt: int) -> np.ndarray:
        """Leg length changes (6,): the planned ones plus an integral of the platform's error
        (its planned pose less the fused estimate, in the base frame of the cabin's estimate
        and the A-B encoders) through the legs' Jacobian, bounded by the stroke."""
        pos, rot = obs["platform_estimate_position"], obs["platform_estimate_rotation"]
        r_base = obs["cabin_estimate_rotation"] @ obs["ab_rotation"]
        error = np.concatenate([r_base.T @ (self.p_platform[nxt] - pos), r_base.T @ vee(self.r_platform[nxt] @ rot.T)])
        stroke = fast.STEWART.stroke
        # np.minimum / np.maximum: np.clip's values at a fifth of its call cost
        self.platform_correction = np.minimum(
            np.maximum(self.platform_correction + self._platform_gain * (self.platform_jacobian @ error), -stroke),
            stroke,
        )
        return self.legs_plan[nxt] + self.platform_correction

    def _fused_legs(self, obs, nxt: int) -> None:
        """The legs' set-point rates with the fused measurement system: the stabilizer's
        lengths (``_fused_stewart_legs``), or off, nominal with integral action on the
        encoders as the idealized path's."""
        if self.options.stewart:
            setpoint = self._fused_stewart_legs(obs, nxt)
        else:
            self.leg_integral = np.clip(
                self.leg_integral + self._leg_gain * (-obs["leg_positions"]),
                -0.05 * fast.STEWART.stroke,
                0.05 * fast.STEWART.stroke,
            )
            setpoint = self.leg_integral
        self.command[self._legs] = (setpoint - obs["leg_setpoints"]) / self.dt  # ramp over the tick

    def __call__(self, tick: int, obs) -> None:
        nxt = tick + 1 if tick < self._last_row else self._last_row
        if nxt >= self._plan_end:
            self._load_plan(tick)
        s, command = self.state, self.command
        # the plan's rows of this tick and the next (``_load_plan``)
        row, nxt = tick - self.plan_start, nxt - self.plan_start
        count = int(obs[self._count_key][0])
        if count != self.seen:
            self.seen = count
            if self.fused:
                self._fused_cable_feedback(obs, tick)
            else:
                self._cable_feedback(obs)
            # Cable lengths for the pose correction dx: dL = -A^T dx (planbench.planners.legs), at the
            # planned pose (it moves by millimetres between two updates).
            a = structure_matrix(
                fast.FAST.tower_anchors, fast.FAST.cabin_anchors, s.cabin_origin[row], s.cabin_rotation[row]
            )
            self.length_correction = -a.T @ self.correction
        command[self._cables] = self.l0_ff[nxt] + self.length_correction
        # A-B rotator: position servo with integral action on the encoder error.
        self.ab_integral += self._ab_gain * (self.ab_reference[row] - obs["ab_angles"])
        command[self._ab] = self.ab_setpoint[nxt] + self.ab_integral
        command[self.multifeed_id] = s.multifeed[nxt]
        if self.fused:
            return self._fused_legs(obs, nxt)
        legs = self._stewart_legs(obs, nxt) if self.options.stewart else self._leg_target
        # Leg servos: integral action on the encoders toward the last commanded lengths,
        # bounded by 5 % of the stroke (anti-windup); off, the legs hold nominal the same way.
        self.leg_integral = np.clip(
            self.leg_integral + self._leg_gain * (self._leg_target - obs["leg_positions"]),
            -0.05 * fast.STEWART.stroke,
            0.05 * fast.STEWART.stroke,
        )
        self._leg_target = legs
        setpoint = legs + self.leg_integral
        command[self._legs] = (setpoint - obs["leg_setpoints"]) / self.dt  # ramp over the tick

    def _stewart_legs(self, obs, nxt: int) -> np.ndarray:
        """Leg length changes (6,) that put the feed platform at its planned pose for the end of
        the tick, from the estimated cabin pose and the A-B encoders (inverse kinematics)."""
        s = self.state
        origin, rotation = self._planned_cabin(int(round(obs["cabin_pose_time"][0] / self.dt)))
        pos, rot = obs["cabin_pose_position"], obs["cabin_pose_rotation"]
        deviation = np.concatenate([pos - origin, vee(rot @ rotation.T)])
        alpha, beta = self._tracker_gains
        predicted = self.stewart_deviation + self.stewart_rate * self.dt
        residual = deviation - predicted
        self.stewart_deviation = predicted + alpha * residual
        self.stewart_rate = self.stewart_rate + beta * residual
        # Where the cabin will be when the legs get there: lead by latency + servo lag.
        ahead = self.stewart_deviation + self.stewart_lead * self.stewart_rate
        pos = s.cabin_origin[nxt] + ahead[:3]
        rot = (np.eye(3) + skew(ahead[3:])) @ s.cabin_rotation[nxt]
        # R_AB from the encoders: the B frame relative to the cabin.
        r_base = rot @ obs["ab_rotation"]
        p_base = pos + rot @ fast.FAST.ab_center
        # The platform's planned pose in the measured base (AB) frame, and its leg lengths;
        # beyond the stroke the actuators' ctrlrange clamps (the log keeps the demand).
        position = r_base.T @ (self.p_platform[nxt] - p_base)
        return (
            leg_lengths(
                fast.STEWART.base_anchors, fast.STEWART.platform_anchors, position, r_base.T @ self.r_platform[nxt]
            )
            - self.nominal_legs
        )
