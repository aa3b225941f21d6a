"""Scenario -> results on disk, written atomically. No argument parsing, no printing."""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from lynxplan.exceptions import LynxplanError
from lynxplan.scenario import Outcome, load_scenario


def run_scenario(path: str | Path, out_dir: str | Path | None, *, quick: bool = False) -> Outcome:
    """Load, validate and run a scenario; write its outputs into ``out_dir``.

    Outputs are first written to a staging folder next to ``out_dir`` and moved in only when the
    run succeeded, so a failed run leaves an earlier run's outputs intact.

    Args:
        path: Scenario YAML file.
        out_dir: Output folder, or None to write nothing.
        quick: Skip slow outputs (plots, HTML); used by the pytest plugin.
    """
    module, scenario = load_scenario(path)
    if out_dir is None:
        return module.run(scenario, None, quick=quick)
    with staged_outputs(out_dir) as staging:
        return module.run(scenario, staging, quick=quick)


@contextmanager
def staged_outputs(out_dir: str | Path) -> Iterator[Path]:
    """A staging folder next to ``out_dir`` whose files move into ``out_dir`` only if the block
    succeeds; the staging folder is always removed.

    Raises:
        LynxplanError: if the folder cannot be created.
    """
    out = Path(out_dir)
    parent = out.resolve().parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.staging-", dir=parent))
    except OSError as exc:
        raise LynxplanError(f"cannot create output folder {out}: {exc.strerror}") from exc
    try:
        yield staging
        commit_outputs(staging, out)
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def commit_outputs(staging: Path, out: Path) -> None:
    """Move every file of ``staging`` into ``out`` (each move is an atomic rename)."""
    out.mkdir(parents=True, exist_ok=True)
    for source in sorted(staging.rglob("*")):
        if source.is_file():
            target = out / source.relative_to(staging)
            target.parent.mkdir(parents=True, exist_ok=True)
            os.replace(source, target)
