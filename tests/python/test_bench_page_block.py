"""bench/page_block.py: a generated block of a docs page is replaced between its markers, the rest of
the page kept byte for byte; a page without the block is refused or gets it appended, as the caller says."""
from __future__ import annotations

import pytest

from bench_module import load_bench

pb = load_bench("page_block")
B, E = "<!-- block: begin -->", "<!-- block: end -->"


def test_block_replaced_alone() -> None:
    page = "# Title\n\nintro\n" + B + "\nold table\n" + E + "\n\nafter\n"
    out = pb.replace_block(page, B, E, B + "\nnew table\n" + E, append_missing=False)
    assert out == "# Title\n\nintro\n" + B + "\nnew table\n" + E + "\n\nafter\n"


def test_missing_block_refused_or_appended() -> None:
    with pytest.raises(ValueError):
        pb.replace_block("# Title\n", B, E, B + E, append_missing=False)
    assert pb.replace_block("# Title\n\n", B, E, "T", append_missing=True) == "# Title\n\nT\n"


def test_block_without_end_marker() -> None:
    page = "# Title\n" + B + "\ncut short"
    with pytest.raises(ValueError):
        pb.replace_block(page, B, E, "T", append_missing=False)
    assert pb.replace_block(page, B, E, "T", append_missing=True) == "# Title\nT"
