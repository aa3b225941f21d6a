"""Compiling ahead of the clock, and the stderr line when numba compiles for long."""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys

import numba

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


#: Answers of the IK solvers to random targets of each kind, as JSON (floats written exactly).
ANSWERS = """
import json, sys
import numpy as np
from lynxplan import load_robot
from lynxplan.arm import load_arm

def answers(name, count):
    robot = load_robot(name)
    rng = np.random.default_rng(11)
    poses = robot.fk(robot.random_configurations(count, seed=21))
    out = []
    for k, pose in enumerate(poses):
        moved = pose.copy()
        moved[:3, 3] += rng.normal(0.0, 0.05, 3)  # mostly off the reachable orientations
        targets = [dict(pose=pose), dict(position=pose[:3, 3], approach=pose[:3, 2])]
        if robot.family is not None:
            targets += [dict(position=pose[:3, 3], pitch=float(rng.uniform(-1, 1))),
                        dict(pose=moved)]
        for target in targets:
            result = robot.ik(**target)
            out.append([[s.q.tolist() for s in result.solutions], [s.branch for s in
                        result.solutions], result.selected, result.distance])
    return out

def arm_answers(count):
    arm = load_arm()
    rng = np.random.default_rng(3)
    poses = arm.fk(rng.uniform(arm.limits.lower, arm.limits.upper, (count, 5)))
    out = [poses.tolist(), np.asarray(arm.ik_batch(poses).q).tolist()]
    for pose in poses:
        for select in ("nearest", "report"):
            result = arm.ik(pose, select=select)
            out.append([[s.q.tolist() for s in result.solutions], result.selected])
    return out

counts = json.loads(sys.argv[1])
print(json.dumps({name: answers(name, n) for name, n in counts.items()} | {"arm": arm_answers(20)}))
"""


def test_the_kernels_answer_the_same_bits_interpreted() -> None:
    """Run as Python (numba's switch NUMBA_DISABLE_JIT=1, the command line's single-target
    ``ik``) the kernels give the compiled answers to the last bit: every IK solver (closed form,
    roll search, near-axis rescue, numerical, the AL5's own kernels) on random targets."""
    counts = json.dumps({"al5": 12, "so100": 8, "so101": 12, "ur5": 6})
    runs = []
    for switch in ("1", "0"):
        env = {**os.environ, "NUMBA_DISABLE_JIT": switch}
        done = subprocess.run(
            [sys.executable, "-c", ANSWERS, counts],
            capture_output=True,
            text=True,
            env=env,
            timeout=600,
            check=False,
        )
        assert done.returncode == 0, done.stderr[-2000:]
        runs.append(json.loads(done.stdout))
    interpreted, compiled = runs
    for name in compiled:
        assert interpreted[name] == compiled[name], name


def test_one_ik_target_from_the_command_line_compiles_nothing(tmp_path) -> None:
    """``lynxplan ik`` of one target runs the kernels as Python: on an empty numba cache it
    writes no cache file and answers as the compiled library does."""
    cli = "import sys; from lynxplan.cli import main; sys.exit(main())"
    command = [sys.executable, "-c", cli, "ik", "--robot", "so101",
               "--position", "0.2", "0", "0.1", "--approach", "0", "0", "-1", "--json"]  # fmt: skip
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_DISABLE_JIT"}
    env["NUMBA_CACHE_DIR"] = str(tmp_path)
    shell = subprocess.run(command, capture_output=True, text=True, env=env, check=False)
    assert shell.returncode == 0, shell.stderr[-2000:]
    assert not list(tmp_path.rglob("*.nb*"))  # nothing compiled
    import lynxplan

    robot = lynxplan.load_robot("so101")
    result = robot.ik(position=[0.2, 0.0, 0.1], approach=[0.0, 0.0, -1.0])
    answered = json.loads(shell.stdout)["solutions"]
    assert [s["q"] for s in answered] == [s.q.tolist() for s in result.solutions]


#: Two functions numba compiles on the first call of g (the second compiles it again for a
#: float): the compiles the notice tests watch.
TWO_COMPILES = """
@numba.njit
def f(x):
    return x + 1

@numba.njit
def g(x):
    return f(x) * 2
"""

ANNOUNCE = (
    """
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
"""
    + TWO_COMPILES
    + """
g(1)
g(2.0)
sys.__stdout__.write(repr(terminal.getvalue()))
"""
)


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


#: A Python program (no CLI): numba compiles two functions, the notice comes after ``after`` s.
PROGRAM = (
    """
import sys, warnings
import numba
import lynxplan
from lynxplan import _jit

_jit.NOTICE_AFTER = float(sys.argv[1])
if sys.argv[2] == "off":
    _jit.disable_notices()
_jit.listen()
"""
    + TWO_COMPILES
    + """
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    g(1)
    g(2.0)
print([(w.category.__name__, str(w.message)) for w in caught
       if issubclass(w.category, lynxplan.CompileWarning)])
"""
)


def _warnings_of_a_program(after: float, mode: str) -> list[tuple[str, str]]:
    done = subprocess.run(
        [sys.executable, "-c", PROGRAM, str(after), mode],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    return list(ast.literal_eval(done.stdout))


def test_a_python_program_is_warned_once_of_a_long_compile() -> None:
    """A notebook's or script's first plan compiles for minutes: a CompileWarning says so (once),
    not a silent wait; a short compile or notices turned off say nothing."""
    said = _warnings_of_a_program(0.0, "on")
    assert len(said) == 1, said
    assert said[0][0] == "CompileWarning"
    assert said[0][1].startswith("compiling numba kernels for the first run")
    assert _warnings_of_a_program(60.0, "on") == []
    assert _warnings_of_a_program(0.0, "off") == []
