"""Bench section ``collision``: the OK task's full collision check at 1 kHz against a naive loop.

Both sides do the same work: every arm primitive against both SPEC walls at each of the 26,001
samples, plus the between-sample test of :mod:`lynxplan.collision.check`. The naive loop runs
Pinocchio FK and builds python-fcl objects at every sample, queries every pair, then applies the
same between-sample inequality; it is timed on the first ``NAIVE_SAMPLES`` samples and scaled
to the whole trajectory (linear in the sample count). The naive loop and the python-fcl engine
need python-fcl (the `test` extra); without it the section reports the coal figures only.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lynxplan.bench import Figure, median_seconds, peer_missing

RATE = 1000.0
NAIVE_SAMPLES = 2000
TARGET_SPEEDUP = 10.0


def _ok_task_samples() -> Any:
    from lynxplan.trajectory.ok_task import ok_task_plan

    return ok_task_plan().sample(RATE)


def naive_check(arm: Any, obstacles: list[Any], q: np.ndarray) -> tuple[float, int]:
    """Per sample: FK, new FCL objects, every pair's distance; then the between-sample test.

    Returns (minimum clearance [m], number of sample intervals failing the inequality).
    """
    import fcl
    import pinocchio as pin

    from lynxplan.collision import CollisionWorld

    reach = np.stack([p.reach for p in CollisionWorld(arm, []).links])
    geometry_data = pin.GeometryData(arm.collision_model)
    request = fcl.DistanceRequest(enable_signed_distance=True)
    shapes = arm.collision_model.geometryObjects
    distances = np.empty((len(q), len(shapes), len(obstacles)))
    for n, config in enumerate(q):
        pin.forwardKinematics(arm.model, arm.data, config)
        pin.updateGeometryPlacements(arm.model, arm.data, arm.collision_model, geometry_data)
        walls = [
            fcl.CollisionObject(
                fcl.Box(*o.size.tolist()), fcl.Transform(np.asarray(o.rotation), o.centre)
            )
            for o in obstacles
        ]
        for g, shape in enumerate(shapes):
            placement = geometry_data.oMg[g]
            geometry = shape.geometry
            if type(geometry).__name__ == "Box":
                primitive = fcl.Box(*(2.0 * np.asarray(geometry.halfSide)).tolist())
            else:
                primitive = fcl.Cylinder(geometry.radius, 2.0 * geometry.halfLength)
            link = fcl.CollisionObject(
                primitive, fcl.Transform(placement.rotation, placement.translation)
            )
            for o, wall in enumerate(walls):
                distances[n, g, o] = fcl.distance(link, wall, request)
    motion = np.abs(np.diff(q, axis=0)) @ reach.T  # (N - 1, G)
    failing = (distances[:-1] + distances[1:] <= motion[:, :, None]).any(axis=(1, 2))
    return float(distances.min()), int(failing.sum())


def run(quick: bool) -> list[Figure]:
    """Measure the collision figures (the python-fcl ones only where python-fcl, a test extra,
    is installed)."""
    from importlib.util import find_spec

    from lynxplan.arm import load_arm
    from lynxplan.collision import CollisionWorld, check_trajectory
    from lynxplan.trajectory.ok_task import ok_task_walls

    arm = load_arm()
    samples = _ok_task_samples()
    q, t, segment = samples.q, samples.t, samples.segment
    bound = np.abs(samples.qdd).max(axis=0)
    walls = ok_task_walls()
    repeats = 3 if quick else 7
    figures = []
    fast: dict[str, float] = {}
    engines = ("coal", "fcl") if find_spec("fcl") is not None else ("coal",)
    for engine in engines:
        world = CollisionWorld(arm, walls, engine=engine)

        def check(world: CollisionWorld = world) -> object:
            return check_trajectory(world, q, t, segment, acceleration_bound=bound)

        fast[engine] = median_seconds(check, repeats=repeats)
        figures.append(
            Figure("collision", f"OK task check, {len(q)} samples at 1 kHz, {engine} engine",
                   fast[engine] * 1e3, "ms")
        )  # fmt: skip
    build = median_seconds(lambda: CollisionWorld(arm, walls), repeats=repeats)
    figures.append(Figure("collision", "world build (once per check)", build * 1e3, "ms"))
    if "fcl" not in engines:
        return [*figures, peer_missing("collision", "python-fcl (naive loop, fcl engine)",
                                       "module fcl: pip install python-fcl")]  # fmt: skip
    subset = q[: 500 if quick else NAIVE_SAMPLES]
    naive = (
        median_seconds(lambda: naive_check(arm, walls, subset), repeats=3) * len(q) / len(subset)
    )
    figures.append(
        Figure("collision", f"naive loop (new FCL objects per sample), from {len(subset)} samples",
               naive * 1e3, "ms")
    )  # fmt: skip
    for engine in engines:
        speedup = naive / fast[engine]
        figures.append(
            Figure("collision", f"speed-up of the {engine} check over the naive loop", speedup, "x",
                   target=f">= {TARGET_SPEEDUP:g}", met=speedup >= TARGET_SPEEDUP)
        )  # fmt: skip
    return figures
