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

#: Stationary (zero-length) segments chosen by auto-timing last this long, in [s].
MIN_SEGMENT_DURATION = 1e-3

#: Uniform grid of the path parameter s (0..1) on which a straight line's joint path is solved
#: once: its finite differences give dq/ds and d2q/ds2 (auto-timing, sampled rates, toppra).
PATH_GRID_POINTS = 401

#: Sampled velocities/accelerations may exceed a limit by this relative amount before it counts
#: as a violation (floating-point noise only; toppra's real overshoots are larger and reported).
LIMIT_CHECK_RELATIVE_TOLERANCE = 1e-6

#: Parallel robot: an assembly mode is accepted when the IK of the pose reproduces the given
#: actuated angles to this, in [rad].
PARALLEL_FK_VERIFY_TOLERANCE = 1e-7

#: Parallel robot: a root ``z`` of the closure polynomial is taken as a real orientation when
#: ``| |z| - 1 |`` is below this (double roots at Type II singularities split by ~sqrt(eps)).
PARALLEL_FK_UNIT_CIRCLE_TOLERANCE = 1e-5

#: Parallel robot: two assembly modes closer than this (in [m] and [rad]) are the same one.
PARALLEL_FK_DUPLICATE_TOLERANCE = 1e-7

#: Agreement of most (95 %) python-fcl (libccd GJK) distances with coal's for the arm's
#: primitives, in [m]; the rest are over-estimated by up to millimetres (FCL issue #508).
FCL_DISTANCE_TOLERANCE = 3e-5

#: Resolved-rate runs: the tool counts as having completed the path once the reference is at its
#: end and the tool point is within this distance of it, in [m].
COMPLETION_TOLERANCE = 1e-3

#: Resolved-rate runs stop after this many times the path duration (plus the hold): a
#: speed-limited run may slow the path down, never without bound.
RESOLVED_RATE_MAX_TIME_FACTOR = 20.0

#: GJK/EPA tolerance of the coal distance queries (coal's default 1e-6 leaves ~1e-6 m error on
#: cylinders; this gives ~1e-9 m).
COAL_GJK_TOLERANCE = 1e-9
