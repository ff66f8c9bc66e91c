"""Every diagnostic code the passes report is registered (specc/codes.py) with a summary and an
example, every registered code is still reported somewhere, and `specc explain` prints them."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

from specc.codes import CODES

SPECC = Path(__file__).resolve().parents[1] / "specc"
CODE = re.compile(r"^[a-z]+(-[a-z]+)+$")
# The calls that take a diagnostic code as one of their arguments.
CALLS = {"error", "warning", "report", "warn", "unknown", "Diagnostic", "resolve_member", "_reject", "Problem",
         "lookup"}


def reported_codes() -> dict[str, str]:
    """code -> a file reporting it, read from the source: the codes given to CALLS, those in the
    check passes' (reference, kind, code) tables, those exception classes carry (`code = ...`),
    and those written into a message (`[code]`)."""
    found: dict[str, str] = {}
    for path in sorted(SPECC.rglob("*.py")):
        if path.name == "codes.py":
            continue
        text = path.read_text(encoding="utf-8")
        for node in ast.walk(ast.parse(text)):
            values: list[ast.expr] = []
            if isinstance(node, ast.Call):
                f = node.func
                name = f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else ""
                if name in CALLS:
                    values = [*node.args, *(k.value for k in node.keywords)]
            elif isinstance(node, ast.Tuple) and "check" in path.relative_to(SPECC).parts:
                values = list(node.elts)
            elif isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "code"
                                                      for t in node.targets):
                values = [node.value]  # an exception class's code (`code = "rules-too-large"`)
            for value in values:
                if isinstance(value, ast.Constant) and isinstance(value.value, str) and CODE.match(value.value):
                    found.setdefault(value.value, str(path.relative_to(SPECC)))
        for match in re.finditer(r"\[([a-z]+(?:-[a-z]+)+)\]\"", text):
            found.setdefault(match.group(1), str(path.relative_to(SPECC)))
    return found


def test_every_code_reported_is_registered_and_every_registered_one_is_reported() -> None:
    reported = reported_codes()
    # Tuples of the check passes hold other words too (property names): only codes are compared.
    unregistered = {c: where for c, where in reported.items() if c not in CODES and not where.startswith("check")}
    assert not unregistered, f"register these in specc/codes.py: {unregistered}"
    stale = sorted(set(CODES) - set(reported))
    assert not stale, f"no pass reports these any more: {stale}"
    assert all(entry.summary and entry.example for entry in CODES.values())


def test_explain_prints_every_code_and_refuses_an_unknown_one() -> None:
    every = subprocess.run([sys.executable, "-m", "specc.cli", "explain"], capture_output=True, text=True,
                           timeout=60)
    assert every.returncode == 0
    assert {line.split(":")[0] for line in every.stdout.splitlines() if not line.startswith(" ")} == set(CODES)
    one = subprocess.run([sys.executable, "-m", "specc.cli", "explain", "[unknown-unit]"], capture_output=True,
                         text=True, timeout=60)
    assert one.returncode == 0 and one.stdout.startswith("unknown-unit: ") and "e.g. " in one.stdout
    typo = subprocess.run([sys.executable, "-m", "specc.cli", "explain", "unknwn-unit"], capture_output=True,
                          text=True, timeout=60)
    assert typo.returncode == 2 and "did you mean 'unknown-unit'" in typo.stderr


def test_a_folder_without_specs_and_a_skeleton_that_cannot_be_written_say_so_with_their_codes(
        tmp_path: Path) -> None:
    empty = subprocess.run([sys.executable, "-m", "specc.cli", "check", str(tmp_path)], capture_output=True,
                           text=True, timeout=60)
    assert empty.returncode == 2 and "[no-spec-files]" in empty.stdout + empty.stderr
    (tmp_path / "notes.spec").write_text("// a robot to come\n", encoding="utf-8")  # a file of comments only
    comments = subprocess.run([sys.executable, "-m", "specc.cli", "check", str(tmp_path)], capture_output=True,
                              text=True, timeout=60)
    assert comments.returncode == 0 and "notes.spec:1:1: warning: " in comments.stderr
    assert "holds no block (module, executive, rules...)" in comments.stderr and "[empty-file]" in comments.stderr
    (tmp_path / "notes.spec").unlink()
    (tmp_path / "m.spec").write_text('module m { number: 1; codels: "m_codels"; request Go { type: control; '
                                     "validate: check; } }\n", encoding="utf-8")
    (tmp_path / "m_codels.py").mkdir()  # where the stubs would go: a folder, not a file
    stubs = subprocess.run([sys.executable, "-m", "specc.cli", "skeleton", str(tmp_path)], capture_output=True,
                           text=True, timeout=60)
    shown = stubs.stdout + stubs.stderr
    assert stubs.returncode != 0 and "[skeleton-failed]" in shown and "Traceback" not in shown, shown
    assert "m.spec:1:1: error: " in shown  # where the spec names the module the stubs were for


def test_every_code_says_how_to_fix_it() -> None:
    from specc.codes import FIXES

    assert list(FIXES) == list(CODES)  # one each, in the table's order
    assert all(fix.strip() and fix.endswith(".") for fix in FIXES.values())
    shown = subprocess.run([sys.executable, "-m", "specc.cli", "explain", "macro-cycle"], capture_output=True,
                           text=True, timeout=60)
    assert shown.returncode == 0 and f"    fix: {FIXES['macro-cycle']}" in shown.stdout


# Codes no test produces yet: this list only shrinks.
UNTESTED: set[str] = set()


def test_every_code_is_produced_by_a_data_first_case_or_a_test() -> None:
    from tests.test_cases import case_paths, expectations

    cased = {code for case in case_paths() for _, _, code in expectations(case)}
    others = " ".join(p.read_text(encoding="utf-8") for p in Path(__file__).parent.glob("test_*.py")
                      if p.name != "test_codes.py")
    here = Path(__file__).read_text(encoding="utf-8")  # its own tests assert `[code]`; UNTESTED names codes too
    untested = {code for code in CODES if code not in cased and f'"{code}"' not in others
                and f"[{code}]" not in others + here}
    assert untested == UNTESTED, f"a test for each of: {sorted(untested - UNTESTED)}; now tested, remove from " \
                                 f"UNTESTED: {sorted(UNTESTED - untested)}"
