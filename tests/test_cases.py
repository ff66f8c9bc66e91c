"""Data-first diagnostics tests: each case under tests/cases declares, on the line where a
diagnostic must appear, `// expect: code[, code]`. A case is a .spec file or a folder."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from specc.pipeline import load

CASES = Path(__file__).parent / "cases"
EXPECT = re.compile(r"//\s*expect:\s*([a-z\-]+(?:\s*,\s*[a-z\-]+)*)\s*$")


def case_paths() -> list[Path]:
    return sorted(p for p in CASES.iterdir() if p.suffix == ".spec" or p.is_dir())


def expectations(case: Path) -> set[tuple[str, int, str]]:
    files = [case] if case.is_file() else sorted(case.rglob("*.spec"))
    expected = set()
    for file in files:
        for number, line in enumerate(file.read_text().splitlines(), start=1):
            match = EXPECT.search(line)
            if match:
                for code in match.group(1).split(","):
                    expected.add((file.name, number, code.strip()))
    return expected


@pytest.mark.parametrize("case", case_paths(), ids=lambda p: p.name)
def test_case_reports_exactly_the_expected_codes(case: Path) -> None:
    loaded = load([case])
    found = {(Path(d.span.file).name, d.span.line, d.code) for d in loaded.diagnostics}
    expected = expectations(case)
    assert expected, f"{case} declares no expectation"
    assert found == expected, (
        f"\nmissing: {sorted(expected - found)}\nunexpected: {sorted(found - expected)}")


def test_at_least_thirty_distinct_codes_are_covered() -> None:
    codes = {code for case in case_paths() for _, _, code in expectations(case)}
    assert len(codes) >= 30, sorted(codes)


@pytest.mark.parametrize("case", case_paths(), ids=lambda p: p.name)
def test_compile_reports_what_check_reports_and_nothing_more(case: Path, tmp_path: Path) -> None:
    """`specc compile` on each case: the same diagnostics as `specc check`, no traceback, no
    error of its own that check missed."""
    import subprocess
    import sys

    def codes(*args: str) -> tuple[int, set[str], str]:
        result = subprocess.run([sys.executable, "-m", "specc.cli", *args], capture_output=True, text=True,
                                timeout=120)
        shown = result.stdout + result.stderr
        return result.returncode, set(re.findall(r": (?:error|warning): .*\[([a-z-]+)\]$", shown, re.M)), shown

    checked, check_codes, check_shown = codes("check", str(case))
    compiled, compile_codes, shown = codes("compile", str(case), "-o", str(tmp_path))
    assert "Traceback" not in shown and "internal error" not in shown, shown
    assert compiled == checked and compile_codes == check_codes, shown
    assert checked != 0 or "\n0 error(s)" in check_shown, check_shown  # a case of warnings only compiles


def test_a_binding_s_constant_is_checked_against_its_own_module_s_enum(tmp_path: Path) -> None:
    """Two modules each with an enum named `speed`: `drive.Go(FAST)` is a value of drive's, not
    of arm's, whichever module comes last."""
    base = (CASES / "system_planned.spec").read_text()
    text = base.replace("  request Lift { type: control; input: height: double; }\n",
                        "  request Lift { type: control; input: height: double; }\n"
                        "  enum speed { SLOW, FAST }\n  request Pace { type: control; input: s: speed; }\n")
    text += "\nmodule arm {\n  number: 2;\n  enum speed { CREEP, QUICK }\n}\n"
    for value, wrong in (("FAST", False), ("QUICK", True)):
        spec = tmp_path / f"{value}.spec"
        spec.write_text(text.replace("LIFT() => request drive.Lift(HIGH);", f"LIFT() => request drive.Pace({value});"))
        found = [d for d in load([spec]).diagnostics if d.code == "bad-argument-type" and "drive.Pace" in d.message]
        assert bool(found) == wrong, [d.message for d in found]


def test_the_sdi_names_check_keeps_for_specc_are_the_runtime_s() -> None:
    """`reserved-name` for an internal data field that would hide what a codel reaches through its
    SDI: the check lists those names itself (importing the runtime would slow every check)."""
    from specc.check.modules import SDI_ATTRIBUTES
    from specc.runtime.functional import InternalData

    assert SDI_ATTRIBUTES == {name for name in vars(InternalData) if not name.startswith("_")}
