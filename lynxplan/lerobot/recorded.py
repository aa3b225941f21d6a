"""Recorded LeRobot data in: joint positions -> tool path, limit and collision checks, figures.

A LeRobot episode (:func:`lynxplan.lerobot.dataset.read_episode`, its ``observation.state``) or a
frames CSV (:func:`lynxplan.lerobot.export.read_csv`) gives joint positions in LeRobot units;
:func:`joints_of` maps them to URDF angles (:mod:`lynxplan.lerobot.units`). Then
:func:`check_recorded`:

- FK of every frame: the tool point's path, in [m];
- limits: each frame's joints against the robot's limits (the calibrated ranges of a
  :func:`~lynxplan.lerobot.calibration.load_calibrated` model), each joint's speed and
  acceleration (finite differences at the recorded times) against the STS3215's figures
  (:mod:`lynxplan.lerobot.servo`; above them the reading is a glitch, not a motion);
- collisions: :func:`lynxplan.collision.check_trajectory` against the obstacles (and the arm's
  own links), at and between the frames (joints moving linearly between readings).

:func:`write_recorded` draws the tool path (top and side views, obstacles), the joints against
their limits, the clearance to each obstacle, and the meshcat HTML (:func:`lynxplan.viz.
export_html`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from lynxplan._plotting import pyplot, save_figure
from lynxplan.exceptions import InputError
from lynxplan.lerobot.servo import STS3215_NO_LOAD_SPEED, STS3215_PROFILE_ACCELERATION

if TYPE_CHECKING:
    from lynxplan.collision import CollisionReport
    from lynxplan.collision.obstacles import Obstacle
    from lynxplan.lerobot.dataset import RecordedEpisode
    from lynxplan.lerobot.units import JointFrames, LeRobotUnits
    from lynxplan.robots.robot import Robot

#: A joint this far past its limit [rad] counts as outside it (readings are 1 tick = 1.5e-3 rad).
LIMIT_TOLERANCE = 1e-6
#: Clearance vs time is drawn at most this many points (exact distances).
CLEARANCE_PLOT_POINTS = 600


class RecordedCheck(NamedTuple):
    """What the recorded joint positions did (:func:`check_recorded`)."""

    t: np.ndarray
    """Frame times, shape (K,), in [s]."""
    q: np.ndarray
    """Joint angles, shape (K, n), in [rad] (URDF angles)."""
    tool: np.ndarray
    """Tool point of each frame, shape (K, 3), in [m]."""
    lower: np.ndarray
    """The limits checked, shape (n,), in [rad]."""
    upper: np.ndarray
    """The limits checked, shape (n,), in [rad]."""
    outside: np.ndarray
    """Frames with the joint outside its limits, shape (K, n), bool."""
    peak_velocity: np.ndarray
    """Largest |joint speed| between frames, shape (n,), in [rad/s]."""
    peak_acceleration: np.ndarray
    """Largest |joint acceleration| over three frames, shape (n,), in [rad/s^2]."""
    collision: CollisionReport | None
    """The collision check, or None when there was nothing to check against."""
    joint_names: tuple[str, ...]
    """The joints, in column order."""

    @property
    def within_limits(self) -> bool:
        """Every frame within the joint limits."""
        return not bool(self.outside.any())

    @property
    def within_servo(self) -> bool:
        """Speeds and accelerations within the STS3215's no-load speed and profile acceleration."""
        return bool(
            (self.peak_velocity <= STS3215_NO_LOAD_SPEED).all()
            and (self.peak_acceleration <= STS3215_PROFILE_ACCELERATION).all()
        )

    @property
    def collision_free(self) -> bool | None:
        """No contact at or between frames (None: nothing was checked)."""
        return None if self.collision is None else self.collision.collision_free

    def limit_violations(self) -> list[str]:
        """One line per joint outside its limits: its frames, farthest value and limit [deg]."""
        lines = []
        for j, name in enumerate(self.joint_names):
            frames = np.flatnonzero(self.outside[:, j])
            if not frames.size:
                continue
            excess = np.maximum(self.lower[j] - self.q[:, j], self.q[:, j] - self.upper[j])
            worst = int(np.argmax(excess))
            limit = self.lower[j] if self.q[worst, j] < self.lower[j] else self.upper[j]
            lines.append(
                f"{name}: {frames.size} frame(s) from t = {self.t[frames[0]]:.3f} s, farthest "
                f"{math.degrees(self.q[worst, j]):+.2f} deg at t = {self.t[worst]:.3f} s "
                f"(limit {math.degrees(limit):+.2f} deg)"
            )
        return lines

    def summary(self) -> list[str]:
        """Lines for a person: duration, tool path extent, limits, servo, collisions."""
        low, high = self.tool.min(axis=0), self.tool.max(axis=0)
        lines = [
            f"{len(self.t)} frames over {self.t[-1] - self.t[0]:.3f} s; tool point x "
            f"{low[0]:.4f}..{high[0]:.4f}, y {low[1]:.4f}..{high[1]:.4f}, "
            f"z {low[2]:.4f}..{high[2]:.4f} m",
            "within limits: yes" if self.within_limits else "within limits: NO",
            *(f"  {line}" for line in self.limit_violations()),
            f"peak joint speed {math.degrees(float(self.peak_velocity.max())):.1f} deg/s, "
            f"acceleration {math.degrees(float(self.peak_acceleration.max())):.0f} deg/s^2 "
            f"({'within' if self.within_servo else 'BEYOND'} the STS3215's figures)",
        ]
        if self.collision is not None:
            best = self.collision.min_clearance
            state = (
                "yes" if self.collision_free else f"NO ({len(self.collision.contacts)} contacts)"
            )
            lines.append(f"collision free: {state}")
            lines.extend(
                f"  {contact.geometry} ({contact.link}) with {contact.obstacle}, "
                f"t = {contact.t_start:.3f}..{contact.t_end:.3f} s, depth "
                f"{contact.penetration_depth * 1000:.2f} mm"
                for contact in self.collision.contacts[:5]
            )
            if math.isfinite(best.clearance) and best.clearance > 0:
                lines.append(
                    f"min clearance {best.clearance * 1000:.2f} mm ({best.geometry} to "
                    f"{best.obstacle}, t = {best.time:.3f} s)"
                )
        return lines


