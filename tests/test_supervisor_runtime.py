"""The PRS supervisor at run time (seed 000 ch. 4): the database and its predicate kinds, the
goal operators, variables, KA selection, choose/parallel/if/while, effects, fact-invoked and
meta KAs, fair scheduling, and the EXEC-REQUEST protocol of Fig 4.3 against the real executive.

Libraries are built directly from the records of `specc.runtime.procedures`."""

from __future__ import annotations

import dataclasses
import importlib
from collections.abc import Callable
from types import ModuleType
from typing import Any

import pytest

from specc.runtime.kernel import Kernel
from specc.runtime.procedures import (
    KA,
    Action,
    Assign,
    Choose,
    Compound,
    Fail,
    Goal,
    If,
    Library,
    Parallel,
    Predicate,
    Primitive,
    Statement,
    Step,
    Var,
    While,
    parse_fact,
    parse_goal,
    parse_term,
)
from specc.runtime.supervisor import Intention, Supervisor
from tests.functional.conftest import shop_package  # noqa: F401 - the fixture of the executive tests

# ---------------------------------------------------------------- building libraries


def goal(text: str, line: int = 0) -> Goal:
    return dataclasses.replace(parse_goal(text), line=line)


def step(text: str, line: int = 0) -> Step:
    return Step(goal(text, line))


def ka(name: str, invocation: str, *body: Statement, context: str | None = None, effects: tuple[str, ...] = (),
       action: str | None = None, result: str | None = None, meta: bool = False, line: int = 1) -> KA:
    """A KA from spec-like text: `invocation` is a goal `!(...)` or a fact pattern `(...)`."""
    return KA(
        name=name,
        invocation=parse_goal(invocation) if invocation.startswith("!") else parse_fact(invocation),
        context=goal(context) if context else None,
        body=None if action else body,
        action=Action(parse_fact(action), Var(result) if result else None, line) if action else None,
        effects=tuple(goal(e) for e in effects),
        properties=("meta",) if meta else (),
        line=line,
    )


def supervisor(*kas: KA, predicates: tuple[Predicate, ...] = (), primitives: tuple[Primitive, ...] = (),
               functions: dict[str, Callable[..., Any]] | None = None, **options: Any) -> Supervisor:
    library = Library("test", predicates=predicates, primitives=primitives, kas=kas)
    return Supervisor(library, functions or {}, **options)


def ran(intention: Intention, name: str) -> int:
    """How many times KA `name` started in the intention."""
    return sum(1 for e in intention.trace if e.ka == name and e.text.startswith("started"))


def done(s: Supervisor, text: str) -> Intention:
    intention = s.post(text)
    s.run()
    return intention


# ---------------------------------------------------------------- terms


def test_the_parser_reads_goals_terms_and_facts() -> None:
    assert parse_goal("!(COLLECT-OBJECTS 3)") == Goal("!", Compound("COLLECT-OBJECTS", (3,)))
    assert parse_goal(" =>(~ (P $X))") == Goal("=>", Compound("~", (Compound("P", (Var("$X"),)),)))
    assert parse_goal("~>(P)").op == "~>"
    assert parse_term('(SAY "two words" -2 0.5 @I INF)') == Compound("SAY", ("two words", -2, 0.5, Var("@I"), "INF"))
    assert parse_fact("(& (A) (< $I (+ $J 1)))").args[1] == parse_term("(< $I (+ $J 1))")
    for bad in ("(P", "P)", "(P) (Q)", "!P", "()"):
        with pytest.raises(ValueError):
            parse_goal(bad) if bad.startswith("!") else parse_fact(bad)


# ---------------------------------------------------------------- database and operators


def test_standard_predicates_are_three_valued() -> None:
    s = supervisor()
    assert s.database.truth("(DOOR OPEN)") is None
    assert done(s, "?(DOOR OPEN)").status == "failed"
    assert done(s, "?(~ (DOOR OPEN))").status == "failed"  # unknown: neither test succeeds
    s.conclude("(~ (DOOR OPEN))")
    assert s.database.truth("(DOOR OPEN)") is False
    assert done(s, "?(~ (DOOR OPEN))").status == "succeeded"
    s.conclude("(DOOR OPEN)")  # the affirmation replaces the negation
    assert s.database.truth("(DOOR OPEN)") is True and s.database.negated("DOOR") == []
    s.retract("(DOOR OPEN)")
    assert s.database.truth("(DOOR OPEN)") is None


def test_closed_predicates_take_absence_for_negation() -> None:
    closed = (Predicate("EXECUTION", "closed", 1),)
    s = supervisor(ka("Stop", "!(STOP)", step("=>(~ (EXECUTION GO))")),
                   ka("Bad", "!(BAD)", step("~>(~ (EXECUTION GO))", 7), line=6), predicates=closed)
    assert done(s, "?(~ (EXECUTION GO))").status == "succeeded"
    s.conclude("(EXECUTION GO)")
    assert done(s, "?(EXECUTION $S)").bindings == {"$S": "GO"}
    assert done(s, "!(STOP)").status == "succeeded"  # concluding the negation is retracting
    assert s.database.facts("EXECUTION") == [] and s.database.truth("(EXECUTION GO)") is False
    bad = done(s, "!(BAD)")
    assert bad.status == "failed"
    assert any(line.startswith("Bad:7: ~>(~ (EXECUTION GO))") for line in bad.lines())


def test_functional_facts_keep_one_value_per_key() -> None:
    s = supervisor(predicates=(Predicate("AT", "functional", 2),))
    for fact in ("(AT ROBOT HALL)", "(AT ARM UP)", "(AT ROBOT KITCHEN)"):
        s.conclude(fact)
    assert s.database.facts("AT") == [parse_fact("(AT ARM UP)"), parse_fact("(AT ROBOT KITCHEN)")]
    assert done(s, "?(AT ROBOT $WHERE)").bindings == {"$WHERE": "KITCHEN"}
    assert s.database.truth("(AT ROBOT HALL)") is False


