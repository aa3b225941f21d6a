"""The collision world: the arm's URDF collision primitives and the obstacles, built once.

Every link primitive (box, cylinder or mesh hull of the URDF's ``<collision>`` elements, read
through Pinocchio's GeometryModel) becomes one collision object when the world is built; a query
only moves those objects (``setRotation``/``setTranslation``). The obstacles' objects never move.

Two distance engines, both built once:

- ``"coal"`` (default): coal, the FCL fork that ships with Pinocchio. Exact for boxes and
  cylinders (to ~1e-9 m with the tolerance set here; checked in the tests against closed forms).
- ``"fcl"``: python-fcl. Its libccd GJK gets box–box distances wrong by millimetres or more (FCL
  issue #508, still open: two unit cubes 3 m apart along y are reported 3.162 m apart) and
  box–cylinder ones too: on the arm's links, 95 % of the answers agree with coal to 3e-5 m but
  some are off by up to 9 mm, always *over*-estimated, the unsafe side for a clearance. It is
  kept for comparison (tests, bench).

Besides the exact distance, the world offers a cheap, vectorised *lower bound* of every
link–obstacle distance: each primitive is covered by a few spheres (a box is cut along its longest
edge, a cylinder along its axis, and each piece is enclosed in its circumscribed sphere), and the
signed distance of a sphere centre to a box, ball or cylinder has a closed form. Because the
primitive lies inside the union of its spheres,

    distance(primitive, obstacle) >= min_s (signed_distance(c_s, obstacle) - r_s)

whenever the primitive and the obstacle are apart; a bound <= 0 proves nothing and is always
followed by an exact query. The collision check uses the bound to skip exact queries whose
answer cannot matter (branch and bound), never to report a clearance.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from lynxplan._arrays import kernel_input
from lynxplan.collision import _kernels
from lynxplan.collision.obstacles import (
    Obstacle,
)
from lynxplan.collision.primitives import (
    LinkPrimitive,
    fcl_shape,
    joint_structure,
    link_primitive,
    obstacle_arrays,
    signed_distance,
)
from lynxplan.constants import COAL_GJK_TOLERANCE
from lynxplan.exceptions import CollisionModelError, NonFiniteInputError, ShapeError


class CollisionWorld:
    """The arm's collision primitives and a set of obstacles, as collision objects built once.

    Args:
        arm: The arm (``lynxplan.arm.Arm``): its Pinocchio model and collision GeometryModel.
        obstacles: The obstacles (boxes, spheres, cylinders), in [m].
        self_collision: Also check every pair of primitives on non-adjacent links, except the
            link pairs of the arm's ``disabled_collisions`` (its SRDF's), if it has any.
        engine: Distance engine, ``"coal"`` (exact) or ``"fcl"`` (python-fcl; see above).

    Attributes:
        links: The arm's primitives, in GeometryModel order.
        obstacles: The obstacles.
        pair_link: Primitive index of each checked pair, shape (P,).
        pair_other: Obstacle index (or, for self pairs, primitive index) of each pair, (P,).
        pair_is_self: Whether each pair is a self-collision pair, shape (P,).
        self_pairs: The primitive pairs (a, b), a < b, a self-collision check covers (see
            :func:`self_collision_pairs`), checked by this world if ``self_collision``.
    """

    def __init__(
        self,
        arm: Any,
        obstacles: tuple[Obstacle, ...] | list[Obstacle] = (),
        *,
        self_collision: bool = False,
        engine: str = "coal",
    ) -> None:
        import coal

        if engine not in ("coal", "fcl"):
            raise CollisionModelError("engine", f"engine must be 'coal' or 'fcl'. Got: {engine!r}")
        self.engine = engine

        self.model = arm.model
        self.obstacles: tuple[Obstacle, ...] = tuple(obstacles)
        names = [o.name for o in self.obstacles]
        if len(set(names)) != len(names):
            raise CollisionModelError("obstacles", f"obstacle names must be unique. Got: {names}")
        self._joint_axes, self._joint_placements = joint_structure(self.model)
        self.links: tuple[LinkPrimitive, ...] = tuple(
            link_primitive(self.model, g, self._joint_placements)
            for g in arm.collision_model.geometryObjects
        )
        self.self_pairs = self_collision_pairs(
            self.model, self.links, getattr(arm, "disabled_collisions", ())
        )
        pairs = [(g, o, False) for o in range(len(self.obstacles)) for g in range(len(self.links))]
        if self_collision:
            pairs += [(a, b, True) for a, b in self.self_pairs]
        self.pair_link = np.array([p[0] for p in pairs], dtype=np.intp)
        self.pair_other = np.array([p[1] for p in pairs], dtype=np.intp)
        self.pair_is_self = np.array([p[2] for p in pairs], dtype=bool)
        for array in (self.pair_link, self.pair_other, self.pair_is_self):
            array.setflags(write=False)
        self._pairs = tuple(pairs)  # (link, other, is_self) as Python values, for the queries
        if engine == "fcl":
            self._build_fcl()
        shapes = [p.shape for p in self.links]
        self._coal_link_poses = [coal.Transform3s() for _ in self.links]
        self._coal_obstacle_poses = [
            coal.Transform3s(np.asarray(o.rotation), o.centre) for o in self.obstacles
        ]
        obstacle_shapes = [o.coal_geometry() for o in self.obstacles]
        # The ComputeDistance functors hold raw pointers: keep the shapes alive with the world.
        self._coal_shapes = (shapes, obstacle_shapes)
        self._coal_pairs = [
            coal.ComputeDistance(shapes[a], shapes[b] if is_self else obstacle_shapes[b])
            for a, b, is_self in pairs
        ]
        self._coal_request = coal.DistanceRequest()
        # coal's default GJK tolerance (1e-6) leaves ~1e-6 m on curved shapes (cylinders).
        self._coal_request.gjk_tolerance = COAL_GJK_TOLERANCE
        self._coal_request.epa_tolerance = COAL_GJK_TOLERANCE
        self._coal_result_type = coal.DistanceResult
        self._sphere_owner = np.concatenate(
            [np.full(len(p.sphere_centres), i) for i, p in enumerate(self.links)]
        )
        self._sphere_starts = np.searchsorted(self._sphere_owner, np.arange(len(self.links)))
        self._sphere_radius = np.array([p.sphere_radius for p in self.links])
        self._sphere_local = np.concatenate(
            [np.hstack((p.sphere_centres, np.ones((len(p.sphere_centres), 1)))) for p in self.links]
        )
        self._primitive_placements = np.stack([p.placement for p in self.links])
        self._primitive_joints = np.array([p.joint for p in self.links], dtype=np.intp)
        self._reach = np.stack([p.reach for p in self.links])
        self._kernel_joints = (
            np.array([a for a, _ in self._joint_axes], dtype=np.int64),
            np.array([i for _, i in self._joint_axes], dtype=np.int64),
            np.array(self.model.parents, dtype=np.int64),
            np.stack(self._joint_placements),
            self._primitive_joints.astype(np.int64),
            self._primitive_placements,
        )
        self._kernel_obstacles = obstacle_arrays(self.obstacles)

    # -- names --------------------------------------------------------------------------------
    @property
    def pair_count(self) -> int:
        """Number of checked pairs P."""
        return len(self.pair_link)

    def pair_names(self, pair: int) -> tuple[str, str, str]:
        """(link, geometry, obstacle) names of a pair; a self pair's obstacle is ``self:<geom>``."""
        link = self.links[int(self.pair_link[pair])]
        other = int(self.pair_other[pair])
        if self.pair_is_self[pair]:
            return link.link, link.geometry, f"self:{self.links[other].geometry}"
        return link.link, link.geometry, self.obstacles[other].name

    # -- kinematics ---------------------------------------------------------------------------
    def primitive_poses(self, q: Any) -> np.ndarray:
        """World poses of every primitive. q: (nq,) or (N, nq) in [rad] -> (N, G, 4, 4), [m]."""
        config = _configurations(q, self.model.nq)
        poses = np.empty((len(config), len(self.links), 4, 4))
        _kernels.poses_kernel(kernel_input(config), *self._kernel_joints, poses)
        return poses

    # -- distances ----------------------------------------------------------------------------
    def lower_bounds(self, poses: np.ndarray) -> np.ndarray:
        """Lower bounds of every pair's distance. poses: (N, G, 4, 4) -> (N, P), in [m].

        A positive bound is a proven lower bound of the distance; a bound <= 0 proves nothing.
        """
        bounds = np.empty((poses.shape[0], self.pair_count))
        obstacle_pairs = ~self.pair_is_self
        if obstacle_pairs.any():
            per_link = np.empty((poses.shape[0], len(self.links), len(self.obstacles)))
            _kernels.obstacle_bounds_kernel(
                np.ascontiguousarray(poses),
                self._sphere_owner,
                self._sphere_local[:, :3].copy(),
                self._sphere_radius,
                tuple(self._kernel_obstacles),
                per_link,
            )
            bounds[:, obstacle_pairs] = per_link[
                :, self.pair_link[obstacle_pairs], self.pair_other[obstacle_pairs]
            ]
        self_pairs = np.flatnonzero(self.pair_is_self)
        if self_pairs.size:
            centres = np.einsum(
                "ngij,gj->ngi", poses[:, self._sphere_owner, :3, :], self._sphere_local
            )  # (N, S, 3)
        for p in self_pairs:
            a, b = int(self.pair_link[p]), int(self.pair_other[p])
            sa = slice(
                self._sphere_starts[a], self._sphere_starts[a] + len(self.links[a].sphere_centres)
            )
            sb = slice(
                self._sphere_starts[b], self._sphere_starts[b] + len(self.links[b].sphere_centres)
            )
            gaps = np.linalg.norm(centres[:, sa, None, :] - centres[:, None, sb, :], axis=-1)
            bounds[:, p] = gaps.min(axis=(1, 2)) - self._sphere_radius[a] - self._sphere_radius[b]
        return np.asarray(bounds)

    def distance(self, poses: np.ndarray, pair: int) -> float:
        """Signed distance of one pair, in [m]; negative: minus the penetration depth.

        poses: Primitive poses of one configuration, shape (G, 4, 4), in [m].
        """
        if self.engine == "coal":
            return self._coal_distance(poses, pair)
        return self._fcl_distance(poses, pair)

    def _posed_pair(
        self, links: Sequence[Any], obstacles: Sequence[Any], poses: np.ndarray, pair: int
    ) -> tuple[Any, Any]:
        """The engine objects of one pair, the links' moved to ``poses`` (G, 4, 4) [m]: ``links``
        and ``obstacles`` are one engine's placements (coal ``Transform3f``, fcl objects)."""
        a, b, is_self = self._pairs[pair]
        first = links[a]
        first.setRotation(poses[a, :3, :3])
        first.setTranslation(poses[a, :3, 3])
        if not is_self:
            return first, obstacles[b]
        second = links[b]
        second.setRotation(poses[b, :3, :3])
        second.setTranslation(poses[b, :3, 3])
        return first, second

    def _coal_distance(self, poses: np.ndarray, pair: int) -> float:
        first, second = self._posed_pair(
            self._coal_link_poses, self._coal_obstacle_poses, poses, pair
        )
        # A DistanceResult keeps the minimum over calls: a fresh one per query.
        result = self._coal_result_type()
        return float(self._coal_pairs[pair](first, second, self._coal_request, result))

    def _build_fcl(self) -> None:
        """python-fcl objects of the links and obstacles (the cross-check engine only)."""
        try:
            import fcl
        except ImportError as exc:
            raise CollisionModelError(
                "engine", "engine 'fcl' needs python-fcl (pip install 'lynxplan[test]')"
            ) from exc
        self._link_objects = [
            fcl.CollisionObject(fcl_shape(p), fcl.Transform()) for p in self.links
        ]
        self._obstacle_objects = [
            fcl.CollisionObject(o.fcl_geometry(), fcl.Transform(np.asarray(o.rotation), o.centre))
            for o in self.obstacles
        ]
        self._request = fcl.DistanceRequest(enable_signed_distance=True)

    def _fcl_distance(self, poses: np.ndarray, pair: int) -> float:
        import fcl

        first, second = self._posed_pair(self._link_objects, self._obstacle_objects, poses, pair)
        return float(fcl.distance(first, second, self._request))

    def distances(self, q: Any) -> np.ndarray:
        """Signed distance of every pair at every configuration: (N, nq) -> (N, P), in [m]."""
        poses = self.primitive_poses(q)
        return np.array(
            [
                [self.distance(poses[n], p) for p in range(self.pair_count)]
                for n in range(len(poses))
            ]
        ).reshape(len(poses), self.pair_count)

    def motion_bounds(self, q: np.ndarray) -> np.ndarray:
        """Largest displacement of any point of each pair's moving geometry between samples.

        With joints moving monotonically from ``q[k]`` to ``q[k+1]`` (e.g. linearly), no point of
        primitive g moves farther than ``sum_j reach[g, j] * |q[k+1, j] - q[k, j]|`` from where it
        was at either sample (see :mod:`lynxplan.collision.verify`). For a self pair both
        primitives move, and the sum of both bounds applies.

        q: shape (N, nq), in [rad] -> shape (N - 1, P), in [m].
        """
        per_link = reach_products(np.abs(np.diff(q, axis=0)), self._reach)  # (N - 1, G)
        bounds = per_link[:, self.pair_link]
        if self.pair_is_self.any():
            bounds[:, self.pair_is_self] += per_link[:, self.pair_other[self.pair_is_self]]
        return np.asarray(bounds)


