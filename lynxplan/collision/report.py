"""The one report of the exact verifier: is this motion collision free, and by how much.

Task trajectories (:func:`lynxplan.collision.check_trajectory`), planned paths
(:func:`lynxplan.planning.verify.verify_path`, a planned trajectory's ``verification``) and the
service's ``/check`` all answer with a :class:`MotionReport`; ``CollisionReport`` and
``VerificationReport`` are its former names.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, NamedTuple


class ClearanceRecord(NamedTuple):
    """The smallest distance between the arm and an obstacle over a set of times.

    Attributes:
        clearance: Exact distance (the world's engine), in [m]; ``inf`` when nothing was checked.
        link: URDF link name of the closest primitive.
        geometry: Name of the closest primitive, e.g. ``"gripper_1"`` (the pen).
        obstacle: Name of the obstacle (``"self:<geometry>"`` for self-collision).
        time: When it occurs, in [s] (for a geometric path: the path parameter, the waypoint
            index, fractional between waypoints).
        sample: Sample (waypoint) index, or -1 for a time between samples (bisection).
    """

    clearance: float
    link: str
    geometry: str
    obstacle: str
    time: float
    sample: int


#: The record of a check with nothing to check.
NO_RECORD = ClearanceRecord(float("inf"), "", "", "", float("nan"), -1)


class Contact(NamedTuple):
    """One contact: a pair in collision over a run of consecutive samples (or between samples).

    Attributes:
        link: URDF link name.
        geometry: Primitive name.
        obstacle: Obstacle name (``"self:<geometry>"`` for self-collision).
        time: Time of the deepest penetration, in [s].
        penetration_depth: Largest penetration depth (signed distance, negated), in [m].
        t_start: First time the pair was found in contact, in [s].
        t_end: Last time the pair was found in contact, in [s].
        between_samples: Found by the between-sample check, not at a sample.
    """

    link: str
    geometry: str
    obstacle: str
    time: float
    penetration_depth: float
    t_start: float
    t_end: float
    between_samples: bool


@dataclass(frozen=True)
class MotionReport:
    """Exact verification of a motion (a sampled trajectory or a path of straight joint
    segments), at and between its samples.

    Attributes:
        collision_free: No contact at any sample nor between samples, and every interval
            certified.
        min_clearance: Smallest exact distance found (link, obstacle, time, sample), in [m].
        required_clearance: The clearance the motion was planned or checked for, in [m].
        certified: Every sample interval passed the between-sample test (none left undecided at
            :data:`lynxplan.collision.verify.MAX_BISECTION_DEPTH` bisections: a grazing contact).
        contacts: Every contact found, sorted by start time (a planned path stops at the first).
        segments: Smallest clearance of each segment, in increasing segment index order.
        segment_ids: The segment index of each entry of ``segments``.
        self_collision_pairs: Number of self-collision pairs checked.
        obstacle_pairs: Number of primitive/obstacle pairs checked.
        exact_queries: Exact distance queries made.
        refined_intervals: (interval, pair) cases that needed bisection.
    """

    collision_free: bool
    min_clearance: ClearanceRecord
    required_clearance: float = 0.0
    certified: bool = True
    contacts: tuple[Contact, ...] = ()
    segments: tuple[ClearanceRecord, ...] = ()
    segment_ids: tuple[int, ...] = ()
    self_collision_pairs: int = 0
    obstacle_pairs: int = 0
    exact_queries: int = 0
    refined_intervals: int = 0

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready fields (records and contacts as mappings), read back by
        :meth:`from_dict`."""
        return {
            "collision_free": self.collision_free,
            "min_clearance": self.min_clearance._asdict(),
            "required_clearance": self.required_clearance,
            "certified": self.certified,
            "contacts": [c._asdict() for c in self.contacts],
            "segments": [r._asdict() for r in self.segments],
            "segment_ids": list(self.segment_ids),
            "self_collision_pairs": self.self_collision_pairs,
            "obstacle_pairs": self.obstacle_pairs,
            "exact_queries": self.exact_queries,
            "refined_intervals": self.refined_intervals,
        }

    @classmethod
    def from_dict(cls, fields: Mapping[str, Any]) -> MotionReport:
        """The report of :meth:`as_dict`'s fields (e.g. a service answer)."""

        def numbers(r: Mapping[str, Any]) -> dict[str, Any]:  # JSON writes NaN as null
            return {k: float("nan") if v is None else v for k, v in r.items()}

        def record(r: Mapping[str, Any]) -> ClearanceRecord:
            values = numbers(r)
            return ClearanceRecord(**{**values, "sample": int(values["sample"])})

        return cls(
            collision_free=bool(fields["collision_free"]),
            min_clearance=record(fields["min_clearance"]),
            required_clearance=float(fields.get("required_clearance", 0.0)),
            certified=bool(fields.get("certified", True)),
            contacts=tuple(Contact(**numbers(c)) for c in fields.get("contacts", ())),
            segments=tuple(record(r) for r in fields.get("segments", ())),
            segment_ids=tuple(int(s) for s in fields.get("segment_ids", ())),
            self_collision_pairs=int(fields.get("self_collision_pairs", 0)),
            obstacle_pairs=int(fields.get("obstacle_pairs", 0)),
            exact_queries=int(fields.get("exact_queries", 0)),
            refined_intervals=int(fields.get("refined_intervals", 0)),
        )


#: Former names of :class:`MotionReport` (task checks; planned paths).
CollisionReport = MotionReport
VerificationReport = MotionReport