def test_an_event_occurrence_is_used_once() -> None:
    s = supervisor(predicates=(Predicate("BUMP", "event", 1),))
    first, second = s.post("^(BUMP $SIDE)"), s.post("^(BUMP $SIDE)")
    s.run()
    assert first.status == second.status == "running"
    s.signal("(BUMP LEFT)")
    s.run()
    woken = [i for i in (first, second) if i.status == "succeeded"]
    assert len(woken) == 1 and woken[0].bindings == {"$SIDE": "LEFT"}
    assert s.database.events("BUMP") == []
    s.signal("(BUMP RIGHT)")
    s.run()
    assert first.status == second.status == "succeeded"
    s.signal("(BUMP FRONT)")  # nobody waits: it stays until a test uses it
    assert s.database.truth("(BUMP FRONT)") is True
    assert done(s, "?(BUMP $SIDE)").bindings == {"$SIDE": "FRONT"}
    assert done(s, "?(BUMP $SIDE)").status == "failed"


def test_evaluable_predicates_call_their_function_with_bound_arguments() -> None:
    calls: list[tuple[Any, ...]] = []

    def near(ctx: Any, x: int, limit: int) -> bool:
        calls.append((x, limit))
        return abs(x) < limit

    s = supervisor(ka("Check", "!(CHECK $X)", step("?(NEAR $X 5)", 3), step("=>(CHECKED $X)"), line=2),
                   predicates=(Predicate("NEAR", "evaluable", 2, "robot.near"),), functions={"robot.near": near})
    assert done(s, "!(CHECK 3)").status == "succeeded"
    assert done(s, "!(CHECK 9)").status == "failed"
    unbound = done(s, "!(CHECK $Y)")
    assert calls == [(3, 5), (9, 5)]  # not called with an unbound argument
    assert unbound.status == "failed"
    assert "Check:3: ?(NEAR $X 5) failed: evaluable predicate (NEAR $X 5): $X is unbound" in unbound.lines()


def test_a_function_given_for_no_binding_is_refused_with_the_bindings_there_are() -> None:
    """`create(functions={...})` with a misspelt key used to import the real module in its
    place without a word (a test's stub never called)."""
    from specc.runtime.procedures import load_functions

    library = Library("test", predicates=(Predicate("NEAR", "evaluable", 2, "robot.near"),), kas=())
    near = lambda ctx, x, limit: True  # noqa: E731
    assert load_functions(library, {"robot.near": near}) == {"robot.near": near}
    with pytest.raises(ValueError, match=r"functions= gives 'robot.naer', which no action or evaluable predicate "
                                         r"is bound to \(did you mean 'robot.near'\?\) \(bound: robot.near\)"):
        load_functions(library, {"robot.naer": near})


def test_achieve_first_tests_the_database() -> None:
    s = supervisor(ka("Open", "!(DOOR $STATE)", step("=>(DOOR OPEN)")))
    s.conclude("(DOOR SHUT)")
    already = done(s, "!(DOOR $STATE)")
    assert already.status == "succeeded" and already.bindings == {"$STATE": "SHUT"}
    assert ran(already, "Open") == 0
    achieved = done(s, "!(DOOR OPEN)")
    assert achieved.status == "succeeded" and ran(achieved, "Open") == 1


def test_wait_blocks_until_the_condition_holds_and_never_fails() -> None:
    s = supervisor(ka("Sync", "!(SYNC $N)", step("^(& (COUNT $C) (>= $C $N))"), step("=>(SYNCED $C)")))
    intention = s.post("!(SYNC 2)")
    s.run()
    assert intention.status == "running" and not s.step()  # blocked: nothing to run
    s.conclude("(COUNT 1)")
    s.run()
    assert intention.status == "running"
    s.conclude("(COUNT 2)")
    s.run()
    assert intention.status == "succeeded" and s.database.facts("SYNCED") == [parse_fact("(SYNCED 2)")]


def test_conclude_retract_and_the_goal_returns_its_values() -> None:
    s = supervisor(ka("Double", "!(DOUBLE $X $Y)", Assign(Var("@T"), parse_term("(* $X 2)")),
                      step("!(= $Y @T)"), step("=>(LAST @T)"), step("~>(PENDING $X)")))
    s.conclude("(PENDING 21)")
    intention = done(s, "!(DOUBLE 21 $RESULT)")
    assert intention.bindings == {"$RESULT": 42}
    assert s.database.facts("LAST") == [parse_fact("(LAST 42)")] and s.database.facts("PENDING") == []


def test_a_conclusion_with_an_unbound_argument_fails_a_retraction_changes_nothing() -> None:
    s = supervisor(ka("Sloppy", "!(SLOPPY)", step("~>(FACT $X)", 3), step("=>(FACT $X)", 4), line=2))
    s.conclude("(FACT 1)")
    intention = done(s, "!(SLOPPY)")
    assert intention.status == "failed" and s.database.facts("FACT") == [parse_fact("(FACT 1)")]
    assert intention.lines()[1:3] == ["Sloppy:3: ~>(FACT $X): nothing retracted, $X is unbound",
                                      "Sloppy:4: =>(FACT $X) failed: $X is unbound"]


