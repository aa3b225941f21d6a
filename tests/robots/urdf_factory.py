"""Random URDFs of the yaw-pitch-pitch-pitch-roll family, written with full float precision."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np


def _f(x: float) -> str:
    return repr(float(x))


def _joint(
    name: str,
    parent: str,
    child: str,
    xyz: np.ndarray,
    rpy: tuple[float, float, float],
    axis: tuple[float, float, float],
    lower: float,
    upper: float,
) -> str:
    return (
        f'  <joint name="{name}" type="revolute">\n'
        f'    <parent link="{parent}"/><child link="{child}"/>\n'
        f'    <origin xyz="{" ".join(map(_f, xyz))}" rpy="{" ".join(map(_f, rpy))}"/>\n'
        f'    <axis xyz="{" ".join(map(_f, axis))}"/>\n'
        f'    <limit lower="{_f(lower)}" upper="{_f(upper)}" effort="1" velocity="3"/>\n'
        f"  </joint>\n"
    )


def random_family_urdf(
    rng: np.random.Generator, off_axis_tool: bool = True, approach_is_z: bool = False
) -> str:
    """A yaw-pitch^3-roll arm with random lengths, offsets, signs, built-in angles, zeros, tool."""
    links = "".join(f'  <link name="l{i}"/>\n' for i in range(6)) + '  <link name="tool"/>\n'
    sign = lambda: float(rng.choice([-1.0, 1.0]))  # noqa: E731
    joints = _joint(
        "j1",
        "l0",
        "l1",
        rng.uniform(-0.03, 0.03, 3) + np.array([0, 0, 0.05]),
        (0.0, 0.0, rng.uniform(-math.pi, math.pi)),
        (0, 0, sign()),
        -2.5,
        2.5,
    )
    # pitch joints about +-y; built-in angles about y keep the axes parallel; any offsets
    joints += _joint(
        "j2",
        "l1",
        "l2",
        rng.uniform(-0.03, 0.03, 3),
        (0.0, rng.uniform(-1, 1), 0.0),
        (0, sign(), 0),
        -2.0,
        2.0,
    )
    joints += _joint(
        "j3",
        "l2",
        "l3",
        np.array([rng.uniform(0.08, 0.2), rng.uniform(-0.03, 0.03), rng.uniform(-0.04, 0.04)]),
        (0.0, rng.uniform(-1, 1), 0.0),
        (0, sign(), 0),
        -2.6,
        2.6,
    )
    joints += _joint(
        "j4",
        "l3",
        "l4",
        np.array([rng.uniform(0.08, 0.2), rng.uniform(-0.03, 0.03), rng.uniform(-0.04, 0.04)]),
        (0.0, rng.uniform(-1, 1), 0.0),
        (0, sign(), 0),
        -2.0,
        2.0,
    )
    # roll about +-x (perpendicular to y), with a built-in angle about y
    joints += _joint(
        "j5",
        "l4",
        "l5",
        np.array([rng.uniform(0.0, 0.05), rng.uniform(-0.02, 0.02), rng.uniform(-0.02, 0.02)]),
        (0.0, rng.uniform(-1, 1), 0.0),
        (sign(), 0, 0),
        -2.8,
        2.8,
    )
    tool_xyz = np.array([rng.uniform(0.02, 0.1), 0.0, 0.0])
    if off_axis_tool:
        tool_xyz[1:] = rng.uniform(-0.012, 0.012, 2)
    rpy = rng.uniform(-math.pi, math.pi, 3)
    if approach_is_z:  # tool z along the roll axis (x of l5), any angle about it
        rpy = np.array([0.0, math.pi / 2, 0.0])
    joints += (
        '  <joint name="tool_joint" type="fixed">\n'
        '    <parent link="l5"/><child link="tool"/>\n'
        f'    <origin xyz="{" ".join(map(_f, tool_xyz))}" rpy="{" ".join(map(_f, rpy))}"/>\n'
        "  </joint>\n"
    )
    return f'<?xml version="1.0"?>\n<robot name="random_arm">\n{links}{joints}</robot>\n'


def write_random_family_urdfs(folder: Path, count: int, seed: int) -> list[Path]:
    rng = np.random.default_rng(seed)
    paths = []
    for i in range(count):
        path = folder / f"arm_{i:03d}.urdf"
        path.write_text(random_family_urdf(rng, off_axis_tool=i % 3 != 0))
        paths.append(path)
    return paths


def tilted_urdf(path: Path, angle: float = 4e-6, joint: str = "j3") -> Path:
    """The URDF with a joint's axis tilted by angle [rad], as real URDFs' rounded angles tilt
    them (the SO-101: 3.7e-6 rad): a model only close to the family, whose branches are
    polished. Joint 3 (its built-in roll): the pitch axes no longer parallel; joint 5 (its
    built-in yaw): the roll axis no longer square to the pitch axes, as in the SO-101."""
    text = path.read_text()
    start = text.index(f'<joint name="{joint}"')
    at = text.index('rpy="', start) + len('rpy="')
    end = text.index('"', at)
    rpy = [float(v) for v in text[at:end].split()]
    rpy[0 if joint == "j3" else 2] += angle
    tilted = path.with_name(f"tilted_{joint}_" + path.name)
    tilted.write_text(text[:at] + " ".join(map(repr, rpy)) + text[end:])
    return tilted
