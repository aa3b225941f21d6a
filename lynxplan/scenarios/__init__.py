"""The scenario layer: one contract for every scenario kind.

- :mod:`~lynxplan.scenarios.base`: the input base model, a kind's output, the frozen result;
- :mod:`~lynxplan.scenarios.registry`: kind name -> module;
- :mod:`~lynxplan.scenarios.expect`: the one ``expect:`` parser;
- :mod:`~lynxplan.scenarios.report`: the one JSON writer and the report's JSON Schema;
- :mod:`~lynxplan.scenarios.outputs`: output folders written all at once, the trajectory CSV;
- :mod:`~lynxplan.scenarios.runner`: load -> validate -> run -> check -> write;
- one module per kind: ``task``, ``trajectory``, ``workspace``, ``singularity``,
  ``parallel_ik``, ``parallel_workspace``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from lynxplan.scenarios.base import Result
    from lynxplan.scenarios.runner import LoadedScenario, load_scenario, run_scenario

__all__ = ["LoadedScenario", "Result", "load_scenario", "run_scenario"]


def __getattr__(name: str) -> Any:
    """Lazy attributes, so that ``import lynxplan.scenarios`` stays cheap."""
    if name in ("LoadedScenario", "load_scenario", "run_scenario"):
        from lynxplan.scenarios import runner

        return getattr(runner, name)
    if name == "Result":
        from lynxplan.scenarios.base import Result

        return Result
    raise AttributeError(f"module 'lynxplan.scenarios' has no attribute {name!r}")
