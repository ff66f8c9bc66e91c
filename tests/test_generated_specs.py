"""What `specc check` accepts compiles, imports and builds, for generated specs (issue #23): random
robots whose modules, executive, rule base and procedures refer to each other coherently, with
names drawn from Python's keywords, builtins and dunders and from the generated code's own names,
recursive and empty types, odd ranges and unicode. Whenever check passes, the package compiles,
every generated module imports, and `create_all` builds the robot; the codels are the stubs
`specc skeleton` writes, so nothing but the specs decides."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, Phase, event, given, settings
from hypothesis import strategies as st

from specc.backends import generate_all
from specc.backends.skeleton import needs, write_stubs
from specc.pipeline import load

# Names a Python file cannot take as they are, or that the generated code itself uses.
HOSTILE = ["class", "def", "None", "True", "import", "if", "match", "case", "type", "list", "print", "id",
           "self", "rt", "os", "sys", "mro", "name", "value", "field", "dataclass", "Any", "SPEC", "create_all",
           "__init__", "__dict__", "__slots__", "_", "annotations"]  # (names are ASCII: unicode goes in strings)
# Rule symbols a Python string must escape: backslashes, quotes, unicode.
SYMBOLS = ["ok", "None", "C:\\\\x", "é✓", "a b", '\\"q\\"']
plain = st.from_regex(r"[a-z][a-z0-9]{0,5}", fullmatch=True)
names = st.one_of(plain, plain, plain, st.sampled_from(HOSTILE))
upper_names = st.one_of(st.from_regex(r"[A-Z][A-Z0-9_]{0,5}", fullmatch=True), st.sampled_from(HOSTILE))


def distinct(strategy: st.SearchStrategy[str], size: int) -> st.SearchStrategy[list[str]]:
    return st.lists(strategy, min_size=size, max_size=size, unique_by=str.lower)


@st.composite
def robots(draw: st.DrawFn) -> str:
    """The text of one robot: a module, and maybe an executive, a rule base and procedures."""
    module, enum, struct, other, request, task, poster, codel_a, codel_b, check = draw(distinct(names, 10))
    values = draw(st.lists(upper_names, min_size=1, max_size=3))
    low, high = draw(st.integers(-5, 5)), draw(st.integers(-5, 5))
    recursive = draw(st.booleans())
    field_a, field_b, field_c, input_name = draw(distinct(names, 4))
    text = textwrap.dedent(f"""\
        module {module} {{
          number: {draw(st.integers(0, 10**6))};
          codels: "{module}_codels";
          enum {enum} {{ {", ".join(values)} }}
          struct {other} {{ {field_a}: double; }}
          struct {struct} {{ {field_a}: double; {field_b}: {struct if recursive else other}; }}
          internal_data {{ {field_a}: double; {field_b}: {struct}; {field_c}: int; }}
          request {request} {{
            type: exec;
            task: {task};
            input: {input_name}: double;
            validate: {check};
            fail: {draw(upper_names)};
            codel start: {codel_a};
            codel exec: {codel_b};
            incompatible_with: {request};
          }}
          exec_task {task} {{ period: {draw(st.sampled_from(["10 ms", "1 s", "0.5 min", "1e308 min"]))}; }}
          poster {poster} {{ update: auto; data: {field_a}; }}
        }}
        """)
    if draw(st.booleans()):
        executive, service = draw(distinct(names, 2))
        text += textwrap.dedent(f"""\
            executive {executive} {{
              service {service.upper()} {{
                request: {module}.{request};
                takes: {input_name};
                timeout {{ final: 1 s; }}
                conflicts {{ {service.upper()}: interrupt; }}
              }}
            }}
            """)
    if draw(st.booleans()):
        base, level, verdict = draw(distinct(names, 3))
        symbols = draw(st.lists(st.sampled_from(SYMBOLS), min_size=1, max_size=3, unique=True))
        text += textwrap.dedent(f"""\
            rules {base} {{
              inputs {level}: [{low}, {high}];
              outputs {verdict}: {{{", ".join(f'"{s}"' for s in symbols)}}};
              high: {level} > {low} ==> restrict {verdict} == "{symbols[0]}";
              low: {level} <= {low} ==> restrict {verdict} == "{symbols[-1]}";
            }}
            """)
    if draw(st.booleans()):
        procedures, predicate = draw(distinct(names, 2))
        text += textwrap.dedent(f"""\
            procedures {procedures} {{
              predicate {predicate.upper()}(n: {low}..{high});
              ka Count {{ invocation: !(COUNT $N); body {{ =>({predicate.upper()} $N); }} }}
            }}
            """)
    return text


def builds(folder: Path, text: str) -> str:
    """Why check refused the spec, else 'built' once the package was shown to import and build."""
    spec = folder / "robot.spec"
    spec.write_text(text, encoding="utf-8")
    parsed = load([spec], check=False)
    for item in parsed.program.items if parsed.program is not None else ():
        for wanted in needs(item):
            try:
                write_stubs(wanted, folder)
            except OSError:  # a codel module name no file can take: check says so below
                pass
    loaded = load([spec])
    if loaded.program is None or loaded.errors:
        return f"check refused: {sorted({d.code for d in loaded.errors})}"
    out = folder / "out"
    generate_all(loaded.program, "robot").write(out / "robot")  # what check accepts compiles
    modules = [".".join(p.relative_to(out).with_suffix("").parts).removesuffix(".__init__")
               for p in sorted(out.rglob("*.py"))]
    script = textwrap.dedent(f"""
        import importlib, sys
        sys.path[:0] = [{str(out)!r}, {str(folder)!r}]
        for name in {modules!r}:
            importlib.import_module(name)
        from specc.runtime import functional as rt
        import robot.modules
        print(sorted(robot.modules.create_all(rt.Registry())))
    """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, f"check accepted, but the package does not import or build:\n{text}\n" \
                                   f"{result.stderr[-2000:]}"
    return "built"


# No explain phase: on a failure, the shrunk spec is what helps, and explaining takes minutes.
SETTINGS: dict[str, Any] = {
    "deadline": None, "phases": [Phase.explicit, Phase.reuse, Phase.generate, Phase.shrink],
    "suppress_health_check": [HealthCheck.too_slow, HealthCheck.function_scoped_fixture]}


def run(text: str, tmp_path_factory: pytest.TempPathFactory) -> None:
    event(builds(tmp_path_factory.mktemp("robot"), text))  # `pytest --hypothesis-show-statistics` shows them


@settings(max_examples=25, **SETTINGS)
@given(robots())
def test_what_check_accepts_compiles_imports_and_builds(tmp_path_factory: pytest.TempPathFactory, text: str) -> None:
    run(text, tmp_path_factory)


@pytest.mark.slow
@settings(max_examples=400, **SETTINGS)
@given(robots())
def test_hundreds_of_generated_robots(tmp_path_factory: pytest.TempPathFactory, text: str) -> None:
    run(text, tmp_path_factory)


def test_the_generator_reaches_robots_that_check_accepts(tmp_path: Path) -> None:
    """The property above is not vacuous: a plain draw of the generator checks and builds."""
    text = textwrap.dedent("""\
        module arm {
          number: 1;
          codels: "arm_codels";
          enum mode { SLOW, FAST }
          struct pair { x: double; }
          struct link { x: double; next: pair; }
          internal_data { x: double; next: link; n: int; }
          request grab { type: exec; task: t; input: force: double; validate: ok; fail: SLIP;
                         codel start: go; codel exec: hold; incompatible_with: grab; }
          exec_task t { period: 10 ms; }
          poster pose { update: auto; data: x; }
        }
        """)
    assert builds(tmp_path, text) == "built"
