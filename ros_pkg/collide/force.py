"""A custom force law for a World (the C API of collide/force.h): World.set_force_callback.

The engine calls the force function wherever it evaluates applied forces (every integrator stage, each
contact-regime sub-step, the step's prediction), so it is called many times per step with intermediate
states. It gets a ForceQuery and returns an (n, 3) array: fx, fy (N, world frame, at the centre of
mass) and torque (N*m) per body row; only the rows in ``query.rows`` are read. It must be a pure
function of the query (and of data changed only between steps) for the engine to stay deterministic,
and must not step or change the world. An exception in it, a wrong shape or a non-finite force fails
the step (World.step raises CollideError from the exception; the step is undone).

The optional potential function returns the force law's potential energy (J) for a ForceQuery; it is
added to ``World.energy.total`` (as ``Energy.callback``). Without it, the total leaves out the force's
work.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from ._ffi import CollideError, check, ffi, lib

if TYPE_CHECKING:
    from .world import World

__all__ = ["ForceQuery", "ForceFn", "PotentialFn"]


@dataclass(frozen=True)
class ForceQuery:
    """One evaluation's bodies, in row order (static ones included). The arrays are copies: a
    callback may keep them."""
    state: np.ndarray    # (n, 6): x, y, angle, vx, vy, omega of each centre of mass at this evaluation
    mass: np.ndarray     # (n,) kg, 0 for static bodies
    inertia: np.ndarray  # (n,) kg*m^2, 0 for static bodies
    ids: np.ndarray      # (n,) body ids
    static: np.ndarray   # (n,) bool
    rows: np.ndarray     # (k,) the dynamic rows whose force is read (a potential: every dynamic row)


ForceFn = Callable[[ForceQuery], Any]        # -> (n, 3) array-like: fx, fy, torque per row
PotentialFn = Callable[[ForceQuery], float]  # -> J


class _Law:
    """The Python side of a world's force callback: its functions, the handle C passes back to them,
    and the exception a call raised (reported by the step or energy reading that made the call)."""

    def __init__(self, force: ForceFn, potential: PotentialFn | None) -> None:
        self.force = force
        self.potential = potential
        self.error: tuple[str, BaseException] | None = None   # which function raised, and what
        self.handle = ffi.new_handle(self)


def _array(ptr: Any, n: int, dtype: Any, shape: tuple[int, ...]) -> np.ndarray:
    size = int(np.prod(shape))
    if size == 0:
        return np.zeros(shape, dtype=dtype)
    return np.frombuffer(ffi.buffer(ptr, size * np.dtype(dtype).itemsize), dtype=dtype).reshape(shape).copy()


def _query(q: Any) -> ForceQuery:
    b = q.bodies
    n = int(b.count)
    return ForceQuery(
        state=_array(b.state, n, np.float64, (n, 6)),
        mass=_array(b.mass, n, np.float64, (n,)),
        inertia=_array(b.inertia, n, np.float64, (n,)),
        ids=_array(b.ids, n, np.uint32, (n,)),
        static=_array(b.is_static, n, np.uint8, (n,)).astype(bool),
        rows=_array(q.rows, int(q.row_count), np.intc, (int(q.row_count),)).astype(np.intp),
    )


@ffi.def_extern()
def collide_force_callback(user: Any, query: Any, out: Any) -> int:
    law: _Law = ffi.from_handle(user)
    try:
        q = _query(query)
        n = q.state.shape[0]
        forces = np.asarray(law.force(q), dtype=np.float64)
        if forces.shape != (n, 3):
            raise ValueError(f"the force function returned shape {forces.shape}, expected ({n}, 3)")
        np.frombuffer(ffi.buffer(out, n * 3 * 8), dtype=np.float64)[:] = forces.reshape(-1)
        return 0
    except BaseException as exc:  # reported by World.step; nothing may unwind through C
        law.error = ("force", exc)
        return 1


@ffi.def_extern()
def collide_potential_callback(user: Any, query: Any, out: Any) -> int:
    law: _Law = ffi.from_handle(user)
    try:
        value = law.potential(_query(query)) if law.potential is not None else 0.0
        out[0] = float(value)
        return 0
    except BaseException as exc:  # reported by World.energy
        law.error = ("potential", exc)
        return 1


def set_force_callback(world: "World", force: ForceFn | None, potential: PotentialFn | None) -> None:
    """Set (or with force None, remove) the world's force law; the World keeps the functions alive."""
    if force is not None and not callable(force):
        raise TypeError(f"force must be callable or None, got {type(force).__name__}")
    if potential is not None and not callable(potential):
        raise TypeError(f"potential must be callable or None, got {type(potential).__name__}")
    if force is None:
        check(world._w, lib.lc_world_set_force_callback(world._w, ffi.NULL, _c_potential(potential), ffi.NULL))
        world._force_law = None
        return
    law = _Law(force, potential)
    check(world._w, lib.lc_world_set_force_callback(world._w, lib.collide_force_callback, _c_potential(potential),
                                                    law.handle))
    world._force_law = law


def _c_potential(potential: PotentialFn | None) -> Any:
    return ffi.NULL if potential is None else lib.collide_potential_callback


def check_call(world: "World", status: int) -> None:
    """check() for a call that may have run the force law: an exception it raised is what failed the
    call (CollideError from it; a KeyboardInterrupt or other BaseException is raised again as it was)."""
    law: _Law | None = world._force_law
    raised = law.error if law is not None else None
    if law is not None:
        law.error = None
    if status == lib.LC_OK:
        return
    if raised is None:
        check(world._w, status)
        return
    where, error = raised
    if not isinstance(error, Exception):
        raise error
    undone = "; the step was undone" if where == "force" else ""
    raise CollideError(status, f"the {where} function raised {type(error).__name__}: {error}{undone}") from error
