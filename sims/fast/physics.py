"""FAST in MuJoCo: physics accessors, the cables' elastic-catenary law and the model's build.

The model is models/fast (README.md there has every number's source). The plant's loads (the
cables' tensions and weight, the wind) are sims/fast/loads.py, the controller
sims/fast/controller.py, the plant's uncertainty sims/fast/params.py (``FastPlant``).

Elastic catenary (Irvine, "Cable Structures", 1981; parabolic sag, small sag-to-span): a cable
of unstretched length L0, axial stiffness EA and weight w per length, with horizontal span
l_h, has the chord length

    L(T) = L0 (1 + T / EA) - w^2 l_h^2 L0 / (24 T^2)

at the tension T. Its tangent stiffness dT/dL = (EA / L0) / (1 + (w l_h)^2 EA / (12 T^3)) is
EA / L0 with Ernst's equivalent modulus E_eq = E / (1 + (w l_h)^2 E A / (12 T^3))
(REFERENCE.md). A cable can only pull: the actuator's force range is [-T_max, 0].
"""

from __future__ import annotations

import copy
import functools
import math
from typing import TYPE_CHECKING

import mujoco
import numpy as np
from dm_control import mujoco as dm_mujoco

from planbench import models
from planbench.planners import fast
from planbench.planners.rotations import wxyz
from planbench.wind import AIR_DENSITY

if TYPE_CHECKING:  # annotations only: sims/fast/params.py imports this module
    from planbench.fast.params import FastPlant

#: s: the default control period (50 Hz; FastParams.control_rate_hz). FAST's own rates are not
#: public; 50 Hz samples the 0.17-0.6 Hz cabin modes and the stabilizer's 2 Hz loop 25-80
#: times per period, and is six times the total stations' 8 Hz. 100 Hz (the earlier default)
#: is an option, and reproduces the earlier figures.
CONTROL_DT = 0.02
PHYSICS_DT = 0.002  # s: models/fast/fast.xml's timestep (tested); a control period is a multiple

#: Cables (REFERENCE.md): 46 mm steel wire rope, ~10 kg/m, E A = 1.5e8 N (E ~ 150 GPa on the
#: rope's metallic area; generic, not a FAST figure).
CABLE_EA = 1.5e8  # N
CABLE_WEIGHT = fast.FAST.cable_mass_per_length * fast.GRAVITY  # N/m
CABLE_DIAMETER = 0.046  # m
#: Stiffness-proportional damping of the cables, s: beta = 2 zeta / omega with zeta = 0.7 % at
#: 0.2 Hz; the model's cabin modes (0.30-0.65 Hz) then have 0.41-1.7 %, at least the measured
#: >= 0.4 % of the lowest cabin mode (REFERENCE.md).
CABLE_DAMPING_S = 2 * 0.007 / (2 * math.pi * 0.2)
#: Below this tension the catenary law is not solved further (a cable this slack is a failed
#: check long before), N.
TENSION_FLOOR = 1e3

#: Drag coefficients: a finite circular cylinder of aspect ratio 7.6 / 13 in cross flow has
#: Cd ~0.6-0.7 (Hoerner, Fluid-Dynamic Drag, ch. 3); 0.8 covers the cabin's fittings. A stranded
#: wire rope across the wind: Cd ~1.2 (ISO 4354 / EN 1991-1-4 for ropes).
CABIN_DRAG_COEFFICIENT = 0.8
CABLE_DRAG_COEFFICIENT = 1.2
CABIN_DIAMETER, CABIN_HEIGHT = 13.0, 7.6  # m (REFERENCE.md)
#: The shell's centre in the cabin frame, m (fast.xml: shell from z = -6.6 to 1.0 m).
CABIN_CENTRE = np.array([0.0, 0.0, -2.8])

CABLE_ACTUATORS = tuple(f"cable{i}" for i in range(1, 7))
AB_ACTUATORS = ("ab_a", "ab_b")
LEG_ACTUATORS = tuple(f"leg{i}" for i in range(1, 7))