def test_a_fact_outside_its_predicate_s_declared_domain_is_refused() -> None:
    """What `verify --goal` proves holds for the declared domains only: a KA concluding
    (OBJ-FOUND 7) under `OBJ-FOUND(n: 0..5)` fails there, and a user's conclusion or goal
    outside them is their mistake."""
    found = Predicate("OBJ-FOUND", "functional", 1, domains=(tuple(range(6)),))
    moved = Predicate("MOVE", "standard", 2, domains=(None, ("A", "B")))
    s = supervisor(ka("Count", "!(COUNT $N)", step("=>(OBJ-FOUND $N)", 3), line=2),
                   ka("Move", "!(MOVE $X $Y)", line=5), predicates=(found, moved))
    assert done(s, "!(COUNT 5)").status == "succeeded"
    late = done(s, "!(COUNT 7)")
    assert late.status == "failed" and s.database.facts("OBJ-FOUND") == [parse_fact("(OBJ-FOUND 5)")]
    assert "Count:3: =>(OBJ-FOUND $N) failed: =>(OBJ-FOUND 7): 7 is outside the domain the spec " \
           "declares for OBJ-FOUND's argument 1 ({0, 1, 2, 3, 4, 5})" in "\n".join(late.lines())
    with pytest.raises(ValueError, match=r"C is outside the domain the spec declares for MOVE's argument 2 \(\{A, B\}"):
        s.post("!(MOVE 99 C)")
    with pytest.raises(ValueError, match="9 is outside"):
        s.conclude("(OBJ-FOUND 9)")
    assert done(s, "!(MOVE 99 $Y)").status == "succeeded"  # an unbound argument is no value yet
    s.conclude("(~ (MOVE 1 A))")  # a standard predicate's negation, in the domain


# ---------------------------------------------------------------- preserve and maintain


def test_preserve_fails_the_ka_once_its_condition_stops_holding() -> None:
    s = supervisor(ka("Careful", "!(CAREFUL)", step("#(SAFE)", 3), step("^(GO)"), step("=>(MOVED)"), line=2))
    s.conclude("(SAFE)")
    intention = s.post("!(CAREFUL)")
    s.run()
    s.retract("(SAFE)")
    s.conclude("(GO)")
    s.run()
    assert intention.status == "failed" and s.database.facts("MOVED") == []
    assert "Careful:3: #(SAFE) no longer holds" in intention.lines()
    assert done(s, "!(CAREFUL)").status == "failed"  # not holding at the start: fails at once


def test_maintain_achieves_its_condition_again_before_going_on() -> None:
    lights = ka("SwitchOn", "!(LIGHT ON)", step("?(POWER)"), step("=>(LIGHT ON)"))
    s = supervisor(ka("Work", "!(WORK)", step("%(LIGHT ON)", 3), step("^(STEP 1)"), step("^(STEP 2)"),
                      step("=>(WORKED)"), line=2), lights)
    s.conclude("(POWER)")
    intention = s.post("!(WORK)")
    s.run()
    assert ran(intention, "SwitchOn") == 1  # did not hold at the start
    s.retract("(LIGHT ON)")  # someone switches it off while the KA waits
    s.run()
    assert ran(intention, "SwitchOn") == 2 and s.database.truth("(LIGHT ON)")
    s.conclude("(STEP 1)")
    s.retract("(POWER)")  # now it cannot be switched on again
    s.retract("(LIGHT ON)")
    s.conclude("(STEP 2)")
    s.run()
    assert intention.status == "failed" and s.database.facts("WORKED") == []
    assert any(line.startswith("Work:3: %(LIGHT ON) could not be achieved again") for line in intention.lines())


# ---------------------------------------------------------------- variables


def test_logic_variables_unify_once_program_variables_are_reassigned() -> None:
    s = supervisor(ka("Logic", "!(LOGIC $R)", step("!(= $X 1)"), step("!(= $X 1)"), step("!(= $X 2)", 4),
                      step("!(= $R $X)"), line=2),
                   ka("Program", "!(PROGRAM $R)", step("!(= @X 1)"), step("!(= @X 2)"),
                      Assign(Var("@X"), parse_term("(+ @X 10)")), step("!(= $R @X)")))
    logic = done(s, "!(LOGIC $R)")
    assert logic.status == "failed" and "Logic:4: $X is 1: it cannot become 2" in logic.lines()
    assert done(s, "!(PROGRAM $R)").bindings == {"$R": 12}


def test_a_program_variable_inside_an_expression_of_a_goal_is_read() -> None:
    """`!(NOTED (+ @I 1))`: @I is no argument of NOTED itself, so the goal reads it (a loop's
    counter passed on to a subgoal), as the Petri-net translation does."""
    s = supervisor(ka("Count", "!(COUNT)", Assign(Var("@I"), 2), step("!(NOTED (+ @I 1))", 3), line=2),
                   ka("Noted", "!(NOTED $N)", step("=>(SEEN $N)", 6), line=5))
    assert done(s, "!(COUNT)").status == "succeeded"
    assert s.database.facts("SEEN") == [parse_fact("(SEEN 3)")]


def test_a_logic_variable_once_bound_is_tested_not_rebound() -> None:
    s = supervisor(ka("Same", "!(SAME)", step("?(COLOUR $C)"), step("?(SHADE $C)")))
    s.conclude("(COLOUR RED)")
    s.conclude("(SHADE BLUE)")
    assert done(s, "!(SAME)").status == "failed"
    s.conclude("(SHADE RED)")
    assert done(s, "!(SAME)").status == "succeeded"


def test_a_program_variable_takes_a_fresh_value_at_each_test() -> None:
    # §5.5: ^(& (OBJ-FOUND @I) (> @I @TAKEN)) in a loop: @I is found afresh, @TAKEN is read.
    s = supervisor(ka("Take", "!(TAKE $N)", Assign(Var("@TAKEN"), 0),
                      While(goal("?(< @TAKEN $N)"), (step("^(& (OBJ-FOUND @I) (> @I @TAKEN))"),
                                                     step("=>(TOOK @I)"),
                                                     Assign(Var("@TAKEN"), parse_term("(+ @TAKEN 1)"))))),
                   predicates=(Predicate("OBJ-FOUND", "functional", 1),))
    s.conclude("(OBJ-FOUND 0)")
    intention = s.post("!(TAKE 2)")
    for found in (1, 2):
        s.run()
        assert intention.status == "running"
        s.conclude(f"(OBJ-FOUND {found})")
    s.run()
    assert intention.status == "succeeded"
    assert s.database.facts("TOOK") == [parse_fact("(TOOK 1)"), parse_fact("(TOOK 2)")]


