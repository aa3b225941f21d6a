"""The registry of scenario kinds: kind name -> module (imported lazily, on first use).

Adding a kind is one module ``lynxplan/scenarios/<kind>.py`` (see :mod:`lynxplan.scenarios.base`)
and one line here (or a call to :func:`register_kind` from outside the package).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from lynxplan.exceptions import ScenarioError

if TYPE_CHECKING:  # the registry is read by every CLI start: keep pydantic out of it
    from lynxplan.scenarios.base import ScenarioKind

#: Scenario kind -> module defining ``NAME``, ``Input``, ``run`` and ``write_outputs``.
KIND_MODULES: dict[str, str] = {
    "workspace": "lynxplan.scenarios.workspace",
    "trajectory": "lynxplan.scenarios.trajectory",
    "task": "lynxplan.scenarios.task",
    "parallel_ik": "lynxplan.scenarios.parallel_ik",
    "parallel_workspace": "lynxplan.scenarios.parallel_workspace",
    "singularity": "lynxplan.scenarios.singularity",
    "plan": "lynxplan.scenarios.plan",
}


def register_kind(name: str, module: str) -> None:
    """Register scenario kind ``name`` implemented by the importable ``module``."""
    KIND_MODULES[name] = module


def kinds() -> list[str]:
    """Registered kind names, sorted."""
    return sorted(KIND_MODULES)


def kind_module(kind: Any, origin: str = "<scenario>") -> ScenarioKind:
    """The module implementing ``kind``.

    Raises:
        ScenarioError: naming the valid kinds if ``kind`` is unknown.
    """
    if not isinstance(kind, str) or kind not in KIND_MODULES:
        what = "missing" if kind is None else f"unknown kind {kind!r}"
        raise ScenarioError(origin, "kind", f"{what}; valid kinds: {', '.join(kinds())}")
    module: Any = importlib.import_module(KIND_MODULES[kind])
    return module  # type: ignore[no-any-return]
