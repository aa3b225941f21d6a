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
#: An approach whose horizontal part is shorter than this [1] does not lean: on the base axis
#: the base angle then keeps its reference (the AL5's closed form).
APPROACH_LEANS = 1e-9
#: Below this rotation angle [rad] the rotation error is its series asin(x) = x + x^3 / 6
#: (exact to ~1e-21 rad; the AL5's closed form).
SMALL_ROTATION_SERIES = 1e-4

#: Default accepted orientation residual for strict IK, in [rad].
STRICT_ORIENTATION_TOLERANCE = 1e-6

#: The AL5 kernels of :mod:`lynxplan.arm`: a wrist centre up to this far outside the reachable
#: annulus is pulled onto it, in [m] (poses typed from a 4-decimal inch printout are off by
#: ~1e-6 m); further is out of reach. Not :data:`REACH_TOLERANCE` (a branch's position error,
#: 1e-9 m): this one admits a typed pose, that one judges a computed branch.
WRIST_SNAP_TOLERANCE = 1e-6

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


# -- inverse kinematics of serial arms (lynxplan.robots) -------------------------------------
# Every tolerance of the IK solvers (the kernels read them as compile-time constants). Two
# tolerances of different quantities keep different names, never one name with two values.

#: The AL5 URDF's DH structure (rotations, zero offsets) must match to this, unitless / [m].
URDF_STRUCTURE_TOLERANCE = 1e-9

#: A branch reaches its target when FK puts the tool this close to the target position [m].
REACH_TOLERANCE = 1e-9

#: Target rotation blocks further than this from orthonormal are re-orthonormalised (up to the
#: guards' repair tolerance; beyond it they are refused).
ORTHONORMAL_TOLERANCE = 1e-12

#: Largest angle by which a URDF's axes may miss parallel/perpendicular and still count as the
#: yaw-pitch-pitch-pitch-roll family [rad].
FAMILY_AXIS_TOLERANCE = 1e-3

#: Deviations below this count as exact (no polishing on the exact model needed) [rad].
FAMILY_EXACT_TOLERANCE = 1e-12

#: A tool point closer than this to the roll axis is on it [m].
ON_AXIS_TOLERANCE = 1e-12

#: Newton polish of a family branch on the exact chain (``family_polish``: roll search,
#: approach and pitch targets, near-family models): it stops once the largest of its five
#: conditions (position [m], in-plane and roll conditions [1]) is below this, and a tentative
#: root is a branch only if its polish gets there.
POLISH_CONDITION_TOLERANCE = 1e-14

#: Gauss-Newton polish of a full-pose branch (``pose_kernel``, ``pose_block``): it stops once the
#: largest component of the 6-vector pose error (position [m], small rotation [rad]) is below
#: this. Not :data:`POLISH_CONDITION_TOLERANCE`: another quantity, and one ulp-level step of
#: either changes the last bits of the branches the tests and benchmarks pin.
POSE_POLISH_TOLERANCE = 1e-15

#: A branch reaches a full pose exactly within this position [m] and orientation [rad] error.
POSE_EXACT = 1e-9

#: A single-pose IK target whose rotation block is this close to orthonormal (and the last row
#: to 0 0 0 1) is taken as it is (``pose_kernel.pose_one``).
RIGID_TOLERANCE = 1e-12

#: A candidate is taken by the vector path when its final position [m] and orientation [rad]
#: errors are both below this; otherwise it is rejected (below) or finished by the scalar polish.
VECTOR_EXACT = 1e-14

#: Two branches closer than this in every joint are one [rad].
BRANCH_DUPLICATE_TOLERANCE = 1e-9

#: The held polish must reach the position and in-plane conditions this closely [m], [1]
#: (next to a fold of the elbow Newton converges only linearly; the roots are polished again);
#: otherwise the branch does not exist at this roll and the equation is undefined (NaN).
HELD_TOLERANCE = 1e-9

