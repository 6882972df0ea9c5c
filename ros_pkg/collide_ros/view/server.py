"""The view's web server: one self-contained page on ``/`` and the sim streamed on ``/ws``.

    python -m collide_ros.view [--host 127.0.0.1] [--port 8080] [--rate 30] [--foxglove [--foxglove-port 8765]]
                               [--ros-args -r __ns:=/robot1]

HTTP and the WebSocket share one port (websockets' ``process_request`` serves the page). Each page
gets the latest state at ``--rate`` Hz as a binary frame (frames.py): a frame is built from the newest
data when it is due and sent before the next one is built, so a slow page gets fewer frames, never a
backlog. ``--foxglove``
also serves the scene over the Foxglove WebSocket protocol (foxglove_bridge.py) on the same host.
"""
from __future__ import annotations

import argparse
import asyncio
import itertools
import json
import signal
import sys
import time
from http import HTTPStatus
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

import rclpy
from websockets.asyncio.server import ServerConnection, serve
from websockets.datastructures import Headers
from websockets.exceptions import ConnectionClosed
from websockets.http11 import Request, Response

from collide_ros.teleop import KEYMAP
from collide_ros.view import frames, protocol
from collide_ros.view.bridge import ViewBridge, spin_in_thread

PAGE = Path(__file__).with_name("page.html")
MAX_PENDING = 8  # parameter/service requests per page waiting for the node at once
HEARTBEAT = 1.0  # s: a state frame at least this often, even when nothing changed
# state frames sent to a page and not acknowledged yet: a browser reads its WebSocket whatever its
# page does, so only the page's acks tell that it keeps up; beyond this the due frames are skipped
# and the next one sent carries the newest state. A client that never acks is not held back.
WINDOW = 2


def _response(status: HTTPStatus, body: bytes, content_type: str) -> Response:
    headers = Headers([("Content-Type", content_type), ("Content-Length", str(len(body))),
                       ("Cache-Control", "no-store"), ("X-Content-Type-Options", "nosniff")])
    return Response(status.value, status.phrase, headers, body)


