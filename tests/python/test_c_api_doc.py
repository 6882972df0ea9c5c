"""docs/c_api.md against the public headers, so the reference cannot drift from the API.

The public API is what libcollide/include/collide/*.h declare: every function marked LC_API, every
typedef'd struct with its fields, every enum with its values, the function pointer types, and the LC_
macros (with those of the generated collide/version.h, from cmake/version.h.in). The page must have,
for each function, a heading "### `name`" whose first C block is the header's declaration (compared
token by token, so only layout may differ); for each struct a "### `name`" section whose table lists
exactly its fields; every enum value; and no lc_/LC_ name that no header declares.

The control tests change the page in one place each and check that the checker reports it, so a
parser that silently finds nothing cannot pass for an up-to-date page.
"""
from __future__ import annotations

import dataclasses
import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[2]
HEADER_DIR = ROOT / "libcollide" / "include" / "collide"
VERSION_TEMPLATE = ROOT / "cmake" / "version.h.in"
DOC = ROOT / "docs" / "c_api.md"


@dataclasses.dataclass
class Api:
    functions: dict[str, str]          # name -> declaration (tokens joined by one space)
    structs: dict[str, list[str]]      # typedef name -> field names in order
    enums: dict[str, list[str]]        # typedef name -> value names
    types: set[str]                    # every lc_ type name
    macros: set[str]                   # every LC_ name in the headers and the version template


def strip_c(text: str) -> str:
    """C text without comments and preprocessor lines."""
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", " ", text)
    return "\n".join(line for line in text.splitlines() if not line.lstrip().startswith("#"))


def tokens(decl: str) -> str:
    return " ".join(re.findall(r"[A-Za-z_][A-Za-z0-9_]*|[0-9]+|\S", decl))


def read_api() -> Api:
    api = Api({}, {}, {}, set(), set())
    headers = sorted(HEADER_DIR.glob("*.h"))
    for path in headers:
        raw = path.read_text()
        api.macros |= set(re.findall(r"\bLC_[A-Z0-9_]+\b", raw))
        code = strip_c(raw)
        for m in re.finditer(r"\bLC_API\s+([^;{}]*?)\s*;", code, re.S):
            name = re.search(r"\b(lc_\w+)\s*\(", m.group(1))
            assert name, f"{path.name}: cannot read the LC_API declaration {m.group(1)!r}"
            assert name.group(1) not in api.functions, f"{name.group(1)} declared twice"
            api.functions[name.group(1)] = tokens(m.group(1))
        for m in re.finditer(r"typedef\s+struct\s+\w+\s*\{(.*?)\}\s*(lc_\w+)\s*;", code, re.S):
            fields = [re.search(r"(\w+)\s*(\[[^\]]*\])?\s*$", stmt.strip()).group(1)
                      for stmt in m.group(1).split(";") if stmt.strip()]
            api.structs[m.group(2)] = fields
        for m in re.finditer(r"typedef\s+enum\s+\w+\s*\{(.*?)\}\s*(lc_\w+)\s*;", code, re.S):
            api.enums[m.group(2)] = re.findall(r"\b(LC_[A-Z0-9_]+)\s*=", m.group(1))
        api.types |= set(re.findall(r"\}\s*(lc_\w+)\s*;", code))
        api.types |= set(re.findall(r"typedef\s+[^;{}]*?\b(lc_\w+)\s*;", code))
        api.types |= set(re.findall(r"typedef\s+[^;{}]*?\(\s*\*\s*(lc_\w+)\s*\)", code))  # function pointers
    api.macros |= set(re.findall(r"\bLC_[A-Z0-9_]+\b", VERSION_TEMPLATE.read_text()))
    return api


def sections(doc: str) -> dict[str, str]:
    """Text under each '### `lc_name`' heading, up to the next heading of any level."""
    out: dict[str, str] = {}
    parts = re.split(r"^(#{1,6} .*)$", doc, flags=re.M)
    for head, body in zip(parts[1::2], parts[2::2]):
        m = re.fullmatch(r"### `(lc_\w+)`\s*", head)
        if m:
            assert m.group(1) not in out, f"two sections for {m.group(1)}"
            out[m.group(1)] = body
    return out


