"""One physics step of the node: the commands' forces applied, the world stepped (a step C undoes taken in
parts instead, within limits: the split policy below), the step's time measured, and the publishing that
is due after it. The world's event stream keeps the impacts of every step and part taken."""
from __future__ import annotations

import time

from collide import CollideError

# A step C undoes (LC_ERR_NUMERIC: e.g. a crossing missed within a trial interval and caught by the
# energy balance) is deterministic: retried as it was, it fails again and the sim would stand still
# until a reset. Halving the step changes the trial intervals, so it is retried as two halves, each
# of which may halve again, down to time_step / 2**SPLIT_DEPTH; only then is it a failure.
SPLIT_DEPTH = 6
# ... unless the undone step was already costly (C's work caps: 5e5 force evaluations, 5e4 serial
# passes, 1e9 solver work per body): 2 + 2 + ... more attempts at that cost would stall the loop (and
# the executor, which waits for the world lock) for many times as long. The soak's command mix on
# four blocks took at most 3 660 evaluations, 1 100 serial passes and 1.2e5 solver work per body in
# a step (soak/step_search.py, 2.5e8 steps; docs/hardening.md "The node when C undoes a step").
SPLIT_MAX_WORK = {"force_evaluations": 20_000, "serial_iterations": 5_000}
SPLIT_MAX_SOLVER_WORK_PER_BODY = 1e7


class Stepping:
    """Owns the step counts (``steps`` since the last build, ``total_steps``, ``split_steps``),
    ``failing_since`` (sim time of the first of the failed steps in a row, or None) and the step and
    publish times summed for /diagnostics (``_step_time_sum``, ``_step_time_max``, ``_pub_time_sum``:
    the stepping thread's time after the step, ``_window_steps``)."""

    def _init_stepping(self) -> None:
        self.steps = 0          # since the last (re)build; drives the publish periods
        self.total_steps = 0
        self._step_time_sum = 0.0
        self._step_time_max = 0.0
        self._pub_time_sum = 0.0
        self._window_steps = 0
        self.split_steps = 0    # steps C undid that went through in parts (_step_in_parts)
        self._split_tried = False  # whether the last step C undid was tried in parts
        self.failing_since: float | None = None

    def _step_in_parts(self, dt: float) -> None:
        """world.step(dt); a step C undoes is taken as halves instead (recursively,
        SPLIT_DEPTH levels), unless its work counters say it was costly (SPLIT_MAX_WORK). Raises C's
        error if a part of dt / 2**SPLIT_DEPTH or a costly part fails; the parts before it stay taken
        (their time too: the sim clock then leaves the time_step grid)."""
        self._split_tried = False
        try:
            self.world.step(dt)
            return
        except CollideError as exc:
            why = str(exc)
            if not self._worth_splitting():
                raise
        self._split_tried = True
        t = self.sim_time
        parts = self._halves(dt, 1)
        self.split_steps += 1
        self._warn("split", f"physics step at t={t:.6f} s was undone by C ({why}); "
                   f"taken as {parts} parts instead")

    def _worth_splitting(self) -> bool:
        """Whether the step C just undid was cheap enough to be tried again in parts (its counters)."""
        c = self.world.counters(last=True)
        return (all(c[k] <= v for k, v in SPLIT_MAX_WORK.items())
                and c["solver_work"] <= SPLIT_MAX_SOLVER_WORK_PER_BODY * max(len(self.world), 1))

    def _halves(self, dt: float, depth: int) -> int:
        """Two steps of dt / 2, each halved again if C undoes it; returns the number of parts taken."""
        n = 0
        for _ in range(2):
            try:
                self.world.step(dt / 2)  # each part's impacts enter the event stream
                n += 1
            except CollideError:
                if depth >= SPLIT_DEPTH or not self._worth_splitting():
                    raise
                n += self._halves(dt / 2, depth + 1)
        return n

    def step_once(self, threaded: bool = False) -> bool:
        """One physics step and whatever publishing is due; False if the step failed (and was undone).
        ``threaded`` (the stepping loop): the publish thread writes and sends the round (publishing.py)."""
        self._apply_forces()
        t0 = time.perf_counter()
        try:
            self._step_in_parts(float(self._p["time_step"]))
        except CollideError as exc:
            # C undid the step. Drop every command and every spring made over ROS, so that what a
            # peer sent cannot keep the world from stepping (the scene's own forces stay).
            how = (f"also in parts of time_step / {2 ** SPLIT_DEPTH}" if self._split_tried
                   else "not split (a costly step: C's work counters past the node's split limits)")
            self._reject("step", f"physics step at t={self.sim_time:.6f} s failed, {how} ({exc}); all thrust, "
                         f"thruster and cmd_vel commands and springs ({', '.join(self._springs) or 'none'}) "
                         "dropped")
            self._drop_commands()
            self._apply_forces()
            if self.failing_since is None:
                self.failing_since = self.sim_time
            return False
        self.failing_since = None
        t1 = time.perf_counter()
        self.steps += 1
        self.total_steps += 1
        self._window_steps += 1
        dt_step = t1 - t0
        self._step_time_sum += dt_step
        self._step_time_max = max(self._step_time_max, dt_step)
        self._publish_due(self.steps, threaded=threaded)
        self._pub_time_sum += time.perf_counter() - t1
        return True
