"""The live view (python -m collide_ros.view) in a real browser: Debian's Chromium driven by
playwright, against a running sim node, over ROS in this test process's own ROS_DOMAIN_ID.

Nothing here is skipped: without /usr/bin/chromium or playwright the tests fail and say to run
scripts/setup. Every wait is on a condition with a generous limit (a loaded 2-core machine).
"""
from __future__ import annotations

import io
import json
import math
import os
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
import rclpy
from libcollide_msgs.msg import SpringCommand, ThrusterCommand
from std_srvs.srv import Empty

from collide_ros.testing import NodeProcess, SimClient
from view_process import ViewProcess

CHROMIUM = "/usr/bin/chromium"
GIVE_UP = 60.0  # s: guards against a hung test only; never a pass/fail criterion


def _need_browser() -> Any:
    if not os.access(CHROMIUM, os.X_OK):
        pytest.fail(f"{CHROMIUM} is missing: the live view tests drive Debian's Chromium. "
                    "Run scripts/setup (as root it runs `apt-get install -y chromium`).", pytrace=False)
    try:
        from playwright.sync_api import sync_playwright
    except ImportError as exc:
        pytest.fail(f"playwright is not installed ({exc}); run scripts/setup (requirements.txt pins it)",
                    pytrace=False)
    return sync_playwright


@dataclass
class Stack:
    client: SimClient
    node: NodeProcess
    view: ViewProcess
    page: Any

    def until(self, cond: Callable[[], Any], what: str, timeout: float = GIVE_UP) -> Any:
        """Spin the ROS client and poll ``cond`` until it is true (its value is returned)."""
        end = time.monotonic() + timeout
        while True:
            got = cond()
            if got:
                return got
            assert self.view.proc.poll() is None, f"the view exited while waiting for {what}:\n{self.view.output()}"
            assert time.monotonic() < end, (f"gave up waiting for {what}; the page: {self.page_summary()}; "
                                            f"view log:\n{self.view.output()[-3000:]}")
            self.client.ex.spin_once(timeout_sec=0.03)

    def page_summary(self) -> str:
        try:
            return str(self.js("""(() => { const V = window.__view; return JSON.stringify({connected: V.connected,
              node: V.node, t: V.t, sent: V.sent, grab: V.grab, refusals: V.refusals.slice(-5), replies:
              V.replies.slice(-3), message: V.lastMessage, shapes: V.shapes.map((b) => [b.id, b.name, b.static]),
              held: V.held}); })()"""))
        except Exception as exc:  # the page itself is the problem
            return f"(no page state: {exc})"

    def js(self, expr: str) -> Any:
        return self.page.evaluate(expr)

    def page_body(self, name: str) -> dict[str, Any] | None:
        return self.js(f"(window.__view && window.__view.bodies[{json.dumps(name)}]) || null")

    def page_shows(self, want: dict[str, tuple[float, float]]) -> bool:
        """Whether the page holds every named body at its (x, y), to 1e-9 m (the JSON carries doubles)."""
        for n, (x, y) in want.items():
            b = self.page_body(n)
            if b is None or abs(b["x"] - x) > 1e-9 or abs(b["y"] - y) > 1e-9:
                return False
        return True

    def screen(self, x: float, y: float) -> tuple[float, float]:
        sx, sy = self.js(f"window.__view.toScreen({x!r}, {y!r})")
        return float(sx), float(sy)

    def reset(self) -> None:
        """~/reset; then wait until the client and the page both show the new run: the default scene
        starts at rest (every velocity exactly 0, so the poses stay put) and the page shows those poses
        and has counted the reset's DELETEALL (the poses alone may already match the run before)."""
        resets = self.js("window.__view.resets || 0")
        assert self.client.call(Empty, "reset") is not None, "sim/reset did not answer"
        got: dict[str, Any] = {}

        def at_rest() -> bool:
            msg = self.client.fresh("bodies/states", timeout=5.0)
            if msg is None or not all(t.linear.x == 0.0 and t.linear.y == 0.0 and t.angular.z == 0.0
                                      for t in msg.twists):
                return False
            got.update({n: (p.position.x, p.position.y) for n, p in zip(msg.names, msg.poses)})
            return True
        self.until(at_rest, "bodies/states of the reset scene")

        self.until(lambda: self.page_shows(got), "the page to show the reset scene")
        self.until(lambda: self.js("window.__view.resets || 0") > resets, "the page to count the reset")

    def state(self, name: str) -> tuple[float, ...]:
        s = self.client.body_state(name)
        assert s is not None, f"no bodies/states with {name}"
        return s


