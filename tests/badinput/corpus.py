"""The bad-input corpus: one row per case. Adding a case is one line.

A CLI row is ``C(argv, code, pattern)``: ``argv`` may use ``{out}`` (an output folder holding a
previous complete run, which must not change) and ``{tmp}`` (the test's temporary folder).

A scenario row is ``S(kind, edit, pattern)``: the kind's small valid base document with ``edit``
applied (``{"a.b[0]": value}`` sets a key path, ``{"a.b": DELETE}`` removes it), written as YAML
and run with ``lynxplan run FILE --out {out}``; expected exit code 2.

A file row is ``F(name, content, pattern)``: raw bytes given to ``lynxplan run``.

``pattern`` is a regex the single stderr line must match; it names the offending key or value.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

NAN, INF = math.nan, math.inf
DELETE = object()


@dataclass(frozen=True)
class C:
    argv: tuple[str, ...]
    code: int
    pattern: str
    xfail: str = ""  # a known gap, with the owner who closes it


@dataclass(frozen=True)
class S:
    kind: str
    edit: dict[str, Any]
    pattern: str
    code: int = 2


@dataclass(frozen=True)
class F:
    name: str
    content: bytes
    pattern: str
    code: int = 2
    mode: int | None = field(default=None)


# -- CLI ----------------------------------------------------------------------------------------
USAGE = r"^lynxplan( [a-z]+)*: error: "
NOT_NUMBER = r"is not a (finite )?number"

_POSE_OK = "[[1,0,0,0.2],[0,-1,0,0],[0,0,-1,0.1],[0,0,0,1]]"
_REFLECTION = "[[1,0,0,0.2],[0,1,0,0],[0,0,-1,0.1],[0,0,0,1]]"
_SCALED = "[[2,0,0,0.2],[0,-1,0,0],[0,0,-1,0.1],[0,0,0,1]]"
_BOTTOM = "[[1,0,0,0.2],[0,-1,0,0],[0,0,-1,0.1],[0,0,1,1]]"
_FAR = "[[1,0,0,1e300],[0,-1,0,0],[0,0,-1,0.1],[0,0,0,1]]"

_FK_BAD: list[tuple[str, str]] = [
    ("nan", r"q\d: 'nan' is not a finite number"),
    ("inf", r"q\d: 'inf' is not a finite number"),
    ("-inf", r"q\d: '-inf' is not a finite number"),
    ("1e400", r"q\d: '1e400' is not a finite number"),
    ("1e19", r"q\d = 1e\+19 is out of range: must be finite, -100 rad"),
    ("-101", r"q\d = -101 is out of range"),
    ("abc", r"q\d: 'abc' is not a number"),
    ("0x10", r"q\d: '0x10' is not a number"),
    ("1,5", r"q\d: '1,5' is not a number"),
    ("", r"q\d: '' is not a number"),
]

CLI: list[C] = [
    # global usage
    C((), 2, r"the following arguments are required: COMMAND"),
    C(("frobnicate",), 2, r"invalid choice: 'frobnicate'"),
    C(("--frobnicate", "fk"), 2, r"unrecognized arguments: --frobnicate"),
    C(("fk", "0", "0", "0", "0", "0", "--frobnicate"), 2, r"unrecognized arguments"),
    C(("--max-samples",), 2, r"--max-samples: expected a number N"),
    C(("--max-samples", "0", "fk", "0", "0", "0", "0", "0"), 2, r"--max-samples = 0 is out"),
    C(("--max-samples", "-5", "fk", "0", "0", "0", "0", "0"), 2, r"--max-samples = -5 is out"),
    C(("--max-samples", "abc", "fk", "0", "0", "0", "0", "0"), 2, r"--max-samples: 'abc' is not"),
    C(("--max-samples=1.5", "fk", "0", "0", "0", "0", "0"), 2, r"--max-samples must be an integ"),
    C(("--max-samples=nan", "fk", "0", "0", "0", "0", "0"), 2, r"--max-samples must be an integ"),
    # fk: every joint position x every bad value
    *[
        C(("fk", *(["0"] * i), bad, *(["0"] * (4 - i))), 2, pattern.replace(r"\d", str(i + 1)))
        for i in (0, 4)
        for bad, pattern in _FK_BAD
    ],
    C(("fk", "1", "2", "3", "4"), 2, r"fk: expected 5 joint angles q1..q5, got 4"),
    C(("fk", "1", "2", "3", "4", "5", "6"), 2, r"fk: expected 5 joint angles q1..q5, got 6"),
    C(("fk",), 2, r"fk: expected 5 joint angles q1..q5, got 0"),
    C(("fk", "--deg", "0", "0", "0", "0", "1e300"), 2, r"q5 = 1e\+300 is out of range.*deg"),
    C(("fk", "--deg", "0", "0", "0", "0", "6000"), 2, r"q5 = 6000 is out of range.*5729"),
    C(("fk", "--units", "furlong", "0", "0", "0", "0", "0"), 2, r"--units: invalid choice"),
    C(("fk", "--units", "MM", "0", "0", "0", "0", "0"), 2, r"--units: invalid choice: 'MM'"),
    C(("fk", "--units", "", "0", "0", "0", "0", "0"), 2, r"--units: invalid choice: ''"),
    C(("fk", "--deg=1", "0", "0", "0", "0", "0"), 2, r"--deg: ignored explicit argument"),
    # ik: --pose
    C(("ik",), 2, r"the following arguments are required: --pose"),
    C(("ik", "--pose", _REFLECTION), 2, r"--pose: rotation block has determinant -1: a reflec"),
    C(("ik", "--pose", _SCALED), 2, r"--pose is not a rigid transform: rotation deviates"),
    C(("ik", "--pose", _BOTTOM), 2, r"--pose \(last row must be 0 0 0 1\) is not a rigid"),
    C(("ik", "--pose", _FAR), 2, r"--pose translation = 1e\+300 is out of range"),
    C(("ik", "--pose", "[[1,0,0],[0,1,0],[0,0,1]]"), 2, r"--pose must have shape \(4, 4\) or \(3"),
    C(("ik", "--pose", "[[1,0,0,0],[0,1,0,0],[0,0,1]]"), 2, r"--pose must be an array.*ragged"),
    C(("ik", "--pose", "[[1,0,0,NaN],[0,1,0,0],[0,0,1,0]]"), 2, r"--pose contains NaN.*= nan"),
    C(("ik", "--pose", "[[1,0,0,Infinity],[0,1,0,0],[0,0,1,0]]"), 2, r"--pose contains NaN.*inf"),
    C(("ik", "--pose", "[[1,0,0,1e400],[0,1,0,0],[0,0,1,0]]"), 2, r"--pose contains NaN.*inf"),
    C(("ik", "--pose", '[["a",0,0,0],[0,1,0,0],[0,0,1,0]]'), 2, r"--pose must be an array"),
    C(("ik", "--pose", "[[1,0,0,0],[0,1,0,0],[0,0,1,0"), 2, r"--pose: not a JSON 4x4"),
    C(("ik", "--pose", ""), 2, r"--pose: not a JSON 4x4 .*Expecting value"),
    C(("ik", "--pose", "null"), 2, r"--pose must have shape \(4, 4\) or \(3, 4\). Got: \(\)"),
    C(("ik", "--pose", "{}"), 2, r"--pose must be an array of real numbers"),
    C(("ik", "--pose", "5"), 2, r"--pose must have shape .* Got: \(\)"),
    C(("ik", "--pose", "[]"), 2, r"--pose must have shape .* Got: \(0,\)"),
    C(("ik", "--pose", "[" * 100_000 + "]" * 100_000), 2, r"--pose: 200000 characters"),
    C(("ik", "--pose", "[" * 20_000 + "]" * 20_000), 2, r"--pose: not a JSON.*nested too deeply"),
    C(("ik", "--pose", _POSE_OK, "--units", "km"), 2, r"--units: invalid choice: 'km'"),
    C(("ik", "--pose", _FAR.replace("1e300", "2e6"), "--units", "mm"), 2, r"translation = 2000"),
    # ik: --tolerance, --reference, --select
    *[
        C(("ik", "--pose", _POSE_OK, "--strict", "--tolerance", bad), 2, rf"--tolerance{pattern}")
        for bad, pattern in [
            ("nan", r" contains NaN.*= nan"),
            ("inf", r" contains NaN.*= inf"),
            ("-1", r" = -1 is out of range: must be a finite number >= 0 rad"),
            ("abc", r": 'abc' is not a number"),
            ("", r": '' is not a number"),
        ]
    ],
    *[
        C(("ik", "--pose", _POSE_OK, "--reference", bad), 2, rf"--reference{pattern}")
        for bad, pattern in [
            ("[0,0,0,0,NaN]", r" contains NaN.*\[4\] = nan"),
            ("[0,0,0,0]", r" must have shape \(5,\). Got: \(4,\)"),
            ("[0,0,0,0,0,0]", r" must have shape \(5,\). Got: \(6,\)"),
            ("[[0,0,0,0,0]]", r" must have shape \(5,\). Got: \(1, 5\)"),
            ("[0,0,0,0,1e19]", r"\[4\] = 1e\+19 is out of range"),
            ('[0,0,0,0,"x"]', r" must be an array of real numbers"),
            ("zero", r": not a JSON list of 5 numbers"),
            ("{}", r" must be an array of real numbers"),
        ]
    ],
    C(("ik", "--pose", _POSE_OK, "--reference", "[0,0,0,0,6000]", "--deg"), 2, r"\[4\] = 104"),
    C(("ik", "--pose", _POSE_OK, "--select", "best"), 2, r"--select: invalid choice: 'best'"),
    # parallel
    C(("parallel",), 2, r"the following arguments are required: ACTION"),
    C(("parallel", "teleport"), 2, r"invalid choice: 'teleport'"),
    *[
        C(("parallel", "ik", *args), 2, pattern)
        for args, pattern in [
            (("nan", "0", "0"), r"XC: 'nan' is not a finite number"),
            (("0", "inf", "0"), r"YC: 'inf' is not a finite number"),
            (("0", "0", "x"), r"ALPHA: 'x' is not a number"),
            (("1e300", "0", "0"), r"XC = 1e\+300 is out of range: .* 1e\+06 mm"),
            (("0", "-2e6", "0"), r"YC = -2e\+06 is out of range"),
            (("0", "0", "1e19"), r"ALPHA = 1e\+19 is out of range.*deg"),
            (("0", "0"), r"the following arguments are required: alpha"),
            (("0", "0", "0", "0"), r"unrecognized arguments: 0"),
            (("0", "0", "0"), r"leg [ABC] cannot reach its platform joint"),
        ]
    ],
    *[
        C(("parallel", "fk", *args), 2, pattern)
        for args, pattern in [
            (("nan", "0", "0"), r"T1: 'nan' is not a finite number"),
            (("0", "0", "-inf"), r"T3: '-inf' is not a finite number"),
            (("0", "1e9", "0"), r"T2 = 1e\+09 is out of range"),
            (("0", "0", "1e300"), r"T3 = 1e\+300 is out of range"),
            (("a", "0", "0"), r"T1: 'a' is not a number"),
            (("0", "0"), r"the following arguments are required: t3"),
            (("0", "0", "0", "--near", "0", "0"), r"--near: expected 3 arguments"),
            (("0", "0", "0", "--near", "nan", "0", "0"), r"XC: 'nan' is not a finite"),
            (("0", "0", "0", "--near", "0", "1e300", "0"), r"--near YC = 1e\+300 is out"),
            (("0", "0", "0", "--near", "0", "0", "1e19"), r"--near ALPHA = 1e\+19 is out"),
            (("-135", "-45", "90", "--near", "1", "2", "3"), r"admit no assembly mode"),
        ]
    ],
    *[
        C(("parallel", "workspace", "--out", "{out}", *args), 2, pattern)
        for args, pattern in [
            ((), r"the following arguments are required: --alpha"),
            (("--alpha", "nan"), r"--alpha: 'nan' is not a finite number"),
            (("--alpha", "1e19"), r"--alpha = 1e\+19 is out of range"),
            (("--alpha", "0", "--step", "0"), r"--step = 0 is out of range"),
            (("--alpha", "0", "--step", "-1"), r"--step = -1 is out of range"),
            (("--alpha", "0", "--step", "nan"), r"--step: 'nan' is not a finite number"),
            (("--alpha", "0", "--step", "1e10"), r"--step = 1e\+10 is out of range"),
            (("--alpha", "0", "--step", "1e-9"), r"grid points for a 1e-09 mm step .*limit of"),
            (("--alpha", "0", "--step", "0.01"), r"grid points .*--max-samples N"),
            (("--alpha", "0", "--step", "x"), r"--step: 'x' is not a number"),
            (("--alpha", "0", "--step", "1000"), r"step 1000 mm is larger than the region"),
            (("--alpha", "0", "--mode", "0"), r"--mode: working mode number must be 1..8"),
            (("--alpha", "0", "--mode", "9"), r"--mode: working mode number must be 1..8. Got: 9"),
            (("--alpha", "0", "--mode", "+x+"), r"unknown working mode '\+x\+'"),
            (("--alpha", "0", "--mode", "1.5"), r"unknown working mode '1.5'"),
            (("--alpha", "0", "--step", "2", "--max-samples", "100"), r"limit of 100;"),
        ]
    ],
    # workspace
    *[
        C(("workspace", "--out", "{out}", *args), 2, pattern)
        for args, pattern in [
            (("--samples", "0"), r"--samples = 0 is out of range: must be an integer >= 1"),
            (("--samples", "-5"), r"--samples = -5 is out of range"),
            (("--samples", "1e12"), r"--samples: 1e\+12 requested, more than the limit of 1e\+08"),
            (("--samples", "10**12"), r"--samples: '10\*\*12' is not a number"),
            (("--samples", "abc"), r"--samples: 'abc' is not a number"),
            (("--samples", "9" * 30), r"--samples: 1e\+30 requested, more than the limit"),
            (("--samples", "1.5"), r"--samples: '1.5' is not an integer"),
            (("--samples", "nan"), r"--samples: 'nan' is not a finite number"),
            (("--samples", "inf"), r"--samples: 'inf' is not a finite number"),
            (("--samples", "100", "--max-samples", "50"), r"--samples: 100 requested.*limit of 50"),
            (("--quick", "--samples", "10"), r"--quick and --samples contradict each other"),
            (("--cell", "1e-9"), r"--cell: must be at least 0.1 mm. Got: 1e-09"),
            (("--cell", "0"), r"--cell: must be at least 0.1 mm"),
            (("--cell", "-1"), r"--cell: must be at least 0.1 mm"),
            (("--cell", "nan"), r"--cell: 'nan' is not a finite number"),
            (("--cell", "1e300"), r"--cell = 1e\+300 is out of range"),
            (("--cell", "x"), r"--cell: 'x' is not a number"),
            (("--voxel", "1e-9"), r"--voxel: must be at least 0.1 mm"),
            (("--voxel", "inf"), r"--voxel: 'inf' is not a finite number"),
            (("--voxel", "1e7"), r"--voxel = 1e\+07 is out of range"),
            (("--seed", "-1"), r"--seed = -1 is out of range: must be an integer >= 0"),
            (("--seed", str(2**64)), r"--seed = 18446744073709551616 is out of range.*2\*\*63"),
            (("--seed", "abc"), r"--seed: 'abc' is not a number"),
            (("--seed", "1.5"), r"--seed: '1.5' is not an integer"),
            (("--units", "furlong"), r"--units: invalid choice: 'furlong'"),
            (("--units",), r"--units: expected one argument"),
            (("--samples",), r"--samples: expected one argument"),
            (("--frobnicate",), r"unrecognized arguments: --frobnicate"),
            (("--samples", "100", "--out", "/dev/null/x"), r"/dev/null/x"),
        ]
    ],
    # run / validate / schema / bench
    C(("run",), 2, r"the following arguments are required: scenario"),
    C(("run", "{tmp}/missing.yaml", "--out", "{out}"), 2, r"missing.yaml: file not found"),
    C(("run", "{tmp}", "--out", "{out}"), 2, r": is a directory, not a scenario file"),
    C(("run", "/dev/zero", "--out", "{out}"), 2, r"/dev/zero: is not a regular file"),
    C(("run", "/dev/null", "--out", "{out}"), 2, r"/dev/null: is not a regular file"),
    C(("run", "{tmp}/x.yaml", "--frobnicate"), 2, r"unrecognized arguments: --frobnicate"),
    C(("run", "{tmp}/x.yaml", "--out"), 2, r"--out: expected one argument"),
    C(("validate",), 2, r"the following arguments are required: scenario"),
    C(("validate", "{tmp}/missing.yaml"), 2, r"missing.yaml: file not found"),
    C(("validate", "{tmp}"), 2, r"is a directory"),
    C(("schema", "teleport"), 2, r"unknown kind 'teleport'; valid kinds: "),
    C(("schema", ""), 2, r"unknown kind ''"),
    C(("bench", "--section", "nope"), 2, r"--section: invalid choice: 'nope'"),
    C(("bench", "--frobnicate"), 2, r"unrecognized arguments: --frobnicate"),
    # serve: every row fails before a server starts
    C(("serve", "--port", "0"), 2, r"--port must be within 1\.\.65535\. Got: 0"),
    C(("serve", "--port", "70000"), 2, r"--port must be within 1\.\.65535\. Got: 70000"),
    C(("serve", "--port", "abc"), 2, r"--port: invalid int value: 'abc'"),
    C(("serve", "--workers", "0"), 2, r"--workers must be >= 1"),
    C(("serve", "--workers", "-3"), 2, r"--workers must be >= 1"),
    C(("serve", "--host", "0.0.0.0"), 2, r"binding to 0.0.0.0 requires --token-file"),
    C(("serve", "--token-file", "{tmp}/missing"), 2, r"cannot read --token-file .*missing"),
    C(("serve", "--frobnicate"), 2, r"unrecognized arguments: --frobnicate"),
    C(("serve", "--max-body", "nan"), 2, r"--max-body"),
    C(("serve", "--run-memory", "inf"), 2, r"--run-memory"),
]

# -- scenario files ---------------------------------------------------------------------------
BASES: dict[str, dict[str, Any]] = {
    "workspace": {
        "kind": "workspace",
        "units": {"length": "in", "angle": "deg"},
        "samples": 2000,
        "cell": 0.4,
        "voxel_size": 1.0,
        "seed": 0,
        "report_grid": False,
    },
    "trajectory": {
        "kind": "trajectory",
        "units": {"length": "in", "angle": "rad"},
        "start": [0, 0, 0, 0, 0],
        "sample_rate": 50,
        "compare": False,
        "segments": [{"motion": "free", "to_q": [0.5, 0.4, -0.3, 0.2, 0], "tt": 1.0, "ta": 0.25}],
    },
    "parallel_ik": {
        "kind": "parallel_ik",
        "units": {"length": "mm", "angle": "deg"},
        "pose": [260, 180, 30],
    },
    "parallel_workspace": {
        "kind": "parallel_workspace",
        "units": {"length": "mm", "angle": "deg"},
        "alphas": [20],
        "step": 10,
        "region": {"x": [70, 420], "y": [0, 320]},
    },
    "singularity": {
        "kind": "singularity",
        "units": {"length": "mm", "angle": "deg"},
        "task": "position_pitch",
        "line": {"start": [110.0, 1.0, 380.0], "end": [-110.0, 1.0, 380.0], "pitch": 180.0},
        "timing": {"duration": 1.0, "blend": 0.25, "hold": 0.5},
        "q_reference": [0.0, 90.0, -40.0, 130.0, 0.0],
        "control": {"dt": 0.01, "gain": 1.0},
        "tr": {"m_bar_fraction": 0.05, "sigma_fraction": 0.05, "k_r": 20.0},
        "dls": {"lambda_max": 0.02, "lambda_min": 0.0001},
    },
    "task": {
        "kind": "task",
        "units": {"length": "in", "angle": "deg"},
        "sample_rate": 50,
        "timing": {"tt": 2.0, "ta": 0.5},
        "obstacles": [
            {"name": "wall", "type": "box", "min_corner": [5, 4.5, -2], "size": [10, 1, 8]}
        ],
        "waypoints": {"A": {"q": [104, 57, -59, 40, 0]}, "B": {"q": [109, 79, -93, 25, 0]}},
        "segments": [{"from": "A", "to": "B", "motion": "free"}],
    },
    # kind ``plan`` (issue 14): its cases run once the kind is registered
    "plan": {
        "kind": "plan",
        "units": {"length": "m", "angle": "deg"},
        "obstacles": [
            {"name": "table", "type": "box", "centre": [0.0, 0.1, -0.105], "size": [0.9, 0.7, 0.03]}
        ],
        "start": [30, 60, -90, 60, 0],
        "goal": {"q": [150, 45, -60, 90, 90]},
        "planner": {"seed": 0, "time_limit": 5.0},
    },
}

#: Bad values applied to every numeric key listed per kind: (value, pattern after the key path).
_NUMERIC_BAD: list[tuple[Any, str]] = [
    (NAN, r""),
    (INF, r""),
    (-INF, r""),
    ("abc", r""),
    ([1, 2], r""),
    ({"a": 1}, r""),
    (None, r""),
]

_NUMERIC_KEYS: dict[str, list[str]] = {
    "workspace": ["samples", "cell", "voxel_size", "seed"],
    "trajectory": [
        "start[0]",
        "segments[0].to_q[4]",
        "segments[0].tt",
        "segments[0].ta",
        "sample_rate",
    ],
    "parallel_ik": ["pose[0]", "pose[2]"],
    "parallel_workspace": ["alphas[0]", "step", "region.x[0]"],
    "singularity": [
        "line.start[0]",
        "line.pitch",
        "timing.duration",
        "timing.blend",
        "control.dt",
        "q_reference[1]",
        "tr.k_r",
        "dls.lambda_max",
    ],
    "task": ["sample_rate", "timing.tt", "waypoints.A.q[0]", "obstacles[0].size[1]"],
    "plan": ["start[0]", "planner.time_limit", "planner.seed"],
}


def _key_regex(path: str, value: Any = 0.0) -> str:
    """The key path as a regex; pydantic may insert a union tag (``timing.fixed.tt``), and a
    missing (null) value may be reported on the parent (``segments[0]: give both tt and ta``)."""
    regex = path.replace("[", r"\[").replace("]", r"\]").replace(".", r"\.(?:[a-z_]+\.)?")
    if value is None and "." in path:
        parent = _key_regex(path.rsplit(".", 1)[0])
        return f"(?:{regex}|{parent})"
    return regex


SCENARIOS: list[S] = [
    *[
        S(kind, {path: value}, _key_regex(path, value) + pattern)
        for kind, paths in _NUMERIC_KEYS.items()
        for path in paths
        for value, pattern in _NUMERIC_BAD
    ],
    # values beyond reason (finite numbers that are out of every documented range)
    S("workspace", {"samples": 10**12}, r"samples"),
    S("workspace", {"samples": 0}, r"samples"),
    S("workspace", {"samples": -1}, r"samples"),
    S("workspace", {"cell": 1e-9}, r"cell"),
    S("workspace", {"cell": -1}, r"cell"),
    S("workspace", {"voxel_size": 1e-12}, r"voxel_size"),
    S("workspace", {"seed": -1}, r"seed"),
    S("workspace", {"seed": 2**70}, r"seed"),
    S("workspace", {"seed": 1.5}, r"seed"),
    S("workspace", {"samples": 1.5}, r"samples"),
    S("trajectory", {"start[0]": 1e19}, r"start"),
    S("trajectory", {"segments[0].to_q[0]": 1e300}, r"to_q"),
    S("trajectory", {"segments[0].tt": -1.0}, r"segments\[0\]\.tt"),
    S("trajectory", {"segments[0].tt": 0}, r"segments\[0\]\.tt"),
    S("trajectory", {"segments[0].tt": 1e9}, r"segments\[0\]\.tt"),
    S("trajectory", {"segments[0].ta": 0.9}, r"segments\[0\]"),
    S("trajectory", {"segments[0].ta": -0.1}, r"segments\[0\]\.ta"),
    S("trajectory", {"sample_rate": 0}, r"sample_rate"),
    S("trajectory", {"sample_rate": -10}, r"sample_rate"),
    S("trajectory", {"sample_rate": 1e12}, r"sample_rate"),
    S("trajectory", {"segments[0].motion": "teleport"}, r"segments\[0\]\.motion"),
    S("trajectory", {"segments": []}, r"segments"),
    S("trajectory", {"segments[0].to_q": [0, 0, 0]}, r"segments\[0\]\.to_q"),
    S("trajectory", {"segments[0].to_pose": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}, r"segments\[0\]"),
    S("trajectory", {"start": DELETE}, r"start"),
    S("trajectory", {"limits": {"acceleration": 0}}, r"limits\.acceleration"),
    S("trajectory", {"limits": {"acceleration": NAN}}, r"limits\.acceleration"),
    S("trajectory", {"limits": {"jerk": -5}}, r"limits\.jerk"),
    S("trajectory", {"units": {"length": "furlong"}}, r"units\.length"),
    S("trajectory", {"units": {"angle": "grad"}}, r"units\.angle"),
    S("trajectory", {"units": "in"}, r"units"),
    S("trajectory", {"kind": "teleport"}, r"unknown kind 'teleport'"),
    S("trajectory", {"kind": DELETE}, r"kind"),
    S("trajectory", {"kind": 5}, r"kind"),
    S("trajectory", {"sampl_rate": 5}, r"sampl_rate"),
    S("trajectory", {"expect": {"max_duration": "<= 5 parsecs"}}, r"max_duration"),
    S("trajectory", {"expect": {"max_duration": "<= nan s"}}, r"max_duration"),
    S("trajectory", {"expect": {"nonexistent_metric": True}}, r"nonexistent_metric"),
    S("parallel_ik", {"pose[0]": 1e300}, r"pose"),
    S("parallel_ik", {"pose[2]": 1e19}, r"pose"),
    S("parallel_ik", {"pose": [1, 2]}, r"pose"),
    S("parallel_ik", {"pose": [0, 0, 0]}, r"leg [ABC] cannot reach"),
    S("parallel_ik", {"geometry": {"proximal": -1}}, r"geometry\.proximal"),
    S("parallel_ik", {"geometry": {"distal": NAN}}, r"geometry\.distal"),
    S("parallel_ik", {"units": {"length": "cubit"}}, r"units\.length"),
    S("parallel_workspace", {"step": 1e-9}, r"step|grid points"),
    S("parallel_workspace", {"step": 0}, r"step"),
    S("parallel_workspace", {"step": -3}, r"step"),
    S("parallel_workspace", {"step": 1000}, r"step 1000 mm is larger than the region"),
    S("parallel_workspace", {"alphas": []}, r"alphas"),
    S("parallel_workspace", {"alphas": list(range(400))}, r"alphas"),
    S("parallel_workspace", {"alphas[0]": 1e300}, r"alpha"),
    S("parallel_workspace", {"region": {"x": [420, 70], "y": [0, 320]}}, r"region"),
    S("parallel_workspace", {"mode": "+x+"}, r"mode"),
    S("singularity", {"timing.duration": -1}, r"timing\.duration"),
    S("singularity", {"timing.duration": 1e12}, r"duration = 1000000000000.0 must be <= 86400 s"),
    S("singularity", {"timing.blend": 5.0}, r"timing|blend"),
    S("singularity", {"timing.hold": -1}, r"timing\.hold"),
    S("singularity", {"control.dt": 1e-12}, r"control\.dt|samples|steps"),
    S("singularity", {"control.dt": 0}, r"control\.dt"),
    S("singularity", {"control.gain": -1}, r"control\.gain"),
    S("singularity", {"task": "teleport"}, r"task"),
    S("singularity", {"q_reference": [0, 0, 0]}, r"q_reference"),
    S("singularity", {"q_reference[0]": 1e19}, r"q_reference"),
    S("singularity", {"line.pitch": 1e300}, r"pitch"),
    S("singularity", {"tr.m_bar_fraction": 2.0}, r"tr\.m_bar_fraction"),
    S("singularity", {"dls.lambda_min": 0}, r"dls\.lambda_min"),
    S("singularity", {"dls.lambda_min": 1e-300}, r"lambda_min = 1e-300 must be within"),
    S("singularity", {"dls.lambda_max": 1e308}, r"lambda_max = 1e\+308 must be within"),
    S("singularity", {"control.gain": 1e19}, r"gain = 1e\+19 must be <= 1 / dt"),
    S("singularity", {"timing.duration": 1e308}, r"duration = 1e\+308 must be <= 86400 s"),
    S("singularity", {"timing.hold": 1e308}, r"hold = 1e\+308 must be <= 86400 s"),
    S("workspace", {"cell": 1e308}, r"cell = 2.54e\+306 is out of range"),
    S("workspace", {"voxel_size": 1e-300}, r"voxel_size"),
    S("task", {"sample_rate": 0}, r"sample_rate"),
    S("task", {"sample_rate": 1e12}, r"sample_rate"),
    S("task", {"timing.tt": -2}, r"timing\.(fixed\.)?tt: Input should be greater than 0"),
    S("task", {"timing.ta": 5}, r"timing"),
    S("task", {"waypoints.A.q": [0, 0]}, r"waypoints\.A\.q"),
    S("task", {"waypoints.A.q[1]": 1e300}, r"waypoints\.A"),
    S("task", {"segments[0].to": "Z"}, r"segments\[0\]\.to|'Z'"),
    S("task", {"segments[0].from": "Q"}, r"segments\[0\]\.from|'Q'"),
    S("task", {"segments[0].motion": "warp"}, r"segments\[0\]\.motion"),
    S("task", {"obstacles[0].size[0]": -1}, r"obstacles\[0\]\.size|size"),
    S("task", {"obstacles[0].size[0]": 0}, r"obstacles\[0\]\.size|size"),
    S("task", {"obstacles[0].size[0]": 1e300}, r"obstacles\[0\]|size"),
    S("task", {"obstacles[0].type": "torus"}, r"obstacles\[0\]"),
    S("task", {"obstacles[0].min_corner": [0, 0]}, r"obstacles\[0\]\.(box\.)?min_corner"),
    S("task", {"robot": {"urdf": "/nonexistent.urdf"}}, r"nonexistent\.urdf|robot"),
    S("task", {"robot": {"name": "r2d2"}}, r"robot|r2d2"),
    S("plan", {"planner.seed": -1}, r"planner\.seed"),
    S("plan", {"planner.seed": 2**70}, r"planner\.seed"),
    S("plan", {"planner.time_limit": 1e9}, r"planner\.time_limit|planning time"),
    S("plan", {"planner.time_limit": 0}, r"planner\.time_limit"),
    S("plan", {"planner.max_nodes": 10**12}, r"planner\.max_nodes"),
    S("plan", {"planner.sample_rate": 0}, r"planner\.sample_rate"),
    S("plan", {"planner.goal_bias": 2}, r"planner\.goal_bias"),
    S("plan", {"goal": {}}, r"goal"),
]

# -- raw files ----------------------------------------------------------------------------------
FILES: list[F] = [
    F("latin1.yaml", b"kind: caf\xe9\n", r"not UTF-8 text.*\(line 1\)"),
    F("binary.yaml", b"\x7fELF\x02\x01\x01\x00\x00", r"binary file \(NUL byte\)"),
    F("empty.yaml", b"", r"empty file"),
    F("comment.yaml", b"# nothing\n", r"empty file"),
    F("list.yaml", b"- kind: workspace\n", r"top level must be a mapping .*not a list"),
    F("scalar.yaml", b"workspace\n", r"top level must be a mapping"),
    F("dup.yaml", b"kind: workspace\nsamples: 1\nsamples: 2\n", r"duplicate key 'samples'"),
    F("unhashable.yaml", b"kind: workspace\n? [a, b]\n: 1\n", r"unhashable key"),
    F("intkey.yaml", b"kind: workspace\n1: 2\n", r"top-level key 1 is not a string"),
    F("tag.yaml", b"kind: !!python/object/apply:os.system [ls]\n", r"invalid YAML"),
    F("broken.yaml", b"kind: [workspace\n", r"invalid YAML.*\(line 2\)"),
    F("tab.yaml", b"kind: workspace\n\tsamples: 1\n", r"invalid YAML.*\(line 2\)"),
    F("multi.yaml", b"kind: workspace\n---\nkind: task\n", r"another document"),
    F("alias_loop.yaml", b"kind: workspace\na: &a [*a]\n", r"alias refers to a node"),
    F(
        "bomb.yaml",
        (
            "kind: workspace\na0: &a0 [x, x, x, x, x, x, x, x, x, x]\n"
            + "".join(
                f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]\n" for i in range(1, 9)
            )
        ).encode(),
        r"anchors/aliases expand to more than",
    ),
    F("deep.yaml", b"kind: " + b"[" * 3000 + b"]" * 3000 + b"\n", r"nesting deeper than 64"),
    F("huge.yaml", b"kind: workspace\n#" + b"x" * (5 * 1024 * 1024) + b"\n", r"more than the lim"),
    F("noperm.yaml", b"kind: workspace\n", r"cannot read file \(Permission denied\)", mode=0),
]
