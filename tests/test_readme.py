"""Every command and code block of README.md runs, against the installed wheel (a README that lies
fails CI).

Conventions the README is written to:

- Blocks fenced ```` ```sh ````, ```` ```bash ```` and ```` ```python ```` run, in the order of
  the README, in one temporary folder outside the repository (the user's folder: it holds a copy
  of the checkout's ``scenarios/`` and ``urdf/``, what a clone gives a user besides the sources,
  and ``.venv``, a link to the venv holding the wheel, so ``.venv/bin/lynxplan`` works as
  written), with that venv activated (``lynxplan``, ``python`` and ``pytest`` are its own). Other
  blocks (yaml, text, json) are not run; any block whose first line is ``# file: NAME`` is
  written to ``NAME`` in that folder instead (a scenario the next commands use).
- A shell block is one command per line (a line ending in ``\\`` continues); ``# comments`` are
  allowed after a command or on their own line. Every command must exit 0, except one whose
  comment says ``# exit N`` (or ``# exit N or M``, e.g. ``lynxplan bench`` that exits 1 when a
  figure misses its target on the machine at hand). Don't use ``cd``: each command starts in
  the user's folder.
- The set-up commands are recognised and not run (the test session did them: built the wheel
  and installed it): ``git clone``, ``cd lynxplan``, ``python -m venv``, ``pip install`` (any
  ``pip``/``python -m pip``), ``source``/``.`` of an activate script, ``.ci/run``, and the test
  command (``pytest`` with options only, ``-n auto`` too, or on ``tests``). A chain
  ``a && b && c`` runs without its leading set-up commands (``python -m venv .venv &&
  .venv/bin/pip install . && .venv/bin/lynxplan run ...`` runs the ``lynxplan run``), except
  the test recipe: a chain holding the test command is not run. ``pytest scenarios/`` (the
  plugin on the user's scenarios) runs.
- ``lynxplan serve ...`` starts as a process: it must print its URL on stdout within
  :data:`SERVE_TIMEOUT` seconds; ``GET <url>/health`` must answer 200; the server keeps running
  for the rest of its block (a later ``--server URL`` line may use it) and is then terminated.
- A command ending in ``# slow`` runs only when ``LYNXPLAN_FULL_BENCH=1`` (the whole ``lynxplan
  bench --quick`` takes ~3 min on 2 cores); the README shows the sections it means.
- A python block runs as a script (``python block.py``) and must exit 0.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import threading
import urllib.error
import urllib.request
from dataclasses import dataclass
from pathlib import Path

import pytest
from wheel_venv import REPO, Installed, installed_lynxplan

README = REPO / "README.md"
#: Seconds a ``lynxplan serve`` line has to print its URL, and one command to finish.
SERVE_TIMEOUT, COMMAND_TIMEOUT = 180.0, 600.0
RUN_LANGUAGES = ("sh", "bash", "python")
_FENCE = re.compile(r"^```\s*([\w+-]*)\s*$")
_EXIT = re.compile(r"#.*?\bexit\s+(\d+(?:\s*(?:or|,|\|)\s*\d+)*)")
_SETUP = re.compile(
    r"^(git\s+clone|cd\s+lynxplan\b|(\S*/)?python3?\s+-m\s+(venv|pip\s+install)\b"
    r"|(\S*/)?pip3?\s+install\b|source\s|\.\s+\S*activate|(\./)?\.ci/run\b"
    r"|(\S*/)?pytest(\s+(-n\s+\w+|-\S+|tests\S*))*\s*$"
    r"|(\S*/)?python3?\s+-m\s+pytest(\s+(-n\s+\w+|-\S+|tests\S*))*\s*$)"
)
_TEST = re.compile(r"^(\S*/)?(pytest|python3?\s+-m\s+pytest)(\s+(-n\s+\w+|-\S+|tests\S*))*\s*$")
_URL = re.compile(r"https?://[^\s'\"<>]+")


@dataclass(frozen=True)
class Block:
    """One fenced block of the README."""

    language: str
    line: int
    """Line number of its first line in the README (1-based)."""
    text: str


@dataclass(frozen=True)
class Command:
    """One command of a shell block."""

    line: int
    text: str
    """The command without its comment."""
    exits: tuple[int, ...]
    """The exit codes it may end with."""
    slow: bool


def blocks(markdown: str) -> list[Block]:
    """The fenced blocks of ``markdown``."""
    found, language, start, body = [], None, 0, []
    for number, line in enumerate(markdown.splitlines(), 1):
        fence = _FENCE.match(line.strip())
        if fence and language is None:
            language, start, body = fence.group(1).lower(), number + 1, []
        elif line.strip() == "```" and language is not None:
            found.append(Block(language, start, "\n".join(body)))
            language = None
        elif language is not None:
            body.append(line)
    return found


def _strip_comment(line: str) -> tuple[str, str]:
    """(command, comment) of a shell line: the comment starts at a ``#`` outside quotes that
    begins the line or follows a blank."""
    quote = None
    for i, char in enumerate(line):
        if quote:
            quote = None if char == quote else quote
        elif char in "'\"":
            quote = char
        elif char == "#" and (i == 0 or line[i - 1].isspace()):
            return line[:i].strip(), line[i:]
    return line.strip(), ""


def commands(block: Block) -> list[Command]:
    """The commands of a shell block (continuation lines joined, comments read)."""
    found, pending, first = [], "", 0
    for offset, raw in enumerate(block.text.splitlines()):
        if not pending:
            first = block.line + offset
        if raw.rstrip().endswith("\\"):
            pending += raw.rstrip()[:-1] + " "
            continue
        text, comment = _strip_comment(pending + raw)
        pending = ""
        if not text:
            continue
        exits = _EXIT.search(comment)
        codes = tuple(int(c) for c in re.findall(r"\d+", exits.group(1))) if exits else (0,)
        slow = bool(re.search(r"#.*\bslow\b", comment))
        found.append(Command(first, text, codes, slow))
    return found


def is_setup(command: str) -> bool:
    """Whether ``command`` (no ``&&``) is a set-up or test command the session has done."""
    return bool(_SETUP.match(command.strip()))


def to_run(command: str) -> str | None:
    """What of ``command`` runs: None for a set-up line or the test recipe (a chain holding the
    test command), else the chain without its leading set-up commands."""
    parts = [part.strip() for part in command.split("&&")]
    if any(_TEST.match(part) for part in parts):
        return None
    while parts and is_setup(parts[0]):
        parts.pop(0)
    return " && ".join(parts) or None


class Runner:
    """Runs README blocks in ``folder`` with environment ``env``."""

    def __init__(self, folder: Path, env: dict[str, str], slow: bool = False) -> None:
        self.folder, self.env, self.slow = folder, env, slow

    def run_block(self, block: Block) -> list[str]:
        """Run ``block``; returns what was skipped. Raises AssertionError naming the README
        line whose command failed."""
        first = block.text.splitlines()[0].strip() if block.text.strip() else ""
        if first.startswith("# file:"):
            path = self.folder / first.removeprefix("# file:").strip()
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(block.text.split("\n", 1)[1] + "\n")
            return []
        if block.language == "python":
            script = self.folder / f"readme_block_{block.line}.py"
            script.write_text(block.text + "\n")
            self._check(Command(block.line, f"python {script.name}", (0,), False))
            return []
        if block.language not in RUN_LANGUAGES:
            return []
        skipped, servers = [], []
        try:
            for written in commands(block):
                text = to_run(written.text)
                if text is None or (written.slow and not self.slow):
                    skipped.append(f"README.md:{written.line}: {written.text}")
                    continue
                command = Command(written.line, text, written.exits, written.slow)
                if re.search(r"(^|\s|/)lynxplan\s+serve\b", command.text):
                    servers.append(self._serve(command))
                else:
                    self._check(command)
        finally:
            for server in servers:
                _stop(server)
        return skipped

    def _check(self, command: Command) -> None:
        done = subprocess.run(
            ["bash", "-c", command.text],
            cwd=self.folder,
            env=self.env,
            capture_output=True,
            text=True,
            timeout=COMMAND_TIMEOUT,
            check=False,
        )
        assert done.returncode in command.exits, (
            f"README.md:{command.line}: `{command.text}` exited {done.returncode}, expected "
            f"{' or '.join(map(str, command.exits))}\n--- stdout\n{done.stdout[-3000:]}\n"
            f"--- stderr\n{done.stderr[-3000:]}"
        )

    def _serve(self, command: Command) -> subprocess.Popen[str]:
        log = open(self.folder / f"serve_{command.line}.log", "w")  # noqa: SIM115 (the server's)
        server = subprocess.Popen(
            ["bash", "-c", f"exec {command.text}"],
            cwd=self.folder,
            env=self.env,
            stdout=subprocess.PIPE,
            stderr=log,
            text=True,
            start_new_session=True,
        )
        lines: list[str] = []
        reader = threading.Thread(target=lambda: lines.extend(server.stdout or []), daemon=True)
        reader.start()
        url = _wait_for_url(server, lines)
        if url is None:
            _stop(server)
            raise AssertionError(
                f"README.md:{command.line}: `{command.text}` printed no URL on stdout within "
                f"{SERVE_TIMEOUT:g} s (exit {server.returncode}); stdout: {''.join(lines)[-2000:]}"
                f"\nstderr: {(self.folder / f'serve_{command.line}.log').read_text()[-2000:]}"
            )
        status = _health(url.rstrip("/.,;") + "/health")
        if status != 200:
            _stop(server)
            raise AssertionError(f"README.md:{command.line}: GET {url}/health: {status}")
        return server


def _health(url: str) -> int | str:
    """The status of ``GET url``; a refused connection is retried for 30 s (the URL may be
    printed a moment before the socket accepts)."""
    import time

    deadline = time.monotonic() + 30
    while True:
        try:
            with urllib.request.urlopen(url, timeout=30) as response:
                return int(response.status)
        except urllib.error.HTTPError as error:  # noqa: PERF203 (a retry loop)
            return int(error.code)
        except OSError as error:
            if time.monotonic() > deadline:
                return str(error)
            time.sleep(0.5)


def _wait_for_url(server: subprocess.Popen[str], lines: list[str]) -> str | None:
    """The first URL the server prints on stdout, or None (it exited or the time ran out)."""
    import time

    deadline = time.monotonic() + SERVE_TIMEOUT
    while time.monotonic() < deadline:
        for line in list(lines):
            if match := _URL.search(line):
                return match.group(0)
        if server.poll() is not None:
            time.sleep(0.2)  # the reader may still hold its last lines
            found = [m.group(0) for line in lines if (m := _URL.search(line))]
            return found[0] if found else None
        time.sleep(0.1)
    return None


def _stop(server: subprocess.Popen[str]) -> None:
    """Terminate the server this test started (its own process group), then wait for it."""
    if server.poll() is None:
        os.killpg(server.pid, signal.SIGTERM)
        try:
            server.wait(30)
        except subprocess.TimeoutExpired:
            os.killpg(server.pid, signal.SIGKILL)
            server.wait(30)


# ---------------------------------------------------------------------------------------------
# The README itself, against the installed wheel.

_README_BLOCKS = [b for b in blocks(README.read_text()) if b.language in RUN_LANGUAGES] + [
    b for b in blocks(README.read_text()) if b.text.startswith("# file:")
]
_README_BLOCKS.sort(key=lambda b: b.line)


@pytest.fixture(scope="module")
def readme_runner(tmp_path_factory: pytest.TempPathFactory) -> Runner:
    installed: Installed = installed_lynxplan(tmp_path_factory.mktemp("wheel"))
    folder = tmp_path_factory.mktemp("readme-user")
    assert not folder.resolve().is_relative_to(REPO)
    for name in ("scenarios", "urdf"):
        shutil.copytree(REPO / name, folder / name, ignore=shutil.ignore_patterns("__pycache__"))
    (folder / ".venv").symlink_to(installed.venv)
    slow = os.environ.get("LYNXPLAN_FULL_BENCH") == "1"
    return Runner(folder, installed.env, slow=slow)


@pytest.mark.parametrize("block", _README_BLOCKS, ids=lambda b: f"README.md:{b.line}-{b.language}")
def test_readme_block(readme_runner: Runner, block: Block) -> None:
    readme_runner.run_block(block)


# ---------------------------------------------------------------------------------------------
# The harness: a README that lies fails.

_FAKE = """\
# Fake