#: A numerical IK solution (``robots/ik/numerical``) must reach the target position within this
#: [m] ...
NUMERICAL_POSITION_TOLERANCE = 1e-10

#: ... and the target orientation (or approach axis) within this [rad].
NUMERICAL_ORIENTATION_TOLERANCE = 1e-9
#: Levenberg-Marquardt stops iterating when the pose error's norm falls below this [m, rad].
NUMERICAL_CONVERGED = 1e-13
#: The near-axis rescue starts the numerical solver only where a branch came this close to the
#: target position [m] (a polish that failed near a double root).
RESCUE_NEAR_MISS = 1e-4
#: ``Robot.ik(verify=True)``: Pinocchio's FK and the solver's agree to this [m].
PINOCCHIO_AGREEMENT = 1e-12

#: A local extremum of the roll equation this close to zero is a double root (f is the sine of
#: a roll mismatch or an axis component: 1e-10 means 1e-10 rad).
TANGENT_TOLERANCE = 1e-10

#: Roots where the tool point misses the yaw circle by more than this [m] are not solutions
#: (more than the ~1e-7 m the exact model differs from the ideal one by).
CLAMPED_ROOT_TOLERANCE = 1e-6

#: Roots of the exact equation are refined until a step is below this [rad].
EXACT_ROOT_STEP = 1e-9

#: The reach boundary of an exact branch is located to this [rad].
BOUNDARY_TOLERANCE = 1e-7

# -- the vectorised full-pose solver (``robots/ik/pose_block`` and its ``block_*`` modules) --

#: A candidate whose final position [m] or orientation [rad] error is above this and has
#: stopped falling (at least BLOCK_STALLED times the error before the last step) is not an
#: exact branch: the orientation is out of reach on that flip, and the steps end at the residual
#: of the nearest orientation (~1e-4), as the scalar polish does, which rejects it too. A
#: candidate still falling there, or next to a fold of the elbow (where Newton's steps converge
#: only linearly: the roots are close), is finished by the scalar polish.
BLOCK_NOT_A_BRANCH = 1e-6
#: ... (the ratio to the error before the last step) [1].
BLOCK_STALLED = 0.5
#: Next to a fold: |cos| of the elbow angle within this of 1 (an elbow ~0.045 rad from straight).
BLOCK_FOLD_BAND = 1e-3
#: A candidate whose step is this ill-conditioned (``newton_ldl``: smallest over largest LDL^T
#: pivot of J^T J; ``newton_parallel``: its two measures) is finished by the scalar polish [1].
BLOCK_ILL_CONDITIONED = 1e-8
#: Pitch axes parallel within this [rad] (and either sign) take ``newton_parallel``'s steps:
#: the same Gauss-Newton step to ~1e-10 of its size, by the family's structure.
BLOCK_PARALLEL_PITCHES = 1e-10
#: The polish's steps [rad] up to which the sines and cosines of the new angles follow exactly
#: (to rounding) from those of the old by their Taylor series (``turn``); a candidate with a
#: larger step is finished by the scalar polish.
BLOCK_TAYLOR_STEP = 1e-3
#: ... and up to which a candidate may be found not to be a branch: there the sines and cosines
#: are within FAR_STEP^6 / 720 (1.4e-9) of the exact ones, far below BLOCK_NOT_A_BRANCH [rad].
BLOCK_FAR_STEP = 0.1
#: The margin [m per m of distance from the yaw axis] of the test that leaves a flip out
#: (``screen_flips``): ~1e5 times the rounding of the yaws it bounds.
BLOCK_OTHER_MARGIN = 1e-9
#: Both flips are computed where the approach's component along the yaw axis [1] or the
#: target's distance from it [m] is within this of 0 (the pitch sum or yaw may be degenerate).
BLOCK_OTHER_DEGENERATE = 1e-9

# -- the IK solvers' tolerances and thresholds (moved from their modules, same values) --

