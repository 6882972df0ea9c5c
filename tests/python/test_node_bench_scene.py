"""The node bench's generated pile scene (bench/node_bench.py, pile_scene): what it holds, that the
scene file validator and C accept it, and that nothing overlaps at the start. No node is started and
nothing is timed."""
from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import collide
from bench_module import load_node_bench

nb = load_node_bench()


@pytest.fixture(scope="module")
def scene() -> dict[str, Any]:
    return nb.pile_scene(200)


def _split(scene: dict[str, Any]) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    dyn = [b for b in scene["bodies"] if not b.get("static")]
    return dyn, [b for b in scene["bodies"] if b.get("static")]


def test_counts_sizes_and_material(scene: dict[str, Any]) -> None:
    dyn, static = _split(scene)
    assert [b["name"] for b in dyn[:2]] == ["block1", "p1"]
    pile = dyn[1:]
    assert len(pile) == 200 and len({b["name"] for b in scene["bodies"]}) == len(scene["bodies"])
    w = np.array([b["width"] for b in pile])
    h = np.array([b["height"] for b in pile])
    assert ((w >= 0.3) & (w <= 0.8) & (h >= 0.3) & (h <= 0.8)).all()
    assert np.ptp(w) > 0.4 and np.ptp(h) > 0.4                       # mixed sizes, not one size
    np.testing.assert_allclose([b["mass"] for b in pile], nb.PILE_DENSITY * w * h)  # mass ~ area
    assert all(b["friction"] == 0.5 and b["elasticity"] == 0.3 for b in scene["bodies"])
    assert scene["world"]["gravity"] == [0.0, -9.81]
    speeds = np.array([np.hypot(*b["velocity"]) for b in pile])
    spins = np.array([abs(b["angular_velocity"]) for b in pile])
    assert 0 < speeds.max() <= np.sqrt(2) and 0 < spins.max() <= 2.0  # small random speeds and spins
    assert len(static) == 5                                           # floor, ceiling, two walls, divider


def test_builds_with_row_order(scene: dict[str, Any]) -> None:
    world = collide.load_scene(scene).build()
    dyn_names = [n for n, s in zip(world.names, world.static_mask) if not s]
    assert dyn_names[0] == "block1" and len(dyn_names) == 201          # block1 is the first pose


def _circle_clear_of_rect(c: np.ndarray, r: np.ndarray, rect: dict[str, Any]) -> np.ndarray:
    """Whether each circle (centre c, radius r) stays clear of an axis-aligned static box."""
    (x, y), hw, hh = rect["position"], rect["width"] / 2, rect["height"] / 2
    dx = np.maximum(np.abs(c[:, 0] - x) - hw, 0.0)
    dy = np.maximum(np.abs(c[:, 1] - y) - hh, 0.0)
    return np.hypot(dx, dy) > r


def _rects_apart(a: dict[str, Any], b: dict[str, Any]) -> bool:
    """Whether two axis-aligned boxes are separated (by a positive gap) along x or y."""
    return any(abs(a["position"][k] - b["position"][k]) > (a[s] + b[s]) / 2 for k, s in ((0, "width"), (1, "height")))


def test_nothing_overlaps_at_start(scene: dict[str, Any]) -> None:
    """Each pile box's circumscribed circle is clear of every other one, of every static box and of
    block1 (a sufficient condition for no overlap at any angle); block1 and the static boxes are
    axis-aligned, and block1 is apart from each static box (it rests 1e-7 m above the floor)."""
    dyn, static = _split(scene)
    block1, pile = dyn[0], dyn[1:]
    assert all(b.get("angle", 0.0) == 0.0 for b in [block1, *static])
    c = np.array([b["position"] for b in pile])
    r = 0.5 * np.hypot([b["width"] for b in pile], [b["height"] for b in pile])
    d = np.hypot(*(c[:, None, :] - c[None, :, :]).transpose(2, 0, 1))
    clear = d > r[:, None] + r[None, :]
    np.fill_diagonal(clear, True)
    assert clear.all()
    for rect in [block1, *static]:
        assert _circle_clear_of_rect(c, r, rect).all(), rect["name"]
    assert all(_rects_apart(block1, rect) for rect in static)
    # inside the walls: above the floor's top, below the ceiling's bottom
    floor, ceiling = (next(b for b in static if b["name"] == k) for k in ("floor", "ceiling"))
    top = ceiling["position"][1] - ceiling["height"] / 2
    assert (c[:, 1] - r > floor["position"][1] + floor["height"] / 2).all() and (c[:, 1] + r < top).all()


def test_parse_case() -> None:
    assert nb.parse_case("pile200") == nb.Case("pile200", 200, True)
    assert nb.parse_case("1000") == nb.Case("1000", 1000, False)
    assert nb.parse_case("pile200@0.005") == nb.Case("pile200@0.005", 200, True, 0.005)
    assert nb.parse_case("pile200").time_step == 0.001
    for bad in ("pile", "pile0", "0", "boxes", "pile200@", "pile200@x", "pile200@0", "pile200@1", "6@-1"):
        with pytest.raises(Exception):
            nb.parse_case(bad)
