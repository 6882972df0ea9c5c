"""Give each test process (or demo run) its own ROS_DOMAIN_ID.

A domain id N is "ours" while we hold TCP port 32768 + N bound on 127.0.0.1 — the same scheme as
ament's domain_coordinator (which binds the same ports), so both coordinate with each other. The
kernel releases the port when the process exits, so a crashed test never leaks a domain.

Ids are taken from 1..101 (Fast DDS uses UDP 7400 + 250*id + small offsets, so ids above 101
would run into the ephemeral port range), skipping 0 (everyone's default) and 50..79 (the ranges
the team uses for hand runs without a lock, see docs/contracts.md).

Library use:   lock = acquire(); os.environ["ROS_DOMAIN_ID"] = str(lock.domain_id); ...; lock.release()
               lock = lock_unless_set()   (exports a locked id unless ROS_DOMAIN_ID is set; None then)
Command line:  python -m collide_ros.ros_domain exec -- CMD ARGS...
                   runs CMD with ROS_DOMAIN_ID set (unless already set) and the lock held by CMD
               python -m collide_ros.ros_domain pick      prints a currently free id (no lock kept)
"""
from __future__ import annotations

import os
import socket
import sys
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

PORT_BASE = 32768
MIN_ID = 1
MAX_ID = 101
HAND_RUN_IDS = range(50, 80)  # infra 50-54, node 55-64, tools 65-74, bench 75-79


def candidate_ids() -> list[int]:
    """The ids tests may use, in a per-process rotated order (spreads concurrent starters)."""
    ids = [i for i in range(MIN_ID, MAX_ID + 1) if i not in HAND_RUN_IDS]
    start = os.getpid() % len(ids)
    return ids[start:] + ids[:start]


@dataclass
class DomainLock:
    """A held ROS_DOMAIN_ID; the id stays reserved until release() or process exit."""

    domain_id: int
    sock: socket.socket = field(repr=False)

    @property
    def port(self) -> int:
        return PORT_BASE + self.domain_id

    def release(self) -> None:
        self.sock.close()

    def __enter__(self) -> "DomainLock":
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()


def try_lock(domain_id: int) -> DomainLock | None:
    """Lock one id, or None if another process holds it."""
    if not MIN_ID <= domain_id <= MAX_ID:
        raise ValueError(f"ROS_DOMAIN_ID {domain_id} outside {MIN_ID}..{MAX_ID}")
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        sock.bind(("127.0.0.1", PORT_BASE + domain_id))
    except OSError:
        sock.close()
        return None
    return DomainLock(domain_id, sock)


def is_locked(domain_id: int) -> bool:
    """True when some process (maybe this one) holds the id."""
    lock = try_lock(domain_id)
    if lock is None:
        return True
    lock.release()
    return False


def acquire(ids: Iterable[int] | None = None) -> DomainLock:
    """Lock the first free id of `ids` (default: candidate_ids())."""
    for domain_id in candidate_ids() if ids is None else ids:
        lock = try_lock(domain_id)
        if lock is not None:
            return lock
    raise RuntimeError("no free ROS_DOMAIN_ID: every candidate port 32768+id is taken")


def lock_unless_set() -> DomainLock | None:
    """Lock a free id and export it as ROS_DOMAIN_ID, unless ROS_DOMAIN_ID is set already (then None).
    Keep the returned lock for as long as the id is in use."""
    if os.environ.get("ROS_DOMAIN_ID"):
        return None
    lock = acquire()
    os.environ["ROS_DOMAIN_ID"] = str(lock.domain_id)
    return lock


def _exec(cmd: Sequence[str]) -> int:
    if not cmd:
        print("usage: python -m collide_ros.ros_domain exec -- CMD [ARGS...]", file=sys.stderr)
        return 2
    env = dict(os.environ)
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    env.pop("ROS_LOCALHOST_ONLY", None)
    if "ROS_DOMAIN_ID" not in env:
        lock = acquire()
        # The bound socket survives exec: CMD itself holds the lock for its whole life.
        os.set_inheritable(lock.sock.fileno(), True)
        env["ROS_DOMAIN_ID"] = str(lock.domain_id)
        print(f"ROS_DOMAIN_ID={lock.domain_id} (free id picked; export ROS_DOMAIN_ID to choose)",
              file=sys.stderr)
    os.execvpe(cmd[0], list(cmd), env)
    return 127  # not reached


def main(argv: Sequence[str]) -> int:
    if argv[:1] == ["pick"]:
        with acquire() as lock:
            print(lock.domain_id)
        return 0
    if argv[:1] == ["exec"]:
        rest = list(argv[1:])
        if rest[:1] == ["--"]:
            rest = rest[1:]
        return _exec(rest)
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