# ----------------------------------------------------------------------------- cable law


def chord_factor(tension, span, ea: float = CABLE_EA, weight: float = CABLE_WEIGHT):
    """g = L / L0, the chord length over the unstretched length at ``tension`` (N) and the
    horizontal span ``span`` (m): 1 + T / EA - w^2 l_h^2 / (24 T^2)."""
    tension = np.asarray(tension, dtype=float)
    return 1.0 + tension / ea - (weight * np.asarray(span)) ** 2 / (24.0 * tension**2)


def tangent_stiffness(tension, span, unstretched, ea: float = CABLE_EA, weight: float = CABLE_WEIGHT):
    """dT/dL at fixed L0, N/m: (EA / L0) / (1 + (w l_h)^2 EA / (12 T^3)) (Ernst's E_eq A / L0)."""
    tension = np.asarray(tension, dtype=float)
    return ea / np.asarray(unstretched) / (1.0 + (weight * np.asarray(span)) ** 2 * ea / (12.0 * tension**3))


def unstretched_length(chord, tension, span, ea: float = CABLE_EA, weight: float = CABLE_WEIGHT):
    """The winch's unstretched length L0 that gives the chord ``chord`` at ``tension``, m."""
    return np.asarray(chord) / chord_factor(tension, span, ea, weight)


def catenary_tension(
    chord, unstretched, span, guess, iterations: int = 30, ea: float = CABLE_EA, weight: float = CABLE_WEIGHT
):
    """The tension (N) at which a cable of unstretched length L0 spans the chord ``chord``.

    Newton's method on L0 g(T) - L = 0 from ``guess``; g is increasing in T, so the root is
    unique (a hanging cable always carries some tension); clamped at TENSION_FLOOR.
    """
    chord, unstretched, span = (np.asarray(x, dtype=float) for x in (chord, unstretched, span))
    a = (weight * span) ** 2 * unstretched / 24.0
    t = np.maximum(np.asarray(guess, dtype=float), TENSION_FLOOR)
    for _ in range(iterations):
        f = unstretched * (1.0 + t / ea) - a / t**2 - chord
        t = np.maximum(t - f / (unstretched / ea + 2.0 * a / t**3), TENSION_FLOOR)
    return t


# ----------------------------------------------------------------------------- physics


#: The Levi-Civita symbol: sum_n a_n x b_n = einsum("ijk,nj,nk->i", ...) in one call (np.cross
#: costs ~40 us a call on these small arrays, and this runs every tick).
_LEVI_CIVITA = np.zeros((3, 3, 3))
_LEVI_CIVITA[0, 1, 2] = _LEVI_CIVITA[1, 2, 0] = _LEVI_CIVITA[2, 0, 1] = 1.0
_LEVI_CIVITA[0, 2, 1] = _LEVI_CIVITA[2, 1, 0] = _LEVI_CIVITA[1, 0, 2] = -1.0


def index_view(ids) -> slice | np.ndarray:
    """``ids`` (integer indices, (n,)) as a slice when they step evenly upward (indexing an
    array with it gives a view at a fraction of fancy indexing's cost, with the same
    elements), else as they are (negative ones too: a slice reads them otherwise)."""
    ids = np.asarray(ids)
    if ids.ndim != 1 or ids.size == 0:
        return ids
    start = int(ids[0])
    step = int(ids[1] - ids[0]) if ids.size > 1 else 1
    if start >= 0 and step > 0 and np.array_equal(ids, start + step * np.arange(ids.size)):
        return slice(start, start + step * ids.size, step)
    return ids


def moment_sum(arms: np.ndarray, forces: np.ndarray) -> np.ndarray:
    """sum_n arms_n x forces_n, (3,), for (n, 3) arrays."""
    return np.einsum("ijk,nj,nk->i", _LEVI_CIVITA, arms, forces)


