"""Physics measures computed by the harness from the states the engines return (never from the
engines): energy with potential m g y (y = 0 is the floor top / box bottom in every scene),
momentum, per-scene errors."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np


def energy(scene: Any, states: np.ndarray) -> np.ndarray:
    """Total energy (J) per sample; states (k, n, 6) or (n, 6)."""
    s = np.asarray(states)
    m, inertia = scene.masses, scene.inertias
    ke = 0.5 * m * (s[..., 3] ** 2 + s[..., 4] ** 2) + 0.5 * inertia * s[..., 5] ** 2
    return np.sum(ke + m * scene.gravity * s[..., 1], axis=-1)


def momentum(scene: Any, states: np.ndarray) -> np.ndarray:
    """(..., 3): px, py, angular momentum about the origin."""
    s = np.asarray(states)
    m, inertia = scene.masses, scene.inertias
    px = np.sum(m * s[..., 3], axis=-1)
    py = np.sum(m * s[..., 4], axis=-1)
    lz = np.sum(inertia * s[..., 5] + m * (s[..., 0] * s[..., 4] - s[..., 1] * s[..., 3]), axis=-1)
    return np.stack([px, py, lz], axis=-1)


def finite(res: dict[str, Any]) -> bool:
    return "states" in res and bool(np.all(np.isfinite(res["states"])))


def seed_metrics(scene: Any, res: dict[str, Any]) -> dict[str, Any]:
    s = res["states"]
    e = energy(scene, s)
    lo, hi = 0.0, scene.meta.get("size", 10.0)
    x, y = s[-1, :, 0], s[-1, :, 1]
    escaped = int(np.sum((x < lo) | (x > hi) | (y < lo) | (y > hi)))
    return {"drift": float((e[-1] - e[0]) / e[0]), "max_abs_drift": float(np.max(np.abs(e - e[0])) / e[0]),
            "escaped": escaped}


def cradle_metrics(scene: Any, res: dict[str, Any]) -> dict[str, Any]:
    v0 = scene.meta["v0"]
    s = res["states"]
    vx = s[-1, :, 3]
    ideal = np.zeros_like(vx)
    ideal[-1] = v0
    e = energy(scene, s)
    p = momentum(scene, s)
    return {"vx": [float(v) for v in vx], "err": float(np.max(np.abs(vx - ideal)) / v0),
            "ke_ratio": float(e[-1] / e[0]), "momentum_err": float(abs(p[-1, 0] - p[0, 0]) / abs(p[0, 0])),
            "max_spin": float(np.max(np.abs(s[-1, :, 5])))}


def impact_metrics(scene: Any, res: dict[str, Any]) -> dict[str, Any]:
    """Single impact / flat drop: energy ratio and spin at the end (one dynamic body)."""
    s = res["states"]
    e = energy(scene, s)
    return {"e_ratio": float(e[-1] / e[0]), "omega": float(s[-1, 0, 5]), "vx": float(s[-1, 0, 3]),
            "vy": float(s[-1, 0, 4])}


def free_flight_metrics(scene: Any, res: dict[str, Any]) -> dict[str, Any]:
    """One body without contacts against the closed form: position error bound over the samples
    (trajectory_error against the exact states) and the relative energy change."""
    b, t, s = scene.dynamic[0], np.asarray(res["times"]), res["states"]
    exact = np.zeros((len(t), 1, 6))
    exact[:, 0, 0] = b.x + b.vx * t
    exact[:, 0, 1] = b.y + b.vy * t - 0.5 * scene.gravity * t * t
    exact[:, 0, 2] = b.angle + b.omega * t
    exact[:, 0, 3] = b.vx
    exact[:, 0, 4] = b.vy - scene.gravity * t
    exact[:, 0, 5] = b.omega
    e = energy(scene, s)
    return {"pos_err": trajectory_error(s, exact, math.hypot(b.w, b.h) / 2),
            "vel_err": float(np.max(np.abs(s[..., 3:5] - exact[..., 3:5]))),
            "e_change": float((e[-1] - e[0]) / e[0])}


def stack_metrics(scene: Any, res: dict[str, Any]) -> dict[str, Any]:
    s, t = res["states"], res["times"]
    top0, top = s[0, -1], s[:, -1]
    last = t >= t[-1] - 5.0 + 1e-9
    sink = float(top0[1] - top[-1, 1])
    dx = float(top[-1, 0] - top0[0])
    jitter = float(np.std(top[last, 1])) if np.sum(last) > 1 else math.nan
    fell = bool(abs(dx) > 0.25 or abs(sink) > 0.25)
    return {"sink": sink, "dx": dx, "jitter": jitter, "fell": fell,
            "max_speed_end": float(np.max(np.hypot(s[-1, :, 3], s[-1, :, 4])))}


def pyramid_metrics(scene: Any, res: dict[str, Any]) -> dict[str, Any]:
    s = res["states"]
    return {"top_moved": float(np.hypot(*(s[-1, -1, :2] - s[0, -1, :2]))), "ms_per_step": res["us_per_step"] / 1e3}


def tunnel_metrics(scene: Any, res: dict[str, Any]) -> dict[str, Any]:
    s = res["states"]
    far = scene.meta["wall_x"] + scene.meta["wall_t"]
    v = scene.dynamic[0].vx
    return {"tunnelled": bool(np.any(s[:, 0, 0] > far)), "vx_ratio": float(s[-1, 0, 3] / -v),
            "e_ratio": float(energy(scene, s)[-1] / energy(scene, s)[0])}


def hard_metrics(scene: Any, res: dict[str, Any]) -> dict[str, Any]:
    """Generic hard-case measures: energy change (and largest rise between samples), momentum error
    (scenes without gravity or walls), final kinetic energy, top-block sink / drift for stacks."""
    s = res["states"]
    e = energy(scene, s)
    rise = float(np.max(e) - e[0])
    ke = 0.5 * scene.masses * (s[-1, :, 3] ** 2 + s[-1, :, 4] ** 2) + 0.5 * scene.inertias * s[-1, :, 5] ** 2
    out = {"e_change": float((e[-1] - e[0]) / abs(e[0])) if e[0] else math.nan,
           "e_max_rise": rise / abs(e[0]) if e[0] else math.nan, "ke_end": float(np.sum(ke)),
           "moved": float(np.max(np.hypot(s[-1, :, 0] - s[0, :, 0], s[-1, :, 1] - s[0, :, 1])))}
    if scene.gravity == 0.0:
        p = momentum(scene, s)
        out["momentum_err"] = float(np.max(np.abs(p[-1, :2] - p[0, :2])) / np.max(np.abs(p[0, :2])))
    if "size" in scene.meta:
        size = scene.meta["size"]
        x, y = s[-1, :, 0], s[-1, :, 1]
        out["escaped"] = int(np.sum((x < 0) | (x > size) | (y < 0) | (y > size)))
    if "gap" in scene.meta:
        out["escaped"] = int(abs(s[-1, 0, 0]) > scene.meta["gap"] / 2 or s[-1, 0, 1] < 0)
    if scene.name.startswith("mass_ratio"):
        out["sink"] = float(s[0, -1, 1] - s[-1, -1, 1])
        out["dx"] = float(s[-1, -1, 0] - s[0, -1, 0])
    return out


def trajectory_error(states: np.ndarray, ref: np.ndarray, half_diagonal: float) -> float:
    """Largest distance (m) any point of any block strays from the reference over the common samples:
    max over samples and blocks of |centre - centre_ref| + r |angle - angle_ref|, r = the block's
    half-diagonal (a bound on every point's displacement). Both (k, n, 6), sampled at the same times.
    Angles are compared modulo 2 pi: engines that keep a rotation as cos/sin report it in (-pi, pi]."""
    k = min(len(states), len(ref))
    a, b = np.asarray(states[:k]), np.asarray(ref[:k])
    turn = np.abs(np.remainder(a[..., 2] - b[..., 2] + np.pi, 2 * np.pi) - np.pi)
    d = np.hypot(a[..., 0] - b[..., 0], a[..., 1] - b[..., 1]) + half_diagonal * turn
    return float(np.max(d))


# ---- contact section (bench/contact.py) ----------------------------------------------------------
@dataclass(frozen=True)
class BoxGeometry:
    """What the overlap test needs of a scene besides the states: half extents (m, 2) of every box
    (dynamic ones first, in state order, then the static ones), the static boxes' centres and angles,
    and the static mask (m,)."""
    half: np.ndarray
    static_centre: np.ndarray
    static_angle: np.ndarray
    static: np.ndarray

    @classmethod
    def of(cls, scene: Any) -> "BoxGeometry":
        dyn = [b for b in scene.boxes if not b.static]
        sta = [b for b in scene.boxes if b.static]
        return cls(0.5 * np.array([[b.w, b.h] for b in dyn + sta]).reshape(-1, 2),
                   np.array([[b.x, b.y] for b in sta]).reshape(-1, 2), np.array([b.angle for b in sta]),
                   np.array([False] * len(dyn) + [True] * len(sta)))

    def poses(self, state: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Centres (m, 2) and angles (m,) of every box at one sample (state: (n_dynamic, 6))."""
        s = np.asarray(state)
        return np.concatenate([s[:, :2], self.static_centre]), np.concatenate([s[:, 2], self.static_angle])


def _expand(start: np.ndarray, stop: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All (p, q) with start[p] <= q < stop[p]: the flattened runs, built without a Python loop."""
    count = np.maximum(stop - start, 0)
    first = np.repeat(np.arange(len(start)), count)
    offset = np.arange(len(first)) - np.repeat(np.cumsum(count) - count, count)
    return first, start[first] + offset


def aabb_pairs(lo: np.ndarray, hi: np.ndarray, static: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Index pairs (i, j), each once, whose boxes [lo, hi] (m, 2) overlap or touch, static-static
    pairs left out. The few static boxes (walls, ground: any size) are tested against every dynamic
    one directly; dynamic pairs come from a uniform grid whose cell is the largest dynamic box
    extent, so two boxes can only meet if their min corners lie in the same or adjacent cells:
    each cell is matched with itself and 4 of its 8 neighbours (each pair once)."""
    dyn, sta = np.flatnonzero(~static), np.flatnonzero(static)
    hit = ((lo[sta, None, 0] <= hi[None, dyn, 0]) & (lo[None, dyn, 0] <= hi[sta, None, 0])
           & (lo[sta, None, 1] <= hi[None, dyn, 1]) & (lo[None, dyn, 1] <= hi[sta, None, 1]))
    si, di = np.nonzero(hit)
    pa, pb = [sta[si]], [dyn[di]]
    if len(dyn) > 1:
        size = max(float(np.max(hi[dyn] - lo[dyn])), 1e-9)
        # cells counted from 1 (room for the -1 neighbour); clipped so that a body flung far away
        # cannot overflow the key: clipping merges far cells, which only adds candidate pairs
        cell = np.clip(np.floor((lo[dyn] - lo[dyn].min(axis=0)) / size), 0, 2 ** 20).astype(np.int64) + 1
        ny = int(cell[:, 1].max()) + 2
        key = cell[:, 0] * ny + cell[:, 1]
        order = np.argsort(key, kind="stable")
        ks = key[order]
        pos = np.arange(len(ks))
        for dx, dy in ((0, 0), (1, -1), (1, 0), (1, 1), (0, 1)):
            want = ks + dx * ny + dy
            start = pos + 1 if (dx, dy) == (0, 0) else np.searchsorted(ks, want, side="left")
            p, q = _expand(start, np.searchsorted(ks, want, side="right"))
            a, b = dyn[order[p]], dyn[order[q]]
            keep = ((lo[a, 0] <= hi[b, 0]) & (lo[b, 0] <= hi[a, 0]) & (lo[a, 1] <= hi[b, 1])
                    & (lo[b, 1] <= hi[a, 1]))
            pa.append(a[keep])
            pb.append(b[keep])
    return np.concatenate(pa), np.concatenate(pb)


def sat_depth(ca: np.ndarray, aa: np.ndarray, ha: np.ndarray, cb: np.ndarray, ab: np.ndarray,
              hb: np.ndarray) -> np.ndarray:
    """Penetration depth (m) of pairs of oriented boxes (centres (k, 2), angles (k,), half extents
    (k, 2)): the smallest overlap of their projections on the four face normals, which for two
    rectangles is exactly the shortest translation that separates them (separating-axis theorem).
    <= 0 where the boxes are apart or touch; the caller clips at 0."""
    ua = np.stack([np.cos(aa), np.sin(aa)], -1)                   # a's local x axis; y is (-s, c)
    ub = np.stack([np.cos(ab), np.sin(ab)], -1)
    va = np.stack([-ua[:, 1], ua[:, 0]], -1)
    vb = np.stack([-ub[:, 1], ub[:, 0]], -1)
    d = cb - ca
    depth = np.full(len(ca), np.inf)
    for n in (ua, va, ub, vb):
        ra = ha[:, 0] * np.abs(np.sum(ua * n, -1)) + ha[:, 1] * np.abs(np.sum(va * n, -1))
        rb = hb[:, 0] * np.abs(np.sum(ub * n, -1)) + hb[:, 1] * np.abs(np.sum(vb * n, -1))
        depth = np.minimum(depth, ra + rb - np.abs(np.sum(d * n, -1)))
    return depth


def overlap_at(geom: BoxGeometry, state: np.ndarray) -> tuple[float, int, int]:
    """Largest penetration depth (m, >= 0) over all pairs of boxes at one sample, static boxes
    included (static-static pairs skipped: walls() boxes share their corners), and the pair (box
    indices in BoxGeometry order; -1, -1 when nothing overlaps)."""
    centre, angle = geom.poses(state)
    c, s = np.abs(np.cos(angle)), np.abs(np.sin(angle))
    half = geom.half
    ext = np.stack([c * half[:, 0] + s * half[:, 1], s * half[:, 0] + c * half[:, 1]], -1)
    a, b = aabb_pairs(centre - ext, centre + ext, geom.static)
    if len(a) == 0:
        return 0.0, -1, -1
    depth = sat_depth(centre[a], angle[a], half[a], centre[b], angle[b], half[b])
    k = int(np.argmax(depth))
    if depth[k] <= 0.0:
        return 0.0, -1, -1
    return float(depth[k]), int(a[k]), int(b[k])


def max_overlap(scene: Any, states: np.ndarray) -> dict[str, Any]:
    """Largest penetration depth (m) over all samples (k, n, 6) and pairs; `overlap_sample` is the
    sample index (= step when sampled every step; 0 = the initial state; -1 if nothing ever
    overlaps) and `overlap_pair` the two boxes (BoxGeometry order: dynamic indices, then static)."""
    geom = BoxGeometry.of(scene)
    best, at, pair = 0.0, -1, (-1, -1)
    for k, st in enumerate(states):
        d, i, j = overlap_at(geom, st)
        if d > best:
            best, at, pair = d, k, (i, j)
    return {"max_overlap": best, "overlap_sample": at, "overlap_pair": list(pair)}


def escaped_bodies(states: np.ndarray, inner: tuple[float, float, float, float]) -> dict[str, Any]:
    """Bodies whose centre is outside the inner box (xmin, ymin, xmax, ymax) at any sample (count)
    and the first such sample (-1 if none). Inclusive bounds: a centre on the boundary is inside."""
    s = np.asarray(states)
    xmin, ymin, xmax, ymax = inner
    out = (s[..., 0] < xmin) | (s[..., 0] > xmax) | (s[..., 1] < ymin) | (s[..., 1] > ymax)   # (k, n)
    per_sample = np.any(out, axis=1)
    return {"escaped": int(np.sum(np.any(out, axis=0))),
            "escape_sample": int(np.argmax(per_sample)) if per_sample.any() else -1}


def energy_steps(scene: Any, states: np.ndarray) -> dict[str, Any]:
    """For runs sampled every step: the largest single-step relative energy gain
    max_k (E[k+1] - E[k]) / |E[k]| with E = metrics.energy, the step k+1 it ends at, and the total
    relative change (E_end - E_0) / |E_0|. In a scene without driving forces a gain is energy the
    solver made; float32 engines (Box2D) show rounding gains of ~1e-7 from their state alone."""
    e = energy(scene, states)
    if len(e) < 2 or e[0] == 0.0:
        return {"max_step_gain": math.nan, "gain_step": -1, "e_change": math.nan}
    with np.errstate(divide="ignore", invalid="ignore"):
        gain = np.diff(e) / np.abs(e[:-1])
    k = int(np.nanargmax(gain)) if np.any(np.isfinite(gain)) else -1
    return {"max_step_gain": float(gain[k]) if k >= 0 else math.nan, "gain_step": k + 1,
            "e_change": float((e[-1] - e[0]) / abs(e[0]))}


def sink_creep(states: np.ndarray) -> dict[str, Any]:
    """For scenes that start at rest with the top box last (pyramid, stack): sink of the top box
    y_0 - y at the end (`sink_end`) and the largest over the samples (`sink_max`), and creep = the
    largest |x - x_0| over all boxes and samples (m; positive sink = lower than at the start)."""
    s = np.asarray(states)
    top = s[:, -1, 1]
    return {"sink_end": float(top[0] - top[-1]), "sink_max": float(np.max(top[0] - top)),
            "creep": float(np.max(np.abs(s[:, :, 0] - s[0, :, 0])))}


def end_motion(states: np.ndarray, window: int) -> dict[str, Any]:
    """Whether a pile has come to rest by the end of a run sampled every step: each body's centre
    displacement over the last `window` samples (1 s at dt 1/60), its median over the bodies
    (`end_motion_median`, m) and largest (`end_motion_max`), and the largest centre speed in the last
    sample (`end_speed_max`, m/s). A pile at rest moves by round-off; a creeping one by its creep."""
    s = np.asarray(states)
    if len(s) <= window:
        return {}
    d = np.hypot(s[-1, :, 0] - s[-1 - window, :, 0], s[-1, :, 1] - s[-1 - window, :, 1])
    return {"end_motion_median": float(np.median(d)), "end_motion_max": float(np.max(d)),
            "end_speed_max": float(np.max(np.hypot(s[-1, :, 3], s[-1, :, 4])))}


def contact_metrics(scene: Any, res: dict[str, Any], inner: tuple[float, float, float, float],
                    at_rest: bool, window: int = 60) -> dict[str, Any]:
    """The contact section's quality measures of one run (states sampled every step): max_overlap,
    escaped, energy_steps, end_motion over the last `window` samples, and sink_creep where the scene
    starts at rest with its top box last."""
    s = res["states"]
    out = {**max_overlap(scene, s), **escaped_bodies(s, inner), **energy_steps(scene, s),
           **end_motion(s, window)}
    if at_rest:
        out.update(sink_creep(s))
    return out
