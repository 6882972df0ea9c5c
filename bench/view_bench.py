"""Benchmark of the live view (python -m collide_ros.view): pointer -> spring latency, the view's CPU
at 6 and 1000 bodies, the page's drawing rate in headless Chromium.

    source scripts/env.sh && nice python bench/view_bench.py [--bodies 6 1000] [--trials 40] [--seconds 8] [--repeat 1]

Per case a sim node runs with bench/node_bench.py's parameters and scene (6: the default scene with
blocks:=6; 1000: its generated scene of 1000 moving boxes), a view beside it with ``--foxglove``
(each process its own), and Debian's Chromium (headless, through playwright) opens the page.
Measured, in this order:

- pointer -> spring (6 bodies only): the mouse presses on block1, then moves --trials times to a new
  point; latency = wall time from ``page.mouse.move`` to the node's echo of that spring on
  ``applied/spring`` (the node took and accepted it) in this process; then --trials more moves timed
  to the view's SpringCommand on ``spring`` (page -> WebSocket -> view -> ROS, without the node). The
  page sends at most one spring per animation frame, so up to one frame (16.7 ms at 60 Hz) of it is
  the page waiting for its next frame. Median and 90th percentile.
- the view process's CPU share (utime + stime from /proc over --seconds), first with the page alone
  (the Foxglove server idle: nothing subscribed), then with a Foxglove client subscribed to /scene,
  /tf and /energy as well, reading every message;
- the page, over --seconds: animation frames per second (a requestAnimationFrame counter beside the
  page's own), the page's draws of the scene per second (it draws when something changed: a new
  state) and the mean time one draw takes (performance.now() around it: the script's work, not the
  raster), state frames per second received from the view, and the sim seconds those frames advance per wall
  second (the node's real-time factor: the node publishes bodies/states at 100 Hz of sim time, so
  at most 100 x that many new states a second exist to be sent, and the view sends at most --rate,
  30); then, over another --seconds, the animation frames per second and the time per draw with the
  page drawing in every frame (``__view.drawEveryFrame``): whether it keeps 60 fps drawing; then how
  many of the page's shapes the view named as the node's dynamic bodies.

Not run by the tests (timings). Uses ROS_DOMAIN_ID from the environment, or picks a free one in the
bench range 75-79. Prints a markdown table.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import struct
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "ros_pkg"))
sys.path.insert(0, str(ROOT / "tests" / "python"))
sys.path.insert(0, str(ROOT / "bench"))

import node_bench  # noqa: E402  (pick_domain, Case, node_args, cpu_seconds)

CHROMIUM = "/usr/bin/chromium"
GIVE_UP = 60.0  # s


def percentile(xs: list[float], q: float) -> float:
    s = sorted(xs)
    return s[min(len(s) - 1, int(round(q * (len(s) - 1))))]


class FoxgloveReader:
    """A Foxglove WebSocket client on a thread: subscribes to every channel and reads every message."""

    def __init__(self, port: int) -> None:
        self.port = port
        self.messages = 0
        self.bytes = 0
        self._stop = threading.Event()
        self._ready = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()
        assert self._ready.wait(GIVE_UP), "the Foxglove client did not subscribe"

    def _run(self) -> None:
        from websockets.sync.client import connect
        from websockets.typing import Subprotocol
        with connect(f"ws://127.0.0.1:{self.port}", subprotocols=[Subprotocol("foxglove.sdk.v1")],
                     max_size=None) as ws:
            channels: dict[str, Any] = {}
            while len(channels) < 3:
                m = json.loads(ws.recv(timeout=GIVE_UP))
                if m["op"] == "advertise":
                    channels.update({c["topic"]: c for c in m["channels"]})
            ws.send(json.dumps({"op": "subscribe", "subscriptions": [
                {"id": i, "channelId": c["id"]} for i, c in enumerate(channels.values(), start=1)]}))
            self._ready.set()
            while not self._stop.is_set():
                try:
                    frame = ws.recv(timeout=0.2)
                except TimeoutError:
                    continue
                if isinstance(frame, bytes) and frame[0] == 1:
                    struct.unpack_from("<IQ", frame, 1)
                    self.messages += 1
                    self.bytes += len(frame)

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5.0)


def cpu_share(pid: int, seconds: float) -> float:
    c0, t0 = node_bench.cpu_seconds(pid), time.monotonic()
    time.sleep(seconds)
    return (node_bench.cpu_seconds(pid) - c0) / (time.monotonic() - t0)


def page_rates(page: Any, seconds: float, every_frame: bool = False) -> tuple[float, float, float, float, float]:
    """(animation frames per second, the page's draws per second, its mean milliseconds per draw,
    state frames received per second, sim seconds per wall second in those frames) over ``seconds``;
    ``every_frame``: the page draws in every animation frame, not only when something changed."""
    page.evaluate(f"window.__view.drawEveryFrame = {str(every_frame).lower()}")
    got = page.evaluate("""async (ms) => {
      const V = window.__view, f0 = V.frames, d0 = V.draws, m0 = V.drawMs, s0 = V.t, t0 = performance.now(); let n = 0;
      await new Promise((ok) => { const tick = () => { n++; if (performance.now() - t0 < ms) requestAnimationFrame(tick);
                                                         else ok(); }; requestAnimationFrame(tick); });
      const dt = (performance.now() - t0) / 1000, draws = V.draws - d0;
      return [n / dt, draws / dt, (V.drawMs - m0) / Math.max(1, draws), (V.frames - f0) / dt, (V.t - s0) / dt]; }""",
                        seconds * 1000.0)
    return float(got[0]), float(got[1]), float(got[2]), float(got[3]), float(got[4])


def spring_latency(page: Any, echoes: list[tuple[float, float]], lock: threading.Lock, trials: int) -> list[float]:
    """Press on block1, move the pointer ``trials`` times; seconds from each move to its echo."""
    x0, y0 = page.evaluate("[window.__view.bodies.block1.x, window.__view.bodies.block1.y]")
    sx, sy = page.evaluate(f"window.__view.toScreen({x0!r}, {y0!r})")
    page.mouse.move(sx, sy)
    page.mouse.down()
    out: list[float] = []
    try:
        for i in range(trials):
            px, py = round(sx) + 40 + 3 * (i % 20), round(sy) - 30  # whole pixels, as MouseEvent.clientX
            tx = page.evaluate(f"window.__view.toWorld({px!r}, {py!r})[0]")  # the target the page will send
            with lock:
                n0 = len(echoes)
            t0 = time.monotonic()
            page.mouse.move(px, py)
            end = t0 + 5.0
            hit = None
            while hit is None and time.monotonic() < end:
                with lock:
                    hit = next((t for t, x in echoes[n0:] if abs(x - tx) < 1e-9), None)
                if hit is None:
                    time.sleep(0.0005)
            if hit is not None:
                out.append(hit - t0)
            time.sleep(0.05 + 0.013 * (i % 7))  # not in step with the page's frames
    finally:
        page.mouse.up()
    return out


def run_case(label: str, trials: int, seconds: float) -> dict[str, Any]:
    import rclpy
    from libcollide_msgs.msg import SpringCommand
    from playwright.sync_api import sync_playwright
    from rclpy.executors import SingleThreadedExecutor

    from collide_ros.testing import NodeProcess
    from view_process import ViewProcess

    case = node_bench.parse_case(label)
    res: dict[str, Any] = {"case": label}
    with tempfile.TemporaryDirectory() as tmp:
        ctx = rclpy.Context()
        rclpy.init(context=ctx)
        node = NodeProcess(*node_bench.node_args(case, Path(tmp)))
        ros = rclpy.create_node(f"view_bench_{os.getpid()}", context=ctx)
        echoes: list[tuple[float, float]] = []
        lock = threading.Lock()

        def on_echo(m: SpringCommand) -> None:
            with lock:
                echoes.append((time.monotonic(), m.target.x))
        ros.create_subscription(SpringCommand, "applied/spring", on_echo, 100)
        sent: list[tuple[float, float]] = []

        def on_sent(m: SpringCommand) -> None:
            with lock:
                sent.append((time.monotonic(), m.target.x))
        ros.create_subscription(SpringCommand, "spring", on_sent, 100)
        ex = SingleThreadedExecutor(context=ctx)
        ex.add_node(ros)
        spin = threading.Thread(target=lambda: _spin(ex, ctx), daemon=True)
        spin.start()
        view = pw = browser = fox = None
        try:
            view = ViewProcess(0, "--foxglove", "--foxglove-port", "0")
            pw = sync_playwright().start()
            browser = pw.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"], headless=True)
            page = browser.new_page(viewport={"width": 1100, "height": 800})
            page.goto(view.url)
            page.wait_for_function(f"window.__view && window.__view.node && window.__view.shapes.length >= {case.bodies}",
                                   timeout=GIVE_UP * 1000)
            page.wait_for_timeout(2000)  # the node and the page settle
            if trials:
                res["latency"] = spring_latency(page, echoes, lock, trials)
                res["latency_view"] = spring_latency(page, sent, lock, trials)
                res["lost"] = 2 * trials - len(res["latency"]) - len(res["latency_view"])
            res["cpu_page"] = cpu_share(view.proc.pid, seconds)
            res["fps"], res["draws"], res["draw_ms"], res["frames"], res["rtf"] = page_rates(page, seconds)
            res["fps_all"], _, res["draw_ms_all"], _, _ = page_rates(page, seconds, every_frame=True)
            page_rates(page, 0.0)  # back to drawing on change
            res["named"] = page.evaluate("window.__view.shapes.filter((b) => b.name).length")
            assert view.foxglove_port
            fox = FoxgloveReader(view.foxglove_port)
            m0, b0, t0 = fox.messages, fox.bytes, time.monotonic()
            res["cpu_fox"] = cpu_share(view.proc.pid, seconds)
            dt = time.monotonic() - t0
            res["fox_msgs"], res["fox_mbps"] = (fox.messages - m0) / dt, (fox.bytes - b0) / dt / 1e6
        finally:
            if fox is not None:
                fox.stop()
            if browser is not None:
                browser.close()
            if pw is not None:
                pw.stop()
            if view is not None:
                view.stop()
            node.stop()
            rclpy.shutdown(context=ctx)
            spin.join(timeout=2.0)
    return res


def median_of(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """One row from the runs of a case: the median of each figure, the latency samples pooled."""
    out: dict[str, Any] = {"case": runs[0]["case"]}
    for key, value in runs[0].items():
        if key.startswith("latency"):
            out[key] = [x for r in runs for x in r[key]]
        elif isinstance(value, (int, float)):
            out[key] = statistics.median(r[key] for r in runs)
    return out


def _spin(ex: Any, ctx: Any) -> None:
    while ctx.ok():
        try:
            ex.spin_once(timeout_sec=0.05)
        except Exception:  # the context shut down while spinning
            return


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bodies", nargs="+", default=["6", "1000"], help="cases (node_bench's: 6, 1000, ...)")
    p.add_argument("--trials", type=int, default=40, help="pointer moves for the latency (6 bodies)")
    p.add_argument("--seconds", type=float, default=8.0, help="wall seconds of each CPU and frame-rate window")
    p.add_argument("--repeat", type=int, default=1,
                   help="runs of each case (each a fresh node, view and browser); the table gives the median "
                        "of every figure over the runs, the latencies pooled")
    a = p.parse_args()
    if not os.access(CHROMIUM, os.X_OK):
        print(f"view_bench: {CHROMIUM} is missing; run scripts/setup", file=sys.stderr)
        return 1
    lock = node_bench.pick_domain()
    print(f"ROS_DOMAIN_ID={os.environ['ROS_DOMAIN_ID']}, {os.cpu_count()} cores, "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load average "
          f"{' '.join(f'{x:.1f}' for x in os.getloadavg())}", flush=True)
    rows = []
    try:
        for label in a.bodies:
            runs = []
            for _ in range(max(1, a.repeat)):
                r = run_case(label, a.trials if int(label) <= 6 else 0, a.seconds)
                runs.append(r)
                print(f"  {label}: {json.dumps({k: v for k, v in r.items() if not k.startswith('latency')})}",
                      flush=True)
            rows.append(median_of(runs))
    finally:
        if lock is not None:
            lock.release()
    print(f"load average at the end: {' '.join(f'{x:.1f}' for x in os.getloadavg())}; "
          f"{max(1, a.repeat)} run(s) per case")
    print("\n| bodies | pointer -> node's echo p50 / p90 (ms) | pointer -> view's spring p50 / p90 (ms) "
          "| view CPU, page | view CPU, page + Foxglove client | page fps (animation frames) | page draws/s (ms each) | page fps drawing every frame (ms each) "
          "| state frames/s on the page | sim s per wall s | bodies named | Foxglove messages/s (MB/s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")

    def ms(lat: list[float] | None) -> str:
        return f"{1e3 * statistics.median(lat):.0f} / {1e3 * percentile(lat, 0.9):.0f}" if lat else "-"
    for r in rows:
        print(f"| {r['case']} | {ms(r.get('latency'))} | {ms(r.get('latency_view'))} | {100 * r['cpu_page']:.0f} % "
              f"| {100 * r['cpu_fox']:.0f} % | {r['fps']:.0f} | {r['draws']:.0f} ({r['draw_ms']:.1f}) | {r['fps_all']:.0f} ({r['draw_ms_all']:.1f}) | {r['frames']:.0f} | {r['rtf']:.2f} "
              f"| {r['named']:.0f} | {r['fox_msgs']:.0f} ({r['fox_mbps']:.2f}) |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
