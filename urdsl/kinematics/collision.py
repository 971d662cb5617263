"""Self-collision and cell-obstacle checks of a UR arm with coal, through Pinocchio.

Robot geometry
--------------
* UR3, UR5, UR10: the collision meshes of the example-robot-data URDFs, each replaced by its
  convex hull (coal's GJK on a hull is about 100× faster than on the triangle mesh, and a hull
  never misses a contact the mesh has: it only adds clearance in concave corners).
* Every other model: capsules along the DH geometry. In the frame of joint ``i`` (origin at
  DH frame ``i − 1``, z along the joint axis) the capsules are

  ===========  ==========================================  ================
  link         segment                                      radius
  ===========  ==========================================  ================
  base         (0, 0, 0) → (0, 0, d1 − r_s)                 r_s = 0.63·d5
  shoulder     (0, 0, d1) → (0, −s, d1)                     r_s
  upper_arm    (0, 0, s) → (a2, 0, s)                       r_u = 0.57·d5
  forearm      (0, 0, f) → (a3, 0, f), (0, 0, f) → (0, 0, s)  r_f = 0.42·d5
  wrist_1      (0, 0, f) → (0, 0, d4)                       r_w = 0.48·d5
  wrist_2      (0, 0, 0) → (0, 0, d5)                       r_w
  wrist_3      (0, 0, 0) → (0, 0, d6)                       0.40·d5
  ===========  ==========================================  ================

  with the upper-arm plane at ``s = 1.2·d4`` and the forearm plane at ``f = 0.15·d4`` along
  the shoulder axis. The ratios are those of the UR5 in ROS-Industrial's ur_description
  (shoulder offset 0.13585 m, elbow offset 0.1197 m, link radii 0.060/0.054/0.040/0.045 m for
  d4 = 0.10915 m, d5 = 0.09465 m), scaled to each model: an approximation, not UR's shapes.
* ``tool``: with a tool radius and a TCP, a capsule from the flange to the TCP point.

Which pairs are checked
-----------------------
Every robot link against every obstacle, except the base (it stands on its mount), and every
pair of links except neighbours in the chain and the pairs example-robot-data's SRDF also
leaves out (base/upper_arm, forearm/wrist_2, forearm/wrist_3, wrist_1/wrist_3; wrist_2/tool).

Distances are signed (coal): negative when two bodies overlap (penetration depth), in m.

Cell file (TOML, obstacles in the robot's Base frame; m, rad)::

    [floor]                    # a solid half-space below z = height (default 0)
    height = 0.0

    [[plane]]                  # solid where normal·x ≤ offset (the normal points to the free side)
    name = "wall"
    normal = [-1.0, 0.0, 0.0]
    offset = -0.8

    [[box]]
    name = "table"
    size = [1.2, 0.8, 0.04]            # full edge lengths x, y, z
    pose = [0.6, 0.0, -0.02, 0, 0, 0]  # centre pose p[x, y, z, rx, ry, rz]

    [[cylinder]]
    name = "post"
    radius = 0.05
    length = 1.5                       # along the cylinder's own z axis, centred on pose
    pose = [-0.5, 0.5, 0.75, 0, 0, 0]

    [tool]                     # the tool as a capsule from the flange to the TCP
    radius = 0.04
"""

from __future__ import annotations

import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin

from . import pose as _pose
from .errors import KinematicsError
from .pinmodel import URDF_MODELS, example_robot_data_dir, load_urdf_model, urdf_path
from .robot import Robot

__all__ = ["CollisionModel", "CollisionResult", "LINKS"]

LINKS = ("base", "shoulder", "upper_arm", "forearm", "wrist_1", "wrist_2", "wrist_3", "tool")

_SKIPPED = {frozenset(pair) for pair in (
    ("base", "shoulder"), ("shoulder", "upper_arm"), ("upper_arm", "forearm"),
    ("forearm", "wrist_1"), ("wrist_1", "wrist_2"), ("wrist_2", "wrist_3"), ("wrist_3", "tool"),
    ("base", "upper_arm"), ("forearm", "wrist_2"), ("forearm", "wrist_3"),
    ("wrist_1", "wrist_3"), ("wrist_2", "tool"),
)}


