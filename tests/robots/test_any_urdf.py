"""Any URDF means any URDF: example-robot-data's arms and a hand-written URDF whose meshes are
relative paths load, solve IK (checked against Pinocchio's FK) and plan through ``lynxplan run``;
a mesh found nowhere is one line naming it, exit 2.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lynxplan.exceptions import MeshNotFoundError, ModelError
from lynxplan.mesh_paths import example_robot_data_robots, resolve_mesh
from lynxplan.robots import load_robot

_SCRIPT = Path(sys.executable).with_name("lynxplan")
LYNXPLAN = [str(_SCRIPT)] if _SCRIPT.is_file() else [sys.executable, "-m", "lynxplan.cli"]
#: FK(IK(pose)) against the pose, position [m] and rotation matrix entries.
ROUND_TRIP_POSITION = 1e-9
ROUND_TRIP_ROTATION = 1e-9
#: Revolute joints of the hand-written arm: (name, axis, offset of the joint from its parent [m]).
HANDMADE_JOINTS = (
    ("shoulder_pan", "0 0 1", "0 0 0.05"),
    ("shoulder_lift", "0 1 0", "0 0 0.10"),
    ("elbow", "0 1 0", "0 0 0.20"),
    ("wrist_roll", "0 0 1", "0 0 0.15"),
    ("wrist_pitch", "0 1 0", "0 0 0.05"),
    ("tool_roll", "0 0 1", "0 0 0.05"),
)
#: Mesh filename of each link of the hand-written arm, as its URDF writes it: relative to the
#: URDF's folder, relative to the package folder (a parent of the URDF's), ``package://`` of the
#: folder holding the URDF's folder; None: a cylinder.
HANDMADE_MESHES = {
    "base_link": "../meshes/base.stl",
    "shoulder_pan_link": "meshes/shoulder.stl",
    "shoulder_lift_link": "package://handmade_description/meshes/upper_arm.stl",
    "elbow_link": "../meshes/forearm.stl",
    "wrist_roll_link": None,
    "wrist_pitch_link": "package://handmade_description/meshes/wrist.stl",
    "tool_roll_link": None,
}
#: Box of each mesh: half sizes [m] and centre height in its link frame [m].
HANDMADE_BOXES = {
    "base.stl": ((0.05, 0.05, 0.02), 0.025),
    "shoulder.stl": ((0.025, 0.025, 0.04), 0.05),
    "upper_arm.stl": ((0.02, 0.02, 0.08), 0.10),
    "forearm.stl": ((0.018, 0.018, 0.06), 0.075),
    "wrist.stl": ((0.015, 0.015, 0.015), 0.025),
}


def write_box_stl(path: Path, half: tuple[float, float, float], centre_z: float) -> None:
    """A binary STL of a box (12 triangles, outward normals)."""
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    corners = signs * np.array(half) + np.array([0.0, 0.0, centre_z])
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    triangles = [(a, b, c) for a, b, c, d in faces] + [(a, c, d) for a, b, c, d in faces]
    record = np.zeros(
        len(triangles), dtype=[("normal", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attr", "<u2")]
    )
    points = corners[np.array(triangles)]
    record["normal"] = np.cross(points[:, 1] - points[:, 0], points[:, 2] - points[:, 0])
    record["vertices"] = points
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(
        b"box".ljust(80, b"\0") + np.uint32(len(triangles)).tobytes() + record.tobytes()
    )


def _geometry(mesh: str | None) -> str:
    if mesh is None:
        return '<geometry><cylinder radius="0.015" length="0.03"/></geometry>'
    return f'<geometry><mesh filename="{mesh}"/></geometry>'


def write_handmade_arm(root: Path) -> Path:
    """A 6R arm in ``root/handmade_description`` (urdf/arm.urdf, meshes/*.stl); its URDF."""
    package = root / "handmade_description"
    for name, (half, centre_z) in HANDMADE_BOXES.items():
        write_box_stl(package / "meshes" / name, half, centre_z)
    links = []
    for link, mesh in HANDMADE_MESHES.items():
        origin = '<origin xyz="0 0 0.02"/>' if mesh is None else ""
        geometry = _geometry(mesh)
        links.append(
            f'<link name="{link}"><visual>{origin}{geometry}</visual>'
            f"<collision>{origin}{geometry}</collision></link>"
        )
    joints = []
    parent = "base_link"
    for name, axis, xyz in HANDMADE_JOINTS:
        joints.append(
            f'<joint name="{name}" type="revolute"><parent link="{parent}"/>'
            f'<child link="{name}_link"/><origin xyz="{xyz}"/><axis xyz="{axis}"/>'
            '<limit lower="-2.8" upper="2.8" effort="10" velocity="3"/></joint>'
        )
        parent = f"{name}_link"
    tool = (
        '<link name="tool"/><joint name="tool_joint" type="fixed">'
        f'<parent link="{parent}"/><child link="tool"/><origin xyz="0 0 0.04"/></joint>'
    )
    urdf = package / "urdf" / "arm.urdf"
    urdf.parent.mkdir(parents=True, exist_ok=True)
    urdf.write_text(f'<robot name="handmade">{"".join(links)}{"".join(joints)}{tool}</robot>')
    return urdf


def _erd(relative: str) -> str:
    robots = example_robot_data_robots()
    assert robots is not None, "example-robot-data is a dependency"
    return str(robots / relative)


#: example-robot-data arms: (id, built-in name or URDF, start, goal), joint angles [deg].
ARMS = (
    ("ur5", "ur_description/urdf/ur5_robot.urdf",
     [0, -90, 90, -90, -90, 0], [30, -80, 80, -90, -90, 20]),
    ("ur10", "ur_description/urdf/ur10_robot.urdf",
     [0, -90, 90, -90, -90, 0], [-30, -100, 80, -80, -90, 0]),
    ("panda", "panda_description/urdf/panda.urdf",
     [0, -45, 0, -135, 0, 90, 45], [30, -30, 10, -120, 10, 100, 30]),
    ("so100", None, [0, 100, -90, -30, 0], [20, 90, -80, -20, 20]),
    ("so101", None, [0, -60, 60, 60, 0], [20, -50, 50, 60, 20]),
)  # fmt: skip


def _robot_source(arm_id: str, relative: str | None) -> str:
    return arm_id if relative is None else _erd(relative)


@pytest.fixture(scope="module")
def handmade(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_handmade_arm(tmp_path_factory.mktemp("any_urdf"))


def _pinocchio_tool_pose(robot: object, q: np.ndarray) -> np.ndarray:
    import pinocchio as pin

    model = robot.model  # type: ignore[attr-defined]
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    return np.asarray(data.oMf[robot.tool_frame_id].homogeneous)  # type: ignore[attr-defined]


def _check_ik_round_trips(robot: object, seed: int) -> None:
    rng = np.random.default_rng(seed)
    lower = np.maximum(robot.limits.lower, -np.pi)  # type: ignore[attr-defined]
    upper = np.minimum(robot.limits.upper, np.pi)  # type: ignore[attr-defined]
    for _ in range(3):
        q = lower + (upper - lower) * (0.2 + 0.6 * rng.random(len(lower)))
        target = _pinocchio_tool_pose(robot, q)
        result = robot.ik(target)  # type: ignore[attr-defined]
        assert result.reachable and result.selected is not None
        reached = _pinocchio_tool_pose(robot, result.q)
        np.testing.assert_allclose(reached[:3, 3], target[:3, 3], rtol=0, atol=ROUND_TRIP_POSITION)
        np.testing.assert_allclose(
            reached[:3, :3], target[:3, :3], rtol=0, atol=ROUND_TRIP_ROTATION
        )


@pytest.mark.parametrize(("arm_id", "relative", "start", "goal"), ARMS, ids=[a[0] for a in ARMS])
def test_example_robot_data_arm_loads_and_solves_ik(
    arm_id: str, relative: str | None, start: list[float], goal: list[float]
) -> None:
    robot = load_robot(_robot_source(arm_id, relative))
    assert robot.nq == len(start) == len(goal)
    # every collision mesh found (the UR5's package://example-robot-data/... included)
    assert len(robot.collision_model.geometryObjects) >= robot.nq
    meshes = [Path(g.meshPath) for g in robot.collision_mesh_model.geometryObjects]
    assert all(m.is_absolute() and m.is_file() for m in meshes if m.suffix)  # not BOX etc.
    _check_ik_round_trips(robot, seed=len(arm_id))


def test_handmade_urdf_with_relative_meshes_loads_and_solves_ik(handmade: Path) -> None:
    robot = load_robot(handmade)
    assert robot.nq == len(HANDMADE_JOINTS)
    meshes = sorted(Path(g.meshPath).name for g in robot.collision_mesh_model.geometryObjects)
    assert [m for m in meshes if m.endswith(".stl")] == sorted(HANDMADE_BOXES)
    assert len(robot.collision_model.geometryObjects) == len(HANDMADE_MESHES)
    visual = {Path(g.meshPath) for g in robot.visual_model.geometryObjects if g.meshPath}
    assert {p.name for p in visual if p.suffix == ".stl"} == set(HANDMADE_BOXES)
    assert all(p.parent == handmade.parent.parent / "meshes" for p in visual if p.suffix)
    _check_ik_round_trips(robot, seed=6)


def _write_plan(folder: Path, name: str, robot: str, start: list[float], goal: list[float]) -> Path:
    key = "urdf" if robot.endswith(".urdf") else "name"
    scenario = folder / f"{name}.yaml"
    scenario.write_text(
        f"kind: plan\nname: {name}\nunits: {{length: m, angle: deg}}\n"
        f"robot: {{{key}: {json.dumps(robot)}}}\n"
        "obstacles:\n"
        "  - {name: floor, type: box, centre: [0.0, 0.0, -0.03], size: [2.0, 2.0, 0.02]}\n"
        f"start: {start}\ngoal: {{q: {goal}}}\n"
        "planner: {seed: 0, time_limit: 10.0}\n"
        "expect: {solved: true, collision_free: true, within_limits: true}\n"
    )
    return scenario


def _run(scenario: Path, out: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*LYNXPLAN, "run", str(scenario), "--out", str(out), "--quick"],
        capture_output=True,
        text=True,
        check=False,
        cwd=scenario.parent,
        env={**os.environ, "PYTHONWARNINGS": "ignore"},
    )


def _check_plan(folder: Path, name: str, robot: str, start: list[float], goal: list[float]) -> None:
    done = _run(_write_plan(folder, name, robot, start, goal), folder / name)
    assert done.returncode == 0, done.stdout + done.stderr
    report = json.loads((folder / name / "report.json").read_text())
    metrics = report["metrics"]
    assert metrics["solved"] and metrics["collision_free"] and metrics["within_limits"]
    assert metrics["min_clearance"] > 0
    assert all(e["passed"] for e in report["expectations"])
    waypoints = np.array(report["details"]["waypoints"])
    np.testing.assert_allclose(waypoints[0], np.radians(start), rtol=0, atol=1e-12)
    np.testing.assert_allclose(waypoints[-1], np.radians(goal), rtol=0, atol=1e-12)


@pytest.mark.parametrize(("arm_id", "relative", "start", "goal"), ARMS, ids=[a[0] for a in ARMS])
def test_example_robot_data_arm_plans_through_the_cli(
    tmp_path: Path, arm_id: str, relative: str | None, start: list[float], goal: list[float]
) -> None:
    _check_plan(tmp_path, f"{arm_id}_small", _robot_source(arm_id, relative), start, goal)


def test_handmade_urdf_plans_through_the_cli(tmp_path: Path) -> None:
    urdf = write_handmade_arm(tmp_path / "robot")
    start, goal = [0, 20, 30, 0, 20, 0], [45, 10, 40, 30, 30, 10]
    _check_plan(tmp_path, "handmade_small", str(urdf), start, goal)


def test_a_missing_mesh_is_one_line_naming_it_exit_2(tmp_path: Path) -> None:
    urdf = write_handmade_arm(tmp_path / "robot")
    (urdf.parent.parent / "meshes" / "upper_arm.stl").unlink()
    scenario = _write_plan(tmp_path, "missing", str(urdf), [0] * 6, [10] * 6)
    done = _run(scenario, tmp_path / "out")
    assert done.returncode == 2, done.stdout + done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert "package://handmade_description/meshes/upper_arm.stl" in lines[0]
    assert "not found" in lines[0] and "internal error" not in lines[0]
    with pytest.raises(MeshNotFoundError, match=r"arm\.urdf: mesh package://handmade_desc"):
        _ = load_robot(urdf).collision_model


def test_package_dirs_and_ros_package_path_find_a_package_elsewhere(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    write_box_stl(tmp_path / "shared" / "parts_pkg" / "meshes" / "part.stl", (0.01,) * 3, 0.0)
    urdf = tmp_path / "arm" / "arm.urdf"
    urdf.parent.mkdir()
    filename = "package://parts_pkg/meshes/part.stl"
    urdf.write_text(
        f'<robot name="one"><link name="base"/><link name="l1"><collision>{_geometry(filename)}'
        '</collision></link><joint name="j1" type="revolute"><parent link="base"/>'
        '<child link="l1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" '
        'velocity="1"/></joint></robot>'
    )
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)
    part = tmp_path / "shared" / "parts_pkg" / "meshes" / "part.stl"
    assert resolve_mesh(filename, urdf.parent, ()) is None
    with pytest.raises(MeshNotFoundError, match="package 'parts_pkg' in package_dirs"):
        _ = load_robot(urdf).collision_model
    # an explicit package folder, or the package itself
    assert resolve_mesh(filename, urdf.parent, (str(tmp_path / "shared"),)) == part
    assert resolve_mesh(filename, None, (str(tmp_path / "shared" / "parts_pkg"),)) == part
    robot = load_robot(urdf, package_dirs=[str(tmp_path / "shared")])
    assert Path(robot.collision_mesh_model.geometryObjects[0].meshPath) == part.resolve()
    monkeypatch.setenv(
        "ROS_PACKAGE_PATH", os.pathsep.join(["/nonexistent", str(tmp_path / "shared")])
    )
    assert resolve_mesh(filename, urdf.parent, ()) == part
    monkeypatch.delenv("ROS_PACKAGE_PATH")
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path))
    (tmp_path / "share").symlink_to(tmp_path / "shared")
    assert (
        resolve_mesh(filename, urdf.parent, ())
        == tmp_path / "share" / "parts_pkg" / "meshes" / "part.stl"
    )


def test_a_copy_of_a_package_next_to_the_urdf_wins_over_example_robot_data(tmp_path: Path) -> None:
    original = Path(_erd("ur_description/urdf/ur5_robot.urdf"))
    copy = tmp_path / "ur_description" / "urdf" / "ur5_robot.urdf"
    copy.parent.mkdir(parents=True)
    copy.write_text(
        original.read_text().replace("package://example-robot-data/robots/", "package://")
    )
    mesh = "package://ur_description/meshes/ur5/collision/base.stl"
    # not in the copy's tree: the installed example-robot-data's robots folder
    assert (
        resolve_mesh(mesh, copy.parent, ())
        == original.parent.parent / "meshes/ur5/collision/base.stl"
    )
    write_box_stl(
        tmp_path / "ur_description" / "meshes" / "ur5" / "collision" / "base.stl", (0.05,) * 3, 0
    )
    assert resolve_mesh(mesh, copy.parent, ()) == (
        tmp_path / "ur_description" / "meshes" / "ur5" / "collision" / "base.stl"
    )


def test_the_srdf_next_to_the_urdf_names_the_pairs_not_checked(tmp_path: Path) -> None:
    from lynxplan.collision import CollisionWorld

    panda = load_robot(_erd("panda_description/urdf/panda.urdf"))
    assert panda.info().name == "panda.urdf"
    assert ("panda_link5", "panda_link7") in panda.disabled_collisions  # ../srdf/panda.srdf
    world = CollisionWorld(panda, (), self_collision=True)
    checked = {frozenset(world.pair_names(p)[1:]) for p in range(world.pair_count)}
    assert frozenset(("panda_link5_0", "self:panda_link7_0")) not in checked
    assert frozenset(("panda_link1_0", "self:panda_link7_0")) in checked  # not disabled
    with pytest.raises(ModelError, match=r"SRDF file not found: nowhere\.srdf"):
        load_robot(_erd("panda_description/urdf/panda.urdf"), srdf="nowhere.srdf")
    with pytest.raises(ModelError, match=r"package_dirs: .* is not a folder"):
        load_robot("so101", package_dirs=[str(tmp_path / "nowhere")])


def test_builtin_arms_of_example_robot_data_carry_their_srdf_and_plan() -> None:
    """``load_robot("ur5")`` reads example-robot-data's ``srdf/ur5.srdf`` (named unlike its URDF,
    ``ur5_robot.urdf``): without its disabled pairs the planner's conservative checker cannot
    certify a UR5 start at all."""
    import lynxplan

    ur5 = load_robot("ur5")
    assert ("shoulder_link", "upper_arm_link") in {
        tuple(sorted(p)) for p in ur5.disabled_collisions
    }
    start, goal = np.radians(ARMS[0][2]), np.radians(ARMS[0][3])
    motion = lynxplan.plan(ur5, [], start, goal, seed=0)
    assert motion.verification.collision_free
    np.testing.assert_allclose(motion.q[-1], goal, atol=1e-9)
    assert len(load_robot("panda").disabled_collisions) > 0
