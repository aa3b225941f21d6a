"""The kinematics, collision, trajectory and planning routes (decoding in :mod:`.inputs` and
:mod:`.wire`, computation in :mod:`.compute`)."""

from __future__ import annotations

import asyncio
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from fastapi import FastAPI, Request
from starlette.responses import HTMLResponse, Response

from lynxplan.service import compute, inputs, sizes, wire
from lynxplan.service.config import ServiceConfig
from lynxplan.service.jobs import RunManager
from lynxplan.service.problems import Problem
from lynxplan.service.robots import get_robot, is_al5, robot_ik_batch_arrays
from lynxplan.service.schemas import openapi_body
from lynxplan.service.workers import ComputePool

#: Batches at least this large are solved off the event loop (or on Dask when configured).
THREAD_BATCH = 2_000


def add_kinematics_routes(
    app: FastAPI, config: ServiceConfig, runs: Callable[[], RunManager]
) -> ComputePool:
    """Add ``/fk``, ``/ik``, ``/check``, ``/trajectory``, ``/plan`` and ``/view`` to ``app``.

    Returns:
        The compute pool that runs /check, /trajectory, /plan and /view (the caller starts it
        with the server and closes it after).
    """
    view_lock = asyncio.Lock()
    pool = ComputePool(config.compute_workers, config.run_memory, compute.MAX_REQUEST_TIME)

    def answer_kind(request: Request) -> str:
        return "binary" if wire.wants_binary(request) else "json"

    async def json_body(request: Request) -> dict[str, Any]:
        return wire.parse_json_object(await wire.read_body(request, config.max_body))

    def batch_limit(request: Request) -> int:
        return config.max_batch if wire.is_binary(request) else config.max_json_batch

    @app.post("/fk", tags=["kinematics"], openapi_extra=openapi_body("FkRequest", binary=True))
    async def fk(request: Request) -> Response:
        # Query options are read by hand: FastAPI's parameter machinery costs ~0.3 ms a request.
        robot = request.query_params.get("robot", "al5") if request.scope["query_string"] else "al5"
        if wire.is_binary(request):
            body: dict[str, Any] = {"robot": robot}
            q_value: Any = wire.decode_binary(
                request, await wire.read_body(request, config.max_body), "q"
            )
        else:
            body = await json_body(request)
            q_value = body.get("q")
        arm = get_robot(inputs.robot_name(body))
        if q_value is None:
            raise Problem(422, "q is required: joint angles (5,) or (N, 5) in rad", "q")
        q = wire.as_array(q_value, "q", (5,), limit=batch_limit(request))
        count = len(q) if q.ndim == 2 else 1
        sizes.check_answer(config, "q", count, sizes.FK_POSE_BYTES[answer_kind(request)], "poses")
        result = await _maybe_threaded(len(q) if q.ndim == 2 else 1, compute.fk_arrays, arm, q)
        if wire.wants_binary(request):
            return wire.arrays_response(
                request, {"T": result["T"]}, {"residual": result["residual"]}
            )
        return wire.json_response(result)

    @app.post("/ik", tags=["kinematics"], openapi_extra=openapi_body("IkRequest", binary=True))
    async def ik(
        request: Request,
    ) -> Response:
        start = time.perf_counter()
        params = request.query_params if request.scope["query_string"] else {}
        robot = params.get("robot", "al5")
        approach_only = inputs.query_flag(params, "approach_only", False)
        verify = inputs.query_flag(params, "verify", True)
        if wire.is_binary(request):
            raw = await wire.read_body(request, config.max_body)
            body: dict[str, Any] = {"robot": robot, "approach_only": approach_only}
            T = wire.as_array(
                wire.decode_binary(request, raw, "T"), "T", (4, 4), limit=config.max_batch
            )
            batch, only_approach = T.ndim == 3, approach_only
        else:
            body = await json_body(request)
            T, batch, only_approach = inputs.ik_target(body, config.max_json_batch)
        arm = get_robot(inputs.robot_name(body))
        if not batch:
            select = inputs.choice(body, "select", ("nearest", "report"))
            result, residual = compute.ik_single(
                arm, T, inputs.reference(body, None), select, only_approach
            )
            return wire.json_response(_ik_single_json(result, residual))
        reference = inputs.reference(body, len(T))
        sizes.check_answer(config, "T", len(T), sizes.IK_POSE_BYTES[answer_kind(request)], "poses")
        scalars: dict[str, Any] = {"count": len(T)}
        if is_al5(arm):
            arrays = await _ik_batch(runs(), config, T, reference, only_approach, verify)
        else:  # SO-100, SO-101: lynxplan.robots (their branch slots named in the answer)
            arrays, scalars["branch_names"] = await _maybe_threaded(
                len(T), robot_ik_batch_arrays, arm, T, reference, only_approach
            )
        if wire.wants_binary(request):
            response = wire.arrays_response(request, arrays, scalars)
        else:
            response = wire.json_response({**scalars, **arrays})
        # Server time from the first body byte to the encoded answer (RFC Server-Timing).
        response.headers["Server-Timing"] = f"app;dur={1e3 * (time.perf_counter() - start):.3f}"
        return response

    # -- collision, trajectories, plans: sizes checked here, computed by the compute pool ----
    @app.post("/check", tags=["collision"], openapi_extra=openapi_body("CheckRequest"))
    async def check(request: Request) -> Response:
        body = await json_body(request)
        name = inputs.robot_name(body)
        get_robot(name)
        q = wire.as_array(body.get("q"), "q", (5,), limit=config.max_json_batch)
        t = None if body.get("t") is None else wire.as_array(body["t"], "t", (), batch=True)
        if t is not None and t.shape != (len(q.reshape(-1, 5)),):
            raise Problem(422, f"t must have shape ({len(q.reshape(-1, 5))},). Got: {t.shape}", "t")
        specs = inputs.obstacle_specs(body)
        sizes.check_pairs(config, len(q.reshape(-1, 5)), len(specs))
        _obstacles(body)  # a bad obstacle is a 422 here, before a worker is asked
        content = await pool.call(request, "check", robot=name, q=q, t=t, obstacles=specs,
                                  self_collision=inputs.flag(body, "self_collision"))  # fmt: skip
        return Response(content, media_type="application/json")

    @app.post("/trajectory", tags=["trajectory"], openapi_extra=openapi_body("TrajectoryRequest"))
    async def trajectory(request: Request) -> Response:
        body = await json_body(request)
        name = inputs.robot_name(body)
        arm = get_robot(name)
        waypoints = wire.as_array(body.get("waypoints"), "waypoints", (5,), limit=1000)
        if waypoints.ndim != 2 or len(waypoints) < 2:
            raise Problem(
                422, "waypoints must hold at least two configurations (M, 5)", "waypoints"
            )
        method = inputs.choice(body, "method", ("lspb", "ruckig", "toppra"))
        rate = inputs.number(body, "rate", 100.0, 1.0, 10_000.0)
        timing = _timing(body) if method == "lspb" else None
        limits = inputs.motion_limits(body, arm)
        _check_trajectory_samples(config, body, arm, waypoints, limits, rate, timing)
        content = await pool.call(
            request, "trajectory", robot=name, waypoints=waypoints, method=method, rate=rate,
            limits=limits, timing=timing, max_samples=sizes.sample_limit(config),
            size_field="rate",
        )  # fmt: skip
        return Response(content, media_type="application/json")

    @app.post("/plan", tags=["planning"], openapi_extra=openapi_body("PlanRequest"))
    async def plan(request: Request) -> Response:
        body = await json_body(request)
        name = inputs.robot_name(body)
        arm = get_robot(name)
        start = wire.as_array(body.get("start"), "start", (5,), batch=False)
        goal_value = body.get("goal")
        goal_shape = (4, 4) if isinstance(goal_value, list) and goal_value and isinstance(
            goal_value[0], list) else (5,)  # fmt: skip
        goal = wire.as_array(goal_value, "goal", goal_shape, batch=False)
        _obstacles(body)
        seed = int(inputs.number(body, "seed", 0, 0, 2**31 - 1))
        budget = inputs.number(body, "time_limit", 1.0, 1e-3, compute.MAX_PLAN_TIME)
        options = inputs.plan_options(body, 5)
        if goal.shape == (5,):  # a joint goal: the motion's samples are bounded from below
            _check_plan_samples(config, arm, start, goal, options)
        content = await pool.call(
            request, "plan", robot=name, start=start, goal=goal,
            obstacles=inputs.obstacle_specs(body), seed=seed, time_limit=budget,
            options=options, max_samples=sizes.sample_limit(config), size_field="options",
        )  # fmt: skip
        return Response(content, media_type="application/json")

    @app.post("/view", tags=["kinematics"], openapi_extra=openapi_body("FkRequest"))
    async def view(request: Request) -> Response:
        body = await json_body(request)
        name = inputs.robot_name(body)
        get_robot(name)
        q = wire.as_array(body.get("q"), "q", (5,), batch=False)
        async with view_lock:  # one meshcat server process at a time
            html = await pool.call(request, "view", robot=name, q=q)
        return HTMLResponse(html)

    return pool


