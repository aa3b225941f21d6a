"""Task results -> metrics, the ``details`` of ``report.json`` and the stdout summary.

Detail keys are stable and every value is in SI units (m, rad, s) with the unit in the key
(``duration_s``, ``clearance_m``, ``value_rad_s``).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from lynxplan.constants import COAL_GJK_TOLERANCE, FCL_DISTANCE_TOLERANCE
from lynxplan.units import angle_factor, length_factor

if TYPE_CHECKING:
    from lynxplan.task.run import TaskResult
    from lynxplan.task.schema import Scenario

ACCURACY_STATEMENT = (
    "Clearances are exact distances between the URDF collision primitives (boxes, cylinders) and "
    f"the obstacles, computed by coal (GJK/EPA tolerance {COAL_GJK_TOLERANCE:g} m; exact to about "
    "1e-9 m, cross-checked in the tests against closed-form distances). python-fcl's libccd GJK "
    f"agrees with coal to {FCL_DISTANCE_TOLERANCE:g} m on most queries but over-estimates some "
    "by millimetres (FCL issue #508), so it is not used for reported figures. Between samples a "
    "conservative-advancement bound (link reach times joint motion, plus the interpolation margin "
    "from the peak joint accelerations; proof in lynxplan.collision.verify) certifies every sample "
    "interval or bisects it until it does or finds a contact."
)


def task_metrics(result: TaskResult) -> dict[str, Any]:
    """The task kind's metrics, SI units (see :mod:`lynxplan.scenarios.task`)."""
    lines = [r.max_line_deviation for r in result.segments if r.max_line_deviation is not None]
    return {
        "collision_free": result.collision.collision_free,
        "within_limits": result.within_limits,
        "min_clearance": result.collision.min_clearance.clearance,
        "duration": result.setup.plan.duration,
        "path_deviation": max(lines, default=0.0),
        "joint_speed": max((r.max_joint_speed for r in result.segments), default=0.0),
        "contacts": len(result.collision.contacts),
    }


def task_notes(result: TaskResult) -> dict[str, str]:
    """Explanations of the collision and limit metrics (for failed expectations)."""
    notes = {}
    contacts = result.collision.contacts
    if contacts:
        c = contacts[0]
        notes["collision_free"] = (
            f"{len(contacts)} contact(s); first: {c.link} ({c.geometry}) hits {c.obstacle} "
            f"at t = {c.time:.3f} s, depth {c.penetration_depth * 1e3:.3f} mm"
        )
    elif not result.collision.collision_free:
        notes["collision_free"] = "some sample interval could not be certified"
    bad = [i for i, check in enumerate(result.limits) if not check.within_limits]
    if bad:
        notes["within_limits"] = f"segments {bad} leave their limits"
    return notes


def _record(record: Any) -> dict[str, Any]:
    return {
        "clearance_m": _finite(record.clearance),
        "link": record.link,
        "geometry": record.geometry,
        "obstacle": record.obstacle,
        "time_s": _finite(record.time),
    }


