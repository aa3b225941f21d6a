"""Family recognition on random URDFs, URDF conventions, unreachable targets, errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lynxplan.exceptions import ModelError, ShapeError, TargetError, UnknownRobotError
from lynxplan.robots import load_robot
from tests.robots.test_round_trips import round_trip
from tests.robots.urdf_factory import write_random_family_urdfs

CI_URDFS = 30
FULL_URDFS = 100


def _check_random_urdfs(folder: Path, count: int, seed: int, trips: int) -> None:
    for path in write_random_family_urdfs(folder, count, seed):
        robot = load_robot(path, tool="tool")
        assert robot.family is not None, (path.name, robot.family_reason)
        assert robot.family.exact
        round_trip(robot, trips, seed=7)


def test_random_family_urdfs_ci(tmp_path: Path) -> None:
    _check_random_urdfs(tmp_path, CI_URDFS, seed=2024, trips=300)


@pytest.mark.slow
def test_random_family_urdfs_full(tmp_path: Path) -> None:
    _check_random_urdfs(tmp_path, FULL_URDFS, seed=4048, trips=2_000)


def test_random_urdfs_cover_the_conventions(tmp_path: Path) -> None:
    robots = [load_robot(p, tool="tool") for p in write_random_family_urdfs(tmp_path, 12, 5)]
    families = [r.family for r in robots if r.family is not None]
    assert len(families) == 12
    assert {s for f in families for s in f.signs} == {-1, 1}  # both axis signs
    assert any(not f.tool_on_roll_axis for f in families)  # off-axis tools
    assert any(f.tool_on_roll_axis for f in families)
    assert any(abs(f.lateral_offset) > 1e-3 for f in families)


ARM = """<?xml version="1.0"?>
<robot name="conv">
  <link name="l0"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="l4"/>
  <link name="l5"/><link name="tool"/>
  <joint name="j1" type="revolute"><parent link="l0"/><child link="l1"/>
    <origin xyz="0 0 0.05" rpy="0 0 {z1}"/><axis xyz="0 0 {s1}"/>
    <limit lower="{l1}" upper="{u1}" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.01 0.002 0.03" rpy="0 {z2} 0"/><axis xyz="0 {s2} 0"/>
    <limit lower="{l2}" upper="{u2}" effort="1" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/>
    <origin xyz="{x3} 0.01 0" rpy="0 {z3} 0"/><axis xyz="0 {s3} 0"/>
    <limit lower="{l3}" upper="{u3}" effort="1" velocity="1"/></joint>
  <joint name="j4" type="revolute"><parent link="l3"/><child link="l4"/>
    <origin xyz="{x4} 0 0.004" rpy="0 {z4} 0"/><axis xyz="0 {s4} 0"/>
    <limit lower="{l4}" upper="{u4}" effort="1" velocity="1"/></joint>
  <joint name="j5" type="revolute"><parent link="l4"/><child link="l5"/>
    <origin xyz="0.03 0 0" rpy="{z5} 0 0"/><axis xyz="{s5} 0 0"/>
    <limit lower="{l5}" upper="{u5}" effort="1" velocity="1"/></joint>
  <joint name="tj" type="fixed"><parent link="l5"/><child link="tool"/>
    <origin xyz="0.05 0.006 -0.004" rpy="0.1 0.2 0.3"/></joint>
</robot>
"""


def _write(path: Path, signs: tuple[int, ...], zeros: tuple[float, ...]) -> Path:
    """The same physical arm with joint i's axis flipped (signs[i] = -1) and its zero moved by
    zeros[i] (a built-in rotation about its own axis): q_i' = s_i (q_i - z_i)."""
    z = [repr(float(v)) for v in zeros]
    signs = tuple(int(v) for v in signs)
    # the same physical range: base limits [-3, 3] mapped through q' = s (q - z)
    ends = [sorted((s * (-3.0 - zi), s * (3.0 - zi))) for s, zi in zip(signs, zeros, strict=True)]
    limits = {f"l{i + 1}": repr(float(e[0])) for i, e in enumerate(ends)}
    limits.update({f"u{i + 1}": repr(float(e[1])) for i, e in enumerate(ends)})
    text = ARM.format(
        **limits,
        s1=signs[0],
        s2=signs[1],
        s3=signs[2],
        s4=signs[3],
        s5=signs[4],
        z1=z[0],
        z2=z[1],
        z3=z[2],
        z4=z[3],
        z5=z[4],
        x3="0.12",
        x4="0.1",
    )
    path.write_text(text)
    return path


