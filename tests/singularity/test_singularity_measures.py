"""Manipulability, its gradient, condition number and the singular configurations of the arm."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from lynxplan.arm import Arm
from lynxplan.exceptions import InputError, ShapeError, TaskError
from lynxplan.singularity import (
    Singularity,
    condition_number,
    extended_jacobian,
    make_task,
    manipulability,
    manipulability_and_gradient,
    manipulability_gradient,
    near_singularities,
    nearest_singularity,
    singular_conditions,
    singular_values,
    singularity_distances,
    task_jacobian,
    task_jacobian_derivative,
)
from lynxplan.singularity.classify import max_manipulability

#: Closed form vs Pinocchio (both exact): floating-point noise only.
EXACT_ATOL = 1e-12
#: Central differences with h = 1e-6 rad: truncation ~h^2, round-off ~eps/h relative.
FD_STEP = 1e-6
FD_RTOL = 1e-6
FD_ATOL = 1e-9

TASKS = ["position", "position_pitch", "position_pitch_roll", ["wx", "wy", "wz"], ["vx", "vz", 5]]


def random_configurations(arm: Arm, n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return rng.uniform(arm.limits.lower, arm.limits.upper, (n, 5))


def test_extended_jacobian_matches_pinocchio_and_closed_form_rows(arm: Arm) -> None:
    for q in random_configurations(arm, 20):
        E = extended_jacobian(q, arm.geometry)
        np.testing.assert_allclose(E[:6], arm.frame_jacobian(q), atol=EXACT_ATOL)
        # pitch row = y4 . w, roll row = a . w (y4 of DH frame 4, a of the tool, by Pinocchio).
        y4 = arm.frame_placement(q, "dh_frame_4")[:3, 1]
        approach = arm.frame_placement(q)[:3, 2]
        J6 = arm.frame_jacobian(q)
        np.testing.assert_allclose(E[6], y4 @ J6[3:], atol=EXACT_ATOL)
        np.testing.assert_allclose(E[7], approach @ J6[3:], atol=EXACT_ATOL)


def test_manipulability_of_position_pitch_is_closed_form(arm: Arm) -> None:
    g = arm.geometry
    q = random_configurations(arm, 200)
    r = np.linalg.norm(arm.fk(q)[:, :2, 3], axis=1)
    expected = r * g.a2 * g.a3 * np.abs(np.sin(q[:, 2]))
    np.testing.assert_allclose(manipulability(q, "position_pitch"), expected, atol=EXACT_ATOL)
    np.testing.assert_allclose(manipulability(q, "position_pitch_roll"), expected, atol=EXACT_ATOL)


def test_manipulability_equals_product_of_singular_values(arm: Arm) -> None:
    q = random_configurations(arm, 50, seed=1)
    for task in TASKS:
        sv = singular_values(q, task)
        np.testing.assert_allclose(manipulability(q, task), np.prod(sv, axis=1), rtol=1e-9)
        np.testing.assert_allclose(condition_number(q, task), sv[:, 0] / sv[:, -1], rtol=1e-12)


@pytest.mark.parametrize("task", TASKS)
def test_gradient_matches_finite_differences(arm: Arm, task: object) -> None:
    for q in random_configurations(arm, 25, seed=2):
        grad = manipulability_gradient(q, task)
        fd = np.array(
            [
                (manipulability(q + FD_STEP * e, task) - manipulability(q - FD_STEP * e, task))
                / (2 * FD_STEP)
                for e in np.eye(5)
            ]
        )
        np.testing.assert_allclose(grad, fd, rtol=FD_RTOL, atol=FD_ATOL)


def test_jacobian_derivative_matches_pinocchio_time_variation(arm: Arm) -> None:
    # dJ/dt with v = e_j is dJ/dq_j.
    for q in random_configurations(arm, 10, seed=3):
        dE = task_jacobian_derivative(q, ["vx", "vy", "vz", "wx", "wy"])
        for j in range(5):
            pin.computeJointJacobiansTimeVariation(arm.model, arm.data, q, np.eye(5)[j])
            dJ = pin.getFrameJacobianTimeVariation(
                arm.model, arm.data, arm.tool_frame_id, pin.LOCAL_WORLD_ALIGNED
            )
            np.testing.assert_allclose(dE[:, :, j], dJ[:5], atol=EXACT_ATOL)


def test_batch_and_single_agree(arm: Arm) -> None:
    q = random_configurations(arm, 5, seed=4)
    m, grad = manipulability_and_gradient(q, "position")
    for i in range(5):
        m_i, grad_i = manipulability_and_gradient(q[i], "position")
        assert m_i == pytest.approx(m[i], abs=EXACT_ATOL)
        np.testing.assert_allclose(grad_i, grad[i], atol=EXACT_ATOL)
    assert task_jacobian(q, "position_pitch").shape == (5, 4, 5)


def test_singular_conditions_match_the_derivation() -> None:
    stretched, folded = Singularity.ELBOW_STRETCHED, Singularity.ELBOW_FOLDED
    tool_axis, collinear = Singularity.TOOL_ON_BASE_AXIS, Singularity.ARM_COLLINEAR
    assert set(singular_conditions("position")) == {tool_axis, collinear}
    assert set(singular_conditions("position_pitch")) == {stretched, folded, tool_axis}
    assert set(singular_conditions("position_pitch_roll")) == {stretched, folded, tool_axis}
    assert set(singular_conditions(["wx", "wy", "wz"])) == {Singularity.APPROACH_VERTICAL}


def test_singular_configurations_have_zero_manipulability(arm: Arm) -> None:
    g = arm.geometry
    # Elbow stretched: q3 = 0; arm collinear additionally q4 = 90 deg.
    assert manipulability([0.3, 0.4, 0.0, 1.0, 0.0], "position_pitch") < EXACT_ATOL
    assert manipulability([0.3, 0.4, 0.0, math.pi / 2, 0.0], "position") < EXACT_ATOL
    assert manipulability([0.3, 0.4, 0.0, 1.0, 0.0], "position") > 1e-4
    # Tool on the base axis with the pen up: q2 from r = 0 (see the scenario's line).
    q3, q4 = -0.7, 2.2
    A = g.a2 + g.a3 * math.cos(q3) + g.d5 * math.sin(q3 + q4)
    B = -g.a3 * math.sin(q3) + g.d5 * math.cos(q3 + q4)
    q = np.array([0.5, math.atan2(A, -B), q3, q4, 0.0])
    assert np.linalg.norm(arm.fk(q)[:2, 3]) < EXACT_ATOL
    assert manipulability(q, "position") < EXACT_ATOL
    assert condition_number(q, "position_pitch") > 1e9


def test_distances_and_nearest(arm: Arm) -> None:
    q = np.array([0.2, 1.2, -0.01, 1.0, 0.0])
    distances = {d.kind: d for d in singularity_distances(q)}
    assert distances[Singularity.ELBOW_STRETCHED].distance == pytest.approx(0.01)
    assert distances[Singularity.ELBOW_FOLDED].distance == pytest.approx(math.pi - 0.01)
    r = np.linalg.norm(arm.fk(q)[:2, 3])
    assert distances[Singularity.TOOL_ON_BASE_AXIS].distance == pytest.approx(r, abs=EXACT_ATOL)
    nearest = nearest_singularity(q, "position_pitch")
    assert nearest.kind == Singularity.ELBOW_STRETCHED
    near = near_singularities(q, "position_pitch", angle_tolerance=0.02, length_tolerance=1e-3)
    assert [d.kind for d in near] == [Singularity.ELBOW_STRETCHED]
    # The position task is not singular with the elbow stretched alone.
    assert near_singularities(q, "position", angle_tolerance=0.02, length_tolerance=1e-3) == ()


def test_wrist_on_axis_distance(arm: Arm) -> None:
    q = np.array([0.0, 1.6, -0.7, 2.2, 0.0])
    T = arm.fk(q)
    wrist = T[:3, 3] - arm.geometry.d5 * T[:3, 2]
    distance = {d.kind: d for d in singularity_distances(q)}[Singularity.WRIST_ON_BASE_AXIS]
    assert distance.distance == pytest.approx(np.linalg.norm(wrist[:2]), abs=EXACT_ATOL)


def test_max_manipulability_bounds_samples(arm: Arm) -> None:
    m_max = max_manipulability("position_pitch", arm.limits.lower, arm.limits.upper)
    samples = manipulability(random_configurations(arm, 20_000, seed=9), "position_pitch")
    assert samples.max() <= m_max * (1 + 1e-9)
    assert m_max < samples.max() * 1.05


def test_task_errors() -> None:
    with pytest.raises(TaskError, match="valid names: position"):
        make_task("orientation")
    with pytest.raises(TaskError, match="unknown task row; valid rows: vx"):
        make_task(["vx", "yaw"])
    with pytest.raises(TaskError, match="1 to 5 distinct rows"):
        make_task(["vx", "vx"])
    with pytest.raises(TaskError, match="1 to 5 distinct rows"):
        make_task([0, 1, 2, 3, 4, 5])
    with pytest.raises(TaskError, match="rank deficient everywhere"):
        singular_conditions(["wx", "wy", "wz", "vx", "vy"])
    with pytest.raises(InputError, match="length_tolerance must be a finite number > 0"):
        near_singularities(np.zeros(5), "position", angle_tolerance=0.1, length_tolerance=0.0)
    with pytest.raises(ShapeError, match=r"q must have shape \(5,\) or \(N, 5\)"):
        manipulability(np.zeros(4), "position")
    with pytest.raises(InputError, match="one configuration"):
        singularity_distances(np.zeros((2, 5)))
    assert make_task(["vx", "vy", "vz", "pitch"]).name == "position_pitch"


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(min_value=-3.0, max_value=3.0, allow_nan=False), min_size=5, max_size=5))
def test_gradient_property_position(q: list[float]) -> None:
    config = np.array(q)
    assume(manipulability(config, "position") > 1e-5)
    grad = manipulability_gradient(config, "position")
    fd = np.array(
        [
            (
                manipulability(config + FD_STEP * e, "position")
                - manipulability(config - FD_STEP * e, "position")
            )
            / (2 * FD_STEP)
            for e in np.eye(5)
        ]
    )
    np.testing.assert_allclose(grad, fd, rtol=FD_RTOL, atol=FD_ATOL)
