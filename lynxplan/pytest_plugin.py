"""pytest plugin: scenario YAML files as test items (``pytest scenarios/``).

Registered as the ``pytest11`` entry point ``lynxplan``. A YAML file with a top-level ``kind:``
key is collected when it was given on the command line or lies under a folder named
``scenarios``. Each file is one test item: the scenario runs with ``quick=True`` and no output
folder (no plots, HTML or files), and the item fails with the ``expect:`` entries that did not
hold, or with the scenario error (file, key path, reason).
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml

from lynxplan.exceptions import LynxplanError
from lynxplan.scenarios.base import Result

#: Folder name under which YAML files are collected without being named on the command line.
SCENARIO_FOLDER = "scenarios"


class ExpectationFailedError(AssertionError):
    """A scenario ran but some of its expectations did not hold.

    Attributes:
        path: The scenario file.
        outcome: What the run produced (its expectations, checked).
    """

    def __init__(self, path: Path, outcome: Result) -> None:
        self.path = path
        self.outcome = outcome
        lines = "\n".join(f"  - {failure}" for failure in outcome.failed_expectations)
        super().__init__(
            f"{path}: {len(outcome.failed_expectations)} expectation(s) failed:\n{lines}"
        )


def run_scenario_file(path: str | Path) -> Result:
    """Run a scenario the way the plugin does (quick, nothing written); returns its result."""
    from lynxplan.scenarios import run_scenario

    return run_scenario(path, None, quick=True)


def check_scenario_file(path: str | Path) -> Result:
    """Run a scenario and raise :class:`ExpectationFailedError` if an expectation fails.

    Raises:
        ExpectationFailedError: listing the failed expectations.
        ScenarioError: the file is invalid (file, key path, reason).
    """
    outcome = run_scenario_file(path)
    if not outcome.ok:
        raise ExpectationFailedError(Path(path), outcome)
    return outcome


def is_scenario_file(path: Path) -> bool:
    """A YAML mapping with a ``kind`` key (an unparsable YAML file counts: its error is shown)."""
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except yaml.YAMLError:
        return True
    except (OSError, UnicodeDecodeError):
        return False
    return isinstance(data, dict) and "kind" in data


def _under_scenario_folder(path: Path, root: Path) -> bool:
    try:
        parts = path.relative_to(root).parts
    except ValueError:
        parts = path.parts
    return SCENARIO_FOLDER in parts[:-1]


def pytest_collect_file(file_path: Path, parent: pytest.Collector) -> pytest.Collector | None:
    """Collect scenario YAML files (see the module docstring for which ones)."""
    if file_path.suffix not in (".yaml", ".yml"):
        return None
    explicit = parent.session.isinitpath(file_path)
    if not (explicit or _under_scenario_folder(file_path, parent.config.rootpath)):
        return None
    if not is_scenario_file(file_path):
        return None
    return ScenarioFile.from_parent(parent, path=file_path)


#: Scenario kinds that run the big numba kernels (IK and planner): a cold cache makes their
#: first run wait minutes (:data:`lynxplan._jit.NOTICE`).
COMPILING_KINDS = frozenset({"task", "plan"})


def pytest_collection_finish(session: pytest.Session) -> None:
    """Say once, before the scenarios run, that numba compiles the kernels they use when its
    cache has none of them (a first run after installation: minutes)."""
    kinds = {
        item.parent.kind
        for item in session.items
        if isinstance(item, ScenarioItem) and isinstance(item.parent, ScenarioFile)
    }
    if not kinds & COMPILING_KINDS:
        return
    from lynxplan import _jit

    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    if reporter is not None:
        _jit.announce_if_cold(lambda line: reporter.write_line(line, yellow=True))
    else:
        _jit.announce_if_cold(lambda line: print(line, file=sys.stderr, flush=True))


class ScenarioFile(pytest.File):
    """A scenario YAML file: one item."""

    @property
    def kind(self) -> Any:
        """The scenario's ``kind:`` (None when the file cannot be read)."""
        try:
            data = yaml.safe_load(self.path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, yaml.YAMLError):
            return None
        return data.get("kind") if isinstance(data, dict) else None

    def collect(self) -> Iterator[pytest.Item]:
        """The file's single scenario item."""
        yield ScenarioItem.from_parent(self, name="scenario")


class ScenarioItem(pytest.Item):
    """Runs one scenario (quick, no outputs) and checks its ``expect:`` block."""

    def runtest(self) -> None:
        """Run the scenario; ExpectationFailedError or a LynxplanError fails the item."""
        check_scenario_file(self.path)

    def repr_failure(self, excinfo: Any, style: Any = None) -> Any:
        """Failed expectations or the scenario error as plain lines, no traceback."""
        if isinstance(excinfo.value, (ExpectationFailedError, LynxplanError)):
            return str(excinfo.value)
        return super().repr_failure(excinfo)

    def reportinfo(self) -> tuple[Path, int, str]:
        """Location shown in reports."""
        return self.path, 0, f"scenario {self.path.name}"