def test_convention_flipped_axes_and_shifted_zeros(tmp_path: Path) -> None:
    base = load_robot(_write(tmp_path / "a.urdf", (1, 1, 1, 1, 1), (0, 0, 0, 0, 0)), tool="tool")
    signs = np.array([-1, 1, -1, -1, -1])
    zeros = np.array([0.4, 0.3, -0.2, 0.5, 0.7])
    other = load_robot(_write(tmp_path / "b.urdf", tuple(signs), tuple(zeros)), tool="tool")
    assert base.family is not None
    assert other.family is not None
    assert other.family.signs != base.family.signs
    q = np.random.default_rng(0).uniform(-2, 2, size=(200, 5))
    q_other = signs * (q - zeros)
    np.testing.assert_allclose(other.fk(q_other), base.fk(q), atol=1e-12)
    # the same solutions, modulo the convention
    for pose in base.fk(q[:30]):
        theirs = base.ik(pose)
        ours = other.ik(pose)
        mapped = np.array([signs * (s.q - zeros) for s in theirs.solutions])
        assert len(ours.solutions) == len(theirs.solutions)
        for s in ours.solutions:
            gap = np.abs((mapped - s.q + np.pi) % (2 * np.pi) - np.pi).max(axis=1)
            assert gap.min() < 1e-9


def test_unreachable_target_gives_nearest_solution() -> None:
    robot = load_robot("so101")
    far = np.eye(4)
    far[:3, 3] = [2.0, 0.3, 0.1]
    batch = robot.ik_batch(np.stack([far, robot.fk(np.zeros(5))]))
    assert not batch.reachable[0]
    assert batch.reachable[1]
    reach = np.linalg.norm(robot.workspace(20_000)[:, :2] - 0.0, axis=1).max()
    assert batch.distance[0] > 2.0 - 0.5  # arm reach is below 0.5 m
    single = robot.ik(far)
    assert not single.reachable
    assert single.distance == pytest.approx(batch.distance[0])
    best = min(single.solutions, key=lambda s: s.position_error)
    np.testing.assert_allclose(
        np.linalg.norm(robot.fk(best.q)[:3, 3] - far[:3, 3]), single.distance, atol=1e-12
    )
    assert reach < 0.5


def test_track_is_continuous_and_flags_jumps() -> None:
    robot = load_robot("so101")
    q0 = np.array([0.2, -0.3, 0.6, 0.4, 0.1])
    q1 = np.array([0.6, 0.2, 0.2, 0.7, -0.3])
    path = q0 + np.linspace(0, 1, 60)[:, None] * (q1 - q0)
    track = robot.ik_track(robot.fk(path), q0)
    assert track.continuous
    np.testing.assert_allclose(track.q, path, atol=1e-9)
    assert track.max_step < 0.05
    # the same targets from the back side: the first step is a big flagged jump
    back = q0.copy()
    back[0] += np.pi - 0.2
    flipped = robot.ik_track(robot.fk(path), np.clip(back, *robot.limits.position.T))
    assert flipped.jumps
    assert flipped.jumps[0].index == 0
    assert flipped.jumps[0].size > 0.5


def test_errors() -> None:
    with pytest.raises(UnknownRobotError, match="unknown robot 'nope'"):
        load_robot("nope")
    with pytest.raises(ModelError, match="no frame 'missing'"):
        load_robot("so101", tool="missing")
    robot = load_robot("so101")
    with pytest.raises(ShapeError, match="pose must have shape"):
        robot.ik(np.eye(3))
    with pytest.raises(TargetError, match="approach direction must be a non-zero"):
        robot.ik(position=[0.2, 0, 0.1], approach=[0, 0, 0])
    with pytest.raises(TargetError, match="needs an approach direction or a pitch"):
        robot.ik(position=[0.2, 0, 0.1])
    with pytest.raises(ShapeError, match="q must have shape"):
        robot.fk(np.zeros(4))


def test_so101_info_and_locked_jaw() -> None:
    robot = load_robot("so101")
    info = robot.info()
    assert info.family == "yaw-pitch-pitch-pitch-roll"
    assert [j.name for j in info.joints] == [
        "shoulder_pan",
        "shoulder_lift",
        "elbow_flex",
        "wrist_flex",
        "wrist_roll",
    ]
    assert info.locked_joints == (("gripper", 0.0),)
    assert info.tool_frame == "gripper_frame_link"
    assert "root search" in info.ik_solver


def test_so100_tool_between_the_jaws() -> None:
    robot = load_robot("so100")
    assert robot.family is not None
    assert robot.family.tool_on_roll_axis
    # the tool is 0.1014 m along the roll axis from the wrist_roll joint
    import pinocchio as pin

    pin.forwardKinematics(robot.model, robot.data, np.zeros(5))
    pin.updateFramePlacements(robot.model, robot.data)
    wrist = robot.data.oMi[5].translation
    assert np.linalg.norm(robot.fk(np.zeros(5))[:3, 3] - wrist) == pytest.approx(0.1014)
    other = load_robot("so100", tool="jaw")
    assert other.tool_frame == "jaw"
