"""Runs tasks (engine, settings, scene, dt) in one persistent worker process per engine, one task at a
time, so a crash or a hang of one engine is recorded instead of ending the benchmark. The parent
imports no engine. Timing is the worker thread's CPU time inside the step loop only; states are
sampled between timed chunks."""
from __future__ import annotations

import math
import multiprocessing as mp
import os
import sys
import time
import traceback
from dataclasses import dataclass, field
from typing import Any

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


@dataclass
class Task:
    engine: str
    scene: Any                        # scenes.Scene
    dt: float
    settings: dict = field(default_factory=dict)
    sample_dt: float | None = None    # s of simulated time between state samples (None: start and end only)
    budget: float = 20.0              # s of CPU; a run that exceeds it stops early (flagged)
    label: str = ""                   # engine variant label for tables and plots
    key: str = ""                     # case key (scene + setting) for grouping
    stream: bool = False              # send every sample to the parent as it is taken, so that a run
                                      # killed inside a step still returns the states it reached
    laps: int = 1                     # the scene this many times from a fresh build, CPU and steps summed
                                      # (a short scene long enough to time); states and stages are the
                                      # last lap's

    def __post_init__(self) -> None:
        if self.laps < 1 or (self.laps > 1 and self.stream):
            raise ValueError(f"laps = {self.laps}: at least 1, and 1 for a streamed task")
        if not self.label:
            self.label = self.engine
        if not self.key:
            self.key = f"{self.scene.name}|{self.label}|{self.dt:.6g}"


def run_task(task: Task, progress: Any = None) -> dict[str, Any]:
    """Executed in the worker: build, step, sample. Returns plain data; progress(steps, cpu) after
    every chunk lets the parent tell a slow step from a dead worker."""
    import engines
    total = int(round(task.scene.duration / task.dt))
    # chunks of at most 0.25 s simulated, so the CPU budget is checked often
    per = max(1, int(round((0.25 if task.sample_dt is None else task.sample_dt) / task.dt)))
    cpu, done, build, status = 0.0, 0, 0.0, "ok"
    for _ in range(task.laps):
        t_build = time.thread_time()
        eng = engines.make(task.engine, task.scene, task.settings)
        build += time.thread_time() - t_build
        times, states = [0.0], [eng.states()]
        if progress is not None and task.stream:
            progress(0, 0.0, states[0])
        lap = 0
        while lap < total:
            n = min(per, total - lap)
            cpu += eng.advance(task.dt, n)
            lap += n
            done += n
            s = eng.states()
            if progress is not None and task.stream:
                progress(done, cpu, s)
            elif progress is not None:
                progress(done, cpu)
            if task.sample_dt is None and len(states) > 1:
                times.pop()
                states.pop()   # start and end only
            times.append(lap * task.dt)
            states.append(s)
            if getattr(eng, "status", 0):
                status = f"step error status {eng.status}"
                break
            if not np.all(np.isfinite(s)):
                status = "nan"
                break
            if cpu > task.budget and done < total * task.laps:
                status = "over_budget"
                break
        if status != "ok":
            break
    return {"key": task.key, "engine": task.engine, "label": task.label, "scene": task.scene.name,
            "dt": task.dt, "settings": task.settings, "steps": done, "sim_time": done * task.dt,
            "laps": task.laps, "cpu": cpu, "build_cpu": build, "status": status, "times": np.array(times),
            "states": np.array(states), "stages": eng.stages(), "precision": eng.precision}


def _worker(conn: Any) -> None:
    sys.path.insert(0, HERE)
    try:
        os.nice(0)
    except OSError:
        pass
    while True:
        try:
            task = conn.recv()
        except EOFError:
            return
        if task is None:
            return
        try:
            conn.send(run_task(task, lambda *msg: conn.send(("progress",) + msg)))
        except Exception as exc:  # report, keep serving
            conn.send({"key": task.key, "engine": task.engine, "label": task.label, "scene": task.scene.name,
                       "dt": task.dt, "status": f"error: {exc!r}", "trace": traceback.format_exc()})


