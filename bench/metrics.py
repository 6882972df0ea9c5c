"""Physics measures computed by the harness from the states the engines return (never from the
engines): energy with potential m g y (y = 0 is the floor top / box bottom in every scene),
momentum, per-scene errors."""
from __future__ import annotations

import math
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
