"""FAST in MuJoCo: physics accessors, the cables' elastic-catenary law, wind, and the controller.

The model is models/fast (README.md there has every number's source). Three pieces run once
per control tick (50 Hz by default: the scenarios' control_rate_hz), MuJoCo takes the
physics steps between them:

* ``CableLoads`` (the runner's disturbance; it is part of the plant, so a user's controller
  gets it too): each cable's tension from the elastic catenary (parabolic sag) at the current
  chord length and the winch's unstretched length, linearized into the cable actuator's gain
  and bias for the tick; half of each cable's weight at its cabin anchor; wind drag on the
  cabin and on the cables (half of each cable's drag at its anchor). ``ChainCableLoads`` does
  the same for the discretized cables (``discretized_spec``), whose chains carry sag and
  weight themselves.
* ``FastController``: winch commands (planned cable lengths less the elastic stretch and the
  sag under the planned tensions, plus feedback on the cabin pose: integral only by
  default), the A-B rotator servo (gravity feed-forward and integral action), the multi-beam
  rotation, and the Stewart stabilizer. With FAST's fused measurement system
  (sims.fast.measurement, the default) the cable loop reads the cabin's fused estimate at
  each GPS/RTK fix, and the stabilizer is an integral loop every tick on the platform's fused
  estimate (its planned pose less the estimate, through the legs' Jacobian, added to the
  legs' planned lengths). With the idealized sensors (``system = "ideal"``) it reads the
  10 Hz total-station fix with 150 ms latency, and the stabilizer leads an alpha-beta
  estimate of the cabin pose by its latency and the legs' lag into the inverse kinematics
  from the base to the planned feed pose.

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
from dataclasses import dataclass

import mujoco
import numpy as np
from dm_control import mujoco as dm_mujoco

import models
from planners import fast
from planners.fast import plan as fast_plan
from planners.errors import LimitError
from planners.legs import leg_lengths, structure_matrix
from planners.rotations import rot_y, rot_z, skew, vee, wxyz
from sims.task import Sensors, SensorSpec, nominal_copy
from sims.params import ParamError, Params, PlantParams, param
from sims.plant import set_inertial
from sims.wind import AIR_DENSITY, check_mean_speed, horizontal_direction, wind_speed_series

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


def catenary_tension(chord, unstretched, span, guess, iterations: int = 30,
                     ea: float = CABLE_EA, weight: float = CABLE_WEIGHT):
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


# ----------------------------------------------------------------------------- plant uncertainty

#: Everything the cabin carries, 30 091.8 kg (CASPR, REFERENCE.md): the shell and structure,
#: the A-B rotator, the Stewart legs, the feed platform and the receiver (models/fast/README.md).
#: The lumped cable masses (anchor_mass*) belong to the cables.
CABIN_BODIES = ("cabin", "ab_a", "ab_b", *(f"leg{i}_{part}" for i in range(1, 7) for part in ("housing", "rod")),
                "feed_platform", "receiver")
#: What bounds the tower tops' errors (assumed; no public figure): their survey and construction
#: tolerance, the guide pulleys' exit points, the >100 m towers' deflection under the cables'
#: pull (the model's towers are rigid): tens of mm; 0.1 m bounds it.
_TOWER_ERROR = dict(unit="mm", low=-100.0, high=100.0,
                    reason="survey and construction tolerance of the tower tops, the pulleys' exit points and the "
                           "towers' deflection under load: tens of mm (assumed); 0.1 m bounds it")


@dataclass(frozen=True)
class FastPlant(PlantParams):
    """FAST's plant uncertainty: how the real feed support differs from models/fast and the
    planner's FastGeometry, which the controller keeps (models/fast/README.md, "Plant
    uncertainty").

    Where each one acts: the tower tops, the cabin's masses and centre of mass, the lumped
    cable masses (``anchor_mass*``) and the Stewart legs' force limits edit the MJCF (MjSpec)
    before compiling (``spec``); the cables' EA and weight per length are constants of the
    plant's Python-side cable physics (``CableLoads``, ``ChainCableLoads``: the catenary law,
    the applied half cable weights, the chain's springs and node masses). The controller's
    winch feed-forward keeps the nominal EA and weight (``winch_feedforward``), its statics the
    nominal masses (planners.fast.FAST). A perturbed plant starts where its own static
    equilibrium lies under the nominal parked commands (``perturbed_start``).
    """

    cable_ea_error: float = param(
        0.0, f"error of the cables' axial stiffness EA ({CABLE_EA / 1e6:g} MN nominal) as a fraction", "fraction",
        low=-0.35, high=0.10, reason="steel wire rope's effective modulus is 100-160 GPa (REFERENCE.md): -33 % to "
        "+7 % of the nominal 150 GPa, rounded out")
    cable_mass_error: float = param(
        0.0, f"error of the cables' mass per length ({fast.FAST.cable_mass_per_length:g} kg/m nominal) as a fraction",
        "fraction", low=-0.2, high=0.2, reason="46 mm steel wire ropes weigh about 8.5 (six-strand) to 12 kg/m "
        "(locked coil) (rope makers' tables, assumed), +/-20 % of 10 kg/m")
    anchor_radial_error: float = param(
        0.0, "every tower top's cable exit moved outward (away from the dish axis) by this", **_TOWER_ERROR)
    anchor_height_error: float = param(0.0, "every tower top's cable exit moved up by this", **_TOWER_ERROR)
    anchor_errors: tuple[tuple[float, ...], ...] = param(
        ((0.0, 0.0, 0.0),) * 6, "each tower top's cable exit moved by (x east, y north, z up), one row per tower 1-6, "
        "added to anchor_radial_error and anchor_height_error", length=3, min_items=6, max_items=6, **_TOWER_ERROR)
    cabin_mass_error: float = param(
        0.0, "error of the mass and inertia of everything the cabin carries (30 091.8 kg: shell, A-B rotator, "
        "Stewart, feed platform, receiver) as a fraction, every part alike", "fraction", low=-0.1, high=0.1,
        reason="CASPR's 30 091.8 kg against the public '30 t'; receivers and equipment change (assumed +/-10 %)")
    cabin_com_offset: tuple[float, ...] = param(
        (0.0, 0.0, 0.0), "shift of the whole cabin's centre of mass (the shell's moves by the cabin's mass over the "
        "shell's, 1.295 times this), cabin frame (x, y, z)", "m", low=-0.5, high=0.5, length=3,
        reason="its place 1 m below the anchor plane is an assumption (planners.fast); 0.5 m, under a tenth of the "
        "cabin's 7.6 m height and 13 m diameter (assumed)")
    stewart_force_scale: float = param(
        1.0, "the Stewart legs' force limits as a fraction of their +/-30 kN rating", "fraction", low=0.5, high=1.0,
        reason="the rating is what a drive guarantees; derating (heat, supply voltage) only lowers it; half still "
        "carries the legs' largest static load, 12.4 kN (models/fast/README.md)")

    @property
    def cable_ea(self) -> float:
        """The true cables' EA, N."""
        return CABLE_EA * (1.0 + self.cable_ea_error)

    @property
    def cable_mass_per_length(self) -> float:
        """The true cables' mass per length, kg/m."""
        return fast.FAST.cable_mass_per_length * (1.0 + self.cable_mass_error)

    def tower_top_errors(self) -> np.ndarray:
        """(6, 3) how far each tower top's cable exit lies from its design position, m (world):
        radially outward, up, and the per-tower table."""
        radial = fast.FAST.tower_anchors[:, :2] / np.linalg.norm(fast.FAST.tower_anchors[:, :2], axis=1)[:, None]
        error = np.asarray(self.anchor_errors, dtype=float).copy()
        error[:, :2] += self.anchor_radial_error * radial
        error[:, 2] += self.anchor_height_error
        return 1e-3 * error

    def spec(self) -> mujoco.MjSpec:
        """models/fast/scene.xml edited into this plant (MjSpec): site_pos of ``tower{i}_top``
        moved by ``tower_top_errors`` (the towers' bodies are not rotated); body_mass and
        body_inertia of CABIN_BODIES times (1 + cabin_mass_error) (explicit inertials, the
        same centres of mass and principal axes); the shell's (``cabin``) body_ipos moved by
        cabin_com_offset times the cabin's mass over the shell's (the whole cabin's centre
        of mass moves by cabin_com_offset); body_mass of ``anchor_mass1..3`` (a third of two
        cables' mass each) times (1 + cable_mass_error); actuator_forcerange of the legs times
        stewart_force_scale. MuJoCo derives the rest (subtree masses, qM at qpos0, the cable
        tendons' lengths at qpos0) from them."""
        nominal = _compiled(0)
        spec = mujoco.MjSpec.from_file(str(models.scene_path("fast")))
        for i, error in enumerate(self.tower_top_errors(), start=1):
            site = spec.site(f"tower{i}_top")
            site.pos = nominal.site_pos[nominal.site(f"tower{i}_top").id] + error
        ids = [nominal.body(b).id for b in CABIN_BODIES]
        ratio = nominal.body_mass[ids].sum() / nominal.body_mass[nominal.body("cabin").id]
        for body in CABIN_BODIES:
            set_inertial(spec, nominal, body, 1.0 + self.cabin_mass_error,
                         ratio * np.asarray(self.cabin_com_offset) if body == "cabin" else None)
        for i in range(1, 4):
            spec.body(f"anchor_mass{i}").mass = nominal.body_mass[nominal.body(f"anchor_mass{i}").id] * (
                1.0 + self.cable_mass_error)
        for name in LEG_ACTUATORS:
            spec.actuator(name).forcerange = nominal.actuator_forcerange[nominal.actuator(name).id] * \
                self.stewart_force_scale
        return spec

    def model(self, cable_segments: int = 0) -> mujoco.MjModel:
        """The plant's compiled model (``spec``); ``cable_segments`` >= 2: with its cables
        discretized (``discretized_spec``, with this plant's EA and mass per length)."""
        spec = self.spec()
        if cable_segments:
            spec = discretized_spec(cable_segments, spec, self.cable_ea, self.cable_mass_per_length)
        return spec.compile()

    def loads(self, cable_segments: int = 0, **wind) -> "CableLoads":
        """The plant's cable physics and wind (CableLoads, or ChainCableLoads for the
        discretized cables) with this plant's EA and mass per length; ``wind``: CableLoads'
        wind arguments."""
        kind = ChainCableLoads if cable_segments else CableLoads
        return kind(**wind, ea=self.cable_ea, mass_per_length=self.cable_mass_per_length)

    def check_segments(self, cable_segments: int) -> None:
        """A ParamError naming the keys when the plant's stiffer or lighter cables vibrate beyond
        the timestep's limit with ``cable_segments`` segments (``max_cable_segments``)."""
        if cable_segments:
            most = max_cable_segments(ea=self.cable_ea, mass_per_length=self.cable_mass_per_length)
            if cable_segments > most:
                raise ParamError(f"cable_segments = {cable_segments} with plant.cable_ea_error = "
                                 f"{self.cable_ea_error:g} and plant.cable_mass_error = {self.cable_mass_error:g}: "
                                 f"the segments vibrate beyond the timestep's limit omega dt <= "
                                 f"{SEGMENT_OMEGA_DT_LIMIT:g}; use at most {most}")