def self_collision_pairs(
    model: Any, links: Sequence[LinkPrimitive], disabled: Sequence[tuple[str, str]] = ()
) -> tuple[tuple[int, int], ...]:
    """The primitive pairs (a, b), a < b, checked for self-collision: primitives on different,
    non-adjacent bodies (adjacent ones touch by design), except those whose links form a pair of
    ``disabled`` (an SRDF's ``disable_collisions``)."""
    parents = list(model.parents)
    skip = {frozenset(pair) for pair in disabled}
    pairs = []
    for a in range(len(links)):
        for b in range(a + 1, len(links)):
            ja, jb = links[a].joint, links[b].joint
            if ja == jb or parents[ja] == jb or parents[jb] == ja:
                continue
            if frozenset((links[a].link, links[b].link)) not in skip:
                pairs.append((a, b))
    return tuple(pairs)


def reach_products(joint_steps: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """``joint_steps @ reach.T``: per row and primitive, ``sum_j reach[g, j] * joint_steps[n, j]``.

    joint_steps: shape (N, nq), in [rad]; reach: shape (G, nq), in [m] -> shape (N, G), in [m].
    Computed by einsum, not BLAS: OpenBLAS splits such a tall, thin product over its threads,
    which took 15-35 ms instead of ~3 ms on a busy 2-core machine (a cold run does two).
    """
    return np.asarray(np.einsum("nj,gj->ng", joint_steps, reach))


def _configurations(q: Any, nq: int) -> np.ndarray:
    config = np.asarray(q, dtype=float)
    if config.ndim == 1:
        config = config[None, :]
    if config.ndim != 2 or config.shape[1] != nq:
        raise ShapeError("q", f"({nq},) or (N, {nq})", np.shape(q))
    if not np.isfinite(config).all():
        raise NonFiniteInputError("q")
    return config


__all__ = ["CollisionWorld", "LinkPrimitive", "self_collision_pairs", "signed_distance"]
