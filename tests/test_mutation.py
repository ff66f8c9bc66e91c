"""Mutation of planning domains on the model (seed 004 §4.1.3): the five classes each change what
they should and nothing else, mutants print back as spec text that parses into the mutated model,
the identical, duplicate, invalid and equivalent ones are discarded and counted, enumeration and
sampling are deterministic, a kept mutant of Modele1 plans differently, and `specc mutants`."""

from __future__ import annotations

import re
import subprocess
import sys
import textwrap
from collections import Counter
from dataclasses import replace
from functools import cache
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from specc.analysis.planning import domain_model
from specc.mutation import (
    CLASSES,
    Mutant,
    MutantSet,
    MutationError,
    MutationTarget,
    enumerate_mutants,
    keep_valid,
    mutant_domain,
    mutation_target,
)
from specc.mutation.edits import DomainTables, domain_edits, value_pool
from specc.mutation.mutants import draw_kept, verdict
from specc.mutation.tree import replace_at
from specc.run import RunError
from specc.run.mission import check_mission, load_robot
from specc.runtime.planner import Planner
from specc.syntax.parser import parse_text
from tests.atrv import ATRV, atrv_models, mutation_1_592, program
from tests.conftest import EXAMPLES, ROOT

# A domain small enough to count its mutants by hand: one attribute with numeric bounds, one
# task with symbolic, numeric and temporal variables, a constant expression and a contingent
# duration.
TINY = textwrap.dedent("""\
    domain tiny {
      constant SIDES = {LEFT, RIGHT};

      attribute AT() {
        ?value in [-oo, +oo];
      }

      attribute ARM() {
        ?value in SIDES | {MOVING};
      }

      task SWING(?from, ?to) (t_start, t_end) {
        ?from in SIDES;
        ?to in SIDES;
        ?from != ?to;
        variable ?d, ?e;
        ?d in [2 * 1, 5];
        ?e =. ?d *. 2;
        event(ARM(): (?from, MOVING), t_start);
        hold(ARM(): MOVING, (t_start, t_end));
        event(ARM(): (MOVING, ?to), t_end);
        contingent (t_end - t_start) in [2, 10];
      } nonPreemptive
    }
    """)
# The values written (-oo and +oo, 2, 1, 5, 10) and the special ones (0, 1, -1).
TINY_POOL = (float("-inf"), -1, 0, 1, 2, 5, 10, float("inf"))
TINY_NUMERIC_SITES = 8  # -oo, +oo, 2, 1, 5, the 2 of `?d *. 2`, 2, 10


