"""Keyboard teleop for the sim node: myPhysicsLab's thruster keys over ROS.

    python -m collide_ros.teleop [--rate 20] [--hold 0.15] [--first-hold 0.6]
    python -m collide_ros.teleop --keys "eeeff[up]" --interval 0.05     # non-interactive

S,D,F,E drive block1 and J,K,L,I (plus the arrow keys) drive block2. Each block has
the four default thrusters (0 left, 1 right, 2 up, 3 down); a key fires one of them.
A terminal gives no key-release events, only autorepeated presses, so a key counts as
"held" for a short time after its last press; while any key of a block is held the
current firing list is republished at a steady rate (the node's watchdog keeps thrust
alive while commands keep coming), and one all-off command is sent when the last key
of the block is released. Publishes libcollide_msgs/ThrusterCommand on `thrusters`.
"""
from __future__ import annotations

import argparse
import os
import re
import select
import sys
import time
from dataclasses import dataclass, field
from typing import Callable, Iterable, Sequence

# thruster indices of the default block thrusters (contracts.md)
LEFT, RIGHT, UP, DOWN = 0, 1, 2, 3
N_THRUSTERS = 4
THRUSTER_NAMES = ("left", "right", "up", "down")

#: key token -> (block slot 0/1, thruster index)
KEYMAP: dict[str, tuple[int, int]] = {
    "s": (0, LEFT), "f": (0, RIGHT), "e": (0, UP), "d": (0, DOWN),
    "j": (1, LEFT), "l": (1, RIGHT), "i": (1, UP), "k": (1, DOWN),
    "left": (1, LEFT), "right": (1, RIGHT), "up": (1, UP), "down": (1, DOWN),
}
QUIT_TOKENS = frozenset({"q", "ctrl-c"})

# ANSI cursor keys, normal (ESC [ x) and application (ESC O x) mode
_ARROWS = {"A": "up", "B": "down", "C": "right", "D": "left"}
_BRACKET = re.compile(r"\[(up|down|left|right)\]")


def parse_keys(data: str) -> tuple[list[str], str]:
    """Split raw terminal input into key tokens.

    Returns (tokens, rest) where rest is an incomplete escape sequence to prepend to
    the next read. Letters are lower-cased (Shift does not matter); arrows become
    "up"/"down"/"left"/"right"; Ctrl-C becomes "ctrl-c"; other escape sequences are
    dropped whole.
    """
    tokens: list[str] = []
    i, n = 0, len(data)
    while i < n:
        c = data[i]
        if c == "\x1b":
            if i + 1 >= n:
                return tokens, data[i:]
            if data[i + 1] in "[O":
                # CSI / SS3: parameters then one final byte in 0x40..0x7e
                j = i + 2
                while j < n and not ("\x40" <= data[j] <= "\x7e"):
                    j += 1
                if j >= n:
                    return tokens, data[i:]
                if data[i + 2:j] == "" and data[j] in _ARROWS:
                    tokens.append(_ARROWS[data[j]])
                i = j + 1
                continue
            i += 1  # lone ESC followed by something else: drop the ESC
            continue
        if c == "\x03":
            tokens.append("ctrl-c")
        elif c.isprintable():
            tokens.append(c.lower())
        i += 1
    return tokens, ""


def script_tokens(keys: str) -> list[str]:
    """Tokens of a --keys script: plain characters plus [up] [down] [left] [right]."""
    out: list[str] = []
    pos = 0
    for m in _BRACKET.finditer(keys):
        out.extend(ch.lower() for ch in keys[pos:m.start()] if not ch.isspace())
        out.append(m.group(1))
        pos = m.end()
    out.extend(ch.lower() for ch in keys[pos:] if not ch.isspace())
    return out


def key_action(token: str) -> tuple[int, int] | None:
    """(block slot, thruster index) a key token fires, or None."""
    return KEYMAP.get(token)


def firing_for(held: Iterable[str]) -> dict[int, list[bool]]:
    """Firing lists per block slot for a set of held key tokens (slots without keys omitted)."""
    out: dict[int, list[bool]] = {}
    for tok in held:
        act = key_action(tok)
        if act is None:
            continue
        slot, idx = act
        out.setdefault(slot, [False] * N_THRUSTERS)[idx] = True
    return out


