"""Pure key-mapping and hold logic of collide_ros.teleop (no ROS needed)."""
from __future__ import annotations

from collide_ros.teleop import (DOWN, LEFT, RIGHT, UP, KeyHold, Teleop, firing_for, key_action,
                                keymap_text, parse_keys, script_tokens)


def test_seed_key_map() -> None:
    # seed page: S,D,F,E -> block1; J,K,L,I and arrows -> block2 (left, down, right, up)
    assert [key_action(k) for k in "sdfe"] == [(0, LEFT), (0, DOWN), (0, RIGHT), (0, UP)]
    assert [key_action(k) for k in "jkli"] == [(1, LEFT), (1, DOWN), (1, RIGHT), (1, UP)]
    assert [key_action(k) for k in ("left", "down", "right", "up")] == \
        [(1, LEFT), (1, DOWN), (1, RIGHT), (1, UP)]
    assert key_action("x") is None and key_action("q") is None


def test_parse_terminal_input() -> None:
    toks, rest = parse_keys("eS\x1b[A\x1bOD\x1b[1;5Cq\x03")
    # ESC[A = up, ESC O D = left (application mode); ESC[1;5C (ctrl-right) is dropped whole
    assert toks == ["e", "s", "up", "left", "q", "ctrl-c"]
    assert rest == ""
    # an escape sequence split across reads is carried over
    toks, rest = parse_keys("f\x1b[")
    assert toks == ["f"] and rest == "\x1b["
    toks, rest = parse_keys(rest + "B")
    assert toks == ["down"] and rest == ""


def test_script_tokens() -> None:
    assert script_tokens("eE f[up][left]k") == ["e", "e", "f", "up", "left", "k"]


def test_firing_lists() -> None:
    fire = firing_for({"e", "f", "up", "x"})
    assert fire == {0: [False, True, True, False], 1: [False, False, True, False]}


def test_hold_first_press_then_autorepeat() -> None:
    h = KeyHold(hold=0.15, first_hold=0.6)
    h.press("e", 0.0)
    # held through the autorepeat delay (0.6 s covers typical 250-600 ms)
    assert h.held(0.59) == {"e"}
    h2 = KeyHold(hold=0.15, first_hold=0.6)
    h2.press("e", 0.0)
    h2.press("e", 0.05)  # an early repeat does not cut the first hold short
    assert h2.held(0.55) == {"e"} and h2.held(0.61) == set()
    # autorepeat at 30 Hz keeps it held with the short hold
    t = 0.5
    while t < 2.0:
        h.press("e", t)
        assert h.held(t + 0.1) == {"e"}
        t += 1 / 30
    # released: gone one short hold (0.15 s) after the last repeat, not a first-hold later
    last = t - 1 / 30
    assert h.held(last + 0.14) == {"e"}
    assert h.held(last + 0.16) == set()
    h.press("x", 3.0)  # unmapped keys are ignored
    assert h.held(3.0) == set()


def test_teleop_republishes_and_releases() -> None:
    sent: list[tuple[str, list[bool]]] = []
    tele = Teleop(["block1", "block2"], lambda b, f: sent.append((b, f)),
                  KeyHold(hold=0.15, first_hold=0.3))
    tele.hold.press("j", 0.0)
    for k in range(5):  # steady ticks while held
        tele.tick(0.05 * k)
    assert sent == [("block2", [True, False, False, False])] * 5
    sent.clear()
    tele.tick(0.31)  # hold expired: exactly one all-off message
    tele.tick(0.36)
    assert sent == [("block2", [False] * 4)]
    assert "S,J,Left" in keymap_text(["block1", "block2"])


def test_terminal_loop_on_a_pty() -> None:
    """The interactive loop in a real (pseudo-)terminal: raw input, arrow escapes, q quits,
    the terminal mode is restored, and releases are sent on exit."""
    import os
    import pty
    import termios
    import threading
    import time

    from collide_ros.teleop import run_terminal

    master, slave = pty.openpty()
    before = termios.tcgetattr(slave)
    sent: list[tuple[str, list[bool]]] = []
    tele = Teleop(["block1", "block2"], lambda b, f: sent.append((b, list(f))),
                  KeyHold(hold=0.15, first_hold=0.6))

    def typing() -> None:
        os.write(master, b"e\x1b[C")  # E and the right arrow, as a terminal sends them
        time.sleep(0.3)
        os.write(master, b"q")

    th = threading.Thread(target=typing)
    th.start()
    run_terminal(tele, rate=20.0, fd=slave)
    th.join()
    after = termios.tcgetattr(slave)
    os.close(master)
    os.close(slave)
    assert after == before  # echo and canonical mode are back
    assert ("block1", [False, False, True, False]) in sent   # E = block1 up
    assert ("block2", [False, True, False, False]) in sent   # right arrow = block2 right
    # quitting while keys are held releases both blocks
    assert sent[-2:] == [("block1", [False] * 4), ("block2", [False] * 4)]
