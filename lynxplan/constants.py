"""Named numerical tolerances, in one place. SI units: metres, radians."""

#: Joint angles within this distance outside a limit are snapped onto it, in [rad].
#: Poses typed from a 4-decimal printout land a hair outside (report: q5 = -0.002 deg).
LIMIT_SNAP_TOLERANCE = 1e-4

#: A 4x4 rotation part with ``max |R^T R - I|`` up to this is re-orthonormalised; worse is rejected.
RIGIDITY_REPAIR_TOLERANCE = 1e-3

#: ``acos`` arguments within this of +-1 are clamped (elbow stretched or folded).
ACOS_CLAMP_TOLERANCE = 1e-9

#: Tool point this close to the base axis is treated as on it, in [m].
BASE_AXIS_TOLERANCE = 1e-9

#: Default accepted orientation residual for strict IK, in [rad].
STRICT_ORIENTATION_TOLERANCE = 1e-6

#: A wrist centre up to this far outside the reachable annulus is pulled onto it, in [m]
#: (poses typed from a 4-decimal inch printout are off by ~1e-6 m); further is out of reach.
REACH_TOLERANCE = 1e-6
