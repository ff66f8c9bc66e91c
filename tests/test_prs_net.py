"""Procedures -> coloured Petri net (seed 000 §4.4) and its analysis (§4.5): small KAs with known
answers (a deadlock, unbounded recursion, a branch that can never fire), the constructs a net
cannot represent, and the Hilare 2 task level of §5.4 with the findings of §5.4.1."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from specc.analysis import petri
from specc.analysis.prs_net import TranslationError
from specc.analysis.prs_verify import Report, parse_query, translate, verify
from specc.model import nodes as m
from specc.pipeline import load
from specc.runtime import procedures as rp
from tests.conftest import EXAMPLES


def program_of(text: str, folder: Path) -> m.Program:
    spec = folder / "tasks.spec"
    spec.write_text(text, encoding="utf-8")
    loaded = load([spec])
    assert loaded.program is not None and not loaded.errors, [d.message for d in loaded.errors]
    return loaded.program


def check(text: str, goal: str, folder: Path, **options: object) -> Report:
    program = program_of(text, folder)
    block = next(i for i in program.items if isinstance(i, m.Procedures))
    return verify(program, block, [rp.parse_goal(goal)], **options)  # type: ignore[arg-type]


def finding(report: Report, kind: str) -> str:
    found = [f for f in report.findings if f.kind == kind]
    assert found, f"no {kind} among {report.kinds()}"
    return found[0].message


DEADLOCK = """
procedures handshake {
  predicate closed LEFT-READY();
  predicate closed RIGHT-READY();
  predicate MEET();
  predicate LEFT();
  predicate RIGHT();
  ka Meet {
    invocation: !(MEET);
    body {
      parallel {
        branch { !(LEFT); }
        branch { !(RIGHT); }
      }
    }
  }
  ka Left {
    invocation: !(LEFT);
    body {
      ^(RIGHT-READY);
      =>(LEFT-READY);
    }
  }
  ka Right {
    invocation: !(RIGHT);
    body {
      ^(LEFT-READY);
      =>(RIGHT-READY);
    }
  }
}
"""


def test_two_kas_each_waiting_for_the_other_deadlock_with_where_each_one_waits(tmp_path: Path) -> None:
    report = check(DEADLOCK, "!(MEET)", tmp_path)
    deadlock = report.findings[0]
    assert deadlock.kind == "deadlock"
    assert any(w.startswith("Left:20 ^(RIGHT-READY)") for w in deadlock.where), deadlock.where
    assert any(w.startswith("Right:27 ^(LEFT-READY)") for w in deadlock.where), deadlock.where
    # the trace is the shortest one: the split, then each KA started
    assert deadlock.trace[0].startswith("goal MEET") and any("goal RIGHT: start Right" in s for s in deadlock.trace)
    assert report.succeeded == report.failed == 0
    # what the deadlock leaves behind: both waits can never be crossed
    assert "Left:20 ^(RIGHT-READY) is reached but can never succeed" in " ".join(report.findings[i].message
                                                                               for i in range(len(report.findings)))


def test_the_handshake_in_the_right_order_ends_with_the_goal_achieved(tmp_path: Path) -> None:
    fixed = DEADLOCK.replace("^(RIGHT-READY);\n      =>(LEFT-READY);", "=>(LEFT-READY);\n      ^(RIGHT-READY);")
    report = check(fixed, "!(MEET)", tmp_path)
    assert report.findings == [] and report.succeeded >= 1 and report.failed == 0


REAL_VALUES = """
procedures docking {
  type XS = {1.5, 10};
  predicate GO(x: XS);
  predicate TOP();
  predicate functional DONE(v: {YES});
  ka Top { invocation: !(TOP); body { !(GO 1.5); } }
  ka Go { invocation: !(GO $X); body { =>(DONE YES); } }
}
"""


@pytest.mark.parametrize("value", ["1.5", "10"])
def test_a_type_of_real_numbers_holds_the_numbers_goals_write(tmp_path: Path, value: str) -> None:
    """`{1.5, 10}` holds the number 1.5 a goal writes (not the symbol "1.5"): the goal is achieved,
    whichever value it names, and check finds 1.5 in the domain of GO's argument."""
    report = check(REAL_VALUES.replace("!(GO 1.5)", f"!(GO {value})"), "!(TOP)", tmp_path)
    assert report.findings == [] and report.succeeded >= 1 and report.failed == 0