def cable_drag_force(wind: np.ndarray, vectors: np.ndarray, lengths) -> np.ndarray:
    """(n, 3) drag of the wind (3,) m/s on cable pieces along ``vectors`` (n, 3) of ``lengths``
    (n,) m: 1/2 rho Cd d |u_n| u_n per metre, u_n the wind's component normal to the piece, N."""
    units = vectors / np.sqrt(np.einsum("ij,ij->i", vectors, vectors))[:, None]
    normal = wind - (units @ wind)[:, None] * units
    speed = np.sqrt(np.einsum("ij,ij->i", normal, normal))
    return (0.5 * AIR_DENSITY * CABLE_DRAG_COEFFICIENT * CABLE_DIAMETER * np.asarray(lengths) * speed)[:, None] * normal


#: Damping of the discretized cables' nodes, as the ratio it gives their first string modes
#: (~0.2 Hz): 0.5 %, the lower bound measured for the cable-cabin system (REFERENCE.md); the
#: cables' internal friction and the still air's drag are not known better.
NODE_DAMPING_RATIO = 0.006
STRING_MODE_HZ = 0.2


def node_mass_factor(segments: int) -> float:
    """A node's mass over its segment's mu L0 / n: (2 n sin(pi / 2n) / pi)^2, so that the
    beaded string's first mode, 2 sqrt(T n / (M L)) sin(pi / 2n), is the continuous string's
    pi sqrt(T / mu) / L (0.81 for two segments, 0.99 for ten)."""
    return (2 * segments * math.sin(math.pi / (2 * segments)) / math.pi) ** 2


def node_load_factor(segments: int) -> float:
    """A node's weight over its segment's mu g L0 / n: sqrt(n^2 / (n^2 - 1)), so that the
    chain's sag lengthens it as much as the uniformly loaded cable's, w^2 l_h^2 L0 / (24 T^2)
    (equal point loads W / n give that times 1 - 1 / n^2)."""
    return math.sqrt(segments**2 / (segments**2 - 1.0))


def node_gravcomp(segments: int) -> float:
    """The nodes' gravcomp: gravity pulls a node with node_load_factor / node_mass_factor of
    its weight."""
    return 1.0 - node_load_factor(segments) / node_mass_factor(segments)


def end_fraction(segments: int, load: bool) -> float:
    """The part of a cable's weight (``load``) or mass at each of its ends: what the nodes
    leave, halved."""
    node = node_load_factor(segments) if load else node_mass_factor(segments)
    return 0.5 * (1.0 - (segments - 1) * node / segments)


#: Stability of the discretized cables' explicit springs: a segment's axial mode omega
#: (2 sqrt(EA / mu) / l rad/s) must keep omega dt <= this at the model's timestep dt (20
#: segments at 1.0 diverge).
SEGMENT_OMEGA_DT_LIMIT = 0.7


def max_cable_segments(
    shortest_cable_m: float | None = None,
    timestep: float | None = None,
    ea: float = CABLE_EA,
    mass_per_length: float = fast.FAST.cable_mass_per_length,
) -> int:
    """The most segments a discretized cable may have: its segments' axial mode
    omega = 2 sqrt(EA / mu) n / L must keep omega dt <= SEGMENT_OMEGA_DT_LIMIT.

    Args:
      shortest_cable_m: the shortest cable's unstretched length L, m; default the winches' L0
        at the model's home keyframe (what ``discretized_spec`` divides). A run checks its
        own cables at its start (``ChainCableLoads.reset``).
      timestep: the physics timestep dt, s; default the model's.
      ea, mass_per_length: the cables' EA (N) and mass per length mu (kg/m); default the
        nominal ones (a perturbed plant's: ``FastPlant``).
    """
    if shortest_cable_m is None or timestep is None:
        model = _compiled(0)
        if shortest_cable_m is None:
            shortest_cable_m = float(np.min(model.key("home").ctrl[: len(CABLE_ACTUATORS)]))
        if timestep is None:
            timestep = float(model.opt.timestep)
    wave = 2.0 * math.sqrt(ea / mass_per_length)  # omega l, m/s
    return int(math.floor(SEGMENT_OMEGA_DT_LIMIT * shortest_cable_m / (wave * timestep) + 1e-9))