class Pool:
    """One worker per engine; tasks run strictly one after another."""

    def __init__(self) -> None:
        self._ctx = mp.get_context("fork")
        self._workers: dict[str, tuple[Any, Any]] = {}

    def _get(self, engine: str) -> tuple[Any, Any]:
        if engine not in self._workers:
            parent, child = self._ctx.Pipe()
            p = self._ctx.Process(target=_worker, args=(child,), daemon=True)
            p.start()
            child.close()
            self._workers[engine] = (p, parent)
        return self._workers[engine]

    def _drop(self, engine: str) -> None:
        p, conn = self._workers.pop(engine)
        if p.is_alive():
            p.kill()   # only our own worker process, by its handle
        p.join(5)
        conn.close()

    def run(self, task: Task) -> dict[str, Any]:
        p, conn = self._get(task.engine)
        conn.send(task)
        wall_limit = 2 * task.budget + 10    # s of wall time without progress
        steps, cpu = 0, 0.0
        times: list[float] = []
        states: list[np.ndarray] = []
        while conn.poll(wall_limit):
            try:
                msg = conn.recv()
            except EOFError:
                break
            if isinstance(msg, tuple) and msg and msg[0] == "progress":
                steps, cpu = msg[1], msg[2]
                if len(msg) > 3:   # a streamed sample (Task.stream)
                    times.append(steps * task.dt)
                    states.append(msg[3])
                continue
            return msg
        code = p.exitcode
        alive = p.is_alive()
        self._drop(task.engine)
        where = f"after {steps} steps ({steps * task.dt:.3g} s simulated, {cpu:.3g} s CPU)"
        why = (f"hang: no progress for {wall_limit:.0f} s wall, {where}" if alive
               else f"crashed (exit code {code}) {where}")
        out = {"key": task.key, "engine": task.engine, "label": task.label, "scene": task.scene.name,
               "dt": task.dt, "status": why, "steps_done": steps, "cpu_done": cpu}
        if states:   # streamed: the samples it reached (the CPU of the step it died in is unknown)
            out.update(times=np.array(times), states=np.array(states), wall_limit=wall_limit)
        return out

    def close(self) -> None:
        for engine, (p, conn) in list(self._workers.items()):
            try:
                conn.send(None)
            except (BrokenPipeError, OSError):
                pass
            p.join(5)
            self._drop(engine)


def run_interleaved(pool: Pool, tasks: list[Task], repeats: int, log: Any = None) -> dict[str, dict[str, Any]]:
    """Runs every task `repeats` times, round-robin over the list (so engines alternate within each
    case), rotating the start each round. Returns per key the first run's data with cpu = median
    over repeats (cpu_all keeps all). Runs that did not finish "ok" are not repeated."""
    out: dict[str, dict[str, Any]] = {}
    n = len(tasks)
    for rep in range(repeats):
        for i in range(n):
            task = tasks[(i + rep) % n]
            prev = out.get(task.key)
            if prev is not None and prev["status"] != "ok":
                continue
            res = pool.run(task)
            if prev is None:
                res["cpu_all"] = [res.get("cpu", math.nan)]
                out[task.key] = res
                if res["status"] != "ok" and log:
                    log(f"  {task.key}: {res['status']}")
            else:
                prev["cpu_all"].append(res.get("cpu", math.nan))
                if res.get("status") == "ok" and not np.array_equal(res["states"][-1], prev["states"][-1]):
                    prev["nondeterministic"] = True
    for res in out.values():
        res["cpu_median"] = float(np.median(res["cpu_all"])) if "cpu" in res else math.nan
        st = res.get("sim_time", 0.0)
        res["cpu_per_sim_s"] = res["cpu_median"] / st if st else math.nan
        res["us_per_step"] = 1e6 * res["cpu_median"] / res["steps"] if res.get("steps") else math.nan
    return out
