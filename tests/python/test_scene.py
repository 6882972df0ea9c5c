"""Scene files: valid files, the embedded default scene, and each kind of malformed file."""
from __future__ import annotations

import gc
import json
import math
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
import yaml

import collide
from collide import SceneError, default_scene, load_scene

SCENES = Path(__file__).resolve().parents[2] / "scenes"

VALID = """\
version: 1
description: test scene
world:
  gravity: [0, -9.81]
  contact_gap: 1e-7
  integrator: rk4
walls: {xmin: -5, ymin: -5, xmax: 5, ymax: 5, thickness: 0.5}
bodies:
  - name: box
    shape: box
    width: 1
    height: 2
    position: [-1, 0]
    velocity: [1, 0]
    mass: 2
    thrusters: default
  - name: tri
    shape: polygon
    vertices: [[0, 0], [1, 0], [0, 1]]
    position: [2, 0]
    elasticity: 0.5
    friction: 0.2
    thrusters:
      - {point: [0.2, 0.2], direction: [0, 1], magnitude: 3}
    external: {force: [0, 1], torque: 0.1}
springs:
  - {name: s, body_a: box, point_a: [0, 1], body_b: tri, stiffness: 4}
  - {body_a: tri, point_b: [3, 3]}
run: {dt: 0.005, duration: 2}
"""


def valid_data() -> dict:
    data = yaml.safe_load(VALID)
    data["world"]["contact_gap"] = 1e-7  # plain YAML 1.1 reads 1e-7 as text; the scene reader does not
    return data


