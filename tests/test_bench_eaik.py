"""EAIK as a peer of ``lynxplan bench robots``: the chain it is given is lynxplan's, and its
answers, as the bench judges them, are right (checked with lynxplan's own FK). Not its speed."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from lynxplan.bench import PEER_NOT_INSTALLED, eaik_peer, verdict
from lynxplan.robots import load_robot
from tests.robots.urdf_factory import random_family_urdf, tilted_urdf

#: lynxplan's FK of the zero configuration against the chain's sums [m] and rotation entries.
CHAIN_TOLERANCE = 1e-12
#: lynxplan's FK of EAIK's answer against the target pose [m] and rotation entries.
ANSWER_TOLERANCE = 1e-9
#: The start configuration among EAIK's solutions [rad] (2-pi wrapped).
START_TOLERANCE = 1e-6


@pytest.mark.parametrize("name", ["al5", "so100", "so101"])
def test_the_chain_is_lynxplans(name: str) -> None:
    """The offsets P add up to the tool point and R6T is the tool's orientation, at q = 0, by
    lynxplan's FK; each axis H is a unit vector through the joint's origin."""
    robot = load_robot(name)
    axes, offsets, tool = eaik_peer.chain_description(robot)
    zero = robot.fk(np.zeros(robot.nq))
    assert axes.shape == (robot.nq, 3) and offsets.shape == (robot.nq + 1, 3)
    np.testing.assert_allclose(np.linalg.norm(axes, axis=1), 1.0, rtol=0, atol=1e-15)
    np.testing.assert_allclose(offsets.sum(axis=0), zero[:3, 3], rtol=0, atol=CHAIN_TOLERANCE)
    np.testing.assert_allclose(tool, zero[:3, :3], rtol=0, atol=CHAIN_TOLERANCE)


@pytest.mark.parametrize("name", ["al5", "so100", "so101"])
def test_eaik_solves_lynxplans_poses(name: str) -> None:
    """Every random full pose solved; the answer the bench counts reaches the pose by lynxplan's
    FK (not Pinocchio's, which the bench uses); the start configuration is among the answers."""
    if eaik_peer.eaik_module() is None:
        pytest.skip("eaik is not installed (pip install eaik, in the [peers] extra)")
    robot = load_robot(name)
    q = robot.random_configurations(200, seed=11)
    poses = robot.fk(q)
    answers = eaik_peer.solve(robot, poses)
    assert answers.solved.all(), np.flatnonzero(~answers.solved)
    assert answers.position_error.max() <= eaik_peer.POSITION_TOLERANCE
    assert answers.orientation_error.max() <= eaik_peer.ORIENTATION_TOLERANCE
    for start, target, found in zip(q, poses, answers.solutions, strict=True):
        reached = robot.fk(found)
        gap = np.abs(reached - target).max(axis=(1, 2))
        assert gap.min() <= ANSWER_TOLERANCE
        turn = np.abs(found - start) % (2 * np.pi)
        turn = np.minimum(turn, 2 * np.pi - turn).max(axis=1)
        assert turn.min() <= START_TOLERANCE, (start, found)


def test_the_bench_figures_of_eaik() -> None:
    """Success 100 %, an error within the tolerance, a finite time, and the speed-up judged
    against its target (the value itself depends on the machine)."""
    if eaik_peer.eaik_module() is None:
        pytest.skip("eaik is not installed (pip install eaik, in the [peers] extra)")
    robot = load_robot("so101")
    poses = robot.fk(robot.random_configurations(20, seed=4))
    rows = {f.name: f for f in eaik_peer.figures(robot, poses, ours=1e-6, target=">= 5")}
    success = next(f for n, f in rows.items() if "success" in n)
    assert success.value == 100.0
    worst = next(f for n, f in rows.items() if "worst position error" in n)
    assert worst.value <= eaik_peer.POSITION_TOLERANCE
    ratio = rows["so101 lynxplan batch speed-up over eaik (same poses)"]
    assert np.isfinite(ratio.value) and ratio.value > 0 and ratio.target == ">= 5"
    assert verdict(ratio) == ("ok" if ratio.value >= 5 else "MISSED")


def test_a_chain_eaik_cannot_decompose_is_said(tmp_path: Path) -> None:
    """A 5R family arm whose pitch axes are not parallel (joint 3 tilted by 0.3 rad): EAIK knows
    no decomposition; the bench says so in one figure (0 % solved), not a failure."""
    if eaik_peer.eaik_module() is None:
        pytest.skip("eaik is not installed (pip install eaik, in the [peers] extra)")
    path = tmp_path / "arm.urdf"
    path.write_text(random_family_urdf(np.random.default_rng(0), off_axis_tool=False))
    robot = load_robot(str(tilted_urdf(path, 0.3, "j3")))
    with pytest.raises(eaik_peer.UnsupportedChainError, match="no known subproblem"):
        eaik_peer.eaik_robot(robot)
    figures = eaik_peer.figures(robot, robot.fk(robot.random_configurations(3)), ours=1e-6)
    assert len(figures) == 1 and figures[0].value == 0.0 and verdict(figures[0]) == ""
    assert "cannot solve this chain" in figures[0].name
    straight = load_robot(str(path))  # the same arm untilted: solved
    assert eaik_peer.solve(straight, straight.fk(straight.random_configurations(5))).solved.all()


def test_eaik_not_installed_is_said(monkeypatch: pytest.MonkeyPatch) -> None:
    """Without eaik (its modules unimportable), one 'peer not installed' figure."""
    for module in ("eaik", "eaik.pybindings", "eaik.pybindings.EAIK"):
        monkeypatch.setitem(sys.modules, module, None)
    robot = load_robot("al5")
    figures = eaik_peer.figures(robot, robot.fk(np.zeros((1, robot.nq))), ours=1e-6)
    assert [verdict(f) for f in figures] == [PEER_NOT_INSTALLED]
    assert "pip install eaik" in figures[0].skipped