@pytest.fixture(scope="module")
def tiny(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("tiny")
    (folder / "tiny.spec").write_text(TINY, encoding="utf-8")
    return folder


@pytest.fixture(scope="module")
def tiny_mutants(tiny: Path) -> list[Mutant]:
    return enumerate_mutants(tiny, "tiny", random_values=0)


@pytest.fixture(scope="module")
def tiny_set(tiny_mutants: list[Mutant]) -> MutantSet:
    return keep_valid(tiny_mutants)


@cache
def model1() -> MutationTarget:
    return mutation_target(ATRV, "model1")


@cache
def model1_mutants() -> tuple[Mutant, ...]:
    return tuple(enumerate_mutants(model1()))


def of_kind(mutants: list[Mutant] | tuple[Mutant, ...], kind: str) -> list[Mutant]:
    return [x for x in mutants if x.kind == kind]


def changed_lines(mutant: Mutant) -> tuple[list[str], list[str]]:
    """The diff's removed and added lines, without their marks (blank ones aside: a task's last
    statement deleted takes the blank line before it along)."""
    lines = [line for line in mutant.diff.splitlines() if not line.startswith(("---", "+++")) and line[1:].strip()]
    return ([line[1:].strip() for line in lines if line.startswith("-")],
            [line[1:].strip() for line in lines if line.startswith("+")])


# ---------------------------------------------------------------- the five classes


def test_numeric_values_are_replaced_by_every_other_value_of_the_pool(tiny_mutants: list[Mutant]) -> None:
    numeric = of_kind(tiny_mutants, "numeric")
    assert len(numeric) == TINY_NUMERIC_SITES * (len(TINY_POOL) - 1)
    # The lower bound of the contingent duration takes each other value, written as the grammar
    # writes it (numbers carry no sign: -1 is a sign and 1).
    at_low = [changed_lines(x)[1][0] for x in numeric
              if x.description.startswith("tiny.spec:22:") and "numeric 2 -> " in x.description]
    assert sorted(at_low) == sorted(f"contingent (t_end - t_start) in [{v}, 10];"
                                    for v in ("-oo", "-1", "0", "1", "5", "10", "+oo"))
    for x in numeric:
        removed, added = changed_lines(x)
        assert len(removed) == len(added) == 1 and removed != added


def test_drawn_values_join_the_pool_and_depend_on_the_seed(tiny: Path) -> None:
    def drawn(seed: int) -> set[str]:
        mutants = enumerate_mutants(tiny, "tiny", random_values=3, seed=seed, classes=["numeric"])
        return {x.description.split(" -> ")[1].split(" in ")[0] for x in mutants} - {
            "-oo", "-1", "0", "1", "2", "5", "10", "+oo"}

    assert len(drawn(0)) == 3 and drawn(0) == drawn(0)
    assert drawn(0) != drawn(1)
    assert all(re.fullmatch(r"-?\d+\.\d", value) for value in drawn(0))


def test_variables_are_replaced_within_their_task_and_their_kind(tiny_mutants: list[Mutant]) -> None:
    variable = of_kind(tiny_mutants, "variable")
    swaps = Counter(x.description.split(": ", 1)[1] for x in variable)
    assert swaps == Counter({
        "variable ?from -> ?to in SWING": 3, "variable ?to -> ?from in SWING": 3,  # symbolic with symbolic
        "variable ?d -> ?e in SWING": 2, "variable ?e -> ?d in SWING": 1,  # numeric with numeric
        "timepoint t_start -> t_end in SWING": 3, "timepoint t_end -> t_start in SWING": 3})
    for x in variable:
        assert "variable ?d, ?e;" in x.text  # a declaration is not a use


def test_symbolic_values_are_replaced_by_the_other_values_of_the_attribute(tiny_mutants: list[Mutant]) -> None:
    value = of_kind(tiny_mutants, "value")
    assert len(value) == 3 * 2  # MOVING, three times, by LEFT and by RIGHT (?from and ?to are variables)
    assert {changed_lines(x)[1][0] for x in value} == {
        "event(ARM(): (?from, LEFT), t_start);", "event(ARM(): (?from, RIGHT), t_start);",
        "hold(ARM(): LEFT, (t_start, t_end));", "hold(ARM(): RIGHT, (t_start, t_end));",
        "event(ARM(): (LEFT, ?to), t_end);", "event(ARM(): (RIGHT, ?to), t_end);"}


def test_operators_of_the_language_are_substituted(tiny_mutants: list[Mutant]) -> None:
    added = {changed_lines(x)[1][0] if changed_lines(x)[1] else "" for x in of_kind(tiny_mutants, "operator")}
    expected = {
        "?value in [+oo, -oo];",  # the attribute's interval, swapped (already open at both ends)
        "} latePreemptive", "}",  # nonPreemptive swapped, and dropped
        "?from == ?to;", "?from < ?to;", "?from <= ?to;", "?from > ?to;", "?from >= ?to;",
        "?d in [2 + 1, 5];", "?d in [2 - 1, 5];", "?d in [2 / 1, 5];",
        "?e =. ?d +. 2;", "?e =. ?d -. 2;", "?e =. ?d /. 2;",  # dotted stays dotted
        "?e != ?d *. 2;", "?e < ?d *. 2;", "?e <= ?d *. 2;", "?e > ?d *. 2;", "?e >= ?d *. 2;",
        "contingent (t_end + t_start) in [2, 10];", "contingent (t_end * t_start) in [2, 10];",
        "contingent (t_end / t_start) in [2, 10];",
        "(t_end - t_start) in [2, 10];",  # contingent dropped
        "?d in [5, 2 * 1];", "?d in [-oo, 5];", "?d in [2 * 1, +oo];",
        "contingent (t_end - t_start) in [10, 2];", "contingent (t_end - t_start) in [-oo, 10];",
        "contingent (t_end - t_start) in [2, +oo];"}
    assert added == expected
    assert len(of_kind(tiny_mutants, "operator")) == len(expected)


def test_each_constraint_of_a_task_is_deleted_in_turn(tiny_mutants: list[Mutant]) -> None:
    deletion = of_kind(tiny_mutants, "deletion")
    removed = [changed_lines(x) for x in deletion]
    assert removed == [([line], []) for line in (
        "?from in SIDES;", "?to in SIDES;", "?from != ?to;", "?d in [2 * 1, 5];", "?e =. ?d *. 2;",
        "contingent (t_end - t_start) in [2, 10];")]


def test_modele1_yields_every_class_with_one_statement_changed_per_mutant() -> None:
    mutants = model1_mutants()
    counts = Counter(x.kind for x in mutants)
    assert set(counts) == set(CLASSES)
    assert [x.id for x in mutants] == [f"model1-{k:04d}" for k in range(1, len(mutants) + 1)]
    for x in mutants:
        removed, added = changed_lines(x)
        # A mutation on the model is one statement's change in the text (a task's preemption
        # is written on its closing line), with the file's comments kept around it.
        assert len(removed) == 1 and len(added) == (0 if x.kind == "deletion" else 1), x.id
        assert x.description.startswith("model1.spec:")
        assert "// seed typo" in x.text
    # Table 1 of the seed counts 32 constraints in MOVE with its macros expanded; written in
    # Modele1 itself, MOVE has 17 (a macro call is one), the five other tasks 10.
    assert counts["deletion"] == 27


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_a_mutant_parses_back_into_the_mutated_model(data: st.DataObject) -> None:
    target = model1()
    edits = domain_edits(target.program, target.file_index, target.item_index)
    rank = data.draw(st.integers(0, len(edits) - 1))
    mutant = model1_mutants()[rank]
    parsed = parse_text(mutant.text, mutant.path)
    assert parsed.source is not None and not parsed.diagnostics
    assert parsed.source == replace_at(target.source, edits[rank].path, edits[rank].new)
    assert parsed.source != target.source


def test_a_mutant_s_diff_is_against_the_file_as_its_author_wrote_it(tmp_path: Path) -> None:
    """A file not laid out as `specc fmt` would (`[2,10]`, a comment, a blank line): each mutant's
    diff is a patch of that file, at its lines, which gives the mutated model back. The preemption,
    written after the task's block, is shown against the printed file, and says so."""
    written = TINY.replace("[2, 10]", "[2,10]").replace("    ?to in SIDES;\n",
                                                       "    ?to in SIDES;   // where it ends\n\n")
    (tmp_path / "tiny.spec").write_text(written, encoding="utf-8")
    mutants = enumerate_mutants(tmp_path, "tiny", random_values=0)
    lines = written.splitlines()
    shown = 0
    for x in mutants:
        header = x.diff.splitlines()[0]
        if x.kind == "operator" and "preemption" in x.description:
            assert header.endswith("(original, as specc fmt prints it)")
            continue
        assert header.endswith("tiny.spec (original)"), x.description
        patched = list(lines)
        for hunk in x.diff.split("\n@@ ")[1:]:
            start = int(hunk.split()[0].lstrip("-").split(",")[0])
            body = [line for line in hunk.splitlines()[1:] if line[:1] in " -+"]
            old = [line[1:] for line in body if line[:1] in " -"]
            new = [line[1:] for line in body if line[:1] in " +"]
            assert patched[start - 1:start - 1 + len(old)] == old, x.description  # the author's own lines
            patched[start - 1:start - 1 + len(old)] = new
        parsed = parse_text("\n".join(patched) + "\n", "tiny.spec").source
        assert parsed == parse_text(x.text, "tiny.spec").source, x.description
        shown += 1
    assert shown == len(mutants) - 2  # two other preemptions
    # Line 23 of the file written (22 as printed: the blank line added), where the description says too.
    ten = next(x for x in mutants if x.description.startswith("tiny.spec:23:") and "10 -> 5" in x.description)
    assert "-    contingent (t_end - t_start) in [2,10];\n+    contingent (t_end - t_start) in [2,5];" in ten.diff


# ---------------------------------------------------------------- filtering


def test_invalid_duplicate_and_equivalent_mutants_are_discarded_and_counted(tiny_set: MutantSet) -> None:
    counts = tiny_set.counts()
    total = tiny_set.total()
    assert total.generated == len(tiny_set.mutants) == total.identical + total.duplicate + total.invalid \
        + total.equivalent + total.kept
    reasons = {r.mutant.description.split(": ", 1)[1]: (r.reason, r.detail) for r in tiny_set.rejected}
    # Reversed bounds fail `specc check` as they would written by hand.
    for swapped in ("interval [2 * 1, 5] bounds swapped in SWING", "interval [2, 10] bounds swapped in SWING",
                    "numeric 10 -> 0 in SWING", "numeric 5 -> -1 in SWING"):
        assert reasons[swapped][0] == "invalid" and reasons[swapped][1].endswith("[empty-interval]"), swapped
    assert all(r.detail.endswith("[empty-interval]") for r in tiny_set.rejected if r.reason == "invalid")
    # An interval opened above is the bound replaced by +oo: one mutant, kept once.
    assert reasons["interval [2 * 1, 5] opened above in SWING"][0] == "duplicate"
    assert counts["operator"].duplicate == 3
    # 2 * 1 and 2 / 1 fold to the same bound: the planner's domain does not change.
    assert reasons["operator * -> / in SWING"][0] == "equivalent"
    assert total.equivalent == 1
    kept = {x.description.split(": ", 1)[1] for x in tiny_set.kept}
    assert {"numeric 5 -> 2 in SWING", "operator * -> + in SWING", "preemption nonPreemptive -> none in SWING",
            "variable ?d -> ?e in SWING"} <= kept
    assert counts["value"].kept == 6 and counts["deletion"].kept == 6 and counts["variable"].kept == 15


def test_a_mutant_printed_as_the_original_is_counted_identical(tiny_mutants: list[Mutant]) -> None:
    # The classes never produce one (each edit changes a value, an operator or a statement), but
    # a hand-made edit that changes nothing must not reach a campaign.
    first = tiny_mutants[0]
    same = replace(first, id="tiny-same", text=first.target.original_text)
    result = keep_valid([first, same])
    assert [r.reason for r in result.rejected] == ["identical"] and result.total().identical == 1


def test_checks_see_the_rest_of_the_robot(tiny: Path, tmp_path: Path) -> None:
    (tmp_path / "tiny.spec").write_text(TINY, encoding="utf-8")
    (tmp_path / "mission.spec").write_text(textwrap.dedent("""\
        problem swing_once for tiny {
          explained event(ARM(): (MOVING, LEFT), t_start);
          hold(ARM(): RIGHT, (t_end, t_end)) goal(1, 1);
        }
        """), encoding="utf-8")
    with_problem, alone = mutation_target(tmp_path, "tiny"), mutation_target(tiny, "tiny")
    # RIGHT taken out of the domain: the task still checks, the problem's goal does not.
    text = with_problem.original_text.replace("{LEFT, RIGHT}", "{LEFT, UP}")
    assert verdict(alone, text) is None
    found = verdict(with_problem, text)
    assert found is not None and found[0] == "invalid"
    assert "mission.spec" in found[1] and found[1].endswith("[value-outside-domain]")


def test_several_processes_give_the_same_verdicts(tiny_mutants: list[Mutant], tiny_set: MutantSet) -> None:
    assert keep_valid(tiny_mutants, workers=2).rejected == tiny_set.rejected


def test_modele1_numeric_mutants_of_a_duration_fail_exactly_when_the_bounds_cross() -> None:
    # COMMUNICATE's `contingent (t_end - t_start) in [18, 25]`: the low bound replaced by a value
    # above 25, or the high one by a value below 18, is an empty interval.
    window = [x for x in model1_mutants() if x.kind == "numeric" and x.description.startswith("model1.spec:101:")]
    result = keep_valid(window)
    target = model1()
    pool = value_pool(DomainTables(target.program, target.domain).expanded, 3, 0)
    assert len(window) == 2 * (len(pool) - 1)
    invalid = {x.id for x in window if result.rejection(x.id) is not None}
    for x in window:
        old, new = x.description.split("numeric ")[1].split(" in ")[0].split(" -> ")
        value = float(new.replace("oo", "inf"))
        crossing = value > 25 if old == "18" else value < 18
        assert (x.id in invalid) == crossing, x.description
    assert all(r.reason == "invalid" for r in result.rejected)


def test_modele1_deletions_all_check() -> None:
    deletion = of_kind(model1_mutants(), "deletion")
    result = keep_valid(deletion)
    assert result.kept == tuple(deletion)


# ---------------------------------------------------------------- determinism and sampling


def test_enumeration_is_deterministic(tiny: Path, tiny_mutants: list[Mutant]) -> None:
    again = enumerate_mutants(tiny, "tiny", random_values=0)
    assert [(x.id, x.kind, x.description, x.text, x.diff) for x in again] == [
        (x.id, x.kind, x.description, x.text, x.diff) for x in tiny_mutants]
    # Ids do not depend on the classes asked for.
    only = enumerate_mutants(tiny, "tiny", random_values=0, classes=["deletion"])
    assert [x.id for x in only] == [x.id for x in tiny_mutants if x.kind == "deletion"]


def test_a_program_given_as_a_model_gives_the_same_mutants() -> None:
    from_model = enumerate_mutants(program(), "model1", classes=["value"])
    assert [(x.id, x.text) for x in from_model] == [(x.id, x.text) for x in of_kind(model1_mutants(), "value")]


def test_a_sample_drawn_lazily_is_the_sample_of_the_judged_set(tiny_set: MutantSet) -> None:
    """draw_kept checks only what it draws (and passes over), and draws what MutantSet.sample
    draws from the whole set judged beforehand."""
    judged: list[str] = []
    kept = {x.id for x in tiny_set.kept}

    def is_kept(x: Mutant) -> bool:
        judged.append(x.id)
        return x.id in kept

    for n, seed in ((5, 0), (10, 3)):
        judged.clear()
        lazily = draw_kept(tiny_set.mutants, n, seed, is_kept)
        assert lazily == tiny_set.sample(n, seed) and len(lazily) == n
        assert n <= len(judged) < len(tiny_set.mutants)
    by_default = draw_kept(tiny_set.mutants, 5, 0)  # judging with the checks themselves
    assert by_default == tiny_set.sample(5, 0)
    # A larger draw holds the smaller one: a campaign can grow by mutants (specc.campaign.store).
    assert set(by_default) <= set(draw_kept(tiny_set.mutants, 9, 0))


def test_sampling_is_stratified_and_deterministic(tiny_set: MutantSet) -> None:
    sample = tiny_set.sample(10, seed=3)
    assert sample == tiny_set.sample(10, seed=3)
    assert Counter(x.kind for x in sample) == Counter(dict.fromkeys(CLASSES, 2))
    assert [x.id for x in sample] == sorted(x.id for x in sample)
    assert set(sample) <= set(tiny_set.kept)
    assert tiny_set.sample(10, seed=4) != sample
    uniform = tiny_set.sample(10, seed=3, stratified=False)
    assert len(uniform) == 10 and uniform == tiny_set.sample(10, seed=3, stratified=False)
    assert tiny_set.sample(10**4) == tiny_set.kept


# ---------------------------------------------------------------- planning with a mutant


def test_the_seeds_mutation_1_592_is_a_kept_mutant_that_plans_differently() -> None:
    found = [x for x in of_kind(model1_mutants(), "value")
             if x.description.endswith("value AT_MY_FEET -> STRAIGHT of PTU_POSITION in TAKE_PICTURE")]
    assert len(found) == 1
    mutant = found[0]
    assert keep_valid([mutant]).kept == (mutant,)
    original, problem = atrv_models("M1_model1")
    mutated = mutant_domain(mutant)
    # The mutation tests/atrv.py makes by hand on the planner's records is this mutant.
    assert mutated == mutation_1_592(original)
    before, after = Planner(original).plan(problem), Planner(mutated).plan(problem)
    assert before.plan is not None and after.plan is not None
    tasks_before = Counter(a.task for a in before.plan.actions)
    tasks_after = Counter(a.task for a in after.plan.actions)
    # The camera no longer needs to look down for a photo: no pan-tilt move is planned.
    assert tasks_before["MOVE_PAN_TILT_UNIT"] > 0 and tasks_after["MOVE_PAN_TILT_UNIT"] == 0
    assert tasks_after["TAKE_PICTURE"] == tasks_before["TAKE_PICTURE"]


def test_a_mutant_domain_takes_the_place_of_the_generated_one_in_a_mission() -> None:
    sys.path.insert(0, str(ROOT / "generated"))
    try:
        import atrv.planner as planning  # the generated package of examples/atrv
        from atrv.ftplan import rover
    finally:
        sys.path.remove(str(ROOT / "generated"))
    from specc.runtime.ftplan.missions import mission_setup

    setup = mission_setup(rover.CONFIGURATIONS, "Robot1/2", "M1", planning)
    target = model1()
    # The original, lowered here, is what `specc compile` generated: a mutant replaces like with like.
    assert replace(domain_model(target.program, target.domain), source="") == replace(
        setup.domains["model1"], source="")
    mutant = of_kind(model1_mutants(), "deletion")[0]
    # A rover mission runs with the mutant in place of the domain of the same name.
    robot = load_robot(ROOT / "generated", ATRV, "atrv")
    changed = check_mission(robot, robot.mission("M1"), "W1", 0, None, "Robot1/2",
                            domains={"model1": mutant_domain(mutant)}).planning
    assert changed.domains["model1"] == mutant_domain(mutant) != setup.domains["model1"]
    assert changed.domains["model2_M1"] == setup.domains["model2_M1"] and changed.problem == setup.problem
    with pytest.raises(RunError, match="plans in model1, model2_M1, not in model9"):
        check_mission(robot, robot.mission("M1"), "W1", 0, None, "Robot1/2",
                      domains={"model9": replace(mutant_domain(mutant), name="model9")})


def test_bad_input_is_one_clear_error(tiny: Path, tmp_path: Path) -> None:
    with pytest.raises(MutationError, match="no domain 'model3'.*model1"):
        mutation_target(ATRV, "model3")
    with pytest.raises(MutationError, match="unknown mutation class"):
        enumerate_mutants(tiny, "tiny", classes=["swap"])
    (tmp_path / "bad.spec").write_text(TINY.replace("?from != ?to", "?from != ?nowhere"), encoding="utf-8")
    with pytest.raises(MutationError, match=r"\[undeclared-variable\].*check clean"):
        mutation_target(tmp_path, "tiny")


def test_a_domain_whose_members_are_all_in_fragments_says_why_it_has_no_mutant(tmp_path: Path) -> None:
    # A campaign of no mutant would run and report empty fault rows: the fragments a domain
    # includes are never mutated (the problems include them too), and the user is told so.
    body = TINY.split("{", 1)[1].rsplit("}", 1)[0]
    (tmp_path / "parts.spec").write_text(f"fragment tiny_parts {{{body}}}\ndomain tiny {{\n  include tiny_parts;\n}}\n",
                                         encoding="utf-8")
    with pytest.raises(MutationError, match=r"'tiny' has nothing of its own to mutate.*\(tiny_parts\).*domain block"):
        enumerate_mutants(tmp_path, "tiny")


# ---------------------------------------------------------------- specc mutants


def specc(*args: str | Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "specc.cli", *map(str, args)], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)


