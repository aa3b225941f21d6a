"""Typed results of the AL5's IK (one pose): the branches, the selected-branch rule and the
result type are every arm's (:mod:`lynxplan.branches`)."""

from __future__ import annotations

from lynxplan.branches import Branch, IkResult, IkSolution, selected_q

__all__ = ["SOLVER", "Branch", "IkResult", "IkSolution", "selected_q"]

#: The solver's name in the AL5's results (``IkResult.solver``).
SOLVER = "AL5 closed form"
