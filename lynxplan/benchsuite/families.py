"""Scene families of SmallArmBench: obstacle templates scaled to a robot's workspace.

A family is a template (MotionBenchMaker's "scene"): a few boxes whose poses and sizes a seeded
sampler perturbs, plus object-relative start and goal targets (a tool point and an approach
direction). Every length is a fraction of the robot's reach ``R`` above its table top ``z_t``;
a scene is placed at an azimuth within the arm's yaw range (:class:`RobotFrame`).

Coordinates of a template: ``u`` radial (away from the base axis, at the scene's azimuth),
``v`` lateral (to the left of ``u``), ``z`` up; every box is turned by the scene's azimuth about
the base z axis (world = base frame of the robot, in [m]).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

#: Names of the families, in the order of their index in a stored suite.
FAMILIES = ("table_pick", "shelf", "bin", "cage", "window", "under_board")


@dataclass(frozen=True)
class RobotFrame:
    """Where a robot's scenes go.

    Attributes:
        reach: Scale of the scenes: about the tool's reach from the shoulder, in [m].
        table_top: Height of the table's top in the base frame, in [m] (under the base).
        azimuth: Direction the scenes are centred on (yaw about base z from +x), in [rad].
        spread: Half range of the scene azimuth around ``azimuth``, in [rad].
        wrist: Added to the openings a wrist goes through (shelf compartments, the cage, the
            window, under the board), in [m]: the UR5's wrist links stand 0.1 m off its flange.
    """

    reach: float
    table_top: float
    azimuth: float
    spread: float
    wrist: float = 0.0


#: The robots of the suite and their scene frames. Table tops: the AL5's as in the shipped
#: scenarios (its base's collision box reaches 0.07 m down); the SO-101's and the UR5's bases
#: reach 2.4 and 3 mm below their origin, their tables are 12.6 and 22 mm lower than that (the
#: generator wants 2 % of the reach between any link and the obstacles at a start or goal).
ROBOT_FRAMES: dict[str, RobotFrame] = {
    "al5": RobotFrame(reach=0.36, table_top=-0.09, azimuth=math.pi / 2, spread=math.radians(50)),
    "so101": RobotFrame(reach=0.40, table_top=-0.015, azimuth=0.0, spread=math.radians(60)),
    "ur5": RobotFrame(
        reach=0.80, table_top=-0.025, azimuth=0.0, spread=math.radians(90), wrist=0.1
    ),
}

#: Approach pitches from straight down towards the scene [rad] tried for a target from above
#: (``DOWN``) or a level one (``FORWARD``), most wanted first.
DOWN = tuple(math.radians(a) for a in (0.0, 20.0, 40.0))
FORWARD = tuple(math.radians(a) for a in (90.0, 70.0, 50.0))


@dataclass(frozen=True)
class Scene:
    """One sampled scene in the base frame.

    Attributes:
        names: Box names, K of them.
        centres: Box centres, shape (K, 3), in [m].
        sizes: Box edge lengths along their own axes, shape (K, 3), in [m].
        yaws: Box rotations about the base z axis, shape (K,), in [rad].
        start: Start target: tool point (3,) [m] and candidate approach directions (A, 3)
            (unit), most wanted first (the generator takes the first one the arm can reach).
        goal: Goal target, as ``start``.
    """

    names: tuple[str, ...]
    centres: np.ndarray
    sizes: np.ndarray
    yaws: np.ndarray
    start: tuple[np.ndarray, np.ndarray]
    goal: tuple[np.ndarray, np.ndarray]


class _Builder:
    """Collects the boxes and targets of one template in (u, v, z) coordinates."""

    def __init__(self, frame: RobotFrame, azimuth: float) -> None:
        self.reach, self.top, self.wrist = frame.reach, frame.table_top, frame.wrist
        self.azimuth = azimuth
        self.boxes: list[tuple[str, np.ndarray, np.ndarray]] = []

    def world(self, u: float, v: float, z: float) -> np.ndarray:
        """A template point in the base frame, in [m]."""
        c, s = math.cos(self.azimuth), math.sin(self.azimuth)
        return np.array([u * c - v * s, u * s + v * c, z])

    def box(self, name: str, centre: tuple[float, float, float], size: tuple[float, ...]) -> None:
        """A box by template centre (u, v, z) and size (along u, v, z), in [m]."""
        self.boxes.append((name, self.world(*centre), np.array(size, dtype=float)))

    def table(self) -> None:
        """The table: a slab whose top is the frame's table top, wide around the base."""
        r, t = self.reach, 0.03 * self.reach
        self.box("table", (0.5 * r, 0.0, self.top - t / 2), (2.4 * r, 2.6 * r, t))

    def target(
        self, u: float, v: float, z: float, pitches: tuple[float, ...]
    ) -> tuple[np.ndarray, np.ndarray]:
        """A tool target: the point (u, v, z) and its candidate approaches, (A, 3): each
        ``pitch`` [rad] from straight down towards +u."""
        approaches = [self.world(math.sin(p), 0.0, -math.cos(p)) for p in pitches]
        return self.world(u, v, z), np.array(approaches)

    def scene(
        self, start: tuple[np.ndarray, np.ndarray], goal: tuple[np.ndarray, np.ndarray]
    ) -> Scene:
        names = tuple(b[0] for b in self.boxes)
        yaws = np.full(len(names), self.azimuth)
        return Scene(
            names,
            np.array([b[1] for b in self.boxes]),
            np.array([b[2] for b in self.boxes]),
            yaws,
            start,
            goal,
        )