@functools.lru_cache(maxsize=4)
def _compiled(cable_segments: int = 0) -> mujoco.MjModel:
    """The model; with ``cable_segments`` >= 2 each cable is a chain of point masses instead
    of a straight tendon with a lumped law (``discretized_spec``)."""
    if cable_segments == 0:
        return models.load("fast")
    return discretized_spec(cable_segments).compile()


def discretized_spec(
    segments: int,
    spec: mujoco.MjSpec | None = None,
    ea: float = CABLE_EA,
    mass_per_length: float = fast.FAST.cable_mass_per_length,
) -> mujoco.MjSpec:
    """models/fast (or ``spec``, a perturbed plant's: ``FastPlant.spec``) with each cable
    discretized into ``segments`` elastic segments of the cables' ``ea`` (N) and
    ``mass_per_length`` (kg/m).

    Cable i becomes ``segments`` spatial tendons ``cable{i}_seg{k}`` joining the tower top,
    ``segments - 1`` point masses ``cable{i}_node{k}`` (three slide joints each, damped by
    ``NODE_DAMPING_RATIO`` at ``STRING_MODE_HZ``) and the cabin anchor. The segments share the
    cable's unstretched length L0 evenly (the winch pays out at the tower and the rope runs through): the winch actuator
    ``cable{i}`` drives the first (ctrl = L0), the others are springs EA / (L0 / n) of rest
    length L0 / n with stiffness-proportional damping; ``ChainCableLoads`` writes both every
    tick, and gives the nodes the mass mu L0 / n of the run's first L0. Written here for the
    home pose. The chord tendons ``cable{i}`` stay, to measure. Gravity loads the nodes
    directly, so the lumped anchor masses are emptied. Sag, its stiffness and the cables' own
    vibration come out of the chain instead of the catenary law.
    """
    if segments < 2:
        raise ValueError(f"cable segments {segments} must be >= 2 (0 for the lumped cables)")
    if spec is None:
        spec = mujoco.MjSpec.from_file(str(models.scene_path("fast")))
    home = spec.compile()  # the lumped model: its home keyframe and sites
    rest = home.key("home").ctrl[0] / segments  # the winches' unstretched length at home
    mass = node_mass_factor(segments) * mass_per_length * rest
    stiffness = ea / rest
    for i in range(1, 4):
        body = spec.body(f"anchor_mass{i}")
        body.mass, body.inertia = 1e-6, [1e-6, 1e-6, 1e-6]
    home_data = mujoco.MjData(home)
    mujoco.mj_kinematics(home, home_data)
    for i in range(1, 7):
        top = home_data.site_xpos[home.site(f"tower{i}_top").id]
        anchor = home_data.site_xpos[home.site(f"anchor{i}").id]
        sites = [f"tower{i}_top"]
        for k in range(1, segments):
            node = spec.worldbody.add_body(
                name=f"cable{i}_node{k}", pos=top + (anchor - top) * k / segments, gravcomp=node_gravcomp(segments)
            )
            for axis, label in zip(np.eye(3), "xyz", strict=True):
                node.add_joint(
                    name=f"cable{i}_node{k}_{label}",
                    type=mujoco.mjtJoint.mjJNT_SLIDE,
                    axis=axis,
                    damping=2 * NODE_DAMPING_RATIO * 2 * math.pi * STRING_MODE_HZ * mass,
                )
            node.add_geom(
                name=f"cable{i}_node{k}",
                type=mujoco.mjtGeom.mjGEOM_SPHERE,
                size=[0.3, 0, 0],
                mass=mass,
                contype=0,
                conaffinity=0,
                group=2,
                rgba=[0.12, 0.12, 0.14, 1],
            )
            node.add_site(name=f"cable{i}_node{k}")
            sites.append(f"cable{i}_node{k}")
        sites.append(f"anchor{i}")
        for k in range(1, segments + 1):
            tendon = spec.add_tendon(name=f"cable{i}_seg{k}", width=0.35, rgba=[0.12, 0.12, 0.14, 1])
            tendon.wrap_site(sites[k - 1])
            tendon.wrap_site(sites[k])
            if k > 1:
                tendon.stiffness, tendon.springlength = [stiffness, 0.0, 0.0], [rest, rest]
                tendon.damping = [CABLE_DAMPING_S * stiffness, 0.0, 0.0]
        spec.tendon(f"cable{i}").rgba = [0, 0, 0, 0]  # the chord measures, the segments show
        spec.actuator(f"cable{i}").target = f"cable{i}_seg1"
    # Keyframe home keeps qpos0: the nodes on the chords (set_configuration sags them).
    return spec


