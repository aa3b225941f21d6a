"""Reading the AL5's URDF: the shipped file, native parser messages, joint limits, and the DH
lengths (checked against the structure of SPEC Part 1)."""

from __future__ import annotations

import math
import os
import sys
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from lynxplan.arm.geometry import DH_FRAMES, JOINT_NAMES, TOOL_FRAME, ArmGeometry, JointLimits
from lynxplan.constants import URDF_STRUCTURE_TOLERANCE
from lynxplan.exceptions import ModelError


@contextmanager
def native_stderr_captured() -> Iterator[Callable[[], str]]:
    """Capture what native code (urdfdom, Pinocchio) writes to file descriptor 2 in the block.

    Yields a function returning the captured text, so that a parser's own messages become part
    of one clear error instead of noise on the user's terminal.
    """
    try:
        saved = os.dup(2)
    except OSError:  # no usable stderr descriptor (embedded interpreter): capture nothing
        yield lambda: ""
        return
    with tempfile.TemporaryFile() as sink:

        def captured() -> str:
            return os.pread(sink.fileno(), 4096, 0).decode("utf-8", "replace")

        sys.stderr.flush()
        os.dup2(sink.fileno(), 2)
        try:
            yield captured
        finally:
            os.dup2(saved, 2)
            os.close(saved)


def read_limits(model: Any) -> JointLimits:
    position = np.column_stack((model.lowerPositionLimit, model.upperPositionLimit))
    velocity = np.array(model.velocityLimit, dtype=float)
    names = tuple(model.names)[1:]
    for j, name in enumerate(names[: len(velocity)]):
        lower, upper = float(position[j, 0]), float(position[j, 1])
        if not (math.isfinite(lower) and math.isfinite(upper) and lower < upper):
            raise ModelError(
                f"joint {name}: position limits [{lower:g}, {upper:g}] rad must be finite with "
                "lower < upper"
            )
        if not (math.isfinite(velocity[j]) and velocity[j] > 0):
            raise ModelError(f"joint {name}: velocity limit {velocity[j]:g} rad/s must be > 0")
    position.setflags(write=False)
    velocity.setflags(write=False)
    return JointLimits(position=position, velocity=velocity)


def read_geometry(model: Any) -> ArmGeometry:
    """DH lengths from the joint placements; ModelError if the structure is not the AL5's."""
    names = tuple(model.names)[1:]
    if names != JOINT_NAMES or model.nq != 5:
        raise ModelError(f"expected revolute joints {JOINT_NAMES}; the URDF has {names}")
    rx90 = np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]])
    placements = [model.jointPlacements[i] for i in range(1, 6)]
    expected_rotations = (np.eye(3), rx90, np.eye(3), np.eye(3), rx90)
    for name, placement, rotation in zip(JOINT_NAMES, placements, expected_rotations, strict=True):
        if not np.allclose(placement.rotation, rotation, atol=URDF_STRUCTURE_TOLERANCE):
            raise ModelError(f"joint {name}: placement rotation is not the DH model's")
    a2, a3 = placements[2].translation[0], placements[3].translation[0]
    tool = model.frames[model.getFrameId(TOOL_FRAME)].placement
    offsets = np.concatenate(
        [placements[i].translation for i in (0, 1, 4)]
        + [placements[2].translation[1:], placements[3].translation[1:], tool.translation[:2]]
    )
    if not np.allclose(offsets, 0.0, atol=URDF_STRUCTURE_TOLERANCE) or min(a2, a3) <= 0:
        raise ModelError("joint placements do not follow the DH model of SPEC Part 1")
    for frame in (*DH_FRAMES, TOOL_FRAME):
        if not model.existFrame(frame):
            raise ModelError(f"the URDF has no frame {frame!r}")
    d5 = tool.translation[2]
    if not math.isfinite(d5) or d5 <= 0:
        raise ModelError("the tool frame must lie ahead of the wrist along the approach axis")
    return ArmGeometry(a2=float(a2), a3=float(a3), d5=float(d5))