@pytest.fixture(scope="module")
def stack() -> Iterator[Stack]:
    sync_playwright = _need_browser()
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    st = Stack(SimClient(context=ctx), NodeProcess("-p", "command_timeout:=0.5"), None, None)  # type: ignore[arg-type]
    st.client._sub("spring", SpringCommand, "spring")
    st.client._sub("thrusters", ThrusterCommand, "thrusters")
    pw = browser = None
    try:
        assert st.client.wait_for(lambda: st.client.count["bodies/states"] > 0, timeout=GIVE_UP), \
            f"the node published no bodies/states:\n{st.node.output()}"
        st.view = ViewProcess()
        pw = sync_playwright().start()
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"], headless=True)
        st.page = browser.new_page(viewport={"width": 1100, "height": 800})
        st.page.goto(st.view.url)
        st.until(lambda: st.js("!!(window.__view && window.__view.node && window.__view.bodies.block1 "
                               "&& window.__view.bodies.block2)"), "the page to show block1 and block2")
        yield st
        assert st.view.stop() == 0, f"the view did not exit cleanly:\n{st.view.output()}"
    finally:
        if browser is not None:
            browser.close()
        if pw is not None:
            pw.stop()
        if st.view is not None:
            st.view.stop()
        st.client.close()
        code = st.node.stop()
        rclpy.shutdown(context=ctx)
    assert code == 0, f"the node exited with {code}:\n{st.node.output()}"


def test_page_draws_bodies_where_poses_put_them(stack: Stack, tmp_path: Path) -> None:
    from PIL import Image
    stack.reset()
    names = list(stack.client.fresh("bodies/states", timeout=GIVE_UP).names)
    poses = stack.client.fresh("bodies/poses", timeout=GIVE_UP)
    assert poses is not None and len(poses.poses) == len(names) >= 2
    # gravity 0 and no command: the default scene rests, so every pose stays where it is
    want = {n: (p.position.x, p.position.y) for n, p in zip(names, poses.poses)}

    stack.until(lambda: stack.page_shows(want), "the page's bodies at the poses of bodies/poses")
    walls = [b for b in stack.js("Object.values(window.__view.bodies)") if b["static"]]
    assert len(walls) == 4, walls  # the default scene's box
    png = stack.page.screenshot()
    (tmp_path / "live_view.png").write_bytes(png)
    img = Image.open(io.BytesIO(png)).convert("RGB")
    for n in ("block1", "block2"):
        sx, sy = stack.screen(*want[n])
        px = img.getpixel((int(round(sx)), int(round(sy))))
        color = stack.page_body(n)["color"]  # the node's marker colour of the body
        rgb = tuple(int(color[i:i + 2], 16) for i in (1, 3, 5))
        assert all(abs(a - b) <= 12 for a, b in zip(px, rgb)), f"pixel at {n}'s centre ({sx:.0f}, {sy:.0f}) is {px}, not {color}"
        green = px[1] > px[0] + 60 and px[1] > px[2] + 60
        assert green == (n == "block1"), f"{n} drawn in {px}: the green block (only) is green"


