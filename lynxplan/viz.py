"""meshcat scene of a motion, exported as one self-contained static HTML file.

The arm is drawn from its URDF visual geometry (boxes, cylinders and STL/OBJ/DAE meshes with the
URDF material colours), the obstacles as semi-transparent orange solids, an optional writing
plane, the pen path as polylines coloured by motion type, and the whole motion as a meshcat
animation.

meshcat is imported only here, inside the functions. ``meshcat.Visualizer()`` starts a ZMQ server
as a child process; :func:`export_html` always stops it before returning.
"""

from __future__ import annotations

import contextlib
import io
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lynxplan.collision.obstacles import BoxObstacle, CylinderObstacle, Obstacle, SphereObstacle
from lynxplan.exceptions import InputError, NonFiniteInputError, ShapeError

#: Colour of obstacles (RGB hex) and their opacity.
OBSTACLE_COLOUR = 0xFF7F00
OBSTACLE_OPACITY = 0.55
#: Pen path colour per motion type (RGB hex); other labels use ``OTHER_MOTION_COLOUR``.
MOTION_COLOURS = {"line": 0xE01010, "free": 0x1040E0}
OTHER_MOTION_COLOUR = 0x10A010
PLANE_COLOUR = 0x40B0B0
#: Default animation frame rate, in [frames/s].
DEFAULT_FPS = 30.0
#: meshcat draws cylinders along their local y axis; URDF and coal along z: rotate by +90 deg
#: about x (maps y onto z).
_Y_TO_Z = np.array([[1.0, 0, 0, 0], [0, 0, -1.0, 0], [0, 1.0, 0, 0], [0, 0, 0, 1.0]])


@dataclass(frozen=True)
class WritingPlane:
    """A flat rectangle drawn in the scene (not an obstacle): the one writing-plane type, used by
    the task plots and the meshcat export.

    Attributes:
        point: A point of the plane (the rectangle's centre), shape (3,), in [m].
        normal: Plane normal, shape (3,) (any length but zero).
        size: Rectangle edge lengths (along the in-plane x and y directions), shape (2,), in [m].
    """

    point: np.ndarray
    normal: np.ndarray
    size: tuple[float, float] = (0.3, 0.3)

    @classmethod
    def tilted(
        cls, point: Any, tilt: float, size: tuple[float, float] = (0.3, 0.3)
    ) -> WritingPlane:
        """A plane through ``point`` (3,) [m] tilted by ``tilt`` [rad] to x-y, rising along +y."""
        normal = np.array([0.0, -np.sin(tilt), np.cos(tilt)])
        return cls(np.asarray(point, float), normal, (float(size[0]), float(size[1])))

    @property
    def rotation(self) -> np.ndarray:
        """Plane axes (columns: in-plane x kept horizontal, in-plane y, unit normal), (3, 3)."""
        return _frame_from_normal(np.asarray(self.normal, float))


def tilted_plane(
    point: Any, tilt_deg: float = 20.0, size: tuple[float, float] = (0.3, 0.3)
) -> WritingPlane:
    """A plane through ``point`` (3,) [m] tilted by ``tilt_deg`` [deg] to x-y, rising along +y."""
    return WritingPlane.tilted(point, float(np.radians(tilt_deg)), size)


def _frame_from_normal(normal: np.ndarray) -> np.ndarray:
    """Rotation (3, 3) whose z axis is the unit normal and whose x axis stays horizontal."""
    z = normal / np.linalg.norm(normal)
    x = np.cross([0.0, 1.0, 0.0], z) if abs(z[1]) < 0.99 else np.cross(z, [1.0, 0.0, 0.0])
    x /= np.linalg.norm(x)
    return np.column_stack((x, np.cross(z, x), z))


def _hex(rgba: np.ndarray) -> int:
    r, g, b = (round(float(c) * 255) for c in rgba[:3])
    return (r << 16) | (g << 8) | b


#: meshcat geometry class of each mesh file suffix.
_MESH_FILES = {".stl": "StlMeshGeometry", ".obj": "ObjMeshGeometry", ".dae": "DaeMeshGeometry"}


