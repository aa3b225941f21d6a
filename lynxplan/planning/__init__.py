"""Motion planning in joint space (OMPL's split): space, validity checker, planner, simplifier.

- :mod:`~lynxplan.planning.space`: joint limits, sampling, distance, interpolation;
- :mod:`~lynxplan.planning.validity`: the checker (a state's pair bounds, quick point tests);
  :mod:`~lynxplan.planning.pair_bound` its one conservative pair bound (scalar and vectorised),
  :mod:`~lynxplan.planning.edge_walk` the one module that decides "free" for an edge
  (conservative advancement, with the motion bounds of :mod:`~lynxplan.planning.motion`);
- :mod:`~lynxplan.planning.rrt_connect`: bidirectional RRT-Connect with goal biasing (numba);
- :mod:`~lynxplan.planning.shortcut`: the simplifier's passes over the cuts of
  :mod:`~lynxplan.planning.cuts`, re-validated after every cut;
- :mod:`~lynxplan.planning.problem`: start and goals (configuration, pose, position+approach);
- :mod:`~lynxplan.planning.verify`: a returned path certified by the exact verifier
  (:mod:`lynxplan.collision.verify`), queried where :mod:`~lynxplan.planning.certify` schedules;
- :mod:`~lynxplan.planning.timing`: time-parameterisation (ruckig, LSPB, toppra);
- :mod:`~lynxplan.planning.planner`: the pipeline and :func:`plan`.
"""

from lynxplan.planning.planner import (
    PlannedTrajectory,
    Planner,
    PlannerOptions,
    PlanningStats,
    plan,
)
from lynxplan.planning.problem import ApproachGoal, GoalSet, JointGoal, PoseGoal
from lynxplan.planning.verify import VerificationReport

__all__ = [
    "ApproachGoal",
    "GoalSet",
    "JointGoal",
    "PlannedTrajectory",
    "Planner",
    "PlannerOptions",
    "PlanningStats",
    "PoseGoal",
    "VerificationReport",
    "plan",
]
