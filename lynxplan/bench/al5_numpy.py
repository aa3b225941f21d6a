"""The AL5 closed-form IK written as plain vectorised numpy: the reference the compiled kernel
(:func:`lynxplan.arm.ik_kernel.ik_kernel`) is measured against in ``lynxplan bench arm``.

The same formulas and the same outputs as the kernel for valid, reachable poses (four branches
wrapped into the limits, their within-limit flags, the orientation residual), as a user would
write them with numpy: whole-array expressions, no Python loop over poses. It skips the
kernel's input admission (finiteness, rigidity repair, far-away and base-axis cases), so it
does less work than the kernel. Angles in [rad], lengths in [m].
"""

from __future__ import annotations

import numpy as np

TWO_PI = 2.0 * np.pi


def _wrap(x: np.ndarray, lower: float, upper: float, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Angles moved by whole turns into [lower, upper] (snapped within tol), and whether inside."""
    y = x - TWO_PI * np.floor((x - lower) / TWO_PI)
    y = np.where((x >= lower) & (x <= upper), x, y)
    inside = y <= upper
    snap_hi = ~inside & (y <= upper + tol)
    snap_lo = ~inside & ~snap_hi & (y >= lower + TWO_PI - tol)
    y = np.where(snap_hi, upper, np.where(snap_lo, lower, y))
    outside = ~(inside | snap_hi | snap_lo)
    nearer_below = (y - upper) > (lower + TWO_PI - y)
    y = np.where(outside & nearer_below, y - TWO_PI, y)
    return y, ~outside


def ik_numpy(  # noqa: PLR0915 (one closed form, kept in the kernel's reading order)
    poses: np.ndarray,
    a2: float,
    a3: float,
    d5: float,
    lower: np.ndarray,
    upper: np.ndarray,
    tol: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """IK of reachable poses (N, 4, 4): q (N, 4, 5), within (N, 4), residual (N,)."""
    p = poses[:, :3, 3]
    a = poses[:, :3, 2] / np.linalg.norm(poses[:, :3, 2], axis=1, keepdims=True)
    n = poses[:, :3, 0] - np.sum(poses[:, :3, 0] * a, axis=1, keepdims=True) * a
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    o = np.cross(a, n)
    rho = np.hypot(p[:, 0], p[:, 1])
    c1, s1 = p[:, 0] / rho, p[:, 1] / rho
    s234, c234 = c1 * a[:, 0] + s1 * a[:, 1], -a[:, 2]
    norm = np.hypot(s234, c234)
    s234, c234 = s234 / norm, c234 / norm
    r_w = c1 * p[:, 0] + s1 * p[:, 1] - d5 * s234
    z_w = p[:, 2] + d5 * c234
    c3 = np.clip((r_w * r_w + z_w * z_w - a2 * a2 - a3 * a3) / (2.0 * a2 * a3), -1.0, 1.0)
    s3 = np.sqrt(1.0 - c3 * c3)
    q3_abs, beta = np.arctan2(s3, c3), np.arctan2(a3 * s3, a2 + a3 * c3)
    n_x4 = n[:, 0] * c1 * c234 + n[:, 1] * s1 * c234 + n[:, 2] * s234
    n_y4 = n[:, 0] * s1 - n[:, 1] * c1
    q1_front, q234_front = np.arctan2(s1, c1), np.arctan2(s234, c234)
    phi_front, q5_front = np.arctan2(z_w, r_w), np.arctan2(n_y4, n_x4)
    q = np.empty((poses.shape[0], 4, 5))
    within = np.empty((poses.shape[0], 4), dtype=bool)
    for base in range(2):
        if base == 0:
            q1, q234, phi, q5, r_b = q1_front, q234_front, phi_front, q5_front, r_w
        else:
            q1 = np.where(q1_front > 0, q1_front - np.pi, q1_front + np.pi)
            q234 = -q234_front
            phi = np.where(phi_front >= 0, np.pi - phi_front, -np.pi - phi_front)
            q5 = np.where(q5_front > 0, q5_front - np.pi, q5_front + np.pi)
            r_b = -r_w
        q1w, in1 = _wrap(q1, lower[0], upper[0], tol)
        q5w, in5 = _wrap(q5, lower[4], upper[4], tol)
        for elbow in range(2):
            negative = (elbow == 0) == (r_b >= 0.0)
            q2 = np.where(negative, phi + beta, phi - beta)
            q3 = np.where(negative, -q3_abs, q3_abs)
            q4 = q234 - q2 - q3
            q2w, in2 = _wrap(q2, lower[1], upper[1], tol)
            q3w, in3 = _wrap(q3, lower[2], upper[2], tol)
            q4w, in4 = _wrap(q4, lower[3], upper[3], tol)
            b = 2 * base + elbow
            q[:, b] = np.stack((q1w, q2w, q3w, q4w, q5w), axis=1)
            within[:, b] = in1 & in2 & in3 & in4 & in5
    # residual: angle between the target frame and the reached one (same for every branch)
    h = np.hypot(n_x4, n_y4)
    c5, s5 = n_x4 / h, n_y4 / h
    x4 = np.stack((c1 * c234, s1 * c234, s234), axis=1)
    y4 = np.stack((s1, -c1, np.zeros_like(c1)), axis=1)
    n_s = c5[:, None] * x4 + s5[:, None] * y4
    o_s = -s5[:, None] * x4 + c5[:, None] * y4
    a_s = np.stack((c1 * s234, s1 * s234, -c234), axis=1)
    target = np.stack((n, o, a), axis=2)
    reached = np.stack((n_s, o_s, a_s), axis=2)
    m = np.einsum("nji,njk->nik", target, reached)
    vee = 0.5 * np.stack(
        (m[:, 2, 1] - m[:, 1, 2], m[:, 0, 2] - m[:, 2, 0], m[:, 1, 0] - m[:, 0, 1])
    )
    residual = np.arctan2(np.linalg.norm(vee, axis=0), 0.5 * (np.trace(m, axis1=1, axis2=2) - 1))
    return q, within, residual
