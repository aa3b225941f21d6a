"""Seeded teleop-like streams of tool targets: what a leader arm, a phone or a gamepad sends.

A stream is a random smooth joint path (a sum of slow sines within 70 % of the joint limits, at
``fps`` frames per second) taken through the forward kinematics, so every target pose is one the
arm can reach; with ``out_of_reach`` the tool point is pushed radially away from the shoulder
over frames 30..55 (smoothly out and back, up to 2.2 times its distance), far out of the arm's
reach, as a hand moving a leader past the follower's workspace does. The same seeds give the same
streams to every solver compared (lynxplan's :func:`~lynxplan.lerobot.track_targets`, placo as
LeRobot drives it: see :mod:`lynxplan.bench.lerobot_track`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

if TYPE_CHECKING:
    from lynxplan.robots.robot import Robot

#: Frames of a stream (3 s at 30 frames/s).
STREAM_FRAMES = 90
#: The SO-101's shoulder point the out-of-reach push is radial from, in [m].
SHOULDER = (0.0, 0.0, 0.1)
#: Farthest push, as a fraction of the tool point's distance from the shoulder (1.2: to 2.2x).
PUSH = 1.2
#: Frames of the push (it rises from the first and is back at the last).
PUSH_FRAMES = (30, 55)


class TargetStream(NamedTuple):
    """One stream of N tool targets and the joint path it came from."""

    q: np.ndarray
    """The generating joint path, shape (N, n), in [rad]."""
    poses: np.ndarray
    """Target tool poses in the base frame, shape (N, 4, 4), in [m] (the push moves the point
    and keeps the orientation)."""
    pitches: np.ndarray
    """The approach pitch pi/2 - (q2 + q3 + q4) of the yaw-pitch^3-roll family, shape (N,), in
    [rad] (it ignores the SO-101 model's small built-in angles: within ~1e-3 rad)."""
    rolls: np.ndarray
    """The wrist roll of the path, shape (N,), in [rad]."""
    pushed: np.ndarray
    """Whether the target was pushed beyond ``out_of_reach_radius``, shape (N,), bool."""

    @property
    def positions(self) -> np.ndarray:
        """Target tool points, shape (N, 3), in [m]."""
        return self.poses[:, :3, 3]


def smooth_joint_path(
    robot: Robot, seed: int, frames: int = STREAM_FRAMES, fps: float = 30.0
) -> np.ndarray:
    """A random sum of sines within 70 % of the limits, shape (frames, n), in [rad]; joint
    speeds under ~1.5 rad/s (amplitudes <= 0.6 rad, 0.5..1.2 rad/s)."""
    rng = np.random.default_rng(seed)
    lower, upper = robot.limits.lower, robot.limits.upper
    middle, half = (lower + upper) / 2, 0.7 * (upper - lower) / 2
    t = np.arange(frames) / fps
    path = np.empty((frames, robot.nq))
    for j in range(robot.nq):
        amplitude = rng.uniform(0.2, 0.5, 3) * min(half[j], 0.6)
        omega = rng.uniform(0.5, 1.2, 3)
        phase = rng.uniform(0, 2 * math.pi, 3)
        centre = middle[j] + rng.uniform(-0.3, 0.3) * half[j]
        path[:, j] = centre + (amplitude * np.sin(omega * t[:, None] + phase)).sum(axis=1)
    return np.clip(path, lower + 0.05, upper - 0.05)


def target_stream(
    robot: Robot,
    seed: int,
    *,
    out_of_reach: bool = False,
    frames: int = STREAM_FRAMES,
    fps: float = 30.0,
    out_of_reach_radius: float = 0.6,
) -> TargetStream:
    """The stream of ``seed`` (module docstring).

    Args:
        robot: A 5-joint arm of the yaw-pitch^3-roll family (SO-100/SO-101).
        seed: The random seed of the joint path.
        out_of_reach: Push the targets of frames 30..55 radially out of reach.
        frames, fps: Length and rate of the stream [frames, frames/s].
        out_of_reach_radius: Distance from :data:`SHOULDER` beyond which a target counts as
            pushed out of reach, in [m] (the SO-101's tool point stays within 0.48 m of it).
    """
    q = smooth_joint_path(robot, seed, frames, fps)
    poses = np.array(robot.fk(q), dtype=float)
    shoulder = np.asarray(SHOULDER)
    k = np.arange(frames)
    first, last = PUSH_FRAMES
    push = np.zeros(frames)
    if out_of_reach:
        inside = (k >= first) & (k <= last)
        push = np.clip(np.sin(np.pi * (k - first) / (last - first)), 0, None) * inside
    poses[:, :3, 3] = shoulder + (poses[:, :3, 3] - shoulder) * (1 + PUSH * push[:, None])
    pushed = np.linalg.norm(poses[:, :3, 3] - shoulder, axis=1) > out_of_reach_radius
    pitches = math.pi / 2 - q[:, 1:4].sum(axis=1)
    return TargetStream(q, poses, pitches, q[:, 4].copy(), pushed)
