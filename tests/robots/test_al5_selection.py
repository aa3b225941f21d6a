"""The AL5 as a Robot carries the report's branch rule (SPEC Part 1) as its own selection
policy: ``load_robot("al5").ik(..., select="report")`` selects the branch ``lynxplan.arm``
selects; other robots offer only "nearest" and say so."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lynxplan.arm import load_arm
from lynxplan.cli import main
from lynxplan.exceptions import TargetError, UnreachablePoseError
from lynxplan.robots import load_robot


def _branch(result: object) -> str | None:
    selected = result.selected  # type: ignore[attr-defined]
    return None if selected is None else str(result.solutions[selected].branch)  # type: ignore[attr-defined]


def test_the_al5_robot_selects_the_branch_of_the_report_rule_as_lynxplan_arm() -> None:
    """400 poses: FK of random configurations over twice the joint ranges (many branches
    outside the limits, some poses with none within them), a third moved off the reachable
    orientations; the same branch selected (or none) by the Robot and by ``lynxplan.arm``, and
    the selected branch obeys the rule (q2 >= 0, q3 <= 0, within the limits). Away from the
    limits: within the snap tolerance of one, a Robot keeps only branches that still reach the
    pose after the snap (the AL5's package keeps the snapped branch)."""
    arm, robot = load_arm(), load_robot("al5")
    assert robot.selection_rules == ("nearest", "report")
    rng = np.random.default_rng(17)
    middle = 0.5 * (arm.limits.lower + arm.limits.upper)
    half = arm.limits.upper - arm.limits.lower
    q = middle + rng.uniform(-1.0, 1.0, (400, 5)) * half
    poses = arm.fk(q)
    poses[::3, :3, 3] += rng.normal(0.0, 0.01, (len(poses[::3]), 3))
    compared = none = 0
    for pose in poses:
        try:
            expected = _branch(arm.ik(pose, select="report"))
        except UnreachablePoseError:
            assert not robot.ik(pose, select="report").reachable
            continue
        mine = robot.ik(pose, select="report")
        assert _branch(mine) == expected
        compared += 1
        if mine.selected is None:
            none += 1
            continue
        chosen = mine.solutions[mine.selected]
        assert chosen.within_limits and chosen.q[1] >= 0.0 and chosen.q[2] <= 0.0
        assert mine.orientation_residual == chosen.orientation_error
        assert not any(  # the first such branch, in slot order
            s.within_limits and s.q[1] >= 0.0 and s.q[2] <= 0.0
            for s in mine.solutions[: mine.selected]
        )
    assert compared >= 300 and 0 < none < compared


def test_the_report_rule_takes_the_first_qualifying_branch_that_reaches() -> None:
    """The rule on constructed branches (the AL5's own limits never leave two to choose from:
    at most one branch of a pose is within them): the first branch within the limits that
    reaches the target with q2 >= 0 and q3 <= 0, in slot order, not the nearest."""
    from lynxplan.branches import IkResult, IkSolution
    from lynxplan.robots.selection import by_report_rule

    def branch(name: str, q2: float, q3: float, within: bool, miss: float) -> IkSolution:
        error = 0.01 * (ord(name) - ord("a") + 1)  # a: 0.01 rad ... f: 0.06 rad
        return IkSolution(np.array([0.1, q2, q3, 0.2, 0.0]), name, within, miss, error)

    solutions = (
        branch("a", 0.5, -0.5, False, 0.0),  # outside the limits
        branch("b", -0.1, -0.5, True, 0.0),  # q2 < 0
        branch("c", 0.5, 0.2, True, 0.0),  # q3 > 0
        branch("d", 0.7, -0.5, True, 1e-3),  # misses the target
        branch("e", 0.6, -0.4, True, 0.0),  # the report's
        branch("f", 0.4, -0.3, True, 0.0),
    )
    nearest = IkResult(solutions, 5, True, 0.0, 0.004, "test")
    chosen = by_report_rule(nearest)
    assert (chosen.selected, chosen.orientation_residual) == (4, 0.05)
    none = by_report_rule(IkResult(solutions[:4], 1, True, 0.0, 0.0, "test"))
    assert none.selected is None and none.orientation_residual == 0.01  # the best branch's


def test_nearest_stays_the_default_and_other_robots_offer_only_nearest() -> None:
    robot = load_robot("al5")
    pose = robot.fk(np.radians([30.0, 60.0, -45.0, 45.0, 10.0]))
    reference = np.radians([30.0, 60.0, -45.0, 45.0, 10.0])
    assert (
        robot.ik(pose, q_reference=reference).selected
        == robot.ik(pose, q_reference=reference, select="nearest").selected
    )
    so101 = load_robot("so101")
    assert so101.selection_rules == ("nearest",)
    with pytest.raises(TargetError, match=r"so101 offers 'nearest'\. Got: 'report'"):
        so101.ik(pose, select="report")
    with pytest.raises(TargetError, match="al5 offers 'nearest', 'report'"):
        robot.ik(pose, select="first")


def test_the_command_line_passes_select_to_the_robot(capsys: pytest.CaptureFixture[str]) -> None:
    """``lynxplan ik --robot al5 ... --select report`` answers by the rule; for the SO-101 it is
    a one-line error with exit 2 (it was ignored)."""
    argv = ["ik", "--robot", "al5", "--position", "0.2", "0", "0.1", "--pitch", "60", "--deg"]
    assert main([*argv, "--select", "report", "--json", "--all"]) == 0
    answer = json.loads(capsys.readouterr().out)
    chosen = answer["solutions"][answer["selected"]]
    assert chosen["q"][1] >= 0.0 and chosen["q"][2] <= 0.0 and chosen["within_limits"]
    argv[2] = "so101"
    assert main([*argv, "--select", "report"]) == 2
    err = capsys.readouterr().err
    assert err.strip().count("\n") == 0 and "so101 offers 'nearest'" in err