class ViewServer:
    """Serves the page and one WebSocket session per open page."""

    def __init__(self, bridge: ViewBridge, rate: float = 30.0) -> None:
        self.bridge = bridge
        self.period = 1.0 / rate
        self.page = PAGE.read_bytes()
        self._ids = itertools.count(1)
        self.sessions = 0

    def process_request(self, conn: ServerConnection, request: Request) -> Response | None:
        path = request.path.split("?", 1)[0]
        if path == "/ws":
            origin = request.headers.get("Origin")
            # another web site open in the same browser must not drive the sim
            if origin is not None and urlsplit(origin).netloc != request.headers.get("Host"):
                return _response(HTTPStatus.FORBIDDEN, b"cross-origin WebSocket refused\n", "text/plain")
            return None  # the WebSocket handshake goes on
        if path in ("/", "/index.html"):
            return _response(HTTPStatus.OK, self.page, "text/html; charset=utf-8")
        return _response(HTTPStatus.NOT_FOUND, b"not found\n", "text/plain")

    async def session(self, ws: ServerConnection) -> None:
        client = next(self._ids)
        self.sessions += 1
        send_lock = asyncio.Lock()
        pending = [0]  # requests sent to the node and not answered yet

        def done_one() -> None:
            pending[0] -= 1
        loop = asyncio.get_running_loop()

        async def send(obj: dict[str, Any] | bytes) -> None:
            """A JSON text message, or bytes as one binary message (a state frame)."""
            async with send_lock:
                await ws.send(obj if isinstance(obj, bytes) else json.dumps(obj, allow_nan=False, default=float))

        def reply_soon(req_id: int | None, kind: str) -> Any:
            def reply(ok: bool, message: str) -> None:  # on the executor thread
                msg = {"type": "reply", "id": req_id, "request": kind, "ok": ok, "message": message}
                loop.call_soon_threadsafe(done_one)
                asyncio.run_coroutine_threadsafe(_safe(send(msg)), loop)
            return reply

        await send({"type": "hello", "client": client, "bodies": list(self.bridge.bodies),
                    "keymap": {k: list(v) for k, v in KEYMAP.items()}, "params": list(protocol.PARAMS),
                    "rate": 1.0 / self.period})
        flow = _Flow()
        streamer = asyncio.create_task(self._stream(ws, send, flow))
        limit = protocol.RateLimit()
        last_flood_notice = 0.0
        try:
            async for text in ws:
                if not limit.take():
                    now = time.monotonic()
                    if now - last_flood_notice >= 1.0:
                        last_flood_notice = now
                        await send({"type": "refused", "id": None, "reason":
                                    f"flood: more than {limit.rate:g} messages/s; {limit.refused} dropped so far"})
                    continue
                try:
                    cmd = protocol.parse(text, self.bridge.dynamic_bodies())
                except protocol.Refused as r:
                    await send({"type": "refused", "id": r.req_id, "reason": r.reason})
                    continue
                if cmd.type == "ack":
                    flow.acked = max(flow.acked or 0, min(cmd.args["frame"], flow.sent))
                elif cmd.type == "spring":
                    self.bridge.spring(client, cmd.args["body"], cmd.args["point"], cmd.args["target"])
                elif cmd.type == "release":
                    self.bridge.release(client)
                elif cmd.type == "keys":
                    self.bridge.keys(client, cmd.args["held"])
                elif pending[0] >= MAX_PENDING:
                    await send({"type": "refused", "id": cmd.id, "reason":
                                f"busy: {pending[0]} requests still wait for the sim node's answer"})
                else:  # may wait for the node's service: on a worker thread
                    pending[0] += 1
                    loop.run_in_executor(None, self._call, cmd.type, cmd.args, reply_soon(cmd.id, cmd.type))
        except ConnectionClosed:
            pass
        finally:
            streamer.cancel()
            self.bridge.forget(client)
            self.sessions -= 1

    def _call(self, kind: str, args: dict[str, Any], reply: Any) -> None:
        try:
            self.bridge.call(kind, args, reply)
        except Exception as exc:  # the page gets an answer whatever happens
            reply(False, f"view: {type(exc).__name__}: {exc}")

    async def _stream(self, ws: ServerConnection, send: Any, flow: "_Flow") -> None:
        version = -1
        seq = -1
        last = 0.0
        try:
            while True:
                t0 = time.monotonic()
                new_seq, state = self.bridge.snapshot()
                if state["version"] != version:
                    shapes = self.bridge.shapes()
                    version = shapes["version"]
                    await send(shapes)
                due = new_seq != seq or t0 - last >= HEARTBEAT or state["version"] != version
                if due and (flow.acked is None or flow.sent - flow.acked < WINDOW):
                    seq, last = new_seq, t0
                    state["frame"] = flow.sent + 1
                    try:
                        data = frames.encode_state(state)
                    except ValueError as exc:  # e.g. a NaN among the JSON values: this frame is skipped
                        self.bridge.get_logger().warning(f"view: state frame not sent: {exc}",
                                                         throttle_duration_sec=5.0)
                    else:
                        flow.sent += 1
                        await send(data)
                await asyncio.sleep(max(0.0, self.period - (time.monotonic() - t0)))
        except (ConnectionClosed, asyncio.CancelledError):
            pass


class _Flow:
    """State frames sent to one page (numbered from 1) and the last one it acknowledged (None: it
    has not acknowledged any, so it is not held back)."""

    def __init__(self) -> None:
        self.sent = 0
        self.acked: int | None = None


async def _safe(coro: Any) -> None:
    try:
        await coro
    except ConnectionClosed:
        pass


async def serve_forever(server: ViewServer, host: str, port: int) -> None:
    stop = asyncio.Event()
    loop = asyncio.get_running_loop()
    for sig in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(sig, stop.set)
    async with serve(server.session, host, port, process_request=server.process_request,
                     max_size=64 * 1024, compression=None) as ws_server:
        sock = next(iter(ws_server.sockets))
        shown = "127.0.0.1" if host in ("", "0.0.0.0") else host
        url = f"http://{shown}:{sock.getsockname()[1]}/"
        print(f"view: open {url}", flush=True)
        await stop.wait()


