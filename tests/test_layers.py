"""The dependency arrows point one way: cli -> scenarios -> domain -> core, and no import cycle
anywhere in the package (the IK solvers never import the Robot).

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


# -- import cycles ----------------------------------------------------------------------------
# A module imports another when any import statement names it (module level, inside a function,
# or under TYPE_CHECKING alike: each is an arrow a reader has to follow). The cycles are the
# strongly connected components of that graph with more than one module (Tarjan).


def _modules(root: Path) -> dict[str, Path]:
    """Dotted module name -> file, for every module of the package at ``root``."""
    out = {}
    for path in root.rglob("*.py"):
        name = ".".join(path.with_suffix("").relative_to(root.parent).parts)
        out[name.removesuffix(".__init__")] = path
    return out


def _import_graph(modules: dict[str, Path]) -> dict[str, set[str]]:
    """Module -> the package's modules it imports (a package's ``__init__`` is not an edge)."""
    graph: dict[str, set[str]] = {name: set() for name in modules}
    for name, path in modules.items():
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base = ".".join(parts + ([base] if base else []))
                targets = [base] + [f"{base}.{alias.name}" for alias in node.names]
            else:
                continue
            for imported in targets:
                target = imported
                while target and target not in modules:
                    target = target.rsplit(".", 1)[0] if "." in target else ""
                if target and target != name and modules[target].name != "__init__.py":
                    graph[name].add(target)
    return graph


def import_cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module, each sorted (iterative
    Tarjan: no recursion limit on a deep package)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    for root, imported in graph.items():
        if root in index:
            continue
        work = [(root, iter(sorted(imported)))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            v, children = work[-1]
            w = next(children, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                elif w in on_stack:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                component = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    component.append(w)
                    if w == v:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def test_the_cycle_finder_finds_a_cycle_and_only_cycles():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": {"f"}, "f": set()}
    assert import_cycles(graph) == [["a", "b", "c"]]
    assert import_cycles({"a": {"b"}, "b": set()}) == []


def test_the_cycle_finder_sees_imports_inside_functions_and_type_checking(tmp_path):
    package = tmp_path / "pkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "low.py").write_text("def f():\n    from pkg.high import g\n")
    (package / "high.py").write_text(
        "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from . import low\n"
    )
    assert import_cycles(_import_graph(_modules(package))) == [["pkg.high", "pkg.low"]]


def test_no_import_cycle_anywhere_in_the_package():
    cycles = import_cycles(_import_graph(_modules(PACKAGE)))
    assert not cycles, [" <-> ".join(c) for c in cycles]


def test_the_ik_solvers_never_import_the_robot():
    """The solvers take a plain kinematic description (chain, family, limits), never the Robot
    (imports under TYPE_CHECKING count too)."""
    graph = _import_graph(_modules(PACKAGE))
    solvers = [name for name in graph if name.startswith("lynxplan.robots.ik.")]
    assert "lynxplan.robots.ik.family_solver" in solvers
    offenders = [name for name in solvers if "lynxplan.robots.robot" in graph[name]]
    assert not offenders, offenders


def test_every_ik_tolerance_is_named_once_in_lynxplan_constants():
    """The IK packages (robots, arm) define no tolerance of their own: each is a named constant
    of :mod:`lynxplan.constants` (one name, one value; two values are two names)."""
    own = {
        f"{path.relative_to(PACKAGE)}: {target.id}"
        for folder in ("robots", "arm")
        for path in (PACKAGE / folder).rglob("*.py")
        for node in ast.parse(path.read_text(encoding="utf-8")).body
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Constant)
        for target in node.targets
        if isinstance(target, ast.Name) and "TOLERANCE" in target.id
    }
    assert not own, sorted(own)
    # nor a tolerance written as a number in a test of the solvers (underflow guards aside)
    solvers = [*(PACKAGE / "robots" / "ik").glob("*.py"), *(PACKAGE / "arm").glob("ik*.py")]
    literal = [
        f"{path.relative_to(PACKAGE)}:{node.lineno} {ast.unparse(node)}"
        for path in solvers
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
        if isinstance(node, ast.Compare)
        for value in ast.walk(node)
        if isinstance(value, ast.Constant)
        and isinstance(value.value, float)
        and 1e-100 < abs(value.value) < 1e-3
    ]
    assert len(solvers) >= 20
    assert not literal, literal
    from lynxplan import constants

    assert constants.REACH_TOLERANCE == 1e-9  # a computed branch reaches its target
    assert constants.WRIST_SNAP_TOLERANCE == 1e-6  # a typed AL5 pose is admitted


def test_the_robots_never_import_the_al5_package():
    """The generic robots and their solvers serve every arm: the AL5's own package
    (``lynxplan.arm``) builds on them and on the core modules they share (joint limits, IK
    branches, shipped files), never the other way round (imports inside functions and under
    TYPE_CHECKING count)."""
    graph = _import_graph(_modules(PACKAGE))
    robots = [name for name in graph if name.startswith("lynxplan.robots")]
    assert "lynxplan.robots.robot" in robots and "lynxplan.robots.ik.family_solver" in robots
    offenders = {
        f"{name}: {target}"
        for name in robots
        for target in graph[name]
        if target.startswith("lynxplan.arm")
    }
    assert not offenders, sorted(offenders)