# ---------------------------------------------------------------- KA selection


def test_the_invocation_and_the_context_select_the_ka() -> None:
    s = supervisor(ka("Fast", "!(GO $WHERE)", step("=>(WENT $WHERE FAST)"), context="?(MODE FAST)"),
                   ka("Slow", "!(GO $WHERE)", step("=>(WENT $WHERE $M)"), context="?(& (MODE $M) (= $M SLOW))"),
                   ka("Home", "!(GO HOME)", step("=>(WENT HOME DIRECT)")))
    s.conclude("(MODE SLOW)")
    assert done(s, "!(GO HALL)").status == "succeeded"
    assert s.database.facts("WENT") == [parse_fact("(WENT HALL SLOW)")]  # context bindings reach the body
    assert done(s, "!(STAY)").lines() == ["top:0: !(STAY) failed: no applicable KA for (STAY)"]


def test_every_applicable_ka_is_tried_before_the_goal_fails() -> None:
    kas = [ka(f"Try{n}", "!(REACH $X)", step(f"=>(TRIED {n})"), Fail(5), line=4) for n in (1, 2, 3)]
    s = supervisor(*kas)
    intention = done(s, "!(REACH DOOR)")
    assert intention.status == "failed"
    assert {ran(intention, k.name) for k in kas} == {1}
    assert len(s.database.facts("TRIED")) == 3
    assert intention.lines()[-1].startswith("top:0: !(REACH DOOR) failed: every applicable KA failed (")
    # With one good KA among them, the goal succeeds once that one is reached.
    good = ka("Good", "!(REACH $X)", step("=>(REACHED $X)"))
    s = supervisor(*kas, good, seed=None)  # library order: the three failures first
    intention = done(s, "!(REACH DOOR)")
    assert intention.status == "succeeded" and [ran(intention, k.name) for k in (*kas, good)] == [1, 1, 1, 1]


def test_the_seed_draws_the_order_of_applicable_kas() -> None:
    kas = [ka(f"Way{n}", "!(PICK)", step(f"=>(PICKED {n})")) for n in range(6)]
    picked = set()
    for seed in range(12):
        s = supervisor(*kas, seed=seed)
        done(s, "!(PICK)")
        picked.add(s.database.facts("PICKED")[0].args[0])
        again = supervisor(*kas, seed=seed)
        done(again, "!(PICK)")
        assert again.database.facts("PICKED") == s.database.facts("PICKED")  # reproducible
    assert len(picked) > 1
    s = supervisor(*kas, seed=None)
    done(s, "!(PICK)")
    assert s.database.facts("PICKED") == [parse_fact("(PICKED 0)")]


def test_no_backtracking_once_a_choose_branch_crossed_its_first_arc() -> None:
    s = supervisor(ka("Pick", "!(PICK)", Choose((
        (step("?(A)"), step("?(IMPOSSIBLE)", 4)),
        (step("?(B)"), step("=>(TOOK B)")),
    ), 3), line=2), seed=None)
    s.conclude("(B)")
    assert done(s, "!(PICK)").status == "succeeded"  # A's first arc fails: B's is tried
    s.conclude("(A)")
    intention = done(s, "!(PICK)")
    assert intention.status == "failed"
    assert intention.lines()[1:3] == ["Pick:3: choose: committed to branch 1",
                                      "Pick:4: ?(IMPOSSIBLE) failed: no solution"]
    assert s.database.facts("TOOK") == [parse_fact("(TOOK B)")]  # only from the first run
    s.retract("(A)")
    s.retract("(B)")
    nothing = done(s, "!(PICK)")
    assert nothing.status == "failed" and "Pick:3: choose: no branch's first step succeeded" in nothing.lines()


def test_a_choice_among_waits_takes_whichever_event_comes_first() -> None:
    for first, second in (("(REPLY 1 OK)", "(WARNING MOVE 1 ZOMBIE)"), ("(WARNING MOVE 1 ZOMBIE)", "(REPLY 1 OK)")):
        s = supervisor(ka("Await", "!(AWAIT $ID $HOW)", Choose((
            (step("^(REPLY $ID $RESULT)"), step("!(= $HOW REPLIED)")),
            (step("?(NEVER)"),),
            (step("^(WARNING $SERVICE $ID ZOMBIE)"), step("!(= $HOW FROZEN)")),
        ))))
        intention = s.post("!(AWAIT 1 $HOW)")
        s.run()
        assert intention.status == "running"  # a wait is not a failure: the choice waits
        s.signal(first)
        s.run()
        s.signal(second)
        s.run()
        assert intention.bindings == {"$HOW": "REPLIED" if first.startswith("(REPLY") else "FROZEN"}
        assert [str(e) for e in s.database.events("REPLY") + s.database.events("WARNING")] == [second]


def test_effects_run_after_a_successful_body_only() -> None:
    # Fig 4.1: count the long displacements.
    s = supervisor(ka("Long", "!(GOTO-FAR)", step("?(CLEAR)"), context="?(& (DISPLACEMENTS $I) (< $I 2))",
                      effects=("~>(DISPLACEMENTS $I)", "=>(DISPLACEMENTS (+ $I 1))")),
                   predicates=(Predicate("DISPLACEMENTS", "functional", 1),))
    s.conclude("(DISPLACEMENTS 0)")
    assert done(s, "!(GOTO-FAR)").status == "failed"  # the body fails: no effects
    s.conclude("(CLEAR)")
    assert [done(s, "!(GOTO-FAR)").status for _ in range(3)] == ["succeeded", "succeeded", "failed"]
    assert s.database.facts("DISPLACEMENTS") == [parse_fact("(DISPLACEMENTS 2)")]


