"""Draw the sim from a recorded bag into an animated GIF (Pillow only).

    python -m collide_ros.render BAG --out out/demo.gif [--fps 20] [--blocks 2]

Each frame shows the walls, the bodies (block1 green), the contact points reported since
the previous frame (red = collision, orange = resting), the spring as a line from its body
point to its target, and an energy bar graph like myPhysicsLab's: translational,
rotational and potential (gravitational + spring) energy stacked, with the total.
Body shapes are not in the bag's messages; they come from the scene (the embedded default
scene unless shapes are given).
"""
from __future__ import annotations

import argparse
import bisect
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable, Sequence

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from .cdr import join_time

BG = (250, 250, 250)
WALL = (120, 120, 120)
GREEN = (60, 170, 70)
OTHER = [(70, 120, 200), (200, 120, 60), (150, 90, 190), (200, 180, 50), (90, 170, 180)]
OUTLINE = (40, 40, 40)
COLLISION = (220, 30, 30)
RESTING = (240, 150, 20)
SPRING = (180, 40, 150)
E_TRANS = (70, 130, 220)
E_ROT = (235, 205, 60)
E_POT = (150, 150, 150)
TEXT = (20, 20, 20)


@dataclass
class Frame:
    """What one picture shows (world coordinates, SI units)."""

    t: float
    bodies: list[tuple[str, np.ndarray]]             # (name, (k,2) world vertices)
    contacts: list[tuple[float, float, int]] = field(default_factory=list)  # x, y, kind
    spring: tuple[tuple[float, float], tuple[float, float]] | None = None
    energy: tuple[float, float, float] = (0.0, 0.0, 0.0)  # translational, rotational, potential
    note: str = ""


@dataclass
class View:
    xmin: float = -7.0
    xmax: float = 7.0
    ymin: float = -7.0
    ymax: float = 7.0
    width: int = 480
    bar_height: int = 112
    energy_max: float = 1.0   # J at full bar width
    energy_ref: float | None = None  # total energy marker (e.g. at the start)
    ref_label: str = "start"
    supersample: int = 2

    @property
    def world_height(self) -> int:
        return int(round(self.width * (self.ymax - self.ymin) / (self.xmax - self.xmin)))


def body_color(name: str) -> tuple[int, int, int]:
    if name.startswith("wall"):
        return WALL
    if name == "block1":
        return GREEN
    digits = "".join(ch for ch in name if ch.isdigit())
    k = int(digits) if digits else sum(map(ord, name))
    return OTHER[(k - 2) % len(OTHER)]


def _font(size: int) -> Any:
    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1
        return ImageFont.load_default()


