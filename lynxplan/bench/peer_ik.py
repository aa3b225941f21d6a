"""Standalone peer-IK runner, executed by a peer's own virtual environment (never lynxplan's).

    python peer_ik.py PEER URDF TOOL_FRAME POSES.npy OUT.json

Solves each pose (N, 4, 4) from the zero configuration with the peer and writes
``{"peer", "version", "success", "median_us", "count"}``. A solve succeeds when the reached tool
pose is within 1e-6 m and 1e-5 rad of the target, by the peer's own FK: Pinocchio's for pink and
placo, ikpy's, MuJoCo's for mink (ikpy's and MuJoCo's agree with lynxplan's FK of SO-100/101 to
1e-15). Imports nothing from lynxplan: the peer venvs do not have it.
"""

from __future__ import annotations

import json
import sys
import time
from importlib import metadata
from typing import Any

import numpy as np

POSITION_TOLERANCE = 1e-6
ORIENTATION_TOLERANCE = 1e-5


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    m = a.T @ b
    return float(np.arccos(np.clip(0.5 * (np.trace(m) - 1.0), -1.0, 1.0)))


def _ok(reached: np.ndarray, target: np.ndarray) -> bool:
    return (
        float(np.linalg.norm(reached[:3, 3] - target[:3, 3])) <= POSITION_TOLERANCE
        and _angle(reached[:3, :3], target[:3, :3]) <= ORIENTATION_TOLERANCE
    )


def run_pink(urdf: str, tool: str, poses: np.ndarray) -> tuple[list[bool], list[float]]:
    import pink
    import pinocchio as pin
    from pink.tasks import FrameTask

    model = pin.buildModelFromUrdf(urdf)
    data = model.createData()
    ok, times = [], []
    for target in poses:
        configuration = pink.Configuration(model, data, pin.neutral(model))
        task = FrameTask(tool, position_cost=1.0, orientation_cost=1.0)
        task.set_target(pin.SE3(target[:3, :3], target[:3, 3]))
        start = time.perf_counter()
        for _ in range(200):
            velocity = pink.solve_ik(configuration, [task], 0.05, solver="daqp")
            configuration.integrate_inplace(velocity, 0.05)
            reached = configuration.get_transform_frame_to_world(tool).homogeneous
            if _ok(reached, target):
                break
        times.append(time.perf_counter() - start)
        ok.append(_ok(configuration.get_transform_frame_to_world(tool).homogeneous, target))
    return ok, times


def run_placo(urdf: str, tool: str, poses: np.ndarray) -> tuple[list[bool], list[float]]:
    """placo's KinematicsSolver (QP, soft frame task, joint limits), iterated to convergence."""
    import tempfile

    import placo

    with tempfile.NamedTemporaryFile("w", suffix=".urdf", delete=False) as stripped:
        stripped.write(_urdf_without_shapes(urdf))
    robot = placo.RobotWrapper(stripped.name, placo.Flags.ignore_collisions)
    solver = placo.KinematicsSolver(robot)
    solver.mask_fbase(True)
    task = solver.add_frame_task(tool, np.eye(4))
    task.configure(tool, "soft", 1.0, 1.0)
    ok, times = [], []
    for target in poses:
        for name in robot.joint_names():
            robot.set_joint(name, 0.0)
        robot.update_kinematics()
        task.T_world_frame = target
        start = time.perf_counter()
        for _ in range(200):
            solver.solve(True)
            robot.update_kinematics()
            if _ok(robot.get_T_world_frame(tool), target):
                break
        times.append(time.perf_counter() - start)
        ok.append(_ok(robot.get_T_world_frame(tool), target))
    return ok, times


def _urdf_without_shapes(urdf: str) -> str:
    """The URDF's text without <visual>/<collision>: IK needs no geometry, and the peers cannot
    resolve ``package://`` mesh URIs."""
    import re

    with open(urdf) as handle:
        return re.sub(r"<(visual|collision)\b.*?</\1>", "", handle.read(), flags=re.S)