def _start_foxglove(bridge: ViewBridge, host: str, port: int, rate: float) -> Any:
    """The Foxglove WebSocket server (foxglove-sdk, imported only for --foxglove); None if it cannot
    start (the reason printed)."""
    try:
        from collide_ros.view.foxglove_bridge import FoxgloveStream
    except ImportError as exc:
        print(f"view: --foxglove needs foxglove-sdk ({exc}); run scripts/setup (requirements.txt pins it)",
              file=sys.stderr)
        return None
    try:
        fox = FoxgloveStream(bridge, host, port, rate).start()
    except Exception as exc:  # the SDK raises its own error types (e.g. the port is taken)
        print(f"view: cannot serve Foxglove WebSocket on {host}:{port}: {exc}", file=sys.stderr)
        return None
    shown = "127.0.0.1" if host in ("", "0.0.0.0") else host
    print(f"view: Foxglove WebSocket on ws://{shown}:{fox.port} (topics {', '.join(fox.topics.values())})",
          flush=True)
    return fox


def parse_args(argv: list[str]) -> tuple[argparse.Namespace, list[str]]:
    """(the view's options, the ROS arguments from --ros-args on); exits with a usage error on bad ones."""
    args = list(argv)
    ros_args = ["--ros-args", *args[args.index("--ros-args") + 1:]] if "--ros-args" in args else []
    if "--ros-args" in args:
        args = args[:args.index("--ros-args")]
    p = argparse.ArgumentParser(prog="python -m collide_ros.view", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--host", default="127.0.0.1",
                   help="address to bind (default 127.0.0.1: this machine only; 0.0.0.0 opens it to the network)")
    p.add_argument("--port", type=int, default=8080, help="HTTP and WebSocket port (0: any free port)")
    p.add_argument("--rate", type=float, default=30.0, help="frames per second sent to each page (1-120)")
    p.add_argument("--sim", default="sim", help="name of the sim node (its services are <sim>/...)")
    p.add_argument("--bodies", nargs=2, default=["block1", "block2"], metavar=("B1", "B2"),
                   help="bodies driven by S,D,F,E and J,K,L,I / arrows")
    p.add_argument("--stiffness", type=float, default=0.0, help="spring stiffness (N/m); 0: the node's default")
    p.add_argument("--foxglove", action="store_true",
                   help="also serve the scene over the Foxglove WebSocket protocol (Foxglove, Lichtblick)")
    p.add_argument("--foxglove-port", type=int, default=8765,
                   help="port of the Foxglove WebSocket server, on --host (default 8765; 0: any free port)")
    a = p.parse_args(args)
    if (not 1.0 <= a.rate <= 120.0 or not 0 <= a.port <= 65535 or not 0 <= a.foxglove_port <= 65535
            or not a.stiffness >= 0):
        p.error("--rate must be in 1..120, --port and --foxglove-port in 0..65535, --stiffness >= 0")
    return a, ros_args


def main(argv: list[str] | None = None) -> int:
    a, ros_args = parse_args(sys.argv[1:] if argv is None else argv)
    rclpy.init(args=[sys.argv[0], *ros_args])
    bridge = ViewBridge(sim=a.sim, bodies=(a.bodies[0], a.bodies[1]), stiffness=a.stiffness)
    thread, ex = spin_in_thread(bridge)
    fox = None
    try:
        if a.foxglove:
            fox = _start_foxglove(bridge, a.host, a.foxglove_port, a.rate)
            if fox is None:
                return 2
        asyncio.run(serve_forever(ViewServer(bridge, a.rate), a.host, a.port))
    except OSError as exc:
        print(f"view: cannot serve on {a.host}:{a.port}: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        pass
    finally:
        if fox is not None:
            fox.stop()
        for client in list(bridge._springs):
            bridge.release(client)
        rclpy.try_shutdown()
        thread.join(timeout=2.0)
        ex.shutdown(timeout_sec=1.0)
        bridge.destroy_node()
    return 0
