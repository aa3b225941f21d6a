"""The arrays of the planner's compiled kernels, built once per collision world.

:func:`kernel_model` turns a :class:`lynxplan.collision.CollisionWorld` and a list of pairs into
one tuple of contiguous arrays (joints, primitives, pairs, pair motion rates, obstacles) that the
numba kernels of :mod:`lynxplan.planning.validity` and :mod:`lynxplan.planning.certify` read;
:func:`make_scratch` gives the matching work arrays. :func:`njit_no_refcount`,
:func:`njit_refcounted` and :func:`stack_array` are how the kernels are compiled: the hot ones
without numba's reference counting, their work rows on their stack.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar, cast

import numba
import numpy as np
from numba.core import types
from numba.extending import intrinsic

from lynxplan.collision.obstacles import BoxObstacle, CylinderObstacle, SphereObstacle
from lynxplan.collision.world import CollisionWorld

#: Configurations per call of the vectorised kernel :func:`lynxplan.planning.lanes.pair_along`
#: (one AVX2 register of doubles). Measured on the AL5 suite: an edge walk accepts 2-3 points
#: of a run on average, so 8 lanes computed about half in vain; 4 gave the fastest planning
#: (median 1.18 ms against 1.36 ms with 8, 1.27 with 6, 1.42 with 3 and 1.36 with 2).
LANES = 4
#: Interior points of an edge at which a walk may know every pair's bound beforehand (the quick
#: tests before it: :func:`lynxplan.planning.validity.point_is_clear`).
GRID_POINTS = 7
#: Obstacle kinds of the kernels.
OBSTACLE_BOX, OBSTACLE_SPHERE = 0, 1


_Kernel = TypeVar("_Kernel", bound=Callable[..., Any])


def njit_no_refcount(**options: Any) -> Callable[[_Kernel], _Kernel]:
    """``numba.njit(cache=True, **options)`` without numba's reference counting (``_nrt=False``),
    for the kernels that the planner's loops call most often.

    Such a kernel allocates no array (its work arrays come in the scratch tuple or lie on its
    stack, :func:`stack_array`), returns none and copies arrays element by element: every array
    it touches belongs to its caller or to its stack. It calls only kernels compiled the same
    way, inlined ones or :func:`njit_refcounted` ones (numba compiles a callee that sets no
    ``_nrt`` with its caller's setting). With reference counting, each call took and dropped
    an atomic reference per array of the model and scratch tuples (about 40) and per view taken
    inside: a fifth of the planning time.
    """
    return _njit(False, options)


#: Alignment of a :func:`stack_array`, in bytes (a cache line: whole-register loads and stores).
_STACK_ALIGNMENT = 64


def njit_refcounted(**options: Any) -> Callable[[_Kernel], _Kernel]:
    """``numba.njit(cache=True, **options)`` with numba's reference counting set explicitly
    (``_nrt=True``): a kernel that allocates or returns an array, and may be called from
    :func:`njit_no_refcount` kernels (a callee that sets no ``_nrt`` is compiled with its first
    caller's setting: it would fail to allocate, or return a view without its reference)."""
    return _njit(True, options)


def _njit(counted: bool, options: dict[str, Any]) -> Callable[[_Kernel], _Kernel]:
    """The decorator ``numba.njit(cache=True, _nrt=counted, **options)``, typed."""
    settings: dict[str, Any] = {"cache": True, "_nrt": counted, **options}

    def compile_lazily(function: _Kernel) -> _Kernel:
        return cast(_Kernel, numba.njit(**settings)(function))

    return compile_lazily


def stack_array(rows: int, columns: int) -> Any:
    """A compiled function ``() -> (rows, columns) float64 array`` on the calling kernel's
    stack (uninitialised; valid until the kernel returns; no allocation, no reference count).

    A kernel's work rows on its own stack: the compiler knows that they alias none of its
    arguments, which keeps its loops vectorised without run-time overlap checks.
    """

    @intrinsic
    def allocate(typingctx: Any) -> Any:
        array_type = types.Array(types.float64, 2, "C")

        def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
            array = context.make_array(array_type)(context, builder)
            double = context.get_data_type(types.float64)
            size = context.get_abi_sizeof(double)
            intp = context.get_value_type(types.intp)
            with builder.goto_entry_block():  # one stack slot per call of the kernel
                data = builder.alloca(double, size=intp(rows * columns))
                data.align = _STACK_ALIGNMENT
            context.populate_array(
                array,
                data=data,
                shape=[intp(rows), intp(columns)],
                strides=[intp(columns * size), intp(size)],
                itemsize=intp(size),
                meminfo=None,
            )
            return array._getvalue()

        return array_type(), codegen

    return allocate


def kernel_model(world: CollisionWorld, pairs: np.ndarray) -> tuple[np.ndarray, ...]:
    """Kernel arrays of a world for the given pairs (rows ``(a, b, is_self)``, shape (P, 3)).

    Layout: 0 joint axes, 1 joint configuration indices, 2 joint parents, 3 joint placements,
    4 primitive joints, 5 primitive placements, 6 primitive box half sizes, 7 primitive bounding
    radii, 8 pairs, 9 pair motion rates (P, nq) [m/rad], 10 obstacle kinds, 11 obstacle centres,
    12 obstacle poses, 13 obstacle half sizes, 14 obstacle bounding radii, 15 pair joint owners
    (P, nq): the primitive of the pair that joint j moves relative to the other side (-1: none),
    16 the joint (frame) index of each configuration index (nq,), 17 primitive covering sphere
    centres (G, K, 3) in the primitive frame, 18 their counts (G,), 19 their radii (G,)
    (:func:`_cover_arrays`).
    """
    axes, index_q, parents, placements, prim_joints, prim_placements = world._kernel_joints
    half = np.array([_box_half_extents(p.kind, p.half_extents) for p in world.links])
    kinds, centres, rotations, obstacle_half, obstacle_radius = _obstacle_arrays(world)
    arrays = (
        axes.astype(np.int64),
        index_q.astype(np.int64),
        parents.astype(np.int64),
        placements,
        prim_joints.astype(np.int64),
        prim_placements,
        half,
        np.linalg.norm(half, axis=1),
        pairs.astype(np.int64).reshape(-1, 3),
        pair_rates(world, pairs),
        kinds,
        centres,
        rotations,
        obstacle_half,
        obstacle_radius,
        pair_owners(world, pairs),
        _joint_of_coordinate(world),
        *_cover_arrays(world),
    )
    return tuple(np.ascontiguousarray(a) for a in arrays)


def _cover_arrays(world: CollisionWorld) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each primitive's covering spheres (:class:`lynxplan.collision.primitives.LinkPrimitive`):
    centres in the primitive frame (G, K, 3) (K: the most of any primitive; unused rows 0), in
    [m], counts (G,), radii (G,), in [m]."""
    links = world.links
    most = max((len(link.sphere_centres) for link in links), default=1)
    centres = np.zeros((len(links), most, 3))
    counts = np.zeros(len(links), dtype=np.int64)
    radii = np.zeros(len(links))
    for g, link in enumerate(links):
        count = len(link.sphere_centres)
        centres[g, :count] = link.sphere_centres
        counts[g], radii[g] = count, link.sphere_radius
    return centres, counts, radii


def world_pairs(world: CollisionWorld) -> np.ndarray:
    """Every pair of the collision world, in its order: rows ``(a, b, is_self)``, (P, 3)."""
    rows = np.column_stack((world.pair_link, world.pair_other, world.pair_is_self))
    return np.asarray(rows, dtype=np.int64).reshape(-1, 3)


def make_scratch(model: tuple[np.ndarray, ...]) -> tuple[np.ndarray, ...]:
    """Work arrays of the kernels for one model: joint and primitive poses, bounds, rates, and
    counters (edge checks, advancement steps, pair bounds evaluated) and the pair that last
    failed a quick state test, the joint and primitive poses at an edge's start, the joints'
    lever arms at two points of an edge, the joint steps of an edge, every pair's lever arms
    and slack trend on an edge, the output rows of :func:`lynxplan.planning.lanes.pair_along`,
    every pair's bound at up to :data:`GRID_POINTS` points of an edge (the quick tests before a
    walk), every pair's slack at an edge's end, the grid points' edge parameters, and the point
    of an edge from which each pair is certified to its end by the grid."""
    joints, pairs, nq = len(model[0]), len(model[8]), model[9].shape[1]
    return (
        np.empty((joints, 4, 4)),
        np.empty((1, 4, 4)),
        np.zeros((4, 4)),
        np.empty((len(model[4]), 4, 4)),
        np.empty(pairs),
        np.empty(pairs),
        np.empty(pairs),
        np.empty(nq),
        np.empty((3, 3)),
        np.zeros(4, dtype=np.int64),
        np.zeros(len(model[4]), dtype=np.int64),
        np.empty((joints, 4, 4)),
        np.empty((len(model[4]), 4, 4)),
        np.empty((2, nq)),
        np.empty(nq),
        np.empty((pairs, nq)),
        np.empty(pairs),
        np.empty((3 + nq, LANES)),
        np.empty((GRID_POINTS, pairs)),
        np.empty(pairs),
        np.empty(GRID_POINTS),
        np.empty(pairs),
    )


def _box_half_extents(kind: str, half: np.ndarray) -> np.ndarray:
    if kind in ("box", "mesh"):  # a mesh primitive is its hull, inside this box
        return np.array(half, dtype=float)
    radius, half_length = float(half[0]), float(half[1])
    return np.array([radius, radius, half_length])


def planner_pairs(world: CollisionWorld) -> tuple[np.ndarray, list[tuple[str, str]]]:
    """Checked pairs: moving primitive vs obstacle, and non-adjacent primitive pairs."""
    rows, names = [], []
    links = world.links
    for o, obstacle in enumerate(world.obstacles):
        for g, link in enumerate(links):
            if link.joint != 0:
                rows.append((g, o, 0))
                names.append((link.geometry, obstacle.name))
    for a, b in world.self_pairs:  # non-adjacent bodies, less the SRDF's disabled pairs
        rows.append((a, b, 1))
        names.append((links[a].geometry, f"self:{links[b].geometry}"))
    return np.array(rows, dtype=np.int64).reshape(-1, 3), names


def _ancestors(model: Any, joint: int) -> set[int]:
    """Configuration indices of the joints that move a body on ``joint``."""
    found = set()
    while joint > 0:
        found.add(int(model.joints[joint].idx_q))
        joint = int(model.parents[joint])
    return found


def _symmetric_about_root_axis(world: CollisionWorld, g: int) -> int | None:
    """The configuration index of the first joint if fixed primitive g is a cylinder coaxial
    with it (turning that joint then cannot change any distance to g), else None."""
    model, link = world.model, world.links[g]
    if link.joint != 0 or link.kind != "cylinder" or model.njoints < 2 or model.parents[1] != 0:
        return None
    axis_index = {"JointModelRX": 0, "JointModelRY": 1, "JointModelRZ": 2}.get(
        model.joints[1].shortname()
    )
    if axis_index is None:
        return None
    placement = np.array(model.jointPlacements[1].homogeneous)
    joint_axis, joint_origin = placement[:3, axis_index], placement[:3, 3]
    cylinder_axis, centre = link.placement[:3, 2], link.placement[:3, 3]
    offset = centre - joint_origin
    off_axis = offset - (offset @ joint_axis) * joint_axis
    if np.linalg.norm(np.cross(joint_axis, cylinder_axis)) > 1e-12:
        return None
    if np.linalg.norm(off_axis) > 1e-12:
        return None
    return int(model.joints[1].idx_q)


def pair_rates(world: CollisionWorld, pairs: np.ndarray) -> np.ndarray:
    """Motion of each pair per radian of each joint, shape (P, nq), in [m/rad].

    Obstacle pair: the primitive's reach about each joint. Self pair: the distance between two
    bodies depends only on their relative pose, so joints that move both (common ancestors)
    do not count; each other joint counts with the reach of the body it moves. A fixed
    cylinder coaxial with the first joint (the AL5's base) is symmetric about it: that joint
    does not count either.
    """
    model = world.model
    rates = np.zeros((len(pairs), model.nq))
    for p, (a, b, is_self) in enumerate(pairs.tolist()):
        first = world.links[a]
        if not is_self:
            rates[p] = first.reach
            continue
        second = world.links[b]
        only_a = _ancestors(model, first.joint) - _ancestors(model, second.joint)
        only_b = _ancestors(model, second.joint) - _ancestors(model, first.joint)
        for j in only_a:
            rates[p, j] += first.reach[j]
        for j in only_b:
            rates[p, j] += second.reach[j]
        for g in (a, b):
            symmetric = _symmetric_about_root_axis(world, g)
            if symmetric is not None:
                rates[p, symmetric] = 0.0
    return rates


def pair_owners(world: CollisionWorld, pairs: np.ndarray) -> np.ndarray:
    """Which primitive of each pair each joint moves relative to the other side, (P, nq).

    Obstacle pair ``(a, o)``: ``a`` for every joint that moves it. Self pair ``(a, b)``: ``a``
    for the joints that move ``a`` and not ``b``, ``b`` for the converse, -1 for the common
    ancestors (they move both rigidly) and for joints that move neither.
    """
    model = world.model
    owners = np.full((len(pairs), model.nq), -1, dtype=np.int64)
    for p, (a, b, is_self) in enumerate(pairs.tolist()):
        moves_a = _ancestors(model, world.links[a].joint)
        moves_b = _ancestors(model, world.links[b].joint) if is_self else set()
        for j in moves_a - moves_b:
            owners[p, j] = a
        for j in moves_b - moves_a:
            owners[p, j] = b
    return owners


def _joint_of_coordinate(world: CollisionWorld) -> np.ndarray:
    """The joint (frame) index of each configuration index, (nq,) (-1: none)."""
    model = world.model
    joints = np.full(model.nq, -1, dtype=np.int64)
    for j in range(1, model.njoints):
        if model.joints[j].nq == 1:
            joints[model.joints[j].idx_q] = j
    return joints


def _obstacle_arrays(world: CollisionWorld) -> tuple[np.ndarray, ...]:
    count = len(world.obstacles)
    kinds = np.zeros(count, dtype=np.int64)
    centres = np.zeros((count, 3))
    poses = np.zeros((count, 4, 4))
    half = np.zeros((count, 3))
    for o, obstacle in enumerate(world.obstacles):
        centres[o] = obstacle.centre
        poses[o, :3, :3] = np.asarray(obstacle.rotation)
        poses[o, :3, 3] = obstacle.centre
        poses[o, 3, 3] = 1.0
        if isinstance(obstacle, BoxObstacle):
            half[o] = obstacle.size / 2.0
        elif isinstance(obstacle, SphereObstacle):
            kinds[o] = OBSTACLE_SPHERE
            half[o] = obstacle.radius
        elif isinstance(obstacle, CylinderObstacle):
            half[o] = (obstacle.radius, obstacle.radius, obstacle.length / 2.0)
    # Bounding-sphere radius of each obstacle (a sphere's own radius).
    radius = np.where(kinds == OBSTACLE_SPHERE, half[:, 0], np.linalg.norm(half, axis=1))
    return kinds, centres, poses, half, radius
