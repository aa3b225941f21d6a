"""Request schemas for the OpenAPI document only: the routes decode bodies with orjson and numpy
(:mod:`.inputs`), never element by element through these models."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, Field


class FkRequest(BaseModel):
    """Forward kinematics: tool pose of joint angles."""

    robot: str = Field("al5", description="Robot name (GET /robots).")
    q: list[Any] = Field(description="Joint angles, (5,) or (N, 5), in rad.")


class IkRequest(BaseModel):
    """Inverse kinematics of one pose or a batch: ``T``, or ``position`` + ``approach`` (5-D)."""

    robot: str = "al5"
    T: list[Any] | None = Field(None, description="Tool pose (4, 4) or (N, 4, 4), in m.")
    position: list[Any] | None = Field(None, description="Tool position (3,) or (N, 3), in m.")
    approach: list[Any] | None = Field(None, description="Approach axis (3,) or (N, 3).")
    q_reference: list[Any] | None = Field(None, description="(5,) or (N, 5), in rad.")
    select: Literal["nearest", "report"] = "nearest"
    approach_only: bool = False


class CheckRequest(BaseModel):
    """Joint-limit and collision check of configurations, or a trajectory when ``t`` is given."""

    robot: str = "al5"
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
    rate: float = Field(100.0, description="Sample rate, in Hz.")
    timing: dict[str, float] | None = Field(None, description="{tt, ta} in s (lspb only).")
    limits: dict[str, Any] | None = Field(None, description="{velocity, acceleration, jerk}.")


class Scenario(BaseModel):
    """A scenario file's content (``kind``, ``name``, ...), as YAML or JSON."""

    kind: str
    name: str | None = None


_MODELS: dict[str, type[BaseModel]] = {
    model.__name__: model
    for model in (FkRequest, IkRequest, CheckRequest, TrajectoryRequest, Scenario)
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
    return {"requestBody": {"required": True, "content": content}}