def test_drag_pulls_body_toward_pointer(stack: Stack) -> None:
    stack.reset()
    x0, y0 = stack.state("block1")[:2]
    before = stack.client.count["spring"]
    m = stack.page.mouse
    m.move(*stack.screen(x0, y0))
    m.down()
    tx, ty = x0, y0 + 3.0
    m.move(*stack.screen(tx, ty), steps=5)
    wiggles = [0]

    def received() -> bool:
        # as a hand does, the pointer keeps moving a little (1 cm): the page sends a spring per move,
        # so messages sent before DDS matched the view's publisher with this client do not matter
        wiggles[0] += 1
        m.move(*stack.screen(tx + 0.01 * (wiggles[0] % 2), ty))
        return stack.client.count["spring"] > before
    try:
        stack.until(received, "spring messages from the page")
        # the press grabs block1 at its centre; the moves follow the pointer to (tx, ty)
        first = stack.client.since("spring", before)[0]
        assert first.body == "block1" and not first.release and first.name.startswith("view")
        assert abs(first.body_point.x) < 0.05 and abs(first.body_point.y) < 0.05
        stack.until(lambda: abs(stack.client.last["spring"].target.y - ty) < 0.05
                    and abs(stack.client.last["spring"].target.x - tx) < 0.05, "a spring target at the pointer")
        # the spring pulls block1 up toward the pointer
        stack.until(lambda: stack.state("block1")[1] > y0 + 0.3, "block1 to move toward the pointer")
        x1 = stack.state("block1")[0]
        assert abs(x1 - x0) < 0.2
    finally:
        m.up()
    stack.until(lambda: stack.client.last["spring"].release, "the spring released on mouse-up")


def test_holding_keys_fires_thrusters(stack: Stack) -> None:
    stack.reset()
    stack.js("document.activeElement && document.activeElement.blur()")
    kb = stack.page.keyboard
    for key, body in (("s", "block1"), ("j", "block2")):
        v0 = stack.state(body)[3]
        n0 = stack.client.count["thrusters"]
        kb.down(key)
        try:
            # S and J fire the left thruster (index 0) of their block: it gains velocity along -x
            stack.until(lambda: stack.state(body)[3] < v0 - 0.05, f"{key} to push {body}")

            def since() -> list[tuple[str, list[bool]]]:
                return [(m.body, list(m.firing)) for m in stack.client.since("thrusters", n0)]
            stack.until(since, f"the view's ThrusterCommand for {body}")
            assert all(s == (body, [True, False, False, False]) for s in since()), since()
        finally:
            kb.up(key)
        stack.until(lambda: stack.client.last["thrusters"].body == body
                    and not any(stack.client.last["thrusters"].firing), f"{body}'s thrusters off on keyup")


def test_gravity_from_the_page_and_refusal(stack: Stack) -> None:
    page = stack.page
    page.fill("#p-gravity", "2.5")
    page.click("#set-gravity")
    stack.until(lambda: (stack.client.get_params(["gravity"]) or {}).get("gravity") == 2.5,
                "the node's gravity parameter to become 2.5")
    stack.until(lambda: "2.5" in page.inner_text("#cur-gravity"), "the page to show gravity 2.5")
    page.fill("#p-gravity", "500")
    page.click("#set-gravity")
    stack.until(lambda: "out of range" in page.inner_text("#message"), "the node's refusal on the page")
    text = page.inner_text("#message")
    assert "refused" in text and "gravity" in text, text
    assert stack.client.get_params(["gravity"]) == {"gravity": 2.5}
    assert stack.client.set_params({"gravity": 0.0})[0].successful