def _finite(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


def _segment_entries(result: TaskResult) -> list[dict[str, Any]]:
    plan, setup = result.setup.plan, result.setup
    minima = dict(zip(result.collision.segment_ids, result.collision.segments, strict=True))
    starts = plan.start_times
    entries = []
    for i, report in enumerate(result.segments):
        check = result.limits[i]
        entry: dict[str, Any] = {
            "index": i,
            "from": setup.route[i][0],
            "to": setup.route[i][1],
            "motion": report.kind,
            "orientation_mode": report.mode,
            "start_time_s": float(starts[i]),
            "duration_s": float(plan.segments[i].duration),
            "tt_s": report.tt,
            "ta_s": report.ta,
            "min_clearance": _record(minima[i]) if i in minima else None,
            "within_limits": check.within_limits,
            "limits": {
                "position_violation_samples": check.position_violation_samples,
                "position_violation_joints": [f"q{j + 1}" for j in check.position_violation_joints],
                "peak_velocity_ratio": check.peak_velocity_ratio,
                "peak_acceleration_ratio": check.peak_acceleration_ratio,
                "velocity_ok": check.velocity_ok,
                "acceleration_ok": check.acceleration_ok,
            },
            "path_deviation_m": report.max_line_deviation,
            "orientation_residual_rad": report.max_orientation_residual,
            "ik_branch_switches": report.branch_switches,
            "peak_joint_speed": {
                "value_rad_s": report.max_joint_speed,
                "joint": f"q{report.max_joint_speed_joint + 1}",
                "time_s": report.max_joint_speed_time,
            },
        }
        entries.append(entry)
    return entries


def _comparison(result: TaskResult) -> dict[str, Any] | None:
    comparison = result.comparison
    if comparison is None:
        return None
    rows = []
    for seg in comparison.segments:
        row: dict[str, Any] = {"index": seg.segment, "motion": seg.kind}
        for method, stats in seg.stats.items():
            row[method] = {
                "duration_s": stats.duration,
                "velocity_ratio": stats.velocity_ratio,
                "acceleration_ratio": stats.acceleration_ratio,
                "violations": list(stats.violations),
                "time_scale": stats.time_scale,
                "duration_matched": stats.duration_matched,
            }
        rows.append(row)
    return {
        "methods": list(comparison.total_duration),
        "segments": rows,
        "totals": {
            name: {
                "total_duration_s": comparison.total_duration[name],
                "segments_covered": comparison.segments_covered[name],
                "segments_with_violations": comparison.violation_count[name],
                "peak_velocity_rad_s": comparison.peak_velocity[name].tolist(),
                "peak_acceleration_rad_s2": comparison.peak_acceleration[name].tolist(),
            }
            for name in comparison.total_duration
        },
        "notes": [
            "lspb: the scenario's timing; lspb_auto: shortest synchronised LSPB within the "
            "velocity and acceleration limits; toppra: time-optimal along the same joint path; "
            "ruckig: time-optimal jerk-limited, free segments only (it does not follow a "
            "Cartesian line); ruckig_lspb_duration: ruckig forced to the LSPB duration.",
            "Figures are measured on the sampled output of each method.",
        ],
    }


def _obstacle_entry(obstacle: Any) -> dict[str, Any]:
    entry: dict[str, Any] = {
        "name": obstacle.name,
        "type": type(obstacle).__name__.removesuffix("Obstacle").lower(),
        "centre_m": obstacle.centre.tolist(),
        "rotation": np.asarray(obstacle.rotation).tolist(),
    }
    for attribute in ("size", "radius", "length"):
        if hasattr(obstacle, attribute):
            value = getattr(obstacle, attribute)
            entry[f"{attribute}_m"] = value.tolist() if isinstance(value, np.ndarray) else value
    return entry


def task_details(scenario: Scenario, result: TaskResult) -> dict[str, Any]:
    """The ``details`` of report.json (JSON-ready: floats, lists, strings; no NaN)."""
    setup, collision, samples = result.setup, result.collision, result.samples
    segments = result.segments
    lines = [r.max_line_deviation for r in segments if r.max_line_deviation is not None]
    fastest = max(segments, key=lambda r: r.max_joint_speed)
    data = {
        "description": scenario.description,
        "units": {
            "length": "m",
            "angle": "rad",
            "time": "s",
            "note": "every value is SI; the key suffix names its unit (_m, _s, _rad_s, ...)",
        },
        "robot": {
            "urdf": str(setup.arm.urdf_path),
            "collision_geometries": [p.geometry for p in result.world.links],
        },
        "sample_rate_hz": scenario.sample_rate,
        "sample_count": len(samples.t),
        "obstacles": [_obstacle_entry(o) for o in setup.obstacles],
        "waypoints_rad": {name: q.tolist() for name, q in setup.waypoints.items()},
        "segments": _segment_entries(result),
        "totals": {
            "segment_count": len(segments),
            "line_segments": sum(1 for r in segments if r.kind == "line"),
            "free_segments": sum(1 for r in segments if r.kind == "free"),
            "duration_s": setup.plan.duration,
            "min_clearance": _record(collision.min_clearance),
            "collision_free": collision.collision_free,
            "contacts": [
                {
                    "link": c.link,
                    "geometry": c.geometry,
                    "obstacle": c.obstacle,
                    "time_s": c.time,
                    "penetration_depth_m": c.penetration_depth,
                    "t_start_s": c.t_start,
                    "t_end_s": c.t_end,
                    "between_samples": c.between_samples,
                }
                for c in collision.contacts
            ],
            "within_limits": result.within_limits,
            "max_path_deviation_m": max(lines, default=None),
            "peak_joint_speed": {
                "value_rad_s": fastest.max_joint_speed,
                "joint": f"q{fastest.max_joint_speed_joint + 1}",
                "time_s": fastest.max_joint_speed_time,
            },
        },
        "collision_check": {
            "engine": result.world.engine,
            "checked_pairs": int(result.world.pair_count),
            "self_collision": scenario.self_collision,
            "samples": len(samples.t),
            "certified_between_samples": collision.certified,
            "refined_intervals": collision.refined_intervals,
            "exact_queries": collision.exact_queries,
            "accuracy": ACCURACY_STATEMENT,
        },
        "timing_comparison": _comparison(result),
        "stage_seconds": result.stage_seconds,
    }
    cleaned: dict[str, Any] = _clean(data)
    return cleaned


def _clean(value: Any) -> Any:
    """NaN/inf -> None, numpy scalars -> Python numbers, tuples -> lists."""
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, np.generic):
        return _clean(value.item())
    if isinstance(value, float):
        return _finite(value)
    return value