# ---------------------------------------------------------------- fact-invoked and meta KAs


def test_facts_and_events_invoke_fact_kas_whose_context_holds() -> None:
    s = supervisor(ka("Avoid", "(OBSTACLE $SIDE)", step("=>(AVOIDED $SIDE)"), context="?(MOVING)"),
                   ka("Stop", "(ALARM $WHY)", step("=>(STOPPED $WHY)")),
                   predicates=(Predicate("ALARM", "event", 1),))
    s.conclude("(OBSTACLE LEFT)")  # not moving: not invoked
    s.conclude("(MOVING)")
    s.conclude("(OBSTACLE RIGHT)")
    s.conclude("(OBSTACLE RIGHT)")  # no change, no new invocation
    s.signal("(ALARM FIRE)")
    s.run()
    assert [(i.ka.name if i.ka else None, str(i.trigger), i.status) for i in s.intentions] == [
        ("Avoid", "(OBSTACLE RIGHT)", "succeeded"), ("Stop", "(ALARM FIRE)", "succeeded")]
    assert s.intentions[0].bindings == {"$SIDE": "RIGHT"}
    assert s.database.facts("AVOIDED") == [parse_fact("(AVOIDED RIGHT)")]
    assert s.database.events("ALARM") == []  # the invocation used the occurrence


def test_the_meta_hook_orders_and_filters_the_applicable_kas() -> None:
    kas = [ka(name, "!(FETCH)", step(f"=>(BY {name})"), Fail()) for name in ("Arm", "Crane", "Hand")]
    seen: list[tuple[str, list[str]]] = []

    def prefer_hand_never_crane(g: Goal, applicable: list[KA]) -> list[KA]:
        seen.append((str(g), [k.name for k in applicable]))
        return sorted((k for k in applicable if k.name != "Crane"), key=lambda k: k.name != "Hand")

    s = supervisor(*kas, seed=None, meta=prefer_hand_never_crane)
    assert done(s, "!(FETCH)").status == "failed"
    assert seen == [("!(FETCH)", ["Arm", "Crane", "Hand"])]
    assert s.database.facts("BY") == [parse_fact("(BY Hand)"), parse_fact("(BY Arm)")]


def test_a_meta_ka_chooses_among_the_kas_applicable_to_its_goals() -> None:
    asked: list[tuple[list[str], str]] = []

    def cheapest_first(ctx: Any, what: str) -> list[str]:
        asked.append((list(ctx.candidates), what))
        return sorted(ctx.candidates, reverse=True)[:2]

    kas = [ka(name, "!(FETCH $X)", step(f"=>(BY {name} $X)"), Fail()) for name in ("Arm", "Crane", "Hand")]
    meta = ka("Cheapest", "!(FETCH $WHAT)", action="(RANK $WHAT)", meta=True)
    s = supervisor(*kas, meta, ka("Lone", "!(LIFT $X)", step("=>(LIFTED $X)")), seed=None,
                   primitives=(Primitive("RANK", 1, "robot.rank", returns=True),),
                   functions={"robot.rank": cheapest_first})
    intention = done(s, "!(FETCH BOX)")
    assert asked == [(["Arm", "Crane", "Hand"], "BOX")]
    assert [str(f) for f in s.database.facts("BY")] == ["(BY Hand BOX)", "(BY Crane BOX)"]  # Arm left out
    assert "top:0: meta KA Cheapest chose Hand, Crane" in intention.lines()
    assert done(s, "!(LIFT BOX)").status == "succeeded" and len(asked) == 1  # one KA: nothing to choose
    assert done(s, "!(FETCH-ALL)").status == "failed"  # a meta KA is never run as an ordinary KA


# ---------------------------------------------------------------- control statements


def test_if_else_and_while() -> None:
    s = supervisor(ka("Sort", "!(SORT $X)", If(goal("?(> $X 10)"), (step("=>(BIG $X)"),), (step("=>(SMALL $X)"),))),
                   ka("Count", "!(COUNT $N)", Assign(Var("@I"), 0),
                      While(goal("?(< @I $N)"), (step("=>(SEEN @I)"), Assign(Var("@I"), parse_term("(+ @I 1)"))))))
    for x in (5, 50):
        assert done(s, f"!(SORT {x})").status == "succeeded"
    assert [str(f) for f in s.database.facts("BIG") + s.database.facts("SMALL")] == ["(BIG 50)", "(SMALL 5)"]
    assert done(s, "!(COUNT 3)").status == "succeeded"
    assert [f.args[0] for f in s.database.facts("SEEN")] == [0, 1, 2]


def test_parallel_branches_join_when_all_succeeded() -> None:
    s = supervisor(ka("Both", "!(BOTH)", Parallel(((step("^(LEFT-DONE)"), step("=>(L)")),
                                                   (step("^(RIGHT-DONE)"), step("=>(R)")))), step("=>(JOINED)")))
    intention = s.post("!(BOTH)")
    s.run()
    s.conclude("(RIGHT-DONE)")
    s.run()
    assert intention.status == "running" and s.database.facts("R") and not s.database.facts("JOINED")
    s.conclude("(LEFT-DONE)")
    s.run()
    assert intention.status == "succeeded" and s.database.facts("JOINED")