def problems(doc: str, api: Api) -> list[str]:
    found: list[str] = []
    secs = sections(doc)
    for name in sorted(set(secs) - set(api.functions) - api.types):
        found.append(f"docs/c_api.md has a section for {name}, which no public header declares")
    for name in sorted(set(api.functions) - set(secs)):
        found.append(f"{name} (LC_API in the public headers) has no '### `{name}`' entry in docs/c_api.md")
    for name, decl in sorted(api.functions.items()):
        if name not in secs:
            continue
        block = re.search(r"```c\n(.*?)```", secs[name], re.S)
        written = tokens(strip_c(block.group(1)).strip().rstrip(";")) if block else "(no C block)"
        if written != decl:
            found.append(f"{name}: docs/c_api.md declares\n    {written}\n  the header declares\n    {decl}")
    for struct, fields in sorted(api.structs.items()):
        if struct not in secs:
            found.append(f"struct {struct} has no '### `{struct}`' section with its fields in docs/c_api.md")
            continue
        listed = re.findall(r"^\| `(\w+)` \|", secs[struct], re.M)
        if sorted(listed) != sorted(fields):
            found.append(f"{struct}: the table lists {sorted(set(listed) - set(fields)) or 'no'} extra and "
                         f"misses {sorted(set(fields) - set(listed)) or 'no'} fields of the header")
    named_lc = set(re.findall(r"\blc_[a-z0-9_]+\b", doc))
    for name in sorted(named_lc - set(api.functions) - api.types):
        found.append(f"docs/c_api.md names {name}, which no public header declares")
    named_macros = set(re.findall(r"\bLC_[A-Z0-9_]+\b", doc))
    for name in sorted(named_macros - api.macros):
        found.append(f"docs/c_api.md names {name}, which no public header defines")
    for enum, values in sorted(api.enums.items()):
        for value in values:
            if value not in named_macros:
                found.append(f"{enum} value {value} is missing from docs/c_api.md")
    return found


def test_headers_are_read() -> None:
    # the parser finds the API it is meant to check (a broken regex would make every check vacuous)
    api = read_api()
    assert len(api.functions) >= 60
    for name in ("lc_world_create", "lc_world_step", "lc_version", "lc_world_add_walls", "lc_body_distance"):
        assert name in api.functions
    assert api.functions["lc_world_step"] == "lc_status lc_world_step ( lc_world * world , double dt )"
    assert api.structs["lc_vec2"] == ["x", "y"]
    assert "sleep_speed" in api.structs["lc_world_def"] and "center_of_mass" in api.structs["lc_body_def"]
    assert "time_contact_regime" in api.structs["lc_counters"]
    assert api.enums["lc_status"][-1] == "LC_ERR_CALLBACK"
    assert {"lc_world", "lc_body_id", "lc_spring_id", "lc_status", "lc_force_fn", "lc_potential_fn"} <= api.types
    assert {"LC_API", "LC_WORLD_ANCHOR", "LC_VERSION_STRING"} <= api.macros


def test_c_api_doc_matches_the_headers() -> None:
    found = problems(DOC.read_text(), read_api())
    assert not found, "docs/c_api.md and the public headers differ:\n" + "\n".join(found)


def test_checker_reports_a_missing_entry_and_an_unknown_one() -> None:
    api = read_api()
    doc = DOC.read_text()
    start = doc.index("### `lc_world_remove_spring`")
    end = doc.index("### ", start + 4)
    without = doc[:start] + doc[end:]
    assert any("lc_world_remove_spring (LC_API" in p for p in problems(without, api))
    extra = doc + "\n### `lc_world_teleport`\n\n```c\nlc_status lc_world_teleport(lc_world *world);\n```\n"
    found = problems(extra, api)
    assert any("section for lc_world_teleport" in p for p in found)
    assert any("names lc_world_teleport" in p for p in found)


def test_checker_reports_a_changed_signature_field_and_enum_value() -> None:
    api = read_api()
    doc = DOC.read_text()
    changed = doc.replace("lc_status lc_world_step(lc_world *world, double dt);",
                          "lc_status lc_world_step(lc_world *world, float dt);")
    assert changed != doc
    assert any(p.startswith("lc_world_step: docs/c_api.md declares") for p in problems(changed, api))
    row = next(line for line in doc.splitlines() if line.startswith("| `sleep_time` |"))
    assert any(p.startswith("lc_world_def: the table") for p in problems(doc.replace(row + "\n", ""), api))
    no_value = doc.replace("`LC_MIX_MEAN`", "`mean`")
    assert any("LC_MIX_MEAN is missing" in p for p in problems(no_value, api))

