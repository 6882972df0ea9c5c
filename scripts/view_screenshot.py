"""docs/live_view.png, the picture of the live view in README.md and docs/live_view.md.

    source scripts/env.sh && python scripts/view_screenshot.py [--out docs/live_view.png]

Starts a sim node (4 blocks, gravity 3 m/s²), a view on a free port and Debian's Chromium (headless,
through playwright) on the page, ticks "show energy", lets the blocks fall for a moment, then drags
block1 up and to the right with the mouse spring while holding J (block2's left thruster) and takes
the screenshot while both act. Uses ROS_DOMAIN_ID from the environment, or locks a free one.
"""
from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = "/usr/bin/chromium"
VIEWPORT = {"width": 1080, "height": 760}   # the page's canvas and side panel, nothing more
GIVE_UP = 60.0   # s: ends a hung start only
FALL = 0.5       # s of wall time before the drag: the blocks start to fall
PULL = 0.6       # s of wall time the spring pulls and J fires before the picture


def start_view(log: Path) -> tuple[subprocess.Popen[bytes], str]:
    """python -m collide_ros.view on a free port; the process and the URL it prints."""
    proc = subprocess.Popen([sys.executable, "-m", "collide_ros.view", "--port", "0"],
                            stdout=log.open("wb"), stderr=subprocess.STDOUT,
                            env=dict(os.environ, PYTHONUNBUFFERED="1"))
    end = time.monotonic() + GIVE_UP
    while True:
        m = re.search(r"view: open (http://\S+)", log.read_text(errors="replace"))
        if m:
            return proc, m.group(1)
        if proc.poll() is not None or time.monotonic() > end:
            raise RuntimeError(f"the view printed no URL:\n{log.read_text(errors='replace')}")
        time.sleep(0.05)


def stop(proc: subprocess.Popen[bytes]) -> None:
    if proc.poll() is None:
        proc.send_signal(2)
        try:
            proc.wait(15)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(15)


def shoot(out: Path) -> None:
    from playwright.sync_api import sync_playwright

    from collide_ros.testing import NodeProcess

    node = NodeProcess("-p", "blocks:=4", "-p", "gravity:=3.0")
    view = pw = browser = None
    with tempfile.TemporaryDirectory() as tmp:
        try:
            view, url = start_view(Path(tmp) / "view.log")
            pw = sync_playwright().start()
            browser = pw.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"], headless=True)
            page = browser.new_page(viewport=VIEWPORT)
            page.goto(url)
            page.wait_for_function("window.__view && window.__view.node && window.__view.bodies.block1 "
                                   "&& window.__view.bodies.block4", timeout=GIVE_UP * 1000)
            page.check("#show-energy")
            page.wait_for_timeout(FALL * 1000)
            b = page.evaluate("window.__view.bodies.block1")
            x, y = b["x"], b["y"]
            sx, sy = page.evaluate(f"window.__view.toScreen({x!r}, {y!r})")
            tx, ty = page.evaluate(f"window.__view.toScreen({x + 0.8!r}, {y + 2.0!r})")
            page.evaluate("document.activeElement && document.activeElement.blur()")
            page.mouse.move(sx, sy)
            page.mouse.down()
            page.keyboard.down("j")
            try:
                page.mouse.move(tx, ty, steps=8)
                end = time.monotonic() + PULL
                k = 0
                while time.monotonic() < end:   # as a hand does, the pointer keeps moving a little
                    k += 1
                    page.mouse.move(tx + k % 2, ty)
                    page.wait_for_timeout(50)
                out.write_bytes(page.screenshot())
            finally:
                page.keyboard.up("j")
                page.mouse.up()
        finally:
            if browser is not None:
                browser.close()
            if pw is not None:
                pw.stop()
            if view is not None:
                stop(view)
            node.stop()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "live_view.png", help="PNG to write")
    args = ap.parse_args()
    if not os.access(CHROMIUM, os.X_OK):
        print(f"view_screenshot: {CHROMIUM} is missing; run scripts/setup", file=sys.stderr)
        return 1
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    from collide_ros import ros_domain
    lock = ros_domain.lock_unless_set()
    try:
        shoot(args.out)
    finally:
        if lock is not None:
            lock.release()
    print(f"view_screenshot: wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
