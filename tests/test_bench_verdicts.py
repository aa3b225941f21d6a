"""``lynxplan bench``'s verdicts: a figure that missed its target never prints ``ok``; a section
that could not run says why and exits 3; a missing optional peer says "peer not installed"."""

from __future__ import annotations

import json
import math
import sys

import pytest

from lynxplan.bench import (
    MISSED,
    NOT_RUN,
    OK,
    PEER_NOT_INSTALLED,
    SECTIONS,
    Figure,
    meets,
    peer_missing,
    verdict,
)
from lynxplan.cli import main


@pytest.mark.parametrize(
    ("value", "target", "expected"),
    [
        (99.0, ">= 99", True),
        (98.9, ">= 99", False),
        (0.0, ">= 99", False),
        (0.5, "<= 0.5", True),
        (0.51, "<= 0.5", False),
        (100.0, "100", True),
        (99.99, "100", False),
        (math.nan, "<= 1", False),
        (math.nan, ">= 1", False),
        (math.inf, ">= 1", False),
        (1.0, "about 1", False),  # a target of another form is met by nothing
    ],
)
def test_meets(value: float, target: str, expected: bool) -> None:
    assert meets(value, target) is expected


def test_a_figure_that_missed_its_target_is_never_ok() -> None:
    # What `lynxplan bench plan --quick` printed after `pip install .`: "success 0 % ... ok".
    assert verdict(Figure("plan", "success", 0.0, "%", ">= 99", met=True)) == MISSED
    assert verdict(Figure("plan", "median", math.nan, "ms", "<= 1", met=True)) == MISSED
    assert verdict(Figure("plan", "median", 0.5, "ms", "<= 1", met=False)) == MISSED
    assert verdict(Figure("plan", "median", 0.5, "ms", "<= 1", met=True)) == OK
    assert verdict(Figure("plan", "length", 2.7, "rad")) == ""
    assert verdict(peer_missing("plan", "ompl", "/nowhere/ompl/bin/python")) == PEER_NOT_INSTALLED


def _fake_section(tmp_path, monkeypatch, name: str, body: str) -> None:
    """A bench section module ``name`` (a real module on sys.path) registered in SECTIONS."""
    (tmp_path / f"{name}.py").write_text(body)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setitem(SECTIONS, name, name)
    sys.modules.pop(name, None)


_GOOD = (
    "from lynxplan.bench import Figure\n"
    "def run(quick):\n"
    "    return [Figure('fake_good', 'fast', 1.0, 'ms', '<= 2', True)]\n"
)


def test_a_section_that_raises_is_reported_and_exits_3(tmp_path, monkeypatch, capsys) -> None:
    _fake_section(tmp_path, monkeypatch, "fake_good", _GOOD)
    _fake_section(
        tmp_path, monkeypatch, "fake_broken", "def run(quick):\n    raise OSError('disk gone')\n"
    )
    assert main(["bench", "fake_broken", "fake_good", "--quick"]) == 3
    out, err = capsys.readouterr()
    assert "[fake_broken] section could not run  NOT RUN: OSError: disk gone" in out
    assert "[fake_good] fast" in out and "ok" in out  # the other section still ran
    assert "could not run: [fake_broken]" in err


def test_a_missed_figure_exits_1_and_a_missing_peer_exits_0(tmp_path, monkeypatch, capsys) -> None:
    _fake_section(
        tmp_path,
        monkeypatch,
        "fake_slow",
        "import math\n"
        "from lynxplan.bench import Figure, peer_missing\n"
        "def run(quick):\n"
        "    return [Figure('fake_slow', 'slow', math.nan, 'ms', '<= 2', True)]\n",
    )
    _fake_section(
        tmp_path,
        monkeypatch,
        "fake_peer",
        "from lynxplan.bench import Figure, peer_missing\n"
        "def run(quick):\n"
        "    return [Figure('fake_peer', 'ours', 1.0, 'ms', '<= 2', True),\n"
        "            peer_missing('fake_peer', 'ompl', '/nowhere/ompl/bin/python')]\n",
    )
    assert main(["bench", "fake_slow", "--json"]) == 1
    rows = json.loads(capsys.readouterr().out)["figures"]
    assert [r["verdict"] for r in rows] == [MISSED]
    assert main(["bench", "fake_peer"]) == 0
    out, err = capsys.readouterr()
    assert "[fake_peer] ompl  peer not installed (no /nowhere/ompl/bin/python" in out
    assert "peers not installed, not compared: ompl (fake_peer)" in err
    assert NOT_RUN not in out
