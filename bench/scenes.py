"""Neutral scene descriptions: every body is a box (width x height, SI units) given by its centre,
angle and velocities; static boxes are walls/floors. Each engine adapter builds its own world from
this. All bodies of one scene share one material (e, mu), so every peer's mixing rule gives the
same contact coefficients (see engines/pymunk_engine.py for Chipmunk's product rule)."""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

BLOCK_W, BLOCK_H = 1.0, 0.5          # the seed block, m
BOX = 10.0                            # interior of the walled box, m (x and y in [0, 10])
WALL = 1.0                            # wall thickness, m


@dataclass(frozen=True)
class Box:
    w: float
    h: float
    x: float
    y: float
    angle: float = 0.0
    vx: float = 0.0
    vy: float = 0.0
    omega: float = 0.0
    mass: float = 1.0
    static: bool = False

    @property
    def inertia(self) -> float:
        return self.mass * (self.w ** 2 + self.h ** 2) / 12.0


@dataclass(frozen=True)
class Scene:
    name: str
    boxes: tuple[Box, ...]
    gravity: float = 0.0              # m/s^2, pointing to -y
    e: float = 1.0                    # restitution of every body
    mu: float = 0.0                   # friction of every body
    duration: float = 10.0            # s
    meta: dict = field(default_factory=dict, compare=False)

    @property
    def dynamic(self) -> list[Box]:
        return [b for b in self.boxes if not b.static]

    @property
    def masses(self) -> np.ndarray:
        return np.array([b.mass for b in self.dynamic])

    @property
    def inertias(self) -> np.ndarray:
        return np.array([b.inertia for b in self.dynamic])

    def initial_state(self) -> np.ndarray:
        return np.array([[b.x, b.y, b.angle, b.vx, b.vy, b.omega] for b in self.dynamic], dtype=np.float64)


def walls(xmin: float = 0.0, ymin: float = 0.0, xmax: float = BOX, ymax: float = BOX,
          t: float = WALL) -> list[Box]:
    """Four static boxes whose inner faces bound [xmin, xmax] x [ymin, ymax] (corners filled)."""
    w, h = xmax - xmin, ymax - ymin
    cx, cy = (xmin + xmax) / 2, (ymin + ymax) / 2
    return [Box(w + 2 * t, t, cx, ymin - t / 2, static=True), Box(t, h + 2 * t, xmax + t / 2, cy, static=True),
            Box(w + 2 * t, t, cx, ymax + t / 2, static=True), Box(t, h + 2 * t, xmin - t / 2, cy, static=True)]