def _geometry_and_offset(geometry_object: Any) -> tuple[Any, np.ndarray]:
    """meshcat geometry of a visual GeometryObject and its offset (4, 4) in the object's frame
    (a mesh's scale; meshcat's cylinder axis)."""
    import meshcat.geometry as mg

    shape = geometry_object.geometry
    kind = type(shape).__name__
    mesh_path = Path(str(getattr(geometry_object, "meshPath", "") or ""))
    if mesh_path.suffix.lower() in _MESH_FILES and mesh_path.is_file():
        mesh = getattr(mg, _MESH_FILES[mesh_path.suffix.lower()]).from_file(str(mesh_path))
        scale = np.eye(4)
        scale[:3, :3] = np.diag(np.asarray(geometry_object.meshScale, dtype=float))
        return mesh, scale
    if kind == "Box":
        return mg.Box((2.0 * np.asarray(shape.halfSide)).tolist()), np.eye(4)
    if kind == "Cylinder":
        return mg.Cylinder(2.0 * shape.halfLength, shape.radius), _Y_TO_Z
    if kind == "Sphere":
        return mg.Sphere(shape.radius), np.eye(4)
    raise InputError(
        f"visual geometry of type {kind} cannot be drawn (box, cylinder, sphere, STL/OBJ/DAE mesh)"
    )


def _obstacle_geometry(obstacle: Obstacle) -> tuple[Any, np.ndarray]:
    import meshcat.geometry as mg

    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = obstacle.rotation, obstacle.centre
    if isinstance(obstacle, BoxObstacle):
        return mg.Box(obstacle.size.tolist()), pose
    if isinstance(obstacle, SphereObstacle):
        return mg.Sphere(obstacle.radius), pose
    assert isinstance(obstacle, CylinderObstacle)
    return mg.Cylinder(obstacle.length, obstacle.radius), pose @ _Y_TO_Z


def _visual_poses(arm: Any, q: np.ndarray) -> np.ndarray:
    """World poses of every visual geometry: q (F, nq) -> (F, V, 4, 4)."""
    import pinocchio as pin

    model, visual = arm.model, arm.visual_model
    data = model.createData()
    geometry_data = pin.GeometryData(visual)
    poses = np.empty((len(q), len(visual.geometryObjects), 4, 4))
    for f, config in enumerate(q):
        pin.forwardKinematics(model, data, config)
        pin.updateGeometryPlacements(model, data, visual, geometry_data)
        for v in range(len(visual.geometryObjects)):
            poses[f, v] = geometry_data.oMg[v].homogeneous
    return poses


def _path_runs(path: np.ndarray, labels: Sequence[str]) -> Iterator[tuple[str, np.ndarray]]:
    """Consecutive runs of equal motion labels; each run shares its first point with the last."""
    start = 0
    for i in range(1, len(labels) + 1):
        if i == len(labels) or labels[i] != labels[start]:
            yield labels[start], path[max(start - 1, 0) : i]
            start = i


@contextlib.contextmanager
def _visualizer() -> Iterator[Any]:
    """A meshcat Visualizer whose ZMQ server process is stopped on exit."""
    import meshcat

    with contextlib.redirect_stdout(io.StringIO()):
        vis = meshcat.Visualizer()
    try:
        yield vis
    finally:
        window = vis.window
        try:
            vis.delete()
        finally:
            window.zmq_socket.close(linger=0)
            if window.server_proc is not None:
                window.server_proc.kill()
                window.server_proc.wait()


