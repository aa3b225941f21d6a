"""The bench's vectorised numpy reference computes what the compiled AL5 IK kernel computes."""

from __future__ import annotations

import numpy as np

from lynxplan.arm import forward_kinematics, load_arm, solve_ik_batch
from lynxplan.bench.al5_numpy import ik_numpy
from lynxplan.constants import LIMIT_SNAP_TOLERANCE


def test_numpy_reference_matches_the_kernel() -> None:
    arm = load_arm()
    rng = np.random.default_rng(4)
    q = rng.uniform(arm.limits.lower, arm.limits.upper, size=(20_000, 5))
    poses = forward_kinematics(q)
    batch = solve_ik_batch(poses)
    g = arm.geometry
    q_np, within, residual = ik_numpy(
        poses, g.a2, g.a3, g.d5, arm.limits.lower, arm.limits.upper, LIMIT_SNAP_TOLERANCE
    )
    # the kernel's atan2/sincos are within a few ulp of libm's; near a stretched elbow the
    # angle amplifies them (d acos / dx ~ 1 / sqrt(1 - x^2))
    np.testing.assert_allclose(q_np, batch.q, rtol=0, atol=1e-9)
    assert (within == batch.within_limits).mean() > 0.9999
    np.testing.assert_allclose(residual, batch.orientation_error, rtol=0, atol=1e-12)