def test_a_failed_branch_fails_the_ka_and_its_siblings_run_on_detached() -> None:
    s = supervisor(ka("Cycles", "!(CYCLES)", Parallel((
        (step("^(RELEASE)"), step("=>(FIRST-DONE)")),
        (step("?(IMPOSSIBLE)", 5),),
    ), 3), step("=>(JOINED)"), line=2))
    intention = done(s, "!(CYCLES)")
    assert intention.status == "failed"
    assert "Cycles:3: parallel branch 2 failed: the KA fails; 1 other branch(es) keep running, detached" in \
        intention.lines()
    s.conclude("(RELEASE)")
    s.run()
    assert s.database.facts("FIRST-DONE") and not s.database.facts("JOINED")  # §5.4.1: it did not stop
    assert intention.status == "failed"
    assert intention.lines()[-1] == "Cycles:3: detached parallel branch succeeded (its outcome is discarded)"


def test_a_busy_intention_does_not_starve_another() -> None:
    s = supervisor(ka("Spin", "!(SPIN)", While(goal("?(= 1 1)"), (step("=>(~ (IDLE))"),))),
                   ka("Chores", "!(CHORES)", *(step(f"=>(CHORE {n})") for n in range(10))))
    spin, chores = s.post("!(SPIN)"), s.post("!(CHORES)")
    s.run(max_steps=40)
    assert chores.status == "succeeded" and spin.status == "running"


def test_a_kernel_turn_runs_at_most_steps_per_turn_steps() -> None:
    kernel = Kernel()
    s = supervisor(ka("Chores", "!(CHORES)", *(step(f"=>(CHORE {n})") for n in range(12))), kernel=kernel,
                   steps_per_turn=5)
    intention = s.post("!(CHORES)")
    counts = []
    while kernel.step():
        counts.append(len(s.database.facts("CHORE")))
    assert intention.status == "succeeded" and len(counts) > 2
    assert all(b - a <= 5 for a, b in zip([0, *counts], counts, strict=False))


def test_a_loop_that_never_waits_is_abandoned_and_time_goes_on(monkeypatch: pytest.MonkeyPatch) -> None:
    """On a kernel, a KA looping without ever waiting would hold the robot's time at one instant
    for ever (a `specc run` that never ends). Past STEPS_PER_INSTANT steps at one instant its
    intention is abandoned, saying where it stood; another intention and the clock go on."""
    from specc.runtime import supervisor as rp

    monkeypatch.setattr(rp, "STEPS_PER_INSTANT", 300)
    kernel = Kernel()
    s = supervisor(ka("Spin", "!(SPIN)", While(goal("?(= 1 1)", 7), (step("=>(~ (IDLE))", 8),)), line=6),
                   ka("Chores", "!(CHORES)", *(step(f"=>(CHORE {n})") for n in range(10))), kernel=kernel)
    spin, chores = s.post("!(SPIN)"), s.post("!(CHORES)")
    kernel.call_later(5.0, lambda: None)
    kernel.run_for(10.0)
    assert chores.status == "succeeded" and spin.status == "failed" and kernel.now == 10.0
    said = spin.lines()[-1]
    assert said.startswith("top:0: abandoned: it ran 300 steps at 0 s with no time passing (at Spin:")
    assert "a loop that never waits" in said


def test_a_recursion_without_end_ends_its_intention_and_one_with_an_end_runs_to_it() -> None:
    """A KA posting its own goal before anything stops it nests KAs without end (Python's stack
    gave out, and the run crashed): at MOST_NESTED_KAS the intention is abandoned, saying so. A
    recursion that ends runs as deep as it needs below that."""
    from specc.runtime.supervisor import MOST_NESTED_KAS

    endless = supervisor(ka("Spot", "!(SPOT $X)", step("!(SPOT $X)", 19), line=17), ka("Ping", "!(PING)", step(
        "!(PONG)", 3)), ka("Pong", "!(PONG)", step("!(PING)", 5)),
        # through a parallel branch: each branch is a thread of its own, its KAs nested in its parent's
        ka("Fork", "!(FORK)", Parallel(((step("!(FORK)", 41),), (step("=>(FORKED)", 42),)), 40), line=39))
    for posted, chain in (("!(SPOT 4)", "Spot -> Spot for (SPOT 4)"), ("!(PING)", "Pong -> Ping for (PING)"),
                          ("!(FORK)", "Fork for (FORK)")):
        failed = done(endless, posted)
        assert failed.status == "failed", posted
        assert failed.lines()[-1].startswith(f"top:0: abandoned: KAs nested {MOST_NESTED_KAS} deep (... ")
        assert f"{chain}), the most the supervisor runs (MOST_NESTED_KAS): most often a KA posting its own goal, " \
            "or KAs posting each other's" in failed.lines()[-1]
    counting = supervisor(ka("Down", "!(DOWN $N)", If(goal("?(> $N 0)"), (step("!(DOWN (- $N 1))"),),
                                                     (step("=>(BOTTOM)"),)), line=30))
    assert done(counting, f"!(DOWN {MOST_NESTED_KAS - 1})").status == "succeeded"  # that many KAs nested
    assert done(counting, f"!(DOWN {MOST_NESTED_KAS})").status == "failed"  # one more


def test_a_recursion_deeper_than_python_s_stack_ends_its_intention_too(monkeypatch: pytest.MonkeyPatch) -> None:
    from specc.runtime import supervisor as rp

    monkeypatch.setattr(rp, "MOST_NESTED_KAS", 100_000)  # each KA nests statements: Python's stack ends first
    counting = supervisor(ka("Down", "!(DOWN $N)", If(goal("?(> $N 0)"), (step("!(DOWN (- $N 1))"),),
                                                     (step("=>(BOTTOM)"),)), line=30))
    failed = done(counting, "!(DOWN 5000)")
    assert failed.status == "failed" and "KAs nested too deep for Python's stack" in failed.lines()[-1]
    assert done(counting, "!(DOWN 3)").status == "succeeded"  # the supervisor goes on


