"""Numba kernels of the collision world: primitive poses and sphere lower bounds per sample."""

from __future__ import annotations

import math

import numba
import numpy as np

#: Obstacle kinds of the kernels.
BOX, SPHERE, CYLINDER = 0, 1, 2


@numba.njit(cache=True)
def _multiply(a: np.ndarray, b: np.ndarray, out: np.ndarray) -> None:
    """out = a @ b for 4x4 rigid transforms (bottom row 0 0 0 1), without allocation."""
    for i in range(3):
        for j in range(4):
            out[i, j] = a[i, 0] * b[0, j] + a[i, 1] * b[1, j] + a[i, 2] * b[2, j]
        out[i, 3] += a[i, 3]
    out[3, 0] = 0.0
    out[3, 1] = 0.0
    out[3, 2] = 0.0
    out[3, 3] = 1.0


@numba.njit(cache=True)
def poses_kernel(
    q: np.ndarray,
    axes: np.ndarray,
    index_q: np.ndarray,
    parents: np.ndarray,
    joint_placements: np.ndarray,
    primitive_joints: np.ndarray,
    primitive_placements: np.ndarray,
    out: np.ndarray,
) -> None:
    """World poses of every primitive: q (N, nq) -> out (N, G, 4, 4)."""
    joints = joint_placements.shape[0]
    world = np.zeros((joints, 4, 4))
    local = np.empty((4, 4))
    rotation = np.zeros((4, 4))
    for i in range(4):
        world[0, i, i] = 1.0
    for n in range(q.shape[0]):
        for j in range(1, joints):
            angle = q[n, index_q[j]]
            c, s = math.cos(angle), math.sin(angle)
            a = axes[j]
            i1, i2 = (a + 1) % 3, (a + 2) % 3
            rotation[:, :] = 0.0
            rotation[a, a] = 1.0
            rotation[3, 3] = 1.0
            rotation[i1, i1] = c
            rotation[i2, i2] = c
            rotation[i1, i2] = -s
            rotation[i2, i1] = s
            _multiply(joint_placements[j], rotation, local)
            _multiply(world[parents[j]], local, world[j])
        for g in range(primitive_joints.shape[0]):
            _multiply(world[primitive_joints[g]], primitive_placements[g], out[n, g])


@numba.njit(cache=True)
def obstacle_bounds_kernel(
    poses: np.ndarray,
    sphere_owner: np.ndarray,
    sphere_local: np.ndarray,
    sphere_radius: np.ndarray,
    obstacles: tuple[np.ndarray, ...],
    out: np.ndarray,
) -> None:
    """Sphere lower bound of every (primitive, obstacle) distance: out (N, G, O), in [m].

    obstacles: kinds (O,), centres (O, 3), rotations (O, 3, 3), sizes (O, 3), in [m]."""
    kinds, centres, rotations, sizes = obstacles
    count, primitives = poses.shape[0], poses.shape[1]
    local = np.empty(3)
    for n in range(count):
        for g in range(primitives):
            for o in range(kinds.shape[0]):
                out[n, g, o] = np.inf
        for k in range(sphere_owner.shape[0]):
            g = sphere_owner[k]
            pose = poses[n, g]
            for o in range(kinds.shape[0]):
                for i in range(3):
                    value = pose[i, 3] - centres[o, i]
                    for m in range(3):
                        value += pose[i, m] * sphere_local[k, m]
                    local[i] = value
                # local = R^T (p - c): obstacle frame coordinates.
                x = rotations[o, 0, 0] * local[0] + rotations[o, 1, 0] * local[1]
                x += rotations[o, 2, 0] * local[2]
                y = rotations[o, 0, 1] * local[0] + rotations[o, 1, 1] * local[1]
                y += rotations[o, 2, 1] * local[2]
                z = rotations[o, 0, 2] * local[0] + rotations[o, 1, 2] * local[1]
                z += rotations[o, 2, 2] * local[2]
                if kinds[o] == SPHERE:
                    signed = math.sqrt(x * x + y * y + z * z) - sizes[o, 0]
                else:
                    if kinds[o] == BOX:
                        e0, e1 = abs(x) - sizes[o, 0], abs(y) - sizes[o, 1]
                        e2 = abs(z) - sizes[o, 2]
                    else:
                        e0, e1 = math.sqrt(x * x + y * y) - sizes[o, 0], abs(z) - sizes[o, 1]
                        e2 = -np.inf
                    p0, p1, p2 = max(e0, 0.0), max(e1, 0.0), max(e2, 0.0)
                    signed = math.sqrt(p0 * p0 + p1 * p1 + p2 * p2) + min(max(e0, e1, e2), 0.0)
                bound = signed - sphere_radius[g]
                out[n, g, o] = min(out[n, g, o], bound)
