"""World queries (collide/query.h through the binding): analytic answers, filters, bad input.

Axis-aligned boxes at representable coordinates give exact answers; turned ones agree with the analytic
answer to 1e-14 m."""
from __future__ import annotations

import math

import numpy as np
import pytest

import collide
from collide import BodyDistance, CollideError, RayHit, RayHits, World
from collide._ffi import lib

TOL = 1e-14


def world() -> World:
    return World(gravity=(0.0, 0.0))


def test_ray_head_on_is_exact() -> None:
    w = world()
    box = w.add_box(2.0, 2.0, name="box")
    hit = w.ray_cast((-5.0, 0.0), (5.0, 0.0))
    assert isinstance(hit, RayHit)
    assert hit == RayHit(box, (-1.0, 0.0), (-1.0, 0.0), 0.4)
    assert hit.body.name == "box"
    assert w.ray_cast((-5.0, 1.5), (5.0, 1.5)) is None
    assert w.ray_cast((-5.0, 0.0), (-1.5, 0.0)) is None


@pytest.mark.parametrize("phi", [0.0, 0.3, -2.0, math.pi / 6])
@pytest.mark.parametrize("alpha", [0.0, 0.2, -0.6])
def test_ray_against_a_turned_box(phi: float, alpha: float) -> None:
    # a ray through the centre at alpha to the normal of the face it enters meets it 1/cos(alpha) early
    w = world()
    c = (0.7, -1.3)
    box = w.add_box(2.0, 2.0, position=c, angle=phi)
    u = (math.cos(phi + alpha), math.sin(phi + alpha))
    d = 10.0
    start = (c[0] - d * u[0], c[1] - d * u[1])
    hit = w.ray_cast(start, (c[0] + d * u[0], c[1] + d * u[1]))
    s = d - 1.0 / math.cos(alpha)
    assert hit is not None and hit.body == box
    assert hit.fraction == pytest.approx(s / (2 * d), abs=TOL)
    assert hit.point == pytest.approx((start[0] + s * u[0], start[1] + s * u[1]), abs=TOL)
    assert hit.normal == pytest.approx((-math.cos(phi), -math.sin(phi)), abs=TOL)


def test_ray_starting_inside_parallel_and_grazing() -> None:
    w = world()
    box = w.add_box(2.0, 2.0)
    inside = w.ray_cast((0.2, 0.3), (3.2, 4.3))
    assert inside is not None and inside.fraction == 0.0 and inside.point == (0.2, 0.3)
    assert inside.normal == pytest.approx((-0.6, -0.8), abs=1e-16)
    along = w.ray_cast((-5.0, 1.0), (5.0, 1.0))   # along the top face's line: the top-left corner
    assert along == RayHit(box, (-1.0, 1.0), (-1.0, 0.0), 0.4)
    assert w.ray_cast((-5.0, 1.0 + 2**-40), (5.0, 1.0 + 2**-40)) is None
    w2 = world()
    diamond = w2.add_body([(1, 0), (0, 1), (-1, 0), (0, -1)])
    graze = w2.ray_cast((-3.0, 1.0), (3.0, 1.0))   # touches the top vertex only
    assert graze is not None and graze.body == diamond and graze.fraction == 0.5 and graze.point == (0.0, 1.0)
    assert graze.normal == pytest.approx((-math.sqrt(0.5), math.sqrt(0.5)), abs=1e-15)


def test_ray_cast_all_sorted_and_filtered() -> None:
    w = world()
    boxes = [w.add_box(2.0, 2.0, position=(12.0 - 3.0 * i, 0.0), name=f"b{i}") for i in range(5)]
    wall = w.add_box(2.0, 2.0, position=(0.0, 10.0), static=True, name="wall")
    hits = w.ray_cast_all((-2.0, 0.0), (18.0, 0.0))
    assert [h.body.name for h in hits] == ["b4", "b3", "b2", "b1", "b0"]
    assert [h.fraction for h in hits] == sorted(h.fraction for h in hits)
    assert hits[0] == RayHit(boxes[4], (-1.0, 0.0), (-1.0, 0.0), 0.05)
    assert w.ray_cast((-2.0, 0.0), (18.0, 0.0)) == hits[0]
    up = ((0.0, -5.0), (0.0, 15.0))
    assert [h.body for h in w.ray_cast_all(*up)] == [boxes[4], wall]
    assert [h.body for h in w.ray_cast_all(*up, skip_static=True)] == [boxes[4]]
    assert w.ray_cast(*up, skip="b4") == w.ray_cast_all(*up)[1]
    assert w.ray_cast(*up, skip=boxes[4], skip_static=True) is None
    assert w.ray_cast_all(*up, skip=boxes[4].id, skip_static=True) == []