RECURSION = """
procedures digging {
  predicate DIG();
  ka Dig {
    invocation: !(DIG);
    body {
      !(DIG);
    }
  }
}
"""


def test_a_ka_posting_its_own_goal_recurses_without_bound(tmp_path: Path) -> None:
    report = check(RECURSION, "!(DIG)", tmp_path)
    message = finding(report, "unbounded")
    assert message.startswith("Dig:7 waits for !(DIG): tokens pile up without bound")
    assert "Dig:7 !(DIG) post" in message  # the repeating sequence
    unbounded = next(f for f in report.findings if f.kind == "unbounded")
    assert any(step.startswith("Dig:7 !(DIG) post") for step in unbounded.trace), unbounded.trace
    # Cut where it grows, not stopped by the state limit: more states would not end it.
    assert not report.space.complete and not report.space.limit_reached
    assert check(DEADLOCK, "!(MEET)", tmp_path, limit=1).space.limit_reached


DEAD_BRANCH = """
procedures doors {
  predicate closed DOOR(state: {OPEN, CLOSED});
  predicate closed INSIDE();
  predicate GO();
  ka Go {
    invocation: !(GO);
    body {
      =>(DOOR CLOSED);
      choose {
        branch {
          ?(DOOR OPEN);
          =>(INSIDE);
        }
        branch {
          ?(DOOR CLOSED);
        }
      }
    }
  }
}
"""


def test_a_branch_whose_arc_is_never_true_is_a_dead_transition(tmp_path: Path) -> None:
    report = check(DEAD_BRANCH, "!(GO)", tmp_path)
    assert "Go:12 ?(DOOR OPEN) is reached but can never succeed" in finding(report, "never-succeeds")
    dead = next(f for f in report.findings if f.kind == "never-succeeds")
    assert dead.trace[-2:] == ["Go:9 =>(DOOR CLOSED)", "Go:10 choose"]  # how the dead arc is reached
    assert "13 =>(INSIDE)" in finding(report, "unreachable")
    assert report.succeeded >= 1 and report.failed == 0  # the other branch is tried (Fig 4.22)


def test_when_every_branch_fails_the_ka_and_its_goal_fail(tmp_path: Path) -> None:
    report = check(DEAD_BRANCH.replace("?(DOOR CLOSED);\n        }", "?(DOOR OPEN);\n        }"), "!(GO)", tmp_path)
    assert report.failed >= 1 and report.succeeded == 0


SEVERAL_KAS = """
procedures fetching {
  predicate closed HAVE(thing: {TOOL});
  predicate closed SHELF-EMPTY();
  predicate FETCH(thing: {TOOL});
  predicate START();
  ka Start {
    invocation: !(START);
    body {
      =>(SHELF-EMPTY);
      !(FETCH TOOL);
    }
  }
  ka FromShelf {
    invocation: !(FETCH $T);
    context: ?(~ (SHELF-EMPTY));
    body { =>(HAVE $T); }
  }
  ka FromStore {
    invocation: !(FETCH $T);
    body { =>(HAVE $T); }
  }
}
"""


def test_several_kas_for_one_goal_are_tried_in_turn_before_it_fails(tmp_path: Path) -> None:
    report = check(SEVERAL_KAS, "!(START)", tmp_path)
    # FromShelf is tried and given up at once: its body never runs here.
    assert report.kinds() == ["unreachable"] and "FromShelf" in report.findings[0].message
    assert report.succeeded >= 1 and report.failed == 0
    # FromShelf's context is never true here: it is tried, fails, and FromStore achieves the goal.
    names = {step.transition for i in report.space.fired() for step in report.space.unfolded.steps[i].elementary}
    assert "goal FETCH: FromShelf fails, try another" in names and "goal FETCH: FromStore succeeds" in names
    without = SEVERAL_KAS.replace("body { =>(HAVE $T); }\n  }\n}", "body { fail; }\n  }\n}")
    assert check(without, "!(START)", tmp_path).failed >= 1