@dataclass
class KeyHold:
    """Turns a stream of (autorepeated) key presses into held keys.

    A first press holds a key for `first_hold` seconds (longer than the terminal's
    autorepeat delay, typically 250-600 ms); a repeat arriving while the key is still
    held extends it by `hold` seconds (longer than the autorepeat period, ~30-40 ms).
    """

    hold: float = 0.15
    first_hold: float = 0.6
    until: dict[str, float] = field(default_factory=dict)

    def press(self, token: str, now: float) -> None:
        if key_action(token) is None:
            return
        until = self.until.get(token, -1.0)
        repeat = until >= now
        # a repeat never shortens the hold left over from the first press
        self.until[token] = max(until, now + (self.hold if repeat else self.first_hold))

    def held(self, now: float) -> set[str]:
        for tok in [t for t, u in self.until.items() if u < now]:
            del self.until[tok]
        return set(self.until)

    def firing(self, now: float) -> dict[int, list[bool]]:
        return firing_for(self.held(now))

    def release_all(self) -> None:
        self.until.clear()


class Teleop:
    """Publishing side: decides what to send each tick (pure apart from `send`)."""

    def __init__(self, bodies: Sequence[str], send: Callable[[str, list[bool]], None],
                 hold: KeyHold) -> None:
        self.bodies = list(bodies)
        self.send = send
        self.hold = hold
        self.active: set[int] = set()

    def tick(self, now: float) -> None:
        fire = self.hold.firing(now)
        for slot, lst in sorted(fire.items()):
            if slot < len(self.bodies):
                self.send(self.bodies[slot], lst)
        for slot in sorted(self.active - set(fire)):
            self.send(self.bodies[slot], [False] * N_THRUSTERS)  # released
        self.active = set(fire)

    def stop(self) -> None:
        for slot in sorted(self.active):
            self.send(self.bodies[slot], [False] * N_THRUSTERS)
        self.active = set()
        self.hold.release_all()


def keymap_text(bodies: Sequence[str]) -> str:
    b1, b2 = (list(bodies) + ["block1", "block2"])[:2]
    return (
        "collide teleop: thruster keys (publishing libcollide_msgs/ThrusterCommand on 'thrusters')\n"
        f"  {b1}:        E            {b2}:        I / Up\n"
        "              S  D  F                 J  K  L / Left Down Right\n"
        "  S,J,Left = fire left thruster    F,L,Right = right\n"
        "  E,I,Up   = up thruster           D,K,Down  = down\n"
        "  hold a key to keep firing (autorepeat); q or Ctrl-C quits\n"
    )


# ---------------------------------------------------------------- ROS side

class _RosSender:
    def __init__(self, node_name: str, topic: str) -> None:
        import rclpy
        from libcollide_msgs.msg import ThrusterCommand
        from rclpy.qos import QoSProfile, ReliabilityPolicy

        rclpy.init(args=None)
        self._rclpy = rclpy
        self._msg = ThrusterCommand
        self.node = rclpy.create_node(node_name)
        qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
        self.pub = self.node.create_publisher(ThrusterCommand, topic, qos)
        self.sent = 0

    def __call__(self, body: str, firing: list[bool]) -> None:
        m = self._msg()
        m.header.stamp = self.node.get_clock().now().to_msg()
        m.body = body
        m.firing = list(firing)
        self.pub.publish(m)
        self.sent += 1

    def wait_for_subscriber(self, timeout: float) -> bool:
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if self.pub.get_subscription_count() > 0:
                return True
            self._rclpy.spin_once(self.node, timeout_sec=0.05)
        return False

    def close(self) -> None:
        # give reliable delivery of the last (release) messages a moment
        end = time.monotonic() + 0.2
        while time.monotonic() < end:
            self._rclpy.spin_once(self.node, timeout_sec=0.02)
        self.node.destroy_node()
        self._rclpy.try_shutdown()