def test_ray_cast_batch_equals_single_casts() -> None:
    # one C call for many rays: each answer is ray_cast's, bit for bit; misses are nan
    w = world()
    rng = np.random.default_rng(5)
    for i in range(30):
        w.add_box(*rng.uniform(0.3, 1.5, 2), position=tuple(rng.uniform(-8, 8, 2)), angle=float(rng.uniform(-3, 3)),
                  name=f"b{i}")
    w.add_walls(-10, -10, 10, 10)
    starts = rng.uniform(-9, 9, (400, 2))
    ang = rng.uniform(-math.pi, math.pi, 400)
    length = np.where(np.arange(400) % 2 == 0, 25.0, rng.uniform(0.05, 3.0, 400))
    ends = starts + length[:, None] * np.column_stack([np.cos(ang), np.sin(ang)])
    for kw in ({}, {"skip_static": True, "skip": "b3"}):
        got = w.ray_cast_batch(starts, ends, **kw)  # type: ignore[arg-type]
        assert isinstance(got, RayHits)
        for i in range(400):
            one = w.ray_cast(tuple(starts[i]), tuple(ends[i]), **kw)  # type: ignore[arg-type]
            assert bool(got.found[i]) == (one is not None)
            if one is None:
                assert got.body[i] == 0 and np.isnan(got.fraction[i]) and np.all(np.isnan(got.point[i]))
            else:
                assert (int(got.body[i]), tuple(got.point[i]), tuple(got.normal[i]), float(got.fraction[i])) == \
                    (one.body.id, one.point, one.normal, one.fraction)
        assert 50 < int(got.found.sum()) < 400
    fan = w.ray_cast_batch((0.0, 0.0), ends[:5])  # one start for every ray
    assert np.array_equal(fan.found, w.ray_cast_batch(np.zeros((5, 2)), ends[:5]).found)
    assert len(w.ray_cast_batch(np.zeros((0, 2)), np.zeros((0, 2))).found) == 0
    bad = ends[:3].copy()
    bad[2, 1] = math.nan
    with pytest.raises(CollideError) as err:
        w.ray_cast_batch(starts[:3], bad)
    assert err.value.status == lib.LC_ERR_NOT_FINITE and "ends[2]" in err.value.message
    with pytest.raises(ValueError):
        w.ray_cast_batch(starts[:3], ends[:3, 0])
    with pytest.raises(ValueError):
        w.ray_cast_batch(starts[:2], ends[:3])


def test_query_point_and_box() -> None:
    w = world()
    a = w.add_box(2.0, 2.0, position=(2.0, 3.0), name="a")
    b = w.add_box(2.0, 2.0, position=(4.0, 3.0), static=True, name="b")
    d = w.add_body([(1, 0), (0, 1), (-1, 0), (0, -1)], position=(-5.0, 0.0), name="d")
    assert w.query_point((3.0, 2.5)) == [a, b]          # the shared edge: both, row order
    assert w.query_point((1.0, 4.0)) == [a]             # a corner
    assert w.query_point((1.0 - 2**-40, 3.5)) == []
    assert w.query_point((3.0, 2.5), skip_static=True) == [a]
    assert w.query_point((3.0, 2.5), skip="a") == [b]
    assert w.query_point((-4.4, 0.6)) == []             # in the diamond's bounding box only
    assert w.query_point((-4.5, 0.5)) == [d]            # on its edge
    assert w.query_box((-10.0, -10.0), (10.0, 10.0)) == [a, b, d]
    assert w.query_box((5.0, 3.0), (6.0, 3.0)) == [b]    # zero height, touching b's face
    assert w.query_box((-4.4, 0.6), (-4.0, 1.0)) == []
    assert w.query_box((-5.1, 0.95), (-4.9, 2.0)) == [d]  # across the top vertex, no corner inside
    a.set_pose((20.0, 0.0), 0.0)
    assert w.query_point((2.0, 3.0)) == [] and w.query_point((20.5, -0.5)) == [a]


