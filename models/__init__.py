"""planbench's MJCF models, one Menagerie-style folder per mechanism.

``load(name)`` compiles ``models/<name>/scene.xml`` into a ``mujoco.MjModel``. The specs
(``loader_spec()``, ``antenna_spec()``) read dimensions and limits from the same MJCF with
ElementTree, so the planners (pure numpy) and MuJoCo share one source of truth for every
number; tests compare the planners' kinematics with MuJoCo's at random poses.
"""

from __future__ import annotations

import functools
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np

MODELS_DIR = Path(__file__).resolve().parent

#: Environment variable naming more mechanism roots (separated by os.pathsep): each holds
#: ``models/<name>/scene.xml`` and ``sims/<name>/`` (and, if it has one, ``planners/<name>/``)
#: of a mechanism of its own, found as the project's own are.
ROOTS_VARIABLE = "PLANBENCH_MECHANISMS"


def _model_folders() -> dict[str, Path]:
    folders = {path.parent.name: path.parent for path in MODELS_DIR.glob("*/scene.xml")}
    for root in filter(None, os.environ.get(ROOTS_VARIABLE, "").split(os.pathsep)):
        for path in sorted(Path(root).resolve().glob("models/*/scene.xml")):
            name = path.parent.name
            if name in folders:
                raise ValueError(f"{ROOTS_VARIABLE}: {path} names the mechanism {name!r}, already at {folders[name]}")
            folders[name] = path.parent
    return dict(sorted(folders.items()))


_FOLDERS = _model_folders()
#: Every mechanism: each folder of models/ with a scene.xml, in name order (found as MuJoCo
#: Menagerie finds its model folders, no hand list), and those of the roots that
#: PLANBENCH_MECHANISMS names. Its simulation is the package sims/<name>/.
MECHANISMS = tuple(_FOLDERS)


def extra_roots() -> tuple[Path, ...]:
    """The mechanism roots PLANBENCH_MECHANISMS names (their folders hold models/, sims/ ...)."""
    return tuple(sorted({folder.parent.parent for folder in _FOLDERS.values()} - {MODELS_DIR.parent}))


def model_dir(name: str) -> Path:
    if name not in MECHANISMS:
        raise ValueError(f"unknown model {name!r}; known models: {', '.join(MECHANISMS)}")
    return _FOLDERS[name]


def scene_path(name: str) -> Path:
    """Path of ``models/<name>/scene.xml``."""
    return model_dir(name) / "scene.xml"


def load(name: str):
    """Compile the scene of mechanism ``name`` into a ``mujoco.MjModel``."""
    import mujoco  # models/ is importable without MuJoCo for the planners' specs.

    return mujoco.MjModel.from_xml_path(str(scene_path(name)))


def _floats(text: str | None, default: tuple[float, ...]) -> np.ndarray:
    return np.array([float(v) for v in text.split()] if text else default, dtype=float)


@dataclass(frozen=True)
class JointSpec:
    """One actuated 1-dof joint of a serial chain.

    Attributes:
      name: joint (and actuator) name.
      kind: "slide" or "hinge".
      body: name of the body the joint moves.
      axis: (3,) unit joint axis in the body frame.
      lower, upper: joint range, m or rad.
      force_limit: actuator force/torque limit, N or N m.
      rate_limit: set-point rate limit of the drive, m/s or rad/s.
      kp, kv: servo stiffness (N/m or N m/rad) and damping (N s/m or N m s/rad).
    """

    name: str
    kind: str
    body: str
    axis: np.ndarray
    lower: float
    upper: float
    force_limit: float
    rate_limit: float
    kp: float
    kv: float


@dataclass(frozen=True)
class BodySpec:
    """A body of a serial chain: its fixed offset in its parent and its joint, if any.

    Attributes:
      name: body name.
      pos: (3,) origin in the parent's frame, m.
      quat: (4,) orientation in the parent's frame (w, x, y, z).
      joint: index into the chain's joints, or None for a body welded to its parent.
    """

    name: str
    pos: np.ndarray
    quat: np.ndarray
    joint: int | None


class _JointColumn:
    """Read-only attribute: the array of one JointSpec field over a chain's joints."""

    def __set_name__(self, owner, name):
        self.field = name

    def __get__(self, chain, owner=None) -> np.ndarray:
        return np.array([getattr(j, self.field) for j in chain.joints])


@dataclass(frozen=True)
class SerialChainSpec:
    """A serial chain read from an MJCF: joints in order from the base, and named sites.

    ``sites`` maps a site name to (body name, (3,) position in that body's frame, m).
    ``base_pos``/``base_quat`` place the parent of the chain's first body in the frame named
    ``frame``: the world, or a moving body above the chain (the antenna's deck).
    """

    joints: tuple[JointSpec, ...]
    bodies: tuple[BodySpec, ...]
    sites: dict
    base_pos: np.ndarray
    base_quat: np.ndarray
    frame: str = "world"

    @property
    def names(self) -> list[str]:
        return [j.name for j in self.joints]

    # Per-joint arrays, in chain order: limits (m, rad), force limits (N, N m), rate limits
    # (m/s, rad/s) and drive gains.
    lower = _JointColumn()
    upper = _JointColumn()
    force_limit = _JointColumn()
    rate_limit = _JointColumn()
    kp = _JointColumn()
    kv = _JointColumn()


def _quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product of two (w, x, y, z) quaternions."""
    aw, av = a[0], a[1:]
    bw, bv = b[0], b[1:]
    return np.concatenate([[aw * bw - av @ bv], aw * bv + bw * av + np.cross(av, bv)])


def _quat_rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate the vector v by the unit quaternion q (w, x, y, z)."""
    w, u = q[0], q[1:]
    return v + 2.0 * np.cross(u, np.cross(u, v) + w * v)