FACT_INVOKED = """
procedures alarms {
  predicate closed ALARM();
  predicate closed HANDLED();
  predicate RAISE();
  ka Raise {
    invocation: !(RAISE);
    body {
      =>(ALARM);
      ^(HANDLED);
    }
  }
  ka OnAlarm {
    invocation: (ALARM);
    body { =>(HANDLED); }
  }
}
"""


def test_a_conclusion_invokes_the_kas_waiting_for_that_fact(tmp_path: Path) -> None:
    report = check(FACT_INVOKED, "!(RAISE)", tmp_path)
    assert report.findings == [] and report.succeeded >= 1
    without = FACT_INVOKED.replace("invocation: (ALARM);", "invocation: (HANDLED);")
    assert "deadlock" in check(without, "!(RAISE)", tmp_path).kinds()


@pytest.mark.parametrize("statement, code, column", [
    ("#(DOOR OPEN);", "unsupported-goal", 7),
    ("%(DOOR OPEN);", "unsupported-goal", 7),
    ("?(COUNT $N);", "unbounded-variable", 15),
    ("?(PING);", "event-test", 7),
    ("choose { branch { fail; } branch { !(GO); } }", "choose-first-arc", None),  # the line (one holds both)
])
def test_constructs_a_net_cannot_represent_are_rejected_where_they_are(tmp_path: Path, statement: str, code: str,
                                                                       column: int | None) -> None:
    text = f"""procedures limits {{
  predicate closed DOOR(state: {{OPEN, CLOSED}});
  predicate functional COUNT(n: int);
  predicate event PING();
  predicate GO();
  ka Go {{
    invocation: !(GO);
    body {{
      {statement}
    }}
  }}
}}
"""
    program = program_of(text, tmp_path)
    block = next(i for i in program.items if isinstance(i, m.Procedures))
    with pytest.raises(TranslationError) as raised:
        translate(program, block, [rp.parse_goal("!(GO)")])
    (diagnostic,) = raised.value.diagnostics
    assert diagnostic.code == code
    assert diagnostic.span.line == 9 and column in (None, diagnostic.span.column), diagnostic.span


def test_a_meta_ka_is_rejected_for_the_goals_it_arbitrates(tmp_path: Path) -> None:
    text = """procedures choosing {
  predicate GO();
  action PREFER() = "tasks_codels.prefer";
  ka Go { invocation: !(GO); body { fail; } }
  ka Policy { invocation: !(GO); property: meta; action: (PREFER); }
}
"""
    (tmp_path / "tasks_codels.py").write_text("def prefer(ctx):\n    return ctx.candidates\n", encoding="utf-8")
    program = program_of(text, tmp_path)
    block = next(i for i in program.items if isinstance(i, m.Procedures))
    with pytest.raises(TranslationError) as raised:
        translate(program, block, [rp.parse_goal("!(GO)")])
    assert [d.code for d in raised.value.diagnostics] == ["unsupported-meta"]
    assert raised.value.diagnostics[0].span.line == 5


# ---------------------------------------------------------------- Hilare 2, §5.4


@pytest.fixture(scope="module")
def hilare() -> tuple[m.Program, m.Procedures]:
    loaded = load([EXAMPLES / "hilare"])
    assert loaded.program is not None
    return loaded.program, next(i for i in loaded.program.items if isinstance(i, m.Procedures))


def test_hilare_no_deadlock_and_an_endless_cycle_when_no_object_is_found(hilare: tuple[m.Program, m.Procedures]
                                                                         ) -> None:
    report = verify(*hilare, [rp.parse_goal("!(COLLECT-OBJECTS 1)")])
    assert report.space.complete and "deadlock" not in report.kinds()
    assert report.kinds() == ["endless-cycle"]
    message = report.findings[0].message
    assert message.startswith("Explore, Modelise may cycle forever")
    assert "service SEARCH-OBJ answers  [answer (EXEC-COUNT SEARCH-OBJ 1)]" in message  # the only way out
    assert report.succeeded >= 1 and report.failed == 0  # every end is the goal achieved
    assert report.bound_summary() == "every KA place holds at most 1 token(s)"  # one intention per task