def test_body_distance_and_overlap() -> None:
    w = world()
    a = w.add_box(2.0, 2.0, name="a")
    b = w.add_box(2.0, 2.0, position=(3.5, 0.0), name="b")
    r = w.body_distance("a", "b")
    assert isinstance(r, BodyDistance)
    assert r.distance == 1.5 and r.normal == (1.0, 0.0) and r.point_a[0] == 1.0 and r.point_b[0] == 2.5
    assert w.body_distance(b, a).normal == (-1.0, 0.0)
    assert not w.bodies_overlap(a, b)
    b.set_pose((4.0, 5.0), 0.0)                        # corner (1, 1) to corner (3, 4)
    r = w.body_distance(a, b)
    assert r.distance == pytest.approx(math.sqrt(13.0), abs=1e-15)
    assert (r.point_a, r.point_b) == ((1.0, 1.0), (3.0, 4.0))
    b.set_pose((2.0, 0.5), 0.0)                        # touching
    assert w.body_distance(a, b).distance == 0.0 and w.bodies_overlap(a, b)
    b.set_pose((1.5, 0.2), 0.0)                        # overlapping by 0.5 along x
    r = w.body_distance(a, b)
    assert r.distance == -0.5 and r.normal == (1.0, 0.0)
    assert r.point_b[0] - r.point_a[0] == -0.5
    for phi in (0.4, -1.1):
        w2 = world()
        c, s = math.cos(phi), math.sin(phi)
        p = w2.add_box(2.0, 2.0, position=(1.0, -2.0), angle=phi)
        for gap in (0.75, -0.3):
            q = w2.add_box(2.0, 2.0, position=(1.0 + (2.0 + gap) * c, -2.0 + (2.0 + gap) * s), angle=phi)
            r = w2.body_distance(p, q)
            assert r.distance == pytest.approx(gap, abs=TOL)
            assert r.normal == pytest.approx((c, s), abs=TOL)
            assert w2.bodies_overlap(p, q) == (gap < 0)
            w2.remove_body(q)


def test_bad_input_raises_and_leaves_the_world_alone() -> None:
    w = world()
    a = w.add_box(2.0, 2.0, name="a")
    w.add_box(2.0, 2.0, position=(5.0, 0.0), name="b")
    before = w.state_hash()
    cases = [
        (lambda: w.ray_cast((math.nan, 0.0), (1.0, 0.0)), lib.LC_ERR_NOT_FINITE, "start.x"),
        (lambda: w.ray_cast_all((0.0, 0.0), (1.0, math.inf)), lib.LC_ERR_NOT_FINITE, "end.y"),
        (lambda: w.ray_cast((0.5, 0.5), (0.5, 0.5)), lib.LC_ERR_OUT_OF_RANGE, "zero length"),
        (lambda: w.query_point((2e9, 0.0)), lib.LC_ERR_OUT_OF_RANGE, "point.x"),
        (lambda: w.query_box((1.0, 0.0), (0.0, 1.0)), lib.LC_ERR_OUT_OF_RANGE, "lower"),
        (lambda: w.body_distance(a, a), lib.LC_ERR_OUT_OF_RANGE, "same body"),
        (lambda: w.bodies_overlap(a, 987654), lib.LC_ERR_UNKNOWN_BODY, "987654"),
    ]
    for call, status, word in cases:
        with pytest.raises(CollideError) as err:
            call()
        assert err.value.status == status
        assert word in err.value.message
        assert w.state_hash() == before and len(w) == 2
    with pytest.raises(TypeError):
        w.query_point("here")  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        w.ray_cast((0.0, 0.0), (1.0, 0.0), skip_static=1)  # type: ignore[arg-type]
    with pytest.raises(KeyError):
        w.ray_cast((0.0, 0.0), (1.0, 0.0), skip="nobody")
    assert w.state_hash() == before


def test_exports() -> None:
    assert collide.RayHit is RayHit and collide.BodyDistance is BodyDistance and collide.RayHits is RayHits
