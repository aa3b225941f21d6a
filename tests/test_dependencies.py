"""Every package lynxplan/ imports is declared in pyproject.toml; one version string."""

from __future__ import annotations

import ast
import re
import sys
from importlib.metadata import packages_distributions, version
from pathlib import Path

import pytest

import lynxplan

tomllib = pytest.importorskip("tomllib")  # Python >= 3.11

ROOT = Path(__file__).resolve().parents[1]


def _imported_top_level_modules() -> set[str]:
    names: set[str] = set()
    for path in (ROOT / "lynxplan").rglob("*.py"):
        found: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                found.update(alias.name.split(".")[0] for alias in node.names)
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                found.add(node.module.split(".")[0])
        # Peer scripts run as plain scripts in their own venvs and import their siblings (the
        # benchmark suite's also import the shared lynxplan/bench/peers/common.py).
        local = {sibling.stem for sibling in path.parent.glob("*.py")}
        if path.parent.name == "peer_scripts":
            local |= {shared.stem for shared in (ROOT / "lynxplan/bench/peers").glob("*.py")}
        names |= found - local
    return names - set(sys.stdlib_module_names) - {"lynxplan", "__future__"}


def _normalise(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _declared() -> set[str]:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    requirements = list(project["dependencies"])
    for extra in project["optional-dependencies"].values():
        requirements += extra
    return {_normalise(re.split(r"[<>=!~\[; ]", r, maxsplit=1)[0]) for r in requirements}


#: Modules whose distribution the metadata does not map (cmeel wheels install under a prefix).
KNOWN = {
    "pinocchio": ["pin"],
    "example_robot_data": ["example-robot-data-loaders"],
    "pink": ["pin-pink"],  # a peer: installed only in its own venv
}


def test_every_imported_package_is_declared() -> None:
    distributions = {**packages_distributions(), **KNOWN}
    declared = _declared()
    # pytest: only the pytest plugin entry point imports it, and pytest is what loads it.
    missing = {
        module: distributions.get(module, ["?"])
        for module in _imported_top_level_modules() - {"pytest"}
        if not declared & {_normalise(d) for d in distributions.get(module, [module])}
    }
    assert not missing, f"imported but not declared in pyproject.toml: {missing}"


def test_version_comes_from_the_package_metadata() -> None:
    assert lynxplan.__version__ == version("lynxplan")
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert pyproject["project"]["version"] == lynxplan.__version__