@dataclass(frozen=True)
class CollisionResult:
    """The outcome of :meth:`CollisionModel.check` for N joint vectors.

    ``distance`` (N,) [m]: the smallest signed distance over all checked pairs (negative:
    overlap); ``closest`` (N,): the pair at that distance; ``pairs``: for every sample with
    ``distance ≤ margin``, all pairs within ``margin`` (link vs link, link vs obstacle).
    """

    distance: np.ndarray
    closest: list[tuple[str, str]]
    pairs: dict[int, list[tuple[str, str]]] = field(default_factory=dict)
    margin: float = 0.0
    stopped: int | None = None
    """:meth:`CollisionModel.sweep` with a deadline: the first sample not checked when the
    deadline passed (the samples from there on were not looked at); None: all checked."""

    @property
    def colliding(self) -> np.ndarray:
        """(N,) True where some pair is within ``margin`` (in contact when margin is 0)."""
        return self.distance <= self.margin

    def __len__(self) -> int:
        return len(self.distance)


@dataclass
class _Body:
    label: str
    joint: int
    placement: pin.SE3
    shape: object
    obstacle: bool = False


def _segment_placement(start, end) -> tuple[pin.SE3, float]:
    """The placement of a capsule/cylinder whose z axis runs from ``start`` to ``end``."""
    start, end = np.asarray(start, float), np.asarray(end, float)
    axis = end - start
    length = float(np.linalg.norm(axis))
    z = axis / length if length > 0 else np.array([0.0, 0.0, 1.0])
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    rotation = np.column_stack([x, np.cross(z, x), z])
    return pin.SE3(rotation, (start + end) / 2.0), length


def _capsule(label: str, joint: int, start, end, radius: float) -> _Body:
    placement, length = _segment_placement(start, end)
    return _Body(label, joint, placement, coal.Capsule(radius, length))