def joints_of(
    units: LeRobotUnits, recorded: RecordedEpisode | Sequence[Mapping[str, Any]]
) -> JointFrames:
    """Joint angles [rad] and gripper channel of recorded LeRobot values (an episode, or the
    frame dicts of a CSV)."""
    from lynxplan.lerobot.dataset import RecordedEpisode

    if isinstance(recorded, RecordedEpisode):
        return units.to_joints(recorded.frames())
    return units.to_joints(list(recorded))


def _finite_differences(t: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    n = q.shape[1]
    if len(t) < 2:
        return np.zeros(n), np.zeros(n)
    dt = np.diff(t)
    velocity = np.diff(q, axis=0) / dt[:, None]
    if len(t) < 3:
        return np.abs(velocity).max(axis=0), np.zeros(n)
    mid = 0.5 * (dt[1:] + dt[:-1])
    acceleration = np.diff(velocity, axis=0) / mid[:, None]
    return np.abs(velocity).max(axis=0), np.abs(acceleration).max(axis=0)


def check_recorded(
    robot: Robot,
    t: Any,
    q: Any,
    *,
    obstacles: Sequence[Obstacle] = (),
    self_collision: bool = True,
) -> RecordedCheck:
    """Check recorded joint positions (module docstring).

    Args:
        robot: The model (its limits are the ones checked: load it with the arm's calibration).
        t: Frame times, shape (K,), strictly increasing, in [s].
        q: Joint angles, shape (K, n), in [rad].
        obstacles: The scene's obstacles, in [m].
        self_collision: Check the arm's non-adjacent links against each other too.

    Raises:
        InputError: shapes, non-finite values, times not strictly increasing.
    """
    from lynxplan.collision import CollisionWorld, check_trajectory

    times = np.asarray(t, dtype=float)
    joints = np.asarray(q, dtype=float)
    if times.ndim != 1 or len(times) < 1 or joints.shape != (len(times), robot.nq):
        raise InputError(
            f"recorded frames: t must have shape (K,) and q (K, {robot.nq}); got {times.shape} "
            f"and {joints.shape}"
        )
    if not (np.isfinite(times).all() and np.isfinite(joints).all()):
        raise InputError("recorded frames: t and q must be finite")
    if np.any(np.diff(times) <= 0):
        raise InputError("recorded frames: timestamps must be strictly increasing")
    lower = np.asarray(robot.limits.lower, dtype=float)
    upper = np.asarray(robot.limits.upper, dtype=float)
    outside = (joints < lower - LIMIT_TOLERANCE) | (joints > upper + LIMIT_TOLERANCE)
    tool = np.asarray(robot.fk(joints))[:, :3, 3]
    velocity, acceleration = _finite_differences(times, joints)
    collision = None
    if obstacles or self_collision:
        world = CollisionWorld(robot, list(obstacles), self_collision=self_collision)
        if world.pair_count:
            collision = check_trajectory(world, joints, times)
    return RecordedCheck(
        times,
        joints,
        tool,
        lower,
        upper,
        outside,
        velocity,
        acceleration,
        collision,
        tuple(robot.joint_names),
    )


def _draw_obstacles(ax: Any, obstacles: Sequence[Obstacle], axes: tuple[int, int]) -> None:
    from matplotlib.patches import Polygon
    from scipy.spatial import ConvexHull

    from lynxplan.task.plots import _obstacle_points

    for obstacle in obstacles:
        points = _obstacle_points(obstacle)[:, list(axes)] * 1000.0
        hull = points[ConvexHull(points).vertices]
        ax.add_patch(Polygon(hull, closed=True, fc="tab:orange", ec="tab:orange", alpha=0.35))


def plot_tool_path(check: RecordedCheck, obstacles: Sequence[Obstacle], path: Path) -> Path:
    """The tool point's path in top (x-y) and side (x-z) views, in [mm]; frames outside the
    limits marked red."""
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(11, 5))
    bad = check.outside.any(axis=1)
    for ax, (h, v, title) in zip(
        axes, ((0, 1, "top view (x-y)"), (0, 2, "side view (x-z)")), strict=True
    ):
        _draw_obstacles(ax, obstacles, (h, v))
        ax.plot(check.tool[:, h] * 1000, check.tool[:, v] * 1000, "-", color="tab:blue", lw=1.3)
        ax.plot(*(check.tool[0, [h, v]] * 1000), "go", ms=6, label="start")
        ax.plot(*(check.tool[-1, [h, v]] * 1000), "ks", ms=6, label="end")
        if bad.any():
            ax.plot(check.tool[bad, h] * 1000, check.tool[bad, v] * 1000, "r.", ms=4,
                    label="outside the joint limits")  # fmt: skip
        ax.set_xlabel(f"{'xyz'[h]} [mm]")
        ax.set_ylabel(f"{'xyz'[v]} [mm]")
        ax.set_title(f"recorded tool path, {title}")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize=8)
    return save_figure(fig, path, dpi=120)


