"""``python -m collide_ros.view`` in a child process for the tests and benches: the URLs it prints."""
from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from collide_ros.testing import _die_with_parent

GIVE_UP = 60.0  # s: guards against a hung start only


class ViewProcess:
    """``python -m collide_ros.view --port P [args]``; ``url`` is the page's URL it prints and, with
    ``--foxglove``, ``foxglove_port`` the Foxglove WebSocket server's port."""

    def __init__(self, port: int = 0, *args: str) -> None:
        self.log = tempfile.NamedTemporaryFile(prefix="view_", suffix=".log", delete=False)
        env = dict(os.environ, PYTHONUNBUFFERED="1", RCUTILS_COLORIZED_OUTPUT="0")
        self.proc = subprocess.Popen([sys.executable, "-m", "collide_ros.view", "--port", str(port), *args],
                                     stdout=self.log, stderr=subprocess.STDOUT, env=env,
                                     preexec_fn=_die_with_parent)
        end = time.monotonic() + GIVE_UP
        self.url = ""
        while not self.url:
            m = re.search(r"view: open (http://\S+)", self.output())
            if m:
                self.url = m.group(1)
                break
            assert self.proc.poll() is None, f"the view exited:\n{self.output()}"
            assert time.monotonic() < end, f"the view printed no URL:\n{self.output()}"
            time.sleep(0.05)
        self.port = int(self.url.rstrip("/").rsplit(":", 1)[1])
        m = re.search(r"view: Foxglove WebSocket on ws://(\S+):(\d+)", self.output())
        self.foxglove_port = int(m.group(2)) if m else None

    def output(self) -> str:
        self.log.flush()
        return Path(self.log.name).read_text(errors="replace")

    def stop(self) -> int:
        if self.proc.poll() is None:
            self.proc.send_signal(2)
            try:
                self.proc.wait(15)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(15)
        return int(self.proc.returncode)