```sh
pip install .                     # set-up: not run
python -m venv .venv && .venv/bin/pip install '.[test]' && .venv/bin/pytest -q -n auto
python3 -m venv .venv && pip install . && echo ran > ran.txt
echo hello > greeting.txt         # a comment
test -f greeting.txt
sh -c 'exit 2'                    # exit 2
sh -c 'exit 1'                    # exit 0 or 1: a figure may miss its target
echo 'a # inside quotes' | grep -q '#'
echo one \\
  two | grep -q 'one two'
```

```yaml
# file: notes/example.yaml
name: example
```

```python
from pathlib import Path
assert Path("notes/example.yaml").read_text().startswith("name: example")
```
"""


@pytest.fixture
def runner(tmp_path: Path) -> Runner:
    return Runner(tmp_path, dict(os.environ))


def test_the_harness_runs_a_truthful_readme(runner: Runner) -> None:
    found = blocks(_FAKE)
    assert [b.language for b in found] == ["sh", "yaml", "python"]
    skipped = [s for b in found for s in runner.run_block(b)]
    chain = "python -m venv .venv && .venv/bin/pip install '.[test]' && .venv/bin/pytest -q -n auto"
    assert skipped == ["README.md:4: pip install .", f"README.md:5: {chain}"]
    assert (runner.folder / "greeting.txt").read_text() == "hello\n"
    assert (runner.folder / "ran.txt").read_text() == "ran\n"  # the chain less its set-up


@pytest.mark.parametrize(
    ("block", "message"),
    [
        ("```sh\ntrue\nfalse\n```", r"README.md:3: `false` exited 1, expected 0"),
        ("```bash\nsh -c 'exit 3'   # exit 2\n```", r"`sh -c 'exit 3'` exited 3, expected 2"),
        ("```python\nraise SystemExit('the API changed')\n```", r"exited 1, expected 0"),
        ("```sh\nlynxplan-no-such-command --help\n```", r"exited 127"),
        ("```sh\npython -c 'print(1)' && false\n```", r"exited 1"),
    ],
)
def test_a_readme_that_lies_fails(runner: Runner, block: str, message: str) -> None:
    (found,) = blocks(block)
    with pytest.raises(AssertionError, match=message):
        runner.run_block(found)


def test_a_server_that_prints_no_url_fails(runner: Runner, monkeypatch) -> None:
    monkeypatch.setattr(f"{__name__}.SERVE_TIMEOUT", 5.0)
    fake = runner.folder / "lynxplan"
    fake.write_text("#!/bin/sh\necho 'serving'\nsleep 60\n")
    fake.chmod(0o755)
    (found,) = blocks("```sh\n./lynxplan serve\n```")
    with pytest.raises(AssertionError, match=r"printed no URL on stdout within 5 s"):
        runner.run_block(found)