def summary(scenario: Scenario, result: TaskResult) -> str:
    """One paragraph for stdout, lengths and speeds in the scenario's units."""
    setup, collision = result.setup, result.collision
    unit, angle = scenario.units.length, scenario.units.angle
    scale, angle_scale = length_factor(unit), angle_factor(angle)
    lines = sum(1 for r in result.segments if r.kind == "line")
    best = collision.min_clearance
    text = (
        f"Task {scenario.name or '(unnamed)'}: {len(result.segments)} segments ({lines} straight "
        f"lines, {len(result.segments) - lines} free motions), {setup.plan.duration:.3f} s, "
        f"{len(result.samples.t)} samples at {scenario.sample_rate:g} Hz."
    )
    if collision.collision_free:
        text += " Collision-free at every sample and between samples"
    else:
        text += f" {len(collision.contacts)} contact(s)" + (
            "" if collision.certified else ", some intervals not certified"
        )
    if math.isfinite(best.clearance):
        index = int(np.searchsorted(setup.plan.start_times, best.time, side="right") - 1)
        text += (
            f"; minimum clearance {best.clearance / scale:.4f} {unit} ({best.link}/{best.geometry} "
            f"to {best.obstacle} at t = {best.time:.3f} s, segment {index} "
            f"{setup.route[index][0]}->{setup.route[index][1]})."
        )
    else:
        text += " (no obstacles)."
    fastest = max(result.segments, key=lambda r: r.max_joint_speed)
    text += (
        f" Joint limits (position, velocity, acceleration) "
        f"{'hold at every sample' if result.within_limits else 'are violated'}; peak joint speed "
        f"{fastest.max_joint_speed / angle_scale:.4g} {angle}/s "
        f"(q{fastest.max_joint_speed_joint + 1})."
    )
    deviations = [r.max_line_deviation for r in result.segments if r.max_line_deviation is not None]
    if deviations:
        text += f" Largest straight-line deviation {max(deviations) / scale:.3g} {unit}."
    if result.comparison is not None:
        totals = ", ".join(f"{k} {v:.3f} s" for k, v in result.comparison.total_duration.items())
        text += f" Durations: {totals} (ruckig: free segments only)."
    return text
