"""The unmodified ``collide_ros.node`` SimNode, with a count of every publish() per topic.

    python soak/counted_node.py COUNTS.json --ros-args ...   (same arguments as collide_ros.node)

Only the publishers are wrapped (``create_publisher`` returns the rclpy publisher with a counting
``publish``); stepping, callbacks and QoS are the node's own. On SIGUSR1 the counts so far are
written atomically to COUNTS.json as ``{"seq": k, "counts": {topic: n}}`` (k = how many snapshots),
so a soak can read the published counts at the start and at the end of a recording. This stands in
for the per-topic published counters the node does not expose (docs/hardening.md, "Soak").
"""
from __future__ import annotations

import json
import os
import signal
import sys
import threading
from pathlib import Path
from typing import Any

import rclpy
from rclpy.executors import ExternalShutdownException

from collide_ros.node import SimNode


class CountedSimNode(SimNode):
    def __init__(self, **kwargs: Any) -> None:
        self.published: dict[str, int] = {}
        self._count_lock = threading.Lock()
        super().__init__(**kwargs)

    def create_publisher(self, msg_type: Any, topic: str, *args: Any, **kwargs: Any) -> Any:
        pub = super().create_publisher(msg_type, topic, *args, **kwargs)
        name = pub.topic_name
        raw = pub.publish

        def publish(msg: Any) -> None:
            raw(msg)
            with self._count_lock:
                self.published[name] = self.published.get(name, 0) + 1
        pub.publish = publish  # type: ignore[method-assign]
        return pub

    def snapshot(self) -> dict[str, int]:
        with self._count_lock:
            return dict(self.published)


def main(argv: list[str]) -> int:
    if len(argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    out = Path(argv[1])
    rclpy.init(args=[argv[0], *argv[2:]])
    node: CountedSimNode | None = None
    seq = [0]

    def dump(signum: int, frame: Any) -> None:
        if node is None:
            return
        seq[0] += 1
        tmp = out.with_suffix(".tmp")
        tmp.write_text(json.dumps({"seq": seq[0], "counts": node.snapshot()}))
        os.replace(tmp, out)

    signal.signal(signal.SIGUSR1, dump)
    try:
        node = CountedSimNode()
        node.run()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        if rclpy.ok():
            rclpy.shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
