"""meshcat scene of a motion, exported as one self-contained static HTML file.

The arm is drawn from its URDF visual geometry (boxes, cylinders and STL/OBJ/DAE meshes with the
URDF material colours), the obstacles as semi-transparent orange solids, an optional writing
plane, the pen path as polylines coloured by motion type, and the whole motion as a meshcat
animation.

meshcat is imported only here, inside the functions; the page is written without meshcat's
server process (:mod:`lynxplan._scene_html`): each visual mesh is sent once and decimated
(:mod:`lynxplan._meshes`), so that a page of a meshed arm stays a few MB.
"""

from __future__ import annotations

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
#: Floor grid colour (pale blue: told apart from the arm's greys and the path's colours).
FLOOR_COLOUR = 0xA8C8F0
#: meshcat's camera: vertical field of view, in [deg].
CAMERA_FOV_DEG = 75.0
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
    (meshcat's cylinder axis). A mesh is the triangles Pinocchio loaded (the URDF's scale
    applied), decimated to :data:`lynxplan._meshes.MAX_FACES` triangles."""
    import meshcat.geometry as mg

    from lynxplan._meshes import decimate, mesh_arrays

    shape = geometry_object.geometry
    kind = type(shape).__name__
    if kind.startswith("BVHModel"):
        vertices, faces = decimate(*mesh_arrays(geometry_object))
        return mg.TriangularMeshGeometry(vertices, faces), np.eye(4)
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


def _joint_poses(arm: Any, q: np.ndarray) -> np.ndarray:
    """World poses of every joint frame: q (F, nq) -> (F, njoints, 4, 4)."""
    import pinocchio as pin

    model = arm.model
    data = model.createData()
    poses = np.empty((len(q), model.njoints, 4, 4))
    for f, config in enumerate(q):
        pin.forwardKinematics(model, data, config)
        for j in range(model.njoints):
            poses[f, j] = data.oMi[j].homogeneous
    return poses


def _path_runs(path: np.ndarray, labels: Sequence[str]) -> Iterator[tuple[str, np.ndarray]]:
    """Consecutive runs of equal motion labels; each run shares its first point with the last."""
    start = 0
    for i in range(1, len(labels) + 1):
        if i == len(labels) or labels[i] != labels[start]:
            yield labels[start], path[max(start - 1, 0) : i]
            start = i


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
    camera_position: Sequence[float] | None = None,
    camera_target: Sequence[float] | None = None,
    autoplay: bool = True,
) -> Path:
    """Write a self-contained meshcat HTML file of a motion.

    The arm's links are animated (each visual mesh sent once, decimated, and copied where the
    URDF uses it again); a grid marks the floor under the arm's base; the pen path is drawn over
    the obstacles.

    Args:
        arm: The arm (``lynxplan.arm.Arm`` or a loaded robot): Pinocchio model and visual
            GeometryModel.
        q: Joint angles, shape (N, nq), in [rad].
        t: Sample times, shape (N,), increasing, in [s].
        out_path: The HTML file to write.
        path: Pen path to draw, shape (M, 3), in [m] (default: none).
        motion: Motion type of each path point, length M (``"line"`` red, ``"free"`` blue).
        obstacles: Obstacles to draw (semi-transparent orange).
        plane: Optional writing plane to draw.
        fps: Animation frame rate, in [frames/s]; the motion is sub-sampled to it.
        camera_position: Camera position in the world, shape (3,), in [m]. Default: framed on
            the task (the pen path, else the arm), seen along the writing plane's normal.
        camera_target: The point the camera looks at, shape (3,), in [m]. Default: the world
            origin (the arm's shoulder) when ``camera_position`` is given, else the task's
            centre.
        autoplay: Start the animation when the page opens.

    Returns:
        ``out_path`` as a Path.

    Raises:
        ShapeError, NonFiniteInputError, InputError: bad arrays or arguments.
    """
    from lynxplan._scene_html import Scene

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
    runs = _path_lines(path, motion) if path is not None else []
    frame_times = np.arange(0.0, times[-1] - times[0] + 0.5 / fps, 1.0 / fps) + times[0]
    frames = np.minimum(np.searchsorted(times, frame_times), len(times) - 1)
    joints = _joint_poses(arm, config[frames])
    scene = Scene()
    scene.set_property("/Grid", "visible", False)
    scene.set_property("/Axes", "visible", False)
    lowest = _draw_arm(scene, arm, joints[0])
    for obstacle in obstacles:
        shape, pose = _obstacle_geometry(obstacle)
        material = _lambert(OBSTACLE_COLOUR, opacity=OBSTACLE_OPACITY, transparent=True)
        scene.set_object(f"/meshcat/obstacles/{obstacle.name}", shape, material)
        scene.set_transform(f"/meshcat/obstacles/{obstacle.name}", pose)
    if plane is not None:
        _draw_plane(scene, plane)
    points = [run for _, run in runs]
    _draw_floor(scene, lowest, np.vstack([joints[0, :, :3, 3], *points]))
    _draw_path(scene, runs)
    position, target = _camera(camera_position, camera_target, joints[0], points, plane)
    scene.set_transform("/Cameras/default", np.eye(4))
    # The camera node is rotated +90 deg about x (three.js is y-up): (a, b, c) -> (a, c, -b).
    a, b, c = position.tolist()
    scene.set_property("/Cameras/default/rotated/<object>", "position", [a, c, -b])
    scene.orbit_target(target.tolist())
    scene.set_animation(_animation(joints, list(arm.model.names), fps), autoplay)
    out = Path(out_path)
    out.write_text(scene.html("lynxplan"), encoding="utf-8")
    return out


def _lambert(colour: int, **kwargs: Any) -> Any:
    import meshcat.geometry as mg

    return mg.MeshLambertMaterial(color=colour, **kwargs)


def _draw_arm(scene: Any, arm: Any, joints: np.ndarray) -> float:
    """The arm's visual geometry under one node per joint (placed at ``joints`` (njoints, 4, 4));
    each mesh file's triangles sent once. Returns the lowest point's height [m]."""
    import meshcat.geometry as mg

    model = arm.model
    sent: dict[tuple[str, str], tuple[str, Any, np.ndarray]] = {}
    lowest = np.inf
    for geometry_object in arm.visual_model.geometryObjects:
        joint = int(geometry_object.parentJoint)
        node = f"/meshcat/arm/{model.names[joint]}"
        where = f"{node}/{geometry_object.name}"
        scene.set_transform(node, joints[joint])
        colour = _hex(geometry_object.meshColor)
        mesh = str(getattr(geometry_object, "meshPath", "") or "")
        key = (mesh, str(geometry_object.meshScale))
        if key in sent:
            source, shape, offset = sent[key]
            scene.copy_object(source, where, colour)
        else:
            shape, offset = _geometry_and_offset(geometry_object)
            if isinstance(shape, mg.TriangularMeshGeometry):
                material = mg.MeshPhongMaterial(color=colour, flatShading=True, shininess=20)
                sent[key] = (where, shape, offset)
            else:
                material = _lambert(colour)
            scene.set_object(where, shape, material)
        local = geometry_object.placement.homogeneous @ offset
        scene.set_transform(where, local)
        lowest = min(lowest, _lowest_point(shape, joints[joint] @ local))
    return float(lowest) if np.isfinite(lowest) else 0.0


def _lowest_point(shape: Any, pose: np.ndarray) -> float:
    """Height of the lowest point of a meshcat mesh, box, cylinder or sphere at ``pose``."""
    vertices = getattr(shape, "vertices", None)
    if vertices is not None:
        return float((np.asarray(vertices, float) @ pose[2, :3] + pose[2, 3]).min())
    if hasattr(shape, "lengths"):  # a box
        half = 0.5 * np.asarray(shape.lengths, float)
    elif hasattr(shape, "radiusTop"):  # a cylinder along its local y
        half = np.array([shape.radiusTop, 0.5 * shape.height, shape.radiusTop], float)
    else:
        half = np.full(3, float(getattr(shape, "radius", 0.0)))
    return float(pose[2, 3] - np.abs(pose[2, :3]) @ half)


def _animation(joints: np.ndarray, names: Sequence[str], fps: float) -> Any:
    """meshcat Animation of the joint nodes (the visual geometry moves with them)."""
    from meshcat.animation import Animation

    from lynxplan._scene_html import anim_path

    animation = Animation(default_framerate=fps)
    moving = [j for j in range(joints.shape[1]) if not np.allclose(joints[:, j], joints[0, j])]
    root = anim_path("/meshcat/arm")
    for f in range(len(joints)):
        with animation.at_frame(root, f) as frame:
            for j in moving:
                frame[names[j]].set_transform(joints[f, j])
    return animation


def _draw_plane(scene: Any, plane: WritingPlane) -> None:
    import meshcat.geometry as mg

    pose = np.eye(4)
    pose[:3, :3] = plane.rotation
    pose[:3, 3] = plane.point
    material = _lambert(PLANE_COLOUR, opacity=0.35, transparent=True)
    scene.set_object("/meshcat/plane", mg.Box([plane.size[0], plane.size[1], 0.001]), material)
    scene.set_transform("/meshcat/plane", pose)


def _draw_path(scene: Any, runs: list[tuple[str, np.ndarray]]) -> None:
    """The pen path, one polyline per run of one motion type, drawn over the obstacles."""
    import meshcat.geometry as mg

    for i, (label, run) in enumerate(runs):
        colour = MOTION_COLOURS.get(label, OTHER_MOTION_COLOUR)
        # transparent (opacity 1): drawn with the translucent solids, after them (renderOrder)
        material = mg.LineBasicMaterial(
            color=colour, linewidth=3, depthTest=False, transparent=True, opacity=1.0
        )
        line = mg.Line(mg.PointsGeometry(run.T), material)
        scene.set_object(f"/meshcat/path/{i:03d}_{label}", line)
    if runs:
        scene.on_top("/meshcat/path")


def _grid_step(extent: float) -> float:
    """A round grid spacing (1, 2 or 5 x 10^k m) giving about 10 to 25 lines over ``extent``."""
    raw = max(extent, 1e-3) / 12.0
    power = 10.0 ** np.floor(np.log10(raw))
    return float(next(m * power for m in (1.0, 2.0, 5.0, 10.0) if m * power >= raw))


def _draw_floor(scene: Any, height: float, points: np.ndarray) -> None:
    """A square grid at ``height`` [m] (the floor under the arm's base) covering ``points``'
    x-y extent with a margin, lines at a round spacing."""
    import meshcat.geometry as mg

    low, high = points[:, :2].min(axis=0), points[:, :2].max(axis=0)
    step = _grid_step(float((high - low).max()) * 1.5)
    low = np.floor((low - 2 * step) / step) * step
    high = np.ceil((high + 2 * step) / step) * step
    segments = []
    for x in np.arange(low[0], high[0] + 0.5 * step, step):
        segments += [[x, low[1], height], [x, high[1], height]]
    for y in np.arange(low[1], high[1] + 0.5 * step, step):
        segments += [[low[0], y, height], [high[0], y, height]]
    material = mg.LineBasicMaterial(color=FLOOR_COLOUR)
    grid = mg.LineSegments(mg.PointsGeometry(np.array(segments).T), material)
    scene.set_object("/meshcat/floor", grid)


def _camera(
    position: Sequence[float] | None,
    target: Sequence[float] | None,
    joints: np.ndarray,
    path: list[np.ndarray],
    plane: WritingPlane | None,
) -> tuple[np.ndarray, np.ndarray]:
    """Camera position and orbit target (``joints``: the joint frames (njoints, 4, 4) at the
    first frame): as given, or framed on the pen path (else the arm):
    the whole path and the arm's joints (first frame) in view, seen from beside the line from
    the base to the path (70 deg about z), 63 deg above the writing plane (40 deg above the
    floor without a plane)."""
    if position is not None:
        eye = _camera_position(position)
        centre = np.zeros(3) if target is None else _camera_position(target, "camera_target")
        return eye, centre
    task = np.vstack(path) if path else joints[:, :3, 3]
    centre = 0.5 * (task.min(axis=0) + task.max(axis=0))
    if target is not None:
        centre = _camera_position(target, "camera_target")
    base = joints[min(1, len(joints) - 1), :3, 3]  # the first joint's origin
    towards_base = np.append(base[:2] - centre[:2], 0.0)
    towards_base /= max(float(np.linalg.norm(towards_base)), 1e-9)
    if not np.linalg.norm(base[:2] - centre[:2]) > 1e-6:
        towards_base = np.array([0.0, -1.0, 0.0])
    # From beside the line base-task (turned 70 deg about z): the arm does not hide the path.
    c, s = np.cos(np.radians(70.0)), np.sin(np.radians(70.0))
    side = np.array(
        [c * towards_base[0] - s * towards_base[1], s * towards_base[0] + c * towards_base[1], 0.0]
    )
    if plane is not None:
        normal = np.asarray(plane.normal, float) / np.linalg.norm(plane.normal)
        up = normal if normal[2] >= 0 else -normal
        direction = up + 0.5 * side  # 63 deg above the plane
    else:
        direction = side + np.array([0.0, 0.0, np.tan(np.radians(40.0))])
    direction = direction / np.linalg.norm(direction)
    radius = float(np.linalg.norm(np.vstack([task, joints[:, :3, 3]]) - centre, axis=1).max())
    distance = 1.35 * max(radius, 0.05) / np.tan(np.radians(CAMERA_FOV_DEG) / 2.0)
    return centre + distance * direction, centre


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


def _camera_position(position: Sequence[float], name: str = "camera_position") -> np.ndarray:
    camera = np.asarray(position, dtype=float)
    nonzero = camera.any() or name != "camera_position"
    if camera.shape != (3,) or not np.isfinite(camera).all() or not nonzero:
        raise InputError(f"{name} must be a finite, non-zero (3,) vector. Got: {camera}")
    return camera
