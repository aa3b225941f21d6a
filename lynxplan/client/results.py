"""The library's typed values rebuilt from the server's JSON answers (bit for bit: numbers
travel as shortest round-trip JSON or raw float64)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class RunResult:
    """A scenario run on the server.

    Attributes:
        id: Run id.
        state: ``queued``, ``running``, ``succeeded``, ``failed``, ``cancelled``, ``interrupted``.
        ok: Every expectation held (None until succeeded).
        summary: The run's summary paragraph (as printed by ``lynxplan run``).
        error: Failed expectations or the error of a failed run.
        report: Its ``report.json`` content, if any.
        artifacts: Relative names of its output files.
        timings: Durations on the server, in [s].
    """

    id: str
    state: str
    ok: bool | None
    summary: str | None
    error: str | None
    report: Any
    artifacts: tuple[str, ...]
    timings: Mapping[str, float]

    @property
    def result(self) -> Any:
        """The library's :class:`lynxplan.scenarios.Result`, rebuilt from the run's report
        (None until the run succeeded)."""
        from lynxplan.scenarios.base import ExpectationResult, Result

        if self.state != "succeeded" or not isinstance(self.report, Mapping):
            return None
        r = self.report
        return Result(
            kind=r["kind"],
            schema_version=r["schema_version"],
            name=r["name"],
            inputs=r["inputs"],
            metrics=r["metrics"],
            expectations=tuple(ExpectationResult(**e) for e in r["expectations"]),
            artifacts=tuple(r["artifacts"]),
            timing=r["timing"],
            details=r["details"],
            summary=self.summary or "",
            units=r.get("units", {"length": "m", "angle": "rad"}),
            metric_quantities=r.get("metric_quantities", {}),
        )


_IK_BATCH_FIELDS = (
    ("q", float),
    ("within_limits", bool),
    ("orientation_error", float),
    ("status", np.int8),
    ("reach_miss", float),
    ("deviation", float),
)


def _read_only(array: np.ndarray) -> np.ndarray:
    array.setflags(write=False)
    return array


def _number(value: Any) -> Any:
    return float("nan") if value is None else value


def ik_result(fields: Mapping[str, Any]) -> Any:
    """The :class:`~lynxplan.branches.IkResult` of a single-pose ``/ik`` answer."""
    from lynxplan.branches import IkResult, IkSolution

    solutions = tuple(
        IkSolution(
            _read_only(np.array(s["q"], dtype=float)),
            s["branch"],
            s["within_limits"],
            s["position_error"],
            s["orientation_error"],
        )
        for s in fields["solutions"]
    )
    return IkResult(
        solutions,
        fields["selected"],
        fields["reachable"],
        fields["distance"],
        fields["orientation_residual"],
        fields["solver"],
    )


def obstacle_json(obstacle: Any) -> dict[str, Any]:
    """The JSON object of a library obstacle (a mapping passes through)."""
    if isinstance(obstacle, Mapping):
        return dict(obstacle)
    kind = type(obstacle).__name__.removesuffix("Obstacle").lower()
    fields = {"type": kind, "name": obstacle.name, "centre": np.asarray(obstacle.centre)}
    for name in ("size", "radius", "length"):
        if hasattr(obstacle, name):
            fields[name] = getattr(obstacle, name)
    if kind != "sphere":
        fields["rotation"] = np.asarray(obstacle.rotation)
    return fields


def ik_batch(fields: Mapping[str, Any]) -> Any:
    """An :class:`~lynxplan.arm.ik.IkBatch` from ``/ik`` batch arrays."""
    from lynxplan.arm.ik import IkBatch

    return IkBatch(
        *(_read_only(np.asarray(fields[name], dtype=dtype)) for name, dtype in _IK_BATCH_FIELDS)
    )


def collision_report(answer: Mapping[str, Any]) -> Any:
    """A :class:`~lynxplan.collision.CollisionReport` from a ``/check`` answer with times."""
    from lynxplan.collision import MotionReport

    return MotionReport.from_dict(answer)


def profiles(answer: Mapping[str, Any]) -> list[Any]:
    """One :class:`~lynxplan.trajectory.Profile` per segment of a ``/trajectory`` answer."""
    from lynxplan.trajectory import Profile

    return [
        Profile(
            np.array(s["t"], dtype=float),
            np.array(s["q"], dtype=float),
            np.array(s["qd"], dtype=float),
            np.array(s["qdd"], dtype=float),
            time_scale=s["time_scale"],
            requested_duration=s["requested_duration"],
        )
        for s in answer["segments"]
    ]


def planned_trajectory(a: Mapping[str, Any]) -> Any:
    """A :class:`~lynxplan.planning.PlannedTrajectory` from a ``/plan`` answer."""
    from lynxplan.collision import MotionReport
    from lynxplan.planning import PlannedTrajectory, PlannerOptions, PlanningStats

    option_fields: dict[str, Any] = {
        k: tuple(x) if isinstance(x, list) else x for k, x in a["options"].items()
    }
    return PlannedTrajectory(
        waypoints=_read_only(np.array(a["waypoints"], dtype=float)),
        t=_read_only(np.array(a["t"], dtype=float)),
        q=_read_only(np.array(a["q"], dtype=float)),
        qd=_read_only(np.array(a["qd"], dtype=float)),
        qdd=_read_only(np.array(a["qdd"], dtype=float)),
        segment=_read_only(np.array(a["segment"], dtype=np.asarray(0).dtype)),
        verification=MotionReport.from_dict(a["verification"]),
        goal_label=a["goal_label"],
        goal_index=a["goal_index"],
        path_length=a["path_length"],
        seed=a["seed"],
        stats=PlanningStats(**a["stats"]),
        options=PlannerOptions(**option_fields),
    )  # fmt: skip


def run_result(fields: Mapping[str, Any]) -> RunResult:
    """A :class:`RunResult` from a ``/runs/{id}`` record."""
    return RunResult(
        fields["id"],
        fields["state"],
        fields["ok"],
        fields["summary"],
        fields["error"],
        fields["report"],
        tuple(fields["artifacts"]),
        fields["timings"],
    )


def _clearance(fields: Mapping[str, Any]) -> Any:
    from lynxplan.collision import ClearanceRecord

    return ClearanceRecord(**{k: _number(v) for k, v in fields.items()})


__all__ = [
    "RunResult",
    "collision_report",
    "ik_batch",
    "ik_result",
    "obstacle_json",
    "planned_trajectory",
    "profiles",
    "run_result",
]
