"""A spec cannot make its generated package run code (issue #23): payloads in every string
position the grammar allows (and in the spec's file and folder names) either are refused by
`specc check`, or compile to a package that parses and whose import runs none of them (a marker
file is never written). Every value of a spec reaches generated code through one escaping
mechanism (`specc.backends.env`): these are its tests."""

from __future__ import annotations

import ast
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from specc.backends import generate_all
from specc.backends.env import Code, UnescapedValue, comment, doc, py, render
from specc.pipeline import load

# Each position holds @P@; the others hold a harmless word. `S` marks a spec string, whose
# payload is written escaped in the spec's own syntax (`\"`, `\\`, `\n`).
SPEC = """\
module drive {
  codels: "@codels@";
  doc: "@module_doc@";
  request Go { type: exec; task: T; codel exec: step; doc: "@request_doc@"; }
  exec_task T { period: 50 ms; doc: "@task_doc@"; }
  poster Pose { data: x; update: auto; doc: "@poster_doc@"; }
  internal_data { x: double; }
}

executive cart {
  codels: "@executive_codels@";
  doc: "@executive_doc@";
  service GO { request: drive.Go; doc: "@service_doc@"; }
}

// Incomplete on purpose: the compiler's findings (in the module's docstring) quote the symbol.
rules policy {
  inputs load: {"@symbol@", "light"};
  outputs speed: {"slow", "fast"};
  light: load == "light" ==> restrict speed == "fast";
}

procedures tasks {
  predicate evaluable NEAR(x: float) = "@predicate_binding@";
  action LOG(text: string) = "@action_binding@";
  ka Say {
    invocation: !(SAY);
    action: (LOG "@goal_string@");
    documentation: "@ka_doc@";
  }
}

system cart {
  modules: drive;
  executive: cart;
  supervisor: tasks;
  extension: "@extension@";
  doc: "@system_doc@";
  worlds { shop: "@world_file@"; }
  mission go { world: shop; goal: !(SAY); doc: "@mission_doc@"; }
}
"""
POSITIONS = ("codels", "module_doc", "request_doc", "task_doc", "poster_doc", "executive_codels", "executive_doc",
             "service_doc", "symbol", "predicate_binding", "action_binding", "goal_string", "ka_doc", "extension",
             "system_doc", "world_file", "mission_doc")
HARMLESS = {"codels": "cart_codels", "executive_codels": "cart_codels", "predicate_binding": "cart_codels.near",
            "action_binding": "cart_codels.log", "extension": "cart_codels", "world_file": "shop.toml",
            "symbol": "heavy"}
CODELS = ("def step(sdi, request):\n    return 'ether'\n\ndef near(ctx, x):\n    return True\n\n"
          "def log(ctx, text):\n    pass\n")
WORLD = "[room]\nwidth = 4.0\nheight = 4.0\n\n[start]\nx = 2.0\ny = 2.0\n"

MARKER = "specc-injected.txt"
WRITE = f"__import__('pathlib').Path('{MARKER}').write_text('x')"
PAYLOADS = (
    f'x" if {WRITE} else "x',  # ends a double-quoted literal inside an expression, and goes on as one
    f"x' if {WRITE} else 'x",
    f'"); {WRITE}; ("',
    f'""" + {WRITE} + """',  # ends a docstring: the module's first statement goes on as an expression
    f"'); {WRITE}; ('",
    f"\n{WRITE}\n",  # a line of its own, after a comment or in a docstring
    f"\\\n{WRITE}",  # a backslash continuing the line before
    "\\N{a} \\x \\u12 \\",  # escapes Python refuses in a (non-raw) literal
    f"\x00 \x1b[31m {WRITE}",  # NUL, ESC
    f"{{{WRITE}}}",  # an f-string's field
    "end with a quote\"",
)


def spec_string(text: str) -> str:
    """`text` as the inside of a spec string literal."""
    return text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n").replace("\t", "\\t")