def draw_frame(fr: Frame, view: View, statics: Sequence[tuple[str, np.ndarray]] = ()) -> Image.Image:
    """One RGB picture of `fr` (supersampled, then reduced for smooth edges)."""
    ss = view.supersample
    w = view.width * ss
    top = view.bar_height * ss
    h = top + view.world_height * ss
    img = Image.new("RGB", (w, h), BG)
    d = ImageDraw.Draw(img)
    sx = w / (view.xmax - view.xmin)

    def px(p: np.ndarray) -> list[tuple[float, float]]:
        p = np.asarray(p, dtype=float).reshape(-1, 2)
        xs = (p[:, 0] - view.xmin) * sx
        ys = top + (view.ymax - p[:, 1]) * sx
        return list(zip(xs.tolist(), ys.tolist()))

    for name, verts in list(statics) + list(fr.bodies):
        d.polygon(px(verts), fill=body_color(name), outline=OUTLINE, width=max(1, ss))
    if fr.spring is not None:
        a, b = fr.spring
        d.line(px(np.array([a, b])), fill=SPRING, width=3 * ss)
        for q in (a, b):
            (x, y), = px(np.array(q))
            r = 3.5 * ss
            d.ellipse([x - r, y - r, x + r, y + r], fill=SPRING)
    for x, y, kind in fr.contacts:
        (cx, cy), = px(np.array([x, y]))
        r = 4.5 * ss
        d.ellipse([cx - r, cy - r, cx + r, cy + r], fill=COLLISION if kind == 0 else RESTING,
                  outline=OUTLINE)
    _draw_energy(d, fr, view, ss)
    return img.resize((view.width, h // ss), Image.LANCZOS)


def _draw_energy(d: ImageDraw.ImageDraw, fr: Frame, view: View, ss: int) -> None:
    w = view.width * ss
    font = _font(12 * ss)
    small = _font(11 * ss)
    margin = 10 * ss
    x0, x1 = margin, w - margin
    y0, y1 = 30 * ss, 52 * ss
    d.rectangle([0, 0, w, view.bar_height * ss], fill=(236, 236, 236))
    d.text((margin, 7 * ss), f"t = {fr.t:6.2f} s   energy bar graph {fr.note}", fill=TEXT, font=font)
    d.text((w - 250 * ss, 9 * ss), "dots: red impact, orange resting; purple spring",
           fill=TEXT, font=_font(10 * ss))
    d.rectangle([x0, y0, x1, y1], outline=OUTLINE, fill=(255, 255, 255))
    scale = (x1 - x0) / max(view.energy_max, 1e-12)
    trans, rot, pot = fr.energy
    x = float(x0)
    for val, col in ((pot, E_POT), (trans, E_TRANS), (rot, E_ROT)):
        wpx = max(0.0, val) * scale
        if wpx > 0:
            d.rectangle([x, y0 + ss, min(x + wpx, x1), y1 - ss], fill=col)
        x += wpx
    if view.energy_ref is not None:
        xr = x0 + view.energy_ref * scale
        if x0 <= xr <= x1:
            d.line([(xr, y0 - 4 * ss), (xr, y1 + 4 * ss)], fill=COLLISION, width=2 * ss)
    ly = 62 * ss
    total = trans + rot + pot
    items = [("potential", pot, E_POT), ("translational", trans, E_TRANS),
             ("rotational", rot, E_ROT)]
    lx = margin
    for label, val, col in items:
        d.rectangle([lx, ly + 2 * ss, lx + 10 * ss, ly + 12 * ss], fill=col, outline=OUTLINE)
        d.text((lx + 14 * ss, ly), f"{label} {val:.4f} J", fill=TEXT, font=small)
        lx += 152 * ss
    ref = "" if view.energy_ref is None else f"   ({view.ref_label} {view.energy_ref:.4f} J, red mark)"
    d.text((margin, 84 * ss), f"total {total:.6f} J{ref}", fill=TEXT, font=small)


def _palette(imgs: Sequence[Image.Image]) -> Image.Image:
    """One palette for every frame: from a sample of frames plus a swatch of every drawing colour
    (a palette made from the first frame alone would lack the colours that appear later)."""
    sample = [imgs[int(i)] for i in np.linspace(0, len(imgs) - 1, min(len(imgs), 12))]
    colours = [BG, WALL, GREEN, *OTHER, OUTLINE, COLLISION, RESTING, SPRING, E_TRANS, E_ROT, E_POT, TEXT,
               (236, 236, 236), (255, 255, 255)]
    w, h = sample[0].size
    sw = Image.new("RGB", (w, 8 * len(colours)))
    d = ImageDraw.Draw(sw)
    for i, c in enumerate(colours):
        d.rectangle([0, 8 * i, w, 8 * i + 7], fill=c)
    sheet = Image.new("RGB", (w, h * len(sample) + sw.size[1]))
    for i, im in enumerate(sample):
        sheet.paste(im, (0, h * i))
    sheet.paste(sw, (0, h * len(sample)))
    return sheet.quantize(colors=128, method=Image.Quantize.MEDIANCUT)


def save_gif(frames: Iterable[Image.Image], path: str | Path, fps: float) -> int:
    """Write an animated GIF with one shared palette; returns the frame count."""
    imgs = list(frames)
    if not imgs:
        raise ValueError("no frames to write")
    pal = _palette(imgs)
    q = [im.quantize(palette=pal, dither=Image.Dither.NONE) for im in imgs]
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    q[0].save(path, save_all=True, append_images=q[1:], duration=int(round(1000 / fps)),
              loop=0, optimize=False, disposal=1)
    return len(q)


# ------------------------------------------------------------------ shapes from a scene

def rot(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def scene_shapes(world: Any) -> tuple[dict[str, np.ndarray], list[tuple[str, np.ndarray]]]:
    """(local vertices about the centre of mass per dynamic body, static polygons) of a World."""
    local: dict[str, np.ndarray] = {}
    statics: list[tuple[str, np.ndarray]] = []
    for name in world.names:
        b = world.body(name)
        wv = np.asarray(b.world_vertices(), dtype=float)
        if b.static:
            statics.append((name, wv))
        else:
            pos = np.asarray(b.position, dtype=float)
            local[name] = (wv - pos) @ rot(float(b.angle))  # R^T applied to rows
    return local, statics


def default_shapes(blocks: int = 2) -> tuple[dict[str, np.ndarray], list[tuple[str, np.ndarray]]]:
    from collide import default_scene

    scene = default_scene(blocks=blocks)
    return scene_shapes(scene.build() if hasattr(scene, "build") else scene.world())


def world_polygon(local: np.ndarray, x: float, y: float, angle: float) -> np.ndarray:
    return local @ rot(angle).T + np.array([x, y])


def yaw(qz: float, qw: float) -> float:
    return 2.0 * math.atan2(qz, qw)


# ------------------------------------------------------------------ bag -> frames

def _stamp(h: Any) -> float:
    return join_time(h.stamp)


def read_bag(bag: str | Path, store: Any | None = None) -> dict[str, list[tuple[int, Any]]]:
    """All messages of a bag, deserialized, per topic: [(bag timestamp ns, msg)]."""
    from rosbags.rosbag2 import Reader

    from .recorder import make_typestore

    store = store or make_typestore()
    out: dict[str, list[tuple[int, Any]]] = {}
    with Reader(Path(bag)) as r:
        for conn, ts, raw in r.messages():
            out.setdefault(conn.topic, []).append((ts, store.deserialize_cdr(raw, conn.msgtype)))
    for v in out.values():
        v.sort(key=lambda p: p[0])
    return out


def _topic(msgs: dict[str, list[tuple[int, Any]]], suffix: str) -> list[tuple[int, Any]]:
    """Messages of the topic named `suffix` in any namespace (e.g. 'bodies/states')."""
    for name, v in msgs.items():
        if name.rstrip("/").endswith("/" + suffix) or name == suffix:
            return v
    return []


def _seg_dist(pts: np.ndarray, poly: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance of each point (k,2) to the boundary of polygon (m,2), and the nearest boundary points."""
    a = poly
    b = np.roll(poly, -1, axis=0)
    ab = b - a                                                   # (m,2)
    ap = pts[:, None, :] - a[None, :, :]                         # (k,m,2)
    t = np.clip(np.einsum("kmi,mi->km", ap, ab) / np.maximum(np.einsum("mi,mi->m", ab, ab), 1e-300),
                0.0, 1.0)
    near = a[None, :, :] + t[..., None] * ab[None, :, :]        # (k,m,2)
    d = np.linalg.norm(pts[:, None, :] - near, axis=2)           # (k,m)
    j = np.argmin(d, axis=1)
    idx = np.arange(len(pts))
    return d[idx, j], near[idx, j]


def closest_contact(body: str, bodies: Sequence[tuple[str, np.ndarray]],
                    statics: Sequence[tuple[str, np.ndarray]]) -> tuple[float, float] | None:
    """The point where `body` comes closest to another polygon (vertex against boundary, both ways)."""
    polys = dict(list(bodies) + list(statics))
    if body not in polys:
        return None
    vb = polys[body]
    best: tuple[float, tuple[float, float]] | None = None
    for name, vo in polys.items():
        if name == body:
            continue
        for pts, poly in ((vb, vo), (vo, vb)):
            d, near = _seg_dist(pts, poly)
            k = int(np.argmin(d))
            if best is None or d[k] < best[0]:
                best = (float(d[k]), (float(near[k, 0]), float(near[k, 1])))
    return None if best is None else best[1]


def impacts(states: Sequence[Any], dv_tol: float = 0.1, dw_tol: float = 0.2) -> list[tuple[int, str]]:
    """(state index just after, body) of every impact visible in a state sequence.

    The node publishes the contacts of the step at which it publishes, and an impact lasts one
    step, so most impacts fall between two contact snapshots. They still show in the states as
    a kink in a body's velocity: the second difference of velocity over consecutive states is
    tiny under smooth forces (thrust, spring: |a'| * dt^2) and about the velocity change at an
    impact. Thresholds: 0.1 m/s and 0.2 rad/s.
    """
    if len(states) < 3:
        return []
    names = list(states[0].names)
    v = np.array([[[tw.linear.x, tw.linear.y, tw.angular.z] for tw in m.twists] for m in states
                  if list(m.names) == names])
    if len(v) < 3:
        return []
    d2 = np.abs(v[2:] - 2 * v[1:-1] + v[:-2])                   # (n-2, bodies, 3)
    hit = (np.hypot(d2[..., 0], d2[..., 1]) > dv_tol) | (d2[..., 2] > dw_tol)
    # a jump between states k and k+1 shows in d2 at k-1 and k: keep the first of each run
    out: list[tuple[int, str]] = []
    for b in range(hit.shape[1]):
        prev = False
        for k in range(hit.shape[0]):
            if hit[k, b] and not prev:
                out.append((k + 1, names[b]))
            prev = bool(hit[k, b])
    return out


def frames_from_bag(msgs: dict[str, list[tuple[int, Any]]], local: dict[str, np.ndarray],
                    fps: float = 20.0, statics: Sequence[tuple[str, np.ndarray]] = (),
                    infer_impacts: bool = True, linger: float = 0.2) -> list[Frame]:
    states = _topic(msgs, "bodies/states")
    if not states:
        raise ValueError("bag has no bodies/states messages")
    st_t = np.array([_stamp(m.header) for _, m in states])
    contacts = _topic(msgs, "contacts")
    c_t = [_stamp(m.header) for _, m in contacts]
    energy = _topic(msgs, "energy")
    e_t = [_stamp(m.header) for _, m in energy]
    springs = _topic(msgs, "spring")
    s_ts = [ts for ts, _ in springs]

    def polygons(m: Any) -> tuple[dict[str, tuple[float, float, float]], list[tuple[str, np.ndarray]]]:
        poses = {}
        bodies = []
        for name, pose in zip(m.names, m.poses):
            a = yaw(pose.orientation.z, pose.orientation.w)
            poses[name] = (pose.position.x, pose.position.y, a)
            if name in local:
                bodies.append((name, world_polygon(local[name], *poses[name])))
        return poses, bodies

    # impacts between contact snapshots (see impacts()): state index -> contact points
    inferred: dict[int, list[tuple[float, float, int]]] = {}
    snap_coll = {round(c_t[i], 6) for i, (_, cm) in enumerate(contacts)
                 if any(c.kind == 0 for c in cm.contacts)}
    # a node that keeps the impacts between two publishes reports them all: infer only for bags
    # whose contacts hold no impact at all (a node that sampled the current step's contacts)
    if infer_impacts and not snap_coll:
        msgs_only = [m for _, m in states]
        for k, body in impacts(msgs_only):
            _, bk = polygons(msgs_only[k])
            p = closest_contact(body, bk, statics)
            if p is not None and not any(math.dist(p, q[:2]) < 0.05 for q in inferred.get(k, [])):
                inferred.setdefault(k, []).append((p[0], p[1], 0))

    frames: list[Frame] = []
    t_next = st_t[0]
    prev_t = -math.inf
    prev_k = -1
    recent: list[tuple[float, tuple[float, float, int]]] = []  # impacts stay visible for `linger` s
    for k, (ts, m) in enumerate(states):
        t = st_t[k]
        if t + 1e-9 < t_next and k != len(states) - 1:
            continue
        t_next = t + 1.0 / fps
        poses, bodies = polygons(m)
        # contacts reported since the previous frame (collisions are instantaneous)
        i0 = bisect.bisect_right(c_t, prev_t)
        i1 = bisect.bisect_right(c_t, t)
        cpts = [(c.point.x, c.point.y, int(c.kind))
                for _, cm in contacts[i0:i1] for c in cm.contacts]
        for kk in range(prev_k + 1, k + 1):  # impacts inferred since the previous frame
            cpts.extend(inferred.get(kk, []))
        recent = [(tc, c) for tc, c in recent if tc > t - linger] + \
            [(t, c) for c in cpts if c[2] == 0]
        cpts = [c for c in cpts if c[2] != 0] + [c for _, c in recent]
        prev_t = t
        prev_k = k
        en = (0.0, 0.0, 0.0)
        j = bisect.bisect_right(e_t, t) - 1
        if j >= 0:
            e = energy[j][1]
            en = (e.translational, e.rotational, e.gravitational + e.spring)
        spring = None
        j = bisect.bisect_right(s_ts, ts) - 1
        if j >= 0:
            sc = springs[j][1]
            if not sc.release and sc.body in poses:
                x, y, a = poses[sc.body]
                bp = np.array([sc.body_point.x, sc.body_point.y]) @ rot(a).T + np.array([x, y])
                spring = ((float(bp[0]), float(bp[1])), (sc.target.x, sc.target.y))
        frames.append(Frame(t=float(t), bodies=bodies, contacts=cpts, spring=spring, energy=en))
    return frames


def render_bag(bag: str | Path, out: str | Path, fps: float = 20.0, blocks: int = 2,
               shapes: tuple[dict[str, np.ndarray], list[tuple[str, np.ndarray]]] | None = None,
               msgs: dict[str, list[tuple[int, Any]]] | None = None,
               energy_ref: tuple[str, float] | None = None) -> dict[str, Any]:
    """Render a bag to an animated GIF; returns a small summary."""
    local, statics = shapes if shapes is not None else default_shapes(blocks)
    msgs = msgs if msgs is not None else read_bag(bag)
    frames = frames_from_bag(msgs, local, fps, statics)
    totals = [sum(f.energy) for f in frames]
    label, ref = energy_ref if energy_ref is not None else ("start", totals[0] if totals else None)
    view = View(energy_max=max(max(totals) * 1.1, 1e-6), energy_ref=ref, ref_label=label)
    n = save_gif((draw_frame(f, view, statics) for f in frames), out, fps)
    return {"frames": n, "gif": str(out), "t0": frames[0].t, "t1": frames[-1].t}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m collide_ros.render", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("bag")
    p.add_argument("--out", default="out/demo.gif")
    p.add_argument("--fps", type=float, default=20.0)
    p.add_argument("--blocks", type=int, default=2, help="blocks in the default scene")
    a = p.parse_args(argv)
    s = render_bag(a.bag, a.out, a.fps, a.blocks)
    print(f"render: {s['frames']} frames, t = {s['t0']:.2f}..{s['t1']:.2f} s -> {s['gif']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