def test_hilare_the_others_never_stop_once_object_taking_fails(hilare: tuple[m.Program, m.Procedures]) -> None:
    report = verify(*hilare, [rp.parse_goal("!(COLLECT-OBJECTS 1)")], failing=["ARM-OBJ"])
    assert "deadlock" not in report.kinds()
    stuck = next(f for f in report.findings if f.kind == "no-way-out")
    assert stuck.message.startswith("Explore, Modelise cycle forever") and "nothing can stop them" in stuck.message
    assert "TakeObject:234 !(EXEC-REQUEST-OK ARM-OBJ) [false]" in stuck.trace
    assert "goal TAKE-OBJECT: TakeObject fails" in stuck.trace
    assert not any(w.startswith("TakeObject") for w in stuck.where)


def test_hilare_an_exploration_cycle_may_start_while_an_object_waits(hilare: tuple[m.Program, m.Procedures]) -> None:
    waiting = parse_query("Explore:254; TakeObject:236 ?(& (OBJ-FOUND @I) (> @I (+ @TAKEN 1)))")
    impossible = parse_query("Explore:254; TakeObject:236 ?(& (OBJ-FOUND @I) (> @I 5))")
    report = verify(*hilare, [rp.parse_goal("!(COLLECT-OBJECTS 1)")], queries=[waiting, impossible])
    reached, never = report.answers
    assert reached.reached and not never.reached
    assert any(w.startswith("TakeObject:236 !(EXEC-REQUEST-OK ARM-BACK)") for w in reached.where)
    assert any(w.startswith("Explore:253 while ?(EXECUTION GO): true") for w in reached.where)


def test_hilare_services_run_only_when_their_group_allows(hilare: tuple[m.Program, m.Procedures]) -> None:
    """§5.4.1: EXEC-TRAJ-GOAL never runs while its group holds EXEC-TRAJ-OBJ, nor while ARM-OBJ
    or CALC-TRAJ-OBJ (groups of Table 5.7) run."""
    translation = translate(*hilare, [rp.parse_goal("!(COLLECT-OBJECTS 1)")])
    starts = translation.net.transitions["service EXEC-TRAJ-GOAL starts"]
    bindings = starts.bindings or ()
    assert bindings and all("ARM-OBJ" not in b.values() and "CALC-TRAJ-OBJ" not in b.values() for b in bindings)
    assert {"ExecTrajState", "ARM_OBJ_ARM_BACKstate"} <= {a.place for a in starts.inputs}


def test_the_translated_net_exports_to_pnml(hilare: tuple[m.Program, m.Procedures]) -> None:
    translation = translate(*hilare, [rp.parse_goal("!(COLLECT-OBJECTS 1)")])
    root = ET.fromstring(petri.to_pnml(translation.net))
    ns = {"p": petri.PNML}
    places = root.findall(".//p:place", ns)
    assert len(places) == len(translation.net.unfold().slots)
    marked = [p for p in places if p.find("p:initialMarking", ns) is not None]
    assert any("COLLECT-OBJECTS.POST" in (p.findtext("p:name/p:text", namespaces=ns) or "") for p in marked)


# ---------------------------------------------------------------- the net and the interpreter agree

FIXED_HANDSHAKE = DEADLOCK.replace("^(RIGHT-READY);\n      =>(LEFT-READY);", "=>(LEFT-READY);\n      ^(RIGHT-READY);")
NO_STORE = SEVERAL_KAS.replace("body { =>(HAVE $T); }\n  }\n}", "body { fail; }\n  }\n}")
NOBODY_LISTENS = FACT_INVOKED.replace("invocation: (ALARM);", "invocation: (HANDLED);")


# A program variable set by a subgoal, then compared: the test reads the value it holds (A), it does
# not bind it afresh to B.
PROGRAM_VARIABLE_TESTED = """
procedures mini {
  predicate GET(v: {A, B});
  predicate GO();
  ka Get { invocation: !(GET $V); body { !(= $V A); } }
  ka Main {
    invocation: !(GO);
    body {
      !(GET @R);
      if ?(= @R B) { fail; }
    }
  }
}
"""


def test_a_test_compares_the_value_a_program_variable_holds(tmp_path: Path) -> None:
    report = check(PROGRAM_VARIABLE_TESTED, "!(GO)", tmp_path)
    assert report.succeeded >= 1 and report.failed == 0, report.kinds()
    assert finding(report, "unreachable").endswith("10 fail")