def robot(folder: Path, position: str, payload: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    text = SPEC
    for name in POSITIONS:
        value = payload if name == position else HARMLESS.get(name, "harmless")
        text = text.replace(f"@{name}@", spec_string(value))
    (folder / "cart.spec").write_text(text, encoding="utf-8")
    (folder / "cart_codels.py").write_text(CODELS, encoding="utf-8")
    (folder / "shop.toml").write_text(WORLD, encoding="utf-8")
    return folder


def compiled_files(folder: Path, out: Path) -> list[Path] | None:
    """The generated files when `specc check` accepts the folder (None when it refuses it)."""
    loaded = load([folder])
    if loaded.program is None or loaded.errors:
        return None
    generate_all(loaded.program, "cart").write(out / "cart")  # what check accepts compiles
    return sorted(out.rglob("*.py"))


def assert_imports_run_no_payload(files: list[Path], out: Path, work: Path) -> None:
    for path in files:
        ast.parse(path.read_text(encoding="utf-8"), str(path))  # valid Python, whatever the spec held
    modules = [".".join(p.relative_to(out).with_suffix("").parts).removesuffix(".__init__") for p in files]
    script = textwrap.dedent(f"""
        import importlib, sys
        sys.path[:0] = [{str(out)!r}, {str(work)!r}]
        for name in {modules!r}:
            try:
                importlib.import_module(name)
            except Exception:
                pass  # a package that cannot import is another issue's: here, no payload may run
    """)
    subprocess.run([sys.executable, "-c", script], cwd=work, capture_output=True, timeout=120)
    assert not (work / MARKER).exists(), "a spec string ran as code when its package was imported"


# Free text: whatever it holds, check accepts it and the package is built with it.
FREE_TEXT = {"module_doc", "request_doc", "task_doc", "poster_doc", "executive_doc", "service_doc", "ka_doc",
             "system_doc", "mission_doc", "symbol", "goal_string"}


@pytest.mark.parametrize("position", POSITIONS)
def test_no_payload_runs_from_any_string_position(position: str, tmp_path: Path) -> None:
    for k, payload in enumerate(PAYLOADS):
        work = tmp_path / f"case{k}"
        folder = robot(work / "robot", position, payload)
        files = compiled_files(folder, work / "generated")
        if position in FREE_TEXT:
            assert files is not None, f"check refused free text at {position}: {payload!r}"
        if files is not None:
            assert_imports_run_no_payload(files, work / "generated", work)


@pytest.mark.parametrize("name", ["x\nimport os; os.system('true')", 'x"""; y', "x\\N{a}", "x\x1b[2J"])
def test_no_payload_runs_from_a_spec_file_or_folder_name(name: str, tmp_path: Path) -> None:
    work = tmp_path / "work"
    folder = robot(work / f"robot {name}", "codels", "cart_codels")
    (folder / "cart.spec").rename(folder / f"cart {name}.spec")
    files = compiled_files(folder, work / "generated")
    assert files is not None
    assert_imports_run_no_payload(files, work / "generated", work)
    header = next(f for f in files if f.name == "__init__.py" and f.parent.name == "cart").read_text()
    assert "\x1b" not in header and "\x00" not in header


def test_the_escapes_keep_every_value_where_it_lands() -> None:
    tricky = 'a"b\'c\\d\ne\x00f\x1b"""g\\N{x}"'
    assert ast.literal_eval(py(tricky)) == tricky
    assert ast.literal_eval(f'"""{doc(tricky)}"""') == tricky.replace("\x00", "\\x00").replace("\x1b", "\\x1b") \
        or ast.parse(f'"""{doc(tricky)}"""')
    assert "\n" not in comment(tricky) and ast.parse(f"# {comment(tricky)}\nx = 1")
    assert ast.literal_eval(py((1, "a", None, 2.5))) == (1, "a", None, 2.5)


def test_a_template_cannot_write_a_string_it_did_not_escape(tmp_path: Path) -> None:
    """The environment refuses any string a template writes without a filter (or Code)."""
    from specc.backends.env import environment

    with pytest.raises(UnescapedValue, match="without saying how it lands"):
        environment().from_string("x = {{ value }}").render(value="1; import os")
    assert environment().from_string("x = {{ value | py }}").render(value='a"b') == 'x = "a\\"b"'
    assert environment().from_string("x = {{ value }}").render(value=Code("f(1)")) == "x = f(1)"
    assert render  # the one renderer every back end uses


def test_control_characters_of_a_spec_never_reach_the_terminal(tmp_path: Path) -> None:
    """A raw ESC in a spec string, quoted by a diagnostic: escaped in the headline, a `?` in the
    source line (the caret stays under its column); each diagnostic's headline is one line."""
    folder = robot(tmp_path / "robot", "codels", "x\x1b[2Jy\x07")
    spec = folder / "cart.spec"
    spec.write_text(spec.read_text(encoding="utf-8").replace("\\n", "\n"), encoding="utf-8")
    result = subprocess.run([sys.executable, "-m", "specc.cli", "check", str(folder)], capture_output=True,
                            text=True, timeout=120)
    shown = result.stdout + result.stderr
    assert result.returncode != 0 and "[bad-python-module]" in shown, shown
    assert "\x1b" not in shown and "\x07" not in shown
    headline = next(line for line in shown.splitlines() if "[bad-python-module]" in line)
    assert "\\x1b[2Jy\\x07" in headline