def _fixed_pose(parents: dict, base, frame: str) -> tuple[np.ndarray, np.ndarray]:
    """Pose of the body ``base`` in the frame of its ancestor body ``frame``.

    Every body from ``base`` up to (not including) ``frame`` must be welded (no joint).
    """
    path = []
    node = base
    while node.get("name") != frame:
        if node.tag != "body":
            raise ValueError(f"body {frame!r} is not an ancestor of {base.get('name')!r}")
        if node.findall("joint") or node.findall("freejoint"):
            raise ValueError(f"body {node.get('name')!r} between {frame!r} and the chain moves")
        path.append(node)
        node = parents[node]
    pos, quat = np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0])
    for node in reversed(path):
        pos = pos + _quat_rotate(quat, _floats(node.get("pos"), (0.0, 0.0, 0.0)))
        q = _floats(node.get("quat"), (1.0, 0.0, 0.0, 0.0))
        quat = _quat_mul(quat, q / np.linalg.norm(q))
    return pos, quat


def _serial_chain(xml_path: Path, root_body: str, frame: str | None = None) -> SerialChainSpec:
    """Read the serial chain below ``root_body`` (inclusive) of an MJCF.

    The model files of planbench give every position, quaternion, axis and range explicitly
    on the element (no inherited pos/axis), which is what this reader relies on; the spec
    test compares it with the compiled model. Without ``frame`` the chain's parent must be a
    child of the worldbody and ``base_pos``/``base_quat`` are its pose in the world; with
    ``frame`` (a body name) they are the parent's pose in that body's frame, composed over
    the welded bodies between them.
    """
    root = ET.parse(xml_path).getroot()
    actuators = {a.get("joint"): a for a in root.iter("general")}
    parents = {child: parent for parent in root.iter() for child in parent}
    body = next(b for b in root.iter("body") if b.get("name") == root_body)
    base = parents[body]
    if frame is None:
        if base.tag == "body" and parents[base].tag != "worldbody":
            raise ValueError(f"the parent of {root_body!r} must be a child of the worldbody")
        base_pos = _floats(base.get("pos"), (0.0, 0.0, 0.0))
        base_quat = _floats(base.get("quat"), (1.0, 0.0, 0.0, 0.0))
    else:
        base_pos, base_quat = _fixed_pose(parents, base, frame)
    joints, bodies, sites = [], [], {}
    node = body
    while node is not None:
        bodies.append(
            BodySpec(
                name=node.get("name"),
                pos=_floats(node.get("pos"), (0.0, 0.0, 0.0)),
                quat=_floats(node.get("quat"), (1.0, 0.0, 0.0, 0.0)),
                joint=len(joints) if node.findall("joint") else None,
            )
        )
        for site in node.findall("site"):
            sites[site.get("name")] = (node.get("name"), _floats(site.get("pos"), (0.0, 0.0, 0.0)))
        for joint in node.findall("joint"):
            act = actuators[joint.get("name")]
            lower, upper = _floats(joint.get("range"), (-np.inf, np.inf))
            gain = _floats(act.get("gainprm"), (1.0,))
            bias = _floats(act.get("biasprm"), (0.0, 0.0, 0.0))
            axis = _floats(joint.get("axis"), (0.0, 0.0, 1.0))
            joints.append(
                JointSpec(
                    name=joint.get("name"),
                    kind=joint.get("type", "hinge"),
                    body=node.get("name"),
                    axis=axis / np.linalg.norm(axis),
                    lower=float(lower),
                    upper=float(upper),
                    force_limit=float(_floats(act.get("forcerange"), (-np.inf, np.inf))[1]),
                    rate_limit=float(_floats(act.get("ctrlrange"), (-np.inf, np.inf))[1]),
                    kp=float(gain[0]),
                    kv=float(-bias[2]),
                )
            )
        children = node.findall("body")
        if len(children) > 1:
            raise ValueError(f"body {node.get('name')!r} of {xml_path.name} branches; not a serial chain")
        if not children:
            break
        child = children[0]
        if len(child.findall("joint")) > 1:
            raise ValueError(f"body {child.get('name')!r} has more than one joint")
        node = child
    return SerialChainSpec(
        joints=tuple(joints),
        bodies=tuple(bodies),
        sites=sites,
        base_pos=base_pos,
        base_quat=base_quat,
        frame=frame or "world",
    )


@functools.cache
def loader_spec() -> SerialChainSpec:
    """The PRR-3R loader's chain, limits and servo gains, read from models/loader/loader.xml.

    Joint order is Table 1's theta1 ... theta6 (slide, shoulder, elbow, wrist_pitch,
    wrist_yaw, wrist_roll). The chain starts at the body ``carriage``, child of ``base``.
    """
    return _serial_chain(model_dir("loader") / "loader.xml", "carriage")


@functools.cache
def antenna_spec() -> SerialChainSpec:
    """The ship antenna's 4-axis chain, limits and servo gains, from models/antenna/antenna.xml.

    Joint order is the paper's theta1 ... theta4: azimuth (about the deck's Z), elevation
    (about -X), cross_elevation (about Z of the elevation frame), polarization (about the
    boresight); f(Theta) = Rz(t1) Rx(-t2) Rz(t3) C0 Rz(t4). The chain starts at the body
    ``azimuth``; ``base_pos``/``base_quat`` place its parent, the pedestal on the mast top, in
    the ``deck`` frame (``frame == "deck"``). Azimuth and polarization are unlimited
    (lower/upper = -inf/inf); the site ``dish`` is the antenna frame at the axes' intersection.
    """
    return _serial_chain(model_dir("antenna") / "antenna.xml", "azimuth", frame="deck")
