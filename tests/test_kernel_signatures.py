"""Each big numba kernel compiles once: the library passes it one argument type whatever the
caller passes (read-only or writable arrays, literal flags).

numba compiles a kernel once per argument type (a read-only array, a literal ``True`` and a
``bool`` are different types); each extra version of the planner's edge walk or of the IK
kernels costs tens of seconds of compile on first use. The workload runs in a fresh process,
which loads the kernels from numba's cache for exactly the types it calls them with; the
inner kernels of the planner and of the robots' IK (compiled from the others) have no version
for a literal argument in numba's cache index, and the planner's have one version each.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

WORKLOAD = """
import json
import numpy as np
import lynxplan
from lynxplan.arm import Arm
from lynxplan.arm.ik import solve_ik_batch
from lynxplan.arm import ik_kernel, ik_select
from lynxplan.planning import certify, rrt_connect, shortcut
from lynxplan.robots.ik import family_kernel, pose_block, pose_kernel

for name in ("p02_box_between", "p05_goal_behind_wall"):
    lynxplan.run_scenario(f"scenarios/planning/{name}.yaml", None, quick=True)

arm = Arm()
q = np.radians([30, 60, -45, 45, 10])
T = arm.fk(q)
T.setflags(write=False)  # the library's results are read-only
arm.ik(T)
arm.ik(arm.fk(q), q_reference=q, limit_tolerance=0.0)
batch = np.stack([T, T])
solve_ik_batch(batch)
batch.setflags(write=False)
solve_ik_batch(batch)
solve_ik_batch(np.stack([T, T]), q_reference=q, limit_tolerance=0.0)

robot = lynxplan.load_robot("so101")
rng = np.random.default_rng(1)
qs = rng.uniform(robot.limits.lower, robot.limits.upper, size=(300, 5))
poses = robot.fk(qs)
poses.setflags(write=False)
robot.ik(poses[0])
robot.ik_batch(poses)
robot.ik_batch(poses[:10])
robot.ik(position=poses[0, :3, 3], approach=poses[0, :3, 2])

kernels = {
    "rrt_connect_begin": rrt_connect.rrt_connect_begin,
    "shortcut_path": shortcut.shortcut_path,
    "verification_rows": certify.verification_rows,
    "ik_kernel": ik_kernel.ik_kernel,
    "ik_single_kernel": ik_select.ik_single_kernel,
    "family_ik_general": family_kernel.family_ik_general,
    "pose_kernel": pose_kernel.pose_kernel,
    "blocks": pose_block.blocks,
}
print(json.dumps({name: len(k.signatures) for name, k in kernels.items()}))

# The inner kernels of the planner and of the robots' IK, compiled from other kernels (now or
# in an earlier process): the versions in numba's cache index for the current sources.
import importlib, pkgutil
import numba
import lynxplan.planning, lynxplan.robots.ik
cached = {}
for package in (lynxplan.planning, lynxplan.robots.ik):
    for info in pkgutil.iter_modules(package.__path__):
        module = importlib.import_module(f"{package.__name__}.{info.name}")
        for name, value in vars(module).items():
            cache = getattr(value, "_cache", None)
            own = getattr(value, "__module__", None) == module.__name__
            if isinstance(value, numba.core.dispatcher.Dispatcher) and own:
                index = cache._cache_file._load_index() if hasattr(cache, "_cache_file") else {}
                cached[f"{module.__name__}.{name}"] = [str(key[0]) for key in index]
print(json.dumps(cached))
"""


def test_each_big_kernel_has_one_compiled_signature() -> None:
    done = subprocess.run(
        [sys.executable, "-c", WORKLOAD],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    counts = json.loads(done.stdout.strip().splitlines()[-2])
    assert all(count <= 1 for count in counts.values()), counts
    for name in ("rrt_connect_begin", "shortcut_path", "ik_kernel", "ik_single_kernel"):
        assert counts[name] == 1, counts  # used by the workload
    # Inside compiled code a constant argument is a literal type (a literal 0 or 2 where the
    # callee also gets an int64 compiles it twice: the certification's chain took 15 s a time).
    # (The roll search compiles some kernels twice on purpose: for the ideal and the exact roll
    # equation. A stale cache entry from an older caller shows here too: delete the cache files
    # lynxplan/**/__pycache__/*.nbi and *.nbc.)
    cached = json.loads(done.stdout.strip().splitlines()[-1])
    assert len([name for name, signatures in cached.items() if signatures]) >= 30, cached
    planning = {name: found for name, found in cached.items() if ".planning." in name}
    repeated = {name: found for name, found in planning.items() if len(found) > 1}
    # Except the flags that are constants by design, so that an arm compiles only its own code:
    # the vectorised full-pose solver's variants (closed form, Newton step) and the roll
    # search's (without the polish and the search, for the AL5).
    flagged = {
        f"lynxplan.robots.ik.{name}"
        for name in (
            "family_kernel._family_ik",
            "pose_block.blocks",
            "block_closed_form.solve_closed_forms",
            "block_settle.polish_settle",
            "block_settle.repolish",
        )
    }
    literal = {
        name: found
        for name, found in cached.items()
        if any("Literal" in s for s in found) and name not in flagged
    }
    assert not repeated and not literal, (repeated, literal)


# -- named kernel data --------------------------------------------------------------------------
#: A compiled kernel takes at most this many parameters (issues 36, 37): what belongs together
#: travels as one NamedTuple (or a tuple named in the docstring).
MAX_KERNEL_PARAMETERS = 8
_KERNEL_DECORATORS = ("njit", "jit", "njit_no_refcount", "njit_refcounted", "register_jitable")


def _wide_kernels(source: str, filename: str) -> list[str]:
    """``file:line name (count)`` of each compiled function of ``source`` with more than
    MAX_KERNEL_PARAMETERS parameters."""
    import ast

    wide = []
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, ast.FunctionDef):
            continue
        names = [ast.unparse(d.func if isinstance(d, ast.Call) else d) for d in node.decorator_list]
        if not any(name.rsplit(".", 1)[-1] in _KERNEL_DECORATORS for name in names):
            continue
        count = len(node.args.posonlyargs) + len(node.args.args) + len(node.args.kwonlyargs)
        if count > MAX_KERNEL_PARAMETERS:
            wide.append(f"{filename}:{node.lineno} {node.name} ({count})")
    return wide


def test_the_parameter_count_finds_a_wide_kernel() -> None:
    source = (
        "import numba\n@numba.njit(cache=True)\ndef k(a, b, c, d, e, f, g, h, i):\n    pass\n"
        "@njit_no_refcount()\ndef ok(a, b, c, d, e, f, g, h):\n    pass\n"
        "def plain(a, b, c, d, e, f, g, h, i):\n    pass\n"
    )
    assert _wide_kernels(source, "x.py") == ["x.py:3 k (9)"]


def test_no_kernel_takes_more_than_eight_parameters() -> None:
    wide = []
    for path in sorted((ROOT / "lynxplan").rglob("*.py")):
        wide += _wide_kernels(path.read_text(), str(path.relative_to(ROOT)))
    assert not wide, wide
