"""The node's threads: the calling thread steps the world on a sleep-until schedule (step k is due at
ref + k * time_step / real_time_factor of wall time) and publishes /diagnostics once a second; a second
thread runs the executor (commands, services, parameters); both take the node's lock (guards.py). With
the parameter publish_thread a third writes and sends each step's publish round while the calling thread
takes the next step (publish_thread.py): given a spare core, the period is bounded by the larger of
physics and publishing, not their sum."""
from __future__ import annotations

import threading
import time

from rclpy.executors import ExternalShutdownException, ShutdownException, SingleThreadedExecutor

CATCH_UP_LIMIT = 0.1  # s (wall): a loop further behind than this drops the backlog (counted as late)


class Loop:
    """Owns ``_schedule_dirty`` (set by a pause, reset or rate change: the schedule starts over) and
    ``late_steps`` (times the loop dropped a backlog)."""

    def _init_loop(self) -> None:
        self._schedule_dirty = True
        self.late_steps = 0

    def _spin(self, ex: SingleThreadedExecutor) -> None:
        """Executor thread: commands, services and parameters are handled as they arrive (under the
        lock). It sleeps inside rcl_wait (GIL released) while nothing arrives, so the size of the
        wait set (per-body topics) costs nothing per physics step."""
        while self.context.ok():
            try:
                ex.spin_once(timeout_sec=0.1)
            except (ExternalShutdownException, ShutdownException):
                return
            except Exception as exc:  # a callback outside our guards (e.g. rclpy's parameter services)
                self._warn("executor", f"executor: {type(exc).__name__}: {exc}")

    def run(self, executor: SingleThreadedExecutor | None = None) -> None:
        """Simulate until the context shuts down (Ctrl-C, SIGTERM, rclpy.shutdown()).

        The calling thread steps the world on a sleep-until schedule (step k is due at
        ref + k * time_step / real_time_factor, wall time); a second thread runs the executor."""
        ex = executor or SingleThreadedExecutor(context=self.context)
        ex.add_node(self)
        spinner = threading.Thread(target=self._spin, args=(ex,), name="sim-executor", daemon=True)
        spinner.start()
        threaded = bool(self._p["publish_thread"])
        if threaded:
            self._start_publish_thread()
        ref_wall = time.perf_counter()
        ref_steps = 0
        next_diag = ref_wall + 1.0
        try:
            while self.context.ok():
                now = time.perf_counter()
                if now >= next_diag:
                    with self._lock:
                        self._publish_diagnostics()
                    next_diag = now + 1.0
                if self._schedule_dirty:
                    self._schedule_dirty = False
                    ref_wall, ref_steps = now, 0
                if self._paused:
                    time.sleep(0.01)
                    ref_wall, ref_steps = time.perf_counter(), 0
                    continue
                rtf = float(self._p["real_time_factor"])
                if rtf > 0:
                    due = ref_wall + ref_steps * float(self._p["time_step"]) / rtf
                    if now < due:
                        time.sleep(min(due - now, 0.05))
                        continue
                    if now - due > CATCH_UP_LIMIT:
                        self.late_steps += 1  # too far behind: drop the backlog, keep the pace from here
                        ref_wall, ref_steps = now, 0
                with self._lock:
                    if self._paused or self._schedule_dirty:
                        continue
                    self.step_once(threaded=threaded)
                ref_steps += 1
                if self._lock_waiters:
                    # A callback waits for the lock (_executor_lock). Without sleeping this loop would
                    # take it back at once (flat out at real_time_factor 0, or catching up), so sleep
                    # long enough for the waiting thread to get it. Only then: time.sleep(0) costs
                    # ~80 us here (an actual timer sleep), more than a step of a small scene.
                    time.sleep(0)
        except KeyboardInterrupt:
            pass
        except Exception:
            # Ctrl-C or SIGTERM between the loop's context check and a publish: rclpy raises on the
            # shut-down context (seen once in CI: "publisher's context is invalid", exit status 1).
            # That is the end of the run, not an error; anything else while the context lives is.
            if self.context.ok():
                raise
        finally:
            with self._lock:
                self._stop_publish_thread()
            spinner.join(timeout=2.0)
            ex.remove_node(self)