def _polar(radius: float, angle: float) -> tuple[float, float]:
    return radius * math.cos(angle), radius * math.sin(angle)


def table_pick(b: _Builder, rng: np.random.Generator) -> Scene:
    """A tall block between two objects on the table; pick from above on the far side."""
    r, top = b.reach, b.top
    b.table()
    d = rng.uniform(0.5, 0.7) * r
    height = rng.uniform(0.35, 0.6) * r
    b.box("block", (d, 0.0, top + height / 2), (rng.uniform(0.1, 0.2) * r,
                                                rng.uniform(0.08, 0.16) * r, height))  # fmt: skip
    side = 1.0 if rng.uniform() < 0.5 else -1.0
    offset = math.radians(rng.uniform(25.0, 45.0))
    cube = rng.uniform(0.06, 0.1) * r
    u, v = _polar(d, side * offset)
    b.box("object", (u, v, top + cube / 2), (cube, cube, cube))
    goal = b.target(u, v, top + cube + rng.uniform(0.03, 0.07) * r, DOWN)
    u, v = _polar(d * rng.uniform(0.85, 1.1), -side * offset)
    start = b.target(u, v, top + rng.uniform(0.05, 0.15) * r, DOWN)
    return b.scene(start, goal)


def shelf(b: _Builder, rng: np.random.Generator) -> Scene:
    """A two-compartment shelf facing the arm; reach into a compartment, level."""
    r, top = b.reach, b.top
    b.table()
    d, width, depth = rng.uniform(0.62, 0.75) * r, rng.uniform(0.45, 0.6) * r + b.wrist, 0.3 * r
    bottom, t = top + rng.uniform(0.05, 0.15) * r, 0.025 * r
    height = rng.uniform(0.22, 0.3) * r + b.wrist
    boards = [bottom + k * height for k in range(3)]
    for k, z in enumerate(boards):
        b.box(f"board_{k}", (d, 0.0, z), (depth, width, t))
    total = boards[-1] - top + t / 2
    for name, v in (("side_left", width / 2), ("side_right", -width / 2)):
        b.box(name, (d, v, top + total / 2), (depth, t, total))
    b.box("back", (d + depth / 2, 0.0, top + total / 2), (t, width, total))
    k = int(rng.integers(2))
    u = d - depth / 2 + rng.uniform(0.25, 0.5) * depth
    goal = b.target(u, rng.uniform(-0.2, 0.2) * width, boards[k] + rng.uniform(0.4, 0.6) * height,
                    FORWARD)  # fmt: skip
    if rng.uniform() < 0.5:  # the other compartment
        z = boards[1 - k] + rng.uniform(0.4, 0.6) * height
        start = b.target(d - depth / 2 + rng.uniform(0.2, 0.5) * depth, 0.0, z, FORWARD)
    else:  # above the shelf
        start = b.target(d - 0.1 * r, 0.0, boards[-1] + rng.uniform(0.1, 0.2) * r, DOWN)
    return b.scene(start, goal)


def bin_box(b: _Builder, rng: np.random.Generator) -> Scene:
    """An open bin on the table; from outside it to its bottom, from above."""
    r, top = b.reach, b.top
    b.table()
    d, a, w = rng.uniform(0.5, 0.65) * r, rng.uniform(0.28, 0.4) * r, rng.uniform(0.28, 0.4) * r
    height, t = rng.uniform(0.15, 0.28) * r, 0.02 * r
    z = top + height / 2
    b.box("bin_near", (d - a / 2, 0.0, z), (t, w + t, height))
    b.box("bin_far", (d + a / 2, 0.0, z), (t, w + t, height))
    b.box("bin_left", (d, w / 2, z), (a + t, t, height))
    b.box("bin_right", (d, -w / 2, z), (a + t, t, height))
    goal = b.target(d + rng.uniform(-0.2, 0.2) * a, rng.uniform(-0.2, 0.2) * w,
                    top + rng.uniform(0.06, 0.1) * r, DOWN)  # fmt: skip
    side = 1.0 if rng.uniform() < 0.5 else -1.0
    u, v = _polar(d * rng.uniform(0.8, 1.05), side * math.radians(rng.uniform(40.0, 60.0)))
    start = b.target(u, v, top + rng.uniform(0.05, 0.12) * r, DOWN)
    return b.scene(start, goal)