class FastPhysics(dm_mujoco.Physics):
    """dm_control Physics of models/fast/scene.xml with FAST's accessors."""

    @classmethod
    def load(cls, cable_segments: int = 0, plant: FastPlant | None = None) -> FastPhysics:
        """The model at keyframe home; ``cable_segments`` >= 2 for the discretized cables;
        ``plant`` (None or nominal: the model as it is) perturbs it (``FastPlant.model``)."""
        if plant is None or plant.is_nominal:
            model = copy.copy(_compiled(cable_segments))
        else:
            model = plant.model(cable_segments)
        physics = cls.from_model(dm_mujoco.wrapper.MjModel(model))
        physics.cable_segments = cable_segments
        physics.reset(keyframe_id=0)
        return physics

    cable_segments = 0

    # ---- indices (from the compiled model)
    def _ids(self, kind, names) -> np.ndarray:
        model = self.model.ptr
        return np.array([getattr(model, kind)(n).id for n in names])

    @functools.cached_property
    def cable_ids(self) -> np.ndarray:
        return self._ids("actuator", CABLE_ACTUATORS)

    @functools.cached_property
    def chord_tendon_ids(self) -> np.ndarray:
        """The six chord tendons, tower top to cabin anchor (named as their cables)."""
        return self._ids("tendon", CABLE_ACTUATORS)

    @functools.cached_property
    def ab_ids(self) -> np.ndarray:
        return self._ids("actuator", AB_ACTUATORS)

    @functools.cached_property
    def leg_ids(self) -> np.ndarray:
        return self._ids("actuator", LEG_ACTUATORS)

    @functools.cached_property
    def multifeed_id(self) -> int:
        return int(self.model.ptr.actuator("multifeed").id)

    @functools.cached_property
    def anchor_sites(self) -> np.ndarray:
        return self._ids("site", [f"anchor{i}" for i in range(1, 7)])

    @functools.cached_property
    def tower_tops(self) -> np.ndarray:
        """(6, 3) the cable exits on the tower tops, world, m (fixed)."""
        model, data = self.model.ptr, self.data.ptr
        mujoco.mj_kinematics(model, data)
        return data.site_xpos[self._ids("site", [f"tower{i}_top" for i in range(1, 7)])].copy()

    @functools.cached_property
    def cabin_body(self) -> int:
        return int(self.model.ptr.body("cabin").id)

    @functools.cached_property
    def ab_b_body(self) -> int:
        return int(self.model.ptr.body("ab_b").id)

    @functools.cached_property
    def feed_site(self) -> int:
        return int(self.model.ptr.site("feed").id)

    def _qpos_adr(self, joint: str) -> int:
        return int(self.model.ptr.joint(joint).qposadr[0])

    @functools.cached_property
    def ab_qpos(self) -> np.ndarray:
        return np.array([self._qpos_adr(n) for n in AB_ACTUATORS])

    @functools.cached_property
    def leg_qpos(self) -> np.ndarray:
        return np.array([self._qpos_adr(n) for n in LEG_ACTUATORS])

    @functools.cached_property
    def leg_dofs(self) -> np.ndarray:
        return np.array([self.model.ptr.joint(n).dofadr[0] for n in LEG_ACTUATORS])

    @functools.cached_property
    def leg_act(self) -> np.ndarray:
        """act index of each leg drive (its set-point)."""
        return self.model.ptr.actuator_actadr[self.leg_ids].copy()

    @functools.cached_property
    def multifeed_qpos(self) -> int:
        return self._qpos_adr("multifeed")

    def sensor_columns(self, names) -> np.ndarray:
        """sensordata indices of 1-d sensors ``names``."""
        model = self.model.ptr
        return np.array([model.sensor(n).adr[0] for n in names])

    def sensor_block(self, name: str) -> slice:
        model = self.model.ptr
        s = model.sensor(name)
        return slice(int(s.adr[0]), int(s.adr[0] + s.dim[0]))

    # ---- drive constants
    def drive_gains(self, ids) -> tuple[np.ndarray, np.ndarray]:
        """(kp, kv) of the servo drives ``ids`` (position actuators and the legs' integrator
        servos: force = kp (set-point - q) - kv qdot)."""
        model = self.model.ptr
        return model.actuator_gainprm[ids, 0].copy(), -model.actuator_biasprm[ids, 2].copy()

    def force_limit(self, ids) -> np.ndarray:
        return self.model.ptr.actuator_forcerange[ids, 1].copy()

    @property
    def tension_max(self) -> float:
        """T_max, N: the cable actuators' pull limit."""
        return float(-self.model.ptr.actuator_forcerange[self.cable_ids[0], 0])

    # ---- state
    def cable_tensions(self) -> np.ndarray:
        """(6,) cable tensions, N (pull positive): minus the cable actuators' force."""
        return -self.data.ptr.actuator_force[self.cable_ids].copy()

    def cable_lengths(self) -> np.ndarray:
        """(6,) chord lengths tower top to cabin anchor, m (MuJoCo's spatial tendons)."""
        return self.data.ptr.ten_length[self.chord_tendon_ids]

    def cabin_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """(origin (3,), rotation (3, 3)) of the cabin frame in the world."""
        data = self.data.ptr
        b = self.cabin_body
        return data.xpos[b].copy(), data.xmat[b].reshape(3, 3).copy()

    def feed_position(self) -> np.ndarray:
        return self.data.ptr.site_xpos[self.feed_site].copy()

    def ab_angles(self) -> np.ndarray:
        return self.data.ptr.qpos[self.ab_qpos].copy()

    def stewart_legs(self) -> np.ndarray:
        """(6,) leg length changes from nominal (the encoders), m."""
        return self.data.ptr.qpos[self.leg_qpos].copy()

    def subtree_mass(self, bodies) -> tuple[float, np.ndarray]:
        """(mass kg, centre of mass (3,) world) of the named bodies together (no subtrees)."""
        model, data = self.model.ptr, self.data.ptr
        ids = self._ids("body", bodies)
        mass = model.body_mass[ids]
        return float(mass.sum()), (mass[:, None] * data.xipos[ids]).sum(axis=0) / mass.sum()

    def set_configuration(self, origin, rotation, theta_a: float, theta_b: float, multifeed: float = 0.0) -> None:
        """Put the feed support at rest: cabin pose, A-B angles, Stewart legs nominal (the
        universal joints and slides at zero, the platform where the loops close)."""
        model, data = self.model.ptr, self.data.ptr
        origin = np.asarray(origin, dtype=float)
        rotation = np.asarray(rotation, dtype=float)
        data.qpos[:] = model.qpos0
        cabin = self._qpos_adr("cabin")
        data.qpos[cabin : cabin + 3] = origin
        data.qpos[cabin + 3 : cabin + 7] = wxyz(rotation)
        data.qpos[self.ab_qpos] = theta_a, theta_b
        g = fast.FAST
        r_ab = fast.ab_rotation(theta_a, theta_b, g.alpha)
        plat = self._qpos_adr("feed_platform")
        data.qpos[plat : plat + 3] = origin + rotation @ (g.ab_center + r_ab @ g.r_ab_s)
        data.qpos[plat + 3 : plat + 7] = wxyz(rotation @ r_ab)
        data.qpos[self.multifeed_qpos] = multifeed
        data.qvel[:] = 0.0
        data.act[:] = 0.0
        if self.cable_segments:
            self._sag_nodes(origin, rotation, r_ab)
        mujoco.mj_forward(model, data)

    def _sag_nodes(self, origin, rotation, r_ab) -> None:
        """Put the discretized cables' nodes on the parabola of the planner's static tension T:
        the sag below the chord at the horizontal distance x is w_h x (l_h - x) / (2 H), H the
        tension's horizontal part, w_h the weight per horizontal metre; the nodes divide its
        arc length evenly, as the segments share the unstretched length."""
        model, data = self.model.ptr, self.data.ptr
        g = fast.FAST
        tension = fast.cable_tensions(origin, rotation, g, ab_rotation=r_ab)
        anchors = origin + g.cabin_anchors @ rotation.T
        n = self.cable_segments
        # The funicular of n - 1 equal loads lies on the parabola of their mean load.
        load = node_load_factor(n) * CABLE_WEIGHT
        x = np.linspace(0.0, 1.0, 2001)
        for i in range(6):
            top, chord = g.tower_anchors[i], anchors[i] - g.tower_anchors[i]
            length, span = np.linalg.norm(chord), np.hypot(chord[0], chord[1])
            horizontal = tension[i] * span / length
            curve = top + x[:, None] * chord
            curve[:, 2] -= load * length / span * (x * span) * ((1 - x) * span) / (2 * horizontal)
            arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(curve, axis=0), axis=1))])
            for k, share in enumerate(np.arange(1, n) / n, start=1):
                point = np.array([np.interp(share * arc[-1], arc, curve[:, j]) for j in range(3)])
                body = model.body(f"cable{i + 1}_node{k}")
                adr = model.jnt_qposadr[body.jntadr[0]]
                data.qpos[adr : adr + 3] = point - model.body_pos[body.id]

    @functools.cached_property
    def node_bodies(self) -> np.ndarray:
        """(6, segments - 1) body ids of the discretized cables' nodes, tower to anchor."""
        return np.array(
            [[self.model.ptr.body(f"cable{i}_node{k}").id for k in range(1, self.cable_segments)] for i in range(1, 7)]
        )

    @functools.cached_property
    def segment_tendons(self) -> np.ndarray:
        """(6, segments) tendon ids of the discretized cables' segments, tower to anchor."""
        return np.array(
            [
                [self.model.ptr.tendon(f"cable{i}_seg{k}").id for k in range(1, self.cable_segments + 1)]
                for i in range(1, 7)
            ]
        )

    def anchor_forces(self) -> np.ndarray:
        """(6, 3) force of each cable on the cabin at its anchor, N (world)."""
        data = self.data.ptr
        anchors = data.site_xpos[self.anchor_sites]
        if not self.cable_segments:
            units = (self.tower_tops - anchors) / self.cable_lengths()[:, None]
            return self.cable_tensions()[:, None] * units
        last = self.segment_tendons[:, -1]
        model = self.model.ptr
        tension = model.tendon_stiffness[last] * (data.ten_length[last] - model.tendon_lengthspring[last, 0])
        before = data.xpos[self.node_bodies[:, -1]]
        units = (before - anchors) / np.linalg.norm(before - anchors, axis=1)[:, None]
        return tension[:, None] * units

    def loop_closure_error(self) -> float:
        """Largest violation of the Stewart's six ball constraints, m."""
        data = self.data.ptr
        rows = data.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        return float(np.abs(data.efc_pos[rows]).max()) if rows.any() else 0.0
