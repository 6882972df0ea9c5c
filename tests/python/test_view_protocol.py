"""The live view without ROS or a browser: what a page may send (protocol.py), how the view
builds its scene from the node's topics (scene.py) and the state frame it sends (frames.py)."""
from __future__ import annotations

import numpy as np
import pytest

from collide_ros.view import frames, protocol
from collide_ros.view.cdr_in import Markers
from collide_ros.view.protocol import Refused, parse
from collide_ros.view.scene import CONTACT_HOLD, MAX_CONTACTS, SceneState, match_rows

BODIES = frozenset({"block1", "block2"})


def refused(text: str | bytes) -> str:
    with pytest.raises(Refused) as exc:
        parse(text, BODIES)
    assert exc.value.reason
    return exc.value.reason


def test_good_messages() -> None:
    c = parse('{"type": "spring", "body": "block1", "point": [0.1, -0.2], "target": [3, 4], "id": 7}', BODIES)
    assert (c.type, c.id, c.args) == ("spring", 7, {"body": "block1", "point": (0.1, -0.2), "target": (3.0, 4.0)})
    assert parse('{"type": "release"}', BODIES).type == "release"
    assert parse('{"type": "keys", "held": ["s", "up"]}', BODIES).args == {"held": frozenset({"s", "up"})}
    assert parse('{"type": "keys", "held": []}', BODIES).args == {"held": frozenset()}
    assert parse('{"type": "param", "name": "gravity", "value": 9.81}', BODIES).args == {"name": "gravity", "value": 9.81}
    assert parse('{"type": "param", "name": "blocks", "value": 4}', BODIES).args == {"name": "blocks", "value": 4}
    assert isinstance(parse('{"type": "param", "name": "damping", "value": 1}', BODIES).args["value"], float)
    assert parse('{"type": "pause", "paused": false}', BODIES).args == {"paused": False}
    assert parse('{"type": "step", "steps": 10}', BODIES).args == {"steps": 10}
    assert parse('{"type": "step"}', BODIES).args == {"steps": 1}
    assert parse('{"type": "reset"}', BODIES).type == "reset"
    assert parse('{"type": "ack", "frame": 17}', BODIES).args == {"frame": 17}


@pytest.mark.parametrize("text, reason", [
    ("{", "malformed JSON"),
    ("", "malformed JSON"),
    ("[1, 2]", "must be a JSON object"),
    ('"spring"', "must be a JSON object"),
    (b'{"type": "reset"}', "binary"),
    ("{" * 3000 + "}" * 3000, "at most"),
    ("[" * 2000 + "]" * 2000, "malformed JSON"),   # deeper than the parser goes: refused, no crash
    ('{"type": "spring", "body": "block1", "point": [0, 0], "target": [NaN, 0]}', "NaN"),
    ('{"type": "spring", "body": "block1", "point": [0, 0], "target": [Infinity, 0]}', "Infinity"),
    ('{"type": "spring", "body": "block1", "point": [0, 0], "target": [1e300, 0]}', "out of range"),
    ('{"type": "spring", "body": "block1", "point": [0, 0], "target": [1e999, 0]}', "finite"),
    ('{"type": "spring", "body": "block1", "point": [0, 0], "target": [1' + "0" * 400 + ', 0]}', "too large"),
    ('{"type": "spring", "body": "block1", "point": [0], "target": [0, 0]}', "[x, y]"),
    ('{"type": "spring", "body": "block1", "point": [true, 0], "target": [0, 0]}', "must be a number"),
    ('{"type": "spring", "body": "block1", "point": ["1", 0], "target": [0, 0]}', "must be a number"),
    ('{"type": "spring", "body": "wall3", "point": [0, 0], "target": [0, 0]}', "unknown body 'wall3'"),
    ('{"type": "spring", "body": 5, "point": [0, 0], "target": [0, 0]}', "body must be a string"),
    ('{"type": "keys", "held": ["q"]}', "not a thruster key"),
    ('{"type": "keys", "held": "s"}', "must be a list"),
    ('{"type": "keys", "held": [' + ",".join(['"s"'] * 13) + "]}", "at most"),
    ('{"type": "param", "name": "scene_file", "value": 1}', "cannot be set"),
    ('{"type": "param", "name": "gravity", "value": "9.81"}', "must be a number"),
    ('{"type": "param", "name": "gravity", "value": 1e300}', "out of range"),
    ('{"type": "param", "name": "blocks", "value": 2.5}', "integer"),
    ('{"type": "pause", "paused": 1}', "true or false"),
    ('{"type": "step", "steps": 0}', "1..100000"),
    ('{"type": "step", "steps": 1000001}', "1..100000"),
    ('{"type": "reset", "id": "x"}', "id must be an integer"),
    ('{"type": "ack", "frame": -1}', "frame must be an integer"),
    ('{"type": "ack", "frame": 1.5}', "frame must be an integer"),
    ('{"type": "ack"}', "frame must be an integer"),
    ('{"type": "launch"}', "unknown message type"),
    ('{"kind": "reset"}', "unknown message type"),
])
def test_bad_messages_refused_with_reason(text: str | bytes, reason: str) -> None:
    assert reason in refused(text)


