"""The ``/fk`` and ``/ik`` computations of every built-in robot, from validated arrays to the
encoded answer, and where they run.

Work estimated to take at most :data:`INLINE_SECONDS` runs inline in the server process (a
single pose, a small closed-form batch: microseconds a pose); anything larger, and every IK of
a numerical-solver robot (ur5, ur10, panda: about a millisecond a pose, tens of milliseconds
for an unreachable one), runs in the compute workers (:mod:`.workers`), bounded in memory and
time and killed when its client disconnects.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lynxplan.service import wire
from lynxplan.service.robots import get_robot, ik_slots, is_al5, is_numerical

#: Longest computation a request may run in the server process itself, in [s] (estimated from
#: the per-pose costs below); longer ones go to the compute workers.
INLINE_SECONDS = 2e-3
#: Server time of one configuration of an /fk answer (FK and its encoding), at most, in [s]
#: (measured: about 0.3 us of FK and 0.1 us of encoding on the CI cores; the FK residual over
#: at most 256 configurations is a fixed ~0.5 ms).
FK_POSE_SECONDS = 0.5e-6
#: Server time of one pose and branch slot of a closed-form IK batch and its encoding, in [s]
#: (measured: 0.5 to 0.75 us a pose of 4 slots for the AL5 and SO-10x batches).
IK_SLOT_SECONDS = 0.25e-6


#: Configurations cross-checked against Pinocchio's own FK in one /fk answer (a fixed subsample).
FK_VERIFICATION_SAMPLES = 256


def fk_arrays(arm: Any, q: np.ndarray) -> dict[str, Any]:
    """Tool poses of ``q`` (n,) or (N, n) [rad] and the verification residual.

    Returns:
        ``T``: (4, 4) or (N, 4, 4) in [m]; ``residual``: largest |closed form - Pinocchio| over
        up to :data:`FK_VERIFICATION_SAMPLES` evenly spaced configurations, in [m] (unitless for
        the rotation part).
    """
    T = arm.fk(q)
    configs = q.reshape(-1, q.shape[-1])
    poses = T.reshape(-1, 4, 4)
    picks = np.unique(
        np.linspace(0, len(configs) - 1, min(len(configs), FK_VERIFICATION_SAMPLES)).astype(np.intp)
    )
    residual = max(
        float(np.abs(arm.frame_placement(configs[i]) - poses[i]).max()) for i in picks.tolist()
    )
    return {"T": T, "residual": residual}


def ik_single(
    arm: Any, T: np.ndarray, q_reference: np.ndarray | None, select: str, approach_only: bool
) -> tuple[Any, float]:
    """IK of one pose (:meth:`Arm.ik`) and the tool position residual of the selected branch.

    Returns:
        The library's ``IkResult`` and ``|p_fk(q) - p_target|`` of the selected solution, in [m]
        (the library checks every branch by forward kinematics; NaN when no branch is within
        limits).
    """
    result = arm.ik(T, q_reference=q_reference, select=select, approach_only=approach_only)
    if result.selected is None:
        return result, float("nan")
    return result, float(result.solutions[result.selected].position_error)


def ik_batch_arrays(
    T: np.ndarray,
    q_reference: np.ndarray | None = None,
    approach_only: bool = False,
    verify: bool = True,
) -> dict[str, np.ndarray]:
    """All-branch IK of (N, 4, 4) poses with each branch's FK position residual.

    Returns:
        The fields of the library's ``IkBatch`` plus, when ``verify``, ``position_error``
        (N, 4), in [m]: ``|p_fk(q) - p_target|`` of every branch (NaN where the pose failed).
    """
    from lynxplan.arm.model import load_arm

    arm = load_arm()
    batch = arm.ik_batch(T, q_reference=q_reference, approach_only=approach_only)
    out = {name: np.asarray(getattr(batch, name)) for name in batch._fields}
    if not verify:
        return out
    q = np.nan_to_num(batch.q.reshape(-1, 5), nan=0.0)  # failed poses: NaN q, error set below
    reached = arm.fk(q)[:, :3, 3].reshape(-1, 4, 3)
    reached -= T.reshape(-1, 4, 4)[:, None, :3, 3]
    error = np.sqrt(np.einsum("nbi,nbi->nb", reached, reached))
    error[np.isnan(batch.q[..., 0])] = np.nan
    out["position_error"] = error
    return out


def fk_inline(count: int) -> bool:
    """Whether the FK of ``count`` configurations runs inline."""
    return count * FK_POSE_SECONDS <= INLINE_SECONDS


def ik_inline(robot: Any, count: int, approach_only: bool) -> bool:
    """Whether the IK of ``count`` poses of ``robot`` runs inline (never for numerical IK)."""
    if is_numerical(robot):
        return False
    return count * ik_slots(robot, approach_only) * IK_SLOT_SECONDS <= INLINE_SECONDS


def fk_answer(robot: str, q: np.ndarray, answer: str) -> wire.Encoded:
    """Tool poses of ``q`` (n,) or (N, n) [rad] of built-in ``robot`` and the FK residual,
    encoded as ``answer`` (:func:`wire.answer_format`)."""
    result = fk_arrays(get_robot(robot), q)
    if answer == "json":
        return wire.dumps(result), "application/json", {}
    return wire.encode_answer({"T": result["T"]}, {"residual": result["residual"]}, answer)


def ik_batch_answer(
    robot: str,
    T: np.ndarray,
    reference: np.ndarray | None,
    approach_only: bool,
    verify: bool,
    answer: str,
) -> wire.Encoded:
    """Every IK branch of poses ``T`` (N, 4, 4) [m] of built-in ``robot``, encoded as
    ``answer``: the library's batch arrays (``position_error``: each branch's FK check, in
    [m]) and ``count`` (and ``branch_names`` but for the AL5)."""
    arm = get_robot(robot)
    scalars: dict[str, Any] = {"count": len(T)}
    if is_al5(arm):
        arrays = ik_batch_arrays(T, reference, approach_only, verify)
    else:
        from lynxplan.service.robots import robot_ik_batch_arrays

        arrays, scalars["branch_names"] = robot_ik_batch_arrays(arm, T, reference, approach_only)
    return wire.encode_answer(arrays, scalars, answer)


def ik_single_answer(
    robot: str, T: np.ndarray, reference: np.ndarray | None, select: str, approach_only: bool
) -> wire.Encoded:
    """IK of one pose (4, 4) [m] of built-in ``robot`` as JSON: every branch, the selected one
    and its tool position residual, in [m]; whether the target is reached, the nearest
    solution's distance [m] and the solver (a Robot answers an unreachable target with its
    nearest solution)."""
    result, residual = ik_single(get_robot(robot), T, reference, select, approach_only)
    selected = result.selected
    content = {
        "q": None if selected is None else result.solutions[selected].q,
        "selected": selected,
        "branch": None if selected is None else result.solutions[selected].branch,
        "orientation_residual": result.orientation_residual,
        "position_residual": residual,
        "reachable": result.reachable,
        "distance": result.distance,
        "solver": result.solver,
        "solutions": [s._asdict() for s in result.solutions],
    }
    return wire.dumps(content), "application/json", {}


def ik_answer(**kwargs: Any) -> wire.Encoded:
    """The compute workers' ``ik`` task: :func:`ik_single_answer` given ``select``, else
    :func:`ik_batch_answer`."""
    if "select" in kwargs:
        return ik_single_answer(**kwargs)
    return ik_batch_answer(**kwargs)


__all__ = [
    "INLINE_SECONDS",
    "fk_answer",
    "fk_arrays",
    "fk_inline",
    "ik_answer",
    "ik_batch_answer",
    "ik_batch_arrays",
    "ik_inline",
    "ik_single",
    "ik_single_answer",
]
