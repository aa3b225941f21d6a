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

from lynxplan.service import compute, inputs, kinematics_tasks, sizes, wire
from lynxplan.service.config import ServiceConfig
from lynxplan.service.jobs import RunManager
from lynxplan.service.problems import Problem
from lynxplan.service.robots import (
    check_robot_name,
    get_robot,
    ik_slots,
    is_al5,
    motion_robot,
    robot_dof,
)
from lynxplan.service.schemas import openapi_body
from lynxplan.service.workers import ComputePool


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
        name = inputs.robot_name(body)
        check_robot_name(name)
        dof, owner = robot_dof(name), f"{name} ({robot_dof(name)} joints)"
        if q_value is None:
            raise Problem(422, f"q is required: joint angles ({dof},) or (N, {dof}) of {owner} "
                          "in rad", "q")  # fmt: skip
        q = wire.as_array(q_value, "q", (dof,), limit=batch_limit(request), owner=owner)
        count = len(q) if q.ndim == 2 else 1
        answer = wire.answer_format(request)
        per_pose = sizes.FK_POSE_BYTES["json" if answer == "json" else "binary"]
        sizes.check_answer(config, "q", count, per_pose, "poses")
        if kinematics_tasks.fk_inline(count):
            encoded = kinematics_tasks.fk_answer(name, q, answer)
        else:
            encoded = await pool.call_encoded(request, "fk", robot=name, q=q, answer=answer)
        return wire.encoded_response(encoded)

    @app.post("/ik", tags=["kinematics"], openapi_extra=openapi_body("IkRequest", binary=True))
    async def ik(request: Request) -> Response:
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
        name = inputs.robot_name(body)
        arm = get_robot(name)
        dof = robot_dof(name)
        count = len(T) if batch else 1
        reference = inputs.reference(body, count if batch else None, dof, name)
        if batch:
            answer = wire.answer_format(request)
            slots = ik_slots(arm, only_approach)
            per_pose = sizes.ik_pose_bytes("json" if answer == "json" else "binary", slots, dof)
            sizes.check_answer(config, "T", count, per_pose, "poses")
            task: dict[str, Any] = {"robot": name, "T": T, "reference": reference,
                                    "approach_only": only_approach, "verify": verify,
                                    "answer": answer}  # fmt: skip
        else:
            select = inputs.choice(body, "select", arm.selection_rules)
            task = {"robot": name, "T": T, "reference": reference, "select": select,
                    "approach_only": only_approach}  # fmt: skip
        if kinematics_tasks.ik_inline(arm, count, only_approach):
            encoded = (kinematics_tasks.ik_batch_answer(**task) if batch
                       else kinematics_tasks.ik_single_answer(**task))  # fmt: skip
        elif batch and is_al5(arm) and _dask_batch(runs(), config, count):
            encoded = await _dask_ik(runs(), task)
        else:
            encoded = await pool.call_encoded(request, "ik", **task)
        response = wire.encoded_response(encoded)
        # Server time from the first body byte to the encoded answer (RFC Server-Timing).
        response.headers["Server-Timing"] = f"app;dur={1e3 * (time.perf_counter() - start):.3f}"
        return response

    # -- collision, trajectories, plans: sizes checked here, computed by the compute pool ----
    @app.post("/check", tags=["collision"], openapi_extra=openapi_body("CheckRequest"))
    async def check(request: Request) -> Response:
        body = await json_body(request)
        name = inputs.robot_name(body)
        get_robot(motion_robot(name, "/check"))
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
        arm = get_robot(motion_robot(name, "/trajectory"))
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
        arm = get_robot(motion_robot(name, "/plan"))
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
        get_robot(motion_robot(name, "/view"))
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


def _dask_batch(manager: RunManager, config: ServiceConfig, count: int) -> bool:
    """Whether an AL5 /ik batch of ``count`` poses goes to the configured Dask cluster."""
    from lynxplan.service.pools import DaskPool

    return isinstance(manager.pool, DaskPool) and count >= config.dask_batch


async def _dask_ik(manager: RunManager, task: dict[str, Any]) -> wire.Encoded:
    """An AL5 /ik batch solved on the Dask cluster (cancelled if this request is), encoded
    off the event loop."""
    from lynxplan.service.pools import DaskPool

    assert isinstance(manager.pool, DaskPool)
    arguments = (task["T"], task["reference"], task["approach_only"], task["verify"])
    future = manager.pool.client.submit(kinematics_tasks.ik_batch_arrays, *arguments, pure=False)
    try:
        arrays: dict[str, np.ndarray] = await asyncio.to_thread(future.result)
    except asyncio.CancelledError:
        future.cancel()
        raise
    scalars = {"count": len(task["T"])}
    return await asyncio.to_thread(wire.encode_answer, arrays, scalars, task["answer"])


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