def test_pause_step_run_reset_buttons(stack: Stack) -> None:
    page = stack.page

    def click(button: str, request: str) -> dict[str, Any]:
        n = stack.js("window.__view.replies.length")
        page.click(button)
        stack.until(lambda: stack.js("window.__view.replies.length") > n, f"the reply to {request}")
        r = stack.js("window.__view.replies[window.__view.replies.length - 1]")
        assert r["request"] == request and r["ok"], r
        return r

    click("#pause", "pause")
    stack.until(lambda: (stack.js("window.__view.health") or {}).get("paused"), "the node's diagnostics: paused")
    t1 = stack.js("window.__view.t")
    stack.client.spin(0.3)
    assert stack.js("window.__view.t") == t1  # paused: no sim time passes
    click("#step", "step")  # 10 steps of 1 ms; the node publishes states every 10 steps
    stack.until(lambda: stack.js("window.__view.t") > t1, "the page's sim time after 10 steps")
    assert stack.js("window.__view.t") - t1 <= 0.02 + 1e-9
    click("#resume", "pause")
    t2 = stack.js("window.__view.t")
    stack.until(lambda: stack.js("window.__view.t") > t2 + 0.2, "sim time to run again")
    resets = stack.js("window.__view.resets")
    click("#reset", "reset")
    stack.until(lambda: stack.js("window.__view.resets") > resets, "the page to count the reset")


def test_resets_from_another_node_each_reach_the_page(stack: Stack) -> None:
    # each reset's markers message (DELETEALL first, then the new scene) reaches the view: the page
    # counts every reset asked for over ROS once, none lost, none twice
    stack.reset()
    r0 = stack.js("window.__view.resets")
    for _ in range(3):
        assert stack.client.call(Empty, "reset") is not None, "sim/reset did not answer"
        stack.client.spin(0.3)
    stack.until(lambda: stack.js("window.__view.resets") >= r0 + 3, "the page to count three resets")
    stack.client.spin(0.5)
    assert stack.js("window.__view.resets") == r0 + 3


def test_spawned_body_appears_and_killed_body_goes(stack: Stack) -> None:
    from libcollide_msgs.srv import Kill, Spawn
    stack.reset()
    req = Spawn.Request(name="crate", width=1.0, height=1.0, mass=2.0, elasticity=1.0)
    req.pose.position.x, req.pose.position.y = 0.0, -4.0
    r = stack.client.call(Spawn, "spawn", req)
    assert r is not None and r.success, r
    stack.until(lambda: (stack.page_body("crate") or {}).get("dynamic"), "the spawned crate on the page")
    b = stack.page_body("crate")
    assert abs(b["x"]) < 1e-9 and abs(b["y"] + 4.0) < 1e-9 and not b["static"]
    assert stack.js("window.__view.shapes.length") == 7  # 4 walls, 2 blocks, the crate
    k = stack.client.call(Kill, "kill", Kill.Request(name="crate"))
    assert k is not None and k.success, k
    stack.until(lambda: stack.page_body("crate") is None and stack.js("window.__view.shapes.length") == 6,
                "the killed crate to go from the page")


def test_energy_bars(stack: Stack) -> None:
    page = stack.page
    assert not page.is_visible("#energy")
    page.check("#show-energy")
    assert page.is_visible("#energy")
    e = stack.until(lambda: stack.js("window.__view.energy"), "energy on the page")
    for key in ("potential", "rotational", "translational", "total", "start"):
        assert key in e and math.isfinite(e[key]), e
    # the bars are drawn (on the next animation frame): some pixels of the energy canvas are not blank
    drawn = """(() => { const c = document.getElementById('energy');
      const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
      let n = 0; for (let i = 3; i < d.length; i += 4) if (d[i] > 0) n++; return n; })()"""
    stack.until(lambda: stack.js(drawn) > 100, "the energy bars drawn")
    page.uncheck("#show-energy")


