"""docs/reference.md against the code: its tables of body keys, world-file keys, devices and
extension hooks list what the code accepts, its world example loads, its Python parses and the
files it names exist. A change to the code that the reference does not follow fails here."""

from __future__ import annotations

import ast
import inspect
import math
import re
import tomllib
from pathlib import Path
from typing import Any

import pytest

from specc.run import mission
from specc.runtime.body import BODY_KEYS
from specc.runtime.sim import WorldError, parse_world
from specc.runtime.sim.simulation import COMMON, DEVICES

ROOT = Path(__file__).resolve().parent.parent
REFERENCE = ROOT / "docs" / "reference.md"
PROBE = "zzz_not_a_key"


def reference() -> str:
    return REFERENCE.read_text()


def section(number: int) -> str:
    """The text of the reference's section `## <number>. ...`, up to the next one."""
    parts = re.split(r"^## ", reference(), flags=re.MULTILINE)
    found = [p for p in parts if p.startswith(f"{number}. ")]
    assert len(found) == 1, f"docs/reference.md has no single section '## {number}. ...'"
    return found[0]


def table_rows(text: str, header: str) -> list[list[str]]:
    """The rows of the markdown table whose header row starts with `| <header> |`, as cells."""
    lines = text.splitlines()
    start = next((k for k, line in enumerate(lines) if line.startswith(f"| {header} |")), None)
    assert start is not None, f"no table with a '{header}' column"
    rows = []
    for line in lines[start + 2:]:
        if not line.startswith("|"):
            break
        rows.append([cell.strip() for cell in line.strip().strip("|").split("|")])
    return rows


def code_name(cell: str) -> str:
    """`name` -> name."""
    match = re.fullmatch(r"`([^`]+)`", cell)
    assert match is not None, f"expected a `name` cell, got {cell!r}"
    return match.group(1)


def code_blocks(text: str, language: str) -> list[str]:
    return re.findall(rf"^```{language}\n(.*?)^```", text, flags=re.MULTILINE | re.DOTALL)


# ---------------------------------------------------------------- body (section 7)


def test_body_table_lists_every_body_key_with_its_unit_and_default() -> None:
    rows = table_rows(section(7), "key")
    documented = {code_name(row[0]): row for row in rows}
    assert len(documented) == len(rows), "a body key is listed twice"
    assert set(documented) == set(BODY_KEYS)
    for name, (_, unit, default, _what) in documented.items():
        key = BODY_KEYS[name]
        assert unit == (key.unit or "count"), f"{name}: unit {unit!r}, the code says {key.unit or 'count'!r}"
        assert math.isclose(float(default), key.spec_default(), rel_tol=1e-3, abs_tol=1e-9), \
            f"{name}: default {default}, the code says {key.spec_default()}"


# ---------------------------------------------------------------- world files (section 6)


def _known(message: str) -> list[str]:
    match = re.search(r"\(known: ([^)]*)\)", message)
    assert match is not None, f"no list of known keys in {message!r}"
    return [k.strip() for k in match.group(1).split(",")]


WALLS = {"room": {"width": 10.0, "height": 10.0}, "bounds": {"xmin": 0.0, "xmax": 10.0, "ymin": 0.0, "ymax": 10.0}}


def _base(section_name: str) -> dict[str, Any]:
    """A valid world to add an unknown key to: walls of the section probed when it gives them
    ([room] and [bounds] exclude each other), else a room."""
    if section_name in WALLS:
        return {section_name: WALLS[section_name]}
    return {"room": WALLS["room"]}


def _probe(data: dict[str, Any]) -> str:
    with pytest.raises(WorldError) as error:
        parse_world(data)
    return str(error.value)


def parser_keys() -> dict[str, tuple[bool, set[str]]]:
    """What the world parser accepts: section -> (an array of tables?, its keys), read from the
    errors it gives for an unknown key; `objects.at` is the array nested in [objects]."""
    sections = _known(_probe({"room": {"width": 1.0, "height": 1.0}, PROBE: {}}))
    accepted: dict[str, tuple[bool, set[str]]] = {}
    for name in sections:
        base = _base(name)
        as_table = {**base, name: {**base.get(name, {}), PROBE: 1}}
        message = _probe(as_table)
        if "array of tables" in message:
            message = _probe({**base, name: [{PROBE: 1}]})
            accepted[name] = (True, set(_known(message)))
        else:
            accepted[name] = (False, set(_known(message)))
    message = _probe({**_base("objects"), "objects": {"at": [{PROBE: 1}]}})
    assert "objects.at[0]" in message
    accepted["objects.at"] = (True, set(_known(message)))
    return accepted