def run_script(tele: Teleop, tokens: list[str], interval: float, rate: float) -> None:
    """Non-interactive: press `tokens` one every `interval` s, tick at `rate` Hz until all released."""
    period = 1.0 / rate
    t0 = time.monotonic()
    presses = [(t0 + i * interval, tok) for i, tok in enumerate(tokens)]
    k = 0
    next_tick = t0
    while True:
        now = time.monotonic()
        while k < len(presses) and presses[k][0] <= now:
            if presses[k][1] in QUIT_TOKENS:
                tele.stop()
                return
            tele.hold.press(presses[k][1], presses[k][0])
            k += 1
        if now >= next_tick:
            tele.tick(now)
            next_tick += period
        if k >= len(presses) and not tele.active and not tele.hold.held(now):
            return
        nxt = min(next_tick, presses[k][0]) if k < len(presses) else next_tick
        time.sleep(max(0.0, nxt - time.monotonic()))


def run_terminal(tele: Teleop, rate: float, fd: int) -> None:
    """Interactive loop on a terminal in no-echo, non-canonical mode."""
    import termios

    old = termios.tcgetattr(fd)
    new = termios.tcgetattr(fd)
    new[3] &= ~(termios.ICANON | termios.ECHO)  # lflag; keep ISIG so Ctrl-C still works
    new[6][termios.VMIN] = 0
    new[6][termios.VTIME] = 0
    termios.tcsetattr(fd, termios.TCSANOW, new)
    period = 1.0 / rate
    pending = ""
    next_tick = time.monotonic()
    try:
        while True:
            timeout = max(0.0, next_tick - time.monotonic())
            r, _, _ = select.select([fd], [], [], timeout)
            now = time.monotonic()
            if r:
                data = os.read(fd, 1024).decode("utf-8", "replace")
                if not data:  # EOF
                    return
                toks, pending = parse_keys(pending + data)
                for tok in toks:
                    if tok in QUIT_TOKENS:
                        return
                    tele.hold.press(tok, now)
                tele.tick(now)  # react to a press at once
                next_tick = now + period
            elif now >= next_tick:
                tele.tick(now)
                next_tick += period
                if next_tick < now:
                    next_tick = now + period
    finally:
        tele.stop()
        termios.tcsetattr(fd, termios.TCSADRAIN, old)


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if "--ros-args" in argv:  # leave ROS arguments to rclpy (read from sys.argv there)
        argv = argv[:argv.index("--ros-args")]
    p = argparse.ArgumentParser(prog="python -m collide_ros.teleop", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--rate", type=float, default=20.0, help="republish rate while a key is held [Hz]")
    p.add_argument("--hold", type=float, default=0.15, help="hold after an autorepeated press [s]")
    p.add_argument("--first-hold", type=float, default=0.6, help="hold after a first press [s]")
    p.add_argument("--bodies", nargs=2, default=["block1", "block2"], metavar=("B1", "B2"),
                   help="body names driven by S,D,F,E and J,K,L,I/arrows")
    p.add_argument("--topic", default="thrusters")
    p.add_argument("--keys", default=None,
                   help="non-interactive: keys to press, e.g. 'eeeff[up][up]'")
    p.add_argument("--interval", type=float, default=0.05, help="seconds between --keys presses")
    p.add_argument("--wait", type=float, default=10.0,
                   help="with --keys: wait up to this long for the node's subscription [s]")
    a = p.parse_args(argv)
    if a.rate <= 0 or a.hold <= 0 or a.first_hold <= 0 or a.interval < 0:
        p.error("--rate, --hold, --first-hold must be > 0 and --interval >= 0")

    print(keymap_text(a.bodies), flush=True)
    sender = _RosSender("teleop", a.topic)
    tele = Teleop(a.bodies, sender, KeyHold(hold=a.hold, first_hold=a.first_hold))
    try:
        if a.keys is not None:
            if not sender.wait_for_subscriber(a.wait):
                print("teleop: no subscriber on 'thrusters'; sending anyway", file=sys.stderr)
            run_script(tele, script_tokens(a.keys), a.interval, a.rate)
        else:
            if not os.isatty(sys.stdin.fileno()):
                print("teleop: stdin is not a terminal (use --keys for scripted input)",
                      file=sys.stderr)
                return 2
            run_terminal(tele, a.rate, sys.stdin.fileno())
    except KeyboardInterrupt:
        tele.stop()
    finally:
        print(f"teleop: sent {sender.sent} thruster commands", flush=True)
        sender.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