@pytest.mark.parametrize("text, goal", [
    (DEADLOCK, "!(MEET)"), (FIXED_HANDSHAKE, "!(MEET)"), (DEAD_BRANCH, "!(GO)"), (SEVERAL_KAS, "!(START)"),
    (NO_STORE, "!(START)"), (FACT_INVOKED, "!(RAISE)"), (NOBODY_LISTENS, "!(RAISE)"),
    (PROGRAM_VARIABLE_TESTED, "!(GO)"),
])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_interpreter_ends_only_where_the_net_says_it_can(tmp_path: Path, text: str, goal: str, seed: int) -> None:
    from specc.analysis.procedures import library
    from specc.runtime.supervisor import Supervisor

    report = check(text, goal, tmp_path)
    program = program_of(text, tmp_path)
    supervisor = Supervisor(library(next(i for i in program.items if isinstance(i, m.Procedures))), seed=seed)
    intention = supervisor.post(goal)
    supervisor.run()
    possible = {"succeeded"} if report.succeeded else set()
    possible |= {"failed"} if report.failed else set()
    possible |= {"running"} if "deadlock" in report.kinds() else set()
    assert intention.status in possible, (intention.status, report.kinds(), intention.lines())


def test_hilare_fig_4_4_asks_for_a_service_the_executive_does_not_offer(hilare: tuple[m.Program, m.Procedures]
                                                                        ) -> None:
    """Fig 4.4's fallback (peristaltic locomotion) is not a service of Hilare's executive: once
    the normal planner may fail, the net reaches the request the executive would refuse."""
    assert verify(*hilare, [rp.parse_goal("!(FIND-SUBTRAJ $R)")]).kinds() == ["unreachable"]
    report = verify(*hilare, [rp.parse_goal("!(FIND-SUBTRAJ $R)")], failing=["CALC-TRAJ-GOAL"])
    unknown = next(f for f in report.findings if f.kind == "unknown-service")
    assert "CALC-TRAJ-PERISTALTIC" in unknown.message
    # The executive answers BAD-SERVICE, which Hilare's EXEC-REQUEST results do not hold: the net
    # stops there and says so, rather than follow another answer.
    assert "it answers BAD-SERVICE, which the answer's domain lacks" in unknown.message
    assert unknown.trace[-1] == "service CALC-TRAJ-PERISTALTIC is not offered"


def test_hilare_fig_4_1_counts_displacements_without_bound(hilare: tuple[m.Program, m.Procedures]) -> None:
    with pytest.raises(TranslationError) as raised:
        translate(*hilare, [rp.parse_goal("!(GOTO-FAR-POSITION)")])
    (diagnostic,) = raised.value.diagnostics
    assert diagnostic.code == "unbounded-variable" and "$I" in diagnostic.message
    assert diagnostic.span.line == 77  # the context of Fig 4.1: (NUMBER-OF-DISPLACEMENTS $I) is an int


FUNCTIONAL_FACT = """
procedures rows {
  predicate functional AT-ROW(row: 0..3);
  predicate GO();
  ka Go {
    invocation: !(GO);
    body {
      ?(AT-ROW $R);
    }
  }
}
"""


@pytest.mark.parametrize(("fact", "said"), [
    ("(AT-ROW 9)", "9 is not in the domain of argument 1 of 'AT-ROW' (0, 1, 2, 3)"),  # a value the net has no place for
    ("(AT-ROW $X)", "a fact is ground"),
    ("(AT-ROW 1 2)", "gives 'AT-ROW' 1 value(s), 2 given"),
])
def test_a_starting_fact_outside_its_predicate_is_refused_not_turned_into_a_deadlock(
        tmp_path: Path, fact: str, said: str) -> None:
    with pytest.raises(ValueError, match=re.escape(said)):
        check(FUNCTIONAL_FACT, "!(GO)", tmp_path, facts=[rp.parse_fact(fact)])
    achieved = check(FUNCTIONAL_FACT, "!(GO)", tmp_path, facts=[rp.parse_fact("(AT-ROW 2)")])
    assert achieved.findings == [] and achieved.succeeded >= 1


