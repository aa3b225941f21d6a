"""Exact verification of planned paths with coal, and the exact start/goal collision test.

The planner's own checker is conservative but approximate (bounding boxes, separating axes). A
returned path is therefore certified by the exact verifier, :mod:`lynxplan.collision.verify`
(the one module that decides "collision free", for task trajectories too): exact coal distances
between the URDF collision geometry and the obstacles, and between every pair of primitives on
non-adjacent links, proven between the queries by its conservative advancement on each straight
joint segment, pair by pair, and bisected with exact distances where they do not suffice (a
distance <= 0 is a contact). This module only chooses *where* to query: the schedule of
:mod:`lynxplan.planning.certify` from the planner's tight bounds, so a clear path needs few
exact queries (one per pair and waypoint near an obstacle, plus about ``L / 2d`` along a segment
that stays ``d`` from it; ``L``: :func:`lynxplan.planning.kernel_model.pair_rates`). Nothing is
sampled at a fixed resolution and nothing between checked configurations is left unproven.

Self-collision pairs ("allowed pairs" from the URDF adjacency): two primitives are *not*
checked when they hang on the same joint or on a parent/child pair of joints (they touch by
design at the joint); every other pair is, including the fixed base against the moving links.
This is :class:`lynxplan.collision.CollisionWorld`'s rule with ``self_collision=True``.

The time-parameterised trajectory follows the path's straight joint segments (rest-to-rest
profiles, see :mod:`lynxplan.planning.timing`), so the set of configurations it visits is the
path: verifying the path verifies the trajectory. The tests also check the sampled trajectory
itself, densely.
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from functools import partial
from typing import NamedTuple

import numpy as np

from lynxplan._arrays import kernel_input
from lynxplan.collision import CollisionWorld
from lynxplan.collision.report import Contact, MotionReport, VerificationReport
from lynxplan.collision.verify import Certification, smallest_exact
from lynxplan.exceptions import PathVerificationError, StateInCollisionError
from lynxplan.planning.certify import (
    configuration_poses,
    row_transforms,
    segment_rates,
    verification_rows,
    waypoint_bounds,
)
from lynxplan.planning.kernel_model import kernel_model, make_scratch, world_pairs

#: First capacity of the schedule's rows (grown while too small).
_ROWS = 1024


class _Schedule(NamedTuple):
    """A path's verification rows (R,), queries (Q,) and waypoints (N,): see
    :meth:`ExactVerifier.schedule`."""

    segment: np.ndarray
    parameter: np.ndarray
    pair: np.ndarray
    motion: np.ndarray
    #: (R,) each row's index among the queries
    lookup: np.ndarray
    #: (Q,) the queries' pairs
    query_pair: np.ndarray
    #: (Q, 2, 3, 3), (Q, 2, 3) the queries' primitive poses, in [m]
    rotation: np.ndarray
    translation: np.ndarray
    bounds: np.ndarray
    poses: np.ndarray


def _row_buffers(capacity: int) -> tuple[tuple[np.ndarray, ...], tuple[np.ndarray, np.ndarray]]:
    """Columns and transforms of :func:`certify.verification_rows` for ``capacity`` rows."""
    columns = tuple(
        np.empty(capacity, dtype=np.int64 if k in (0, 2, 4, 5) else float) for k in range(6)
    )
    return columns, (np.empty((capacity, 2, 3, 3)), np.empty((capacity, 2, 3)))


class ExactVerifier:
    """Exact (coal) verification of joint paths in one collision world, set up once.

    Args:
        world: The collision world; every one of its pairs is checked.
    """

    def __init__(self, world: CollisionWorld) -> None:
        self.world = world
        self.pairs = world_pairs(world)
        self.model = kernel_model(world, self.pairs)
        self.scratch = make_scratch(self.model)
        # coal objects built once by the world; transforms updated in place, one result reused.
        self._functors = world._coal_pairs
        self._obstacle_poses = world._coal_obstacle_poses
        self._request = world._coal_request
        self._result = world._coal_result_type()
        self._link_poses = [type(t)() for t in world._coal_link_poses]
        self._rows = tuple(tuple(int(v) for v in row) for row in self.pairs.tolist())
        # per pair: (coal functor, first transform, second transform, is a self pair)
        self._queries = tuple(
            (
                self._functors[p],
                self._link_poses[a],
                self._link_poses[b] if is_self else self._obstacle_poses[b],
                bool(is_self),
            )
            for p, (a, b, is_self) in enumerate(self._rows)
        )
        self.queries = 0
        self._buffers = _row_buffers(_ROWS)

    def exact(self, poses: np.ndarray, pair: int) -> float:
        """coal's signed distance of one pair at primitive poses (G, 4, 4), in [m]."""
        a, b, is_self = self._rows[pair]
        first = self._link_poses[a]
        first.setTransform(poses[a, :3, :3], poses[a, :3, 3])
        if is_self:
            second = self._link_poses[b]
            second.setTransform(poses[b, :3, :3], poses[b, :3, 3])
        else:
            second = self._obstacle_poses[b]
        self._result.clear()
        self.queries += 1
        return float(self._functors[pair](first, second, self._request, self._result))

    def exact_rows(
        self, path: np.ndarray, segment: np.ndarray, parameter: np.ndarray, pair: np.ndarray
    ) -> np.ndarray:
        """coal's signed distance of each row's pair at path parameter (segment, s), in [m]:
        shape (R,). The rows' poses come from one compiled call
        (:func:`certify.row_transforms`); the loop only hands them to coal."""
        count = len(segment)
        rotation = np.empty((count, 2, 3, 3))
        translation = np.empty((count, 2, 3))
        row_transforms(
            path, segment, parameter, pair, self.model, self.scratch, rotation, translation
        )
        return self.exact_posed(pair, rotation, translation)

    def exact_posed(
        self, pair: np.ndarray, rotation: np.ndarray, translation: np.ndarray
    ) -> np.ndarray:
        """coal's signed distance of each row's pair (R,) with its primitives' world poses
        rotation (R, 2, 3, 3), translation (R, 2, 3) (the second only for a self pair), in [m]:
        shape (R,)."""
        request, result, queries = self._request, self._result, self._queries
        clear = result.clear
        out = np.empty(len(pair))
        for r, p in enumerate(pair.tolist()):
            functor, first, second, is_self = queries[p]
            first.setTransform(rotation[r, 0], translation[r, 0])
            if is_self:
                second.setTransform(rotation[r, 1], translation[r, 1])
            clear()
            out[r] = functor(first, second, request, result)
        self.queries += len(out)
        return out

    def poses(self, path: np.ndarray, segment: np.ndarray, parameter: np.ndarray) -> np.ndarray:
        """Primitive poses at path parameters (segment, s): shape (R, G, 4, 4)."""
        out = np.empty((len(segment), len(self.world.links), 4, 4))
        configuration_poses(path, segment, parameter, self.model, self.scratch, out)
        return out

    def closest(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """coal's smallest signed distance over every pair at each configuration of q (N, nq)
        or (nq,), in [m], and its pair: shapes (N,), (N,) (inf, -1 without pairs).

        Branch and bound: the pairs are queried in the order of the planner's tight lower
        bounds (one compiled call for all rows) until a positive bound reaches the best exact
        distance (a bound <= 0 proves nothing: such a pair is always queried); usually one or
        two coal queries per configuration instead of one per pair."""
        config = kernel_input(
            np.reshape(np.asarray(q, dtype=float), (-1, self.model.rates.shape[1]))
        )
        bounds = np.empty((len(config), len(self.pairs)))
        poses = np.empty((len(config), len(self.world.links), 4, 4))
        waypoint_bounds(config, self.model, self.scratch, bounds, poses)
        distances = np.full(len(config), np.inf)
        pairs = np.full(len(config), -1, dtype=np.int64)
        for n in range(len(config)):
            exact = partial(self.exact, poses[n])
            distances[n], pairs[n] = smallest_exact(bounds[n], exact)
        return distances, pairs

    def schedule(self, path: np.ndarray) -> _Schedule:
        """The rows to query exactly and their primitives' poses (:func:`certify.schedule`,
        :func:`certify.verification_rows`), and the waypoints' bounds and poses. The columns are
        views of buffers kept for the next path."""
        waypoints = (
            np.empty((len(path), len(self.pairs))),
            np.empty((len(path), len(self.world.links), 4, 4)),
        )
        while True:
            columns, transforms = self._buffers
            rows, queries = verification_rows(
                path, self.model, self.scratch, columns, transforms, waypoints
            )
            if rows >= 0:
                segment, parameter, pair, motion, lookup = (c[:rows] for c in columns[:5])
                return _Schedule(
                    segment,
                    parameter,
                    pair,
                    motion,
                    lookup,
                    columns[5][:queries],
                    transforms[0][:queries],
                    transforms[1][:queries],
                    *waypoints,
                )
            self._buffers = _row_buffers(4 * len(columns[0]))

    def verify(self, waypoints: np.ndarray, clearance: float) -> MotionReport:
        """Certify a piecewise-linear path (N, nq), in [rad]; see :func:`verify_path`."""
        path = kernel_input(np.asarray(waypoints, dtype=float))
        if len(path) == 1:
            path = np.vstack([path, path])
        self.queries = 0
        certification = self.certify(path)
        if certification.contacts:
            raise PathVerificationError(_describe(certification.contacts[0]))
        if not certification.certified:
            raise PathVerificationError("an interval could not be certified (grazing contact)")
        return certification.report(clearance, queries=self.queries)

    def certify(self, path: np.ndarray) -> Certification:
        """The exact verifier's certification of path (M, nq) [rad] (time: the path parameter,
        the waypoint index), fed with the scheduled exact distances; it stops at the first
        contact."""
        rates: list[np.ndarray] = []  # the static motion bounds, for bisection only

        def exact_at(k: int, s: float, pair: int) -> float:
            return self.exact(self.poses(path, np.array([k]), np.array([s]))[0], pair)

        certification = Certification(self.world, np.arange(len(path), dtype=float), exact_at)
        planned = self.schedule(path)
        exact = self.exact_posed(planned.query_pair, planned.rotation, planned.translation)
        # a row at an earlier row's configuration has its distance
        distance = exact[planned.lookup]
        segment, parameter, pair = planned.segment, planned.parameter, planned.pair
        certification.add_rows(segment, parameter, pair, distance)
        if certification.first_row_contact():
            return certification
        self._waypoint_minimum(certification, planned, distance)
        if certification.contacts:
            return certification
        for r in certification.failed_rows(planned.motion).tolist():
            if not rates:
                rates.append(segment_rates(path, self.model))
            k, p, s0, s1 = int(segment[r]), int(pair[r]), parameter[r], parameter[r + 1]
            ends = (float(s0), float(s1), float(distance[r]), float(distance[r + 1]))
            certification.bisect(k, p, ends, float(rates[0][k, p]) * (s1 - s0))
            if certification.contacts or not certification.certified:
                break
        return certification

    def _waypoint_minimum(
        self, certification: Certification, planned: _Schedule, distance: np.ndarray
    ) -> None:
        """Exact smallest distance over the waypoints (:func:`smallest_exact` on the planner's
        bounds (N, P), in [m], below the rows' smallest distance; a pair a row has at a
        waypoint is not queried again), at the primitive poses of its waypoint."""
        pairs = planned.bounds.shape[1]
        where = (planned.segment + planned.parameter).tolist()
        known = set(zip(where, planned.pair.tolist(), strict=True))

        def exact(flat: int) -> float:
            n, pair = divmod(flat, pairs)
            if (float(n), pair) in known:
                return np.inf  # a row's distance: not below the rows' minimum
            d = self.exact(planned.poses[n], pair)
            certification.probe(n, 0.0, pair, d)
            if d <= 0.0 and not certification.contacts:
                certification.contacts.append(certification.contact_at(d, n, 0.0, pair, False))
            return d

        smallest_exact(planned.bounds.ravel(), exact, float(distance.min(initial=np.inf)))


def _describe(contact: Contact) -> str:
    """A path's contact, for :class:`PathVerificationError`."""
    return (
        f"{contact.link} ({contact.geometry}) touches {contact.obstacle} at path parameter "
        f"{contact.time:.4f}, penetration {contact.penetration_depth * 1e3:.4f} mm"
    )


_VERIFIERS: weakref.WeakKeyDictionary[CollisionWorld, ExactVerifier] = weakref.WeakKeyDictionary()


def verifier_of(world: CollisionWorld) -> ExactVerifier:
    """The world's exact verifier, built on first use and kept with the world."""
    verifier = _VERIFIERS.get(world)
    if verifier is None:
        verifier = _VERIFIERS[world] = ExactVerifier(world)
    return verifier


def verify_path(world: CollisionWorld, waypoints: np.ndarray, clearance: float) -> MotionReport:
    """Verify a piecewise-linear joint path exactly.

    Args:
        world: Collision world built with ``self_collision=True``.
        waypoints: Shape (N, nq), in [rad]; the path is the straight joint segments between them.
        clearance: The required clearance the planner guaranteed, in [m] (reported).

    Returns:
        The exact verifier's report (:class:`lynxplan.collision.MotionReport`); its
        ``min_clearance.time`` is the path parameter (waypoint index, fractional between).

    Raises:
        PathVerificationError: a contact or an uncertified interval (never expected: the
            planner's checker is conservative).
    """
    return verifier_of(world).verify(np.asarray(waypoints, dtype=float), clearance)


def closest_contact(world: CollisionWorld, q: np.ndarray) -> tuple[float, str, str]:
    """Exact smallest signed distance at q (nq,), with its link and obstacle names, in [m]
    (:meth:`ExactVerifier.closest`: coal distances, branch and bound on the planner's bounds)."""
    distances, pairs = verifier_of(world).closest(np.asarray(q, dtype=float))
    if pairs[0] < 0:
        return float("inf"), "", ""
    link, _geometry, obstacle = world.pair_names(int(pairs[0]))
    return float(distances[0]), link, obstacle


def require_clear(world: CollisionWorld, q: np.ndarray, what: str, clearance: float) -> None:
    """Raises StateInCollisionError where the exact clearance at q (nq,) is below
    ``clearance`` [m]."""
    problem = clear_states(world, np.reshape(q, (1, -1)), (what,), clearance)[0]
    if problem is not None:
        raise problem


def clear_states(
    world: CollisionWorld, q: np.ndarray, what: Sequence[str], clearance: float
) -> list[StateInCollisionError | None]:
    """For each configuration of q (N, nq): None when its exact clearance reaches ``clearance``
    [m], else the StateInCollisionError naming ``what[n]``, the link, the obstacle and the depth
    (the configurations' bounds in one compiled call: :meth:`ExactVerifier.closest`)."""
    distances, pairs = verifier_of(world).closest(np.asarray(q, dtype=float))
    problems: list[StateInCollisionError | None] = []
    for distance, pair, name in zip(distances.tolist(), pairs.tolist(), what, strict=True):
        if distance >= clearance:
            problems.append(None)
            continue
        link, _geometry, obstacle = world.pair_names(pair) if pair >= 0 else ("", "", "")
        problems.append(StateInCollisionError(name, link, obstacle, -distance, clearance))
    return problems


def sample_clearances(world: CollisionWorld, q: np.ndarray) -> np.ndarray:
    """Exact smallest distance over every pair at each sample (branch and bound on the
    planner's bounds, :meth:`ExactVerifier.closest`).

    q: shape (N, nq), in [rad] -> shape (N,), in [m] (inf without pairs).
    """
    distances: np.ndarray = verifier_of(world).closest(np.asarray(q, dtype=float))[0]
    return distances


__all__ = [
    "ExactVerifier",
    "VerificationReport",
    "clear_states",
    "closest_contact",
    "require_clear",
    "sample_clearances",
    "verifier_of",
    "verify_path",
]
