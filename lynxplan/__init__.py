"""lynxplan: modelling and planning for small robot arms and planar parallel robots.

``import lynxplan`` is cheap; the arm model (numba, Pinocchio) loads on first use of
:func:`load_arm`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from lynxplan.exceptions import LynxplanError

if TYPE_CHECKING:
    from lynxplan._jit import CompileWarning
    from lynxplan.arm.model import Arm, load_arm
    from lynxplan.planning.planner import PlannedTrajectory, plan
    from lynxplan.robots import Robot, load_robot
    from lynxplan.scenarios.runner import run_scenario

__all__ = [
    "Arm",
    "CompileWarning",
    "LynxplanError",
    "PlannedTrajectory",
    "Robot",
    "__version__",
    "load_arm",
    "load_robot",
    "plan",
    "run_scenario",
]


#: Lazy public name -> the module that defines it.
_HOMES = {
    "load_arm": "lynxplan.arm.model",
    "Arm": "lynxplan.arm.model",
    "load_robot": "lynxplan.robots",
    "Robot": "lynxplan.robots",
    "plan": "lynxplan.planning.planner",
    "PlannedTrajectory": "lynxplan.planning.planner",
    "run_scenario": "lynxplan.scenarios.runner",
    "CompileWarning": "lynxplan._jit",
}


def __getattr__(name: str) -> Any:
    """Lazy attributes: ``__version__`` (the installed distribution's, read from its metadata:
    pyproject.toml is the one place it is written), ``load_arm``, ``Arm``, ``load_robot``,
    ``Robot``, ``run_scenario``, ``plan``, ``PlannedTrajectory``, ``CompileWarning``."""
    if name == "__version__":
        from importlib.metadata import PackageNotFoundError, version

        try:
            return version("lynxplan")
        except PackageNotFoundError:  # a source tree on sys.path, no installed distribution
            return "0+unknown"
    if name in _HOMES:
        import importlib

        return getattr(importlib.import_module(_HOMES[name]), name)
    raise AttributeError(f"module 'lynxplan' has no attribute {name!r}")
