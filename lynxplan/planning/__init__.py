"""Motion planning in joint space (OMPL's split): space, validity checker, planner, simplifier.

- :mod:`~lynxplan.planning.space`: joint limits, distance, interpolation;
- :mod:`~lynxplan.planning.validity`: fast conservative state/edge test (numba);
- :mod:`~lynxplan.planning.rrt_connect`: bidirectional RRT-Connect with goal biasing (numba);
- :mod:`~lynxplan.planning.shortcut`: shortcutting and smoothing, re-validated after every cut;
- :mod:`~lynxplan.planning.problem`: start and goals (configuration, pose, position+approach);
- :mod:`~lynxplan.planning.verify`: exact verification with coal;
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
