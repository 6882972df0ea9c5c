"""Record the sim node's topics to a rosbag2 directory (MCAP storage, metadata version 9).

    python -m collide_ros.recorder --out DIR [--topics T ...] [--duration S] [--ros-args ...]

Subscribes with raw=True (CDR bytes are written as received, never re-serialized) and
stores each message at its receive time (what Jazzy's `ros2 bag record` stores). QoS is
adapted to the publishers seen in the graph, as rosbag2 does: reliable only if every
publisher is reliable, transient_local only if every publisher is. Message definitions and
RIHS01 type hashes come from the installed interface packages (libcollide_msgs and our
rebuilt tf2_msgs) and from rosbags' Jazzy typestore for the standard messages; the hash of
our own types is checked against the hash rosidl generated. A node's ``~/snapshot``
(libcollide_msgs/WorldSnapshot, the state a replay starts from) is always recorded, --topics or
not: once the recorder's readers of what a replay needs from that node have matched, it asks the
node for a fresh snapshot (StateRequest) and prints ``recorder: state saved on <topic>`` when one is
in the bag that shows the node's writers had matched them too. It prints ``recorder: recording``
when every subscription has matched its publishers and every such state is saved: from then on,
every message the publishers send is delivered to it (a recorder slower than them loses the oldest
of its queue). --duration counts from that line. Stops on
--duration, SIGINT or SIGTERM, then prints the message count per topic. The bag's metadata
(metadata.yaml and the MCAP file's own copy) says ``ros_distro: jazzy``.
"""
from __future__ import annotations

import argparse
import importlib
import json
import os
import re
import signal
import sys
import time
from pathlib import Path
from typing import Any, Iterable

#: topics recorded when --topics is not given and nothing else is discovered; more are
#: picked up from the graph as they appear (all topics except the excluded ones)
EXCLUDED = frozenset({"/rosout", "/parameter_events"})
OWN_PACKAGES = ("libcollide_msgs", "tf2_msgs")
COMMAND_TOPICS = ("thrusters", "spring", "cmd_vel")  # plus every "<body>/thrust"
#: always recorded, --topics or not: the sim's state a replay starts from. On subscribing, the recorder
#: calls the node's save service (the topic's sibling), so the bag holds the state at its start.
SNAPSHOT_TYPE = "libcollide_msgs/msg/WorldSnapshot"
SAVE_SERVICE = "save_snapshot"
#: the bag's ros_distro (metadata.yaml and the MCAP file's rosbag2 metadata record): the ROS 2
#: release whose bag format, message definitions and type hashes the bag has. rosbags writes
#: "rosbags" there and has no option for it, so the recorder rewrites it (_set_ros_distro).
ROS_DISTRO = "jazzy"
_ROS_DISTRO_LINE = re.compile(r"^(\s*ros_distro:[ \t]*)\S.*$", re.MULTILINE)


# ------------------------------------------------------------------ types / typestore

def _share_dirs(pkg: str) -> list[Path]:
    """Candidate share/<pkg> directories of an installed interface package."""
    cands: list[Path] = []
    for pre in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep):
        if pre:
            cands.append(Path(pre) / "share" / pkg)
    cands.append(Path(sys.prefix) / "share" / pkg)
    try:
        mod = importlib.import_module(pkg)
        # <prefix>/lib/python3.11/site-packages/<pkg>/__init__.py -> <prefix>/share/<pkg>
        p = Path(mod.__file__ or "").resolve().parent
        for up in p.parents:
            cands.append(up / "share" / pkg)
            if up.name == "lib":
                break
    except ImportError:
        pass
    repo = Path(__file__).resolve().parents[2] / "msg" / pkg  # source tree fallback
    cands.append(repo)
    return [c for c in dict.fromkeys(cands) if (c / "msg").is_dir()]


def installed_type_hash(msgtype: str) -> str | None:
    """RIHS01 hash rosidl generated for `pkg/msg/Name` (from share/pkg/msg/Name.json)."""
    pkg, _, name = msgtype.split("/")
    for d in _share_dirs(pkg):
        f = d / "msg" / f"{name}.json"
        if f.is_file():
            data = json.loads(f.read_text())
            for entry in data.get("type_hashes", []):
                if entry.get("type_name") == msgtype:
                    return str(entry["hash_string"])
    return None