def documented_world_keys() -> dict[str, tuple[bool, set[str]]]:
    found: dict[str, tuple[bool, set[str]]] = {}
    for row in table_rows(section(6), "table"):
        table, key = code_name(row[0]), code_name(row[1])
        array = table.startswith("[[")
        name = table.strip("[]")
        previous = found.setdefault(name, (array, set()))
        assert previous[0] == array, f"{table} written both as a table and as an array of tables"
        previous[1].add(key)
    return found


def test_world_table_lists_every_key_the_parser_accepts() -> None:
    assert documented_world_keys() == parser_keys()


def test_world_example_parses_and_uses_every_table() -> None:
    blocks = code_blocks(section(6), "toml")
    assert len(blocks) == 1, "section 6 should hold one complete world example"
    data = tomllib.loads(blocks[0])
    world = parse_world(data, "docs/reference.md")
    sections = set(parser_keys()) - {"objects.at"}
    assert set(data) == sections - {"bounds"}, "the example should use every table but [bounds]"
    assert world.objects and world.random_objects and world.targets and world.windows and world.obstacles


def test_world_error_quoted_in_the_reference_is_the_parsers() -> None:
    message = _probe({"room": {"width": 10.0, "height": 10.0}, "start": {"thetaa": 0.0}})
    assert "[start]: unknown key 'thetaa' (known: x, y, theta)" in message
    assert "[start]: unknown key 'thetaa' (known: x, y, theta)" in section(6)


# ---------------------------------------------------------------- devices (section 8)


def test_device_tables_list_the_simulations_devices() -> None:
    text = section(8)
    devices = [code_name(row[0]) for row in table_rows(text, "device")]
    assert sorted(devices) == sorted(DEVICES)
    common = [code_name(row[0]) for row in table_rows(text, "name")]
    assert sorted(common) == sorted(COMMON)


# ---------------------------------------------------------------- extension (section 9)


def test_extension_hooks_are_those_the_runner_calls() -> None:
    called = set(re.findall(r'hook\("(\w+)"\)', inspect.getsource(mission)))
    documented = {code_name(row[0]).partition("(")[0] for row in table_rows(section(9), "hook")}
    assert documented == called


def test_run_and_setup_attributes_exist() -> None:
    text = section(9)
    run = set(re.findall(r"\brun\.(\w+)", text))
    setup = set(re.findall(r"\bsetup\.(\w+)", text))
    assert run and setup
    assert {n for n in run if not hasattr(mission.RunContext, n)
            and n not in mission.RunContext.__dataclass_fields__} == set()
    assert {n for n in setup if n not in mission.RunSetup.__dataclass_fields__} == set()


# ---------------------------------------------------------------- the whole document


def test_python_examples_parse() -> None:
    for block in code_blocks(reference(), "python"):
        ast.parse(block)


def test_files_named_exist() -> None:
    text = reference()
    path = r"((?:specc|examples|docs|tests|generated)/[\w./<>-]+\.(?:py|md|spec|toml))"
    named = set(re.findall(rf"(?:`|# ){path}", text))
    named = {n for n in named if "<" not in n}  # generated/<robot>/... are patterns
    named |= {f"docs/{link}" for link in re.findall(r"\]\((\w[\w-]*\.md)\)", text)}
    assert named
    missing = sorted(n for n in named if not (ROOT / n).is_file())
    assert missing == []


def test_dotted_names_exist() -> None:
    """Every `specc.x.y[.Name]` the reference names is a module, or an attribute of one."""
    import importlib

    names = set(re.findall(r"`(specc(?:\.\w+)+)`", reference()))
    assert names
    for name in sorted(names):
        try:
            importlib.import_module(name)
        except ImportError:
            module, _, attribute = name.rpartition(".")
            assert hasattr(importlib.import_module(module), attribute), f"{name} does not exist"


def _code(line: str) -> str:
    return line.split("#", 1)[0].strip()


def test_quoted_code_is_in_the_files_it_quotes() -> None:
    """A Python example headed `# path/to/file.py` (not marked shortened) quotes that file:
    every line of its code is a line of the file (comments aside)."""
    checked = 0
    for block in code_blocks(reference(), "python"):
        if not block.startswith("# ") or "shortened" in block.splitlines()[0]:
            continue
        source: set[str] = set()
        for line in block.splitlines():
            header = re.match(r"# ((?:examples|specc)/\S+\.py)", line)
            if header is not None:
                source = {_code(x) for x in (ROOT / header.group(1)).read_text().splitlines()}
                continue
            if _code(line):
                assert _code(line) in source, f"{line.strip()!r} is not in the file it quotes"
                checked += 1
    assert checked