def test_refusal_keeps_request_id() -> None:
    with pytest.raises(Refused) as exc:
        parse('{"type": "param", "name": "gravity", "value": NaN, "id": 12}', BODIES)
    # NaN is refused by the JSON parser, before the id is known
    assert exc.value.req_id is None
    with pytest.raises(Refused) as exc:
        parse('{"type": "param", "name": "gravity", "value": 1e300, "id": 12}', BODIES)
    assert exc.value.req_id == 12


def test_rate_limit_refuses_floods() -> None:
    now = [0.0]
    lim = protocol.RateLimit(rate=100.0, burst=10.0, clock=lambda: now[0])
    assert all(lim.take() for _ in range(10))
    assert not lim.take() and lim.refused == 1
    now[0] += 0.05  # 5 tokens back
    assert sum(lim.take() for _ in range(20)) == 5


# ---------------------------------------------------------------- scene
SQUARE = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]
GREEN = "#33bf33"


def markers(stamp: float, bodies: list[tuple[int, float, float]], springs: list[list[float]] | None = None,
            delete_alls: int = 0) -> Markers:
    """A markers message as cdr_in reads it: bodies (id, x, y), squares at yaw 0."""
    return Markers(delete_alls=delete_alls, stamp=stamp, ids=[b[0] for b in bodies],
                   verts=[[list(p) for p in SQUARE] for _ in bodies], colors=[GREEN] * len(bodies),
                   poses=np.array([[x, y, 0.0] for _, x, y in bodies]).reshape(-1, 3), springs=springs or [])


def test_match_rows_in_order() -> None:
    assert match_rows([(0, -6, 0), (1, 2, 0), (6, 0, 0), (3, 4, 0)], [(1, 2, 0), (3, 4, 0)]) == [1, 3]
    assert match_rows([(0, -6, 0), (1, 2, 0)], [(1, 2, 0), (3, 4, 0)]) is None
    assert match_rows([(1, 2, 0)], []) == []


