"""Planar 3-RRR parallel robot (SPEC Part 4): geometry, IK, FK, workspace, singularities.

Everything inside is SI ([m], [rad]); the CLI and scenario files use the report's mm and degrees.
"""

from lynxplan.parallel.fk import ParallelFKResult, nearest_assembly_mode, solve_fk, solve_fk_batch
from lynxplan.parallel.geometry import LEG_NAMES, ParallelGeometry, pose_from_mm_deg, pose_to_mm_deg
from lynxplan.parallel.ik import WORKING_MODES, ParallelIKResult, solve_ik, solve_ik_batch
from lynxplan.parallel.workspace import (
    OrientationStack,
    Workspace,
    constant_orientation_workspace,
    orientation_stack,
)

__all__ = [
    "LEG_NAMES",
    "WORKING_MODES",
    "OrientationStack",
    "ParallelFKResult",
    "ParallelGeometry",
    "ParallelIKResult",
    "Workspace",
    "constant_orientation_workspace",
    "nearest_assembly_mode",
    "orientation_stack",
    "pose_from_mm_deg",
    "pose_to_mm_deg",
    "solve_fk",
    "solve_fk_batch",
    "solve_ik",
    "solve_ik_batch",
]
