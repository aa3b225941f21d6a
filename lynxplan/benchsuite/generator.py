"""The SmallArmBench generator: seeded scenes, starts and goals through IK, kept when hard.

For one robot, family and attempt number, a generator draws a scene
(:func:`lynxplan.benchsuite.families.sample_scene`) from a random generator seeded with
``(seed, robot, family, attempt)``, solves the IK of its start and goal targets (every branch),
keeps the branches within the joint limits whose exact distance to every obstacle and to the
robot itself is at least ``margin`` (a fraction of the robot's reach), picks one branch each at
random, and keeps the problem only when the straight joint motion from start to goal collides.
Attempts run in order until a family has its count: the suite is a pure function of the seed
(same machine and library versions: bit for bit).
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Callable
from typing import Any

import numpy as np

from lynxplan.benchsuite.families import FAMILIES, ROBOT_FRAMES, sample_scene
from lynxplan.benchsuite.problem import Problem, suite_robot, yaw_rotation
from lynxplan.exceptions import InputError

#: Default seed of the stored suite.
SUITE_SEED = 2024
#: Problems per family and robot in the stored suite (6 families: 120 per robot).
PER_FAMILY = 20
#: Start/goal clearance required by the generator, as a fraction of the robot's reach (the
#: planner's own clearance is 2 mm; its conservative checker needs more than that).
MARGIN_FRACTION = 0.02
#: Self-collision clearance of a start or goal (exact distance), in [m].
SELF_MARGIN = 0.003
#: Joint step of the straight-motion collision test, in [rad].
STRAIGHT_STEP = 0.01
#: Attempts per wanted problem before the generator gives up on a family.
MAX_ATTEMPTS_PER_PROBLEM = 200
#: IK references drawn per target (the numerical solver returns the branch nearest each).
IK_REFERENCES = 4
#: Largest IK position error accepted, in [m].
IK_TOLERANCE = 1e-5


def _stable_id(name: str) -> int:
    """A seed word of a name that is the same in every process (``hash`` is salted)."""
    return zlib.crc32(name.encode())


def _rng(seed: int, robot: str, family: str, attempt: int) -> np.random.Generator:
    return np.random.default_rng([seed, _stable_id(robot), _stable_id(family), attempt])


class _Context:
    """A loaded robot and its figures the attempts share."""

    def __init__(self, robot_name: str) -> None:
        if robot_name not in ROBOT_FRAMES:
            raise InputError(
                f"robot {robot_name!r} has no SmallArmBench frame; robots: "
                f"{', '.join(ROBOT_FRAMES)}"
            )
        self.name = robot_name
        self.robot = suite_robot(robot_name)
        self.frame = ROBOT_FRAMES[robot_name]
        self.margin = MARGIN_FRACTION * self.frame.reach
        lower, upper = self.robot.limits.lower, self.robot.limits.upper
        # IK references within one turn of zero (the UR5's limits are +-2 pi)
        self.reference_bounds = np.maximum(lower, -math.pi), np.minimum(upper, math.pi)


def _clear_branches(
    ctx: _Context, world: Any, target: tuple[np.ndarray, np.ndarray], rng: np.random.Generator
) -> np.ndarray | None:
    """One IK branch of ``target`` within the limits and clear by the margin, drawn at random
    among those of the first approach that has one; None when there is none."""
    point, approaches = target
    references = rng.uniform(*ctx.reference_bounds, size=(IK_REFERENCES, ctx.robot.nq))
    rows = len(approaches) * IK_REFERENCES
    batch = ctx.robot.ik_batch(
        positions=np.repeat(point[None], rows, axis=0),
        approaches=np.repeat(approaches, IK_REFERENCES, axis=0),
        q_reference=np.tile(references, (len(approaches), 1)),
    )
    ok = batch.valid & batch.within_limits & (batch.position_error <= IK_TOLERANCE)
    for row in range(len(approaches)):  # the first approach with a clear branch
        found = batch.q[row * IK_REFERENCES : (row + 1) * IK_REFERENCES]
        unique = _unique_rows(found[ok[row * IK_REFERENCES : (row + 1) * IK_REFERENCES]])
        candidates = [q for q in unique if _clear(ctx, world, q)]
        if candidates:
            return np.array(candidates[int(rng.integers(len(candidates)))], dtype=float)
    return None


def _unique_rows(q: np.ndarray) -> list[np.ndarray]:
    """The rows of ``q`` (M, nq) without repeats (branches that coincide), in order."""
    unique: list[np.ndarray] = []
    for row in q:
        if not any(np.array_equal(row, u) for u in unique):
            unique.append(row)
    return unique


def _clear(ctx: _Context, world: Any, q: np.ndarray) -> bool:
    """Obstacles at least the margin away, the robot's own links :data:`SELF_MARGIN` apart
    (exact distances where the conservative bound does not prove it)."""
    poses = world.primitive_poses(q)
    bounds = world.lower_bounds(poses)[0]
    needed = np.where(world.pair_is_self, SELF_MARGIN, ctx.margin)
    for pair in np.flatnonzero(bounds < needed):
        if world.distance(poses[0], int(pair)) < needed[pair]:
            return False
    return True


def straight_motion_collides(world: Any, start: np.ndarray, goal: np.ndarray) -> bool:
    """Whether the straight joint motion start -> goal touches anything, sampled at
    :data:`STRAIGHT_STEP` (exact coal distances where the conservative bound proves nothing)."""
    steps = max(1, math.ceil(float(np.abs(goal - start).max()) / STRAIGHT_STEP))
    path = start + np.linspace(0.0, 1.0, steps + 1)[:, None] * (goal - start)
    poses = world.primitive_poses(path)
    bounds = world.lower_bounds(poses)
    for n, p in zip(*np.nonzero(bounds <= 0.0), strict=True):
        if world.distance(poses[n], int(p)) <= 0.0:
            return True
    return False


def attempt_problem(
    ctx: _Context, family: str, seed: int, attempt: int, index: int
) -> Problem | None:
    """The problem of one attempt, or None when the attempt is rejected (a target out of reach
    or not clear, or a straight motion that is free)."""
    from lynxplan.collision import BoxObstacle, CollisionWorld

    rng = _rng(seed, ctx.name, family, attempt)
    scene = sample_scene(ctx.frame, family, rng)
    obstacles = tuple(
        BoxObstacle(n, c, s, yaw_rotation(float(y)))
        for n, c, s, y in zip(scene.names, scene.centres, scene.sizes, scene.yaws, strict=True)
    )
    world = CollisionWorld(ctx.robot, obstacles, self_collision=True)
    start = _clear_branches(ctx, world, scene.start, rng)
    if start is None:
        return None
    goal = _clear_branches(ctx, world, scene.goal, rng)
    if goal is None or not straight_motion_collides(world, start, goal):
        return None
    return Problem(
        ctx.name, family, index, attempt, scene.names, scene.centres, scene.sizes, scene.yaws,
        start, goal,
    )  # fmt: skip


def generate_family(
    robot: str, family: str, count: int, seed: int = SUITE_SEED, *, ctx: _Context | None = None
) -> list[Problem]:
    """The first ``count`` problems of ``family`` for ``robot`` from ``seed``.

    Raises:
        InputError: unknown robot or family, or the family gave fewer than ``count`` problems
            within ``count * MAX_ATTEMPTS_PER_PROBLEM`` attempts.
    """
    if family not in FAMILIES:
        known = ", ".join(FAMILIES)
        raise InputError(f"unknown SmallArmBench family {family!r}; families: {known}")
    ctx = ctx or _Context(robot)
    problems: list[Problem] = []
    attempt = 0
    while len(problems) < count:
        if attempt >= count * MAX_ATTEMPTS_PER_PROBLEM:
            raise InputError(
                f"family {family} gave {len(problems)} of {count} {robot} problems in "
                f"{attempt} attempts"
            )
        problem = attempt_problem(ctx, family, seed, attempt, len(problems))
        if problem is not None:
            problems.append(problem)
        attempt += 1
    return problems


def generate_suite(
    robot: str,
    per_family: int = PER_FAMILY,
    seed: int = SUITE_SEED,
    *,
    families: tuple[str, ...] = FAMILIES,
    progress: Callable[[int, int], None] | None = None,
) -> list[Problem]:
    """Every family's first ``per_family`` problems for ``robot``, family by family."""
    ctx = _Context(robot)
    problems: list[Problem] = []
    for k, family in enumerate(families):
        problems += generate_family(robot, family, per_family, seed, ctx=ctx)
        if progress is not None:
            progress(k + 1, len(families))
    return problems


def regenerate(problem: Problem, seed: int = SUITE_SEED) -> Problem | None:
    """The problem that ``problem``'s attempt gives from ``seed`` (None: that attempt is
    rejected), to check a stored problem against its generator."""
    ctx = _Context(problem.robot)
    return attempt_problem(ctx, problem.family, seed, problem.attempt, problem.index)