def test_scene_names_dynamic_bodies_by_matching_poses() -> None:
    s = SceneState()
    s.on_states(1.0, ["block1"], [(1.0, 2.0, 0.0)], [(0.0, 0.0, 0.0)], wall=0.0)
    s.on_markers(markers(1.0, [(10, 0.0, -6.0), (11, 1.0, 2.0)], springs=[[1.0, 2.0, 3.0, 3.0]]))
    msg = s.shapes_message()
    assert [(b["id"], b["name"], b["static"]) for b in msg["bodies"]] == [(10, None, True), (11, "block1", False)]
    assert msg["bodies"][1]["verts"] == [list(p) for p in SQUARE]
    assert s.dynamic_bodies() == {"block1"}
    # later states move block1; the state message takes its pose from bodies/states
    s.on_states(1.01, ["block1"], [(1.5, 2.0, 0.1)], [(1.0, 0.0, 0.0)], wall=0.6)
    st = s.state_message(wall=0.6)
    assert st["poses"].tolist() == [[0.0, -6.0, 0.0], [1.5, 2.0, 0.1]]
    # a velocity for the named body only; the wall has none (NaN)
    assert np.isnan(st["velocities"][0]).all() and st["velocities"][1].tolist() == [1.0, 0.0, 0.0]
    assert st["springs"] == [[1.0, 2.0, 3.0, 3.0]]
    assert st["rtf"] == pytest.approx(0.01 / 0.6)
    # the page's frame carries the same values
    back = frames.decode_state(frames.encode_state({**st, "node": True, "health": None, "params": {}}))
    assert back["poses"].tolist() == st["poses"].tolist() and back["springs"] == st["springs"]
    assert back["type"] == "state" and back["bodies"] == 2 and back["points"] == 0


def test_scene_delete_all_and_energy_start() -> None:
    s = SceneState()
    s.on_markers(markers(0.0, [(1, 0.0, 0.0)]))
    s.on_energy({"total": 5.0, "translational": 5.0, "rotational": 0.0, "potential": 0.0})
    s.on_energy({"total": 4.0, "translational": 4.0, "rotational": 0.0, "potential": 0.0})
    assert s.state_message()["energy"]["start"] == 5.0
    v = s.shapes_version
    s.on_markers(markers(2.0, [(1, 0.0, 0.0)], delete_alls=1))
    assert s.resets == 1 and s.shapes_version > v and s.energy_start is None
    s.on_energy({"total": 1.0, "translational": 1.0, "rotational": 0.0, "potential": 0.0})
    assert s.state_message()["energy"]["start"] == 1.0
    # a body that is no longer among the markers (killed) goes
    s.on_markers(markers(3.0, [(2, 0.0, 0.0)]))
    assert [b["id"] for b in s.shapes_message()["bodies"]] == [2]


def test_scene_spawn_within_a_step_names_the_new_body() -> None:
    # states at t = 1 with two blocks; a spawn before the next step: markers of three bodies with the
    # same stamp; the next states name all three
    s = SceneState()
    s.on_states(1.0, ["a", "b"], [(1.0, 0.0, 0.0), (2.0, 0.0, 0.0)], [(0.0, 0.0, 0.0)] * 2, wall=0.0)
    walls_and = [(1, 0.0, -6.0), (2, 1.0, 0.0), (3, 2.0, 0.0)]
    s.on_markers(markers(1.0, walls_and))
    assert s.matched and s.name_of == {2: "a", 3: "b"}
    s.on_markers(markers(1.0, walls_and + [(4, 0.0, 3.0)]))
    s.on_states(1.01, ["a", "b", "crate"], [(1.0, 0.0, 0.0), (2.0, 0.0, 0.0), (0.0, 3.0, 0.0)],
                [(0.0, 0.0, 0.0)] * 3, wall=0.1)
    assert not s.matched  # the body set changed: named again with the next markers
    s.on_markers(markers(1.01, walls_and + [(4, 0.0, 3.0)]))
    assert s.matched and s.name_of == {2: "a", 3: "b", 4: "crate"}
    assert [b["static"] for b in s.shapes_message()["bodies"]] == [True, False, False, False]


def test_scene_contacts_held_and_capped() -> None:
    s = SceneState()
    s.on_contacts(np.ones((3, 2)), wall=0.0)
    s.on_contacts(np.zeros((MAX_CONTACTS, 2)), wall=0.1)
    assert len(s.state_message(wall=0.1)["contacts"]) == MAX_CONTACTS  # both held, the sum capped
    assert len(s.state_message(wall=0.1 + CONTACT_HOLD + 0.01)["contacts"]) == 0  # both older than the hold