# ----------------------------------------------------------------------------- physics


#: The Levi-Civita symbol: sum_n a_n x b_n = einsum("ijk,nj,nk->i", ...) in one call (np.cross
#: costs ~40 us a call on these small arrays, and this runs every tick).
_LEVI_CIVITA = np.zeros((3, 3, 3))
_LEVI_CIVITA[0, 1, 2] = _LEVI_CIVITA[1, 2, 0] = _LEVI_CIVITA[2, 0, 1] = 1.0
_LEVI_CIVITA[0, 2, 1] = _LEVI_CIVITA[2, 1, 0] = _LEVI_CIVITA[1, 0, 2] = -1.0


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


def max_cable_segments(shortest_cable_m: float | None = None, timestep: float | None = None,
                       ea: float = CABLE_EA, mass_per_length: float = fast.FAST.cable_mass_per_length) -> int:
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
            shortest_cable_m = float(np.min(model.key("home").ctrl[:len(CABLE_ACTUATORS)]))
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


def discretized_spec(segments: int, spec: mujoco.MjSpec | None = None, ea: float = CABLE_EA,
                     mass_per_length: float = fast.FAST.cable_mass_per_length) -> mujoco.MjSpec:
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
            node = spec.worldbody.add_body(name=f"cable{i}_node{k}", pos=top + (anchor - top) * k / segments,
                                           gravcomp=node_gravcomp(segments))
            for axis, label in zip(np.eye(3), "xyz"):
                node.add_joint(name=f"cable{i}_node{k}_{label}", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=axis,
                               damping=2 * NODE_DAMPING_RATIO * 2 * math.pi * STRING_MODE_HZ * mass)
            node.add_geom(name=f"cable{i}_node{k}", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.3, 0, 0],
                          mass=mass, contype=0, conaffinity=0, group=2, rgba=[0.12, 0.12, 0.14, 1])
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
    def load(cls, cable_segments: int = 0, plant: "FastPlant | None" = None) -> "FastPhysics":
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
        return self.data.ptr.ten_length[:6].copy()

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

    def set_configuration(self, origin, rotation, theta_a: float, theta_b: float,
                          multifeed: float = 0.0) -> None:
        """Put the feed support at rest: cabin pose, A-B angles, Stewart legs nominal (the
        universal joints and slides at zero, the platform where the loops close)."""
        model, data = self.model.ptr, self.data.ptr
        origin = np.asarray(origin, dtype=float)
        rotation = np.asarray(rotation, dtype=float)
        data.qpos[:] = model.qpos0
        cabin = self._qpos_adr("cabin")
        data.qpos[cabin:cabin + 3] = origin
        data.qpos[cabin + 3:cabin + 7] = wxyz(rotation)
        data.qpos[self.ab_qpos] = theta_a, theta_b
        g = fast.FAST
        r_ab = fast.ab_rotation(theta_a, theta_b, g.alpha)
        plat = self._qpos_adr("feed_platform")
        data.qpos[plat:plat + 3] = origin + rotation @ (g.ab_center + r_ab @ g.r_ab_s)
        data.qpos[plat + 3:plat + 7] = wxyz(rotation @ r_ab)
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
                data.qpos[adr:adr + 3] = point - model.body_pos[body.id]

    @functools.cached_property
    def node_bodies(self) -> np.ndarray:
        """(6, segments - 1) body ids of the discretized cables' nodes, tower to anchor."""
        return np.array([[self.model.ptr.body(f"cable{i}_node{k}").id for k in range(1, self.cable_segments)]
                         for i in range(1, 7)])

    @functools.cached_property
    def segment_tendons(self) -> np.ndarray:
        """(6, segments) tendon ids of the discretized cables' segments, tower to anchor."""
        return np.array([[self.model.ptr.tendon(f"cable{i}_seg{k}").id for k in range(1, self.cable_segments + 1)]
                         for i in range(1, 7)])

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


