"""Built-in robots and URDF loading: a fixed-base Pinocchio model of the arm chain and its tool.

Built-ins: ``al5`` (the shipped URDF); ``so100``, ``so101``, ``ur5``, ``ur10`` and ``panda``
(from ``example_robot_data``, loaded with a fixed base, not the loader's free-flyer). Joints off
the path from the base to the tool (a gripper's jaw) are locked at zero (clamped into their
limits) and reported separately.

SO-100 tool frame: the upstream model has none. lynxplan adds ``tool`` on the roll axis between
the jaws: in the ``gripper`` link frame at (0, -0.1014, 0) m, i.e. midway between the closed jaws'
inner faces (x = +-7.9 mm, measured on Fixed_Jaw.stl and Moving_Jaw.stl) and 5 mm behind their
tips (y = -0.1064 m), with its z axis along the approach (-y of ``gripper``) and x towards the
fixed jaw. Pass ``tool=`` to use another frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lynxplan.exceptions import ModelError, UnknownRobotError
from lynxplan.shipped import default_urdf_path

#: SO-100 tool placement in the ``gripper`` link frame (see the module docstring).
SO100_TOOL_TRANSLATION = (0.0, -0.1014, 0.0)
SO100_TOOL_RPY = (np.pi / 2, 0.0, 0.0)


@dataclass(frozen=True)
class BuiltinRobot:
    """A robot lynxplan knows by name.

    Attributes:
        name: Short name (``load_robot(name)``).
        description: One line for ``lynxplan robots``.
        urdf: Path of its URDF.
        tool: Name of its tool frame.
        package_dirs: Folders that ``package://`` mesh URIs resolve against.
        arm_joints: Joints of its arm chain (the gripper's locked joints not counted).
        srdf: Its SRDF (the self-collision pairs it disables) where :func:`find_srdf` would not
            find it by the URDF's name; None: found by name, or none.
        selection_rules: The IK branch-selection rules it offers (``Robot.ik``'s ``select``):
            "nearest" for every robot, the AL5 also the report's "report".
    """

    name: str
    description: str
    urdf: Path
    tool: str
    package_dirs: tuple[str, ...]
    arm_joints: int = 5
    srdf: Path | None = None
    selection_rules: tuple[str, ...] = ("nearest",)


def _example_robot_data_dir() -> Path:
    from lynxplan.mesh_paths import example_robot_data_robots

    robots = example_robot_data_robots()
    if robots is None:  # pragma: no cover - a dependency
        raise ModelError(
            "example_robot_data is not installed (pip install example-robot-data-loaders)"
        )
    return robots


def builtin_robots() -> dict[str, BuiltinRobot]:
    """The built-in robots by name."""
    robots = _example_robot_data_dir()
    packages = (str(robots.parent.parent),)  # package://example-robot-data/robots/...
    return {
        "al5": BuiltinRobot(
            "al5",
            "Lynxmotion AL5-class 5-DOF arm with a pen (SPEC Part 1)",
            default_urdf_path(),
            "tool",
            (),
            selection_rules=("nearest", "report"),
        ),
        "so100": BuiltinRobot(
            "so100",
            "SO-ARM100 (LeRobot), 5 arm joints + gripper jaw; tool between the jaws",
            robots / "so_arm_description" / "urdf" / "so100.urdf",
            "tool",
            packages,
        ),
        "so101": BuiltinRobot(
            "so101",
            "SO-101 (LeRobot), 5 arm joints + gripper jaw; tool gripper_frame_link",
            robots / "so_arm_description" / "urdf" / "so101.urdf",
            "gripper_frame_link",
            packages,
        ),
        "ur5": BuiltinRobot(
            "ur5",
            "Universal Robots UR5 (example-robot-data), 6 joints; tool tool0",
            robots / "ur_description" / "urdf" / "ur5_robot.urdf",
            "tool0",
            packages,
            6,
            robots / "ur_description" / "srdf" / "ur5.srdf",
        ),
        "ur10": BuiltinRobot(
            "ur10",
            "Universal Robots UR10 (example-robot-data), 6 joints; tool tool0",
            robots / "ur_description" / "urdf" / "ur10_robot.urdf",
            "tool0",
            packages,
            6,
        ),
        "panda": BuiltinRobot(
            "panda",
            "Franka Panda (example-robot-data), 7 joints, fingers locked; tool panda_hand_tcp",
            robots / "panda_description" / "urdf" / "panda.urdf",
            "panda_hand_tcp",
            packages,
            7,
        ),
    }


@dataclass(frozen=True)
class LoadedModel:
    """A URDF reduced to its arm chain.

    Attributes:
        name: Built-in name or the URDF's file name.
        urdf: The URDF path.
        model: Pinocchio model of the arm chain (fixed base; locked joints removed).
        tool_frame: Name of the tool frame.
        tool_frame_id: Its Pinocchio frame id.
        locked_joints: Joints off the arm chain, locked at the given angle/position.
        package_dirs: Mesh search folders.
        urdf_xml: The URDF text with the locked joints made fixed (for the geometry models).
        srdf: The SRDF read, or None.
        disabled_collisions: Link pairs whose self-collision is not checked (the SRDF's
            ``disable_collisions``).
    """

    name: str
    urdf: Path
    model: Any
    tool_frame: str
    tool_frame_id: int
    locked_joints: tuple[tuple[str, float], ...]
    package_dirs: tuple[str, ...]
    urdf_xml: str
    srdf: Path | None = None
    disabled_collisions: tuple[tuple[str, str], ...] = ()


def _add_frame(model: Any, name: str, parent_frame: str, translation: Any, rpy: Any) -> None:
    import pinocchio as pin

    parent = model.frames[_frame_id(model, parent_frame)]
    placement = parent.placement * pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(translation))
    model.addFrame(pin.Frame(name, parent.parentJoint, placement, pin.FrameType.OP_FRAME))


def _frame_id(model: Any, name: str) -> int:
    """Frame id by name, preferring the link (BODY) frame where a joint has the same name."""
    import pinocchio as pin

    matches = [i for i, f in enumerate(model.frames) if f.name == name]
    bodies = [i for i in matches if model.frames[i].type == pin.FrameType.BODY]
    return int((bodies or matches)[0])


def _lock_joints(xml: str, angles: dict[str, float]) -> str:
    """The URDF text with the named joints made fixed at the given angles."""
    import xml.etree.ElementTree as ET

    import pinocchio as pin

    root = ET.fromstring(xml)
    for joint in root.iter("joint"):
        name = joint.get("name")
        if name not in angles or joint.get("type") == "fixed":
            continue
        angle = angles[name]
        if angle != 0.0 and joint.get("type") in ("revolute", "continuous"):
            origin = joint.find("origin")
            axis_el = joint.find("axis")
            axis = np.array(
                [
                    float(v)
                    for v in (
                        (axis_el.get("xyz") if axis_el is not None else None) or "1 0 0"
                    ).split()
                ]
            )
            rpy = [
                float(v)
                for v in (origin.get("rpy", "0 0 0") if origin is not None else "0 0 0").split()
            ]
            rotation = (
                pin.rpy.rpyToMatrix(*rpy)
                @ pin.AngleAxis(angle, axis / np.linalg.norm(axis)).matrix()
            )
            if origin is None:
                origin = ET.SubElement(joint, "origin")
            origin.set("rpy", " ".join(repr(float(v)) for v in pin.rpy.matrixToRpy(rotation)))
        joint.set("type", "fixed")
    return ET.tostring(root, encoding="unicode")


def find_srdf(urdf: Path) -> Path | None:
    """The SRDF of a URDF where the usual layouts put it: ``<stem>.srdf`` next to it, or in
    ``../srdf/`` (example-robot-data's ``panda_description/{urdf,srdf}``); None if neither."""
    name = urdf.with_suffix(".srdf").name
    return next(
        (p for p in (urdf.parent / name, urdf.parent.parent / "srdf" / name) if p.is_file()), None
    )


def read_disabled_collisions(srdf: Path) -> tuple[tuple[str, str], ...]:
    """The link pairs of an SRDF's ``<disable_collisions link1= link2=>`` elements.

    Raises:
        ModelError: an unreadable SRDF, naming it.
    """
    import xml.etree.ElementTree as ET

    try:
        root = ET.parse(srdf).getroot()
    except (OSError, ET.ParseError) as exc:
        raise ModelError(f"cannot read SRDF {srdf}: {exc}") from exc
    pairs = []
    for element in root.iter("disable_collisions"):
        first, second = element.get("link1"), element.get("link2")
        if not first or not second:
            raise ModelError(f"SRDF {srdf.name}: disable_collisions needs link1 and link2")
        pairs.append((first, second))
    return tuple(pairs)


def _srdf_of(urdf: Path, srdf: str | Path | None) -> Path | None:
    if srdf is None:
        return find_srdf(urdf)
    path = Path(srdf)
    if not path.is_file():
        raise ModelError(f"SRDF file not found: {srdf}")
    return path


def load_model(  # noqa: PLR0912, PLR0915 (URDF reading steps in order)
    name_or_urdf: str | Path,
    tool: str | None,
    base: np.ndarray | None,
    package_dirs: tuple[str, ...] | list[str] | None,
    srdf: str | Path | None = None,
) -> tuple[LoadedModel, BuiltinRobot | None]:
    """Read a built-in robot or a URDF into a fixed-base arm chain ending at the tool frame.

    ``package_dirs`` are searched first for its meshes (see :mod:`lynxplan.mesh_paths`); the
    SRDF (``srdf``, else :func:`find_srdf`) names the link pairs not checked for self-collision.

    Raises:
        UnknownRobotError: a name that is neither a built-in nor an existing file.
        ModelError: the URDF cannot be parsed, the tool frame is missing, or a joint type on
            the chain is not revolute.
    """
    import pinocchio as pin

    builtins = builtin_robots()
    spec = builtins.get(str(name_or_urdf)) if isinstance(name_or_urdf, str) else None
    if spec is not None:
        urdf, name = spec.urdf, spec.name
        dirs = tuple(package_dirs) if package_dirs is not None else spec.package_dirs
    else:
        urdf = Path(name_or_urdf)
        if not urdf.is_file():
            raise UnknownRobotError(str(name_or_urdf), tuple(builtins))
        name, dirs = urdf.name, tuple(package_dirs or ())
    for folder in dirs:
        if not Path(folder).is_dir():
            raise ModelError(f"package_dirs: {folder} is not a folder")
    srdf_path = _srdf_of(urdf, srdf if srdf is not None or spec is None else spec.srdf)
    disabled = read_disabled_collisions(srdf_path) if srdf_path is not None else ()
    try:
        xml = urdf.read_text()
        full = pin.buildModelFromXML(xml)
    except (RuntimeError, ValueError, OSError) as exc:
        raise ModelError(f"cannot load URDF {urdf}: {exc}") from exc
    if base is not None:
        base_placement = np.asarray(base, dtype=float)
        if base_placement.shape != (4, 4):
            from lynxplan.exceptions import ShapeError

            raise ShapeError("base", "(4, 4)", base_placement.shape)
    tool_name = tool if tool is not None else (spec.tool if spec is not None else None)
    tool_parent: str | None = None
    if spec is not None and spec.name == "so100" and tool is None:
        tool_parent = "gripper"
    if tool_name is None:
        tool_name = full.frames[len(full.frames) - 1].name
    if tool_parent is None and not full.existFrame(tool_name):
        names = ", ".join(f.name for f in full.frames if f.name != "universe")
        raise ModelError(f"URDF {urdf.name} has no frame {tool_name!r}; frames: {names}")
    frame_id = _frame_id(full, tool_parent or tool_name)
    on_path: set[int] = set()
    joint = int(full.frames[frame_id].parentJoint)
    while joint != 0:
        on_path.add(joint)
        joint = int(full.parents[joint])
    locked = tuple(j for j in range(1, full.njoints) if j not in on_path)
    q_ref = np.clip(np.zeros(full.nq), full.lowerPositionLimit, full.upperPositionLimit)
    locked_joints = tuple((str(full.names[j]), float(q_ref[full.idx_qs[j]])) for j in locked)
    if locked:
        xml = _lock_joints(xml, dict(locked_joints))
    try:
        model = pin.buildModelFromXML(xml)
    except (RuntimeError, ValueError) as exc:  # pragma: no cover - parsed once already
        raise ModelError(f"cannot load URDF {urdf}: {exc}") from exc
    if base is not None:
        for j in range(1, model.njoints):
            if model.parents[j] == 0:
                model.jointPlacements[j] = pin.SE3(base_placement) * model.jointPlacements[j]
        for f in model.frames:
            if f.parentJoint == 0 and f.name != "universe":
                f.placement = pin.SE3(base_placement) * f.placement
    if tool_parent is not None:
        _add_frame(model, tool_name, tool_parent, SO100_TOOL_TRANSLATION, SO100_TOOL_RPY)
    return (
        LoadedModel(
            name,
            urdf,
            model,
            tool_name,
            _frame_id(model, tool_name),
            locked_joints,
            dirs,
            xml,
            srdf_path,
            disabled,
        ),
        spec,
    )
