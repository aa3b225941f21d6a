"""Peer: placo driven frame by frame as LeRobot drives it (``lerobot.model.kinematics``).

    python placo_track.py OUT.json < problem.json

LeRobot 0.4.4's ``RobotKinematics.inverse_kinematics`` (the IK of its end-effector processors,
``InverseKinematicsEEToJoints``) does, per frame: set the joints to the current ones (the
observation, or the previous solution), set the frame task's target pose, configure it
``"soft"`` with position weight 1.0 and orientation weight 0.01, one ``solver.solve(True)``,
read the joints (no ``update_kinematics`` between setting the joints and solving: the solve
linearises where the kinematics were last updated; ``update_before_solve`` adds that update, as
a variant). The solver is ``placo.KinematicsSolver`` with the floating base masked and
placo's defaults otherwise (joint limits on, no velocity limits). This script does the same for
every frame of every stream, the previous frame's solution standing for the observation (an arm
that follows its commands exactly), and writes the joint angles and placo's own FK of them.

Input (JSON on stdin): ``urdf`` (a path; no meshes needed), ``tool`` (frame name), ``joints``
(names, lynxplan's order), ``position_weight``, ``orientation_weight``, ``streams``: a list of
``{"start": (n,), "poses": (N, 4, 4)}``. Imports nothing from lynxplan (the peer venv lacks it).
"""

from __future__ import annotations

import json
import sys
from importlib import metadata
from typing import Any

import numpy as np


def track(spec: dict[str, Any]) -> dict[str, Any]:
    import placo

    robot = placo.RobotWrapper(spec["urdf"], placo.Flags.ignore_collisions)
    solver = placo.KinematicsSolver(robot)
    solver.mask_fbase(True)
    tool, joints = spec["tool"], spec["joints"]
    task = solver.add_frame_task(tool, np.eye(4))
    streams = []
    for stream in spec["streams"]:
        current = np.asarray(stream["start"], dtype=float)
        q, reached = [], []
        for pose in stream["poses"]:
            for name, value in zip(joints, current, strict=True):
                robot.set_joint(name, float(value))
            if spec.get("update_before_solve"):  # not in LeRobot: linearise at the joints set
                robot.update_kinematics()
            task.T_world_frame = np.asarray(pose, dtype=float)
            task.configure(tool, "soft", spec["position_weight"], spec["orientation_weight"])
            solver.solve(True)
            robot.update_kinematics()
            current = np.array([robot.get_joint(name) for name in joints])
            q.append(current.tolist())
            reached.append(np.asarray(robot.get_T_world_frame(tool)).tolist())
        streams.append({"q": q, "fk": reached})
    return {"peer": "placo", "version": metadata.version("placo"), "streams": streams}


def main() -> None:
    spec = json.load(sys.stdin)
    with open(sys.argv[1], "w") as out:
        json.dump(track(spec), out)


if __name__ == "__main__":
    main()
