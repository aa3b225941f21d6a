"""Closed-form FK and Jacobian against SPEC values, the DH product and Pinocchio."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from arm_reference import INCH, dh_frames, random_configurations
from hypothesis import given, settings
from hypothesis import strategies as st

from lynxplan.arm import forward_kinematics, tool_jacobian
from lynxplan.exceptions import NonFiniteInputError, ShapeError

PINOCCHIO_TOLERANCE = 1e-12  # [m] and [rad]: closed form vs Pinocchio
SPEC_TOLERANCE = 0.6e-4  # SPEC reference values are rounded to 4 decimals (inches)
FD_TOLERANCE = 1e-6


def test_spec_reference_pose_in_inches() -> None:
    T = forward_kinematics(np.radians([120, 60, -45, 45, 0]))
    expected = np.array(
        [[-0.25, 0.866, -0.433, -6.4608], [0.433, 0.5, 0.75, 11.1904], [0.866, 0, -0.5, 5.2009]]
    )
    T_inch = T[:3].copy()
    T_inch[:, 3] /= INCH
    np.testing.assert_allclose(T_inch, expected, atol=SPEC_TOLERANCE)
    np.testing.assert_array_equal(T[3], [0, 0, 0, 1])


def test_spec_reference_positions() -> None:
    T = forward_kinematics(np.array([1.2, 0.5, -0.8, 1, 0]))
    np.testing.assert_allclose(T[:3, 3] / INCH, [5.1694, 13.2964, -2.0041], atol=SPEC_TOLERANCE)
    home = forward_kinematics(np.zeros(5))
    np.testing.assert_allclose(home[:3, 3] / INCH, [13.125, 0, -3.375], atol=1e-12)
    np.testing.assert_allclose(home[:3, 2], [0, 0, -1], atol=1e-15)  # pointing straight down


def test_closed_form_matches_dh_product() -> None:
    rng = np.random.default_rng(1)
    q = rng.uniform(-np.pi, np.pi, size=(500, 5))
    expected = np.array([dh_frames(config)[-1] for config in q])
    np.testing.assert_allclose(forward_kinematics(q), expected, atol=1e-15)


def test_pinocchio_frames_match_closed_form_and_dh(arm) -> None:
    rng = np.random.default_rng(2)
    q = random_configurations(rng, 10_000, arm.limits.lower, arm.limits.upper)
    closed_form = forward_kinematics(q)
    frame_ids = [arm.model.getFrameId(f"dh_frame_{i}") for i in range(1, 5)]
    worst_tool = worst_dh = 0.0
    for k in range(q.shape[0]):
        pin.framesForwardKinematics(arm.model, arm.data, q[k])
        tool = arm.data.oMf[arm.tool_frame_id].homogeneous
        worst_tool = max(worst_tool, np.abs(tool - closed_form[k]).max())
        if k < 1000:
            reference = dh_frames(q[k])
            for i, frame_id in enumerate(frame_ids):
                frame = arm.data.oMf[frame_id].homogeneous
                worst_dh = max(worst_dh, np.abs(frame - reference[i]).max())
    assert worst_tool <= PINOCCHIO_TOLERANCE
    assert worst_dh <= PINOCCHIO_TOLERANCE


def test_pinocchio_jacobian_matches_closed_form(arm) -> None:
    rng = np.random.default_rng(3)
    q = random_configurations(rng, 10_000, arm.limits.lower, arm.limits.upper)
    closed_form = tool_jacobian(q)
    frame = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    worst = 0.0
    for k in range(q.shape[0]):
        J = pin.computeFrameJacobian(arm.model, arm.data, q[k], arm.tool_frame_id, frame)
        worst = max(worst, np.abs(J - closed_form[k]).max())
    assert worst <= PINOCCHIO_TOLERANCE


def test_model_accessors_agree_with_closed_form(arm) -> None:
    q = np.radians([100, 40, -70, 60, 30])
    np.testing.assert_allclose(arm.frame_placement(q), arm.fk(q), atol=PINOCCHIO_TOLERANCE)
    np.testing.assert_allclose(arm.frame_jacobian(q), arm.jacobian(q), atol=PINOCCHIO_TOLERANCE)
    dh4 = dh_frames(q)[3]
    np.testing.assert_allclose(arm.frame_placement(q, "dh_frame_4"), dh4, atol=1e-12)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-np.pi, np.pi), min_size=5, max_size=5))
def test_jacobian_matches_finite_differences(q_list: list[float]) -> None:
    q = np.array(q_list)
    J = tool_jacobian(q)
    step = 1e-6
    for j in range(5):
        dq = np.zeros(5)
        dq[j] = step
        plus, minus = forward_kinematics(q + dq), forward_kinematics(q - dq)
        linear = (plus[:3, 3] - minus[:3, 3]) / (2 * step)
        dR = (plus[:3, :3] - minus[:3, :3]) / (2 * step) @ forward_kinematics(q)[:3, :3].T
        angular = np.array([dR[2, 1], dR[0, 2], dR[1, 0]])
        np.testing.assert_allclose(J[:3, j], linear, atol=FD_TOLERANCE)
        np.testing.assert_allclose(J[3:, j], angular, atol=FD_TOLERANCE)


def test_batch_and_single_shapes() -> None:
    q = np.zeros((3, 5))
    assert forward_kinematics(q).shape == (3, 4, 4)
    assert forward_kinematics(q[0]).shape == (4, 4)
    assert tool_jacobian(q).shape == (3, 6, 5)
    assert tool_jacobian(q[0]).shape == (6, 5)


@pytest.mark.parametrize("bad", [np.zeros(4), np.zeros((2, 6)), np.zeros((2, 2, 5))])
def test_wrong_shape_is_rejected(bad: np.ndarray) -> None:
    with pytest.raises(ShapeError, match=r"q must have shape \(5,\) or \(N, 5\)\. Got"):
        forward_kinematics(bad)


def test_nan_is_rejected() -> None:
    with pytest.raises(NonFiniteInputError, match="q contains NaN"):
        tool_jacobian(np.array([0, np.nan, 0, 0, 0]))


def test_fk_into_preallocated_output() -> None:
    q = np.random.default_rng(9).uniform(-3, 3, size=(7, 5))
    out = np.empty((7, 4, 4))
    assert forward_kinematics(q, out=out) is out
    np.testing.assert_array_equal(out, forward_kinematics(q))
    with pytest.raises(ShapeError, match="out must have shape"):
        forward_kinematics(q, out=np.empty((6, 4, 4)))


def test_top_level_load_arm_is_the_shared_default() -> None:
    import lynxplan
    from lynxplan.arm import load_arm

    assert lynxplan.load_arm() is load_arm()
    np.testing.assert_allclose(lynxplan.load_arm().fk(np.zeros(5))[:3, 3], [0.333375, 0, -0.085725])


def test_default_limits_match_the_urdf(arm) -> None:
    """JointLimits() (used where no arm is at hand) must not drift from the URDF."""
    from lynxplan.arm import JointLimits

    defaults = JointLimits()
    np.testing.assert_allclose(defaults.position, arm.limits.position, atol=1e-12)
    np.testing.assert_allclose(defaults.velocity, arm.limits.velocity, atol=0)


def test_single_pose_formula_matches_the_batch_kernel() -> None:
    from lynxplan.arm.closed_form import tool_pose
    from lynxplan.arm.kinematics import forward_kinematics

    rng = np.random.default_rng(42)
    for q in rng.uniform(-3.0, 3.0, (50, 5)):
        np.testing.assert_allclose(tool_pose(q), forward_kinematics(q), atol=1e-15)


def test_fk_command_starts_without_numba() -> None:
    import subprocess
    import sys

    code = (
        "import sys, contextlib, io\n"
        "from lynxplan.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    main(['fk', '0', '0.1', '0.2', '0.3', '0.4'])\n"
        "print(sorted(m for m in ('numba', 'matplotlib', 'meshcat', 'toppra', 'pydantic', 'scipy')"
        " if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]", out.stdout