def test_bad_websocket_input_is_refused(stack: Stack) -> None:
    # a second page's socket sends junk; each is refused with a reason and the view keeps streaming
    out = stack.page.evaluate("""async () => {
      const ws = new WebSocket(location.origin.replace('http', 'ws') + '/ws');
      const got = [];
      let frames = 0;
      ws.onmessage = (e) => {  // text: JSON replies and refusals; binary: state frames (never acknowledged here)
        if (typeof e.data !== 'string') { frames++; return; }
        const m = JSON.parse(e.data); if (m.type === 'refused') got.push(m.reason); };
      await new Promise((ok) => { ws.onopen = ok; });
      for (const s of ['{', '[1,2]', '{"type":"spring","body":"block1","point":[0,0],"target":[NaN,0]}',
                       '{"type":"spring","body":"block1","point":[0,0],"target":[1e300,0]}',
                       '{"type":"spring","body":"nosuchbody","point":[0,0],"target":[0,0]}',
                       '{"type":"keys","held":["q"]}', '{"type":"launch"}']) ws.send(s);
      for (let i = 0; i < 3000; i++) ws.send('{"type":"release"}');
      const end = Date.now() + 30000;
      while (Date.now() < end && !got.some((r) => r.startsWith('flood'))) await new Promise((ok) => setTimeout(ok, 50));
      // a client that never acknowledges a state frame still gets them (the window holds back pages that ack)
      while (Date.now() < end && frames < 5) await new Promise((ok) => setTimeout(ok, 50));
      ws.close();
      got.push('state frames: ' + frames);
      return got;
    }""")
    joined = "\n".join(out)
    assert int(out[-1].split(": ")[1]) >= 5, out[-1]
    for reason in ("malformed JSON", "must be a JSON object", "NaN", "out of range", "unknown body 'nosuchbody'",
                   "not a thruster key", "unknown message type", "flood"):
        assert reason in joined, f"no refusal with {reason!r} in:\n{joined}"
    frames = stack.js("window.__view.frames")
    stack.until(lambda: stack.js("window.__view.frames") > frames + 5, "the page's stream to go on")
    assert stack.node.alive()


def test_binds_loopback_and_refuses_other_origins(stack: Stack) -> None:
    import asyncio
    import concurrent.futures

    from websockets.asyncio.client import connect
    from websockets.exceptions import InvalidStatus
    assert stack.view.url.startswith("http://127.0.0.1:")
    listening = Path("/proc/net/tcp").read_text().splitlines()[1:]
    local = {ln.split()[1] for ln in listening if ln.split()[3] == "0A"}  # state LISTEN
    assert f"0100007F:{stack.view.port:04X}" in local  # 127.0.0.1, not 0.0.0.0

    async def other_site() -> int:
        try:
            async with connect(f"ws://127.0.0.1:{stack.view.port}/ws", origin="http://example.com"):
                return 101
        except InvalidStatus as exc:
            return exc.response.status_code
    # playwright's sync API runs an event loop in this thread: the client gets a thread of its own
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        assert pool.submit(asyncio.run, other_site()).result(timeout=GIVE_UP) == 403


def test_page_reconnects_after_node_and_view_restart(stack: Stack) -> None:
    stack.node.stop()
    stack.until(lambda: stack.js("window.__view.node") is False, "the page to see the node gone")
    stack.node = NodeProcess("-p", "command_timeout:=0.5")
    stack.until(lambda: stack.js("window.__view.node && window.__view.t !== null && !!window.__view.bodies.block1"),
                "the page to show the restarted node")
    # the view itself restarts on the same port: the page's WebSocket comes back by itself
    connects = stack.js("window.__view.connects")
    port = stack.view.port
    assert stack.view.stop() == 0, stack.view.output()
    stack.until(lambda: stack.js("window.__view.connected") is False, "the page to see the view gone")
    stack.view = ViewProcess(port)
    stack.until(lambda: stack.js("window.__view.connects") > connects and stack.js("window.__view.node"),
                "the page to reconnect to the restarted view")
    t = stack.js("window.__view.t")
    stack.until(lambda: (stack.js("window.__view.t") or 0) > t, "sim time to advance on the page")
    assert math.isfinite(stack.js("window.__view.bodies.block1.x"))