def test_the_command_counts_lists_and_writes_the_kept_mutants(tiny: Path, tiny_set: MutantSet,
                                                              tmp_path: Path) -> None:
    result = specc("mutants", tiny, "--domain", "tiny", "--workers", "1", "-o", tmp_path / "out")
    assert result.returncode == 0, result.stderr
    total = tiny_set.total()
    row = re.search(r"total\s*│\s*(\d+)\s*│\s*(\d+)\s*│\s*(\d+)\s*│\s*(\d+)\s*│\s*(\d+)\s*│\s*(\d+)", result.stdout)
    assert row is not None, result.stdout
    # The default draws three values more than random_values=0: eight numeric sites get three more each.
    assert int(row[1]) == total.generated + 3 * TINY_NUMERIC_SITES and int(row[5]) == total.equivalent
    listed = re.findall(r"^(tiny-\d{4})  ", result.stdout, re.M)
    assert len(listed) == int(row[6])
    written = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert written == sorted(["index.tsv"] + [f"{i}.spec" for i in listed] + [f"{i}.diff" for i in listed])
    first = (tmp_path / "out" / f"{listed[0]}.spec").read_text()
    assert parse_text(first, "tiny.spec").source is not None and first != TINY


def test_mutants_are_not_written_where_they_would_be_read_as_the_robot_s_specs(tiny: Path) -> None:
    inside = tiny / "mutants" if tiny.is_dir() else tiny.parent / "mutants"
    result = specc("mutants", tiny, "--domain", "tiny", "--workers", "1", "-o", inside)
    assert result.returncode == 2 and "inside the robot's folder" in result.stderr, result.stderr
    assert not inside.exists()


