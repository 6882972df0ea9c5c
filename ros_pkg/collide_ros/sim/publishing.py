"""What the node publishes at rates counted in sim-time steps: bodies/poses, bodies/states, contacts and
energy (state_rate), /tf, markers and /clock; the laser scans are scanners.py's. The bulk messages are
written as CDR bytes with numpy (cdr.py, markers.py); the contacts message takes the impacts since the
last one from the world's impact event stream, which keeps them across steps
(docs/events_and_snapshots.md). The poses are computed once per publish round (pose_frame.py) and shared
by the topics due after a step; nothing per body runs in Python. A round is read from the world on the
stepping thread and, in the stepping loop, written and sent by the publish thread (publish_thread.py)."""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from geometry_msgs.msg import PoseArray
from libcollide_msgs.msg import BodyStates, Contacts, Energy
from rosgraph_msgs.msg import Clock
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

import collide

from collide_ros import cdr, markers, qos
from collide_ros.sim.pose_frame import PoseFrame
from collide_ros.sim.publish_thread import PublishThread

# Contacts per contacts message (impacts since the last one first, then resting contacts). Impacts
# past it stay in the world's event stream for the next message; resting contacts past it are dropped
# and counted (dropped_contacts). A reliable writer's history keeps every slot's
# largest message (Fast DDS reallocates a slot's buffer upwards, never down), so the node's memory
# grows towards state_qos_depth x the largest contacts message: 1000 contacts (~74 kB) x 100 =
# ~7 MB. Uncapped, the soak saw 100 000 impacts (7.4 MB) in one message and the RSS grew by 94 MiB
# in an hour (docs/hardening.md, "Soak").
MAX_CONTACTS_PER_MESSAGE = 1000

#: the fields an impact event and a collision contact share under one name
_SHARED_FIELDS = ("body_a", "body_b", "point", "normal", "gap", "tangent_impulse", "time")


def impact_rows(events: np.ndarray) -> np.ndarray:
    """Impact events (collide.EVENT_DTYPE) as the contacts view's rows (collide.CONTACT_DTYPE, kind
    COLLISION): the numbers the step's collision contact carries, normal_velocity being minus the
    approach speed (a sign flip, exact) and force 0."""
    rows = np.zeros(len(events), dtype=collide.CONTACT_DTYPE)
    for f in _SHARED_FIELDS:
        rows[f] = events[f]
    rows["normal_velocity"] = -events["approach_speed"]
    rows["impulse"] = events["normal_impulse"]
    rows["kind"] = collide.COLLISION
    return rows


def hex_color(value: Any, fallback: markers.Color) -> markers.Color:
    """A scene's '#rrggbb' colour as RGBA, or ``fallback``."""
    if isinstance(value, str) and value.startswith("#") and len(value) == 7:
        try:
            return (int(value[1:3], 16) / 255.0, int(value[3:5], 16) / 255.0, int(value[5:7], 16) / 255.0, 1.0)
        except ValueError:
            return fallback
    return fallback


def concat_rows(parts: list[np.ndarray]) -> np.ndarray:
    """np.concatenate of structured rows, copied as opaque records when all have one dtype: numpy
    copies a structured dtype with padding (lc_contact's) field by field into a packed dtype, several
    times slower; this keeps the dtype."""
    dtype = parts[0].dtype
    if any(p.dtype != dtype for p in parts):
        return np.concatenate(parts)
    record = np.dtype((np.void, dtype.itemsize))
    return np.concatenate([p.view(record) for p in parts]).view(dtype)


