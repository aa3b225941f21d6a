"""Load, validate and run a scenario through the registry; check expectations; write outputs.

This is the one path every front end takes: ``lynxplan run``, the pytest plugin, the service and
:func:`lynxplan.run_scenario`.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from lynxplan.exceptions import LynxplanError, ScenarioError, ScenarioValueError
from lynxplan.scenarios.base import (
    SCHEMA_VERSION,
    ExpectationResult,
    KindOutput,
    Result,
    ScenarioKind,
    ScenarioModel,
)
from lynxplan.scenarios.expect import evaluate, parse_expectations
from lynxplan.scenarios.registry import kind_module
from lynxplan.scenarios.source import ScenarioSource, format_location, read_source


@dataclass(frozen=True)
class LoadedScenario:
    """A validated scenario and the kind module that runs it.

    Attributes:
        kind: The kind module.
        scenario: The validated, frozen input model.
        origin: File path or ``<mapping>``.
        source: The raw source (for the line numbers of run-time errors).
    """

    kind: ScenarioKind
    scenario: ScenarioModel
    origin: str
    source: ScenarioSource | None = None

    def located(self, exc: ScenarioValueError) -> ScenarioError:
        """A run-time scenario problem as a ScenarioError naming the file, key path and line."""
        if self.source is not None:
            return self.source.error(exc.loc, exc.reason)
        return ScenarioError(self.origin, format_location(exc.loc), exc.reason)


def validate(source: ScenarioSource) -> LoadedScenario:
    """Validate raw scenario data (no computation).

    Raises:
        ScenarioError: naming the origin, the key path with its line, and the reason.
    """
    module = kind_module(source.data.get("kind"), source.origin)
    try:
        scenario = module.Input.model_validate(source.data)
    except ValidationError as exc:
        first = _most_specific(exc.errors())
        message = first["msg"].removeprefix("Value error, ")
        loc = _data_path(source.data, tuple(first["loc"]), first["type"] == "missing")
        raise source.error(loc, message) from None
    return LoadedScenario(module, scenario, source.origin, source)


def _most_specific(errors: list[Any]) -> Any:
    """The error to show: for a value that matches no branch of a union (a number or a list),
    the branch whose type matched says more ("at least 5 items") than "not a number"."""
    for error in errors:
        if not str(error["type"]).endswith(("_type", "_parsing")):
            return error
    return errors[0]


def _data_path(data: Any, loc: tuple[Any, ...], missing: bool) -> tuple[int | str, ...]:
    """``loc`` without pydantic's union and validator tags: only the keys and indices found in
    the data (``limits.acceleration.list[...][1]`` -> ``limits.acceleration[1]``), plus the last
    key when it is a missing required one."""
    path: list[int | str] = []
    node = data
    for i, part in enumerate(loc):
        if (isinstance(node, dict) and part in node) or (
            isinstance(node, list) and isinstance(part, int) and 0 <= part < len(node)
        ):
            node = node[part]
            path.append(part)
        elif missing and i == len(loc) - 1:
            path.append(part)
    return tuple(path)


def load_scenario(source: str | Path | Mapping[str, Any]) -> LoadedScenario:
    """Read and validate a scenario file or mapping (no computation).

    Raises:
        ScenarioError: naming the file, the key path (and line) and the reason.
    """
    return validate(read_source(source))


def check_expectations(
    scenario: ScenarioModel, output: KindOutput
) -> tuple[ExpectationResult, ...]:
    """Evaluate the kind's default expectations and the file's ``expect:`` block."""
    block = {**type(scenario).default_expect, **scenario.expect}
    parsed = parse_expectations(block, type(scenario).metrics, scenario.units)
    results = []
    for item in parsed:
        note = output.notes.get(item.metric)
        if item.metric not in output.metrics:
            message = f"{item.key}: metric {item.metric!r} was not measured by this run"
            message += f" ({note})" if note else ""
            results.append(ExpectationResult(item.key, item.text, None, False, message))
        else:
            checked = evaluate(item, output.metrics[item.metric], scenario.units)
            if note and not checked.passed:
                checked = replace(checked, message=f"{checked.message} ({note})")
            results.append(checked)
    return tuple(results)


def execute(
    loaded: LoadedScenario,
    out_dir: str | Path | None = None,
    *,
    quick: bool = False,
    force: bool = False,
) -> Result:
    """Run a loaded scenario; write its outputs (all or nothing) into ``out_dir`` if given.

    The output folder is checked before the computation (a folder holding files lynxplan did not
    write is refused at once, see :mod:`lynxplan.scenarios.folders`), and the run works in a
    staging folder next to it from start to end.
    """
    if out_dir is None:
        return _compute(loaded, None, quick=quick)
    from lynxplan.scenarios.outputs import staged_outputs

    with staged_outputs(out_dir, force=force) as staging:
        return _compute(loaded, staging, quick=quick)


def _compute(loaded: LoadedScenario, staging: Path | None, *, quick: bool) -> Result:
    """Run the scenario; write its outputs and report.json into ``staging`` if given."""
    from lynxplan.scenarios.report import write_json

    start = time.perf_counter()
    try:
        output = loaded.kind.run(loaded.scenario, quick=quick)
    except ScenarioError:
        raise
    except ScenarioValueError as exc:
        raise loaded.located(exc) from exc
    except LynxplanError as exc:  # a run-time problem: say which file it came from
        raise ScenarioError(loaded.origin, "", str(exc)) from exc
    expectations = check_expectations(loaded.scenario, output)
    timing = {**output.stage_seconds, "run": time.perf_counter() - start}

    def result(artifacts: tuple[str, ...]) -> Result:
        return Result(
            kind=loaded.scenario.kind,
            schema_version=SCHEMA_VERSION,
            name=loaded.scenario.name,
            inputs=loaded.scenario.si_inputs(),
            metrics=dict(output.metrics),
            expectations=expectations,
            artifacts=artifacts,
            timing={**timing, "total": time.perf_counter() - start},
            details=dict(output.details),
            summary=output.summary,
            units=loaded.scenario.units.model_dump(),
            metric_quantities=dict(type(loaded.scenario).metrics),
        )

    if staging is None:
        return result(())
    from lynxplan.scenarios.report import result_dict

    written = loaded.kind.write_outputs(loaded.scenario, output, staging, quick=quick)
    final = result(tuple(sorted({*written, "report.json"})))
    write_json(staging / "report.json", result_dict(final))
    return final


def run_scenario(
    source: str | Path | Mapping[str, Any],
    out_dir: str | Path | None = None,
    *,
    quick: bool = False,
    force: bool = False,
) -> Result:
    """Load, validate and run a scenario; write its outputs into ``out_dir`` if given.

    Args:
        source: Scenario YAML file, or the scenario as a mapping.
        out_dir: Output folder, or None to write nothing. A complete run replaces lynxplan's
            previous outputs there as a whole; files lynxplan did not write are never touched.
        quick: Skip plots, HTML and the comparisons with peer time laws.
        force: Use ``out_dir`` even if it holds files lynxplan did not write (they stay; only
            lynxplan's own outputs are replaced).

    Returns:
        The run's :class:`Result`; ``result.ok`` tells whether every expectation held.

    Raises:
        ScenarioError: the scenario is invalid or cannot run (file, key path, reason).
    """
    return execute(load_scenario(source), out_dir, quick=quick, force=force)
