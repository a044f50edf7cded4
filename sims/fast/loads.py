"""FAST's plant loads per control tick: the cables' catenary law, their weight and the wind.

* ``CableLoads`` (the runner's disturbance; it is part of the plant, so a user's controller
  gets it too): each cable's tension from the elastic catenary (parabolic sag) at the current
  chord length and the winch's unstretched length, linearized into the cable actuator's gain
  and bias for the tick; half of each cable's weight at its cabin anchor; wind drag on the
  cabin and on the cables (half of each cable's drag at its anchor). ``ChainCableLoads`` does
  the same for the discretized cables (``discretized_spec``), whose chains carry sag and
  weight themselves.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from planbench.fast.physics import (
    CABIN_CENTRE,
    CABIN_DIAMETER,
    CABIN_DRAG_COEFFICIENT,
    CABIN_HEIGHT,
    CABLE_DAMPING_S,
    CABLE_EA,
    CONTROL_DT,
    NODE_DAMPING_RATIO,
    SEGMENT_OMEGA_DT_LIMIT,
    STRING_MODE_HZ,
    FastPhysics,
    cable_drag_force,
    catenary_tension,
    chord_factor,
    end_fraction,
    index_view,
    max_cable_segments,
    moment_sum,
    node_mass_factor,
    tangent_stiffness,
)
from planbench.logfile import temporary_writer
from planbench.planners import fast
from planbench.planners.errors import LimitError
from planbench.wind import AIR_DENSITY, check_mean_speed, horizontal_direction, wind_speed_series

#: The winches' rope speed and acceleration limits, m/s and m/s^2 (models/fast/README.md "Winches
#: as built"): 25 % above the paper's source-switching speed of the cabin (0.4 m/s, which no
#: rope exceeds), twice its 0.025 m/s^2.
WINCH_MAX_SPEED = 0.5
_CENTRE = tuple(CABIN_CENTRE.tolist())
WINCH_MAX_ACCEL = 0.05


class Winches:
    """FAST's six winches as built: each pays its rope out or in toward the controller's command
    (the unstretched length L0, the ``ctrl`` of its cable actuator) as its drive's position loop
    does, within the drive's speed and acceleration limits.

    Per control tick the rope moves to the command when that takes at most ``max_speed`` and a
    change of speed of at most ``max_accel`` dt; otherwise at the speed a limited position loop
    takes: the command's own rate plus a closing speed min(|e| / dt, v_close(|e|)), v_close
    the speed from which ticks braking at a still close the gap e, within v_max and a change
    of speed of a dt. The rope length it reached is what the cable's law
    sees (it replaces the command in ``ctrl``). The drive's own loop is taken as faster than a
    tick (the cable's lowest mode is 0.19 Hz).

    Args:
      max_speed: m/s. max_accel: m/s^2.
    """

    def __init__(self, max_speed: float = WINCH_MAX_SPEED, max_accel: float = WINCH_MAX_ACCEL):
        self.max_speed = float(max_speed)
        self.max_accel = float(max_accel)
        self._length = None
        self._rate = None

    def reset(self, lengths: np.ndarray, dt: float) -> None:
        """Start at rest with the ropes at ``lengths`` (m), ticks of ``dt`` s."""
        self._length = [float(x) for x in np.asarray(lengths, dtype=float).ravel()]
        self._rate = [0.0] * len(self._length)
        self._last_command = list(self._length)
        self.dt = float(dt)
        self._dv = self.max_accel * self.dt

    @property
    def length(self) -> np.ndarray:
        """(6,) the ropes' lengths, m (a copy)."""
        return None if self._length is None else np.array(self._length)

    @property
    def rate(self) -> np.ndarray:
        """(6,) the ropes' speeds over the last tick, m/s (a copy)."""
        return None if self._rate is None else np.array(self._rate)

    def __call__(self, command: np.ndarray) -> None:
        """Move the ropes toward ``command`` (m, (6,)) for one tick and write where they are
        into it.

        Six ropes: Python floats, one after the other, cost a tenth of numpy's calls on
        6-vectors; each rope's arithmetic is the vectorized form's, operation for operation
        (tests/test_fast_winches.py compares them bit for bit)."""
        dt, dv, max_speed = self.dt, self._dv, self.max_speed
        wanted = command.tolist()
        length, last, old = self._length, self._last_command, self._rate
        rate = [(c - x) / dt for c, x in zip(wanted, length, strict=True)]
        self._last_command = wanted
        within = all(-max_speed <= r <= max_speed for r in rate)
        if within and all(-dv <= r - q <= dv for r, q in zip(rate, old, strict=True)):
            self._length = wanted  # within the limits: the command, to the bit
            self._rate = rate
            return
        # Toward the command moving at its own rate: the gap closes at most at the speed from
        # which ticks slowing by a dt each still close it within |e|, v = (n + f) a dt for
        # a dt^2 (n + 1) (n / 2 + f) = |e|, n whole, 0 <= f < 1.
        step = dv * dt
        new_rate = []
        for c, x, p, q in zip(wanted, length, last, old, strict=True):
            error = c - x
            size = abs(error)
            ticks = size / step
            n = (math.sqrt(1.0 + 8.0 * ticks) - 1.0) / 2.0
            n = float(math.floor(n)) if n < math.inf else n  # (a command that is not finite: NaN on)
            # (conditional expressions: what min and max return, without their calls)
            f = ticks / (n + 1.0) - n / 2.0
            f = 0.0 if 0.0 > f else f
            f = 1.0 if 1.0 < f else f
            closing = dv * (n + f)
            closing = size / dt if size / dt < closing else closing
            r = (c - p) / dt + (closing if error > 0.0 else -closing if error < 0.0 else 0.0 * closing)
            r = -max_speed if -max_speed > r else r
            r = max_speed if max_speed < r else r
            low, high = q - dv, q + dv
            r = low if low > r else r
            new_rate.append(high if high < r else r)
        self._length = length = [x + r * dt for x, r in zip(length, new_rate, strict=True)]
        self._rate = new_rate
        command[:] = length


def _run_view(array: np.ndarray, ids) -> np.ndarray | None:
    """``array[ids]`` ((m, ...) indices) as a view when the indices, flattened, are one
    ascending run (writing into it writes into ``array``); None otherwise."""
    ids = np.asarray(ids)
    run = index_view(ids.ravel())
    if not isinstance(run, slice) or run.step != 1:
        return None
    view = array[run]
    view.shape = ids.shape + array.shape[1:]  # in place: a view of a contiguous run always reshapes
    return view


class CableLoads:
    """The cables' physics and the wind, per control tick (the runner's disturbance).

    Per tick, with the winch's unstretched lengths L0 = ``ctrl`` of the cable actuators:
    the tension T at the current chord (``catenary_tension``, from the last tick's value),
    the tangent stiffness k and the chord factor g, written into the actuator's affine law so
    that over the tick force = -(T + k (L' - L) - g k (L0' - L0)) - beta k L'_dot, i.e. the
    catenary law linearized at the tick's start (the tension changes little in 20 ms); half
    of each cable's weight at its anchor; with wind: drag on the cabin (its silhouette across
    the wind at its tilt) and on each cable (the wind's component normal to the chord; half of
    the cable's drag at its anchor). All as one force and torque on the cabin body
    (``xfrc_applied``).

    Args:
      wind_speed: mean wind, m/s (0: none).
      wind_azimuth_deg: the direction the wind blows toward, deg from +x (east) toward +y.
      spectrum: "kaimal" or "davenport" (planbench.wind).
      turbulence_intensity: sigma_u / U; None: the spectrum's own (planbench.wind.wind_speed_series).
      measured: a planbench.wind.MeasuredWind record instead of the model (its speed, and its
        direction where it has one), resampled to the ticks.
      ea, mass_per_length: the true cables' EA (N) and mass per length (kg/m) for the plant's
        law and loads; default the nominal ones (a perturbed plant's: ``FastPlant``). The
        controller's feed-forward keeps the nominal ones (``winch_feedforward``).
      winches: the winches as built (``Winches``) between the command and the ropes; None: the
        ideal winches, whose ropes are the command.
    """

    def __init__(
        self,
        wind_speed: float = 0.0,
        wind_azimuth_deg: float = 0.0,
        spectrum: str = "kaimal",
        turbulence_intensity: float | None = None,
        measured=None,
        ea: float = CABLE_EA,
        mass_per_length: float = fast.FAST.cable_mass_per_length,
        winches: Winches | None = None,
    ):
        self.winches = winches
        self.ea = float(ea)
        self.mass_per_length = float(mass_per_length)
        self.weight = self.mass_per_length * fast.GRAVITY  # N/m; CABLE_WEIGHT at the nominal mass
        self.mean_speed = check_mean_speed(wind_speed) if measured is None else float(np.mean(measured.speed))
        self.direction = horizontal_direction(wind_azimuth_deg)
        self.spectrum = spectrum
        self.turbulence_intensity = turbulence_intensity
        self.measured = measured
        self._directions = None
        self.speed = None
        self.tension = None  # (6,) the catenary tensions of the current tick, N
        # Per tick, streamed to a file of their own (``log``): "tension" (6,) N, before the
        # actuator's force clamp; "force" (3,) N, the wind's on cabin and cables.
        self.records = None

    def reset(self, physics: FastPhysics, times: np.ndarray, rng: np.random.Generator) -> None:
        if self.measured is None:
            self.speed = wind_speed_series(
                times, self.mean_speed, rng, self.spectrum, turbulence_intensity=self.turbulence_intensity
            )
        else:
            self.speed, self._directions = self.measured.resample(times)
            if self._directions is not None:
                self.direction = self._directions[0]
        self.still_air = not np.any(self.speed)  # the speeds are known for the whole run
        self.records = temporary_writer({"tension": (6,), "force": (3,)}, times, prefix="planbench-loads-")
        model, data = physics.model.ptr, physics.data.ptr
        self._model, self._data = model, data
        self._cables = physics.cable_ids
        self._sites = physics.anchor_sites
        self._towers = physics.tower_tops
        self._cabin = physics.cabin_body
        self._xfrc = data.xfrc_applied[self._cabin]
        self._ropes = index_view(self._cables)  # the winches' commands in ctrl
        # A view of them where the cables' actuators are a run (None: read by index).
        self._rope_ctrl = data.ctrl[self._ropes] if isinstance(self._ropes, slice) else None
        if self.winches is not None:
            self.winches.reset(data.ctrl[self._cables], times[1] - times[0] if times.size > 1 else CONTROL_DT)
        mujoco.mj_forward(model, data)
        chord, span, _ = self._geometry()
        self.tension = catenary_tension(
            chord, data.ctrl[self._cables], span, np.full(6, 150e3), iterations=60, ea=self.ea, weight=self.weight
        )
        self.apply(physics)

    def log(self, rows: int):
        """The per-tick records of the run's first ``rows`` ticks (a ``planbench.logfile.LogFile``:
        "tension" (rows, 6) N, "force" (rows, 3) N; a tick with no wind has zero force), their
        file closed the first time."""
        return self.records.read_back(rows)

    def _geometry(self):
        data = self._data
        vectors = data.site_xpos[self._sites] - self._towers
        chord = np.sqrt(np.einsum("ij,ij->i", vectors, vectors))
        span = np.hypot(vectors[:, 0], vectors[:, 1])
        return chord, span, vectors

    def apply(self, physics, tick: int | None = None) -> None:
        """Update the cable laws and the loads for the coming tick (``tick`` None: no wind,
        nothing logged)."""
        model, data = self._model, self._data
        chord, span, vectors = self._geometry()
        l0 = data.ctrl[self._cables]
        # One Newton step from the last tick's tension: it moves by a fraction of a percent in
        # 10 ms, and Newton's error squares (the tests compare with the converged solution).
        t = catenary_tension(chord, l0, span, self.tension, iterations=1, ea=self.ea, weight=self.weight)
        self.tension = t
        if tick is not None:
            self.records.row("tension", tick)[:] = t
        k = tangent_stiffness(t, span, l0, self.ea, self.weight)
        g = chord_factor(t, span, self.ea, self.weight)
        ids = self._cables
        model.actuator_gainprm[ids, 0] = g * k
        model.actuator_biasprm[ids, 0] = -t + k * chord - g * k * l0
        model.actuator_biasprm[ids, 1] = -k
        model.actuator_biasprm[ids, 2] = -CABLE_DAMPING_S * k
        anchor_force = np.zeros((6, 3))
        anchor_force[:, 2] = -0.5 * self.weight * chord
        com = data.xipos[self._cabin]
        arms = data.site_xpos[self._sites] - com
        u = 0.0 if tick is None else float(self.speed[tick])
        force, torque = np.zeros(3), np.zeros(3)
        if u != 0.0:
            # Cables: the normal component of the wind on each chord, half the drag at the anchor.
            cable_drag = cable_drag_force(u * self.direction, vectors, 0.5 * chord)
            force, torque = self._cabin_drag(u)
            self.records.row("force", tick)[:] = cable_drag.sum(axis=0) + force
            anchor_force += cable_drag
        self._xfrc[:3] = anchor_force.sum(axis=0) + force
        self._xfrc[3:] = moment_sum(arms, anchor_force) + torque

    def _cabin_drag(self, u: float):
        """(force (3,), torque (3,) about the cabin body's centre of mass) of the wind speed
        ``u`` on the cabin: a cylinder of its size along its z axis, drag at the shell's centre."""
        data, cabin = self._data, self._cabin
        r0, r1, r2, r3, r4, r5, r6, r7, r8 = data.xmat[cabin].tolist()
        dx, dy, dz = self.direction.tolist()
        cos_t = min(abs(r2 * dx + r5 * dy + r8 * dz), 1.0)  # the cabin's axis along the wind
        area = (
            CABIN_DIAMETER * CABIN_HEIGHT * math.sqrt(1.0 - cos_t * cos_t) + math.pi * CABIN_DIAMETER**2 / 4.0 * cos_t
        )
        size = 0.5 * AIR_DENSITY * CABIN_DRAG_COEFFICIENT * area * abs(u) * u
        fx, fy, fz = size * dx, size * dy, size * dz
        # The shell's centre R c + x less the centre of mass, in floats (c = CABIN_CENTRE).
        (px, py, pz), (qx, qy, qz), (c0, c1, c2) = data.xpos[cabin].tolist(), data.xipos[cabin].tolist(), _CENTRE
        ax = px + ((r0 * c0 + r1 * c1) + r2 * c2) - qx
        ay = py + ((r3 * c0 + r4 * c1) + r5 * c2) - qy
        az = pz + ((r6 * c0 + r7 * c1) + r8 * c2) - qz
        return np.array([fx, fy, fz]), np.array([ay * fz - az * fy, az * fx - ax * fz, ax * fy - ay * fx])

    def __call__(self, tick: int, physics) -> None:
        if self._directions is not None:
            self.direction = self._directions[tick]
        if self.winches is not None:
            if self._rope_ctrl is not None:
                self.winches(self._rope_ctrl)  # in place
            else:
                ropes = self._data.ctrl[self._ropes]
                self.winches(ropes)
                self._data.ctrl[self._ropes] = ropes
        self.apply(physics, tick)


class ChainCableLoads(CableLoads):
    """The plant's loads with the discretized cables (``FastPhysics.load(cable_segments=n)``).

    The chain carries sag, cable weight and cable inertia itself; per tick this shares the
    winch command L0 (``ctrl``) among the segments: rest length l = L0 / n, stiffness EA / l
    and damping beta EA / l for the springs, and the winch segment's law force =
    (EA / l) (L0 / n - L1) - beta (EA / l) L1'; gives the nodes and ends the mass of the rope
    paid out (``_set_masses``); puts the half segment that ends at the cabin
    anchor (its weight) on the cabin; and applies the wind: on the cabin, and on every node half
    of each neighbouring segment's normal drag (half the last segment on the cabin).
    """

    def reset(self, physics: FastPhysics, times: np.ndarray, rng: np.random.Generator) -> None:
        n = physics.cable_segments
        self._n = n
        self._nodes = physics.node_bodies
        self._segments = physics.segment_tendons
        self._node_ids = self._nodes.ravel()
        self._first = self._segments[:, 0]
        self._passive = self._segments[:, 1:].ravel()
        self._passive_cable = np.repeat(np.arange(self._segments.shape[0]), n - 1)  # each passive segment's cable
        model, data = physics.model.ptr, physics.data.ptr
        rest = data.ctrl[physics.cable_ids] / n
        # A segment's axial mode, 2 sqrt(EA / mu) / l rad/s, must stay slow for the timestep
        # (the springs are explicit): ``max_cable_segments`` at this run's cables.
        most = max_cable_segments(float(rest.min()) * n, float(model.opt.timestep), self.ea, self.mass_per_length)
        if n > most:
            omega = 2.0 * math.sqrt(self.ea / self.mass_per_length) / rest.min()
            raise LimitError(
                f"cable segments {n}: the shortest segment ({rest.min():.1f} m) vibrates at "
                f"{omega / (2 * math.pi):.0f} Hz, beyond the {1e3 * model.opt.timestep:g} ms "
                f"timestep's limit omega dt <= {SEGMENT_OMEGA_DT_LIMIT:g}; use at most "
                f"{most} segments"
            )
        self._anchor_masses = np.array([model.body(f"anchor_mass{i + 1}").id for i in range(3)])
        self._node_dofs = model.body_dofadr[self._nodes][..., None] + np.arange(3)  # (6, n - 1, 3)
        self.settling_damping = np.zeros(self._node_dofs.shape)  # N s/m on the nodes (static_equilibrium's)
        tick = float(times[1] - times[0]) if times.size > 1 else self.GEOMETRY_S
        self.geometry_ticks = max(1, int(round(self.GEOMETRY_S / tick)))
        # Per tick, views where the indices allow (they do in FastPhysics' models: the
        # segments of each cable in a run, the nodes in a run): the winch segments' lengths,
        # the passive segments' rest lengths (both ends of the spring's dead band) and the
        # nodes' applied forces.
        tendons = self._segments.ravel()
        first, count = int(tendons[0]), tendons.size
        if np.array_equal(tendons, np.arange(first, first + count)):
            self._first_lengths = data.ten_length[first : first + count : n]
            self._passive_rest = model.tendon_lengthspring[first : first + count].reshape(6, n, 2)[:, 1:]
        else:
            self._first_lengths = self._passive_rest = None
        nodes = index_view(self._node_ids)
        self._node_xfrc = data.xfrc_applied[nodes, :3] if isinstance(nodes, slice) else None
        # The refresh's writes into the model, as views where the indices are runs (None: by
        # index), and its constant factors (each the product the expressions take first).
        self._node_mass_view = _run_view(model.body_mass, self._nodes)
        self._node_damping_view = _run_view(model.dof_damping, self._node_dofs)
        self._anchor_mass_view = _run_view(model.body_mass, self._anchor_masses)
        self._law_views = None
        ropes, passive = index_view(physics.cable_ids), _run_view(np.arange(model.ntendon), self._segments)
        if isinstance(ropes, slice) and ropes.step == 1 and passive is not None:
            segments = slice(int(self._segments[0, 0]), int(self._segments[-1, -1]) + 1)
            self._law_views = (
                model.actuator_gainprm[ropes, 0],
                model.actuator_biasprm[ropes, 0],
                model.actuator_biasprm[ropes, 1],
                model.actuator_biasprm[ropes, 2],
                model.tendon_stiffness[segments].reshape(6, n)[:, 1:],
                model.tendon_damping[segments].reshape(6, n)[:, 1:],
            )
        self._node_mass_factor = node_mass_factor(n) * self.mass_per_length
        self._node_damping_factor = 2 * NODE_DAMPING_RATIO * 2 * math.pi * STRING_MODE_HZ
        self._end_mass_factor = end_fraction(n, load=False) * self.mass_per_length
        self._end_weight_factor = -end_fraction(n, load=True) * self.weight
        self._points = np.empty((6, n + 1, 3))
        self._points[:, 0] = physics.tower_tops
        super().reset(physics, times, rng)

    def _set_masses(self, rest: np.ndarray) -> None:
        """The rope between tower and cabin is the winch's unstretched length L0 = n l (rest:
        (6,) l): the nodes' masses (and so their weights, through their fixed gravcomp) and
        their damping, and the ends' share at the anchors (two cables each, gravity-compensated),
        follow it as the winches pay out (a few per cent of L0 over a switch; held at the
        start's, they left the cabin 40 mm from where the catenary law puts it, tested). MuJoCo's dynamics
        read body_mass every step (body_subtreemass stays the compiled one: it only moves the
        reference point of the trees' spatial quantities, which the dynamics do not depend on)."""
        model, n = self._model, self._n
        mass = self._node_mass_factor * rest  # (6,): node_mass_factor(n) mu l
        damping = (self._node_damping_factor * mass)[:, None, None] + self.settling_damping  # 2 zeta omega m
        ends = self._end_mass_factor * rest * n  # end_fraction(n, load=False) mu L0
        if (
            self._node_mass_view is not None
            and self._node_damping_view is not None
            and self._anchor_mass_view is not None
        ):
            self._node_mass_view[...] = mass[:, None]
            self._node_damping_view[...] = damping
            self._anchor_mass_view[...] = ends[0::2] + ends[1::2]
            return
        model.body_mass[self._nodes] = mass[:, None]
        model.dof_damping[self._node_dofs] = damping
        model.body_mass[self._anchor_masses] = ends[0::2] + ends[1::2]

    #: Seconds between refreshes of what changes slowly: the springs' stiffness EA / l (l =
    #: L0 / n moves by under 1.3e-4 of itself in 0.1 s at the winches' 0.4 m/s), the
    #: directions of the segments and the cabin's tilt that shape the drag (under 1.2e-4 rad
    #: in 0.1 s), the end weights' moment, and the rope's mass and weight on the nodes and
    #: ends (``_set_masses``); a whole number of ticks, at least one. The
    #: rest lengths (the rope paying through) and the wind's speed act every tick.
    #: tests/test_fast_physics.py compares with refreshing every tick.
    GEOMETRY_S = 0.1

    def apply(self, physics, tick: int | None = None) -> None:
        model, data = self._model, self._data
        ropes = data.ctrl[self._ropes] if self._rope_ctrl is None else self._rope_ctrl
        self._rest = rest = ropes * (1.0 / self._n)  # (6,) every segment's unstretched length
        refresh = tick is None or tick % self.geometry_ticks == 0 or self._directions is not None
        if refresh:
            self._refresh(rest)
        # The winch's segment: force = (k / n) L0 - k L1 - beta k L1' (k frozen between
        # refreshes, so L0 itself moves its rest length); the others: springs of rest l.
        if self._passive_rest is not None:
            self._passive_rest[...] = rest[:, None, None]
            self.tension = np.maximum(self._k * (self._first_lengths - rest), 0.0)
        else:
            model.tendon_lengthspring[self._passive] = rest[self._passive_cable, None]
            self.tension = np.maximum(self._k * (data.ten_length[self._first] - rest), 0.0)
        if tick is not None:
            self.records.row("tension", tick)[:] = self.tension
        u = 0.0 if tick is None else float(self.speed[tick])
        scale = u * abs(u)  # drag goes with u |u|
        if u != 0.0:
            if self._node_xfrc is not None:
                np.multiply(self._node_drag, scale, out=self._node_xfrc)
            else:
                np.multiply(self._node_drag, scale, out=self._node_force)
                data.xfrc_applied[self._node_ids, :3] = self._node_force
            np.multiply(self._total_drag, scale, out=self.records.row("force", tick))
        np.add(self._static_wrench, scale * self._drag_wrench, out=self._xfrc)

    def _refresh(self, rest: np.ndarray) -> None:
        """The slowly changing parts (GEOMETRY_S): the springs' stiffness and damping, the
        end weights' force and moment on the cabin, and the drag per unit of u |u| on every
        node, on the cabin and in all."""
        model, data = self._model, self._data
        ids, n = self._cables, self._n
        self._k = k = self.ea / np.maximum(rest, 1e-3)
        self._set_masses(rest)
        if self._law_views is not None:
            gain, bias0, bias1, bias2, stiffness, damping = self._law_views
            gain[:] = k / n
            bias0[:] = 0.0
            bias1[:] = -k
            bias2[:] = -CABLE_DAMPING_S * k
            stiffness[...] = k[:, None]
            damping[...] = (CABLE_DAMPING_S * k)[:, None]
        else:
            model.actuator_gainprm[ids, 0] = k / n
            model.actuator_biasprm[ids, 0] = 0.0
            model.actuator_biasprm[ids, 1] = -k
            model.actuator_biasprm[ids, 2] = -CABLE_DAMPING_S * k
            model.tendon_stiffness[self._passive] = k[self._passive_cable]
            model.tendon_damping[self._passive] = CABLE_DAMPING_S * k[self._passive_cable]
        anchors = data.site_xpos[self._sites]
        arms = anchors - data.xipos[self._cabin]
        # The end weights -end_fraction(n, load=True) w L0, straight down: their moment about
        # the centre of mass is (sum y w, -sum x w, 0).
        weight = self._end_weight_factor * rest * n
        self._static_wrench = np.array([0.0, 0.0, weight.sum(), arms[:, 1] @ weight, -(arms[:, 0] @ weight), 0.0])
        if self.still_air:
            self._drag_wrench = np.zeros(6)
            return
        points = self._points  # (6, n + 1, 3): tower top, nodes, anchor
        points[:, 1:-1] = data.xpos[self._nodes]
        points[:, -1] = anchors
        pieces = points[:, 1:] - points[:, :-1]  # (6, n, 3) segment vectors
        drag = cable_drag_force(self.direction, pieces.reshape(-1, 3), np.repeat(rest, n)).reshape(6, n, 3)
        self._node_drag = (0.5 * (drag[:, :-1] + drag[:, 1:])).reshape(-1, 3)  # half of each neighbour
        if self._node_xfrc is None:
            self._node_force = np.empty_like(self._node_drag)
        anchor = 0.5 * drag[:, -1]
        cabin_force, cabin_torque = self._cabin_drag(1.0)
        self._drag_wrench = np.concatenate([anchor.sum(axis=0) + cabin_force, moment_sum(arms, anchor) + cabin_torque])
        self._total_drag = drag.sum(axis=(0, 1)) - 0.5 * drag[:, 0].sum(axis=0) + cabin_force