class Publishing:
    """Owns the publishers of the state topics (``_pub_poses``, ``_pub_states``, ``_pub_contacts``,
    ``_pub_energy``, ``_pub_clock`` (None with publish_clock false), ``_pub_tf``, ``_pub_markers``), their
    CDR writers (``_cdr_*``), the poses of the current publish round (``_frame``, ``_state_copy``), the
    publish thread of the stepping loop (``_publish_thread``, None outside Loop.run), the publish periods in steps (``_every_*``) and the counts of what the
    contacts messages left out (``dropped_contacts``, ``dropped_impacts``)."""

    def _init_publishing(self) -> None:
        state_qos = qos.state(int(self._p["state_qos_depth"]))
        self._pub_poses = self._publisher(PoseArray, "bodies/poses", state_qos)
        self._pub_states = self._publisher(BodyStates, "bodies/states", state_qos)
        self._pub_contacts = self._publisher(Contacts, "contacts", state_qos)
        self._pub_energy = self._publisher(Energy, "energy", state_qos)
        # one /clock per domain: a sim beside the clock owner leaves it out (publish_clock, read-only)
        self._pub_clock = self._publisher(Clock, "/clock", qos.CLOCK) if self._p["publish_clock"] else None
        self._pub_tf = self._publisher(TFMessage, "/tf", qos.TF)
        self._pub_markers = self._publisher(MarkerArray, "markers", qos.MARKERS)
        self.dropped_contacts = 0  # resting contacts beyond MAX_CONTACTS_PER_MESSAGE, since the start
        self.dropped_impacts = 0   # impacts the event stream let go (event_capacity unread), since the start
        self._publish_thread: PublishThread | None = None  # the stepping loop's (Loop.run)

    def _periods(self) -> None:
        dt = float(self._p["time_step"])

        def every(rate: float) -> int:
            return 0 if rate <= 0 else max(1, int(round(1.0 / (rate * dt))))
        self._every_state = every(self._p["state_rate"])
        self._every_tf = every(self._p["tf_rate"])
        self._every_marker = every(self._p["marker_rate"])
        self._every_clock = every(self._p["clock_rate"])

    def _make_writers(self) -> None:
        """The CDR writers for the current body set and frames (after the pending round: it uses them)."""
        self._wait_published()
        frame = self._p["world_frame"]
        self._cdr_poses = cdr.PoseArrayCdr(len(self._dyn_rows), frame)
        self._cdr_states = cdr.BodyStatesCdr(self._dyn_names, frame)
        prefix = self._p["frame_prefix"]
        self._cdr_tf = cdr.TFMessageCdr(frame, [prefix + n for n in self._dyn_names])
        self._cdr_contacts = cdr.ContactsCdr(frame, self._name_of_id)
        self._cdr_energy = cdr.EnergyCdr(frame)
        self._frame = PoseFrame(self._dyn_rows, len(self._names))
        self._state_copy = np.zeros((len(self._names), 6))  # a round's state, for the publish thread
        outlines, colors = [], []
        for i, n in enumerate(self._names):
            outlines.append(self._bodies[n].local_vertices())
            colors.append(hex_color(self._colors.get(n), markers.body_color(n, i, bool(self._static[i]))))
        ids = [int(i) for i in self._ids]
        self._cdr_markers = markers.MarkerArrayCdr(frame, ids, outlines, colors)
        # DELETEALL heads the new scene's message: sent on its own, the depth-1 history could replace it
        # with the scene before a subscriber (RViz, the live view) took it
        self._cdr_markers_reset = markers.MarkerArrayCdr(frame, ids, outlines, colors, lead=[markers.DELETE_ALL])

    # ------------------------------------------------------------------ the publish thread
    def _start_publish_thread(self) -> None:
        """From here on, the rounds of ``_publish_due(s, threaded=True)`` are written and sent by a
        thread of their own (publish_thread.py)."""
        if self._publish_thread is None:
            self._publish_thread = PublishThread(self._publish_thread_error)

    def _stop_publish_thread(self) -> None:
        """Send the pending round and end the thread; publishing is inline again."""
        t, self._publish_thread = self._publish_thread, None
        if t is not None:
            t.stop()

    def _publish_thread_error(self, exc: Exception) -> None:
        if self.context.ok():  # on a shut-down context rclpy raises from publish: the end of the run
            self._warn("publish-thread", f"publishing: {type(exc).__name__}: {exc}")

    def _wait_published(self) -> None:
        """Wait until the publish thread's pending round (if any) was sent: the state topics go out in
        order, and the writers and the pose frame are free."""
        if self._publish_thread is not None:
            self._publish_thread.wait_idle()

    def _publish_thread_time(self) -> float:
        """Seconds the publish thread spent sending rounds since the last call (0 without it)."""
        return self._publish_thread.take_busy_time() if self._publish_thread is not None else 0.0

    # ------------------------------------------------------------------ rounds
    def _publish_due(self, s: int, threaded: bool = False) -> None:
        """What is due after step ``s`` (counted since the last build). ``threaded`` (the stepping
        loop, with the publish thread running): what the round needs from the world (stamp, state,
        energy, contacts) is read here, and the thread writes and sends it while the loop steps on."""
        clock = self._pub_clock is not None and bool(self._every_clock) and s % self._every_clock == 0
        state = s % self._every_state == 0
        tf = bool(self._every_tf) and s % self._every_tf == 0
        marker = bool(self._every_marker) and s % self._every_marker == 0
        worker = self._publish_thread if threaded else None
        if clock or state or tf or marker:
            if worker is not None:
                worker.wait_idle()  # the previous round reads the state copy and the writers
            job = self._collect_round(clock, state, tf, marker, copy=worker is not None)
            if worker is not None:
                worker.submit(job)
            else:
                job()
        if self._scanners:
            self._publish_scans(s)

    def _collect_round(self, clock: bool, state: bool, tf: bool, marker: bool, copy: bool,
                       reset: bool = False) -> Callable[[], None]:
        """Read what a round needs from the world now; returns the round, which writes and sends it.
        ``copy``: the state is copied (the round runs after the world stepped on)."""
        sec, ns = self._stamp()
        rows = None
        if state or tf or marker:
            rows = self.world.state
            if copy:
                np.copyto(self._state_copy, rows)
                rows = self._state_copy
        energy = self.world.energy if state else None
        contacts = self._take_contacts() if state else None
        extras = self._marker_extras() if marker else []

        def send() -> None:
            if clock and self._pub_clock is not None:
                self._pub_clock.publish(cdr.clock_cdr(sec, ns))
            if rows is not None:
                self._frame.refresh(rows)
            f = self._frame
            if state:
                self._pub_poses.publish(self._cdr_poses.encode(sec, ns, f.dyn_poses))
                self._pub_states.publish(self._cdr_states.encode(sec, ns, f.dyn_poses, f.dyn_twists))
                self._pub_energy.publish(self._cdr_energy.encode(sec, ns, energy))
                self._pub_contacts.publish(self._cdr_contacts.encode(sec, ns, contacts))
            if tf:
                self._pub_tf.publish(self._cdr_tf.encode(sec, ns, f.dyn_poses))
            if marker:
                template = self._cdr_markers_reset if reset else self._cdr_markers
                self._pub_markers.publish(template.encode(sec, ns, f.all_poses, extras))
        return send

    def _stamp(self) -> tuple[int, int]:
        return cdr.split_time(self.sim_time)

    def _publish_state(self) -> None:
        """bodies/poses, bodies/states, energy and contacts of the current state, now."""
        self._wait_published()
        self._collect_round(False, True, False, False, copy=False)()

    def _take_contacts(self) -> np.ndarray:
        """The impacts since the last publish (the event stream, oldest first, at most
        MAX_CONTACTS_PER_MESSAGE: the rest wait for the next message), then the resting contacts of
        the current step as room allows."""
        # sized to what is unread (a buffer of the cap would be zeroed at every publish), and at least
        # 1 so that the read reports the drops even when nothing is kept (event_capacity 0)
        events, dropped = self.world.read_events(min(max(self.world.pending_events, 1), MAX_CONTACTS_PER_MESSAGE))
        self.dropped_impacts += dropped
        impacts = impact_rows(events)
        c = self.world.contacts
        resting = c[c["kind"] != collide.COLLISION]
        room = MAX_CONTACTS_PER_MESSAGE - len(impacts)
        if len(resting) > room:
            self.dropped_contacts += len(resting) - room
            resting = resting[:room]
        if not len(impacts):
            return resting.copy()
        return concat_rows([impacts, resting]) if len(resting) else impacts

    def _publish_tf(self) -> None:
        """/tf of the current state, now."""
        self._wait_published()
        self._collect_round(False, False, True, False, copy=False)()

    def _marker_extras(self) -> list[markers.MarkerSpec]:
        """The springs and the current contacts as markers (copies: C's contacts change with the step)."""
        ends = [(np.asarray(a), np.asarray(b)) for a, b in (e.spring.endpoints() for e in self._springs.values())]
        extras = markers.spring_markers(ends)
        c = self.world.contacts
        extras += markers.contact_markers(np.array(c["point"]).reshape(-1, 2), np.array(c["normal"]).reshape(-1, 2))
        return extras

    def _publish_markers(self, reset: bool = False) -> None:
        """The bodies, springs and contacts of the current state, now; ``reset``: headed by a DELETEALL
        (a new scene)."""
        self._wait_published()
        self._collect_round(False, False, False, True, copy=False, reset=reset)()
