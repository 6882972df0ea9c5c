"""The fast scene reader (collide/scene_fast.py: libyaml or json) against the line-numbered one
(scene.py's PyYAML composer): the same data and Scene for the repository's scenes and generated ones,
what it leaves to the line-numbered reader, and that large or hostile files keep their line numbers,
paths and depth limit. Nothing is timed (bench/scene_load.py times them)."""
from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
import yaml

import collide
from collide import SceneError, load_scene
from collide.scene import _MAX_DEPTH, _MAX_NODES, _load_lined, _parse_text, load_scene_text, read_scene_text
from collide.scene_fast import NotPlain, read_plain
from bench_module import load_node_bench

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "scenes"


def _node_bench() -> ModuleType:
    """bench/node_bench.py (its big_scene and pile_scene generate the scenes the benches load)."""
    return load_node_bench()


def same(a: Any, b: Any) -> bool:
    """Equal with the same types everywhere (== takes 1 for 1.0 and True for 1; repr does not)."""
    return repr(a) == repr(b)


def both_readers(text: str, source: str) -> tuple[collide.Scene, collide.Scene]:
    """load_scene_text's Scene, which must come from the fast reader, and the line-numbered reader's."""
    fast = load_scene_text(text, source)
    assert fast._relines is not None and not fast._lines, "the fast reader was not used"
    lined = _load_lined(text, source, source.endswith(".json"), True)
    assert lined._lines
    return fast, lined


def scene_files(tmp_path: Path) -> list[Path]:
    """The repository's scenes, each also as JSON and YAML (Scene.dump) and as compact JSON, and
    bench/node_bench.py's generated scenes in both formats."""
    nb = _node_bench()
    out = sorted(SCENES.glob("*.yaml")) + sorted(SCENES.glob("*.json"))
    for f in list(out):
        sc = load_scene(f)
        for suffix in (".yaml", ".json"):
            out.append(tmp_path / f"{f.stem}_dumped{suffix}")
            sc.dump(out[-1])
        out.append(tmp_path / f"{f.stem}_compact.json")
        out[-1].write_text(json.dumps(sc.to_dict(), separators=(",", ":")))
    nb.big_scene(300, tmp_path / "big300.yaml")
    pile = nb.pile_scene(60)
    (tmp_path / "pile60.yaml").write_text(yaml.safe_dump(pile))
    (tmp_path / "pile60_flow.yaml").write_text(yaml.safe_dump(pile, default_flow_style=True, width=200))
    (tmp_path / "pile60.json").write_text(json.dumps(pile, indent=1))
    load_scene(tmp_path / "big300.yaml").dump(tmp_path / "big300.json")
    return out + [tmp_path / n for n in ("big300.yaml", "big300.json", "pile60.yaml", "pile60_flow.yaml",
                                         "pile60.json")]


def test_fast_and_lined_readers_agree_on_shipped_and_generated_scenes(tmp_path: Path) -> None:
    files = scene_files(tmp_path)
    assert len(files) >= 5 * 4 + 5
    for f in files:
        text, is_json = f.read_text(), f.suffix == ".json"
        data, _ = _parse_text(text, str(f), is_json)
        assert same(read_plain(text, is_json, _MAX_DEPTH, _MAX_NODES), data), f
        fast, lined = both_readers(text, str(f))
        assert fast == lined and same(fast.to_dict(), lined.to_dict()), f
        assert fast.names == lined.names and fast.source == lined.source == str(f)
        assert load_scene(f) == lined  # the public entry takes the same path
    # the built worlds hold the same bodies in the same state
    fast, lined = both_readers((tmp_path / "pile60.yaml").read_text(), str(tmp_path / "pile60.yaml"))
    wf, wl = fast.build(), lined.build()
    assert wf.names == wl.names and (wf.state == wl.state).all() and list(wf.masses) == list(wl.masses)


# plain scalars of every YAML 1.1 implicit type and the spellings the format reads as numbers
SCALARS = ["1", "-0", "0", "+1", "007", "010", "0x1F", "0b101", "1_000", "1:30", "190:20:30.15", "0.5", "-0.0",
           "1.", "+1.5", ".5", "-.5", "00.5", "1e-7", "1E5", "1.5e3", "1.5e+3", "1.0e-07", "1_0.5", "6.8523015e+5",
           ".inf", "-.inf", "+.INF", ".nan", ".NaN", "NaN", "nan", "inf", "-inf", "Infinity", "yes", "No", "ON", "off",
           "y", "n", "true", "True", "FALSE", "~", "null", "Null", "", "2001-12-14", "2001-12-14t21:59:43.10-05:00",
           "b12", "block1", "box", "polygon", "rk4", "'quoted 1'", '"2"', '"#2ca02c"', "'#fff'", "a b c",
           "x: y"]