def _vector(values, size: int, name: str) -> np.ndarray:
    try:
        array = np.array(values, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        array = np.array([])
    if array.shape != (size,) or not np.all(np.isfinite(array)):
        raise KinematicsError(f"{name} must be {size} finite numbers, got {values!r}")
    return array


class CollisionModel:
    """Collision geometry of ``robot`` plus the obstacles of its cell (see the module doc).

    ``tool_radius`` [m]: model the tool as a capsule from the flange to the TCP of
    :meth:`check` (None: no tool body).
    """

    def __init__(self, robot: Robot, tool_radius: float | None = None) -> None:
        self.robot = robot
        self.tool_radius = tool_radius
        self.uses_meshes = robot.name in URDF_MODELS
        self._obstacles: list[_Body] = []
        if self.uses_meshes:
            self.model = load_urdf_model(robot.name)
            self._links = self._mesh_bodies()
            base = self.model.getFrameId("base")
            self._base = pin.SE3(self._fixed_frame(base))   # controller Base in base_link
            self._flange = self.model.frames[self.model.getFrameId("tool0")].placement
            self._joint6 = self.model.getJointId("wrist_3_joint")
        else:
            self.model = robot.pin_model
            self._links = self._capsule_bodies()
            self._base = pin.SE3.Identity()
            frame = self.model.frames[self.model.getFrameId("tool0")]
            self._flange = frame.placement
            self._joint6 = frame.parentJoint
        self.data = self.model.createData()
        self._tool_key: tuple | None = None
        self._tool: list[_Body] = []
        self._geometry: pin.GeometryModel | None = None

    # -- robot bodies ---------------------------------------------------------------------

    def _fixed_frame(self, frame_id: int) -> np.ndarray:
        data = self.model.createData()
        pin.framesForwardKinematics(self.model, data, pin.neutral(self.model))
        return data.oMf[frame_id].homogeneous

    def _mesh_bodies(self) -> list[_Body]:
        share = example_robot_data_dir().parent.parent
        meshes = pin.buildGeomFromUrdf(self.model, str(urdf_path(self.robot.name)),
                                       pin.GeometryType.COLLISION, package_dirs=[str(share)])
        bodies = []
        for item in meshes.geometryObjects:
            link = item.name.rsplit("_", 1)[0].removesuffix("_link")
            label = "wrist_3" if link == "ee" else link
            if label not in LINKS:
                raise KinematicsError(f"unexpected collision body {item.name} in the URDF")
            shape = item.geometry
            if isinstance(shape, coal.BVHModelBase):
                shape.buildConvexHull(True, "Qt")
                shape = shape.convex
            bodies.append(_Body(label, item.parentJoint, item.placement, shape))
        return bodies

    def _capsule_bodies(self) -> list[_Body]:
        theta, a, d, _ = self.robot.dh
        d1, a2, a3, d4, d5, d6 = d[0], a[1], a[2], d[3], d[4], d[5]
        s, f = 1.2 * d4, 0.15 * d4
        r_s, r_u, r_f, r_w, r_3 = 0.63 * d5, 0.57 * d5, 0.42 * d5, 0.48 * d5, 0.40 * d5
        base = _capsule("base", 0, (0, 0, 0), (0, 0, max(d1 - r_s, 0.01)), r_s)
        return [
            base,
            _capsule("shoulder", 1, (0, 0, d1), (0, -s, d1), r_s),
            _capsule("upper_arm", 2, (0, 0, s), (a2, 0, s), r_u),
            _capsule("forearm", 3, (0, 0, f), (a3, 0, f), r_f),
            _capsule("forearm", 3, (0, 0, f), (0, 0, s), r_f),
            _capsule("wrist_1", 4, (0, 0, f), (0, 0, d4), r_w),
            _capsule("wrist_2", 5, (0, 0, 0), (0, 0, d5), r_w),
            _capsule("wrist_3", 6, (0, 0, 0), (0, 0, d6), r_3),
        ]

    # -- obstacles ------------------------------------------------------------------------

    def _add(self, name: str, shape, placement_base: np.ndarray) -> None:
        if not name or name in LINKS or any(o.label == name for o in self._obstacles):
            raise KinematicsError(f"obstacle name {name!r} is empty, taken, or a link name")
        placement = self._base * pin.SE3(placement_base)
        self._obstacles.append(_Body(name, 0, placement, shape, obstacle=True))
        self._geometry = None

    def add_plane(self, normal, offset: float, name: str = "plane") -> None:
        """A solid half-space ``normal·x ≤ offset`` (x in Base, m); the normal points to the
        free side. ``add_plane((0, 0, 1), 0.0, "floor")`` is a floor at z = 0."""
        n = _vector(normal, 3, "normal")
        norm = float(np.linalg.norm(n))
        if norm == 0.0:
            raise KinematicsError("a plane normal must not be zero")
        self._add(name, coal.Halfspace(n / norm, float(offset) / norm), np.eye(4))

    def add_box(self, size, pose, name: str = "box") -> None:
        """A box with full edge lengths ``size`` (x, y, z) [m] centred on ``pose`` (Base)."""
        size = _vector(size, 3, "box size")
        if np.any(size <= 0):
            raise KinematicsError(f"box size must be positive, got {size.tolist()}")
        self._add(name, coal.Box(*size), _pose.to_matrix(_vector(pose, 6, "box pose")))

    def add_cylinder(self, radius: float, length: float, pose, name: str = "cylinder") -> None:
        """A cylinder along its own z axis, centred on ``pose`` (Base); radius, length [m]."""
        if radius <= 0 or length <= 0:
            raise KinematicsError("cylinder radius and length must be positive")
        self._add(name, coal.Cylinder(float(radius), float(length)),
                  _pose.to_matrix(_vector(pose, 6, "cylinder pose")))

    @property
    def obstacles(self) -> list[str]:
        """The obstacle names, in the order they were added."""
        return [body.label for body in self._obstacles]

    def load_cell(self, path: str | Path) -> None:
        """Add the obstacles (and tool radius) of a cell TOML file (format in the module doc)."""
        path = Path(path)
        try:
            data = tomllib.loads(path.read_text(encoding="utf-8"))
        except OSError as error:
            raise KinematicsError(f"{path}: cannot read cell: {error.strerror}") from None
        except tomllib.TOMLDecodeError as error:
            raise KinematicsError(f"{path}: not valid TOML: {error}") from None
        unknown = set(data) - {"floor", "plane", "box", "cylinder", "tool"}
        if unknown:
            raise KinematicsError(f"{path}: unknown tables {sorted(unknown)}; expected floor, "
                                  "plane, box, cylinder, tool")
        try:
            if "floor" in data:
                self.add_plane((0, 0, 1), float(data["floor"].get("height", 0.0)), "floor")
            for i, item in enumerate(data.get("plane", [])):
                self.add_plane(item["normal"], item["offset"], item.get("name", f"plane{i}"))
            for i, item in enumerate(data.get("box", [])):
                self.add_box(item["size"], item["pose"], item.get("name", f"box{i}"))
            for i, item in enumerate(data.get("cylinder", [])):
                self.add_cylinder(item["radius"], item["length"], item["pose"],
                                  item.get("name", f"cylinder{i}"))
            if "tool" in data:
                self.tool_radius = float(data["tool"]["radius"])
        except KeyError as error:
            raise KinematicsError(f"{path}: an entry lacks {error.args[0]!r}") from None
        except (TypeError, ValueError, AttributeError) as error:
            raise KinematicsError(f"{path}: {error}") from None

    # -- checking -------------------------------------------------------------------------

    def _tool_bodies(self, tcp) -> list[_Body]:
        if self.tool_radius is None or tcp is None:
            return []
        tcp = _pose.to_matrix(_vector(tcp, 6, "tcp")) if np.shape(tcp) == (6,) else \
            np.asarray(tcp, dtype=float)
        point = tcp[:3, 3]
        if np.linalg.norm(point) < 1e-6:
            return []
        start = self._flange.translation
        end = self._flange.act(point)
        return [_capsule("tool", self._joint6, start, end, float(self.tool_radius))]

    def _build(self, tcp) -> None:
        key = None if tcp is None else tuple(np.asarray(tcp, dtype=float).ravel().tolist())
        if self._geometry is not None and key == self._tool_key:
            return
        self._tool_key = key
        self._tool = self._tool_bodies(tcp)
        geometry = pin.GeometryModel()
        bodies = self._links + self._tool + self._obstacles
        for i, body in enumerate(bodies):
            geometry.addGeometryObject(pin.GeometryObject(f"{body.label}#{i}", body.joint,
                                                          body.placement, body.shape))
        names = []
        for i, first in enumerate(bodies):
            for j in range(i + 1, len(bodies)):
                second = bodies[j]
                if first.obstacle and second.obstacle:
                    continue
                if first.obstacle or second.obstacle:
                    if "base" in (first.label, second.label):
                        continue
                elif first.label == second.label or \
                        frozenset((first.label, second.label)) in _SKIPPED:
                    continue
                geometry.addCollisionPair(pin.CollisionPair(i, j))
                names.append((first.label, second.label))
        if not names:
            raise KinematicsError("nothing to check")
        self._geometry = geometry
        self._geometry_data = pin.GeometryData(geometry)
        self._pair_names = names

    @staticmethod
    def _joint_vectors(Q) -> np.ndarray:
        Q = np.asarray(Q, dtype=float)
        if Q.ndim == 1:
            Q = Q[None]
        if Q.ndim != 2 or Q.shape[1] != 6 or not np.all(np.isfinite(Q)):
            raise KinematicsError(f"Q must be finite joint vectors of shape (N, 6), got {Q.shape}")
        return Q

    def check(self, Q, tcp=None, margin: float = 0.0) -> CollisionResult:
        """Check joint vectors ``Q`` (N, 6) [rad]: the smallest signed distance [m] per
        sample and, where it is ≤ ``margin`` [m], the pairs involved. ``tcp`` (pose in the
        flange frame) places the tool capsule when a tool radius is set."""
        Q = self._joint_vectors(Q)
        self._build(tcp)
        model, data = self.model, self.data
        geometry, geometry_data, names = self._geometry, self._geometry_data, self._pair_names
        results = geometry_data.distanceResults
        distance = np.empty(len(Q))
        closest: list[tuple[str, str]] = []
        pairs: dict[int, list[tuple[str, str]]] = {}
        for i, q in enumerate(Q):
            # Pinocchio runs the FK and every pair's GJK/EPA in C++ and returns the index of
            # the closest pair; the other results are read only for samples in contact
            k = pin.computeDistances(model, data, geometry, geometry_data, q)
            value = results[k].min_distance
            distance[i] = value
            closest.append(names[k])
            if value <= margin:
                pairs[i] = [names[j] for j, result in enumerate(results)
                            if result.min_distance <= margin]
        return CollisionResult(distance, closest, pairs, margin)

    def sweep(self, Q, tcp=None, stride: int = 1, margin: float = 0.0,
              deadline: float | None = None) -> tuple[np.ndarray, CollisionResult]:
        """Check a sampled path ``Q`` (N, 6) [rad] every ``stride``-th sample, or further
        apart where no contact is possible in between (conservative advancement): with a
        clearance ``d`` [m] at one sample, no pair can touch before the joints have
        travelled ``Σ_k |Δq_k|·R_k = d``, where ``R_k`` bounds how far from joint k's axis
        anything it moves reaches (:meth:`levers`). A distance between two links does not
        change with the joints before the first of them: seen from that link, only the other
        one moves, by at most that travel; an obstacle stands still. An arm at rest is
        checked once.

        With a ``deadline`` (``time.monotonic()``) the sweep stops once it has passed, and
        the result's ``stopped`` says at which sample.

        Returns the indices of the checked samples and their :class:`CollisionResult`.
        """
        Q = self._joint_vectors(Q)
        self._build(tcp)
        stride = max(int(stride), 1)
        levers = self.levers()
        travel = np.zeros(len(Q))
        block = 32768  # rows per pass (cache-sized)
        for begin in range(0, len(Q) - 1, block):
            end = min(begin + block, len(Q) - 1)
            travel[begin + 1:end + 1] = np.abs(Q[begin + 1:end + 1] - Q[begin:end]) @ levers
        np.cumsum(travel, out=travel)
        model, data = self.model, self.data
        geometry, geometry_data, names = self._geometry, self._geometry_data, self._pair_names
        results = geometry_data.distanceResults
        index: list[int] = []
        distance: list[float] = []
        closest: list[tuple[str, str]] = []
        pairs: dict[int, list[tuple[str, str]]] = {}
        i, n = 0, len(Q)
        stopped = None
        while i < n:
            if deadline is not None and not len(index) & 63 and time.monotonic() > deadline:
                stopped = i
                break
            k = pin.computeDistances(model, data, geometry, geometry_data, Q[i])
            value = results[k].min_distance
            if value <= margin:
                pairs[len(index)] = [names[j] for j, result in enumerate(results)
                                     if result.min_distance <= margin]
            index.append(i)
            distance.append(value)
            closest.append(names[k])
            ahead = i + stride
            if value > margin:  # before `safe`, nothing has moved by the clearance
                safe = int(travel.searchsorted(travel[i] + (value - margin)))
                ahead = max(ahead, safe)
            i = ahead
        return np.array(index, dtype=np.int64), CollisionResult(
            np.array(distance), closest, pairs, margin, stopped)

    def levers(self) -> np.ndarray:
        """(6,) [m]: for each joint, a bound on the distance from its axis of every point
        that it moves (the bodies after it in the chain, and the tool): the lengths of the
        joint placements in between plus the body's bounding sphere seen from its joint."""
        placements = [float(np.linalg.norm(p.translation)) for p in self.model.jointPlacements]
        levers = np.zeros(6)
        for body in self._links + self._tool:
            body.shape.computeLocalAABB()
            centre = body.placement.act(np.asarray(body.shape.aabb_center, dtype=float))
            radius = float(np.linalg.norm(centre)) + float(body.shape.aabb_radius)
            for joint in range(1, body.joint + 1):
                reach = sum(placements[joint + 1:body.joint + 1]) + radius
                levers[joint - 1] = max(levers[joint - 1], reach)
        return levers

    def distances(self, q, tcp=None) -> dict[tuple[str, str], float]:
        """Every checked pair's signed distance [m] at one joint vector ``q`` (6,) (the
        smallest over the bodies of a pair), e.g. to see how close a part comes to a fixture.
        """
        q = np.asarray(q, dtype=float)
        if q.shape != (6,) or not np.all(np.isfinite(q)):
            raise KinematicsError(f"q must be 6 finite joint angles, got shape {q.shape}")
        self._build(tcp)
        pin.computeDistances(self.model, self.data, self._geometry, self._geometry_data, q)
        out: dict[tuple[str, str], float] = {}
        for name, result in zip(self._pair_names, self._geometry_data.distanceResults,
                                strict=True):
            out[name] = min(out.get(name, np.inf), float(result.min_distance))
        return out