@pytest.mark.parametrize(("condition", "said"), [
    ("?(NOPE)", "no predicate 'NOPE'"),
    ("?(GO 1)", "'GO' takes 0 argument(s), 1 given"),
    ("?(& (GO) (AT-ROW 7))", "7 is not in the domain of argument 1 of 'AT-ROW'"),
])
def test_a_reach_condition_that_cannot_mean_anything_is_refused_not_answered_never(
        tmp_path: Path, condition: str, said: str) -> None:
    with pytest.raises(ValueError, match=re.escape(said)):
        check(FUNCTIONAL_FACT, "!(GO)", tmp_path, queries=[parse_query(f"Go:8 {condition}")])
    (answer,) = check(FUNCTIONAL_FACT, "!(GO)", tmp_path, facts=[rp.parse_fact("(AT-ROW 2)")],
                      queries=[parse_query("Go:8 ?(AT-ROW 2)")]).answers
    assert answer.reached


COUNTER = """
procedures rows {
  predicate functional AT-ROW(row: 0..3);
  predicate GO-ROW(row: 1..3);
  predicate SWEEP(rows: 1..3);
  ka Sweep {
    invocation: !(SWEEP $N);
    body {
      assign @I = 1;
      while ?(TEST) {
        !(GO-ROW (+ @I 0));
        assign @I = (+ @I 1);
      }
    }
  }
  ka GoRow {
    invocation: !(GO-ROW $R);
    body {
      ~>(AT-ROW $OLD);
      =>(AT-ROW $R);
    }
  }
}
"""


@pytest.mark.parametrize(("test", "step"), [("(< @I 4)", "(+ @I 1)"), ("(<= @I $N)", "(+ @I 1)"),
                                            ("(< @I 3)", "(* @I 2)"), ("(< @I 3)", "(+ @I @I)")])
def test_a_loop_counter_takes_every_value_its_steps_reach(tmp_path: Path, test: str, step: str) -> None:
    # @I is given 1 and compared with 4 (or $N, 1..3): its domain is 1..4 (or 1..4, the step past
    # $N it exits with), not the constants alone (a false out-of-domain at @I = 2). Doubling from
    # 1 under 3: 1, 2 and the 4 it exits with.
    report = check(COUNTER.replace("(TEST)", test).replace("(+ @I 1)", step), "!(SWEEP 3)", tmp_path)
    assert "out-of-domain" not in report.kinds() and report.succeeded == 1
    # GoRow:19 retracts AT-ROW with $OLD never bound: it changes nothing, and the KA goes on.
    assert finding(report, "changes-nothing").startswith("GoRow:19 ~>(AT-ROW $OLD) only ever runs with an unbound")
    assert "never-succeeds" not in report.kinds()


def test_what_keeps_procedures_from_a_net_is_said_in_the_files_order() -> None:
    from specc.diagnostics import error
    from specc.model.span import Span

    late, early = (error("unbounded-variable", f"line {n}", Span("p.spec", n, 1, n, 2)) for n in (51, 18))
    assert [d.message for d in TranslationError([late, early]).diagnostics] == ["line 18", "line 51"]


# ---------------------------------------------------------------- what the executive answers

PROBED = """
module probe {
  codels: "probe_codels";
  request Measure {
    type: exec;
    output: level: double;
    task: Sampling;
    fail: NO_SAMPLE;
    codel exec: measure;
  }
  request Spray {
    type: exec;
    task: Sampling;
    codel exec: spray;
  }
  exec_task Sampling { period: 100 ms; }
}

executive field {
  codels: "field_codels";
  service MEASURE { request: probe.Measure; output: verdict; }
  service SPRAY { request: probe.Spray; }
}

procedures tasks {
  type SERVICES = {MEASURE, SPRAY};
  type RESULTS = {OK, TIMEOUT, INT, ERROR, REFUSED, NO_SAMPLE, HEAVY, LIGHT, NONE};
  predicate event REPLY(id: int, result: RESULTS);
  predicate EXEC(service: SERVICES, result: RESULTS);
  action MEASURE() -> int = service MEASURE;
  action SPRAY() -> int = service SPRAY;
  ka Exec {
    invocation: !(EXEC $SERVICE $RESULT);
    property: executive;
    body { !(SEND $SERVICE $ID); ^(REPLY $ID $RESULT); }
  }
  ka SendMeasure { invocation: !(SEND MEASURE $ID); action: (MEASURE) -> $ID; }
  ka SendSpray { invocation: !(SEND SPRAY $ID); action: (SPRAY) -> $ID; }
  ka Check {
    invocation: !(CHECK);
    body {
      !(EXEC MEASURE $V);
      if ?(= $V HEAVY) {
        !(EXEC SPRAY $S);
      } else {
        if ?(= $V LIGHT) {
          !(EXEC SPRAY $S);
        }
      }
    }
  }
}

system field {
  modules: probe;
  executive: field;
  supervisor: tasks;
}
"""
PROBE_CODELS = 'def measure(sdi, request):\n    return "end"\n\n\ndef spray(sdi, request):\n    return "end"\n'
VERDICT = ('def verdict(ctx, outputs):\n'
           '    return "HEAVY" if outputs.level > 0.6 else "LIGHT" if outputs.level > 0.3 else "NONE"\n')