@pytest.mark.parametrize("style", ["block", "flow"])
def test_every_kind_of_plain_scalar_reads_the_same(style: str) -> None:
    if style == "block":
        text = "".join(f"k{i}: {s}\n" for i, s in enumerate(SCALARS[:-1])) + "s:\n" + "".join(
            f"  - {s}\n" for s in SCALARS[:-1]) + "lit: |\n  two\n  lines\nfold: >\n  one\n  line\n"
    else:
        text = "{" + ", ".join(f"k{i}: {s}" for i, s in enumerate(SCALARS[:-1]) if s) + "}\n"
    lined, _ = _parse_text(text, "s.yaml", False)
    fast = read_plain(text, False, _MAX_DEPTH, _MAX_NODES)
    assert same(fast, lined), (fast, lined)
    assert fast["k0"] == 1 and type(fast["k17"]) is float and math.isnan(fast["k28"])


@pytest.mark.parametrize("text", [
    "a: &x 1\nb: *x\n",                      # anchors and aliases
    "a: !!float 1\n",                        # explicit tags, even known ones
    "a: !custom 1\n",
    "a: ! 1\n",
    "a: !!map {b: 1}\n",
    "a: 1\na: 2\n",                          # duplicate key
    "[1]: 2\n",                              # a key that is not a plain name
    "? {a: 1}\n: 2\n",
    "",                                      # no document
    "# only a comment\n",
    "a: 1\n---\nb: 2\n",                     # two documents
    "a: [1, 2\n",                            # malformed
    "a:\tb\n\tc: 1\n",
    "a: \x07\n",                             # a character PyYAML's reader refuses
    "a: =\n",                                # types SafeLoader cannot construct
    "a: <<\n",
    "a: " + "[" * (_MAX_DEPTH + 1) + "]" * (_MAX_DEPTH + 1) + "\n",  # deeper than the limit
])
def test_what_the_fast_reader_leaves_to_the_lined_one(text: str) -> None:
    with pytest.raises(NotPlain):
        read_plain(text, False, _MAX_DEPTH, _MAX_NODES)


@pytest.mark.parametrize("text", [
    '{"a": 1, "a": 2}',                      # duplicate key (json keeps the last)
    '{"a": "\\ud83d\\ude00"}',               # a surrogate pair (json joins it, PyYAML does not)
    '{"a": "\x7f"}',                         # json takes DEL, PyYAML's reader does not
    '{"a": [1, 2}',
    "",
    "[" * (_MAX_DEPTH + 2) + "]" * (_MAX_DEPTH + 2),
])
def test_what_the_fast_json_reader_leaves_to_the_lined_one(text: str) -> None:
    with pytest.raises(NotPlain):
        read_plain(text, True, _MAX_DEPTH, _MAX_NODES)


def test_value_count_limit_is_the_lined_readers() -> None:
    """A file with more values than _MAX_NODES is left to the line-numbered reader, which refuses it;
    one at the limit is read (the root counts, keys do not)."""
    text = "[" + ", ".join(["1"] * 9) + "]"
    for is_json in (False, True):
        assert read_plain(text, is_json, _MAX_DEPTH, 10) == [1] * 9
        with pytest.raises(NotPlain):
            read_plain(text, is_json, _MAX_DEPTH, 9)
    assert read_plain("{a: 1, b: [2]}", False, _MAX_DEPTH, 4) == {"a": 1, "b": [2]}
    with pytest.raises(NotPlain):
        read_plain("{a: 1, b: [2]}", False, _MAX_DEPTH, 3)


def big_file(tmp_path: Path, suffix: str, n: int = 600) -> tuple[Path, list[str]]:
    nb = _node_bench()
    path = tmp_path / f"big{suffix}"
    nb.big_scene(n, tmp_path / "big.yaml")
    if suffix == ".json":
        load_scene(tmp_path / "big.yaml").dump(path)
    return path, path.read_text().splitlines(keepends=True)


def line_of(lines: list[str], start: int, needle: str) -> int:
    """The 1-based number of the first line at or after line `start` (1-based) that holds `needle`."""
    return next(i + 1 for i in range(start - 1, len(lines)) if needle in lines[i])


@pytest.mark.parametrize("suffix", [".yaml", ".json"])
def test_bad_field_in_a_large_file_names_its_line_and_path(tmp_path: Path, suffix: str) -> None:
    path, lines = big_file(tmp_path, suffix)
    name = line_of(lines, 1, '"b400"' if suffix == ".json" else "name: b400\n")
    mass = line_of(lines, name - 1, "mass")  # YAML sorts a body's keys: mass just before name
    lines[mass - 1] = lines[mass - 1].replace("1.0", '"heavy"')
    path.write_text("".join(lines))
    with pytest.raises(SceneError) as err:
        load_scene(path)
    assert str(err.value) == f"{path}:{mass}: bodies[400].mass: expected a number, got str 'heavy'"
    assert err.value.errors == [(mass, "bodies[400].mass", "expected a number, got str 'heavy'")]
    text = path.read_text()
    with pytest.raises(SceneError) as lined:
        _load_lined(text, str(path), suffix == ".json", True)
    assert str(lined.value) == str(err.value)


