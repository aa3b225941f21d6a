"""Trajectories: the report's LSPB time law, free and straight-line motion, plans, retiming."""

from lynxplan.trajectory.free import FreeSegment, JointSamples, free_segment
from lynxplan.trajectory.limits import DEFAULT_MAX_ACCELERATION, DEFAULT_MAX_JERK, MotionLimits
from lynxplan.trajectory.line import ORIENTATION_MODES, LineSegment, PathGrid, line_segment
from lynxplan.trajectory.lspb import LspbState, LspbTiming, lspb, lspb_since_start, unit_lspb
from lynxplan.trajectory.ok_task import (
    OK_TASK_WAYPOINTS,
    REPORT_TIMING,
    ok_task_configurations,
    ok_task_plan,
    ok_task_specs,
)
from lynxplan.trajectory.plan import (
    DEFAULT_SAMPLE_RATE,
    Plan,
    PlanSamples,
    SegmentReport,
    SegmentSpec,
    build_plan,
    segment_reports,
)
from lynxplan.trajectory.retime import (
    METHODS,
    PlanComparison,
    Profile,
    ProfileStats,
    SegmentComparison,
    compare_plan,
    compare_segment,
    profile_stats,
    ruckig_profile,
    toppra_profile,
)
from lynxplan.trajectory.timing import auto_timing_linear, auto_timing_path

__all__ = [
    "DEFAULT_MAX_ACCELERATION",
    "DEFAULT_MAX_JERK",
    "DEFAULT_SAMPLE_RATE",
    "METHODS",
    "OK_TASK_WAYPOINTS",
    "ORIENTATION_MODES",
    "REPORT_TIMING",
    "FreeSegment",
    "JointSamples",
    "LineSegment",
    "LspbState",
    "LspbTiming",
    "MotionLimits",
    "PathGrid",
    "Plan",
    "PlanComparison",
    "PlanSamples",
    "Profile",
    "ProfileStats",
    "SegmentComparison",
    "SegmentReport",
    "SegmentSpec",
    "auto_timing_linear",
    "auto_timing_path",
    "build_plan",
    "compare_plan",
    "compare_segment",
    "free_segment",
    "line_segment",
    "lspb",
    "lspb_since_start",
    "ok_task_configurations",
    "ok_task_plan",
    "ok_task_specs",
    "profile_stats",
    "ruckig_profile",
    "segment_reports",
    "toppra_profile",
    "unit_lspb",
]