SPRAY_LINES = [n for n, line in enumerate(PROBED.splitlines(), start=1) if "!(EXEC SPRAY $S);" in line]


def probed(folder: Path, text: str = PROBED) -> str:
    """`text` with the codels its module and its executive name, written next to it."""
    (folder / "probe_codels.py").write_text(PROBE_CODELS, encoding="utf-8")
    (folder / "field_codels.py").write_text(VERDICT, encoding="utf-8")
    return text


def test_a_service_s_output_function_may_answer_any_word_of_the_result_s_domain(tmp_path: Path) -> None:
    """MEASURE's output function returns HEAVY, LIGHT or NONE when the service worked, which the
    net cannot compute: both spray branches are reached without any `--fail`."""
    branches = [parse_query(f"Check:{line}") for line in SPRAY_LINES]
    report = check(probed(tmp_path), "!(CHECK)", tmp_path, queries=branches)
    assert "unreachable" not in report.kinds() and report.findings == [], report.kinds()
    assert [answer.reached for answer in report.answers] == [True, True]
    assert report.succeeded >= 1 and report.failed == 0


def test_a_service_without_an_output_function_answers_ok_when_it_works(tmp_path: Path) -> None:
    """The executive answers OK to a service that has no output function: neither branch runs
    unless MEASURE may fail (a failing service answers any word of the domain)."""
    text = probed(tmp_path, PROBED.replace(" output: verdict;", ""))
    expected = f"KA 'Check': these statements can never run: {SPRAY_LINES[0]} !(EXEC SPRAY $S); " \
               f"{SPRAY_LINES[1]} !(EXEC SPRAY $S)"
    assert finding(check(text, "!(CHECK)", tmp_path), "unreachable") == expected
    assert "unreachable" not in check(text, "!(CHECK)", tmp_path, failing=["MEASURE"]).kinds()


@pytest.mark.parametrize(("failing", "failures"), [
    ((), set()),
    (("MEASURE",), {"TIMEOUT", "INT", "ERROR", "REFUSED", "NO_SAMPLE"}),
])
def test_an_output_function_s_answers_leave_the_failures_to_fail(tmp_path: Path, failing: tuple[str, ...],
                                                                 failures: set[str]) -> None:
    """The words the executive answers a failure with (its own categories, the module request's
    reports) come only with `--fail`, as for any service; the output's words come either way."""
    program = program_of(probed(tmp_path), tmp_path)
    block = next(i for i in program.items if isinstance(i, m.Procedures))
    translation = translate(program, block, [rp.parse_goal("!(CHECK)")], failing=failing)
    answers = translation.net.transitions["service MEASURE answers"].bindings or ()
    assert {binding["1"][1] for binding in answers} == {"OK", "HEAVY", "LIGHT", "NONE"} | failures


def test_a_request_protocol_whose_answer_has_no_domain_is_refused_not_a_deadlock(tmp_path: Path) -> None:
    """Without `predicate EXEC(...)` the net has no answer for any service: saying "deadlock" would
    report what the robot never does; the missing declaration is said instead, at the KA."""
    text = probed(tmp_path, PROBED.replace("  predicate EXEC(service: SERVICES, result: RESULTS);\n", "")
                  .replace("!(EXEC SPRAY $S);", "!(EXEC SPRAY $V);"))
    with pytest.raises(TranslationError) as raised:
        check(text, "!(CHECK)", tmp_path)
    [diagnostic] = [d for d in raised.value.diagnostics if "answer of EXEC" in d.message]
    assert diagnostic.code == "unbounded-variable" and "declare `predicate EXEC(" in diagnostic.message