#: Where the ideal branch misses the target by more than this [m] the exact one (~1e-7 m away)
#: cannot reach it either: undefined without a polish.
REACH_MARGIN = 1e-6
#: The chord method keeps its Jacobian while each step divides the conditions by 1 / CHORD_RATE.
CHORD_RATE = 1e-3
#: Finite-difference step of the Jacobian of the conditions [rad].
POLISH_FD_STEP = 1e-7
#: The yaw one side of the lateral offset gives must match the orientation's within this [rad],
#: plus YAW_MATCH_LENGTH / (distance from the yaw axis) (the ideal model's tool point differs
#: from the exact chain's by ~1e-6 m for the SO-101, which turns the yaw more near the axis),
#: and within YAW_MATCH_DEVIATIONS times what the model's deviation from the ideal family can
#: move it (``yaw_match``): the yaw of the other flip misses by twice the lateral offset over
#: the distance (~4e-4 m / rho for the SO-101), the exact branches' by < 8 deviations (1e6 poses).
YAW_MATCH, YAW_MATCH_LENGTH = 1e-3, 1e-4
YAW_MATCH_DEVIATIONS = 30.0
#: The deviation the yaw match assumes at least [rad] (an exact model's rounding).
MIN_DEVIATION = 1e-9
#: The approach this close to the yaw axis leaves the yaw to the position: root search.
AXIAL_APPROACH = 1e-6
#: A closed-form branch that misses the reach by more than this [m] is not polished.
REACH_MISS = 1e-5
#: An iteration must divide the error by at least this much, or the polish stops: from a
#: closed-form start it falls quadratically (1e-6, 1e-12, ...), next to a fold of the elbow
#: (a double root: the error ~ the square of the joint gap, which Newton halves) by ~4 per
#: step; a start that is not near an exact branch falls slower and stops early.
MIN_FALL = 2.0
#: Below this the target is on the yaw axis, or the approach along the pitch axis [m], [1]:
#: there the angle form (with its reference angles) is used.
ROLL_DEGENERATE = 1e-12
#: Near-roots of the ideal model (|f| below this at a local extremum) are tried on the exact one.
NEAR_ROOT = 5e-3
#: A model only close to the family: where the ideal equation is below this many times the
#: model's deviation (times 1 + d / rho, d the target's distance from the shoulder, rho the
#: wrist circle's radius), the roots are searched on the exact chain (``exact_roll_equation.py``).
EXACT_BAND = 16.0
#: Roots of the two elbows' exact equations closer than this are one root [rad] (each elbow's
#: branch is then polished from it).
ROOT_MERGE = 1e-6
#: Brent's minimisation: relative and absolute tolerance on the minimiser [rad].
BRENT_RELATIVE, BRENT_ABSOLUTE = 1.5e-8, 1e-11
#: The Illinois refinement of a root stops when its bracket is narrower than this [rad], or
#: than ROOT_BRACKET_RELATIVE times (1 + |root|) (a few units in the last place).
ROOT_BRACKET, ROOT_BRACKET_RELATIVE = 1e-15, 4e-16
#: Targets this much closer to the yaw axis than the wrist's lateral offset plus the tool's
#: off-axis distance are "near the axis" [m]: there the yaw is so sensitive that a model only
#: close to the family (SO-101) can hide a root of the exact model from the ideal one.
NEAR_AXIS_MARGIN = 0.01
#: Elbow cosines this close to +-1 are +-1 (a straight or folded elbow).
FOLD_SNAP_TOLERANCE = 1e-14
#: A model only close to the family, its elbow cosine within this of +-1 (near a fold): the
#: closed form starts the two elbows at least FOLD_START_GAP [rad] apart, and Newton then finds
#: each exact root (they are ~sqrt(deviation) apart) [1], [rad].
FOLD_START_BAND, FOLD_START_GAP = 1e-6, 2e-3
#: Translations beyond this, in [m], are out of reach before any arithmetic can overflow.
FAR_AWAY = 1e9