def plot_joints(check: RecordedCheck, path: Path) -> Path:
    """Each joint [deg] vs time with its limits (dashed); frames outside them red."""
    plt = pyplot()
    n = len(check.joint_names)
    fig, axes = plt.subplots(n, 1, figsize=(9, 1.6 * n + 1), sharex=True)
    for j, ax in enumerate(np.atleast_1d(axes)):
        ax.plot(check.t, np.degrees(check.q[:, j]), lw=1.2)
        for limit in (check.lower[j], check.upper[j]):
            ax.axhline(math.degrees(limit), color="k", ls="--", lw=0.8)
        bad = check.outside[:, j]
        if bad.any():
            ax.plot(check.t[bad], np.degrees(check.q[bad, j]), "r.", ms=4)
        ax.set_ylabel(f"{check.joint_names[j]}\n[deg]", fontsize=8)
        ax.grid(True, alpha=0.3)
    np.atleast_1d(axes)[-1].set_xlabel("time [s]")
    np.atleast_1d(axes)[0].set_title("recorded joints and their limits (dashed)")
    return save_figure(fig, path, dpi=120)


def plot_clearance(
    robot: Robot, check: RecordedCheck, obstacles: Sequence[Obstacle], path: Path
) -> Path | None:
    """Exact clearance of the arm to each obstacle vs time, in [mm] (None: no obstacles)."""
    if not obstacles:
        return None
    from lynxplan.collision import CollisionWorld, clearance_profile

    plt = pyplot()
    world = CollisionWorld(robot, list(obstacles), self_collision=False)
    step = max(1, math.ceil(len(check.t) / CLEARANCE_PLOT_POINTS))
    index = np.unique(np.append(np.arange(0, len(check.t), step), len(check.t) - 1))
    profile = clearance_profile(world, check.q[index])
    fig, ax = plt.subplots(figsize=(9, 4.5))
    for o, obstacle in enumerate(obstacles):
        ax.plot(check.t[index], profile[:, o] * 1000, lw=1.3, label=obstacle.name)
    ax.axhline(0.0, color="r", lw=0.8)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("clearance [mm]")
    ax.set_title("recorded motion: clearance of the arm to each obstacle")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper right", fontsize=8)
    return save_figure(fig, path, dpi=120)


def write_recorded(
    robot: Robot,
    check: RecordedCheck,
    out_dir: str | Path,
    *,
    obstacles: Sequence[Obstacle] = (),
    name: str = "recorded",
    html: bool = True,
) -> list[Path]:
    """Write ``tool_path.png``, ``joints.png``, ``clearance.png`` (with obstacles) and
    ``<name>.html`` (meshcat, the arm replaying the frames) into ``out_dir`` (created).

    Raises:
        InputError: ``out_dir`` exists and is not a folder.
    """
    from lynxplan.viz import export_html

    folder = Path(out_dir)
    if folder.exists() and not folder.is_dir():
        raise InputError(f"{folder} is not a folder")
    folder.mkdir(parents=True, exist_ok=True)
    written = [
        plot_tool_path(check, obstacles, folder / "tool_path.png"),
        plot_joints(check, folder / "joints.png"),
    ]
    clearance = plot_clearance(robot, check, obstacles, folder / "clearance.png")
    if clearance is not None:
        written.append(clearance)
    if html:
        written.append(
            export_html(
                robot,
                check.q,
                check.t,
                folder / f"{name}.html",
                path=check.tool,
                motion=["free"] * len(check.t),
                obstacles=list(obstacles),
            )
        )
    return written
