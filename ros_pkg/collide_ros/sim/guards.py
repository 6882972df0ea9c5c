"""The node's guards: the lock shared by the stepping loop and the executor thread, throttled warnings,
rejections, and the counted publishers and guarded subscriptions and services whose numbers
/diagnostics reports. Nothing a peer sends gets past a guard as an exception."""
from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from collide_ros import qos

WARN_PERIOD = 1.0  # s (wall) between two warnings with the same key


class CountedPublisher:
    """An rclpy publisher that counts its publish() calls, for the ``published/<topic>`` values of
    /diagnostics: one int increment per message, whatever the message holds."""

    __slots__ = ("pub", "count")

    def __init__(self, pub: Any) -> None:
        self.pub = pub
        self.count = 0

    def publish(self, msg: Any) -> None:
        self.pub.publish(msg)
        self.count += 1


class CommandCounts:
    """Per command topic: messages the node took (received = accepted + rejected) and the ones DDS
    dropped before the node took them (lost: gaps in the publisher's sequence numbers)."""

    __slots__ = ("received", "accepted", "rejected", "lost", "topic", "writer", "last_seq")

    def __init__(self) -> None:
        self.received = self.accepted = self.rejected = self.lost = 0
        self.topic = ""            # resolved topic name (for the graph query on a gap)
        self.writer: tuple[int, ...] | None = None  # gid of the only publisher when last_seq was seen
        self.last_seq = -1         # its publication sequence number of the last message taken

    def restart(self, topic: str) -> None:
        """A new subscription: sequence numbers start over."""
        self.topic, self.writer, self.last_seq = topic, None, -1


def finite(*vals: float) -> bool:
    return all(math.isfinite(v) for v in vals)


class Guards:
    """Owns the lock (``_lock``), the warning throttle, ``rejected`` / ``last_rejection``, and the
    counted endpoints (``_published``: diagnostics key -> publisher, ``_commands``: topic -> counts)."""

    def _init_guards(self) -> None:
        self._lock = threading.RLock()  # world and command state: stepping thread vs executor thread
        self._lock_waiters = 0  # executor threads waiting for self._lock (see _executor_lock)
        self._waiters_lock = threading.Lock()
        self._warned: dict[str, float] = {}
        self.rejected = 0
        self.last_rejection = ""
        self._published: dict[str, CountedPublisher] = {}  # diagnostics key (topic without '/') -> publisher
        self._commands: dict[str, CommandCounts] = {}      # command topic (relative) -> counts

    def _publisher(self, msg_type: Any, topic: str, profile: Any) -> CountedPublisher:
        """A counted publisher; its count is ``published/<topic without a leading '/'>`` in /diagnostics."""
        pub = CountedPublisher(self.create_publisher(msg_type, topic, profile))
        self._published[topic.lstrip("/")] = pub
        return pub

    def _unpublish(self, topic: str, pub: CountedPublisher) -> None:
        self._published.pop(topic.lstrip("/"), None)
        self.destroy_publisher(pub.pub)

    def _subscribe(self, msg_type: Any, topic: str, kind: str, fn: Callable[[Any], None], **kwargs: Any) -> Any:
        """A command subscription whose messages are counted (``received/<topic>`` ...) and guarded."""
        counts = self._commands.setdefault(topic, CommandCounts())
        sub = self.create_subscription(msg_type, topic, self._guard(kind, counts, fn), qos.COMMAND, **kwargs)
        counts.restart(sub.topic_name)
        return sub

    def _warn(self, key: str, msg: str) -> None:
        now = time.monotonic()
        if now - self._warned.get(key, -1e9) >= WARN_PERIOD:
            self._warned[key] = now
            self.get_logger().warning(msg)

    def _reject(self, key: str, msg: str) -> None:
        """A command was refused: count it, remember why, warn (throttled per key)."""
        self.rejected += 1
        self.last_rejection = msg
        self._warn(key, f"rejected: {msg}")

    @contextmanager
    def _executor_lock(self) -> Iterator[None]:
        """self._lock for a callback. Python's lock is not fair: a stepping loop that releases and
        retakes it at once can keep a waiting thread out for seconds (at real_time_factor 0 the
        command queues overflowed). So a callback says it is waiting, and the loop then yields."""
        with self._waiters_lock:
            self._lock_waiters += 1
        try:
            self._lock.acquire()
        finally:
            with self._waiters_lock:
                self._lock_waiters -= 1
        try:
            yield
        finally:
            self._lock.release()

    def _guard(self, kind: str, counts: CommandCounts, fn: Callable[[Any], None]) -> Callable[[Any, Any], None]:
        """The subscription callback: count the message, run ``fn`` under the lock; an exception
        is a rejection. Accepted = not rejected (every handler either rejects or echoes)."""
        def wrapped(msg: Any, info: Any) -> None:
            try:
                self._note_sequence(counts, info.get("publication_sequence_number"))
            except Exception as exc:  # the graph query; the command itself is still handled
                self._warn(f"{kind}:sequence", f"{kind}: cannot check the sequence number: {exc}")
            with self._executor_lock():
                counts.received += 1
                before = self.rejected
                try:
                    fn(msg)
                except Exception as exc:  # nothing a peer sends may stop the simulation
                    self._reject(f"{kind}:exception", f"{kind} command failed: {type(exc).__name__}: {exc}")
                if self.rejected != before:
                    counts.rejected += 1
                else:
                    counts.accepted += 1
        return wrapped

    def _note_sequence(self, counts: CommandCounts, seq: Any) -> None:
        """Count the messages DDS dropped before the node took them (a full depth-10 queue, or the
        publisher's own history overwritten before delivery): a gap in the publisher's sequence
        numbers. The rmw does not say which publisher sent a message, so a gap is only counted when
        the topic has a single publisher, the same one as for the previous message (a graph query,
        only on a gap: a new publisher starts its own numbering)."""
        if not isinstance(seq, int) or seq <= 0:
            return  # an rmw without publication sequence numbers
        if seq == counts.last_seq + 1:
            counts.last_seq = seq
            return
        infos = self.get_publishers_info_by_topic(counts.topic)
        writer = tuple(infos[0].endpoint_gid) if len(infos) == 1 else None
        if writer is not None and writer == counts.writer and seq > counts.last_seq + 1:
            counts.lost += seq - counts.last_seq - 1
        counts.writer, counts.last_seq = writer, seq

    def _guard_srv(self, kind: str, fn: Callable[[Any, Any], Any]) -> Callable[[Any, Any], Any]:
        def wrapped(req: Any, resp: Any) -> Any:
            try:
                with self._executor_lock():
                    return fn(req, resp)
            except Exception as exc:
                msg = f"{kind} failed: {type(exc).__name__}: {exc}"
                self._warn(f"srv:{kind}", msg)
                if hasattr(resp, "success"):
                    resp.success = False
                    resp.message = msg
                return resp
        return wrapped