def export_html(
    arm: Any,
    q: Any,
    t: Any,
    out_path: str | Path,
    *,
    path: Any = None,
    motion: Sequence[str] | None = None,
    obstacles: Sequence[Obstacle] = (),
    plane: WritingPlane | None = None,
    fps: float = DEFAULT_FPS,
    camera_position: Sequence[float] = (0.45, -0.25, 0.4),
    autoplay: bool = True,
) -> Path:
    """Write a self-contained meshcat HTML file of a motion.

    Args:
        arm: The arm (``lynxplan.arm.Arm``): Pinocchio model and visual GeometryModel.
        q: Joint angles, shape (N, nq), in [rad].
        t: Sample times, shape (N,), increasing, in [s].
        out_path: The HTML file to write.
        path: Pen path to draw, shape (M, 3), in [m] (default: none).
        motion: Motion type of each path point, length M (``"line"`` red, ``"free"`` blue).
        obstacles: Obstacles to draw (semi-transparent orange).
        plane: Optional writing plane to draw.
        fps: Animation frame rate, in [frames/s]; the motion is sub-sampled to it.
        camera_position: Camera position in the world, shape (3,), in [m]; the camera looks at
            the world origin (meshcat's orbit target), i.e. the arm's shoulder.
        autoplay: Start the animation when the page opens.

    Returns:
        ``out_path`` as a Path.

    Raises:
        ShapeError, NonFiniteInputError, InputError: bad arrays or arguments.
    """
    import meshcat.geometry as mg
    from meshcat.animation import Animation

    config = np.asarray(q, dtype=float)
    times = np.asarray(t, dtype=float)
    if config.ndim != 2 or config.shape[1] != arm.model.nq:
        raise ShapeError("q", f"(N, {arm.model.nq})", config.shape)
    if times.shape != (len(config),):
        raise ShapeError("t", f"({len(config)},)", times.shape)
    if not (np.isfinite(config).all() and np.isfinite(times).all()):
        raise NonFiniteInputError("q or t")
    if not fps > 0:
        raise InputError(f"fps must be positive. Got: {fps!r}")
    camera = _camera_position(camera_position)
    runs = _path_lines(path, motion) if path is not None else []
    frame_times = np.arange(0.0, times[-1] - times[0] + 0.5 / fps, 1.0 / fps) + times[0]
    frames = np.minimum(np.searchsorted(times, frame_times), len(times) - 1)
    poses = _visual_poses(arm, config[frames])
    visual = arm.visual_model.geometryObjects
    with _visualizer() as vis:
        vis["/Grid"].set_property("visible", False)
        vis["/Axes"].set_property("visible", False)
        offsets = []
        for v, geometry_object in enumerate(visual):
            shape, offset = _geometry_and_offset(geometry_object)
            material = mg.MeshLambertMaterial(color=_hex(geometry_object.meshColor))
            vis["arm"][geometry_object.name].set_object(shape, material)
            vis["arm"][geometry_object.name].set_transform(poses[0, v] @ offset)
            offsets.append(offset)
        for obstacle in obstacles:
            shape, pose = _obstacle_geometry(obstacle)
            material = mg.MeshLambertMaterial(
                color=OBSTACLE_COLOUR, opacity=OBSTACLE_OPACITY, transparent=True
            )
            vis["obstacles"][obstacle.name].set_object(shape, material)
            vis["obstacles"][obstacle.name].set_transform(pose)
        if plane is not None:
            _draw_plane(vis, plane)
        for i, (label, run) in enumerate(runs):
            colour = MOTION_COLOURS.get(label, OTHER_MOTION_COLOUR)
            material = mg.LineBasicMaterial(color=colour, linewidth=3)
            vis["path"][f"{i:03d}_{label}"].set_object(mg.Line(mg.PointsGeometry(run.T), material))
        vis["/Cameras/default"].set_transform(np.eye(4))
        # The camera node is rotated +90 deg about x (three.js is y-up): (a, b, c) -> (a, c, -b).
        a, b, c = camera.tolist()
        vis["/Cameras/default/rotated/<object>"].set_property("position", [a, c, -b])
        animation = Animation(default_framerate=fps)
        for f in range(len(frames)):
            with animation.at_frame(vis, f) as frame:
                for v, geometry_object in enumerate(visual):
                    frame["arm"][geometry_object.name].set_transform(poses[f, v] @ offsets[v])
        vis.set_animation(animation, play=autoplay, repetitions=1)
        html = vis.static_html()
    out = Path(out_path)
    out.write_text(html, encoding="utf-8")
    return out


def _draw_plane(vis: Any, plane: WritingPlane) -> None:
    import meshcat.geometry as mg

    pose = np.eye(4)
    pose[:3, :3] = plane.rotation
    pose[:3, 3] = plane.point
    material = mg.MeshLambertMaterial(color=PLANE_COLOUR, opacity=0.35, transparent=True)
    vis["plane"].set_object(mg.Box([plane.size[0], plane.size[1], 0.001]), material)
    vis["plane"].set_transform(pose)


def _path_lines(path: Any, motion: Sequence[str] | None) -> list[tuple[str, np.ndarray]]:
    """The pen path cut into polylines of one motion type each."""
    points = np.asarray(path, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ShapeError("path", "(M, 3)", points.shape)
    labels = list(motion) if motion is not None else ["line"] * len(points)
    if len(labels) != len(points):
        raise InputError(
            f"motion must have one label per path point: {len(labels)} != {len(points)}"
        )
    return [(label, run) for label, run in _path_runs(points, labels) if len(run) >= 2]


def _camera_position(position: Sequence[float]) -> np.ndarray:
    camera = np.asarray(position, dtype=float)
    if camera.shape != (3,) or not np.isfinite(camera).all() or not camera.any():
        raise InputError(f"camera_position must be a finite, non-zero (3,) vector. Got: {camera}")
    return camera
