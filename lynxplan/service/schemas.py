"""Request schemas for the OpenAPI document only: the routes decode bodies with orjson and numpy
(:mod:`.inputs`), never element by element through these models."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, Field


class FkRequest(BaseModel):
    """Forward kinematics: tool pose of joint angles."""

    robot: str = Field("al5", description="Robot name (GET /robots): any built-in robot.")
    q: list[Any] = Field(
        description="Joint angles, (n,) or (N, n), in rad; n: the robot's joints (al5, so100, "
        "so101: 5; ur5, ur10: 6; panda: 7)."
    )


class IkRequest(BaseModel):
    """Inverse kinematics of one pose or a batch: ``T``, or ``position`` + ``approach`` (5-D)."""

    robot: str = Field("al5", description="Robot name (GET /robots): any built-in robot.")
    T: list[Any] | None = Field(None, description="Tool pose (4, 4) or (N, 4, 4), in m.")
    position: list[Any] | None = Field(None, description="Tool position (3,) or (N, 3), in m.")
    approach: list[Any] | None = Field(None, description="Approach axis (3,) or (N, 3).")
    q_reference: list[Any] | None = Field(
        None, description="(n,) or (N, n), in rad; n: the robot's joints."
    )
    select: Literal["nearest", "report"] = "nearest"
    approach_only: bool = False


class CheckRequest(BaseModel):
    """Joint-limit and collision check of configurations, or a trajectory when ``t`` is given."""

    robot: str = Field("al5", description="A 5-joint robot: al5, so100 or so101.")
    q: list[Any] = Field(description="(5,) or (N, 5), in rad.")
    t: list[float] | None = Field(None, description="Sample times (N,), in s.")
    obstacles: list[dict[str, Any]] = Field(
        default_factory=list,
        description="{type: box|sphere|cylinder, name, centre, size|radius|length, rotation}, m.",
    )
    self_collision: bool = False


class TrajectoryRequest(BaseModel):
    """Time-parameterisation of free motions through joint waypoints."""

    robot: str = "al5"
    waypoints: list[list[float]] = Field(description="(M, 5), in rad, M >= 2.")
    method: Literal["lspb", "ruckig", "toppra"] = "lspb"
    rate: float = Field(
        100.0, description="Sample rate, in Hz (1 to 10000; duration x rate is bounded: 413)."
    )
    timing: dict[str, float] | None = Field(None, description="{tt, ta} in s (lspb only).")
    limits: dict[str, Any] | None = Field(None, description="{velocity, acceleration, jerk}.")


class PlanRequest(BaseModel):
    """Collision-free motion planning (RRT-Connect, shortcut, verified, time-parameterised)."""

    robot: str = "al5"
    start: list[float] = Field(description="Start joint angles (5,), in rad.")
    goal: list[Any] = Field(description="Goal joints (5,) in rad, or tool pose (4, 4) in m.")
    obstacles: list[dict[str, Any]] = Field(default_factory=list, description="As /check.")
    seed: int = 0
    time_limit: float = Field(1.0, description="Planning budget, in s (at most 30).")
    options: dict[str, Any] | None = Field(
        None,
        description="PlannerOptions fields: clearance [0, 1] m, step [1e-4, 10] rad, goal_bias, "
        "max_nodes <= 1e6, shortcut_iterations, shortcut_patience, timing, max_acceleration and "
        "max_jerk (a number or 5, > 0), sample_rate [1, 10000] Hz.",
    )


class Scenario(BaseModel):
    """A scenario file's content (``kind``, ``name``, ...), as YAML or JSON."""

    kind: str
    name: str | None = None


_MODELS: dict[str, type[BaseModel]] = {
    model.__name__: model
    for model in (FkRequest, IkRequest, CheckRequest, TrajectoryRequest, PlanRequest, Scenario)
}
_BINARY = {"schema": {"type": "string", "format": "binary"}}


def openapi_body(name: str, *, binary: bool = False) -> dict[str, Any]:
    """``openapi_extra`` documenting a route's request body by the model ``name``."""
    schema = _MODELS[name].model_json_schema()
    content: dict[str, Any] = {"application/json": {"schema": schema}}
    if binary:
        content["application/x-npy"] = _BINARY
        content["application/octet-stream"] = _BINARY
    if name == "Scenario":
        content["application/yaml"] = {"schema": {"type": "string"}}
    extra: dict[str, Any] = {"requestBody": {"required": True, "content": content}}
    if binary:  # options of binary bodies travel in the query string
        extra["parameters"] = [
            {"name": "robot", "in": "query", "schema": {"type": "string", "default": "al5"}},
            {"name": "approach_only", "in": "query", "schema": {"type": "boolean"}},
            {"name": "verify", "in": "query", "schema": {"type": "boolean", "default": True},
             "description": "/ik batches: FK position residual of every branch"},
        ]  # fmt: skip
    return extra