def _mujoco_model(urdf: str) -> Any:
    """The URDF through MuJoCo's URDF compiler, every link kept as a body.

    The compiler fuses links on fixed joints into their parents by default (``fusestatic``),
    which removes tool links such as ``gripper_frame_link``: a ``<mujoco><compiler/>``
    element turns that off. Links without inertia get a tiny bound (IK ignores mass).
    """
    import xml.etree.ElementTree as ET

    import mujoco

    root = ET.fromstring(_urdf_without_shapes(urdf))
    extension = root.find("mujoco")
    if extension is None:
        extension = ET.SubElement(root, "mujoco")
    compiler = extension.find("compiler")
    if compiler is None:
        compiler = ET.SubElement(extension, "compiler")
    compiler.set("fusestatic", "false")
    compiler.set("boundmass", "1e-6")
    compiler.set("boundinertia", "1e-9")
    return mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))


def run_mink(urdf: str, tool: str, poses: np.ndarray) -> tuple[list[bool], list[float]]:
    """mink's differential IK (FrameTask on the tool link's body, daqp, configuration limits),
    integrated like pink's; the reached pose is MuJoCo's FK of that body."""
    import mink

    model = _mujoco_model(urdf)
    configuration = mink.Configuration(model)
    task = mink.FrameTask(tool, "body", position_cost=1.0, orientation_cost=1.0)
    zero = np.zeros(model.nq)
    ok, times = [], []
    for target in poses:
        configuration.update(zero)
        task.set_target(mink.SE3.from_matrix(target))
        start = time.perf_counter()
        for _ in range(200):
            velocity = mink.solve_ik(configuration, [task], 0.05, solver="daqp")
            configuration.integrate_inplace(velocity, 0.05)
            reached = configuration.get_transform_frame_to_world(tool, "body").as_matrix()
            if _ok(reached, target):
                break
        times.append(time.perf_counter() - start)
        ok.append(_ok(configuration.get_transform_frame_to_world(tool, "body").as_matrix(), target))
    return ok, times


def _path_to(urdf: str, tool: str) -> list[str]:
    """The URDF elements from the root link to the link ``tool``: link, joint, link, ... tool.

    ikpy follows the first child joint of a link where the path is not given, which on a link
    with two children (a gripper with a jaw and a tool link) may miss the tool."""
    import xml.etree.ElementTree as ET

    tree = ET.parse(urdf).getroot()
    parent_joint = {
        child.get("link"): joint
        for joint in tree.iter("joint")
        if (child := joint.find("child")) is not None
    }
    path = [tool]
    while path[0] in parent_joint:
        joint = parent_joint[path[0]]
        parent = joint.find("parent")
        path[:0] = [str(parent.get("link") if parent is not None else ""), str(joint.get("name"))]
    return path


def run_ikpy(urdf: str, tool: str, poses: np.ndarray) -> tuple[list[bool], list[float]]:
    from ikpy.chain import Chain

    base = _path_to(urdf, tool)
    chain = Chain.from_urdf_file(urdf, last_link_vector=None, base_elements=base)
    names = [link.name for link in chain.links]
    mask = [link.joint_type != "fixed" for link in chain.links]
    chain = Chain.from_urdf_file(urdf, base_elements=base, active_links_mask=mask)
    ok, times = [], []
    for target in poses:
        start = time.perf_counter()
        q = chain.inverse_kinematics(
            target[:3, 3],
            target[:3, :3],
            orientation_mode="all",
            initial_position=[0.0] * len(names),
        )
        times.append(time.perf_counter() - start)
        ok.append(_ok(chain.forward_kinematics(q), target))
    return ok, times


def main() -> None:
    peer, urdf, tool, poses_path, out = sys.argv[1:6]
    poses = np.load(poses_path)
    runner = {"pink": run_pink, "ikpy": run_ikpy, "placo": run_placo, "mink": run_mink}[peer]
    ok, times = runner(urdf, tool, poses)
    package = {"pink": "pin-pink", "ikpy": "ikpy", "placo": "placo", "mink": "mink"}[peer]
    with open(out, "w") as handle:
        json.dump(
            {
                "peer": peer,
                "version": metadata.version(package),
                "success": float(np.mean(ok)),
                "median_us": float(np.median(times) * 1e6),
                "count": len(ok),
            },
            handle,
        )


if __name__ == "__main__":
    main()
