"""Compiling ahead of the clock, and the stderr line when numba compiles for long."""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys

import numba
import numpy as np

from lynxplan._jit import compile_before_timing


def test_compile_before_timing_compiles_once_without_running() -> None:
    @numba.njit
    def twice(x: float) -> float:
        return 2.0 * x

    assert not twice.signatures
    seconds = compile_before_timing(twice, (1.5,))
    assert seconds > 0.0
    assert [tuple(str(t) for t in s) for s in twice.signatures] == [("float64",)]
    assert compile_before_timing(twice, (2.5,)) == 0.0
    assert twice(2.5) == 5.0


def test_a_constant_flag_prunes_the_other_branch_before_it_is_compiled() -> None:
    """The mechanism of ``robots/ik/pose_block``'s variants: a kernel called with a constant
    ``True`` or ``None`` for a flag compiles only the callee of its ``is None`` branch (numba
    prunes such branches when it compiles: a plain ``bool`` flag would compile both)."""

    @numba.njit
    def on_axis(x: float) -> float:
        return x + 1.0

    @numba.njit
    def off_axis(x: float) -> float:
        return x + 2.0

    @numba.njit
    def kernel(x: float, flag: bool | None) -> float:
        if flag is None:
            return on_axis(x)
        return off_axis(x)

    @numba.njit
    def variant_off(x: float) -> float:
        return kernel(x, True)

    assert variant_off(1.0) == 3.0
    assert off_axis.signatures and not on_axis.signatures

    @numba.njit
    def variant_on(x: float) -> float:
        return kernel(x, None)

    assert variant_on(1.0) == 2.0
    assert on_axis.signatures


def test_lynxplan_runs_under_numbas_debugging_switch() -> None:
    """With NUMBA_DISABLE_JIT=1 (numba's switch for debugging jitted code as Python) the
    kernels run as Python and answer as compiled, to rounding: the first IK of an SO-101 pose,
    roll free, position and approach, and the same through the command line."""
    code = (
        "import json, numpy as np, lynxplan; r = lynxplan.load_robot('so101');"
        " q = np.array([0.3, -0.4, 0.9, 0.6, -1.2]); T = r.fk(q);"
        " a = r.ik(T); b = r.ik(position=T[:3, 3], approach=T[:3, 2]);"
        " print(json.dumps([a.q.tolist(), b.q.tolist()]))"
    )
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1"}
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, check=False
    )
    assert done.returncode == 0, done.stderr[-2000:]
    interpreted = json.loads(done.stdout)
    import lynxplan

    robot = lynxplan.load_robot("so101")
    pose = robot.fk(np.array([0.3, -0.4, 0.9, 0.6, -1.2]))
    compiled = [
        robot.ik(pose).q,
        robot.ik(position=pose[:3, 3], approach=pose[:3, 2]).q,
    ]
    for got, want in zip(interpreted, compiled, strict=True):
        np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-12)
    cli = "import sys; from lynxplan.cli import main; sys.exit(main())"
    command = [sys.executable, "-c", cli, "ik", "--robot", "so101",
               "--position", "0.2", "0", "0.1", "--approach", "0", "0", "-1", "--json"]  # fmt: skip
    shell = subprocess.run(command, capture_output=True, text=True, env=env, check=False)
    assert shell.returncode == 0, shell.stderr[-2000:]
    assert json.loads(shell.stdout)["solutions"]


ANNOUNCE = """
import io, sys
import numba
from lynxplan import _jit

class Terminal(io.StringIO):
    def isatty(self):
        return True

terminal = Terminal()
sys.stderr = terminal
_jit.NOTICE_AFTER = float(sys.argv[1])
_jit.enable_notices()
_jit.listen()

@numba.njit
def f(x):
    return x + 1

@numba.njit
def g(x):
    return f(x) * 2

g(1)
g(2.0)
sys.__stdout__.write(repr(terminal.getvalue()))
"""


def _stderr_of_compiles(after: float) -> str:
    done = subprocess.run(
        [sys.executable, "-c", ANNOUNCE, str(after)],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    return str(ast.literal_eval(done.stdout))  # the repr written above


def test_a_long_compile_is_announced_once_on_a_terminal() -> None:
    said = _stderr_of_compiles(0.0)
    assert said.count("\n") == 1, said
    assert said.startswith("lynxplan: compiling numba kernels for the first run")


def test_a_short_compile_says_nothing() -> None:
    assert _stderr_of_compiles(60.0) == ""


def test_not_a_terminal_says_nothing() -> None:
    quiet = ANNOUNCE.replace("return True", "return False")
    done = subprocess.run(
        [sys.executable, "-c", quiet, "0"], capture_output=True, text=True, timeout=120, check=True
    )
    assert done.stdout == "''"
