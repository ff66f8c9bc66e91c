"""The command line as a user meets it: exit codes, gcc-style messages, no tracebacks,
deterministic output."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import EXAMPLES, ROOT


def specc(*args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "specc.cli", *args], cwd=cwd, capture_output=True, text=True,
                          timeout=120)


BROKEN = """module loco {
  number: 700;
  request Track { type: exec; task: Pump; codel exec: track; }
  exec_task PumpTask { period: 25 ms; }
}
"""


def test_check_reports_gcc_style_with_source_line_and_marker(tmp_path: Path) -> None:
    spec = tmp_path / "loco.spec"
    spec.write_text(BROKEN)
    result = specc("check", str(spec))
    assert result.returncode == 1
    lines = result.stderr.splitlines()
    headline = next(line for line in lines if "[undefined-exec-task]" in line)
    expected = f"{spec}:3:37: error: unknown exec task 'Pump' in module 'loco' (did you mean 'PumpTask'?)"
    assert headline.startswith(expected)
    marker_line = lines[lines.index(headline) + 2]
    assert marker_line.strip().startswith("^~~")
    assert "Traceback" not in result.stderr + result.stdout


def test_verify_stopped_by_the_state_limit_says_so_and_which_parts_it_never_explored() -> None:
    result = specc("verify", str(EXAMPLES / "atrv"), "--requests", "2", "--max-states", "20")
    assert result.returncode == 1, result.stderr  # nothing proved
    assert "INCOMPLETE: the state limit stopped the exploration at 20 states" in result.stdout
    assert "parts not explored at all: PTU-MOVE, PTU-INIT | PICTURE | COMMUNICATE" in result.stdout


@pytest.mark.parametrize(("arguments", "said"), [
    (("compile", "{tug}", "-o", "-"), "'-' names no folder"),
    (("export", "{tug}", "--problem", "shuttle", "-o", "-"), "'-' names no folder"),
    (("run", "{tug}", "--folder", "-"), "'-' names no folder"),
    (("campaign", "{tug}", "--timeout", "nan"), "nan is not a finite number"),
    (("plan", "{tug}", "--problem", "shuttle", "--improve", "99999999999"), "not in the range"),
])
def test_option_values_that_name_nothing_are_usage_errors(tmp_path: Path, arguments: tuple[str, ...],
                                                          said: str) -> None:
    """'-' given for a folder, a NaN for a duration, a budget no planning ends in: said at once
    (exit 2), nothing made (no folder named '-')."""
    result = specc(*(a.format(tug=EXAMPLES / "tug") for a in arguments), cwd=tmp_path)
    assert result.returncode == 2 and said in result.stderr, result.stderr
    assert list(tmp_path.iterdir()) == []


def test_a_diagnostic_on_line_100_says_100_for_every_problem_matcher(tmp_path: Path) -> None:
    """`:100:` is rich's emoji code for 💯: the consoles must print the line number."""
    spec = tmp_path / "long.spec"
    spec.write_text("\n" * 99 + BROKEN.replace("\n", " ", 2))
    result = specc("check", str(spec))
    assert f"{spec}:100:" in result.stderr and "\N{HUNDRED POINTS SYMBOL}" not in result.stderr
    assert re.search(r"^(.+):(\d+):(\d+): error: .* \[undefined-exec-task\]$", result.stderr, re.MULTILINE)


def test_syntax_error_is_one_labelled_message(tmp_path: Path) -> None:
    spec = tmp_path / "bad.spec"
    spec.write_text("module loco {\n  number 700;\n}\n")
    result = specc("check", str(spec))
    assert result.returncode == 1
    assert f"{spec}:2:10: error: unexpected '700'; expected ':'" in result.stderr
    assert "[unexpected-token]" in result.stderr
    assert "Traceback" not in result.stderr


@pytest.mark.parametrize(("written", "meant"), [("latePremptive", "latePreemptive"), ("tsk", "task")])
def test_a_misspelt_keyword_is_named_even_where_the_parser_no_longer_expects_it(written: str, meant: str) -> None:
    from specc.syntax.parser import parse_text

    # A task's preemption is optional after its '}': a typo there reads as the next member's name.
    text = f"domain d {{\n  task T() (t_start, t_end) {{\n  }} {written}\n}}\n"
    (found,) = parse_text(text, "d.spec").diagnostics
    assert found.code == "unexpected-token" and f"'{written}' (did you mean '{meant}'?)" in found.message


@pytest.mark.parametrize("args", [["check", "no/such/file.spec"], ["compile", "no/such/dir"],
                                  ["fmt", "no/such/file.spec"]])
def test_missing_inputs_are_clear_errors(args: list[str]) -> None:
    result = specc(*args)
    assert result.returncode == 2  # the command could not do its work (docs/reference.md §11), no verdict
    assert "no such file or folder" in result.stderr and "[missing-file]" in result.stderr
    assert "Traceback" not in result.stderr


def test_binary_file_is_a_clear_error(tmp_path: Path) -> None:
    spec = tmp_path / "blob.spec"
    spec.write_bytes(b"\xff\xfe\x00module")
    result = specc("check", str(spec))
    assert result.returncode == 1 and "[bad-encoding]" in result.stderr
    assert "Traceback" not in result.stderr
    # Latin-1 in a comment: the line and column of the first byte that is not UTF-8.
    spec.write_bytes("module a {\n  number: 1; // é ".encode() + b"caf\xe9\n}\n")
    assert "blob.spec:2:22: error:" in specc("check", str(spec)).stderr  # é counts one column


@pytest.mark.parametrize("content", [b"def go(sdi, request):\n    return '\xe9t\xe9'\n",  # Latin-1
                                     b"def go(sdi, request):\x00\n    return 'end'\n"])  # a NUL byte
def test_a_codel_module_that_is_not_python_text_is_one_clear_error(tmp_path: Path, content: bytes) -> None:
    (tmp_path / "m.spec").write_text('module m {\n  codels: "m_codels";\n  request Go { type: control; '
                                     'validate: go; }\n}\n')
    (tmp_path / "m_codels.py").write_bytes(content)
    result = specc("check", str(tmp_path))
    shown = result.stdout + result.stderr
    assert result.returncode == 1 and "Traceback" not in shown
    headline = next(line for line in shown.splitlines() if "[python-syntax-error]" in line)
    assert headline.startswith(f"{tmp_path / 'm.spec'}:2:11: error: ") and "m_codels.py:1:" in headline


