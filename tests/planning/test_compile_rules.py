"""The rule that keeps the planner's kernels without reference counting safe.

A kernel compiled with ``njit_no_refcount`` takes and drops no references; numba compiles a
callee that sets no ``_nrt`` with its first caller's setting. A compiled function that returns
an array must therefore say ``njit_refcounted``: compiled without reference counting it would
hand its caller a view without a reference, which the caller then drops (memory freed early).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PLANNING = Path(__file__).resolve().parents[2] / "lynxplan" / "planning"


def _compiled_functions() -> list[tuple[str, ast.FunctionDef, list[str]]]:
    found = []
    for path in sorted(PLANNING.glob("*.py")):
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if isinstance(node, ast.FunctionDef):
                decorators = [ast.unparse(d) for d in node.decorator_list]
                if any("njit" in d for d in decorators):
                    found.append((path.name, node, decorators))
    return found


def test_the_planner_has_kernels_without_reference_counting() -> None:
    kinds = [d for _, _, decorators in _compiled_functions() for d in decorators]
    assert sum("njit_no_refcount" in d for d in kinds) >= 10


def _returns_array(node: ast.FunctionDef) -> bool:
    return node.returns is not None and "ndarray" in ast.unparse(node.returns)


@pytest.mark.parametrize(
    ("module", "name", "decorators"),
    [(m, node.name, d) for m, node, d in _compiled_functions() if _returns_array(node)],
)
def test_a_kernel_returning_an_array_counts_its_references(
    module: str, name: str, decorators: list[str]
) -> None:
    assert any(d.startswith("njit_refcounted") for d in decorators), (module, name, decorators)