def test_an_answer_domain_without_ok_is_refused_not_a_deadlock(tmp_path: Path) -> None:
    """SPRAY has no output function: it answers OK when it works. A result type without OK would
    leave the net no answer for it, a deadlock the robot does not have: said instead."""
    text = probed(tmp_path, PROBED.replace("type RESULTS = {OK, TIMEOUT,", "type RESULTS = {TIMEOUT,"))
    with pytest.raises(TranslationError) as raised:
        check(text, "!(CHECK)", tmp_path)
    assert any("service SPRAY answers OK when it works" in d.message for d in raised.value.diagnostics)
    assert "answer-without-ok" in {d.code for d in raised.value.diagnostics}


def test_a_protocol_that_never_hears_a_zombie_s_warning_waits_for_ever(tmp_path: Path) -> None:
    """A service gone ZOMBIE gets no REPLY until the procedures interrupt it (§3.4.1): its
    (WARNING ...) comes instead. The net answered ZOMBIE as if the REPLY came by itself, and
    missed the wait for ever a run shows; a protocol waiting for the WARNING too (Fig 4.3's
    `choose`, then the interruption) gets it, and has no such finding."""
    zombie = PROBED.replace("NO_SAMPLE, HEAVY", "NO_SAMPLE, ZOMBIE, HEAVY")
    report = check(probed(tmp_path, zombie), "!(CHECK)", tmp_path, failing=["SPRAY"])
    said = finding(report, "zombie-unanswered")
    assert said.startswith("service SPRAY may go ZOMBIE") and "KA Exec never waits for the WARNING" in said
    # A service that works never goes ZOMBIE: only `--fail` brings it.
    assert "zombie-unanswered" not in check(probed(tmp_path, zombie), "!(CHECK)", tmp_path).kinds()
    heard = zombie.replace(
        "  predicate event REPLY(id: int, result: RESULTS);",
        "  predicate event REPLY(id: int, result: RESULTS);\n"
        "  predicate event WARNING(service: SERVICES, id: int, type: {ZOMBIE});\n"
        "  action INTERRUPT(id: int) = \"field_codels.interrupt\";\n"
        "  ka Interrupt { invocation: !(INTERRUPT $ID); action: (INTERRUPT $ID); }").replace(
        "body { !(SEND $SERVICE $ID); ^(REPLY $ID $RESULT); }",
        "body { !(SEND $SERVICE $ID); choose { branch { ^(REPLY $ID $RESULT); } "
        "branch { ^(WARNING $SERVICE $ID ZOMBIE); !(INTERRUPT $ID); ^(REPLY $ID $RESULT); } } }")
    # The same wait in a KA of its own that the protocol calls: heard all the same.
    handed = heard.replace(
        "body { !(SEND $SERVICE $ID); choose {",
        "body { !(SEND $SERVICE $ID); !(AWAIT $SERVICE $ID $RESULT); } }\n"
        "  ka Await { invocation: !(AWAIT $SERVICE $ID $RESULT); body { choose {").replace(
        "  predicate EXEC(service: SERVICES, result: RESULTS);",
        "  predicate EXEC(service: SERVICES, result: RESULTS);\n"
        "  predicate AWAIT(service: SERVICES, id: int, result: RESULTS);")
    (tmp_path / "field_codels.py").write_text(VERDICT + "\n\ndef interrupt(ctx, ident):\n    pass\n", encoding="utf-8")
    for protocol in (heard, handed):
        probed(tmp_path, protocol)
        (tmp_path / "field_codels.py").write_text(VERDICT + "\n\ndef interrupt(ctx, ident):\n    pass\n",
                                                  encoding="utf-8")
        report = check(protocol, "!(CHECK)", tmp_path, failing=["SPRAY"])
        assert "zombie-unanswered" not in report.kinds(), report.kinds()