@pytest.mark.parametrize("suffix", [".yaml", ".json"])
def test_range_error_from_c_in_a_large_file_names_its_line(tmp_path: Path, suffix: str) -> None:
    """A value only C refuses (mass -1) passes the fast reader's structure checks: the trial build's
    message, and a later build() of a scene loaded with validate=False, still name its line."""
    path, lines = big_file(tmp_path, suffix)
    name = line_of(lines, 1, '"b300"' if suffix == ".json" else "name: b300\n")
    body = max(i + 1 for i in range(name) if lines[i].lstrip().startswith(("- ", "{")))
    mass = line_of(lines, name - 1, "mass")
    lines[mass - 1] = lines[mass - 1].replace("1.0", "-1")
    path.write_text("".join(lines))
    with pytest.raises(SceneError) as err:
        load_scene(path)
    assert f"{path}:{body}: bodies[300]: mass = -1" in str(err.value), (body, str(err.value))
    unchecked = load_scene(path, validate=False)
    assert unchecked._relines is not None and not unchecked._lines  # the fast reader's scene
    with pytest.raises(SceneError) as built:
        unchecked.build()
    assert str(built.value) == str(err.value)


@pytest.mark.parametrize("name,text", [
    ("seq.yaml", "bodies: " + "[" * 5000 + "]" * 5000 + "\n"),
    ("map.yaml", "a: " + "{b: " * 5000 + "1" + "}" * 5000 + "\n"),
    ("block.yaml", "".join(" " * i + "- \n" for i in range(0, 200, 2)) + "bodies: []\n"),
    ("arr.json", "[" * 5000 + "]" * 5000),
    ("obj.json", '{"a": ' * 5000 + "1" + "}" * 5000),
    ("at_limit.yaml", "bodies: " + "[" * (_MAX_DEPTH - 1) + "1" + "]" * (_MAX_DEPTH - 1) + "\n"),
    ("over.yaml", "bodies: " + "[" * _MAX_DEPTH + "1" + "]" * _MAX_DEPTH + "\n"),
    ("over.json", '{"bodies": ' + "[" * _MAX_DEPTH + "1" + "]" * _MAX_DEPTH + "}"),
])
def test_deep_nesting_gives_the_lined_readers_error(tmp_path: Path, name: str, text: str) -> None:
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(SceneError) as err:
        load_scene(path)
    with pytest.raises(SceneError) as lined:
        _load_lined(read_scene_text(path), str(path), name.endswith(".json"), True)
    assert str(err.value) == str(lined.value)
    assert ("nested more than" in str(err.value)) == (not name.startswith("at_limit")), str(err.value)


def test_nesting_that_would_crash_a_recursive_c_composer(tmp_path: Path) -> None:
    """libyaml's own composer (yaml.compose with CSafeLoader) recurses in C per level and crashes on
    a million levels; the fast reader reads libyaml's events without recursion and stops at the
    limit. In a child process, so a crash fails this test rather than ending the run."""
    code = f"""
import collide, sys
from pathlib import Path
for name, text in (("s.yaml", "[" * 10**6 + "]" * 10**6), ("m.yaml", "{{a: " * 10**6 + "1" + "}}" * 10**6),
                   ("s.json", "[" * 10**6 + "]" * 10**6)):
    p = Path(sys.argv[1]) / name
    p.write_text(text)
    try:
        collide.load_scene(p)
    except collide.SceneError as exc:
        print(str(exc).split(": ", 1)[1])
"""
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.splitlines() == [
        f"[0][0][0][0]...: nested more than {_MAX_DEPTH} levels deep (a valid scene nests at most 6)",
        f"a.a.a.a...: nested more than {_MAX_DEPTH} levels deep (a valid scene nests at most 6)",
        f"[0][0][0][0]...: nested more than {_MAX_DEPTH} levels deep (a valid scene nests at most 6)"]


def test_without_libyaml_the_lined_reader_reads_yaml(monkeypatch: pytest.MonkeyPatch) -> None:
    """PyYAML built without libyaml: YAML files go to the line-numbered reader, JSON keeps json."""
    text = (SCENES / "default.yaml").read_text()
    monkeypatch.setattr(yaml, "__with_libyaml__", False)
    with pytest.raises(NotPlain):
        read_plain(text, False, _MAX_DEPTH, _MAX_NODES)
    sc = load_scene_text(text, "default.yaml")
    assert sc._relines is None and sc._lines and sc == collide.default_scene()
    assert read_plain('{"bodies": []}', True, _MAX_DEPTH, _MAX_NODES) == {"bodies": []}
