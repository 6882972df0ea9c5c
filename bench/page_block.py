"""A generated block of a Markdown page, between a begin and an end marker line, that a bench command
rewrites while the rest of the page stays as written."""
from __future__ import annotations


def replace_block(page: str, begin: str, end: str, text: str, *, append_missing: bool) -> str:
    """page with the text from its `begin` marker through its `end` marker replaced by text (which
    carries its own markers). A page without `begin`: ValueError, or text appended after a blank line when
    append_missing. A page with `begin` but no `end` after it: ValueError, or replaced to the page's end
    when append_missing (a block cut short by hand)."""
    i = page.find(begin)
    j = page.find(end, i) if i >= 0 else -1
    if i < 0 and append_missing:
        return page.rstrip("\n") + "\n\n" + text + "\n"
    if i < 0 or (j < 0 and not append_missing):
        raise ValueError(f"no block between {begin!r} and {end!r}")
    return page[:i] + text + (page[j + len(end):] if j >= 0 else "")