def test_a_failed_goal_says_why_each_applicable_ka_failed() -> None:
    s = supervisor(ka("Count", "!(COUNT)", Assign(Var("@N"), parse_term("(+ @N 1)"), 71), line=70),
                   ka("Other", "!(COUNT)", Fail(81), line=80))
    failed = done(s, "!(COUNT)")
    assert failed.status == "failed"
    last = failed.lines()[-1]
    assert "every applicable KA failed (" in last and "Count: line 71: " in last and "@N" in last
    assert "Other: line 81: fail" in last


# ---------------------------------------------------------------- primitive KAs


def test_a_primitive_that_raises_or_lacks_an_argument_fails_its_ka() -> None:
    def grip(ctx: Any, force: int) -> str:
        if force > 10:
            raise OverflowError("too hard")
        ctx.log(f"gripping at {force}")
        return "HELD"

    s = supervisor(ka("Grip", "!(GRIP $F $STATE)", action="(GRIP $F)", result="$STATE", line=8),
                   primitives=(Primitive("GRIP", 1, "arm.grip", returns=True),), functions={"arm.grip": grip})
    held = done(s, "!(GRIP 3 $S)")
    assert held.bindings == {"$S": "HELD"}
    assert held.lines()[1:3] == ["Grip:8: operator: gripping at 3", "Grip:8: (GRIP 3) -> 'HELD'"]
    crushed = done(s, "!(GRIP 30 $S)")
    assert crushed.status == "failed" and "Grip:8: (GRIP 30) raised OverflowError: too hard" in crushed.lines()
    unbound = done(s, "!(GRIP $F $S)")
    assert unbound.status == "failed" and "Grip:8: (GRIP $F): $F is unbound" in unbound.lines()


def test_a_primitive_returning_outside_its_result_domain_fails_its_ka() -> None:
    """`action GRIP(force: int) -> {HELD, SLIPPED}`: `specc verify --goal` assumes one of those two,
    so the supervisor refuses anything else (a typo in the Python) instead of running on it."""
    def grip(ctx: Any, force: int) -> str:
        return "HELD" if force < 5 else "HLED"

    s = supervisor(ka("Grip", "!(GRIP $F $STATE)", action="(GRIP $F)", result="$STATE", line=8),
                   primitives=(Primitive("GRIP", 1, "arm.grip", returns=True, domain=("HELD", "SLIPPED")),),
                   functions={"arm.grip": grip})
    assert done(s, "!(GRIP 3 $S)").bindings == {"$S": "HELD"}
    typo = done(s, "!(GRIP 7 $S)")
    assert typo.status == "failed"
    assert "Grip:8: (GRIP 7) returned 'HLED', which is not in the domain of its result (HELD, SLIPPED)" in typo.lines()


# ---------------------------------------------------------------- Fig 4.3 against the executive


# Fig 4.3, written two ways. As one wait on the disjunction, after which the warning is known by
# $RESULT being still unbound (the wait used the event: it cannot be tested again):
DISJUNCTION = (
    step("^(| (REPLY $ID $RESULT) (WARNING $REQUEST $ID ZOMBIE))", 12),
    If(goal("?(~ (BOUNDP $RESULT))", 13), (step("!(WARN-OPERATOR $REQUEST $ID)", 14),
                                           step("!(SEND-INTERRUPT $ID)", 15),
                                           step("^(REPLY $ID $RESULT)", 16)), (), 13),
)
# As the figure's two wait arcs leaving one node (examples/hilare/procedures.spec):
TWO_ARCS = (
    Choose(((step("^(REPLY $ID $RESULT)", 13),),
            (step("^(WARNING $REQUEST $ID ZOMBIE)", 14), step("!(WARN-OPERATOR $REQUEST $ID)", 15),
             step("!(SEND-INTERRUPT $ID)", 16), step("^(REPLY $ID $RESULT)", 17))), 12),
)


def exec_request_library(after_sending: tuple[Statement, ...]) -> tuple[Library, dict[str, Callable[..., Any]]]:
    """Figs 4.2 and 4.3."""

    def send_request(ctx: Any, request: str) -> int:
        ident: int = ctx.new_id()
        ctx.send((request, ident))
        return ident

    def send_interrupt(ctx: Any, ident: int) -> None:
        ctx.send(("INT", ident))

    def warn_operator(ctx: Any, request: str, ident: int) -> None:
        ctx.log(f"service {request} ({ident}) is ZOMBIE: interrupting it")

    exec_request = ka("ExecRequest", "!(EXEC-REQUEST $REQUEST $RESULT)", step("!(SEND-REQUEST $REQUEST $ID)", 11),
                      *after_sending, line=10)
    library = Library(
        "tasks",
        # REPLY is declared a basic event (§4.4.2); WARNING is left undeclared: still signalled.
        predicates=(Predicate("REPLY", "event", 2),),
        primitives=(Primitive("SEND-REQUEST", 1, "prs.send_request", returns=True),
                    Primitive("SEND-INTERRUPT", 1, "prs.send_interrupt"),
                    Primitive("WARN-OPERATOR", 2, "prs.warn_operator")),
        kas=(ka("SendRequest", "!(SEND-REQUEST $REQUEST $ID)", action="(SEND-REQUEST $REQUEST)", result="$ID"),
             ka("SendInterrupt", "!(SEND-INTERRUPT $ID)", action="(SEND-INTERRUPT $ID)"),
             ka("WarnOperator", "!(WARN-OPERATOR $REQUEST $ID)", action="(WARN-OPERATOR $REQUEST $ID)"),
             exec_request),
    )
    functions = {"prs.send_request": send_request, "prs.send_interrupt": send_interrupt,
                 "prs.warn_operator": warn_operator}
    return library, functions


