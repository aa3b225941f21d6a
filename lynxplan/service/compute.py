"""The computations behind the routes, on validated numpy arrays; no HTTP here.

They are plain functions of arrays (the kinematics ones in :mod:`.kinematics_tasks`, whose
``ik_batch_arrays`` a Dask worker runs for large batches).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from lynxplan.service import kinematics_tasks


def build_obstacles(specs: Sequence[Mapping[str, Any]]) -> list[Any]:
    """Obstacles from JSON objects ``{type: box|sphere|cylinder, name, centre, ...}`` in [m].

    Raises:
        KeyError, TypeError: a missing or misspelt key (the caller names the entry).
        lynxplan.exceptions.InputError: bad values.
    """
    from lynxplan.collision import BoxObstacle, CylinderObstacle, SphereObstacle

    kinds: dict[str, Any] = {
        "box": BoxObstacle,
        "sphere": SphereObstacle,
        "cylinder": CylinderObstacle,
    }
    obstacles = []
    for i, spec in enumerate(specs):
        fields = dict(spec)
        kind = fields.pop("type", None)
        if kind not in kinds:
            raise KeyError(f"obstacles[{i}].type must be one of box, sphere, cylinder")
        fields.setdefault("name", f"{kind}_{i}")
        obstacles.append(kinds[kind](**fields))
    return obstacles


def check_arrays(
    arm: Any,
    q: np.ndarray,
    t: np.ndarray | None,
    obstacles: list[Any],
    self_collision: bool,
) -> dict[str, Any]:
    """Joint-limit and collision check of configurations (N, 5), or of a trajectory with times.

    Without ``t``: the clearance of every configuration to every obstacle. With ``t`` (N,)
    strictly increasing [s]: :func:`lynxplan.collision.check_trajectory` (between samples too).
    """
    from lynxplan.collision import CollisionWorld, check_trajectory, clearance_profile

    configs = q.reshape(-1, 5)
    lower, upper = arm.limits.lower, arm.limits.upper
    within = ((configs >= lower) & (configs <= upper)).all(axis=1)
    world = CollisionWorld(arm, obstacles, self_collision=self_collision)
    out: dict[str, Any] = {"within_limits": within, "all_within_limits": bool(within.all())}
    if t is None:
        clearance = (
            clearance_profile(world, configs) if obstacles else np.full((len(configs), 0), np.inf)
        )
        per_config = clearance.min(axis=1) if clearance.shape[1] else np.full(len(configs), np.inf)
        out.update(
            clearance=clearance,
            min_clearance=per_config,
            collision_free=bool((per_config > 0).all()),
            obstacles=[o.name for o in obstacles],
        )
        return out
    # the exact verifier's report (lynxplan.collision.MotionReport), every field
    out.update(check_trajectory(world, configs, t).as_dict())
    return out


def trajectory_profiles(
    arm: Any,
    waypoints: np.ndarray,
    method: str,
    rate: float,
    limits: Any,
    timing: tuple[float, float] | None,
    max_samples: int | None = None,
) -> list[Any]:
    """Time-parameterise free (joint-space) motions through ``waypoints`` (M, 5) [rad].

    Args:
        method: ``"lspb"`` (``timing`` (tt, ta) [s] per segment, or the shortest LSPB within
            ``limits`` when None), ``"ruckig"`` or ``"toppra"``.
        rate: Sample rate, in [Hz].
        limits: :class:`lynxplan.trajectory.MotionLimits`.
        max_samples: Most samples over all segments (None: the resource limit in force), each
            segment's checked before it is sampled.

    Returns:
        One library ``Profile`` per segment (M - 1).

    Raises:
        ResourceLimitError: the segments need more than ``max_samples`` samples.
    """
    from lynxplan import guards
    from lynxplan.trajectory import LspbTiming, free_segment, ruckig_profile, toppra_profile
    from lynxplan.trajectory.retime import lspb_profile

    budget = guards.current_limits().max_samples if max_samples is None else max_samples
    profiles: list[Any] = []
    for a, b in itertools.pairwise(waypoints):
        fixed = LspbTiming(*timing) if timing is not None and method == "lspb" else None
        segment = free_segment(a, b, fixed, limits=limits)
        used = sum(len(p.t) for p in profiles)
        with guards.raised_limits(max_samples=max(1, budget - used)):
            if method == "lspb":
                profiles.append(lspb_profile(segment, segment.timing, rate))
            elif method == "ruckig":
                profiles.append(ruckig_profile(a, b, limits, rate))
            else:
                profiles.append(toppra_profile(segment, limits, rate))
    return profiles


def view_html(arm: Any, q: np.ndarray) -> str:
    """A self-contained meshcat HTML page of the arm at ``q`` (5,) [rad]
    (:func:`lynxplan.viz.export_html`; no network needed to display it)."""
    import tempfile
    from pathlib import Path

    from lynxplan.viz import export_html

    with tempfile.TemporaryDirectory(prefix="lynxplan-view-") as folder:
        path = export_html(
            arm, q.reshape(1, 5), np.zeros(1), Path(folder) / "view.html", autoplay=False
        )
        return path.read_text(encoding="utf-8")


#: Largest planning time budget one /plan request may ask for, in [s].
MAX_PLAN_TIME = 30.0
#: Longest a compute worker may work on one request (the longest plan and its verification
#: and timing), in [s]; the worker is killed past it.
MAX_REQUEST_TIME = 2 * MAX_PLAN_TIME


def plan_json(
    arm: Any,
    start: np.ndarray,
    goal: np.ndarray,
    obstacles: list[Any],
    seed: int,
    time_limit: float,
    options: dict[str, Any],
) -> dict[str, Any]:
    """:func:`lynxplan.planning.plan` from ``start`` (5,) [rad] to ``goal`` ((5,) joints or
    (4, 4) tool pose [m]); the trajectory's fields as a JSON-ready mapping."""
    import dataclasses

    from lynxplan.planning import PlannerOptions, plan

    result = plan(arm, obstacles, start, goal, seed=seed, time_limit=time_limit,
                  options=PlannerOptions(**options))  # fmt: skip
    fields = {f.name: getattr(result, f.name) for f in dataclasses.fields(result)}
    fields.update(
        verification=result.verification.as_dict(),
        stats=dataclasses.asdict(result.stats),
        options=dataclasses.asdict(result.options),
        duration=result.duration,
    )
    return fields


