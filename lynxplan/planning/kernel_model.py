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
from typing import Any, NamedTuple, TypeVar, cast

import numba
import numpy as np
from numba.core import types
from numba.extending import intrinsic

from lynxplan._jit import kernels_run_as_python
from lynxplan.collision.obstacles import BoxObstacle, CylinderObstacle, SphereObstacle
from lynxplan.collision.world import CollisionWorld

#: Configurations per call of the vectorised kernel :func:`lynxplan.planning.lanes.pair_along`
#: (one AVX2 register of doubles). Measured on the AL5 suite: an edge walk accepts 2-3 points
#: of a run on average, so 8 lanes computed about half in vain; 4 gave the fastest planning
#: (median 1.18 ms against 1.36 ms with 8, 1.27 with 6, 1.42 with 3 and 1.36 with 2).
LANES = 4
#: Interior points of an edge at which a walk may know every pair's bound beforehand (the quick
#: tests before it: :func:`lynxplan.planning.bounds.point_is_clear`).
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
    if kernels_run_as_python():  # a fresh array
        return lambda: np.empty((rows, columns))

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


class KernelModel(NamedTuple):
    """The arrays of the checker's kernels for one world and its checked pairs (contiguous).

    J joint frames, G primitives, P pairs, O obstacles, nq configuration indices.
    """

    #: Rotation axis (0, 1, 2 for x, y, z) of each joint frame, (J,).
    axes: np.ndarray
    #: Configuration index of each joint frame, (J,).
    index_q: np.ndarray
    #: Parent frame of each joint frame, (J,) (a parent's index is below its child's).
    parents: np.ndarray
    #: Placement of each joint frame in its parent's, (J, 4, 4), in [m].
    joint_placements: np.ndarray
    #: Joint frame each primitive hangs on, (G,).
    prim_joints: np.ndarray
    #: Placement of each primitive in its joint frame, (G, 4, 4), in [m].
    prim_placements: np.ndarray
    #: Half sizes of each primitive's box (a cylinder's or mesh hull's bounding box), (G, 3), [m].
    prim_half: np.ndarray
    #: Bounding-sphere radius of each primitive, (G,), in [m].
    prim_radius: np.ndarray
    #: Checked pairs, rows (a, b, is_self), (P, 3): b an obstacle unless is_self.
    pairs: np.ndarray
    #: Motion of each pair per radian of each joint, (P, nq), in [m/rad] (:func:`pair_rates`).
    rates: np.ndarray
    #: Kind of each obstacle, (O,): :data:`OBSTACLE_BOX` or :data:`OBSTACLE_SPHERE`.
    obstacle_kinds: np.ndarray
    #: Centre of each obstacle, (O, 3), in [m].
    obstacle_centres: np.ndarray
    #: Pose of each obstacle, (O, 4, 4), in [m].
    obstacle_poses: np.ndarray
    #: Half sizes of each obstacle's box (a sphere's radius in column 0), (O, 3), in [m].
    obstacle_half: np.ndarray
    #: Bounding-sphere radius of each obstacle, (O,), in [m].
    obstacle_radius: np.ndarray
    #: The primitive of each pair that each joint moves relative to the other side, (P, nq)
    #: (-1: none; :func:`pair_owners`).
    owners: np.ndarray
    #: The joint frame of each configuration index, (nq,) (-1: none).
    joint_of_q: np.ndarray
    #: Covering-sphere centres of each primitive in its frame, (G, K, 3), in [m].
    cover_centres: np.ndarray
    #: Covering spheres of each primitive, (G,).
    cover_counts: np.ndarray
    #: Covering-sphere radius of each primitive, (G,), in [m].
    cover_radii: np.ndarray


class Scratch(NamedTuple):
    """Work arrays of the kernels for one :class:`KernelModel` (J joints, G primitives, P pairs)."""

    #: World pose of every joint frame, (J, 4, 4).
    joint_poses: np.ndarray
    #: One joint's local pose, (1, 4, 4).
    local: np.ndarray
    #: World pose of every primitive, (G, 4, 4).
    prim_poses: np.ndarray
    #: Each pair's slack (bound minus clearance) where its walk stands, (P,), in [m].
    slack: np.ndarray
    #: The point of the edge each pair is certified to, (P,).
    reach: np.ndarray
    #: The point of the edge where each pair's walk stands, (P,).
    where: np.ndarray
    #: A configuration, (nq,), in [rad].
    q: np.ndarray
    #: Counters: edge checks, advancement steps, pair bounds evaluated, the pair that last
    #: failed a quick test (4,).
    counters: np.ndarray
    #: Lever arms of the pair being walked at two points of the edge, (2, nq), in [m].
    arms: np.ndarray
    #: |joint steps| of the edge, (nq,), in [rad].
    dq: np.ndarray
    #: Each pair's lever arms where its walk stands, (P, nq), in [m].
    all_arms: np.ndarray
    #: Each pair's slack trend on the edge, (P,), in [m per unit s].
    trend: np.ndarray
    #: Output rows of the vectorised kernels, (3 + nq, LANES).
    lanes: np.ndarray
    #: Every pair's bound at up to :data:`GRID_POINTS` points of an edge, (GRID_POINTS, P).
    grid: np.ndarray
    #: Every pair's slack at an edge's end, (P,), in [m].
    end: np.ndarray
    #: The grid points' edge parameters, (GRID_POINTS,).
    grid_at: np.ndarray
    #: The point from which the grid certifies each pair to the edge's end, (P,).
    tail: np.ndarray


class CheckData(NamedTuple):
    """What the kernels of a validity checker take: its model, its scratch and the clearance."""

    model: KernelModel
    scratch: Scratch
    #: Required distance between the robot and anything else, in [m].
    clearance: float


def kernel_model(world: CollisionWorld, pairs: np.ndarray) -> KernelModel:
    """Kernel arrays of a world for the given pairs (rows ``(a, b, is_self)``, shape (P, 3))."""
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
    return KernelModel(*(np.ascontiguousarray(a) for a in arrays))


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


def make_scratch(model: KernelModel) -> Scratch:
    """Work arrays of the kernels for one model (:class:`Scratch`)."""
    joints, pairs, nq = len(model.axes), len(model.pairs), model.rates.shape[1]
    primitives = len(model.prim_joints)
    return Scratch(
        joint_poses=np.empty((joints, 4, 4)),
        local=np.empty((1, 4, 4)),
        prim_poses=np.empty((primitives, 4, 4)),
        slack=np.empty(pairs),
        reach=np.empty(pairs),
        where=np.empty(pairs),
        q=np.empty(nq),
        counters=np.zeros(4, dtype=np.int64),
        arms=np.empty((2, nq)),
        dq=np.empty(nq),
        all_arms=np.empty((pairs, nq)),
        trend=np.empty(pairs),
        lanes=np.empty((3 + nq, LANES)),
        grid=np.empty((GRID_POINTS, pairs)),
        end=np.empty(pairs),
        grid_at=np.empty(GRID_POINTS),
        tail=np.empty(pairs),
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
