"""The exact verifier: the one place that decides whether a motion is collision free.

Every answer lynxplan gives to "is this motion collision free, and by how much" comes from a
:class:`Certification` of this module: a task's sampled trajectory
(:func:`lynxplan.collision.check_trajectory`, the service's ``/check``), a planned path
(:func:`lynxplan.planning.verify.verify_path`, before the planner returns it). The callers
only choose *where* to ask the engine for exact distances (at the samples, by branch and bound
on the sphere bounds; along a path, by the planner's schedule
:mod:`lynxplan.planning.certify`); this module turns those distances into the verdict, by one
conservative advancement, and into one report (:class:`lynxplan.collision.report.MotionReport`).

Conservative advancement
    Motion model: on sample interval k the joints move monotonically from ``q[k]`` to
    ``q[k+1]`` (linearly: ``q(s) = q[k] + s (q[k+1] - q[k])``, ``s`` in [0, 1]). Claim: if a
    pair's distances ``d0`` at ``s0`` and ``d1`` at ``s1`` satisfy ``d0 + d1 > D + 2 m``
    (:func:`separated`), with ``D`` a bound on the motion of any point of the pair between
    ``s0`` and ``s1`` and ``m`` the margin below, the pair does not touch anywhere in between;
    its clearance there is at least ``(d0 + d1 - D) / 2 - m``.

    Proof. Let ``R_j`` bound the distance of any point of the primitive from joint j's axis in
    any configuration (chain of joint offsets plus the primitive's extent, see
    :class:`lynxplan.collision.LinkPrimitive`). Changing the joints one at a time, a rotation by
    ``dq_j`` about axis j moves a point along an arc of length at most ``R_j |dq_j|``, so a
    material point p satisfies ``|p(tau) - p(s0)| <= a(tau) = sum_j R_j |q_j(tau) - q_j(s0)|``
    and likewise ``|p(tau) - p(s1)| <= b(tau)``; monotone joints give ``a + b = D``. The
    distance to a fixed set is 1-Lipschitz, and every point of the primitive is at least ``d0``
    (resp. ``d1``) from the obstacle at the ends, so at time tau every point is at least
    ``max(d0 - a, d1 - b) >= (d0 + d1 - (a + b)) / 2 = (d0 + d1 - D) / 2`` away. For a self
    pair both primitives move and ``D`` is the sum of both bounds (joints that move both
    rigidly may be left out: the distance depends only on the relative pose). If the real
    motion deviates from the linear one by at most ``e_j = max|qdd_j| dt^2 / 8`` per joint
    (interpolation error of a C2 function), the same argument adds ``m = sum_j R_j e_j``.

    An interval where the inequality fails is bisected (:meth:`Certification.bisect`): the
    midpoint is queried exactly, a distance <= 0 is a contact between samples, otherwise both
    halves (each with half of D) are tested again. Each bisection halves D, so the recursion
    ends unless the clearance is ~0 (grazing contact); after :data:`MAX_BISECTION_DEPTH` levels
    the interval is reported as not certified.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from lynxplan.collision.report import NO_RECORD, ClearanceRecord, Contact, MotionReport
from lynxplan.collision.world import CollisionWorld

#: Bisection levels of one interval before it is reported as not certified (grazing contact).
MAX_BISECTION_DEPTH = 40

#: Exact signed distance of a pair at parameter s of interval k: (k, s, pair) -> [m].
ExactDistance = Callable[[int, float, int], float]


def separated(d0: Any, d1: Any, motion: Any, margin: Any = 0.0) -> Any:
    """The conservative-advancement test: distances d0, d1 [m] at the ends of an interval on
    which no point of the pair moves more than ``motion`` [m] from the linear motion's (plus
    ``margin`` [m] of deviation from it) prove the pair apart on the whole interval. Scalars or
    arrays (broadcast)."""
    return d0 + d1 > motion + 2.0 * margin


def smallest_exact(
    bounds: np.ndarray, exact: Callable[[int], float], best: float = np.inf
) -> tuple[float, int]:
    """Branch and bound: the smallest exact distance among candidates with lower bounds.

    bounds: lower bounds of the candidates' distances, shape (M,), in [m] (a bound <= 0 proves
    nothing, not even about penetration depth: such a candidate is always queried); exact(i):
    candidate i's exact distance, in [m]; best: a distance already known, in [m] (only
    candidates below it are looked at). Candidates are queried in increasing order of their
    bound until a positive bound reaches the best distance found. Returns the smallest distance
    and its candidate (``best`` and -1 when no candidate is below it).
    """
    first = index = -1
    if bounds.size and best == np.inf:
        first = index = int(np.argmin(bounds))
        best = exact(first)
    candidates = np.flatnonzero((bounds < best) | (bounds <= 0.0))
    flat = bounds[candidates]
    order = np.argsort(flat, kind="stable")
    # Plain Python numbers in the loop: it runs thousands of times in a 1 kHz trajectory.
    for bound, i in zip(flat[order].tolist(), candidates[order].tolist(), strict=True):
        if bound > 0.0 and bound >= best:
            break
        if i == first:
            continue
        distance = exact(i)
        if distance < best:
            best, index = distance, i
    return best, index


class Certification:
    """One motion's exact certification: exact distances where they were queried, the contacts,
    the intervals proven, and the report.

    The motion has samples q (N, nq) [rad] at times t (N,) [s] (a geometric path: t = its
    waypoint index); sample interval k is the straight joint segment from ``q[k]`` to
    ``q[k+1]``, parameter s in [0, 1] along it.

    Args:
        world: The collision world (pair names and counts).
        t: The samples' times, shape (N,), in [s].
        exact_at: Exact signed distance of a pair at parameter s of interval k, in [m]
            (bisection midpoints).
    """

    def __init__(self, world: CollisionWorld, t: np.ndarray, exact_at: ExactDistance) -> None:
        self.world, self.t, self.exact_at = world, t, exact_at
        #: Every exact distance not in the batched rows: (distance, interval, s, pair).
        self.probes: list[tuple[float, int, float, int]] = []
        self.contacts: list[Contact] = []
        self.certified = True
        self.refined = 0
        self.queries = 0
        self._rows: tuple[np.ndarray, ...] = ()

    # -- where: time and sample of a probe ---------------------------------------------------
    def time_of(self, k: int, s: float) -> float:
        """Time [s] of parameter s in [0, 1] of interval k."""
        if s == 0.0:
            return float(self.t[k])
        return float(self.t[k] + s * (self.t[k + 1] - self.t[k]))

    def record(self, distance: float, k: int, s: float, pair: int) -> ClearanceRecord:
        """The clearance record of an exact distance [m] of pair at parameter s of interval k."""
        sample = k if s == 0.0 else k + 1 if s == 1.0 else -1
        return ClearanceRecord(distance, *self.world.pair_names(pair), self.time_of(k, s), sample)

    def contact_at(self, distance: float, k: int, s: float, pair: int, between: bool) -> Contact:
        """A contact (distance <= 0 [m]) of pair at parameter s of interval k."""
        time = self.time_of(k, s)
        return Contact(*self.world.pair_names(pair), time, -distance, time, time, between)

    # -- evidence -----------------------------------------------------------------------------
    def add_rows(
        self, interval: np.ndarray, s: np.ndarray, pair: np.ndarray, distance: np.ndarray
    ) -> None:
        """Exact distances queried in one batch: rows (R,) of (interval, s, pair, distance [m])."""
        self._rows = (interval, s, pair, distance)

    def probe(self, k: int, s: float, pair: int, distance: float) -> None:
        """An exact distance [m] of pair at parameter s of interval k, queried by the caller."""
        self.probes.append((distance, k, s, pair))

    def exact(self, k: int, s: float, pair: int) -> float:
        """Query (and keep) the exact distance of pair at parameter s of interval k, in [m]."""
        distance = float(self.exact_at(k, s, pair))
        self.queries += 1
        self.probe(k, s, pair, distance)
        return distance

    # -- the verdict --------------------------------------------------------------------------
    def bisect(
        self,
        k: int,
        pair: int,
        ends: tuple[float, float, float, float],
        motion: float,
        margin: float = 0.0,
    ) -> ClearanceRecord | None:
        """Prove pair apart on [s0, s1] of interval k by bisection with exact distances.

        ends: (s0, s1, d0, d1), the parameters and the exact distances [m] there; motion: the
        bound D [m] of the pair's motion on [s0, s1]; margin: the deviation m [m] from the
        linear motion. A midpoint distance <= 0 is a contact between samples (kept, and the
        bisection stops); :data:`MAX_BISECTION_DEPTH` levels without a verdict leave the motion
        not certified. Returns the lowest midpoint's record (None when none was queried: the
        exact distances at the ends prove the interval).
        """
        s0, s1, d0, d1 = ends
        if separated(d0, d1, motion, margin):
            return None
        self.refined += 1
        stack = [(s0, s1, d0, d1, motion, 0)]
        lowest: ClearanceRecord | None = None
        while stack:
            a, b, da, db, span, depth = stack.pop()
            if separated(da, db, span, margin):
                continue
            if depth >= MAX_BISECTION_DEPTH:
                self.certified = False
                return lowest
            s = 0.5 * (a + b)
            distance = self.exact(k, s, pair)
            if lowest is None or distance < lowest.clearance:
                lowest = self.record(distance, k, s, pair)
            if distance <= 0.0:
                self.contacts.append(self.contact_at(distance, k, s, pair, True))
                return lowest
            stack.append((a, s, da, distance, span / 2.0, depth + 1))
            stack.append((s, b, distance, db, span / 2.0, depth + 1))
        return lowest

    def failed_rows(self, motion: np.ndarray) -> np.ndarray:
        """Rows r (increasing) of the batch whose interval to the next row (the same chain:
        ``motion[r] >= 0``, the bound [m] of the pair's motion between the two) the exact
        distances do not prove (:func:`separated`)."""
        distance = self._rows[3]
        if distance.size < 2:
            return np.empty(0, dtype=np.int64)
        link = motion[:-1]
        failing = (link >= 0.0) & ~separated(distance[:-1], distance[1:], link)
        return np.flatnonzero(failing)

    def first_row_contact(self) -> bool:
        """Whether a batched row is in contact (distance <= 0): the first becomes a contact."""
        interval, s, pair, distance = self._rows or (np.empty(0),) * 4
        touching = np.flatnonzero(distance <= 0.0)
        if not touching.size:
            return False
        r = int(touching[0])
        self.contacts.append(
            self.contact_at(float(distance[r]), int(interval[r]), float(s[r]), int(pair[r]), False)
        )
        return True

    @property
    def collision_free(self) -> bool:
        """No contact found and every interval certified."""
        return not self.contacts and self.certified

    def minimum(self) -> ClearanceRecord:
        """The smallest exact distance of every row and probe."""
        # ties: the earliest, then the lowest pair
        candidates = [(d, k + s, pair, k, s) for d, k, s, pair in self.probes]
        if self._rows and self._rows[3].size:
            interval, s, pair, distance = self._rows
            r = int(np.argmin(distance))
            k, where = int(interval[r]), float(s[r])
            candidates.append((float(distance[r]), k + where, int(pair[r]), k, where))
        if not candidates:
            return NO_RECORD
        d, _, pair_r, k, where = min(candidates)
        return self.record(d, k, where, pair_r)

    def report(
        self,
        required_clearance: float,
        segments: dict[int, ClearanceRecord] | None = None,
        queries: int | None = None,
    ) -> MotionReport:
        """The motion's report; segments: the smallest clearance of each segment (default: one
        segment, the whole motion); queries: the exact queries made (default: this
        certification's)."""
        if segments is None:
            segments = {0: self.minimum()}
        ids = sorted(segments)
        ordered = tuple(segments[s] for s in ids)
        overall = min(ordered, key=lambda r: r.clearance) if ordered else NO_RECORD
        self_pairs = int(np.count_nonzero(self.world.pair_is_self))
        contacts = sorted(self.contacts, key=lambda c: (c.t_start, c.geometry, c.obstacle))
        return MotionReport(
            collision_free=self.collision_free,
            min_clearance=overall,
            required_clearance=float(required_clearance),
            certified=self.certified,
            contacts=tuple(contacts),
            segments=ordered,
            segment_ids=tuple(ids),
            self_collision_pairs=self_pairs,
            obstacle_pairs=self.world.pair_count - self_pairs,
            exact_queries=self.queries if queries is None else queries,
            refined_intervals=self.refined,
        )


__all__ = [
    "MAX_BISECTION_DEPTH",
    "Certification",
    "ExactDistance",
    "separated",
    "smallest_exact",
]
