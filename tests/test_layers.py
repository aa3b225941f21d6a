"""The dependency arrows point one way: cli -> scenarios -> domain -> core.

Domain packages take and return arrays and typed values: they never import pydantic, YAML, the
scenario layer or the command line (checked on the source, imports inside functions included).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "lynxplan"
DOMAIN = ["arm", "trajectory", "collision", "parallel", "singularity", "planning"]
FORBIDDEN_IN_DOMAIN = (
    "pydantic",
    "yaml",
    "lynxplan.scenarios",
    "lynxplan.task",
    "lynxplan.cli",
    "lynxplan.commands",
    "lynxplan.service",
)


def _imports(path: Path) -> set[str]:
    names = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            names |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
    return names


@pytest.mark.parametrize("package", DOMAIN)
def test_domain_packages_do_not_import_the_layers_above(package):
    offenders = {
        f"{path.relative_to(PACKAGE)}: {name}"
        for path in (PACKAGE / package).rglob("*.py")
        for name in _imports(path)
        if name.startswith(FORBIDDEN_IN_DOMAIN)
    }
    assert not offenders, sorted(offenders)


def test_the_scenario_layer_does_not_import_the_command_line():
    offenders = {
        f"{path.relative_to(PACKAGE)}: {name}"
        for folder in ("scenarios", "task")
        for path in (PACKAGE / folder).rglob("*.py")
        for name in _imports(path)
        if name.startswith(("lynxplan.cli", "lynxplan.commands"))
    }
    assert not offenders, sorted(offenders)