def _check_trajectory_samples(
    config: ServiceConfig,
    body: dict[str, Any],
    arm: Any,
    waypoints: np.ndarray,
    limits: Any,
    rate: float,
    timing: tuple[float, float] | None,
) -> None:
    """413 before any work when the /trajectory motion implies more samples than the limit."""
    from lynxplan.trajectory import MotionLimits

    base = MotionLimits.from_joint_limits(arm.limits)
    given = body.get("limits") or {}
    values = {
        "timing.tt": None if timing is None else timing[0],
        "limits.velocity": limits.velocity,
        "limits.acceleration": limits.acceleration,
        "rate": rate,
    }
    defaults: dict[str, Any] = {} if timing is None else {"timing.tt": None}
    defaults.update({f"limits.{k}": getattr(base, k) for k in ("velocity", "acceleration")
                     if k in given})  # fmt: skip

    def count(v: dict[str, Any]) -> tuple[float, float]:
        return sizes.motion_samples(waypoints, v["limits.velocity"], v["limits.acceleration"],
                                    v["rate"], v["timing.tt"])  # fmt: skip

    sizes.check_samples(config, count, values, defaults, "rate")


def _check_plan_samples(
    config: ServiceConfig, arm: Any, start: np.ndarray, goal: np.ndarray, options: dict[str, Any]
) -> None:
    """413 before planning when the direct motion from ``start`` to the joint ``goal`` (a lower
    bound of any path's) already implies more samples than the limit."""
    from lynxplan.planning.timing import DEFAULT_SAMPLE_RATE
    from lynxplan.trajectory.limits import DEFAULT_MAX_ACCELERATION

    ends = np.stack([start, goal])
    values = {
        "options.max_acceleration": options.get("max_acceleration", DEFAULT_MAX_ACCELERATION),
        "options.sample_rate": options.get("sample_rate", DEFAULT_SAMPLE_RATE),
    }
    defaults = {"options.max_acceleration": DEFAULT_MAX_ACCELERATION} if (
        "max_acceleration" in options) else {}  # fmt: skip

    def count(v: dict[str, Any]) -> tuple[float, float]:
        return sizes.motion_samples(ends, arm.limits.velocity, v["options.max_acceleration"],
                                    v["options.sample_rate"])  # fmt: skip

    sizes.check_samples(config, count, values, defaults, "options.sample_rate")