def cage(b: _Builder, rng: np.random.Generator) -> Scene:
    """Four posts, a roof and a back bar; from above the roof to under it, through the front."""
    r, top = b.reach, b.top
    b.table()
    d, side = rng.uniform(0.55, 0.68) * r, rng.uniform(0.32, 0.45) * r + b.wrist
    height = rng.uniform(0.3, 0.42) * r + b.wrist
    post, t = 0.04 * r, 0.02 * r
    for name, du, dv in (("post_nl", -1, 1), ("post_nr", -1, -1), ("post_fl", 1, 1),
                         ("post_fr", 1, -1)):  # fmt: skip
        b.box(name, (d + du * side / 2, dv * side / 2, top + height / 2), (post, post, height))
    b.box("roof", (d, 0.0, top + height + t / 2), (side + post, side + post, t))
    b.box("back_bar", (d + side / 2, 0.0, top + rng.uniform(0.3, 0.6) * height), (t, side, t))
    goal = b.target(d + rng.uniform(-0.15, 0.1) * side, rng.uniform(-0.2, 0.2) * side,
                    top + rng.uniform(0.3, 0.6) * height, FORWARD)  # fmt: skip
    start = b.target(d + rng.uniform(-0.2, 0.2) * side, rng.uniform(-0.2, 0.2) * side,
                     top + height + rng.uniform(0.08, 0.18) * r, DOWN)  # fmt: skip
    return b.scene(start, goal)


def window(b: _Builder, rng: np.random.Generator) -> Scene:
    """A wall across the arm's front with a window; reach through it, level."""
    r, top = b.reach, b.top
    b.table()
    d, t, span = rng.uniform(0.42, 0.52) * r, 0.03 * r, 1.4 * r
    wall_top = top + rng.uniform(0.65, 0.85) * r
    v0, size = rng.uniform(-0.1, 0.1) * r, rng.uniform(0.24, 0.32) * r + b.wrist
    z0 = top + rng.uniform(0.25, 0.4) * r
    low, high, left, right = z0 - size / 2, z0 + size / 2, v0 + size / 2, v0 - size / 2
    b.box("wall_left", (d, (left + span / 2) / 2, (top + wall_top) / 2),
          (t, span / 2 - left, wall_top - top))  # fmt: skip
    b.box("wall_right", (d, (right - span / 2) / 2, (top + wall_top) / 2),
          (t, right + span / 2, wall_top - top))  # fmt: skip
    b.box("wall_below", (d, v0, (top + low) / 2), (t, size, low - top))
    b.box("wall_above", (d, v0, (high + wall_top) / 2), (t, size, wall_top - high))
    goal = b.target(d + rng.uniform(0.06, 0.16) * r, v0 + rng.uniform(-0.2, 0.2) * size,
                    z0 + rng.uniform(-0.2, 0.2) * size, FORWARD)  # fmt: skip
    u, v = _polar(d * rng.uniform(0.6, 0.8), math.radians(rng.uniform(-40.0, 40.0)))
    start = b.target(u, v, top + rng.uniform(0.05, 0.15) * r, DOWN)
    return b.scene(start, goal)


def under_board(b: _Builder, rng: np.random.Generator) -> Scene:
    """A board on a leg above the table; from above it to under it, level."""
    r, top = b.reach, b.top
    b.table()
    d, depth = rng.uniform(0.55, 0.68) * r, rng.uniform(0.25, 0.4) * r
    width = rng.uniform(0.4, 0.6) * r
    level, t = top + rng.uniform(0.24, 0.34) * r + b.wrist, 0.02 * r
    b.box("board", (d, 0.0, level), (depth, width, t))
    leg = 0.04 * r
    b.box("leg", (d + depth / 2 - leg / 2, 0.0, (top + level) / 2), (leg, leg, level - top))
    start = b.target(d + rng.uniform(-0.2, 0.1) * depth, rng.uniform(-0.2, 0.2) * width,
                     level + rng.uniform(0.08, 0.18) * r, DOWN)  # fmt: skip
    goal = b.target(d - depth / 2 + rng.uniform(0.15, 0.45) * depth,
                    rng.uniform(-0.25, 0.25) * width,
                    top + rng.uniform(0.35, 0.6) * (level - top), FORWARD)  # fmt: skip
    return b.scene(start, goal)


TEMPLATES: dict[str, Callable[[_Builder, np.random.Generator], Scene]] = {
    "table_pick": table_pick,
    "shelf": shelf,
    "bin": bin_box,
    "cage": cage,
    "window": window,
    "under_board": under_board,
}


def sample_scene(frame: RobotFrame, family: str, rng: np.random.Generator) -> Scene:
    """One scene of ``family`` for a robot of ``frame``, drawn with ``rng``."""
    azimuth = frame.azimuth + rng.uniform(-frame.spread, frame.spread)
    return TEMPLATES[family](_Builder(frame, azimuth), rng)