def write(tmp_path: Path, text: str, name: str = "scene.yaml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def test_valid_yaml_scene_loads_and_builds(tmp_path: Path) -> None:
    sc = load_scene(write(tmp_path, VALID))
    assert sc.world["gravity"] == [0.0, -9.81] and sc.world["contact_gap"] == 1e-7
    assert sc.run == {"dt": 0.005, "duration": 2.0}
    w = sc.build()
    assert w.names == ["wall_bottom", "wall_right", "wall_top", "wall_left", "box", "tri"]
    assert w.settings["contact_gap"] == 1e-7 and w.settings["gravity"] == (0.0, -9.81)
    assert len(w.body("box").thrusters) == 4 and len(w.body("tri").thrusters) == 1
    assert w.body("box").mass == 2.0 and w.body("tri").elasticity == 0.5
    assert w.spring_count == 2 and w.spring("s").definition["stiffness"] == 4.0
    assert sc.names == w.names


def test_json_scene_equals_yaml_scene_and_dump_round_trips(tmp_path: Path) -> None:
    sc = load_scene(write(tmp_path, VALID))
    as_json = write(tmp_path, json.dumps(valid_data()), "scene.json")
    assert load_scene(as_json) == sc
    sc.dump(tmp_path / "out.yaml")
    sc.dump(tmp_path / "out.json")
    assert load_scene(tmp_path / "out.yaml") == sc
    assert load_scene(tmp_path / "out.json") == sc
    assert load_scene(sc.to_dict()) == sc


def test_default_scene_reproduces_the_seed_demo() -> None:
    sc = default_scene()
    w = sc.build()
    assert w.names == ["wall_bottom", "wall_right", "wall_top", "wall_left", "block1", "block2"]
    w6 = default_scene(blocks=6, green_mass=2.5, gravity=9.81, elasticity=0.8, damping=0.1).build()
    assert w6.names[4:] == [f"block{i}" for i in range(1, 7)]
    np.testing.assert_array_equal(w6.masses[4:], [2.5, 1, 1, 1, 1, 1])
    assert [len(w6.body(f"block{i}").thrusters) for i in range(1, 7)] == [4, 4, 0, 0, 0, 0]
    st = w6.settings
    assert st["gravity"] == (0.0, -9.81) and st["damping"] == 0.1 and st["damping_rotation_ratio"] == 0.1
    assert w6.body("block3").elasticity == 0.8 and w6.body("wall_top").elasticity == 0.8
    # 1 m x 3 m blocks: corners at distance sqrt(0.5^2 + 1.5^2) from the centre (rounding only)
    v = w6.body("block1").world_vertices()
    np.testing.assert_allclose(np.hypot(v[:, 0] + 2.5, v[:, 1]), [math.hypot(0.5, 1.5)] * 4, rtol=1e-12)
    # every block inside the inner box [-6, 6]^2 and no two blocks overlapping (axis-aligned boxes)
    boxes = [w6.body(f"block{i}").world_vertices() for i in range(1, 7)]
    assert all((np.abs(b) < 6.0).all() for b in boxes)
    for i in range(6):
        for j in range(i + 1, 6):
            lo_i, hi_i, lo_j, hi_j = boxes[i].min(0), boxes[i].max(0), boxes[j].min(0), boxes[j].max(0)
            assert (hi_i < lo_j).any() or (hi_j < lo_i).any(), (i, j)
    assert sc.bodies[0]["color"] == collide.scene.DEFAULT_COLORS[0]
    for bad in (0, 7, 2.0, True):
        with pytest.raises(ValueError):
            default_scene(blocks=bad)
    with pytest.raises(ValueError, match="mass"):
        default_scene(green_mass=float("nan"))


def test_shipped_scenes_load_and_default_yaml_is_the_default_scene() -> None:
    files = sorted(SCENES.glob("*.yaml")) + sorted(SCENES.glob("*.json"))
    assert len(files) >= 4
    for f in files:
        load_scene(f).build()
    assert load_scene(SCENES / "default.yaml") == default_scene()


# ---- malformed files: each error names the line and the value -----------------------------------

BAD = [
    # (description, text, expected line, words in the message)
    ("unknown top-level key", "bodies: []\ncolour: red\n", 2, "unknown key 'colour'"),
    ("unknown world key", "world:\n  gravty: [0, 0]\nbodies: []\n", 2, "unknown key 'gravty'"),
    ("unknown body key", "bodies:\n  - name: a\n    shape: box\n    width: 1\n    height: 1\n    mas: 2\n", 6,
     "unknown key 'mas'"),
    ("wrong type", "bodies:\n  - name: a\n    shape: box\n    width: 1\n    height: 1\n    mass: heavy\n", 6,
     "bodies[0].mass: expected a number, got str 'heavy'"),
    ("bool is not a number", "bodies:\n  - {name: a, shape: box, width: 1, height: true}\n", 2,
     "expected a number"),
    ("NaN", "bodies:\n  - name: a\n    shape: box\n    width: 1\n    height: 1\n    mass: .nan\n", 6,
     "finite"),
    ("NaN spelled NaN", "world:\n  damping: NaN\nbodies: []\n", 2, "finite"),
    ("infinity", "bodies:\n  - {name: a, shape: box, width: 1, height: 1, velocity: [.inf, 0]}\n", 2, "finite"),
    ("missing field", "bodies:\n  - name: a\n    shape: box\n    width: 1\n", 2, "missing required key 'height'"),
    ("missing shape", "bodies:\n  - name: a\n    width: 1\n", 2, "missing required key 'shape'"),
    ("missing bodies", "world: {}\n", 1, "missing required key 'bodies'"),
    ("bad shape", "bodies:\n  - {name: a, shape: circle}\n", 2, "expected 'box' or 'polygon'"),
    ("bad pair", "bodies:\n  - {name: a, shape: box, width: 1, height: 1, position: [1, 2, 3]}\n", 2,
     "expected a pair"),
    ("bad enum", "world:\n  integrator: rk5\nbodies: []\n", 2, "expected one of euler, midpoint, rk4"),
    ("duplicate key", "bodies: []\nworld: {}\nworld: {}\n", 3, "duplicate key 'world'"),
    ("duplicate body name", "bodies:\n  - {name: a, shape: box, width: 1, height: 1}\n"
     "  - {name: a, shape: box, width: 1, height: 1}\n", 3, "duplicate body name 'a'"),
    ("wall name taken", "walls: {xmin: -1, ymin: -1, xmax: 1, ymax: 1}\n"
     "bodies:\n  - {name: wall_top, shape: box, width: 1, height: 1}\n", 3, "duplicate body name"),
    ("spring to unknown body", "bodies: []\nsprings:\n  - {body_a: ghost}\n", 3, "no body named 'ghost'"),
    ("bad thrusters", "bodies:\n  - {name: a, shape: box, width: 1, height: 1, thrusters: lots}\n", 2,
     "expected 'default'"),
    ("bad run dt", "bodies: []\nrun: {dt: 0}\n", 2, "run.dt: must be in (0, 1]"),
    ("truncated YAML", "bodies:\n  - {name: a, shape: box, width: 1,\n", 3, "invalid YAML"),
    ("top level not a mapping", "- a\n- b\n", 1, "expected a mapping"),
    ("wrong version", "version: 2\nbodies: []\n", 1, "unsupported version 2"),
    # range errors come from C, anchored at the item C refused
    ("negative mass (C)", "bodies:\n  - {name: a, shape: box, width: 1, height: 1}\n"
     "  - {name: b, shape: box, width: 1, height: 1, mass: -1}\n", 3, "mass"),
    ("non-convex polygon (C)", "bodies:\n  - name: p\n    shape: polygon\n"
     "    vertices: [[0, 0], [2, 0], [1, 0.3], [2, 2], [0, 2]]\n", 2, "bodies[0]"),
    ("bad world range (C)", "world:\n  contact_gap: 5\nbodies: []\n", 1, "contact_gap"),
]


@pytest.mark.parametrize("desc,text,line,words", BAD, ids=[b[0] for b in BAD])
def test_malformed_yaml_is_rejected_with_line_and_reason(tmp_path: Path, desc: str, text: str, line: int,
                                                         words: str) -> None:
    path = write(tmp_path, text)
    with pytest.raises(SceneError) as err:
        load_scene(path)
    msg = str(err.value)
    assert f"{path}:{line}:" in msg, msg
    assert words in msg, msg
    assert err.value.errors and err.value.errors[0][0] == line


def test_malformed_json_and_empty_and_missing_files(tmp_path: Path) -> None:
    good = json.dumps(valid_data(), indent=1)
    truncated = write(tmp_path, good[: len(good) // 2], "cut.json")
    with pytest.raises(SceneError, match=r"cut\.json:\d+: invalid JSON"):
        load_scene(truncated)
    bad_json = write(tmp_path, '{"bodies": [], "world": {"damping": NaN}}', "nan.json")
    with pytest.raises(SceneError, match=r"nan\.json:1: world\.damping: must be a finite number"):
        load_scene(bad_json)
    with pytest.raises(SceneError, match="empty"):
        load_scene(write(tmp_path, "", "empty.yaml"))
    with pytest.raises(SceneError, match="no such file"):
        load_scene(tmp_path / "absent.yaml")
    with pytest.raises(TypeError):
        load_scene(42)  # type: ignore[arg-type]


def test_several_errors_are_reported_together(tmp_path: Path) -> None:
    text = "bodies:\n  - {name: a, shape: box, width: x, height: 1}\n  - {name: b, shape: box, width: 1}\n"
    with pytest.raises(SceneError) as err:
        load_scene(write(tmp_path, text))
    assert [e[0] for e in err.value.errors] == [2, 3]


def test_dict_scene_errors_have_paths() -> None:
    with pytest.raises(SceneError, match=r"<dict>: bodies\[0\]\.mass: expected a number"):
        load_scene({"bodies": [{"name": "a", "shape": "box", "width": 1, "height": 1, "mass": "x"}]})


def test_hostile_yaml_recursive_and_exploding_aliases(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(collide.scene, "_MAX_NODES", 10_000)  # same code path as 1e6, quicker
    with pytest.raises(SceneError, match="recursive alias"):
        load_scene(write(tmp_path, "bodies: &b [*b]\n"))
    bomb = "a: &a [x, x, x, x, x, x, x, x, x, x]\n" + "".join(
        f"{c}: &{c} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n"
        for p, c in zip("abcdefg", "bcdefgh")) + "bodies: []\n"
    with pytest.raises(SceneError, match="more than"):
        load_scene(write(tmp_path, bomb))
    with pytest.raises(SceneError, match=r"scene.yaml:2: invalid YAML"):
        load_scene(write(tmp_path, "bodies: []\n\tworld: {}\n"))


# ---- regressions of the scene fuzzer's inputs (fuzz/corpus/scene-regressions, docs/hardening.md "Fuzzing") ----

def test_deep_nesting_is_refused_before_recursion(tmp_path: Path) -> None:
    """Thousands of levels must not reach a RecursionError in json, PyYAML's composer or the reader
    (scene-regressions/deep-*)."""
    limit = collide.scene._MAX_DEPTH
    cases = [
        ("seq.yaml", "[" * 5000 + "]" * 5000, "1: [0][0][0][0]...: nested more than"),
        ("map.yaml", "a: " + "{b: " * 5000 + "1" + "}" * 5000 + "\n", "1: a.b.b.b...: nested more than"),
        ("arr.json", "[" * 5000 + "]" * 5000, "1: [0][0][0][0]...: nested more than"),
        # each tree within the limit, but the alias grafts one onto the other at depth 40
        ("alias.yaml", "x: &x " + "[" * 20 + "1" + "]" * 20 + "\ny: " + "[" * 20 + "*x " + "]" * 20
         + "\nbodies: []\n", "y[0][0][0]...: nested more than"),
    ]
    for name, text, words in cases:
        with pytest.raises(SceneError) as err:
            load_scene(write(tmp_path, text, name))
        assert words in str(err.value) and f"{limit} levels deep" in str(err.value), str(err.value)
    deep: list = []
    inner = deep
    for _ in range(5000):
        inner.append([])
        inner = inner[0]
    with pytest.raises(SceneError, match=r"<dict>: bodies\[0\]\[0\]\[0\]\.\.\.: nested more than"):
        load_scene({"bodies": deep})
    # exactly at the limit is still read (and then refused for what it is, not for its depth)
    at_limit = "bodies: " + "[" * (limit - 1) + "1" + "]" * (limit - 1) + "\n"
    with pytest.raises(SceneError, match=r"bodies\[0\]: expected a body") as err:
        load_scene(write(tmp_path, at_limit, "ok.yaml"))
    assert "nested" not in str(err.value)
    with pytest.raises(SceneError, match="nested more than"):
        load_scene(write(tmp_path, "bodies: " + "[" * limit + "1" + "]" * limit + "\n", "over.yaml"))


@pytest.mark.parametrize("entry,shown", [("-", "nothing (null)"), ("- 3", "int 3"), ("- [a]", "a list of 1"),
                                         ("- box", "str 'box'")])
def test_body_entry_that_is_not_a_mapping_names_its_index(tmp_path: Path, entry: str, shown: str) -> None:
    """A non-mapping `bodies` entry is named by its index, not a KeyError
    (scene-regressions/*-body-entry)."""
    text = f"bodies:\n  - {{name: a, shape: box, width: 1, height: 1}}\n  {entry}\n"
    with pytest.raises(SceneError) as err:
        load_scene(write(tmp_path, text))
    assert f"scene.yaml:3: bodies[1]: expected a body (a mapping with name, shape, ...), got {shown}" \
        in str(err.value), str(err.value)
    with pytest.raises(SceneError, match=r"<dict>: bodies\[0\]: expected a body"):
        load_scene({"bodies": [None]})


@pytest.mark.parametrize("text,words", [
    ("bodies: !custom 1\n", "scene.yaml:1: bodies: unsupported YAML tag '!custom'"),
    ("bodies: []\nworld: !thing {damping: 1}\n", "scene.yaml:2: world: unsupported YAML tag '!thing'"),
    ("bodies: !!set {a, b}\n", "scene.yaml:1: bodies: unsupported YAML tag 'tag:yaml.org,2002:set'"),
    ("bodies: []\nrun: {dt: !!python/name:os.system x}\n",
     "scene.yaml:2: run.dt: unsupported YAML tag 'tag:yaml.org,2002:python/name:os.system'"),
    ("\n!!!!!!!", "scene.yaml:2: (top level): unsupported YAML tag"),
    # a known tag whose text it cannot read (PyYAML raises ValueError, KeyError, AttributeError)
    ("bodies:\n  - {name: a, shape: box, width: !!float abc, height: 1}\n",
     "scene.yaml:2: bodies[0].width: cannot read 'abc' as float"),
    ("bodies: []\nworld: {gravity: [0, !!bool maybe]}\n", "scene.yaml:2: world.gravity[1]: cannot read 'maybe' as bool"),
    ("bodies: []\ndescription: !!timestamp never\n", "scene.yaml:2: description: cannot read 'never' as timestamp"),
])
def test_unknown_or_unreadable_yaml_tags(tmp_path: Path, text: str, words: str) -> None:
    """An unknown or unreadable tag is a SceneError, not a PyYAML error
    (scene-regressions/unknown-yaml-tag*)."""
    with pytest.raises(SceneError) as err:
        load_scene(write(tmp_path, text))
    assert words in str(err.value), str(err.value)


def test_scene_without_world_round_trips(tmp_path: Path) -> None:
    """Without a `world` key, load_scene(scene.to_dict()) equals the scene
    (scene-regressions/no-world-key-round-trip)."""
    sc = load_scene(write(tmp_path, "bodies:\n  - {name: a, shape: box, width: 1, height: 1}\n"))
    assert sc.world == dict.fromkeys(sc.world) and "gravity" in sc.world  # every field present, unset
    again = load_scene(sc.to_dict())
    assert again == sc and again.world == sc.world
    assert load_scene({"bodies": [], "world": {}}) == load_scene({"bodies": []})
    sc.dump(tmp_path / "out.yaml")
    assert load_scene(tmp_path / "out.yaml") == sc


@pytest.mark.parametrize("shape,shown", [("[box]", "a list of 1"), ("{box: 1}", "a mapping"), ("1", "int 1"),
                                         ("null", "nothing (null)")])
def test_shape_that_is_not_a_string(tmp_path: Path, shape: str, shown: str) -> None:
    """`shape: [box]` is a SceneError, not TypeError: unhashable type: 'list'
    (scene-regressions/list-shape)."""
    text = f"bodies:\n  - {{name: a, shape: {shape}, width: 1, height: 1}}\n"
    with pytest.raises(SceneError) as err:
        load_scene(write(tmp_path, text))
    assert f"scene.yaml:2: bodies[0].shape: expected 'box' or 'polygon', got {shown}" in str(err.value), str(err.value)


def test_integer_too_large_for_a_double(tmp_path: Path) -> None:
    """A 400-digit integer is a SceneError, not float()'s OverflowError."""
    text = "bodies:\n  - {name: a, shape: box, width: 1, height: 1, mass: 1" + "0" * 400 + "}\n"
    with pytest.raises(SceneError, match=r"scene.yaml:2: bodies\[0\]\.mass: must be a finite number, "
                                         r"got an integer of 401 digits"):
        load_scene(write(tmp_path, text))


def test_loading_scenes_keeps_no_memory() -> None:
    """A process that reloads scenes does not grow: the YAML constructor keeps no node of a scene
    once it is loaded (a module-level one that remembered every node grows without bound, as the
    scene fuzzer's memory showed)."""
    path = SCENES / "default.yaml"
    for _ in range(20):  # warm-up: caches and interned strings settle
        load_scene(path)
    gc.collect()
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        for _ in range(30):
            load_scene(path)
        gc.collect()
        grown = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    # a reader that keeps every node keeps ~30 KB per load (0.9 MB here); this one ~4 KB in all
    assert grown < 50_000, grown
