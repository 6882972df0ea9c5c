"""The documentation's indexes stay complete: README.md links every page of docs/, and docs/testing.md
names every test program and suite file, so a new page or test cannot go unlisted."""
from __future__ import annotations

import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_readme_links_every_docs_page() -> None:
    readme = (ROOT / "README.md").read_text()
    pages = sorted(p.name for p in (ROOT / "docs").glob("*.md"))
    assert {"c_api.md", "testing.md", "hardening.md"} <= set(pages)
    missing = [p for p in pages if f"(docs/{p})" not in readme]
    assert not missing, f"README.md does not link {missing}"


def test_testing_doc_names_every_test() -> None:
    doc = (ROOT / "docs" / "testing.md").read_text()
    named = set(re.findall(r"`([A-Za-z0-9_./]+)`", doc))
    c_tests = sorted(p.stem for p in (ROOT / "tests" / "c").glob("test_*.c"))
    py_tests = sorted(p.name for p in (ROOT / "tests" / "python").glob("test_*.py"))
    other = ["fuzz_step_regressions", "fuzz_scene_regressions", "exported_symbols", "find_package_consumer",
             "fuzz/fuzz_step.c", "fuzz/fuzz_scene.py", "soak/soak.py", "soak/load.py", "soak/step_search.py"]
    assert len(c_tests) >= 30 and len(py_tests) >= 30
    missing = [t for t in c_tests + py_tests + other if t not in named]
    assert not missing, f"docs/testing.md does not name {missing}"