def make_typestore() -> Any:
    """rosbags Jazzy typestore plus our interface packages' message definitions."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    add: dict[str, Any] = {}
    for pkg in OWN_PACKAGES:
        dirs = _share_dirs(pkg)
        if not dirs:
            continue
        for f in sorted((dirs[0] / "msg").glob("*.msg")):
            name = f"{pkg}/msg/{f.stem}"
            if pkg == "tf2_msgs" and name in store.fielddefs:
                continue  # identical definition already in the Jazzy store
            add.update(get_types_from_msg(f.read_text(), name))
    store.register(add)
    return store


def msgdef_and_hash(store: Any, msgtype: str) -> tuple[str, str]:
    """(concatenated ros2msg definition, RIHS01 hash) for a bag connection."""
    msgdef, _ = store.generate_msgdef(msgtype, ros_version=2)
    computed = store.hash_rihs01(msgtype)
    installed = installed_type_hash(msgtype)
    if installed is not None and installed != computed:
        raise RuntimeError(f"type hash mismatch for {msgtype}: installed {installed}, "
                           f"from definition {computed}")
    return msgdef, computed


def msg_class(msgtype: str) -> Any:
    pkg, sub, name = msgtype.split("/")
    return getattr(importlib.import_module(f"{pkg}.{sub}"), name)


def bag_qos(profile: Any) -> Any:
    """rclpy QoSProfile -> rosbags Qos (for offered_qos_profiles)."""
    from rosbags.interfaces import (Qos, QosDurability, QosHistory, QosLiveliness,
                                    QosReliability, QosTime)

    def t(d: Any) -> QosTime:
        ns = int(d.nanoseconds)
        return QosTime(sec=ns // 1_000_000_000, nsec=ns % 1_000_000_000)

    def enum(cls: Any, v: Any) -> Any:
        try:
            return cls[v.name]
        except KeyError:
            return cls.UNKNOWN

    return Qos(history=enum(QosHistory, profile.history), depth=int(profile.depth),
               reliability=enum(QosReliability, profile.reliability),
               durability=enum(QosDurability, profile.durability),
               deadline=t(profile.deadline), lifespan=t(profile.lifespan),
               liveliness=enum(QosLiveliness, profile.liveliness),
               liveliness_lease_duration=t(profile.liveliness_lease_duration),
               avoid_ros_namespace_conventions=bool(profile.avoid_ros_namespace_conventions))


# ------------------------------------------------------------------ recorder

class Recorder:
    """Subscribes raw to topics as their publishers appear and writes them to an MCAP bag."""

    def __init__(self, node: Any, out: str | Path, topics: Iterable[str] | None = None) -> None:
        from rosbags.rosbag2 import StoragePlugin, Writer

        self.node = node
        self.store = make_typestore()
        self.wanted = None if topics is None else {self._resolve(t) for t in topics}
        self.writer = Writer(Path(out), version=9, storage_plugin=StoragePlugin.MCAP)
        self.writer.open()
        self.subs: dict[str, Any] = {}
        self.conns: dict[str, Any] = {}
        self.counts: dict[str, int] = {}
        self.expected: dict[str, int] = {}  # topic -> publishers seen when it was subscribed
        self._snapshot_requests: dict[str, StateRequest] = {}
        self.saved: list[str] = []  # snapshot topics whose state at the recording's start is in the bag
        self.closed = False
        self._timer = node.create_timer(0.2, self.discover)
        self.discover()

    def _resolve(self, topic: str) -> str:
        from rclpy.expand_topic_name import expand_topic_name
        return expand_topic_name(topic, self.node.get_name(), self.node.get_namespace())

    def discover(self) -> None:
        """Subscribe to every wanted topic that now has a publisher."""
        if self.closed:
            return
        for name, types in self.node.get_topic_names_and_types():
            if name in self.subs or not types:
                continue
            if self.wanted is None:
                if name in EXCLUDED:
                    continue
            elif name not in self.wanted and types[0] != SNAPSHOT_TYPE:
                continue
            pubs = [p for p in self.node.get_publishers_info_by_topic(name)
                    if p.node_name != self.node.get_name()
                    or p.node_namespace != self.node.get_namespace()]
            if not pubs:
                continue
            self._subscribe(name, types[0], pubs)

    def _subscribe(self, topic: str, msgtype: str, pubs: list[Any]) -> None:
        from rclpy.qos import (DurabilityPolicy, HistoryPolicy, QoSProfile,
                               ReliabilityPolicy)

        try:
            cls = msg_class(msgtype)
            msgdef, rihs = msgdef_and_hash(self.store, msgtype)
        except Exception as exc:  # unknown type: skip the topic, say why once
            self.node.get_logger().warning(f"not recording {topic} [{msgtype}]: {exc}")
            self.subs[topic] = None
            return
        reliable = all(p.qos_profile.reliability == ReliabilityPolicy.RELIABLE for p in pubs)
        latched = all(p.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL for p in pubs)
        qos = QoSProfile(
            history=HistoryPolicy.KEEP_LAST, depth=1000,
            reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
            durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE)
        conn = self.writer.add_connection(
            topic, msgtype, msgdef=msgdef, rihs01=rihs,
            offered_qos_profiles=[bag_qos(p.qos_profile) for p in pubs])
        self.conns[topic] = conn
        self.counts[topic] = 0
        self.expected[topic] = len(pubs)

        def cb(data: bytes, info: Any, topic: str = topic, conn: Any = conn) -> None:
            if self.closed:
                return
            ts = info["received_timestamp"] if isinstance(info, dict) else time.time_ns()
            self.writer.write(conn, int(ts), data)
            self.counts[topic] += 1
            if topic in self._snapshot_requests and self._snapshot_requests[topic].on_message(data):
                self.saved.append(topic)

        self.subs[topic] = self.node.create_subscription(cls, topic, cb, qos, raw=True)
        if msgtype == SNAPSHOT_TYPE:
            self._snapshot_requests[topic] = StateRequest(self, topic)

    def wants(self, topic: str) -> bool:
        return self.wanted is None or topic in self.wanted

    def matched(self, topic: str) -> bool:
        """This recorder's subscription to ``topic`` has matched every publisher it was made for that is
        still in the graph (rmw's matched count: what it receives from now on)."""
        sub = self.subs.get(topic)
        if sub is None:
            return False
        in_graph = sum(1 for p in self.node.get_publishers_info_by_topic(topic)
                       if p.node_name != self.node.get_name() or p.node_namespace != self.node.get_namespace())
        return sub.get_publisher_count() >= min(self.expected[topic], in_graph)

    def recording(self) -> bool:
        """Every topic subscribed so far has matched its publishers, and every node whose ~/snapshot is
        recorded has its state at the start in the bag, taken once its writers had matched this
        recorder's readers. Messages sent before this may be missing from the bag."""
        subs = self.subscribed()
        return (bool(subs) and all(self.matched(t) for t in subs)
                and all(r.done for r in self._snapshot_requests.values()))

    def subscribed(self) -> list[str]:
        return sorted(t for t, s in self.subs.items() if s is not None)

    def close(self) -> dict[str, int]:
        if not self.closed:
            self.closed = True
            self.node.destroy_timer(self._timer)
            for s in self.subs.values():
                if s is not None:
                    self.node.destroy_subscription(s)
            _set_ros_distro(self.writer)
        return dict(self.counts)


class StateRequest:
    """Gets a node's state at the start of the recording into the bag, from the node's ``~/snapshot``.

    The node's latched snapshot (from its start or last reset) arrives first and names the topics a
    replay needs from the node (its ``matched_readers``). Once this recorder's subscriptions to them
    have matched the node's publishers, it calls the node's ``~/save_snapshot``. The next snapshot holds
    the node's state and how many readers each of those writers had matched at that moment; it is
    the start when every count reaches the subscriptions the graph shows (this recorder's included),
    so every message the node sends after it reaches the bag. Otherwise the recorder asks again. The
    service's answer is not waited for: an answer sent before the client's reader has matched is
    dropped, so the snapshot message is the proof. A request can be dropped the same way: with no
    snapshot RESEND_POLLS polls after a call, it calls again (a second snapshot does no harm)."""

    PERIOD = 0.1  # s between polls
    RESEND_POLLS = 10

    def __init__(self, rec: Recorder, topic: str) -> None:
        from std_srvs.srv import Trigger

        self.rec, self.topic = rec, topic
        # ~/snapshot's sibling ~/save_snapshot
        self.client = rec.node.create_client(Trigger, topic.rsplit("/", 1)[0] + "/" + SAVE_SERVICE)
        self.request = Trigger.Request()
        self.needed: list[str] | None = None  # absolute topics a replay needs, from the first snapshot
        self.sent = False   # a call is out and no snapshot arrived since
        self.polls_since_call = 0
        self.done = False
        self.asked = 0      # calls made
        self.unmatched: list[str] = []  # the last snapshot's topics whose writer had not matched us
        self.timer = rec.node.create_timer(self.PERIOD, self.poll)

    def poll(self) -> None:
        if self.done or self.needed is None or self.rec.closed:
            return
        if self.sent:
            self.polls_since_call += 1
            if self.polls_since_call < self.RESEND_POLLS:
                return
        if not all(self.rec.matched(t) for t in self.needed) or not self.client.service_is_ready():
            return
        self.sent = True
        self.polls_since_call = 0
        self.asked += 1
        self.client.call_async(self.request)

    def on_message(self, data: bytes) -> bool:
        """A snapshot arrived; True once it is the recording's start."""
        if self.done:
            return False
        from libcollide_msgs.msg import WorldSnapshot
        from rclpy.serialization import deserialize_message

        counts = json.loads(deserialize_message(data, WorldSnapshot).node_state).get("matched_readers", {})
        topics = {t: n for t, n in counts.items() if self.rec.wants(t)}
        if self.needed is None:
            self.needed = sorted(topics)
        if not self.sent:
            return False  # the latched one, from before the call
        self.sent = False
        self.unmatched = [t for t, n in sorted(topics.items())
                          if not self.rec.matched(t) or n < len(self.rec.node.get_subscriptions_info_by_topic(t))]
        if self.unmatched:
            if self.asked in (10, 100):  # say why the recording has not started, not on every call
                self.rec.node.get_logger().warning(
                    f"{self.topic}: after {self.asked} snapshots, the node's writers on "
                    f"{', '.join(self.unmatched)} have not matched every subscription the graph shows yet")
            return False  # poll() asks again
        self.done = True
        self.rec.node.destroy_timer(self.timer)
        return True


def _ros_distro_yaml(text: str) -> str:
    """The metadata YAML ``text`` with its ros_distro value set to ROS_DISTRO."""
    out, n = _ROS_DISTRO_LINE.subn(lambda m: m.group(1) + ROS_DISTRO, text)
    if n != 1:
        raise RuntimeError(f"bag metadata holds {n} ros_distro lines, expected 1")
    return out


def _set_ros_distro(writer: Any) -> None:
    """writer.close(), with ros_distro: ROS_DISTRO in the metadata it writes into the storage file
    and into metadata.yaml."""
    storage = writer.storage
    storage_close = storage.close
    storage.close = lambda version, metadata: storage_close(version, _ros_distro_yaml(metadata))
    writer.close()
    meta: Path = writer.metapath
    tmp = meta.with_suffix(".yaml.tmp")
    tmp.write_text(_ros_distro_yaml(meta.read_text("utf8")), "utf8")
    tmp.replace(meta)


def snapshot_params(node: Any, target: str, timeout: float = 5.0) -> dict[str, Any] | None:
    """All parameters of node `target` (e.g. "sim"), or None when it does not answer in time."""
    import rclpy
    from rclpy.parameter import parameter_value_to_python
    from rclpy.parameter_client import AsyncParameterClient

    client = AsyncParameterClient(node, target)
    if not client.wait_for_services(timeout_sec=timeout):
        return None
    fut = client.list_parameters()
    rclpy.spin_until_future_complete(node, fut, timeout_sec=timeout)
    if not fut.done() or fut.result() is None:
        return None
    names = sorted(fut.result().result.names)
    fut = client.get_parameters(names)
    rclpy.spin_until_future_complete(node, fut, timeout_sec=timeout)
    if not fut.done() or fut.result() is None:
        return None
    return {n: parameter_value_to_python(v) for n, v in zip(names, fut.result().values)}


PARAMS_KEY = "collide_ros.params"


def format_counts(counts: dict[str, int]) -> str:
    width = max([len(t) for t in counts] + [5])
    lines = [f"  {t:<{width}}  {n:>7}" for t, n in sorted(counts.items())]
    lines.append(f"  {'total':<{width}}  {sum(counts.values()):>7}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    import rclpy
    from rclpy.executors import SingleThreadedExecutor

    argv = list(sys.argv[1:] if argv is None else argv)
    if "--ros-args" in argv:
        argv = argv[:argv.index("--ros-args")]
    p = argparse.ArgumentParser(prog="python -m collide_ros.recorder", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", required=True, help="bag directory to create (must not exist)")
    p.add_argument("--topics", nargs="*", default=None,
                   help="topics to record (relative names resolve in the recorder's "
                        "namespace); default: every topic except /rosout, /parameter_events")
    p.add_argument("--duration", type=float, default=0.0, help="stop S seconds after 'recording' (0 = on signal)")
    p.add_argument("--node-name", default="recorder")
    p.add_argument("--params-of", default=None, metavar="NODE",
                   help="store this node's parameters (e.g. 'sim') in the bag's custom_data, "
                        "for readers of the bag (the replay takes them from the node's ~/snapshot)")
    a = p.parse_args(argv)
    if Path(a.out).exists():
        p.error(f"{a.out} exists already")

    rclpy.init(args=sys.argv)
    node = rclpy.create_node(a.node_name)
    rec = Recorder(node, a.out, a.topics)
    if a.params_of:
        params = snapshot_params(node, a.params_of)
        if params is None:
            print(f"recorder: no parameters from {a.params_of!r}", file=sys.stderr, flush=True)
        else:
            rec.writer.set_custom_data(PARAMS_KEY, json.dumps(params, sort_keys=True))
            print(f"recorder: stored {len(params)} parameters of {a.params_of}", flush=True)
    stop = {"flag": False}

    def on_signal(signum: int, frame: Any) -> None:
        stop["flag"] = True

    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    ex = SingleThreadedExecutor()
    ex.add_node(node)
    print(f"recorder: writing {a.out} (mcap, rosbag2 v9)", flush=True)
    t0 = time.monotonic()
    since: float | None = None  # when it reported "recording"; --duration counts from there
    announced: set[str] = set()
    saved: list[str] = []
    try:
        while not stop["flag"] and not (since is not None and 0 < a.duration <= time.monotonic() - since):
            ex.spin_once(timeout_sec=0.05)
            new = set(rec.subscribed()) - announced
            for t in sorted(new):
                print(f"recorder: subscribed {t}", flush=True)
            announced |= new
            while len(saved) < len(rec.saved):
                saved.append(rec.saved[len(saved)])
                asked = rec._snapshot_requests[saved[-1]].asked
                print(f"recorder: state saved on {saved[-1]} ({asked} call{'s' * (asked > 1)} to "
                      f"{SAVE_SERVICE})", flush=True)
            if since is None and rec.recording():
                since = time.monotonic()
                print(f"recorder: recording ({len(announced)} topics matched, {since - t0:.2f} s after "
                      "the start)", flush=True)
    finally:
        counts = rec.close()
        ex.remove_node(node)
        node.destroy_node()
        rclpy.try_shutdown()
    print(f"recorder: wrote {a.out}\n{format_counts(counts)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