# ----------------------------------------------------------------------------- the plant's loads


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
      spectrum: "kaimal" or "davenport" (sims.wind).
      turbulence_intensity: sigma_u / U; None: the spectrum's own (sims.wind.wind_speed_series).
      measured: a sims.wind.MeasuredWind record instead of the model (its speed, and its
        direction where it has one), resampled to the ticks.
      ea, mass_per_length: the true cables' EA (N) and mass per length (kg/m) for the plant's
        law and loads; default the nominal ones (a perturbed plant's: ``FastPlant``). The
        controller's feed-forward keeps the nominal ones (``winch_feedforward``).
    """

    def __init__(self, wind_speed: float = 0.0, wind_azimuth_deg: float = 0.0, spectrum: str = "kaimal",
                 turbulence_intensity: float | None = None, measured=None, ea: float = CABLE_EA,
                 mass_per_length: float = fast.FAST.cable_mass_per_length):
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
        self.force = None  # (n, 3) wind force on cabin and cables, N (logged)
        self.tension = None  # (6,) the catenary tensions of the current tick, N
        self.tension_log = None  # (n, 6) per tick, before the actuator's force clamp

    def reset(self, physics: FastPhysics, times: np.ndarray, rng: np.random.Generator) -> None:
        if self.measured is None:
            self.speed = wind_speed_series(times, self.mean_speed, rng, self.spectrum,
                                           turbulence_intensity=self.turbulence_intensity)
        else:
            self.speed, self._directions = self.measured.resample(times)
            if self._directions is not None:
                self.direction = self._directions[0]
        self.still_air = not np.any(self.speed)  # the speeds are known for the whole run
        self.force = np.zeros((times.size, 3))
        self.tension_log = np.zeros((times.size, 6))
        model, data = physics.model.ptr, physics.data.ptr
        self._model, self._data = model, data
        self._cables = physics.cable_ids
        self._sites = physics.anchor_sites
        self._towers = physics.tower_tops
        self._cabin = physics.cabin_body
        self._xfrc = data.xfrc_applied[self._cabin]
        mujoco.mj_forward(model, data)
        chord, span, _ = self._geometry()
        self.tension = catenary_tension(chord, data.ctrl[self._cables], span, np.full(6, 150e3), iterations=60,
                                        ea=self.ea, weight=self.weight)
        self.apply(physics)

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
            self.tension_log[tick] = t
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
            self.force[tick] = cable_drag.sum(axis=0) + force
            anchor_force += cable_drag
        self._xfrc[:3] = anchor_force.sum(axis=0) + force
        self._xfrc[3:] = moment_sum(arms, anchor_force) + torque

    def _cabin_drag(self, u: float):
        """(force (3,), torque (3,) about the cabin body's centre of mass) of the wind speed
        ``u`` on the cabin: a cylinder of its size along its z axis, drag at the shell's centre."""
        data = self._data
        rotation = data.xmat[self._cabin].reshape(3, 3)
        cos_t = min(abs(float(rotation[:, 2] @ self.direction)), 1.0)
        area = CABIN_DIAMETER * CABIN_HEIGHT * math.sqrt(1.0 - cos_t * cos_t) + \
            math.pi * CABIN_DIAMETER**2 / 4.0 * cos_t
        drag = 0.5 * AIR_DENSITY * CABIN_DRAG_COEFFICIENT * area * abs(u) * u * self.direction
        centre = data.xpos[self._cabin] + rotation @ CABIN_CENTRE - data.xipos[self._cabin]
        return drag, moment_sum(centre[None], drag[None])

    def __call__(self, tick: int, physics) -> None:
        if self._directions is not None:
            self.direction = self._directions[tick]
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
            raise LimitError(f"cable segments {n}: the shortest segment ({rest.min():.1f} m) vibrates at "
                             f"{omega / (2 * math.pi):.0f} Hz, beyond the {1e3 * model.opt.timestep:g} ms "
                             f"timestep's limit omega dt <= {SEGMENT_OMEGA_DT_LIMIT:g}; use at most "
                             f"{most} segments")
        self._anchor_masses = np.array([model.body(f"anchor_mass{i + 1}").id for i in range(3)])
        self._node_dofs = model.body_dofadr[self._nodes][..., None] + np.arange(3)  # (6, n - 1, 3)
        self.settling_damping = np.zeros(self._node_dofs.shape)  # N s/m on the nodes (static_equilibrium's)
        tick = float(times[1] - times[0]) if times.size > 1 else self.GEOMETRY_S
        self.geometry_ticks = max(1, int(round(self.GEOMETRY_S / tick)))
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
        mass = node_mass_factor(n) * self.mass_per_length * rest  # (6,)
        model.body_mass[self._nodes] = mass[:, None]
        model.dof_damping[self._node_dofs] = ((2 * NODE_DAMPING_RATIO * 2 * math.pi * STRING_MODE_HZ * mass)[:, None, None]
                                              + self.settling_damping)
        ends = end_fraction(n, load=False) * self.mass_per_length * rest * n
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
        ids = self._cables
        self._rest = rest = data.ctrl[ids] * (1.0 / self._n)  # (6,) every segment's unstretched length
        refresh = tick is None or tick % self.geometry_ticks == 0 or self._directions is not None
        if refresh:
            self._refresh(rest)
        # The winch's segment: force = (k / n) L0 - k L1 - beta k L1' (k frozen between
        # refreshes, so L0 itself moves its rest length); the others: springs of rest l.
        model.tendon_lengthspring[self._passive] = rest[self._passive_cable, None]
        self.tension = np.maximum(self._k * (data.ten_length[self._first] - rest), 0.0)
        if tick is not None:
            self.tension_log[tick] = self.tension
        u = 0.0 if tick is None else float(self.speed[tick])
        scale = u * abs(u)  # drag goes with u |u|
        if u != 0.0:
            np.multiply(self._node_drag, scale, out=self._node_force)
            data.xfrc_applied[self._node_ids, :3] = self._node_force
            self.force[tick] = scale * self._total_drag
        np.add(self._static_wrench, scale * self._drag_wrench, out=self._xfrc)

    def _refresh(self, rest: np.ndarray) -> None:
        """The slowly changing parts (GEOMETRY_S): the springs' stiffness and damping, the
        end weights' force and moment on the cabin, and the drag per unit of u |u| on every
        node, on the cabin and in all."""
        model, data = self._model, self._data
        ids, n = self._cables, self._n
        self._k = k = self.ea / np.maximum(rest, 1e-3)
        self._set_masses(rest)
        model.actuator_gainprm[ids, 0] = k / n
        model.actuator_biasprm[ids, 0] = 0.0
        model.actuator_biasprm[ids, 1] = -k
        model.actuator_biasprm[ids, 2] = -CABLE_DAMPING_S * k
        model.tendon_stiffness[self._passive] = k[self._passive_cable]
        model.tendon_damping[self._passive] = CABLE_DAMPING_S * k[self._passive_cable]
        anchors = data.site_xpos[self._sites]
        arms = anchors - data.xipos[self._cabin]
        weight = np.zeros((6, 3))
        weight[:, 2] = -end_fraction(n, load=True) * self.weight * rest * n
        self._static_wrench = np.concatenate([weight.sum(axis=0), moment_sum(arms, weight)])
        if self.still_air:
            self._drag_wrench = np.zeros(6)
            return
        nodes = data.xpos[self._nodes]  # (6, n - 1, 3)
        points = np.concatenate([self._towers[:, None], nodes, anchors[:, None]], axis=1)
        pieces = np.diff(points, axis=1)  # (6, n, 3) segment vectors
        drag = cable_drag_force(self.direction, pieces.reshape(-1, 3), np.repeat(rest, n)).reshape(6, n, 3)
        self._node_drag = (0.5 * (drag[:, :-1] + drag[:, 1:])).reshape(-1, 3)  # half of each neighbour
        self._node_force = np.empty_like(self._node_drag)
        anchor = 0.5 * drag[:, -1]
        cabin_force, cabin_torque = self._cabin_drag(1.0)
        self._drag_wrench = np.concatenate([anchor.sum(axis=0) + cabin_force, moment_sum(arms, anchor) + cabin_torque])
        self._total_drag = drag.sum(axis=(0, 1)) - 0.5 * drag[:, 0].sum(axis=0) + cabin_force


# ----------------------------------------------------------------------------- a perturbed start

#: Settling a plant into its static equilibrium (``static_equilibrium``): extra damping
#: 2 omega M_ii on the cabin's six degrees of freedom, omega at its lowest mode (heave,
#: 0.30 Hz, models/fast/README.md), and on the discretized cables' nodes at their string mode
#: (STRING_MODE_HZ), M_ii the mass matrix's diagonal: every mode then decays at least as
#: exp(-omega t). Damping acts on velocities only, so the plant comes to rest where it would
#: without it. It is at rest when no joint moves faster than SETTLE_SPEED (m/s, rad/s: 1 um/s
#: is a micrometre of creep per second), within SETTLE_MAX_S.
SETTLE_CABIN_HZ = 0.30
SETTLE_SPEED = 1e-6
SETTLE_MAX_S = 60.0
SETTLE_DT = 0.01  # s: the loads' tick while settling (the earlier control tick; the settled state does not depend on it)


def static_equilibrium(physics: FastPhysics, loads: CableLoads, max_duration: float = SETTLE_MAX_S) -> np.ndarray:
    """The qpos (nq,) where ``physics`` comes to rest from its present state under its present
    commands (ctrl, act) and the cable physics of ``loads`` (made without wind): a copy of it
    (``physics`` is not changed) stepped with the damping above until at rest. A LimitError
    when it does not come to rest within ``max_duration`` s (a cable gone slack, a drive at
    its limit)."""
    scratch = nominal_copy(physics)()
    model, data = scratch.model.ptr, scratch.data.ptr
    n = int(round(max_duration / SETTLE_DT))
    steps = int(round(SETTLE_DT / model.opt.timestep))
    loads.reset(scratch, np.arange(n + 1) * SETTLE_DT, np.random.default_rng(0))  # sets the nodes' masses
    mujoco.mj_forward(model, data)
    dense = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, dense)
    diagonal = np.diag(dense).copy()
    cabin = model.jnt_dofadr[model.joint("cabin").id] + np.arange(6)
    model.dof_damping[cabin] += 2 * (2 * math.pi * SETTLE_CABIN_HZ) * diagonal[cabin]
    if physics.cable_segments:  # the loads write the nodes' damping with their masses, from the first tick on
        nodes = model.body_dofadr[scratch.node_bodies][..., None] + np.arange(3)
        loads.settling_damping = 2 * (2 * math.pi * STRING_MODE_HZ) * diagonal[nodes]
    for tick in range(n):
        loads(tick, scratch)
        mujoco.mj_step(model, data, nstep=steps)
        if tick % 100 == 99 and float(np.abs(data.qvel).max()) < SETTLE_SPEED:
            return data.qpos.copy()
    raise LimitError(f"the plant does not come to rest within {max_duration:g} s under the parked commands "
                     f"(joint speeds up to {float(np.abs(data.qvel).max()):.3g}, more than {SETTLE_SPEED:g} m/s or "
                     "rad/s): a cable slack or a drive at its limit")


def perturbed_start(physics: FastPhysics, nominal: FastPhysics, plant: FastPlant) -> None:
    """Move the perturbed plant ``physics``, put at ``nominal``'s state and commands (the
    plan's first pose at rest, the parked winch lengths of the nominal model), to where its
    perturbation moves that state's static equilibrium, at rest: qpos = the nominal start +
    (the plant's equilibrium - the nominal model's), both under the same commands
    (``static_equilibrium``; free joints composed, mj_differentiatePos / mj_integratePos).
    A machine parked under the operator's nominal winch lengths stands there: a heavier cabin
    lower, one on softer cables lower still. Released from the nominal pose it would instead
    ring at its 0.3-0.65 Hz modes with a swing twice the offset, a start no real run has. The
    difference, not the plant's own equilibrium, so that the start tends to the nominal one as
    the perturbation vanishes (the discretized cables start off theirs by the chain's sag
    error, ``discretized_spec``)."""
    segments = physics.cable_segments
    at_rest_nominal = static_equilibrium(nominal, FastPlant().loads(segments))
    at_rest_plant = static_equilibrium(physics, plant.loads(segments))
    model, data = physics.model.ptr, physics.data.ptr
    shift = np.zeros(model.nv)
    mujoco.mj_differentiatePos(model, shift, 1.0, at_rest_nominal, at_rest_plant)
    mujoco.mj_integratePos(model, data.qpos, shift, 1.0)
    data.qvel[:] = 0.0
    mujoco.mj_forward(model, data)


# ----------------------------------------------------------------------------- control


@dataclass(frozen=True)
class ControllerOptions(Params):
    """The FAST controller's settings (typed and ranged as sims.params declares).

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
    stewart_bandwidth_hz: float = param(3.0, "bandwidth of the stabilizer's pose estimator", "Hz", low=0.0,
                                        low_open=True, high=0.5 / PHYSICS_DT, high_open=True,
                                        reason="below half the control rate (checked against the run's at the "
                                               "start)")
    kp: float = param(0.0, "cable-loop proportional gain on the cabin pose error", "", low=0.0,
                      reason="a gain, not a sign change")
    kd: float = param(0.0, "cable-loop derivative gain", "s", low=0.0, reason="a gain, not a sign change")
    ki: float = param(0.02, "cable-loop integral gain (the pose correction is kp e + kd de/dt + ki int e, mapped "
                      "to cable lengths by the Jacobian)", "1/s", low=0.0, reason="a gain, not a sign change")
    derivative_filter_s: float = param(0.05, "time constant of the first-order filter on de/dt", "s", low=0.0,
                                       reason="a time constant")
    ab_integral_s: float = param(1.0, "the A-B servo's integral time (removes what the gravity feed-forward "
                                 "leaves)", "s", low=0.0, low_open=True, reason="an integral time")
    platform_bandwidth_hz: float = param(2.0, "with the fused measurement system: bandwidth of the stabilizer's "
                                         "integral loop on the platform's fused pose estimate", "Hz", low=0.0,
                                         low_open=True, high=0.5 / PHYSICS_DT, high_open=True,
                                         reason="below half the control rate (checked against the run's at "
                                                "the start)")
    leg_integral_s: float = param(0.2, "the Stewart legs' integral time on their encoder error (removes the servo "
                                  "droop under the platform's weight, 0.2-0.7 mm at kp = 2e7 N/m)", "s", low=0.0,
                                  low_open=True, reason="an integral time")


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


def parked_command(physics: "FastPhysics", state) -> np.ndarray:
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


class FastController:
    """Winches, A-B rotator, multi-beam rotation and Stewart stabilizer (see the module doc).

    It follows the reference's feed and multi-beam channels (planners.fast.plan.PLAN_LABELS);
    the cabin pose, the A-B angles, the cable lengths and the tensions that go with them come
    from the planners' kinematics and statics (``planners.fast.plan.reference_state``), so
    any FAST trajectory can be followed. It reads the task's observation: with the fused
    measurement system (``sims.fast.measurement.FusedSensors``) the cabin's estimate for the
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
        g = fast.FAST
        control_dt = context.control_dt
        for name in ("stewart_bandwidth_hz", "platform_bandwidth_hz"):
            if getattr(o, name) >= 0.5 / control_dt:
                raise ParamError(f"ControllerOptions.{name} = {getattr(o, name):g} Hz is not below half the "
                                 f"control rate, {0.5 / control_dt:g} Hz")
        nominal = context.nominal_physics()
        self.state = state = fast_plan.reference_state(context.reference)
        specs = {s.name: s for s in context.sensors}
        # Winch feed-forward: the unstretched lengths that give the planned chords under the
        # planned tensions (stretch and sag).
        self.l0_ff = winch_feedforward(state, nominal.tower_tops)
        self.r_platform = np.einsum("nij,njk->nik", state.cabin_rotation,
                                    fast.ab_rotation(state.theta_a, state.theta_b, g.alpha))
        self.p_platform = state.feed - np.einsum("nij,j->ni", self.r_platform, g.r_s_feed)
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
        self.ab_reference = np.column_stack([state.theta_a, state.theta_b])
        kp_ab, _ = nominal.drive_gains(self.ab_ids)
        self.ab_setpoint = self.ab_reference - ab_gravity_torque(state) / kp_ab
        # The fused measurement system (sims.fast.measurement.FusedSensors): the cable loop on
        # the cabin's fused estimate at its fixes' rate, the stabilizer closed on the
        # platform's; otherwise the idealized pair of cabin-pose measurements.
        self.fused = fused
        if fused:
            self._setup_fused(specs, control_dt)
        self.command = command = context.command
        command[self.cable_ids] = self.l0_ff[0]
        command[self.ab_ids] = self.ab_setpoint[0]
        command[self.leg_ids] = 0.0
        command[self.multifeed_id] = state.multifeed[0]

    def _cable_feedback(self, obs) -> None:
        s = self.state
        j = int(round(obs["cabin_pose_ts_time"][0] / self.dt))
        pos, rot = obs["cabin_pose_ts_position"], obs["cabin_pose_ts_rotation"]
        # Rotation error: the small rotation that turns the measured attitude to the planned one.
        self._pid(np.concatenate([s.cabin_origin[j] - pos, vee(s.cabin_rotation[j] @ rot.T)]), self.pose_dt)

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
        """The fused path's plan and gains: the legs' planned lengths along the plan (the
        planned platform pose in the planned base frame), the legs' Jacobian at the nominal
        pose, dl = J dx for a platform motion dx = (dp, dtheta) in the base frame (J = -A^T,
        A the structure matrix, planners.legs), and the integral gain 2 pi f dt."""
        s, g = self.state, fast.FAST
        r_base = np.einsum("nij,njk->nik", s.cabin_rotation, fast.ab_rotation(s.theta_a, s.theta_b, g.alpha))
        p_base = s.cabin_origin + np.einsum("nij,j->ni", s.cabin_rotation, g.ab_center)
        position = np.einsum("nji,nj->ni", r_base, self.p_platform - p_base)
        rotation = np.einsum("nji,njk->nik", r_base, self.r_platform)
        self.legs_plan = leg_lengths(fast.STEWART.base_anchors, fast.STEWART.platform_anchors, position,
                                     rotation) - self.nominal_legs
        self.platform_jacobian = -structure_matrix(fast.STEWART.base_anchors, fast.STEWART.platform_anchors,
                                                   g.r_ab_s, np.eye(3)).T
        self._platform_gain = 2 * math.pi * self.options.platform_bandwidth_hz * control_dt
        self.platform_correction = np.zeros(6)
        self.cabin_fix_dt = max(1, int(round(1.0 / (specs["cabin_rtk"].rate_hz * control_dt)))) * control_dt

    def _fused_cable_feedback(self, obs, tick: int) -> None:
        """Integral (and optional proportional-derivative) action on the cabin's fused
        estimate, at each GPS/RTK fix's arrival: the estimate of the present tick."""
        s = self.state
        pos, rot = obs["cabin_estimate_position"], obs["cabin_estimate_rotation"]
        self._pid(np.concatenate([s.cabin_origin[tick] - pos, vee(s.cabin_rotation[tick] @ rot.T)]),
                  self.cabin_fix_dt)

    def _fused_stewart_legs(self, obs, nxt: int) -> np.ndarray:
        """Leg length changes (6,): the planned ones plus an integral of the platform's error
        (its planned pose less the fused estimate, in the base frame of the cabin's estimate
        and the A-B encoders) through the legs' Jacobian, bounded by the stroke."""
        pos, rot = obs["platform_estimate_position"], obs["platform_estimate_rotation"]
        r_base = obs["cabin_estimate_rotation"] @ obs["ab_rotation"]
        error = np.concatenate([r_base.T @ (self.p_platform[nxt] - pos), r_base.T @ vee(self.r_platform[nxt] @ rot.T)])
        stroke = fast.STEWART.stroke
        # np.minimum / np.maximum: np.clip's values at a fifth of its call cost
        self.platform_correction = np.minimum(np.maximum(self.platform_correction + self._platform_gain *
                                                         (self.platform_jacobian @ error), -stroke), stroke)
        return self.legs_plan[nxt] + self.platform_correction

    def _fused_legs(self, obs, nxt: int) -> None:
        """The legs' set-point rates with the fused measurement system: the stabilizer's
        lengths (``_fused_stewart_legs``), or off, nominal with integral action on the
        encoders as the idealized path's."""
        if self.options.stewart:
            setpoint = self._fused_stewart_legs(obs, nxt)
        else:
            self.leg_integral = np.clip(self.leg_integral + self._leg_gain * (-obs["leg_positions"]),
                                        -0.05 * fast.STEWART.stroke, 0.05 * fast.STEWART.stroke)
            setpoint = self.leg_integral
        self.command[self.leg_ids] = (setpoint - obs["leg_setpoints"]) / self.dt  # ramp over the tick

    def __call__(self, tick: int, obs) -> None:
        s, command = self.state, self.command
        nxt = min(tick + 1, self.l0_ff.shape[0] - 1)
        count = int(obs["cabin_rtk_count" if self.fused else "cabin_pose_ts_count"][0])
        if count != self.seen:
            self.seen = count
            if self.fused:
                self._fused_cable_feedback(obs, tick)
            else:
                self._cable_feedback(obs)
            # Cable lengths for the pose correction dx: dL = -A^T dx (planners.legs), at the
            # planned pose (it moves by millimetres between two updates).
            a = structure_matrix(fast.FAST.tower_anchors, fast.FAST.cabin_anchors, s.cabin_origin[tick],
                                 s.cabin_rotation[tick])
            self.length_correction = -a.T @ self.correction
        command[self.cable_ids] = self.l0_ff[nxt] + self.length_correction
        # A-B rotator: position servo with integral action on the encoder error.
        self.ab_integral += self._ab_gain * (self.ab_reference[tick] - obs["ab_angles"])
        command[self.ab_ids] = self.ab_setpoint[nxt] + self.ab_integral
        command[self.multifeed_id] = s.multifeed[nxt]
        if self.fused:
            return self._fused_legs(obs, nxt)
        legs = self._stewart_legs(obs, nxt) if self.options.stewart else self._leg_target
        # Leg servos: integral action on the encoders toward the last commanded lengths,
        # bounded by 5 % of the stroke (anti-windup); off, the legs hold nominal the same way.
        self.leg_integral = np.clip(self.leg_integral + self._leg_gain * (self._leg_target - obs["leg_positions"]),
                                    -0.05 * fast.STEWART.stroke, 0.05 * fast.STEWART.stroke)
        self._leg_target = legs
        setpoint = legs + self.leg_integral
        command[self.leg_ids] = (setpoint - obs["leg_setpoints"]) / self.dt  # ramp over the tick

    def _stewart_legs(self, obs, nxt: int) -> np.ndarray:
        """Leg length changes (6,) that put the feed platform at its planned pose for the end of
        the tick, from the estimated cabin pose and the A-B encoders (inverse kinematics)."""
        s = self.state
        j = int(round(obs["cabin_pose_time"][0] / self.dt))
        pos, rot = obs["cabin_pose_position"], obs["cabin_pose_rotation"]
        deviation = np.concatenate([pos - s.cabin_origin[j], vee(rot @ s.cabin_rotation[j].T)])
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
        return leg_lengths(fast.STEWART.base_anchors, fast.STEWART.platform_anchors, position,
                           r_base.T @ self.r_platform[nxt]) - self.nominal_legs
