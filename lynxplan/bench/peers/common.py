"""Shared by the peer scripts: the Pinocchio collision model of a problem (robot + obstacles).

Self-contained (pinocchio, coal, numpy): it runs inside a peer's own virtual environment.
Collision pairs: every moving robot geometry against every obstacle, and the self pairs lynxplan
checks: given by name (``self_pairs``, lynxplan's own list, its SRDF's disabled pairs left out),
or else robot geometries on non-adjacent joints (same or parent/child joints are skipped).
"""

from __future__ import annotations

from typing import Any

import numpy as np


def obstacle_shape(entry: dict[str, Any]) -> Any:
    import coal

    if entry["type"] == "box":
        return coal.Box(*entry["size"])
    if entry["type"] == "sphere":
        return coal.Sphere(entry["radius"])
    return coal.Cylinder(entry["radius"], entry["length"])


def build(
    urdf: str, obstacles: list[dict[str, Any]], self_pairs: list[list[str]] | None = None
) -> tuple[Any, Any, Any, Any]:
    """(model, data, geometry model with obstacles and pairs, geometry data); ``self_pairs``:
    the robot's self pairs as [name, name] of its collision geometries (None: non-adjacent)."""
    import pinocchio as pin

    model = pin.buildModelFromUrdf(urdf)
    geometry = pin.buildGeomFromUrdf(model, urdf, pin.GeometryType.COLLISION)
    robot = len(geometry.geometryObjects)
    for entry in obstacles:
        placement = pin.SE3(np.array(entry["rotation"]), np.array(entry["centre"]))
        geometry.addGeometryObject(
            pin.GeometryObject(entry["name"], 0, 0, placement, obstacle_shape(entry))
        )
    joints = [geometry.geometryObjects[i].parentJoint for i in range(robot)]
    parents = list(model.parents)
    for g in range(robot):
        if joints[g] != 0:
            for o in range(robot, len(geometry.geometryObjects)):
                geometry.addCollisionPair(pin.CollisionPair(g, o))
    if self_pairs is not None:
        for name_a, name_b in self_pairs:
            a, b = geometry.getGeometryId(name_a), geometry.getGeometryId(name_b)
            geometry.addCollisionPair(pin.CollisionPair(a, b))
        return model, model.createData(), geometry, pin.GeometryData(geometry)
    for a in range(robot):
        for b in range(a + 1, robot):
            ja, jb = joints[a], joints[b]
            if ja != jb and parents[ja] != jb and parents[jb] != ja:
                geometry.addCollisionPair(pin.CollisionPair(a, b))
    return model, model.createData(), geometry, pin.GeometryData(geometry)


def make_validity(
    urdf: str, obstacles: list[dict[str, Any]], self_pairs: list[list[str]] | None = None
) -> Any:
    """A Python callable q -> bool (True: collision-free), pinocchio.computeCollisions."""
    import pinocchio as pin

    model, data, geometry, geometry_data = build(urdf, obstacles, self_pairs)

    def valid(q: np.ndarray) -> bool:
        return not pin.computeCollisions(model, data, geometry, geometry_data, q, True)

    return valid, model


def result_row(
    problem: str, seed: int, solved: bool, times: tuple[float, float, float], path: list[Any]
) -> dict[str, Any]:
    """One JSON result row: times are (began, planned, done) perf counters, in [s]."""
    began, planned, done = times
    return {
        "problem": problem,
        "seed": seed,
        "solved": solved,
        "plan_time": planned - began,
        "simplify_time": done - planned,
        "path": path,
    }
