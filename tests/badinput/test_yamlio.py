"""The hardened YAML reader: every malformed file is one ScenarioError naming the file."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

from lynxplan.exceptions import LynxplanInputError, ScenarioError
from lynxplan.yamlio import MAX_DEPTH, read_yaml_mapping


def _bomb(levels: int, fan: int = 9) -> str:
    lines = ["kind: workspace", "a0: &a0 [" + ", ".join(["lol"] * fan) + "]"]
    for i in range(1, levels + 1):
        lines.append(f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * fan) + "]")
    return "\n".join(lines) + "\n"


def _map_bomb(levels: int) -> str:
    lines = ["b0: &b0 {x: 1, y: 1}"]
    lines += [f"b{i}: &b{i} {{p: *b{i - 1}, q: *b{i - 1}}}" for i in range(1, levels)]
    return "\n".join(lines) + "\n"


#: (file name, content as bytes, regex the message must match after "scenario <file>")
CASES: list[tuple[str, bytes, str]] = [
    ("dup.yaml", b"kind: x\na: 1\na: 2\n", r": invalid YAML: duplicate key 'a'.*\(line 3\)"),
    ("dup_nested.yaml", b"kind: x\nb:\n  c: 1\n  c: 2\n", r": .*duplicate key 'c'.*\(line 4\)"),
    ("unhashable.yaml", b"? [a, b]\n: 1\n", r": invalid YAML: unhashable key \(list\).*\(line 1\)"),
    (
        "unhashable_map.yaml",
        b"kind: x\nb: {{a: 1}: 2}\n",
        r": .*unhashable key \(dict\).*\(line 2\)",
    ),
    ("latin1.yaml", b"kind: caf\xe9\n", r": not UTF-8 text \(byte 0xe9 at offset 9\).*\(line 1\)"),
    ("latin1_l3.yaml", b"kind: x\n\nname: \xff\n", r": not UTF-8.*\(line 3\)"),
    ("utf16.yaml", "kind: x\n".encode("utf-16"), r"(binary file|not UTF-8)"),
    ("binary.yaml", b"\x7fELF\x02\x01\x01\x00\x00", r": binary file \(NUL byte\).*\(line 1\)"),
    ("empty.yaml", b"", r": empty file"),
    ("blank.yaml", b"\n\n   \n", r": empty file"),
    ("comments.yaml", b"# only a comment\n", r": empty file"),
    ("null.yaml", b"~\n", r"top level must be a mapping .*not a single value"),
    ("list.yaml", b"- kind: x\n", r": the top level must be a mapping .*not a list.*\(line 1\)"),
    ("scalar.yaml", b"hello\n", r"top level must be a mapping .*not a single value"),
    ("number.yaml", b"42\n", r"not a single value"),
    ("intkey.yaml", b"1: a\n", r": top-level key 1 is not a string"),
    ("boolkey.yaml", b"kind: x\nyes: 1\n", r": top-level key True is not a string"),
    ("nullkey.yaml", b"kind: x\n~: 1\n", r": top-level key None is not a string"),
    ("tag.yaml", b"kind: !!python/object:os.system x\n", r": invalid YAML: could not.*\(line 1\)"),
    ("tag_apply.yaml", b"kind: !!python/object/apply:os.system [ls]\n", r"invalid YAML"),
    ("broken.yaml", b"kind: [1, 2\n", r": invalid YAML: .*expected ','.*\(line 2\)"),
    ("tab.yaml", b"kind: x\n\tb: 1\n", r": invalid YAML.*\(line 2\)"),
    ("colon.yaml", b"kind: x\nb: c: d\n", r": invalid YAML: mapping values.*\(line 2\)"),
    ("multi.yaml", b"a: 1\n---\nb: 2\n", r"invalid YAML: but found another document"),
    (
        "undefined_alias.yaml",
        b"kind: *nope\n",
        r": invalid YAML: found undefined alias.*\(line 1\)",
    ),
    (
        "self_alias.yaml",
        b"a: &a [*a]\n",
        r": an alias refers to a node that contains it.*\(line 1\)",
    ),
    ("self_alias_map.yaml", b"a: &a {b: *a}\n", r"an alias refers to a node that contains it"),
    ("bomb.yaml", _bomb(9).encode(), r"anchors/aliases expand to more than 1000000 YAML nodes"),
    (
        "bomb_map.yaml",
        _map_bomb(25).encode(),
        r"anchors/aliases expand",
    ),
    (
        "deep_flow.yaml",
        b"kind: " + b"[" * 5000 + b"]" * 5000 + b"\n",
        r": nesting deeper.*\(line 1\)",
    ),
    ("deep_flow_map.yaml", b"kind: " + b"{a: " * 3000 + b"1" + b"}" * 3000 + b"\n", r"nesting"),
    (
        "deep_block.yaml",
        b"kind: x\nk:\n" + b"".join(b" " * (i + 1) + b"- \n" for i in range(MAX_DEPTH + 5)),
        r": nesting deeper than 64 levels.*\(line \d+\)",
    ),
    ("bad_escape.yaml", b'kind: "\\q"\n', r": invalid YAML: found unknown escape.*\(line 1\)"),
    ("control.yaml", b"kind: \x07\n", r"invalid YAML: .*(special|control) characters"),
]


@pytest.mark.parametrize(("name", "content", "pattern"), CASES, ids=[c[0] for c in CASES])
def test_malformed_file(tmp_path: Path, name: str, content: bytes, pattern: str) -> None:
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(ScenarioError) as info:
        read_yaml_mapping(path)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"scenario {path}"), message
    assert re.search(pattern, message), message
    assert isinstance(info.value, LynxplanInputError)


def test_missing_directory_device_and_size(tmp_path: Path) -> None:
    with pytest.raises(ScenarioError, match=r"missing.yaml: file not found$"):
        read_yaml_mapping(tmp_path / "missing.yaml")
    with pytest.raises(ScenarioError, match=r": is a directory, not a scenario file$"):
        read_yaml_mapping(tmp_path)
    with pytest.raises(ScenarioError, match=r"/dev/zero: is not a regular file"):
        read_yaml_mapping("/dev/zero")
    big = tmp_path / "big.yaml"
    big.write_text("kind: x\n# " + "a" * 200 + "\n")
    with pytest.raises(ScenarioError, match=r"file is 211 bytes, more than the limit of 100"):
        read_yaml_mapping(big, max_bytes=100)
    with pytest.raises(ScenarioError, match=r"not a directory|file not found|cannot read"):
        read_yaml_mapping(big / "inside.yaml")


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads files without read permission")
def test_unreadable_file(tmp_path: Path) -> None:
    path = tmp_path / "secret.yaml"
    path.write_text("kind: x\n")
    path.chmod(0)
    with pytest.raises(ScenarioError, match=r"secret.yaml: cannot read file \(Permission denied\)"):
        read_yaml_mapping(path)


def test_valid_files_read_as_plain_data(tmp_path: Path) -> None:
    path = tmp_path / "ok.yaml"
    path.write_bytes(
        b"\xef\xbb\xbfkind: trajectory\nbase: &b {x: 1.5, y: [1, 2]}\nother: *b\nnan: .nan\n"
    )
    data = read_yaml_mapping(path)
    assert data["kind"] == "trajectory" and data["other"] == {"x": 1.5, "y": [1, 2]}
    assert data["nan"] != data["nan"]  # NaN is read; the guards reject it where it is used
    path.write_text("kind: x\nk: " + _bomb(3).replace("\n", " ").split("a3:")[0] + "\n")
    shipped = sorted(Path(__file__).resolve().parents[2].glob("scenarios/**/*.yaml"))
    assert shipped
    for scenario in shipped:
        assert isinstance(read_yaml_mapping(scenario)["kind"], str)


def test_node_limit_is_exact(tmp_path: Path) -> None:
    path = tmp_path / "fan.yaml"
    path.write_text(_bomb(2, fan=3))  # 3 + 3*... nodes, well under any default
    assert len(read_yaml_mapping(path)["a2"]) == 3
    with pytest.raises(ScenarioError, match=r"expand to more than 10 YAML nodes"):
        read_yaml_mapping(path, max_nodes=10)
