"""Run the bad-input corpus (:mod:`tests.badinput.corpus`) through the real CLI, in-process.

Every case must: exit with its code, write exactly one line to stderr that matches its pattern
(naming the offending key or value), show no traceback, and leave a previous complete output
folder byte-for-byte unchanged, with no staging debris next to it.
"""

from __future__ import annotations

import copy
import hashlib
import os
import re
import shutil
from pathlib import Path
from typing import Any

import pytest
import yaml

from lynxplan.cli import main
from lynxplan.scenarios.registry import KIND_MODULES
from tests.badinput.corpus import BASES, CLI, DELETE, FILES, SCENARIOS, C, F, S


@pytest.fixture(scope="session")
def previous_output(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A complete output folder of a real (fast) run, copied into each case's ``{out}``."""
    folder = tmp_path_factory.mktemp("previous")
    scenario = folder / "previous.yaml"
    scenario.write_text(yaml.safe_dump(BASES["parallel_ik"]))
    assert main(["run", str(scenario), "--out", str(folder / "out"), "--quick"]) == 0
    return folder / "out"


def _snapshot(folder: Path) -> dict[str, str]:
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def _check(
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    out: Path,
    argv: list[str],
    code: int,
    *patterns: str,
) -> None:
    before = _snapshot(out)
    got = main(argv)
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    assert err.count("\n") == 1 and err.endswith("\n"), f"not one line: {err!r}"
    for pattern in patterns:
        assert re.search(pattern, err), f"{err!r} does not match {pattern!r}"
    assert got == code, f"exit {got}, expected {code}: {err}"
    assert _snapshot(out) == before, "the previous output folder changed"
    debris = [p.name for p in out.parent.iterdir() if ".staging" in p.name]
    assert not debris, debris


@pytest.fixture
def out(tmp_path: Path, previous_output: Path) -> Path:
    folder = tmp_path / "out"
    shutil.copytree(previous_output, folder)
    return folder


def _fill(argv: tuple[str, ...], tmp_path: Path, out: Path) -> list[str]:
    return [a.replace("{out}", str(out)).replace("{tmp}", str(tmp_path)) for a in argv]


def _case_id(case: C) -> str:
    text = " ".join(case.argv)
    return text if len(text) <= 60 else text[:57] + "..."


_CLI_PARAMS = [
    pytest.param(c, marks=pytest.mark.xfail(reason=f"known gap: {c.xfail}")) if c.xfail else c
    for c in CLI
]


@pytest.mark.parametrize("case", _CLI_PARAMS, ids=[_case_id(c) for c in CLI])
def test_cli_case(capsys, tmp_path: Path, out: Path, case: C) -> None:
    _check(capsys, tmp_path, out, _fill(case.argv, tmp_path, out), case.code, case.pattern)


_PATH_PART = re.compile(r"([^.\[\]]+)|\[(\d+)\]")


def _edited(base: dict[str, Any], edit: dict[str, Any]) -> dict[str, Any]:
    doc = copy.deepcopy(base)
    for path, value in edit.items():
        parts: list[str | int] = [
            name if name else int(index) for name, index in _PATH_PART.findall(path)
        ]
        parent: Any = doc
        for part in parts[:-1]:
            parent = parent[part]
        if value is DELETE:
            del parent[parts[-1]]
        elif isinstance(parts[-1], int):
            parent[parts[-1]] = value
        else:
            parent[parts[-1]] = value
    return doc


def _scenario_id(case: S) -> str:
    (path, value), *_ = case.edit.items()
    shown = "DELETE" if value is DELETE else repr(value)
    shown = shown if len(shown) <= 30 else shown[:27] + "..."
    return f"{case.kind}:{path}={shown}"


def _dump(doc: dict[str, Any]) -> str:
    return yaml.safe_dump(doc, sort_keys=False, width=1000)  # NaN/inf as .nan/.inf


@pytest.mark.parametrize("case", SCENARIOS, ids=[_scenario_id(c) for c in SCENARIOS])
def test_scenario_case(capsys, tmp_path: Path, out: Path, case: S) -> None:
    if case.kind not in KIND_MODULES:
        pytest.skip(f"scenario kind {case.kind!r} is not registered on this branch yet")
    scenario = tmp_path / f"bad_{case.kind}.yaml"
    scenario.write_text(_dump(_edited(BASES[case.kind], case.edit)), encoding="utf-8")
    argv = ["run", str(scenario), "--out", str(out), "--quick"]
    where = rf"^lynxplan: error: scenario {re.escape(str(scenario))}"
    _check(capsys, tmp_path, out, argv, case.code, where, case.pattern)


@pytest.mark.parametrize("case", FILES, ids=[c.name for c in FILES])
def test_file_case(capsys, tmp_path: Path, out: Path, case: F) -> None:
    if case.mode is not None and os.geteuid() == 0:
        pytest.skip("root reads files without read permission")
    scenario = tmp_path / case.name
    scenario.write_bytes(case.content)
    if case.mode is not None:
        scenario.chmod(case.mode)
    argv = ["run", str(scenario), "--out", str(out)]
    pattern = rf"^lynxplan: error: scenario {re.escape(str(scenario))}.*{case.pattern}"
    _check(capsys, tmp_path, out, argv, case.code, pattern)


def test_every_base_scenario_is_valid(capsys, tmp_path: Path) -> None:
    """The corpus' base documents are valid: each case fails because of its one edit."""
    for kind, base in BASES.items():
        if kind not in KIND_MODULES:
            continue
        scenario = tmp_path / f"{kind}.yaml"
        scenario.write_text(_dump(base))
        assert main(["validate", str(scenario)]) == 0, capsys.readouterr().err


def test_every_registered_kind_has_a_base() -> None:
    """Every scenario kind is in the corpus: a new kind needs a base document in BASES."""
    missing = sorted(set(KIND_MODULES) - set(BASES))
    assert not missing, f"add a base document (and bad-value keys) to corpus.py for {missing}"


def test_corpus_size() -> None:
    assert len(CLI) + len(SCENARIOS) + len(FILES) >= 300