def test_every_example_checks_from_another_directory(tmp_path: Path) -> None:
    result = specc("check", *(str(EXAMPLES / robot) for robot in ("hilare", "generic", "atrv")), cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("ok: ")


def test_compile_is_deterministic_and_writes_a_manifest(tmp_path: Path) -> None:
    first, second = tmp_path / "a", tmp_path / "b"
    assert specc("compile", str(EXAMPLES / "hilare"), "-o", str(first)).returncode == 0
    assert specc("compile", str(EXAMPLES / "hilare"), "-o", str(second)).returncode == 0
    files = sorted(p.relative_to(first) for p in first.rglob("*") if p.is_file())
    assert Path("hilare/MANIFEST.json") in files and Path("hilare/__init__.py") in files
    for relative in files:
        assert (first / relative).read_bytes() == (second / relative).read_bytes()
    init = (first / "hilare" / "__init__.py").read_text()
    assert init.startswith("# Generated by specc from ") and "DO NOT EDIT" in init


def test_compile_of_a_broken_spec_writes_nothing(tmp_path: Path) -> None:
    spec = tmp_path / "loco.spec"
    spec.write_text(BROKEN)
    result = specc("compile", str(spec), "-o", str(tmp_path / "out"))
    assert result.returncode == 1
    assert not (tmp_path / "out").exists()


def test_check_strict_fails_on_a_warning_for_ci(tmp_path: Path) -> None:
    spec = tmp_path / "rules.spec"
    spec.write_text('rules r {\n  inputs a: [0, 1], unused: [0, 1];\n  outputs o: {"x"};\n'
                    '  r1: a > 0.5 ==> restrict o == "x";\n}\n')
    plain, strict = specc("check", str(spec)), specc("check", "--strict", str(spec))
    assert "[input-never-read]" in plain.stderr and plain.returncode == 0
    assert "[input-never-read]" in strict.stderr and strict.returncode == 1


def test_check_json_gives_every_diagnostic_as_data(tmp_path: Path) -> None:
    import json

    spec = tmp_path / "loco.spec"
    spec.write_text(BROKEN)
    result = specc("check", "--json", "loco.spec", cwd=tmp_path)
    assert result.returncode == 1 and result.stderr == ""
    document = json.loads(result.stdout)
    assert document["format"] == "specc-diagnostics/1" and document["files"] == ["loco.spec"]
    found = next(d for d in document["diagnostics"] if d["code"] == "undefined-exec-task")
    assert (found["file"], found["line"], found["column"], found["severity"]) == ("loco.spec", 3, 37, "error")
    assert document["errors"] == sum(d["severity"] == "error" for d in document["diagnostics"]) >= 1


def test_fmt_check_reports_and_fmt_rewrites(tmp_path: Path) -> None:
    spec = tmp_path / "loco.spec"
    spec.write_text("module loco{number:700; // the number\n}\n")
    result = specc("fmt", "--check", str(spec))
    assert result.returncode == 1 and result.stdout == f"would reformat {spec}\n"  # the files, not the diff
    assert spec.read_text() == "module loco{number:700; // the number\n}\n"
    shown = specc("fmt", "--diff", str(spec))  # shows the change, makes none
    assert shown.returncode == 0 and "+  number: 700;" in shown.stdout and "would reformat" in shown.stderr
    assert shown.stdout.splitlines()[-1].startswith(" }")  # the patch alone: `patch -p0` reads it
    assert spec.read_text() == "module loco{number:700; // the number\n}\n"
    assert specc("fmt", str(spec)).returncode == 0
    assert spec.read_text() == "module loco {\n  number: 700;  // the number\n}\n"
    assert specc("fmt", "--check", str(spec)).returncode == 0


@pytest.mark.parametrize("command", ["check", "compile", "fmt", "verify", "graph", "rules"])
def test_help_has_examples(command: str) -> None:
    result = specc(command, "--help")
    assert result.returncode == 0 and "Example: specc " + command in result.stdout


def specc_unprivileged(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    """specc without the power to ignore file permissions (root keeps it unless told otherwise)."""
    prefix: list[str] = []
    if os.geteuid() == 0:
        setpriv = shutil.which("setpriv")
        if setpriv is None:
            pytest.skip("running as root without setpriv: permissions cannot be tested")
        drop = "-dac_override,-dac_read_search"
        prefix = [setpriv, f"--bounding-set={drop}", f"--inh-caps={drop}"]
    return subprocess.run([*prefix, sys.executable, "-m", "specc.cli", *args], cwd=cwd, capture_output=True,
                          text=True, timeout=120)


def test_unreadable_file_and_folder_are_gcc_style_errors(tmp_path: Path) -> None:
    (tmp_path / "hidden.spec").write_text("module a { number: 1; }\n")
    (tmp_path / "hidden.spec").chmod(0)
    robot = tmp_path / "robot"
    (robot / "locked").mkdir(parents=True)
    (robot / "ok.spec").write_text("module b { number: 2; }\n")
    (robot / "locked" / "c.spec").write_text("module c { number: 3; }\n")
    (robot / "locked").chmod(0)
    try:
        for command in ("check", "fmt", "compile"):
            result = specc_unprivileged(command, "hidden.spec", cwd=tmp_path)
            assert result.returncode == 2, result.stderr  # could not do its work (docs/reference.md §11)
            assert "hidden.spec:1:1: error: cannot read" in result.stderr and "[unreadable-file]" in result.stderr
        # A folder that cannot be listed is not silently skipped.
        result = specc_unprivileged("check", "robot", cwd=tmp_path)
        assert result.returncode == 2 and "[unreadable-folder]" in result.stderr, result.stderr
    finally:
        (robot / "locked").chmod(0o755)
    assert "Traceback" not in result.stderr


def test_an_unreadable_codel_module_is_unreadable_not_a_syntax_error(tmp_path: Path) -> None:
    (tmp_path / "bot_codels").mkdir()
    codels = tmp_path / "bot_codels" / "drive.py"
    codels.write_text("def stop(sdi, request):\n    return 'ether'\n")
    (tmp_path / "drive.spec").write_text('module drive {\n  codels: "bot_codels.drive";\n'
                                         "  request Stop { type: exec; task: T; codel exec: stop; }\n"
                                         "  exec_task T { period: 100 ms; }\n}\n")
    codels.chmod(0)
    try:
        result = specc_unprivileged("check", "drive.spec", cwd=tmp_path)
    finally:
        codels.chmod(0o644)
    assert result.returncode == 2 and "[unreadable-file]" in result.stderr, result.stderr
    assert "cannot read Python module 'bot_codels.drive' (bot_codels/drive.py)" in result.stderr
    assert "[python-syntax-error]" not in result.stderr and str(tmp_path) not in result.stderr


def test_fmt_of_a_read_only_file_is_an_error_not_a_traceback(tmp_path: Path) -> None:
    spec = tmp_path / "ro.spec"
    spec.write_text("module a {number: 1;}\n")
    spec.chmod(0o444)
    result = specc_unprivileged("fmt", "ro.spec", cwd=tmp_path)
    assert result.returncode == 1 and "ro.spec:1:1: error: cannot rewrite" in result.stderr, result.stderr
    assert "[unwritable-file]" in result.stderr and "Traceback" not in result.stderr
    assert spec.read_text() == "module a {number: 1;}\n"


def test_compile_into_a_file_is_an_error_not_a_traceback(tmp_path: Path) -> None:
    spec = tmp_path / "a.spec"
    spec.write_text("module a { number: 1; }\n")
    (tmp_path / "out").write_text("not a folder")
    result = specc("compile", str(spec), "-o", str(tmp_path / "out"))
    assert result.returncode == 1 and "[unwritable-output]" in result.stderr
    assert "Traceback" not in result.stderr


def test_compile_never_deletes_outside_the_package_whatever_the_old_manifest_says(tmp_path: Path) -> None:
    spec = tmp_path / "a.spec"
    spec.write_text("module a { number: 1; }\n")
    victim = tmp_path / "precious.txt"
    victim.write_text("mine")
    (tmp_path / "out" / "a" / "sub").mkdir(parents=True)
    (tmp_path / "out" / "a" / "MANIFEST.json").write_text(
        '{"files": [{"path": "../../precious.txt"}, {"path": "' + str(victim) + '"}, {"path": 5}, {"path": "sub"}]}')
    result = specc("compile", str(spec), "-o", str(tmp_path / "out"))
    assert result.returncode == 0, result.stderr
    assert victim.read_text() == "mine" and (tmp_path / "out" / "a" / "sub").is_dir()


def test_compile_writes_the_same_package_from_any_folder(tmp_path: Path) -> None:
    """The package names the specs from the robot's folder: compiled from the repository's root,
    from examples/ or from the robot's own folder, the files are the same, byte for byte (a CI
    diffing generated code must not depend on where it runs)."""
    trees = []
    for number, (cwd, given) in enumerate([(ROOT, "examples/tug"), (EXAMPLES, "tug"), (EXAMPLES / "tug", ".")]):
        output = tmp_path / f"out{number}"
        result = specc("compile", given, "-o", str(output), cwd=cwd)
        assert result.returncode == 0, result.stderr
        trees.append({p.relative_to(output): p.read_bytes() for p in sorted(output.rglob("*.py")) + sorted(
            output.rglob("*.json"))})
    assert trees[0] == trees[1] == trees[2]
    assert b'"tug/planning.spec"' in trees[0][Path("tug/__init__.py")]


def test_a_package_whose_modules_all_went_leaves_no_folder_to_import(tmp_path: Path) -> None:
    """Compiling again without the rule bases removes rules/ whole: an empty folder left there
    would still import (a namespace package), and a codel importing it would not fail where it
    should."""
    (tmp_path / "a.spec").write_text("module a { number: 1; }\n")
    rules = tmp_path / "r.spec"
    rules.write_text('rules r {\n  inputs x: [0, 1];\n  outputs o: {"y"};\n  r1: x > 0.5 ==> restrict o == "y";\n}\n')
    first = specc("compile", str(tmp_path / "a.spec"), str(rules), "-o", str(tmp_path / "out"), "--robot", "bot")
    assert first.returncode == 0 and (tmp_path / "out" / "bot" / "rules").is_dir(), first.stderr
    (tmp_path / "out" / "bot" / "rules" / "__pycache__").mkdir(exist_ok=True)
    second = specc("compile", str(tmp_path / "a.spec"), "-o", str(tmp_path / "out"), "--robot", "bot")
    assert second.returncode == 0, second.stderr
    assert not (tmp_path / "out" / "bot" / "rules").exists()
    assert not list((tmp_path / "out").rglob("*.tmp"))


def test_files_are_replaced_whole_and_a_read_only_one_is_refused(tmp_path: Path) -> None:
    from specc.files import write_text_atomically

    kept = tmp_path / "kept.txt"
    kept.write_text("old")
    kept.chmod(0o640)
    write_text_atomically(kept, "new")
    assert kept.read_text() == "new" and kept.stat().st_mode & 0o777 == 0o640
    locked = tmp_path / "locked.txt"
    locked.write_text("mine")
    locked.chmod(0o444)
    result = subprocess.run(
        [*(["setpriv", "--bounding-set=-dac_override,-dac_read_search", "--inh-caps=-dac_override,-dac_read_search"]
           if os.geteuid() == 0 and shutil.which("setpriv") else []), sys.executable, "-c",
         "import sys; from pathlib import Path; from specc.files import write_text_atomically\n"
         "try:\n    write_text_atomically(Path(sys.argv[1]), 'x')\nexcept PermissionError:\n    sys.exit(3)",
         str(locked)], cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert result.returncode == 3, result.stderr
    assert locked.read_text() == "mine" and sorted(p.name for p in tmp_path.iterdir()) == ["kept.txt", "locked.txt"]


@pytest.mark.parametrize(("name", "content", "expected"), [
    ("bom.spec", "\ufeffmodule a { number: 1; }\n", "ok: 1 file(s)"),
    ("crlf.spec", "module a {\r\n\tnumber: 1;\r\n}\r\n", "ok: 1 file(s)"),
    ("empty.spec", "", "ok: 1 file(s), 0 block(s)"),
    ("brace.spec", "}", "brace.spec:1:1: error: unexpected '}'"),
    # Not kept as infinity: `specc fmt` would write it back as `inf`, a name.
    ("huge.spec", "module a { number: 1e999; }\n", "huge.spec:1:20: error: '1e999' is too large a number"),
    # The excerpt is the line the lexer counted, even past a U+2028 or a form feed.
    ("sep.spec", "module a { number: 1;\u2028 }\n", "1:22: error: unexpected character 'U+2028'"),
    ("sep2.spec", "module a {\f\n number: 1; $ }\n", "2:13: error: unexpected character '$'"),
])
def test_odd_inputs_give_a_clean_result(tmp_path: Path, name: str, content: str, expected: str) -> None:
    spec = tmp_path / name
    spec.write_bytes(content.encode("utf-8"))
    result = specc("check", name, cwd=tmp_path)
    assert expected in result.stdout + result.stderr
    assert result.returncode in (0, 1) and "Traceback" not in result.stderr
    if name == "sep2.spec":  # the excerpt shows line 2, not the empty "line" after the form feed
        assert "\n     number: 1; $ }\n" in result.stderr


def test_symbolic_link_loops_are_clear_errors(tmp_path: Path) -> None:
    (tmp_path / "loop").symlink_to("loop")
    robot = tmp_path / "robot"
    robot.mkdir()
    (robot / "a.spec").write_text("module a { number: 1; }\n")
    (robot / "again").symlink_to(robot)
    result = specc("check", "loop", "robot", cwd=tmp_path)
    assert "'loop' is a broken or looping symbolic link [missing-file]" in result.stderr
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert specc("check", "robot", cwd=tmp_path).stdout.startswith("ok: 1 file(s)")


def test_a_file_named_twice_is_read_once(tmp_path: Path) -> None:
    robot = tmp_path / "robot"
    robot.mkdir()
    (robot / "a.spec").write_text("module a { number: 1; }\n")
    (robot / "link.spec").symlink_to(robot / "a.spec")
    result = specc("check", "robot", "robot/a.spec", "./robot/../robot/a.spec", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("ok: 1 file(s), 1 block(s)")


def test_compile_refuses_a_package_name_python_cannot_import(tmp_path: Path) -> None:
    (tmp_path / "class.spec").write_text("module a { number: 1; }\n")
    result = specc("compile", "class.spec", "-o", "out", cwd=tmp_path)
    assert result.returncode == 1 and "not a valid Python package name" in result.stderr
    assert not (tmp_path / "out").exists()
    for shadowed in ("sys", "specc"):  # importable names, but another module answers to them
        named = specc("compile", "class.spec", "-o", "out", "--robot", shadowed, cwd=tmp_path)
        assert named.returncode == 1 and f"'{shadowed}' names a module Python imports first" in named.stderr
    assert not (tmp_path / "out").exists()


def python(script: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    """`script` run by a new Python process in `cwd` (what happens around the command's main())."""
    return subprocess.run([sys.executable, "-c", script], cwd=cwd, capture_output=True, text=True, timeout=60)


def test_an_internal_bug_is_one_line_not_a_traceback(tmp_path: Path) -> None:
    # Simulate a bug in specc: the front end raises an unexpected exception.
    result = python("import sys, specc.pipeline as p\n"
                    "def boom(*a, **k):\n    raise ValueError('boom')\n"
                    "p.load = boom\nimport specc.cli as c\nc.load = boom\nsys.argv = ['specc', 'check', 'x.spec']\n"
                    "c.main()\n", tmp_path)
    assert result.returncode == 2
    assert "internal error: ValueError: boom" in result.stderr and "SPECC_DEBUG=1" in result.stderr
    assert "Traceback" not in result.stderr


def test_the_command_ends_without_teardown_but_runs_exit_handlers_and_keeps_its_exit_code(tmp_path: Path) -> None:
    # main() ends the process at once (os._exit); what a library registered with atexit still runs.
    (tmp_path / "bad.spec").write_text("module a { number: x; }\n")
    result = python("import atexit, pathlib, sys\n"
                    "atexit.register(lambda: pathlib.Path('handler-ran').write_text('yes'))\n"
                    "import specc.cli as c\nsys.argv = ['specc', 'check', 'bad.spec']\nc.main()\n"
                    "pathlib.Path('after-main').write_text('main returned')\n", tmp_path)
    assert result.returncode == 1 and "bad.spec:1:" in result.stderr and "1 error(s)" in result.stderr
    assert (tmp_path / "handler-ran").read_text() == "yes"
    assert not (tmp_path / "after-main").exists()

def test_verify_options_of_procedures_without_a_goal_are_refused(tmp_path: Path) -> None:
    result = specc("verify", str(EXAMPLES / "tug"), "--pnml", str(tmp_path / "net.pnml"), "--fact", "(BUSY)")
    assert result.returncode == 2 and "--fact, --pnml: for verifying procedures only; add --goal" in result.stderr
    assert not (tmp_path / "net.pnml").exists()


def test_replay_refuses_a_time_window_that_holds_nothing(tmp_path: Path) -> None:
    (tmp_path / "events.jsonl").write_text('{"t": 0, "kind": "mission-start"}\n')
    for args, said in ((("--from", "50", "--to", "10"), "--from 50 is after --to 10"),
                       (("--from", "nan"), "--from nan: give a mission time in seconds")):
        result = specc("replay", str(tmp_path), *args)
        assert result.returncode == 2 and said in result.stderr, result.stderr

def test_verify_proves_or_refutes_with_a_trace_and_exit_code(tmp_path: Path) -> None:
    proved = specc("verify", str(EXAMPLES / "generic"), "--executive", "fig35", "--requests", "1")
    assert proved.returncode == 0, proved.stderr
    assert proved.stdout.count(": holds - ") == 5 and "states" in proved.stdout
    from tests.test_verify import robot

    spec = robot(tmp_path, 'backAnyway: event == "START", service == "BACK" ==> restrict status == "OK";',
                 policy="interrupt")
    refuted = specc("verify", str(spec[0]))
    assert refuted.returncode == 1
    assert "exclusion: REFUTED" in refuted.stdout and "2. task: RQST EXEC BACK" in refuted.stdout
    ambiguous = specc("verify", str(EXAMPLES / "generic"))
    assert ambiguous.returncode == 2 and "pick one with --executive" in ambiguous.stderr
    assert "Traceback" not in ambiguous.stderr + refuted.stderr


def test_compile_warns_about_rule_bases_that_leave_inputs_unsettled(tmp_path: Path) -> None:
    result = specc("compile", str(EXAMPLES / "generic"), "-o", str(tmp_path))
    assert result.returncode == 0, result.stderr
    warnings = [line for line in result.stderr.splitlines() if "[rules-unsettled]" in line]
    # Fig 3.8 is "quelques règles": incomplete on its own. The executives' controllers are complete,
    # and the hand-written §3.8.1 rules are completed by the generated ones, so neither is reported.
    assert len(warnings) == 1 and "rule base 'diagnosis'" in warnings[0] and ": warning: " in warnings[0]
    listed = specc("rules", str(EXAMPLES / "generic"))
    assert "executive generic: resource controller" in listed.stdout
    assert listed.stdout.count("complete and consistent for every input") == 2
    # A base an executive joins is judged with the controller it completes, not alone: --strict
    # passes on Hilare, whose own rules decide only where they apply.
    strict = specc("rules", "--strict", str(EXAMPLES / "hilare"))
    assert strict.returncode == 0, strict.stdout
    assert "rules hilare_controller: joined to the resource controller of executive 'hilare'" in strict.stdout


def test_unsettled_inputs_are_counted_per_kind_and_the_inconsistent_ones_shown_first(tmp_path: Path) -> None:
    # Speed 'hot' leaves status undetermined whatever the load (one incomplete case), and a
    # heavy load at speed 'fast' is both OK and STOP (one inconsistent case: loads 4 and 5), while
    # 'slow' settles it (OK).
    spec = tmp_path / "base.spec"
    spec.write_text("""rules base {
  inputs speed: {"slow", "fast", "hot"}, load: {1, 2, 3, 4, 5};
  outputs status: {"OK", "STOP"};
  r1: speed == "slow" ==> restrict status == "OK";
  r2: speed == "fast" ==> restrict status == "OK";
  r3: speed == "fast", load oneof [4, 5] ==> restrict status == "STOP";
}
""")
    compiled = specc("compile", str(spec), "-o", str(tmp_path / "out"))
    warning = next(line for line in compiled.stderr.splitlines() if "[rules-unsettled]" in line)
    assert "2 case(s) of inputs unsettled (1 inconsistent, 1 incomplete), e.g. inconsistent:" in warning
    assert "when speed=fast, load=4 | 5 (rules fired: r2, r3)" in warning
    shown = specc("rules", str(spec), "--limit", "1")
    listed = shown.stdout.splitlines()
    assert listed[listed.index("  ... 1 more (--limit 0 shows all)") - 1].startswith("  inconsistent: ")
    assert "  2 case(s) of inputs unsettled: 1 inconsistent, 1 incomplete" in listed
    # A report by default (exit 0); with --strict, for CI, an unsettled case fails.
    assert shown.returncode == 0 and specc("rules", str(spec), "--strict").returncode == 1
    assert specc("rules", str(EXAMPLES / "tug"), "--strict").returncode == 0


def test_verify_procedures_reports_findings_traces_queries_and_pnml(tmp_path: Path) -> None:
    pnml = tmp_path / "hilare.pnml"
    result = specc("verify", str(EXAMPLES / "hilare"), "--goal", "!(COLLECT-OBJECTS 1)", "--fail", "ARM-OBJ",
                   "--reach", "Explore:254; TakeObject:236", "--steps", "3", "--pnml", str(pnml))
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0].startswith("net of CollectObjects") and f"wrote {pnml} (the reduced net explored)" in lines
    # The PNML is the net whose states are counted: the reduced one, as printed.
    explored = next(line for line in lines if line.startswith("explored: the unfolded net reduced to "))
    places, transitions = (int(n) for n in re.findall(r"(\d+) of its \d+ (?:places|transitions)", explored))
    written = pnml.read_text(encoding="utf-8")
    assert written.count("<place ") == places and written.count("<transition ") == transitions
    assert any(re.match(r"\d+ states of the reduced net in ", line) for line in lines)
    assert any(line.startswith("no-way-out: Explore, Modelise cycle forever") for line in lines)
    assert any(line.startswith("reach Explore:254; TakeObject:236: yes") for line in lines)
    assert "    goal COLLECT-OBJECTS: CollectObjects fails" in lines  # the last of the trace's 3 steps
    assert pnml.read_text(encoding="utf-8").startswith("<?xml")
    strict = specc("verify", str(EXAMPLES / "hilare"), "--goal", "!(COLLECT-OBJECTS 1)", "--strict")
    assert strict.returncode == 1 and "endless-cycle: Explore, Modelise" in strict.stdout


def test_verify_procedures_rejects_bad_goals_and_unrepresentable_procedures(tmp_path: Path) -> None:
    garbled = specc("verify", str(EXAMPLES / "hilare"), "--goal", "COLLECT-OBJECTS 1")
    assert garbled.returncode == 2 and "is not a goal" in garbled.stderr
    query = specc("verify", str(EXAMPLES / "hilare"), "--goal", "!(COLLECT-OBJECTS 1)", "--reach", "Explore:999")
    assert query.returncode == 2 and "no statement at Explore:999: its statements are on lines" in query.stderr
    spec = tmp_path / "tasks.spec"
    spec.write_text("procedures t {\n  predicate closed DOOR(s: {OPEN});\n  predicate GO();\n"
                    "  ka Go { invocation: !(GO); body { #(DOOR OPEN); } }\n}\n", encoding="utf-8")
    rejected = specc("verify", str(spec), "--goal", "!(GO)")
    assert rejected.returncode == 2
    assert f"{spec}:4:37: error: '#' (preserve/maintain) has no Petri-net equivalent" in rejected.stderr
    assert "[unsupported-goal]" in rejected.stderr
    assert "Traceback" not in garbled.stderr + query.stderr + rejected.stderr


def test_graph_draws_the_procedures_net_or_one_ka(tmp_path: Path) -> None:
    whole = specc("graph", "--net", str(EXAMPLES / "hilare"), "--goal", "!(COLLECT-OBJECTS 1)", "-o",
                  str(tmp_path / "net.svg"))
    assert whole.returncode == 0, whole.stderr
    one = specc("graph", "--net", str(EXAMPLES / "hilare"), "--goal", "!(COLLECT-OBJECTS 1)", "--ka", "TakeObject",
                "-o", str(tmp_path / "take.svg"))
    assert one.returncode == 0, one.stderr
    everything, take = ((tmp_path / name).read_text(encoding="utf-8") for name in ("net.svg", "take.svg"))
    assert "Explore:254" in everything and "Explore:254" not in take and "TakeObject:236" in take
    unknown = specc("graph", "--net", str(EXAMPLES / "hilare"), "--goal", "!(COLLECT-OBJECTS 1)", "--ka", "Nope")
    assert unknown.returncode == 2 and "KA 'Nope' is not among the KAs the goal reaches" in unknown.stderr
    goalless = specc("graph", "--net", str(EXAMPLES / "hilare"))
    assert goalless.returncode == 2 and "--goal" in goalless.stderr and "Traceback" not in goalless.stderr


def test_verify_procedures_says_when_it_stopped_short() -> None:
    short = specc("verify", str(EXAMPLES / "hilare"), "--goal", "!(COLLECT-OBJECTS 1)", "--max-states", "500")
    assert short.returncode == 0 and "500 states of the reduced net in" in short.stdout
    assert "more not explored" in short.stdout
    assert "no finding" not in short.stdout  # nothing is established about what was not explored
    assert "deadlocks, cycles and dead statements are not established" in short.stderr


def test_plan_prints_the_plan_checked_by_the_validator_and_draws_its_timeline(tmp_path: Path) -> None:
    picture = tmp_path / "m1.png"
    result = specc("plan", str(EXAMPLES / "atrv"), "--problem", "M1", "--domain", "model1", "--no-exact",
                   "-o", str(picture))
    assert result.returncode == 0, result.stderr
    assert "problem M1_model1 for domain model1" in result.stdout
    assert "COMMUNICATE(W1)" in result.stdout and "strongly controllable" in result.stdout
    assert "validator: the plan is valid" in result.stdout
    assert picture.read_bytes().startswith(b"\x89PNG")


def test_plan_with_a_short_horizon_lists_the_dropped_goals_and_why() -> None:
    result = specc("plan", str(EXAMPLES / "atrv"), "--problem", "M4_model1", "--horizon", "300", "--no-exact")
    assert result.returncode == 0, result.stderr
    dropped = [line for line in result.stdout.splitlines() if "DROPPED" in line]
    assert any("COMMUNICATION(W4)" in line and "impossible even alone" in line for line in dropped)


@pytest.mark.parametrize(("controllability", "w2_dropped"), [("strong", True), ("pseudo", False)])
def test_plan_asks_the_controllability_the_user_chooses(controllability: str, w2_dropped: bool) -> None:
    result = specc("plan", str(EXAMPLES / "atrv"), "--problem", "M4_model1", "--no-exact",
                   "--controllability", controllability)
    assert result.returncode == 0, result.stderr
    dropped = [line for line in result.stdout.splitlines() if "DROPPED" in line]
    assert any("COMMUNICATION(W2)" in line for line in dropped) == w2_dropped
    assert {"strong": "strongly controllable", "pseudo": "pseudo-controllable"}[controllability] in result.stdout
    if controllability == "pseudo":
        assert "t_svisi2=152.00" in result.stdout  # the opening it waits for
    # What the validator's verdict covers: every instant nature may pick, or the dates assumed.
    assert ("window instant nature may pick" in result.stdout) == (controllability == "strong")
    assert ("contingent instants at the dates it assumes" in result.stdout) == (controllability == "pseudo")


def test_plan_replans_from_facts_given_on_the_command_line() -> None:
    result = specc("plan", str(EXAMPLES / "atrv"), "--problem", "M1_model1", "--no-exact", "--now", "170",
                   "--fact", "AT_ROBOT_X() = 4", "--fact", "AT_ROBOT_Y() = 0", "--fact", "PICTURE(OBJ1, 0, 0) = DONE",
                   "--fact", "PICTURE(OBJ2, 4, 0) = DONE", "--goal", "29", "--goal", "30", "--goal", "39")
    assert result.returncode == 0, result.stderr
    assert "MOVE(4, 0, 3, -3)" in result.stdout and "TAKE_PICTURE(OBJ1" not in result.stdout


@pytest.mark.parametrize(("args", "message"), [
    (("--problem", "M1"), "ambiguous (M1_model1, M1_model2); add --domain"),
    (("--problem", "M9"), "no problem 'M9'"),
    (("--problem", "M1_model1", "--horizon", "-5"), "--horizon must be a positive number of seconds, not -5"),
    (("--problem", "M1_model1", "--horizon", "nan"), "--horizon must be a positive number of seconds, not nan"),
    (("--problem", "M1_model1", "--now", "-5"), "--now must be a mission time of 0 s or more, not -5"),
    (("--problem", "M1_model1", "--fact", "AT_ROBOT_X = 3"), "is not a fact"),
    # Facts are checked against the domain: arity, each argument's and the value's domain, one value each.
    (("--problem", "M1_model1", "--now", "10", "--fact", "PTU_POSITION() = SIDEWAYS"),
     "fact 'PTU_POSITION() = SIDEWAYS': SIDEWAYS is not one of"),
    (("--problem", "M1_model1", "--fact", "PTU_POSITION(3) = STRAIGHT"), "PTU_POSITION takes 0 argument(s), 1 given"),
    (("--problem", "M1_model1", "--fact", "AT_ROBOT_X() = abc"), "fact 'AT_ROBOT_X() = abc': abc is not a number"),
    (("--problem", "M1_model1", "--fact", "AT_ROBOT_X() = 2", "--fact", "AT_ROBOT_X() = 3"),
     "AT_ROBOT_X() is already 2: give one value"),
    (("--problem", "M1_model1", "--fact", "NOWHERE() = 2"), "domain 'model1' has no attribute NOWHERE"),
    (("--problem", "M1_model1", "--goal", "5"), "no goal on line(s) 5"),
])
def test_plan_bad_input_is_one_clear_error(args: tuple[str, ...], message: str) -> None:
    result = specc("plan", str(EXAMPLES / "atrv"), *args)
    assert result.returncode == 2  # bad input, not "no plan" (1)
    assert message in result.stderr and "Traceback" not in result.stderr


@pytest.mark.parametrize(("args", "message"), [
    (("--now", "900"),  # the mission must end by 800 s: contradictory constraints
     "no plan: no plan satisfies the problem's required assertions and constraints"),
    (("--horizon", "1"), "no plan: every goal is dropped, for the reasons above"),  # unsolvable
])
def test_plan_without_a_plan_says_why_and_fails(args: tuple[str, ...], message: str) -> None:
    result = specc("plan", str(EXAMPLES / "atrv"), "--problem", "M1_model1", "--no-exact", *args)
    assert result.returncode == 1
    assert message in result.stdout and "Traceback" not in result.stderr


def test_export_writes_pddl_and_says_what_it_could_not_express(tmp_path: Path) -> None:
    result = specc("export", str(EXAMPLES / "atrv"), "--problem", "M1_model2", "-o", str(tmp_path))
    assert result.returncode == 0, result.stderr
    assert "(:durative-action" in (tmp_path / "domain.pddl").read_text().lower()
    assert "(:init" in (tmp_path / "problem.pddl").read_text().lower()
    notes = [line for line in result.stdout.splitlines() if line.startswith("not expressed:")]
    assert any("priorit" in line for line in notes) and any("contingent" in line for line in notes)


def test_export_leaves_the_in_progress_markers_out_unless_kept(tmp_path: Path) -> None:
    compact, full = tmp_path / "compact", tmp_path / "full"
    for folder, extra in ((compact, ()), (full, ("--keep-markers",))):
        result = specc("export", str(EXAMPLES / "atrv"), "--problem", "M1_model1", "-o", str(folder), *extra)
        assert result.returncode == 0, result.stderr
        said = "only mark a task in progress are left out" in result.stdout
        assert said is (folder == compact)
    assert "robot_status_moving" not in (compact / "domain.pddl").read_text().lower()
    assert "robot_status_moving" in (full / "domain.pddl").read_text().lower()


def test_an_operator_written_a_character_short_is_named() -> None:
    from specc.syntax.parser import parse_text

    text = 'rules q {\n  inputs x: [0, 10];\n  outputs o: {"a"};\n  q1: x < 5 => restrict o == "a";\n}\n'
    (found,) = parse_text(text, "q.spec").diagnostics
    assert found.code == "unexpected-token" and "unexpected '=' (did you mean '==>'?)" in found.message



def test_a_misspelt_keyword_read_as_a_property_s_name_is_named() -> None:
    """`requst Goto {` fails at 'Goto' (a property `requst: ...` was the parser's reading): the
    word before it is the misspelt keyword."""
    from specc.syntax.parser import parse_text

    text = "module m {\n  number: 1;\n  requst Goto { type: control; }\n}\n"
    (found,) = parse_text(text, "m.spec").diagnostics
    assert (found.span.line, found.span.column) == (3, 10)
    assert "unexpected 'Goto' after 'requst' (did you mean 'request'?)" in found.message
    (plain,) = parse_text(text.replace("requst", "pigeon"), "m.spec").diagnostics  # close to no keyword
    assert "did you mean" not in plain.message


def test_a_word_processor_s_quote_or_sign_is_named_with_the_character_to_write() -> None:
    from specc.syntax.parser import parse_text

    (quote,) = parse_text('module m {\n  codels: \u201cm_codels\u201d;\n}\n', "m.spec").diagnostics
    assert quote.code == "unexpected-character" and (quote.span.line, quote.span.column) == (2, 11)
    assert "unexpected character '\u201c' here (a word processor's character: write '\"')" in quote.message
    rule = 'rules r {\n  inputs x: [0, 9];\n  outputs o: {"a"};\n  q: x \u2264 5 ==> restrict o == "a";\n}\n'
    (sign,) = parse_text(rule, "r.spec").diagnostics
    assert "(a word processor's character: write '<=')" in sign.message


def test_a_brace_missing_or_one_too_many_above_the_error_is_suspected_from_the_indentation() -> None:
    """The parser fails at the next block, lines below the mistake: the braces open there, against
    the line's indentation, point back at it."""
    from specc.syntax.parser import parse_text

    module = ("module m {\n  number: 1;\n  request Go {\n    type: exec;\n    task: T;\n  }\n"
              "  exec_task T { period: 10 ms; }\n}\n")
    (missing,) = parse_text(module.replace("    task: T;\n  }\n", "    task: T;\n\n"), "m.spec").diagnostics
    assert (missing.span.line, missing.code) == (7, "unexpected-token")
    assert missing.message.endswith("; is a '}' missing above? the '{' of line 3 is still open here")
    (extra,) = parse_text(module.replace("    task: T;\n  }\n", "    task: T;\n  }}\n"), "m.spec").diagnostics
    assert extra.span.line == 7 and extra.message.endswith("; is the '}' of line 6 one too many? It closed the '{' "
                                                           "of line 1")
    (inline,) = parse_text("module m {\n  request Go { type control; }\n}\n", "m.spec").diagnostics
    assert "'}'" not in inline.message  # a mistake inside a block written on one line: no brace to blame
    # A value missing before the '}' (the brace is the unexpected token), a file written flush left:
    # no guess at braces where adding or removing one would not mend the file.
    (value,) = parse_text("module m {\n  request Go {\n    type:\n  }\n}\n", "m.spec").diagnostics
    (flush,) = parse_text('module m {\nnumber: 1;\ncodels "m_codels";\n}\n', "m.spec").diagnostics
    assert "is a '}' missing" not in value.message + flush.message and "too many" not in value.message + flush.message


def test_a_negative_number_where_none_has_a_meaning_is_said_so() -> None:
    from specc.syntax.parser import parse_text

    text = "system s {\n  body {\n    wheel_base: -0.5;\n  }\n}\n"
    (found,) = parse_text(text, "s.spec").diagnostics
    assert found.code == "unexpected-token" and (found.span.line, found.span.column) == (3, 17)
    assert "unexpected '-' (a negative number has no meaning here: this value must be 0 or more)" in found.message
    (other,) = parse_text(text.replace("-0.5", "-x"), "s.spec").diagnostics  # a name: no such hint
    assert "negative number" not in other.message
    listed = "procedures p {\n  type LEVEL = {-1, 0, 1};\n}\n"  # in a list a negative value may mean something
    assert all("negative number" not in d.message for d in parse_text(listed, "p.spec").diagnostics)

def test_skeleton_writes_codels_where_specc_run_imports_them(tmp_path: Path) -> None:
    # docs/your-robot.md's step 1: a module in a subfolder, no system block yet. The stubs go to
    # the robot's folder given to the command (not beside the module's spec), and once a system
    # block exists, to its folder.
    robot = tmp_path / "bot"
    (robot / "modules").mkdir(parents=True)
    (robot / "modules" / "drive.spec").write_text('module drive {\n  number: 1;\n  codels: "bot_codels.drive";\n'
                                                  "  request Go { type: control; validate: check; }\n}\n")
    first = specc("skeleton", str(robot))
    assert first.returncode == 0 and (robot / "bot_codels" / "drive.py").is_file(), first.stdout + first.stderr
    assert not (robot / "modules" / "bot_codels").exists()
    (robot / "modules" / "arm.spec").write_text('module arm {\n  number: 2;\n  codels: "bot_codels.arm";\n'
                                                "  request Lift { type: control; validate: lift; }\n}\n")
    (robot / "system.spec").write_text("system bot {\n  modules: drive, arm;\n}\n")
    second = specc("skeleton", str(robot / "modules"), str(robot / "system.spec"))
    assert second.returncode == 0 and (robot / "bot_codels" / "arm.py").is_file(), second.stdout + second.stderr


def test_an_output_that_cannot_be_written_stops_plan_and_graph_before_any_work(tmp_path: Path) -> None:
    """A picture format matplotlib does not write, or a folder given for a file, is said at once:
    nothing is planned or drawn first (the plan's text, printed after planning, never appears)."""
    tug = str(EXAMPLES / "tug")
    (tmp_path / "taken").mkdir()
    cases = [
        (("plan", tug, "--problem", "shuttle", "-o", str(tmp_path / "plan.txt")), "matplotlib writes no '.txt'"),
        (("plan", tug, "--problem", "shuttle", "--json", str(tmp_path / "taken")), "is a folder: give a file name"),
        (("graph", "--incompat", tug, "-o", str(tmp_path / "graph.docx")), "end the name with .png, .svg or .pdf"),
        (("plan", tug, "--problem", "shuttle", "-o", str(tmp_path / "noext")), "end the picture's name with .png"),
    ]
    for arguments, said in cases:
        result = specc(*arguments)
        assert result.returncode == 2 and said in result.stderr, result.stderr
        assert "Traceback" not in result.stderr and "partial plans" not in result.stdout + result.stderr
        assert "group(s)" not in result.stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == ["taken"]


def test_plan_json_on_stdout_is_the_document_alone_even_with_a_picture(tmp_path: Path) -> None:
    import json

    picture = tmp_path / "plan.png"
    result = specc("plan", str(EXAMPLES / "tug"), "--problem", "shuttle", "--json", "-", "-o", str(picture))
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["plan"]["actions"] and picture.is_file()
    assert f"wrote {picture}" in result.stderr
    refused = specc("plan", str(EXAMPLES / "tug"), "--problem", "shuttle", "-o", "-", cwd=tmp_path)
    assert refused.returncode == 2 and "a picture cannot go to the standard output" in refused.stderr
    assert list(tmp_path.iterdir()) == [picture]


def test_plan_printed_to_a_pipe_keeps_its_tables_whole() -> None:
    """Captured output is not a terminal: the plan's tables are not squeezed into 80 columns (no
    cell cut with an ellipsis, every column heading whole)."""
    result = specc("plan", str(EXAMPLES / "atrv"), "--problem", "M1", "--domain", "model1")
    assert result.returncode == 0, result.stderr
    assert "…" not in result.stdout
    assert all(heading in result.stdout for heading in ("start", "action", "duration", "ends by", "may start",
                                                         "preemption"))


def test_a_reader_that_left_does_not_change_the_exit_status() -> None:
    """`specc ... | head`: once the pipe's reader is gone, what is written is dropped and the
    command ends with its own status (0: the specs check), not click's silent 1 for a broken pipe."""
    read_end, write_end = os.pipe()
    os.close(read_end)  # the reader left before the first line
    try:
        done = subprocess.run([sys.executable, "-m", "specc.cli", "check", str(EXAMPLES / "tug")], cwd=ROOT,
                              stdout=write_end, stderr=subprocess.PIPE, text=True, timeout=120)
    finally:
        os.close(write_end)
    assert done.returncode == 0 and "Traceback" not in done.stderr, done.stderr


def test_long_work_in_a_log_says_it_is_alive_at_most_once_a_heartbeat(monkeypatch: pytest.MonkeyPatch,
                                                                      capsys: pytest.CaptureFixture[str]) -> None:
    """stderr a log (CI, a pipe): no live line can be drawn there, so a verification or a run that
    takes minutes prints a progress line every HEARTBEAT seconds, not at every step."""
    import specc.cli as cli

    beat = cli.Heartbeat()
    beat("exploring: 1,000 states")  # under a heartbeat since it began: nothing yet
    monkeypatch.setattr(cli, "HEARTBEAT", 0.0)
    beat("exploring: 2,000 states")
    assert capsys.readouterr().err == "... exploring: 2,000 states\n"
    with cli.ProgressDisplay(quiet=False, clock=lambda done: f"{done:.0f} checked") as progress:
        assert progress is not None  # captured stderr is no terminal
        progress(3, 10, "checking warehouse's mutants")
    assert capsys.readouterr().err == "... 3 checked of 10: checking warehouse's mutants\n"
    with cli.ProgressDisplay(quiet=True) as silent:
        assert silent is None


def test_verify_says_what_it_assumed_when_codels_send_what_sends_does_not_declare(tmp_path: Path) -> None:
    """PICK's codel sends gripper.Close without `sends:` saying so (check warns): the controller
    cannot keep OPEN apart from it, and verify proves its properties of the declared sends. It
    says that its 'holds' rests on them."""
    (tmp_path / "shop_codels.py").write_text(
        "def pick(sdi, request):\n    sdi.send_request('gripper.Close')\n    return 'exec'\n\n"
        "def work(sdi, request):\n    return 'end'\n")
    spec = tmp_path / "robot.spec"
    spec.write_text("""
module arm {
  codels: "shop_codels";
  request Pick { type: exec; task: T; codel start: pick; codel exec: work; }
  exec_task T { period: 100 ms; }
}
module gripper {
  codels: "shop_codels";
  request Close { type: exec; task: T; incompatible_with: Open; codel exec: work; }
  request Open { type: exec; task: T; incompatible_with: Close; codel exec: work; }
  exec_task T { period: 100 ms; }
}
executive e {
  service PICK { request: arm.Pick; }
  service OPEN { request: gripper.Open; }
}
""")
    result = specc("verify", str(spec), "--requests", "1")
    assert "[undeclared-send]" in result.stderr
    assumed = [line for line in result.stdout.splitlines() if line.startswith("assumed: ")]
    assert len(assumed) == 1 and "(undeclared-send)" in assumed[0], result.stdout
    # Declared, the send is followed (and PICK kept apart from OPEN): nothing is assumed.
    spec.write_text(spec.read_text().replace("codel start: pick;", "sends: gripper.Close; codel start: pick;"))
    declared = specc("verify", str(spec), "--requests", "1")
    assert declared.returncode == 0 and "assumed: " not in declared.stdout, declared.stdout + declared.stderr