async def _maybe_threaded(count: int, function: Any, *args: Any) -> Any:
    if count >= THREAD_BATCH:
        return await asyncio.to_thread(function, *args)
    return function(*args)


async def _ik_batch(
    manager: RunManager,
    config: ServiceConfig,
    T: np.ndarray,
    reference: Any,
    approach: bool,
    verify: bool,
) -> dict[str, np.ndarray]:
    from lynxplan.service.pools import DaskPool

    if isinstance(manager.pool, DaskPool) and len(T) >= config.dask_batch:
        future = manager.pool.client.submit(
            compute.ik_batch_arrays, T, reference, approach, verify, pure=False
        )
        result: dict[str, np.ndarray] = await asyncio.to_thread(future.result)
        return result
    arrays: dict[str, np.ndarray] = await _maybe_threaded(
        len(T), compute.ik_batch_arrays, T, reference, approach, verify
    )
    return arrays


def _ik_single_json(result: Any, residual: float) -> dict[str, Any]:
    selected = result.selected
    return {
        "q": None if selected is None else result.solutions[selected].q,
        "selected": selected,
        "branch": None if selected is None else result.solutions[selected].branch,
        "orientation_residual": result.orientation_residual,
        "position_residual": residual,
        "solutions": [s._asdict() for s in result.solutions],
    }


def _timing(body: dict[str, Any]) -> tuple[float, float] | None:
    timing = body.get("timing")
    if timing is None:
        return None
    if not isinstance(timing, dict) or set(timing) != {"tt", "ta"}:
        raise Problem(422, "timing must be an object {tt, ta} in s", "timing")
    return (
        inputs.number(timing, "tt", 0.0, 1e-6, 3600.0),
        inputs.number(timing, "ta", 0.0, 1e-9, 1800.0),
    )


def _obstacles(body: dict[str, Any]) -> list[Any]:
    try:
        return compute.build_obstacles(inputs.obstacle_specs(body))
    except (KeyError, TypeError) as exc:
        raise Problem(422, f"obstacle: {str(exc).strip(chr(39))}", "obstacles") from None
