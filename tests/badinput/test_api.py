"""The bad-input corpus of the public Python API: one row per call, a LynxplanInputError each.

Rows: ``(id, call, exception type, regex)``; ``call`` takes the shared ``arm`` and returns the
result of one public call with one bad argument.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from lynxplan import guards, load_arm
from lynxplan.collision import CollisionWorld, check_trajectory
from lynxplan.collision.check import clearance_profile
from lynxplan.collision.obstacles import BoxObstacle, SphereObstacle, axis_aligned_box
from lynxplan.exceptions import (
    InputError,
    InvalidObstacleError,
    LynxplanInputError,
    NonFiniteInputError,
    NotRigidTransformError,
    OutOfRangeError,
    ResourceLimitError,
    ShapeError,
    TimingError,
)
from lynxplan.parallel import (
    constant_orientation_workspace,
    nearest_assembly_mode,
    orientation_stack,
    solve_fk,
    solve_fk_batch,
    solve_ik,
    solve_ik_batch,
)
from lynxplan.trajectory import (
    LspbTiming,
    MotionLimits,
    SegmentSpec,
    build_plan,
    free_segment,
    line_segment,
)

Q0 = np.radians([90.0, 60.0, -60.0, 40.0, 0.0])
_ARM = load_arm()
T0 = _ARM.fk(Q0)
REFLECTION = T0.copy()
REFLECTION[:3, 0] *= -1
SCALED = T0.copy()
SCALED[:3, :3] *= 1.1
NAN_POSE = T0.copy()
NAN_POSE[1, 2] = math.nan
FAR = T0.copy()
FAR[0, 3] = 1e19
BOTTOM = T0.copy()
BOTTOM[3, 0] = 0.5


def _plan_with(spec: SegmentSpec) -> Any:
    return build_plan(Q0, [spec])


def _world() -> CollisionWorld:
    return CollisionWorld(_ARM, [axis_aligned_box("wall", [0.1, 0.1, -0.1], [0.1, 0.02, 0.3])])


Row = tuple[str, Callable[[], Any], type[Exception], str]

ROWS: list[Row] = [
    # Arm.fk / jacobian / frame_placement
    ("fk nan", lambda: _ARM.fk([0, 0, math.nan, 0, 0]), NonFiniteInputError, r"q\[2\] = nan"),
    ("fk inf", lambda: _ARM.fk([0, 0, 0, 0, math.inf]), NonFiniteInputError, r"q\[4\] = inf"),
    ("fk 1e19", lambda: _ARM.fk([1e19, 0, 0, 0, 0]), OutOfRangeError, r"q\[0\] = 1e\+19"),
    ("fk -101", lambda: _ARM.fk([0, -101, 0, 0, 0]), OutOfRangeError, r"q\[1\] = -101 is out"),
    ("fk batch 1e300", lambda: _ARM.fk(np.full((3, 5), 1e300)), OutOfRangeError, r"q\[0, 0\]"),
    ("fk shape 4", lambda: _ARM.fk(np.zeros(4)), ShapeError, r"q must have shape \(5,\) or"),
    ("fk shape 3d", lambda: _ARM.fk(np.zeros((2, 2, 5))), ShapeError, r"Got: \(2, 2, 5\)"),
    ("fk scalar", lambda: _ARM.fk(0.0), ShapeError, r"Got: \(\)"),
    ("fk strings", lambda: _ARM.fk(["a"] * 5), InputError, r"q must be an array of real"),
    ("fk ragged", lambda: _ARM.fk([[0] * 5, [0] * 4]), InputError, r"ragged"),
    ("fk complex", lambda: _ARM.fk(np.zeros(5) * 1j), InputError, r"Got dtype complex128"),
    ("fk object", lambda: _ARM.fk(np.array([object()] * 5)), InputError, r"dtype object"),
    ("fk None", lambda: _ARM.fk(None), InputError, r"q must be an array|Got: \(\)"),
    ("fk dict", lambda: _ARM.fk({"a": 1}), InputError, r"q must be an array of real"),
    ("jac nan", lambda: _ARM.jacobian([math.nan] * 5), NonFiniteInputError, r"q\[0\] = nan"),
    ("jac 1e19", lambda: _ARM.jacobian([0, 0, 0, 1e19, 0]), OutOfRangeError, r"q\[3\]"),
    ("jac shape", lambda: _ARM.jacobian(np.zeros((5, 1))), ShapeError, r"Got: \(5, 1\)"),
    ("frame nan", lambda: _ARM.frame_placement([math.nan] * 5), NonFiniteInputError, r"q"),
    ("frame 1e19", lambda: _ARM.frame_jacobian([1e19] * 5), OutOfRangeError, r"q\[0\]"),
    # Arm.ik
    ("ik reflection", lambda: _ARM.ik(REFLECTION), InputError, r"T: .*determinant -1"),
    ("ik scaled", lambda: _ARM.ik(SCALED), NotRigidTransformError, r"T is not a rigid"),
    ("ik nan", lambda: _ARM.ik(NAN_POSE), NonFiniteInputError, r"T contains NaN"),
    ("ik far", lambda: _ARM.ik(FAR), OutOfRangeError, r"T translation = 1e\+19"),
    ("ik bottom", lambda: _ARM.ik(BOTTOM), NotRigidTransformError, r"last row must be 0 0 0 1"),
    ("ik 3x3", lambda: _ARM.ik(np.eye(3)), ShapeError, r"a 3x3 rotation is not a pose"),
    ("ik 3x4", lambda: _ARM.ik(T0[:3]), ShapeError, r"T must have shape \(4, 4\)"),
    ("ik batch", lambda: _ARM.ik(T0[None]), ShapeError, r"Got: \(1, 4, 4\)"),
    ("ik strings", lambda: _ARM.ik(np.full((4, 4), "x")), InputError, r"dtype <U1"),
    (
        "ik tol nan",
        lambda: _ARM.ik(T0, orientation_tolerance=math.nan),
        NonFiniteInputError,
        r"orientation_tolerance",
    ),
    (
        "ik tol neg",
        lambda: _ARM.ik(T0, orientation_tolerance=-1e-3),
        OutOfRangeError,
        r"orientation_tolerance = -0.001",
    ),
    (
        "ik tol str",
        lambda: _ARM.ik(T0, orientation_tolerance="big"),
        InputError,
        r"orientation_tolerance: 'big' is not a number",
    ),
    (
        "ik limit tol",
        lambda: _ARM.ik(T0, limit_tolerance=math.inf),
        NonFiniteInputError,
        r"limit_tolerance",
    ),
    (
        "ik ref nan",
        lambda: _ARM.ik(T0, q_reference=[0, 0, 0, 0, math.nan]),
        NonFiniteInputError,
        r"q_reference\[4\] = nan",
    ),
    (
        "ik ref 1e19",
        lambda: _ARM.ik(T0, q_reference=[1e19, 0, 0, 0, 0]),
        OutOfRangeError,
        r"q_reference\[0\]",
    ),
    ("ik ref shape", lambda: _ARM.ik(T0, q_reference=[0, 0]), ShapeError, r"q_reference"),
    ("ik select", lambda: _ARM.ik(T0, select="best"), InputError, r"select must be 'nearest'"),
    # Arm.ik_batch
    (
        "ikb reflection",
        lambda: _ARM.ik_batch(np.stack([T0, REFLECTION])),
        InputError,
        r"T\[1\]: rotation block has determinant -1",
    ),
    (
        "ikb nan",
        lambda: _ARM.ik_batch(np.stack([T0, T0, NAN_POSE])),
        NonFiniteInputError,
        r"in T\[2\]",
    ),
    ("ikb far", lambda: _ARM.ik_batch(np.stack([FAR])), OutOfRangeError, r"T\[0\] translation"),
    (
        "ikb scaled",
        lambda: _ARM.ik_batch(np.stack([T0, SCALED])),
        NotRigidTransformError,
        r"T\[1\] is not a rigid",
    ),
    ("ikb shape", lambda: _ARM.ik_batch(np.zeros((2, 3, 4))), ShapeError, r"Got: \(2, 3, 4\)"),
    ("ikb 3x3 batch", lambda: _ARM.ik_batch(np.zeros((2, 3, 3))), ShapeError, r"3x3 rotation"),
    (
        "ikb dtype",
        lambda: _ARM.ik_batch(np.zeros((2, 4, 4), dtype=complex)),
        InputError,
        r"dtype complex128",
    ),
    (
        "ikb ref",
        lambda: _ARM.ik_batch(T0, q_reference=[math.nan] * 5),
        NonFiniteInputError,
        r"q_reference",
    ),
    ("ikb tol", lambda: _ARM.ik_batch(T0, limit_tolerance=-1), OutOfRangeError, r"limit_tol"),
    # 3-RRR
    ("pik nan", lambda: solve_ik([0.2, math.nan, 0.1]), NonFiniteInputError, r"pose\[1\] = nan"),
    ("pik far", lambda: solve_ik([1e300, 0.1, 0.0]), OutOfRangeError, r"pose x = 1e\+300"),
    ("pik angle", lambda: solve_ik([0.2, 0.1, 1e19]), OutOfRangeError, r"pose alpha = 1e\+19"),
    ("pik shape", lambda: solve_ik([0.2, 0.1]), ShapeError, r"pose must have shape \(3,\)"),
    ("pik batch", lambda: solve_ik([[0.2, 0.1, 0.0]]), ShapeError, r"pose must have shape \(3"),
    ("pik strings", lambda: solve_ik(["a", "b", "c"]), InputError, r"pose must be an array"),
    (
        "pikb nan",
        lambda: solve_ik_batch([[0.2, 0.1, 0], [0, 0, math.inf]]),
        NonFiniteInputError,
        r"poses\[1, 2\] = inf",
    ),
    (
        "pikb angles",
        lambda: solve_ik_batch(np.full((2, 3), 200.0)),
        OutOfRangeError,
        r"poses\[0\] x = 200 is out of range|poses alpha",
    ),
    ("pfk nan", lambda: solve_fk([0, math.nan, 0]), NonFiniteInputError, r"theta\[1\] = nan"),
    ("pfk 1e19", lambda: solve_fk([0, 0, 1e19]), OutOfRangeError, r"theta\[2\] = 1e\+19"),
    ("pfk shape", lambda: solve_fk([0, 0]), ShapeError, r"theta must have shape \(3,\)"),
    ("pfkb shape", lambda: solve_fk_batch(np.zeros((2, 4))), ShapeError, r"Got: \(2, 4\)"),
    (
        "pfk near",
        lambda: nearest_assembly_mode([0.5, 1.0, -1.0], [0, 0, math.nan]),
        NonFiniteInputError,
        r"reference\[2\] = nan",
    ),
    ("pws alpha", lambda: constant_orientation_workspace(math.nan), NonFiniteInputError, r"alpha"),
    (
        "pws alpha big",
        lambda: constant_orientation_workspace(1e19),
        OutOfRangeError,
        r"alpha = 1e\+19",
    ),
    (
        "pws step",
        lambda: constant_orientation_workspace(0.0, step=1e-12),
        ResourceLimitError,
        r"grid points for a 1e-09 mm step.*--max-samples",
    ),
    (
        "pws step 0",
        lambda: constant_orientation_workspace(0.0, step=0.0),
        InputError,
        r"step must be positive",
    ),
    (
        "pws mode",
        lambda: constant_orientation_workspace(0.0, mode=8),
        InputError,
        r"working mode index must be an integer in 0..7",
    ),
    (
        "pws mode nan",
        lambda: constant_orientation_workspace(0.0, mode=math.nan),
        InputError,
        r"working mode index",
    ),
    (
        "pws stack",
        lambda: orientation_stack(np.zeros(10_000), step=1e-4),
        ResourceLimitError,
        r"orientation workspace grid points|grid points",
    ),
    ("pws stack nan", lambda: orientation_stack([0.0, math.nan]), NonFiniteInputError, r"alph"),
    # trajectory builders
    ("timing neg", lambda: LspbTiming(-1.0, 0.5), TimingError, r"tt must be positive"),
    ("timing nan", lambda: LspbTiming(math.nan, 0.5), TimingError, r"must be finite"),
    ("timing overlap", lambda: LspbTiming(1.0, 0.8), TimingError, r"blends overlap"),
    (
        "free nan",
        lambda: free_segment(Q0, [0, 0, 0, 0, math.nan]),
        NonFiniteInputError,
        r"q_end\[4\] = nan",
    ),
    ("free 1e19", lambda: free_segment([1e19, 0, 0, 0, 0], Q0), OutOfRangeError, r"q_start\[0\]"),
    ("free shape", lambda: free_segment(Q0, [0, 0, 0]), ShapeError, r"q_end must have shape"),
    (
        "free timing",
        lambda: free_segment(Q0, Q0 + 0.1, LspbTiming(1e9, 1.0)),
        OutOfRangeError,
        r"timing\.tt = 1e\+09",
    ),
    (
        "free timing type",
        lambda: free_segment(Q0, Q0 + 0.1, (1.0, 0.2)),
        InputError,
        r"timing must be an LspbTiming",
    ),
    (
        "free limits",
        lambda: free_segment(Q0, Q0 + 0.1, limits=MotionLimits(acceleration=0.0)),
        InputError,
        r"acceleration limits must be positive",
    ),
    (
        "line reflection",
        lambda: line_segment(T0, REFLECTION, Q0),
        InputError,
        r"T_end: rotation block has determinant -1",
    ),
    ("line nan", lambda: line_segment(NAN_POSE, T0, Q0), NonFiniteInputError, r"T_start"),
    ("line far", lambda: line_segment(T0, FAR, Q0), OutOfRangeError, r"T_end translation"),
    (
        "line mode",
        lambda: line_segment(T0, T0, Q0, mode="spiral"),
        InputError,
        r"unknown orientation mode 'spiral'",
    ),
    ("line q", lambda: line_segment(T0, T0, [math.inf] * 5), NonFiniteInputError, r"q_start"),
    ("plan empty", lambda: build_plan(Q0, []), InputError, r"at least one segment"),
    (
        "plan not spec",
        lambda: build_plan(Q0, [{"kind": "free"}]),
        InputError,
        r"specs\[0\] must be a SegmentSpec",
    ),
    (
        "plan both",
        lambda: _plan_with(SegmentSpec("free", target_q=Q0, target_pose=T0)),
        InputError,
        r"exactly one of target_q and target_pose",
    ),
    (
        "plan pose",
        lambda: _plan_with(SegmentSpec("line", target_pose=REFLECTION)),
        InputError,
        r"segments\[0\]\.target_pose: rotation block has determinant -1",
    ),
    (
        "plan q",
        lambda: _plan_with(SegmentSpec("free", target_q=[1e19] * 5)),
        OutOfRangeError,
        r"segments\[0\]\.target_q\[0\]",
    ),
    (
        "plan kind",
        lambda: _plan_with(SegmentSpec("warp", target_q=Q0)),
        InputError,  # type: ignore[arg-type]
        r"unknown kind 'warp'",
    ),
    (
        "plan rate",
        lambda: build_plan(Q0, [SegmentSpec("free", target_q=Q0 + 0.1)]).sample(math.nan),
        NonFiniteInputError,
        r"sample rate",
    ),
    (
        "plan rate 0",
        lambda: build_plan(Q0, [SegmentSpec("free", target_q=Q0 + 0.1)]).sample(0),
        OutOfRangeError,
        r"sample rate = 0 is out of range",
    ),
    (
        "plan samples",
        lambda: build_plan(
            Q0, [SegmentSpec("free", target_q=Q0 + 0.1, timing=LspbTiming(80_000.0, 1.0))]
        ).sample(1e6),
        ResourceLimitError,
        r"trajectory samples \(80000 s at 1e\+06 Hz\)",
    ),
    # collision
    (
        "box size",
        lambda: axis_aligned_box("b", [0, 0, 0], [0.1, -1, 0.1]),
        InvalidObstacleError,
        r"obstacle 'b'",
    ),
    (
        "box nan",
        lambda: axis_aligned_box("b", [0, math.nan, 0], [0.1, 0.1, 0.1]),
        NonFiniteInputError,
        r"min_corner|centre",
    ),
    (
        "box huge",
        lambda: axis_aligned_box("b", [0, 0, 0], [1e300, 1, 1]),
        LynxplanInputError,
        r"1e\+300",
    ),
    ("box str", lambda: BoxObstacle("b", [0, 0, 0], ["a", 1, 1]), InputError, r"must be"),
    (
        "box reflection",
        lambda: BoxObstacle("b", [0, 0, 0], [1, 1, 1], np.diag([1, 1, -1])),
        InvalidObstacleError,
        r"not a proper rotation",
    ),
    (
        "sphere radius",
        lambda: SphereObstacle("s", [0, 0, 0], math.nan),
        LynxplanInputError,
        r"radius",
    ),
    (
        "check nan q",
        lambda: check_trajectory(_world(), [[0, 0, 0, 0, math.nan]] * 2, [0, 1]),
        NonFiniteInputError,
        r"q\[0, 4\] = nan",
    ),
    (
        "check q 1e19",
        lambda: check_trajectory(_world(), [[1e19, 0, 0, 0, 0]] * 2, [0, 1]),
        OutOfRangeError,
        r"q\[0, 0\] = 1e\+19",
    ),
    (
        "check t",
        lambda: check_trajectory(_world(), [Q0, Q0], [0, math.nan]),
        NonFiniteInputError,
        r"\bt\b",
    ),
    (
        "check t order",
        lambda: check_trajectory(_world(), [Q0, Q0], [1, 0]),
        InputError,
        r"strictly increasing",
    ),
    (
        "check t str",
        lambda: check_trajectory(_world(), [Q0, Q0], ["a", "b"]),
        InputError,
        r"t must be an array",
    ),
    (
        "check shape",
        lambda: check_trajectory(_world(), np.zeros((2, 4)), [0, 1]),
        ShapeError,
        r"q must have shape",
    ),
    (
        "check accel",
        lambda: check_trajectory(_world(), [Q0, Q0], [0, 1], acceleration_bound=[1, 2]),
        ShapeError,
        r"acceleration_bound",
    ),
    (
        "profile nan",
        lambda: clearance_profile(_world(), [math.nan] * 5),
        NonFiniteInputError,
        r"q\[0\] = nan",
    ),
    # guards themselves
    (
        "limits",
        lambda: guards.raised_limits(max_samples=0).__enter__(),
        OutOfRangeError,
        r"max_samples = 0",
    ),
    ("seed neg", lambda: guards.seed("seed", -1), OutOfRangeError, r"seed = -1"),
    ("seed huge", lambda: guards.seed("seed", 2**64), OutOfRangeError, r"2\*\*63"),
    ("seed float", lambda: guards.seed("seed", 1.5), InputError, r"must be an integer"),
    ("seed bool", lambda: guards.seed("seed", True), InputError, r"must be an integer"),
    ("duration", lambda: guards.duration("tt", 0.0), OutOfRangeError, r"tt = 0 is out"),
    ("rate", lambda: guards.sample_rate("rate", 1e9), OutOfRangeError, r"rate = 1e\+09"),
    (
        "rotation 3x3 det",
        lambda: guards.rotation("R", np.diag([1.0, 1.0, -1.0])),
        InputError,
        r"R: rotation block has determinant -1",
    ),
    ("rotation 4x4", lambda: guards.rotation("R", np.eye(4)), ShapeError, r"R must have shape"),
    (
        "planning time",
        lambda: guards.planning_time("time_limit", 1e9),
        ResourceLimitError,
        r"time_limit \(planning time in s\): 1e\+09 requested.*max_planning_time=",
    ),
    (
        "grid cells",
        lambda: guards.grid_cells("cells", 1.0, 1e-9, 3),
        ResourceLimitError,
        r"cells \(1e\+09 per axis.*1e\+27 requested",
    ),
    (
        "monte carlo",
        lambda: guards.count("samples", 10**12),
        ResourceLimitError,
        r"samples: 1e\+12 requested, more than the limit of 1e\+08; raise",
    ),
    ("workspace", lambda: _ARM_WORKSPACE(samples=10**12), ResourceLimitError, r"samples"),
    ("workspace cell", lambda: _ARM_WORKSPACE(cell=1e-9), ResourceLimitError, r"planar grid"),
    ("workspace voxel", lambda: _ARM_WORKSPACE(voxel_size=1e-30), OutOfRangeError, r"voxel_size"),
    ("workspace seed", lambda: _ARM_WORKSPACE(seed=-3), OutOfRangeError, r"seed = -3"),
]


def _ARM_WORKSPACE(**kwargs: Any) -> Any:
    from lynxplan.arm.workspace import estimate_workspace

    settings = {"samples": 1000, "cell": 0.01, "voxel_size": 0.05, **kwargs}
    return estimate_workspace(_ARM.geometry, _ARM.limits, **settings)


@pytest.mark.parametrize(("name", "call", "error", "pattern"), ROWS, ids=[r[0] for r in ROWS])
def test_api_case(name: str, call: Callable[[], Any], error: type[Exception], pattern: str):
    with pytest.raises(error) as info:
        call()
    assert isinstance(info.value, LynxplanInputError), type(info.value).__mro__
    message = str(info.value)
    assert "\n" not in message
    assert re.search(pattern, message), f"{message!r} does not match {pattern!r}"


def test_raised_limits_allow_what_the_default_refuses() -> None:
    with pytest.raises(ResourceLimitError):
        guards.count("samples", 200_000_000)
    with guards.raised_limits(max_samples=300_000_000):
        assert guards.count("samples", 200_000_000) == 200_000_000
    with pytest.raises(ResourceLimitError):
        guards.count("samples", 200_000_000)


_AL5_URDF = Path(__file__).resolve().parents[2] / "urdf" / "lynxmotion_al5.urdf"

#: (file content, regex of the one ModelError line)
URDF_CASES: list[tuple[str, bytes | Callable[[str], str], str]] = [
    ("truncated", b'<robot name="x"><link name="a"/><joint', r"cannot load URDF .*XML_ERROR"),
    ("random bytes", bytes(range(256)) * 4, r"cannot load URDF .*\(parser: "),
    ("empty", b"", r"cannot load URDF"),
    ("no joints", b'<robot name="x"><link name="a"/></robot>', r"expected revolute joints"),
    (
        "zero limits",
        lambda t: re.sub(r'(lower|upper)="[^"]*"', r'\1="0"', t),
        r"joint q1: position limits \[0, 0\] rad must be finite with lower < upper",
    ),
    (
        "inverted limits",
        lambda t: re.sub(r'lower="([^"]*)" upper="([^"]*)"', r'lower="\2" upper="\1"', t),
        r"joint q\d: position limits .* lower < upper",
    ),
    (
        "zero velocity",
        lambda t: re.sub(r'velocity="[^"]*"', 'velocity="0"', t),
        r"joint q1: velocity limit 0 rad/s must be > 0",
    ),
    (
        "renamed joint",
        lambda t: t.replace('joint name="q3"', 'joint name="elbow"'),
        r"expected revolute joints",
    ),
]


@pytest.mark.parametrize(("name", "content", "pattern"), URDF_CASES, ids=[c[0] for c in URDF_CASES])
def test_urdf_case(
    tmp_path: Path, capfd: pytest.CaptureFixture[str], name: str, content: Any, pattern: str
) -> None:
    from lynxplan.arm.model import Arm
    from lynxplan.exceptions import ModelError

    path = tmp_path / f"{name.replace(' ', '_')}.urdf"
    if callable(content):
        path.write_text(content(_AL5_URDF.read_text(encoding="utf-8")), encoding="utf-8")
    else:
        path.write_bytes(content)
    with pytest.raises(ModelError) as info:
        Arm(path)
    assert isinstance(info.value, LynxplanInputError)
    assert "\n" not in str(info.value) and re.search(pattern, str(info.value)), str(info.value)
    captured = capfd.readouterr()
    assert captured.err == "", f"parser noise reached stderr: {captured.err!r}"


def test_odd_but_valid_arrays_are_copied_not_refused() -> None:
    """Non-contiguous, Fortran-ordered, float32 and integer arrays are accepted (copied as needed)
    and give the same result as a contiguous float64 array."""
    rng = np.random.default_rng(3)
    q = rng.uniform(-2.0, 2.0, (6, 10))
    strided = q[:, ::2]  # (6, 5), not contiguous
    expected = _ARM.fk(np.ascontiguousarray(strided))
    np.testing.assert_array_equal(_ARM.fk(strided), expected)
    np.testing.assert_array_equal(_ARM.fk(np.asfortranarray(strided)), expected)
    np.testing.assert_allclose(_ARM.fk(strided.astype(np.float32)), expected, atol=1e-6)
    np.testing.assert_array_equal(
        _ARM.fk(np.zeros((2, 5), dtype=np.int64)), _ARM.fk(np.zeros((2, 5)))
    )
    T = expected.transpose(0, 2, 1).copy().transpose(0, 2, 1)  # Fortran-like strides per pose
    batch = _ARM.ik_batch(T)
    np.testing.assert_array_equal(batch.q, _ARM.ik_batch(np.ascontiguousarray(expected)).q)
    np.testing.assert_array_equal(_ARM.jacobian(strided), _ARM.jacobian(strided.copy()))


def test_functional_api_refuses_bad_dtypes_and_nan_reference() -> None:
    from lynxplan.arm import forward_kinematics, solve_ik_batch, tool_jacobian

    with pytest.raises(InputError, match=r"q must be an array of real numbers"):
        forward_kinematics(["a"] * 5)
    with pytest.raises(InputError, match=r"ragged"):
        tool_jacobian([[0] * 5, [0] * 4])
    with pytest.raises(InputError, match=r"T must be an array of real numbers"):
        solve_ik_batch("x")
    with pytest.raises(NonFiniteInputError, match=r"q_reference"):
        solve_ik_batch(T0, q_reference=[0, 0, 0, 0, math.nan])  # one (5,) reference too


def test_pose_check_finds_the_first_bad_pose_of_a_batch() -> None:
    """The pose check's fast pass (no early exit) and its scan agree: each kind of bad pose,
    alone or after another, is reported at its index with its code; a good batch reports the
    largest deviation from orthonormal (numpy's max |R^T R - I|)."""
    from scipy.spatial.transform import Rotation

    from lynxplan.guards import pose_kernel as pk

    n = 500
    good = np.zeros((n, 4, 4))
    good[:, :3, :3] = Rotation.random(n, random_state=5).as_matrix()
    good[:, :3, 3] = 0.2
    good[:, 3, 3] = 1.0
    gram = np.einsum("nji,njk->nik", good[:, :3, :3], good[:, :3, :3]) - np.eye(3)
    for approach in (False, True):
        k, code, detail = pk.pose_check_kernel(good, 10.0, approach)
        assert (k, code) == (0, pk.POSE_OK)
        assert detail == (0.0 if approach else pytest.approx(np.abs(gram).max(), rel=1e-12))
    breaks = {
        pk.POSE_NON_FINITE: lambda t: t.__setitem__((1, 2), np.inf),
        pk.POSE_FAR: lambda t: t.__setitem__((0, 3), 11.0),
        pk.POSE_BOTTOM_ROW: lambda t: t.__setitem__((3, 1), 1e-6),
        pk.POSE_NOT_ORTHONORMAL: lambda t: t.__setitem__((0, 2), t[0, 2] + 0.1),
        pk.POSE_REFLECTION: lambda t: t.__setitem__(slice(None, 3, None), -t[:3]),
    }
    rng = np.random.default_rng(8)
    for code, spoil in breaks.items():
        for trial in range(6):
            batch = good.copy()
            at = int(rng.integers(n - 1))
            spoil(batch[at])
            if trial % 2:
                batch[at + 1, 0, 0] = np.nan  # a later bad pose is not reported
            got = pk.pose_check_kernel(batch, 10.0, False)
            assert (int(got[0]), int(got[1])) == (at, code)