# -- tasks of the compute pool (:mod:`.workers`): robot by name, answer as JSON/HTML bytes ------


def check_task(
    robot: str, q: np.ndarray, t: np.ndarray | None, obstacles: list[Any], self_collision: bool
) -> bytes:
    """:func:`check_arrays` of built-in ``robot`` with obstacle specs, as JSON bytes."""
    from lynxplan.service.robots import get_robot
    from lynxplan.service.wire import dumps

    world = build_obstacles(obstacles)
    return dumps(check_arrays(get_robot(robot), q, t, world, self_collision))


def trajectory_task(
    robot: str,
    waypoints: np.ndarray,
    method: str,
    rate: float,
    limits: Any,
    timing: tuple[float, float] | None,
    max_samples: int,
) -> bytes:
    """:func:`trajectory_profiles` as JSON bytes, at most ``max_samples`` samples in all."""
    from lynxplan.service.robots import get_robot
    from lynxplan.service.wire import dumps

    profiles = trajectory_profiles(
        get_robot(robot), waypoints, method, rate, limits, timing, max_samples
    )
    return dumps(
        {
            "method": method,
            "duration": float(sum(p.t[-1] for p in profiles)),
            "segments": [p._asdict() for p in profiles],
        }
    )


def plan_task(
    robot: str,
    start: np.ndarray,
    goal: np.ndarray,
    obstacles: list[Any],
    seed: int,
    time_limit: float,
    options: dict[str, Any],
    max_samples: int,
) -> bytes:
    """:func:`plan_json` as JSON bytes, the trajectory at most ``max_samples`` samples."""
    from lynxplan import guards
    from lynxplan.service.robots import get_robot
    from lynxplan.service.wire import dumps

    arm, world = get_robot(robot), build_obstacles(obstacles)
    with guards.raised_limits(max_samples=max_samples):
        return dumps(plan_json(arm, start, goal, world, seed, time_limit, options))


def view_task(robot: str, q: np.ndarray) -> bytes:
    """:func:`view_html` as UTF-8 bytes."""
    from lynxplan.service.robots import get_robot

    return view_html(get_robot(robot), q).encode("utf-8")


#: The computations a compute worker runs, by name: each answers JSON or HTML bytes, or
#: (content, media type, headers).
TASKS: dict[str, Callable[..., Any]] = {
    "check": check_task,
    "trajectory": trajectory_task,
    "plan": plan_task,
    "view": view_task,
    "fk": kinematics_tasks.fk_answer,
    "ik": kinematics_tasks.ik_answer,
}


def run_task(name: str, kwargs: dict[str, Any], memory_limit: int) -> tuple[int, Any]:
    """``(200, answer bytes)`` of task ``name``, or ``(status, (detail, field))``: 413 for a
    resource limit or the worker's memory limit, 422 for bad input, 500 for a bug (one line,
    no traceback)."""
    from lynxplan.exceptions import LynxplanError, ResourceLimitError
    from lynxplan.service.problems import Problem

    size_field = kwargs.pop("size_field", None)
    try:
        return 200, TASKS[name](**kwargs)
    except Problem as exc:
        return exc.status, (exc.detail, exc.field)
    except ResourceLimitError as exc:
        detail = f"{exc.quantity}: {exc.requested:.4g}, more than the limit of {exc.limit:.4g}"
        return 413, (detail, size_field)
    except LynxplanError as exc:
        field = getattr(exc, "name", None)
        return 422, (str(exc).splitlines()[0], field if isinstance(field, str) else None)
    except MemoryError:
        limit = f"{memory_limit / 1024**3:.3g} GiB" if memory_limit else "the host's memory"
        return 413, (f"the computation needs more memory than a worker has ({limit})", size_field)
    except Exception as exc:  # a bug in lynxplan: one line, never a traceback
        return 500, (f"internal error ({type(exc).__name__})", None)


def warm_up() -> None:
    """Import what the tasks use and load the AL5 once (a worker's first request is fast)."""
    import lynxplan.collision
    import lynxplan.planning
    import lynxplan.trajectory.retime  # noqa: F401
    from lynxplan._toppra import import_toppra
    from lynxplan.service.robots import get_robot

    import_toppra()

    arm = get_robot("al5")
    check_arrays(arm, np.zeros((1, 5)), None, [], False)
