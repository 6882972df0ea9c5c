"""Load: soak/load.py against one node at real_time_factor 1, 4 s per phase.

Phases: 10 kHz WrenchStamped flood on block1/thrust, a reliable subscriber to every topic that is
SIGSTOPped (stops reading) and then killed, set/get_parameters spam (accepted, out-of-range,
wrongly typed, on-set-rejected values), service spam (~/step while running, ~/kill ghost, ~/spawn
degenerate, ~/pause false). The assertions are the issue's: the node keeps its real-time factor
(>= 0.9, its own WARN threshold) or reports the drop as WARN "falling behind" in /diagnostics, and
recovers when the load ends (RTF >= 0.95 with level OK; a command is accepted; ~/step answers;
the spammed parameters hold their last accepted value).
"""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))

from soak.load import Phase, run_load  # noqa: E402

SECONDS = 4.0
RATE = 10_000.0


@pytest.fixture(scope="module")
def phases() -> dict[str, Phase]:
    return {ph.name: ph for ph in run_load(SECONDS, RATE, log=lambda s: None)}


@pytest.mark.parametrize("name", ["command flood", "stopped subscriber", "parameter spam", "service spam"])
def test_phase_keeps_or_reports_rtf_and_recovers(phases: dict[str, Phase], name: str) -> None:
    ph = phases[name]
    assert ph.failures == []
    assert ph.unreported_drops == []          # every window < 0.9 was a WARN "falling behind"
    assert len(ph.diags) >= SECONDS / 2       # the 1 Hz diagnostics kept coming
    assert ph.sim_advanced_s > 0.0
    assert ph.recovered and ph.recovery_rtf >= 0.95
    assert ph.accepted_after and ph.step_answered_after


def test_flood_really_was_10khz(phases: dict[str, Phase]) -> None:
    ph = phases["command flood"]
    # paced per millisecond by the publisher: the achieved rate is within 20 % of the target
    # unless the publishing process itself was starved (2 shared cores); 5 kHz is still a flood
    # 5x beyond the 1 kHz physics rate.
    assert ph.rate_hz >= 0.5 * RATE
    # whatever got through the depth-10 command queue was accepted and echoed, none rejected
    assert 0 < ph.accepted <= ph.sent and ph.rejected_during == 0
    # The node's own counts (/diagnostics): every flood message was either taken (and accepted,
    # and echoed) or counted lost, a gap in the publisher's sequence numbers after the first message
    # the node took (sent before the flood). Exact: a reliable writer delivers its last sample, so
    # the last sequence number reaches the node; between the first and the last every number is
    # taken or in a gap.
    c = ph.node_counts
    assert c["received"] + c["lost"] == ph.sent, c
    assert c["accepted"] == c["received"] and c["rejected"] == 0, c
    # the echoes this client got: at most the accepted ones (the echo writer's depth 10 may drop some
    # while this flooding process is descheduled)
    assert 0 < ph.accepted <= c["accepted"]


def test_spam_was_answered(phases: dict[str, Phase]) -> None:
    for name in ("parameter spam", "service spam"):
        ph = phases[name]
        assert ph.sent > 100, name
        # MAX_IN_FLIGHT (50) exceeds the services' request queue (rmw default depth 10), so
        # some requests may be dropped by the middleware; most are answered
        assert ph.answered >= 0.9 * ph.sent, (name, ph.answered, ph.sent)