def seed(n: int = 20, gravity: float = 0.0, seed: int = 1, size: float = BOX, duration: float = 10.0,
         vmax: float = 3.0, wmax: float = 2.0) -> Scene:
    """n seed blocks at random cells of a 2 m grid in a walled size x size box, random angle,
    v in [-vmax, vmax]^2 m/s, omega in [-wmax, wmax] rad/s; e = 1, no friction, no damping."""
    rng = np.random.default_rng(seed)
    cells = int(size // 2.0)
    if cells * cells < n:
        raise ValueError(f"{n} blocks do not fit a {size} m box on a 2 m grid")
    pick = rng.permutation(cells * cells)[:n]
    off = (size - 2.0 * cells) / 2 + 1.0
    bodies = [Box(BLOCK_W, BLOCK_H, off + 2.0 * (k % cells), off + 2.0 * (k // cells),
                  angle=float(rng.uniform(0, np.pi)), vx=float(rng.uniform(-vmax, vmax)),
                  vy=float(rng.uniform(-vmax, vmax)), omega=float(rng.uniform(-wmax, wmax))) for k in pick]
    return Scene(f"seed{n}_g{gravity:g}_s{seed}", tuple(bodies + walls(0, 0, size, size)), gravity=gravity,
                 duration=duration, meta={"seed": seed, "size": size})


def cradle(gap: float, v0: float = 5.0, n: int = 5, duration: float = 3.0) -> Scene:
    """Newton's cradle: a striker (1 m x 0.5 m) at v0 into a row of n blocks whose end faces are
    `gap` apart (0 = touching); no walls, no gravity, e = 1, mu = 0. Exact (sequential) answer: only
    the last block moves, at v0."""
    row = [Box(BLOCK_W, BLOCK_H, 2.0 + i * (BLOCK_W + gap), 0.0) for i in range(n)]
    striker = Box(BLOCK_W, BLOCK_H, 0.0, 0.0, vx=v0)   # 0.5 m from the first block
    return Scene(f"cradle_gap{gap * 100:g}cm", tuple([striker] + row), duration=duration, meta={"v0": v0})


def flat_drop(height: float = 2.0, duration: float = 1.0, g: float = 9.8) -> Scene:
    """A block held flat with its bottom face `height` above the floor, released at rest; e = 1.
    Exact: it bounces back to the same height without spin (E ratio 1, omega 0)."""
    floor = Box(20.0, 1.0, 0.0, -0.5, static=True)
    return Scene("flat_drop", (Box(BLOCK_W, BLOCK_H, 0.0, height + BLOCK_H / 2), floor), gravity=g, duration=duration)


def free_flight(vx: float = 3.0, vy: float = 6.0, omega: float = 5.0, angle: float = 0.3, duration: float = 1.0,
                g: float = 9.8) -> Scene:
    """A seed block thrown with spin, nothing to hit. Exact: a parabola, the angle linear in time, the
    spin and the energy constant (metrics.free_flight_metrics)."""
    b = Box(BLOCK_W, BLOCK_H, 0.0, 0.0, angle=angle, vx=vx, vy=vy, omega=omega)
    return Scene("free_flight", (b,), gravity=g, duration=duration)


def wall_hit(v: float = 3.0, angle: float = 0.0, duration: float = 1.0) -> Scene:
    """Single impact: a block at v m/s into a wall, face-on (angle 0: 2-point manifold) or on a corner.
    Exact: E ratio 1; face-on v' = -v, omega' = 0."""
    wall = Box(1.0, 10.0, 2.0, 0.0, static=True)
    b = Box(BLOCK_W, BLOCK_H, 0.0, 0.0, angle=angle, vx=v)
    return Scene(f"wall_hit_{np.degrees(angle):.0f}deg", (b, wall), duration=duration)


def stack(n: int, e: float = 0.0, mu: float = 0.6, duration: float = 10.0, g: float = 9.8) -> Scene:
    """n seed blocks (1 m wide, 0.5 m tall) stacked exactly touching on a floor; mu 0.6."""
    floor = Box(20.0, 1.0, 0.0, -0.5, static=True)
    blocks = [Box(BLOCK_W, BLOCK_H, 0.0, BLOCK_H * (i + 0.5)) for i in range(n)]
    return Scene(f"stack{n}_e{e:g}", tuple(blocks + [floor]), gravity=g, e=e, mu=mu, duration=duration)


def pyramid(base: int, duration: float = 500 / 60, g: float = 10.0) -> Scene:
    """Box2D's large_pyramid layout: unit boxes (1 kg), rows touching, on a ground box; mu 0.6, e 0."""
    boxes = []
    for i in range(base):
        y = 0.5 + i * 1.0
        for j in range(i, base):
            x = (i + 1.0) * 0.5 + (j - i) * 1.0 - 0.5 * base
            boxes.append(Box(1.0, 1.0, x, y))
    ground = Box(2.0 * base + 20.0, 1.0, 0.0, -0.5, static=True)
    return Scene(f"pyramid{base}", tuple(boxes + [ground]), gravity=g, e=0.0, mu=0.6, duration=duration)


def tunnel(v: float, wall_t: float = 0.1, size: float = 0.2, duration: float = 0.5) -> Scene:
    """A size x size block at v m/s towards a static wall of thickness wall_t, 1 m away; e = 1.
    Exact: it comes back at -v; it must never be found beyond the wall."""
    wall = Box(wall_t, 4.0, 1.0 + wall_t / 2, 0.0, static=True)
    b = Box(size, size, 0.0, 0.0, vx=v, mass=0.1)
    return Scene(f"tunnel_v{v:g}", (b, wall), duration=duration, meta={"wall_x": 1.0, "wall_t": wall_t})


def many(n: int, seed_: int = 7) -> Scene:
    """Scaling: n seed blocks in a walled box sized to keep the seed scene's crowding (n / area)."""
    cells = int(np.ceil(np.sqrt(n / 0.8)))
    size = 2.0 * cells
    sc = seed(n, 0.0, seed_, size=size, duration=1.0)
    return replace(sc, name=f"many{n}", meta={"size": size, "n": n})


def settling(n: int = 20, e: float = 0.8, mu: float = 0.5, seed_: int = 1, duration: float = 10.0) -> Scene:
    """The seed scene with e = 0.8, mu = 0.5 and g = 9.8: the blocks come to rest on the floor."""
    sc = seed(n, 9.8, seed_, duration=duration)
    return replace(sc, name=f"settling{n}", e=e, mu=mu)


def mass_ratio_stack(ratio: float = 1000.0, duration: float = 10.0) -> Scene:
    """A 1 kg seed block on the floor with a ratio x heavier seed block resting on it; mu 0.6, e 0."""
    floor = Box(20.0, 1.0, 0.0, -0.5, static=True)
    blocks = [Box(BLOCK_W, BLOCK_H, 0.0, BLOCK_H / 2, mass=1.0), Box(BLOCK_W, BLOCK_H, 0.0, 1.5 * BLOCK_H, mass=ratio)]
    return Scene(f"mass_ratio_{ratio:g}", tuple(blocks + [floor]), gravity=9.8, e=0.0, mu=0.6, duration=duration)


def wedged(angle_deg: float = 30.0, mu: float = 0.6, duration: float = 10.0) -> Scene:
    """A seed block turned by angle_deg whose two lower/upper corners touch two vertical walls exactly
    (gap = w cos a + h sin a), 3 m above a floor, g = 9.8, mu 0.6, e 0: friction holds it or it slides
    down; it must never pass through a wall or blow up."""
    a = np.radians(angle_deg)
    gap = BLOCK_W * np.cos(a) + BLOCK_H * np.sin(a)
    y = 3.0
    boxes = (Box(BLOCK_W, BLOCK_H, 0.0, y, angle=float(a)), Box(1.0, 10.0, -gap / 2 - 0.5, 5.0, static=True),
             Box(1.0, 10.0, gap / 2 + 0.5, 5.0, static=True), Box(10.0, 1.0, 0.0, -0.5, static=True))
    return Scene(f"wedged_{angle_deg:g}deg", boxes, gravity=9.8, e=0.0, mu=mu, duration=duration,
                 meta={"gap": float(gap)})


def smash(rows: int = 10, cols: int = 10, v: float = 20.0, e: float = 1.0, duration: float = 2.0) -> Scene:
    """A heavy 2 m x 2 m block (40 kg) at v m/s into a rows x cols grid of 0.4 m blocks (0.16 kg)
    spaced 0.5 m, no gravity, no walls, e = 1: momentum and energy must be conserved."""
    heavy = Box(2.0, 2.0, -3.0, 0.5 * (rows - 1) * 0.5, vx=v, mass=40.0)
    grid = [Box(0.4, 0.4, 0.5 * c, 0.5 * r, mass=0.16) for r in range(rows) for c in range(cols)]
    return Scene(f"smash_{rows}x{cols}", tuple([heavy] + grid), e=e, duration=duration)


# ---- contact section (bench/contact.py): piles, pushing, friction --------------------------------
MIXED_SPACING = 1.2    # m between grid cells: the largest box's diagonal (0.8 sqrt 2 = 1.13 m) fits in
                       # a cell, so no two boxes start overlapping whatever their angles


def mixed_boxes(n: int, seed: int = 1, duration: float = 5.0, mu: float = 0.5, e: float = 0.3,
                g: float = 9.81) -> Scene:
    """n boxes with width and height each uniform in [0.3, 0.8] m (default_rng(seed): widths, then
    heights, then angles in [0, pi)), 2 kg/m^2 (mass = 2 x area), at rest on a grid of
    MIXED_SPACING cells, bottom row first, in a walled box of cols = ceil(1.2 sqrt n) columns whose
    inner top is 2 m above the grid. They fall and pile up on the floor. meta["inner"] is the walls'
    inner box (xmin, ymin, xmax, ymax)."""
    rng = np.random.default_rng(seed)
    w = rng.uniform(0.3, 0.8, n)
    h = rng.uniform(0.3, 0.8, n)
    angle = rng.uniform(0.0, np.pi, n)
    cols = int(np.ceil(np.sqrt(n) * 1.2))
    rows = int(np.ceil(n / cols))
    width, height = cols * MIXED_SPACING, rows * MIXED_SPACING + 2.0
    bodies = [Box(float(w[k]), float(h[k]), (k % cols + 0.5) * MIXED_SPACING, (k // cols + 0.5) * MIXED_SPACING,
                  angle=float(angle[k]), mass=float(2.0 * w[k] * h[k])) for k in range(n)]
    return Scene(f"mixed{n}_s{seed}", tuple(bodies + walls(0.0, 0.0, width, height)), gravity=g, e=e, mu=mu,
                 duration=duration, meta={"inner": (0.0, 0.0, width, height), "seed": seed})


def push_row(n: int = 40, v: float = 6.0, duration: float = 5.0, mu: float = 0.5, e: float = 0.3,
             g: float = 9.81, width: float = 40.0) -> Scene:
    """A 20 kg 1 m x 1 m block sliding at v m/s on the floor into a row of n 0.5 m boxes (1 kg)
    resting on it 0.05 m apart; the block's front face starts 1 m from the first box. The walled
    box is `width` m wide (the row ends at ~24.5 m, so it has room to be pushed) and 5 m tall.
    meta["inner"]: the walls' inner box."""
    block = Box(1.0, 1.0, 1.0, 0.5, vx=v, mass=20.0)
    first = 1.5 + 1.0 + 0.25                       # block front face + 1 m gap + half a box
    row = [Box(0.5, 0.5, first + k * 0.55, 0.25, mass=1.0) for k in range(n)]
    return Scene(f"push_row{n}", tuple([block] + row + walls(0.0, 0.0, width, 5.0)), gravity=g, e=e, mu=mu,
                 duration=duration, meta={"inner": (0.0, 0.0, width, 5.0)})


def drop_on_pyramid(base: int = 12, duration: float = 5.0) -> Scene:
    """bench/repro/drop_into_pyramid.py as a one-material scene: pyramid(base) (unit boxes, 1 kg,
    mu 0.6, e 0, g 10) and a 5 kg unit box 2 m above the top (centre at y = base + 2) at 8 m/s
    down, turning at 1 rad/s. The repro gives the box and the ground e 0.5; here all is e 0."""
    pile = pyramid(base, duration=duration)
    drop = Box(1.0, 1.0, 0.3, base + 2.0, vy=-8.0, omega=1.0, mass=5.0)
    return replace(pile, name=f"drop_on_pyramid{base}", boxes=pile.boxes + (drop,))