@pytest.fixture
def executive(shop_package: ModuleType) -> Any:  # noqa: F811 - the imported fixture
    from specc.runtime import functional as rt

    registry = rt.Registry()
    importlib.import_module("shop.modules").create_all(registry)
    return importlib.import_module("shop.executive.shop").create(registry)


def until_done(s: Supervisor, intention: Intention, seconds: float = 5.0) -> None:
    assert s.kernel is not None
    s.kernel.run_while(lambda: intention.status == "running", s.kernel.now + seconds)


@pytest.mark.parametrize("after_sending", [DISJUNCTION, TWO_ARCS], ids=["disjunction", "two-arcs"])
def test_exec_request_returns_the_executive_s_reply(executive: Any, after_sending: tuple[Statement, ...]) -> None:
    library, functions = exec_request_library(after_sending)
    s = Supervisor(library, functions, executive=executive)
    executive.context.vars["next"] = ["exec,exec"]
    intention = s.post("!(EXEC-REQUEST FREE $RESULT)")
    until_done(s, intention)
    assert intention.status == "succeeded" and intention.bindings == {"$RESULT": "OK"}
    assert s.kernel is executive.kernel and executive.activities == {}
    assert s.database.events("REPLY") == []  # the wait used it
    unknown = s.post("!(EXEC-REQUEST FLY $RESULT)")
    until_done(s, unknown)
    assert unknown.bindings == {"$RESULT": "BAD-SERVICE"}


@pytest.mark.parametrize("after_sending", [DISJUNCTION, TWO_ARCS], ids=["disjunction", "two-arcs"])
def test_exec_request_interrupts_a_zombie_and_returns_the_final_reply(executive: Any,
                                                                     after_sending: tuple[Statement, ...]) -> None:
    library, functions = exec_request_library(after_sending)
    warnings: list[str] = []
    s = Supervisor(library, functions, executive=executive, log=warnings.append)
    executive.context.vars["next"] = ["exec,zombie"]
    intention = s.post("!(EXEC-REQUEST FREE $RESULT)")
    until_done(s, intention)
    assert intention.status == "succeeded"
    assert intention.bindings == {"$RESULT": "ZOMBIE"}  # the final reply after the interruption
    assert warnings == ["service FREE (1) is ZOMBIE: interrupting it"]
    assert [m.fact for m in executive.messages] == [("WARNING", "FREE", 1, "ZOMBIE"), ("REPLY", 1, "ZOMBIE")]
    assert executive.activities == {} and executive.zombies == {}  # the module is released
    assert ran(intention, "SendInterrupt") == 1
    executive.context.vars["next"] = ["exec"]
    after = s.post("!(EXEC-REQUEST FREE $RESULT)")  # the module accepts requests again
    until_done(s, after)
    assert after.bindings == {"$RESULT": "OK"}


def test_a_supervisor_on_another_kernel_than_its_executive_s_is_refused(executive: Any) -> None:
    """Its intentions would wait for replies that come on the executive's clock only."""
    library, functions = exec_request_library(TWO_ARCS)
    with pytest.raises(ValueError, match="the supervisor runs on its executive's kernel"):
        Supervisor(library, functions, kernel=Kernel(), executive=executive)
    assert Supervisor(library, functions, kernel=executive.kernel, executive=executive).kernel is executive.kernel


def test_the_supervisor_s_request_ids_are_none_another_client_gave(executive: Any) -> None:
    """A program's own request with id 1 (refused: BAD-SERVICE) before the supervisor's first:
    the supervisor's request gets an id of its own, and its reply, not the program's."""
    library, functions = exec_request_library(TWO_ARCS)
    s = Supervisor(library, functions, executive=executive)
    executive.request("FLY", 1)
    executive.kernel.run_for(0.1)
    executive.context.vars["next"] = ["exec"]
    intention = s.post("!(EXEC-REQUEST FREE $RESULT)")
    until_done(s, intention)
    assert intention.bindings == {"$RESULT": "OK"} and intention.requests == [2]


def test_a_reply_outside_its_declared_domain_is_received_and_noted_as_an_incident(executive: Any) -> None:
    """The executive's BAD-SERVICE is not in REPLY's declared domain: the procedures' proofs did
    not cover it, which the executive notes; the robot still gets the reply, as it would."""
    library, functions = exec_request_library(TWO_ARCS)
    reply = Predicate("REPLY", "event", 2, domains=(None, ("OK", "ZOMBIE")))
    s = Supervisor(dataclasses.replace(library, predicates=(reply,)), functions, executive=executive)
    executive.context.vars["next"] = ["exec"]
    ok = s.post("!(EXEC-REQUEST FREE $RESULT)")
    until_done(s, ok)
    assert ok.bindings == {"$RESULT": "OK"} and executive.incidents == []
    unknown = s.post("!(EXEC-REQUEST FLY $RESULT)")
    until_done(s, unknown)
    assert unknown.bindings == {"$RESULT": "BAD-SERVICE"}
    assert executive.incidents == ["the supervisor received (REPLY 2 BAD-SERVICE): BAD-SERVICE is outside the "
                                   "domain the spec declares for REPLY's argument 2 ({OK, ZOMBIE}), which `specc "
                                   "verify --goal` assumes: add BAD-SERVICE to it"]


def test_a_failed_test_says_what_its_variables_held() -> None:
    # The reply a procedure tested is in the trace: why a goal failed, without listening to the executive.
    s = supervisor(ka("Go", "!(GO $R)", step("?(= $R OK)", 2), line=1), seed=None)
    intention = done(s, "!(GO ERROR)")
    assert intention.status == "failed"
    assert "Go:2: ?(= $R OK) failed: no solution ($R = ERROR)" in intention.lines()