def test_the_command_samples_and_shows_a_mutant(tiny: Path) -> None:
    sampled = specc("mutants", tiny, "--domain", "tiny", "--class", "deletion", "--class", "value", "--sample",
                    "4", "--seed", "2")
    assert sampled.returncode == 0, sampled.stderr
    lines = re.findall(r"^tiny-\d{4}  (\w+)", sampled.stdout, re.M)
    assert Counter(lines) == Counter({"value": 2, "deletion": 2})
    assert "numeric" not in sampled.stdout.split("sample of")[0]
    shown = specc("mutants", ATRV, "--show", "model1-0012")
    assert shown.returncode == 0, shown.stderr
    assert "numeric 0.0 -> " in shown.stdout and "passes the checks" in shown.stdout
    assert "-    ?x1 in [0.0 - 10.0, 10.0];" in shown.stdout
    other = specc("mutants", EXAMPLES / "tug", "--show", "warehouse_slow-0001")  # the id names its domain
    assert other.returncode == 0, other.stderr
    assert other.stdout.startswith("warehouse_slow-0001 ")


@pytest.mark.parametrize(("args", "message"), [
    (("examples/nowhere",), "no such file or folder"),
    ((ATRV, "--domain", "model3"), "no domain 'model3'"),
    ((ATRV, "--show", "model1-9999"), "no mutant 'model1-9999'"),
    ((ATRV, "--class", "swap"), "unknown mutation class"),
])
def test_the_command_refuses_bad_input_in_one_line(args: tuple[str | Path, ...], message: str) -> None:
    result = specc("mutants", *args)
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr and "internal error" not in result.stderr
    assert result.stderr.startswith("error: ") and message in result.stderr and result.stderr.count("\n") == 1


def test_a_spec_error_met_by_the_command_is_said_gcc_style(tmp_path: Path) -> None:
    spec = tmp_path / "x.spec"
    spec.write_text("domain d {\n  oops\n}\n")
    result = specc("mutants", spec)
    assert result.returncode == 2 and result.stderr.startswith(f"{spec}:2:3: error: unexpected 'oops'"), result.stderr
