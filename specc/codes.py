"""Every diagnostic code specc reports, with what it means and an example of a spec line that
gets it (`specc explain CODE`). A test keeps the table and the codes the passes use the same."""

from __future__ import annotations

from typing import NamedTuple


class Code(NamedTuple):
    summary: str
    example: str  # a spec line (or a command) that gets this code


CODES: dict[str, Code] = {
    # ---------------------------------------------------------------- reading the files
    "no-spec-files": Code("a folder or a list of paths holds no .spec file", "specc check empty_folder/"),
    "empty-file": Code("a spec file holding no block, only comments or nothing (warning)", "an empty robot.spec"),
    "missing-file": Code("a path given on the command line does not exist", "specc check nowhere.spec"),
    "unreadable-file": Code("a spec file or codel module exists but cannot be read (permissions, a folder .spec)",
                            "specc check locked.spec"),
    "unreadable-folder": Code("a folder cannot be listed", "specc check locked_folder/"),
    "bad-encoding": Code("a spec file is not UTF-8 text", "a .spec saved as Latin-1 with an accented comment"),
    "unwritable-output": Code("the package cannot be written into the output folder", "specc compile x -o /read-only"),
    "skeleton-failed": Code("specc skeleton cannot write a codel stub file", "specc skeleton on a read-only folder"),
    "unwritable-file": Code("a file a command writes cannot be written", "specc fmt on a read-only spec"),
    # ---------------------------------------------------------------- syntax
    "unexpected-token": Code("the parser found a word or symbol that cannot come there; the message lists what can",
                             "type control;   (in a request: 'type: control;')"),
    "unexpected-character": Code("a character the language has no use for", "period: 50 ms $"),
    "unexpected-end": Code("the file ends inside a block (an unclosed '{' is pointed at)", "module m { number: 1;"),
    "unterminated-string": Code("a string is not closed on its line", 'codels: "m_codels;'),
    "unterminated-comment": Code("a /* comment is never closed by */", "/* a comment"),
    "too-deeply-nested": Code("an expression nests deeper than the parser follows", "(((((...))))) two hundred deep"),
    "number-too-large": Code("a number past the largest float", "number: 1e400;"),
    "unknown-unit": Code("a duration's unit is not us, ms, s or min", "period: 50 mss;"),
    "missing-semicolon": Code("a statement's line ends without its ';'", "number: 1     (then the next statement)"),
    "bad-operator": Code("IxTeT's own operator notation where the plain one is written",
                         "?d =. ?s *. ?t;   (write = and *)"),
    "bad-conflict-policy": Code("a conflict policy other than wait or interrupt", "conflicts { GOTO: stop; }"),
    "duplicate-property": Code("a property given twice in one block", "period: 50 ms; period: 60 ms;"),
    "unknown-property": Code("a property the block does not have (did-you-mean suggests one)", "perod: 50 ms;"),
    "bad-property-value": Code("a property's value is not of the kind it takes", "number: fast;"),
    # ---------------------------------------------------------------- names and references
    "duplicate-definition": Code("a name defined twice where it must be once (two blocks, fields, rules, bindings, "
                                 "or two blocks written to one file)", "request A {...} request A {...}"),
    "reserved-name": Code("a name the generated Python cannot hold: a keyword, a dunder, a standard module's, a "
                          "method of the generated client", "request abort { type: control; }"),
    "bad-reference": Code("a reference not written as the context asks (module.request, module.Poster.field)",
                          "request: GoTo;   (not loco.GoTo)"),
    "undefined-module": Code("no module of that name", "request: lcoo.GoTo;"),
    "undefined-request": Code("no request of that name in the module", "request: loco.Trak;"),
    "undefined-poster": Code("no poster of that name in the module (in a spec, or read by a codel or an "
                             "executive function)", "get: loco.Robo;   sdi.read_poster(\"loco.Robo\")"),
    "undefined-field": Code("no field of that name in the record or poster", "data: pos, spede;"),
    "undefined-type": Code("no type of that name", "struct P { y: dooble; }"),
    "undefined-exec-task": Code("no exec task of that name in the module", "task: Missing;"),
    "undefined-activity": Code("a poster's activity names no request of the module", "activity: nowhere;"),
    "undefined-codel": Code("a codel function the codel module does not define", "codel exec: stpe;"),
    "bad-codel-signature": Code("a user function cannot be called with the arguments the runtime passes it",
                                "def watch(sdi, request): ...   (an exec task's codel gets (sdi))"),
    "incomplete-reply-domain": Code("the procedures' REPLY result domain lacks a result a service they name may "
                                    "answer: a fail code, or FINAL_ERROR for a codel that raises (warning)",
                                    "predicate event REPLY(id: int, result: {OK, ERROR});"),
    "computed-send": Code("a codel sends a request whose name it computes, which no analysis can follow",
                          "sdi.send_request(\"arm.\" + name)"),
    "undeclared-send": Code("a codel sends a request (`sdi.send_request`) its request's `sends:` does not list "
                            "(warning): the incompatibility graph and `specc verify` leave it out",
                            'sdi.send_request("ptu.Sweep")   (no sends: ptu.Sweep;)'),
    "undeclared-result": Code("a codel returns a string its request does not declare (no such state or fail)",
                              'return "SLIPPED"   (fail: SLIP;)'),
    "undefined-codel-state": Code("a codel leads to a state the request has no codel for",
                                  "codel exec: go -> finished;"),
    "undefined-service": Code("no executive service of that name", "conflicts { GOTOO: wait; }"),
    "undefined-input": Code("a service's args or takes name an input its request does not have", "args { z: 0.0; }"),
    "undefined-rules": Code("an executive's rules name no rule base", "rules: controlr;"),
    "undefined-executive": Code("a system's executive names no executive block", "executive: tugg;"),
    "undefined-procedures": Code("a system's supervisor names no procedures block", "supervisor: taks;"),
    "undefined-ftplan": Code("a system's planning names no ftplan block", "planning: rovr;"),
    "undefined-predicate": Code("a KA uses a predicate the procedures do not declare", "^(RPLY $ID $R);"),
    "undefined-action": Code("a KA calls an action the procedures do not declare", "action: (GOTTO $X $Y) -> $ID;"),
    "undefined-goal": Code("a goal no KA is invoked by", "goal: !(GOO 1 2);"),
    "undefined-world": Code("a mission names no world of the system", "world: elsewhere;"),
    "undefined-mission": Code("a planned mission names no mission of the ftplan block", "plan: M9;"),
    "undefined-device": Code("a module is given a device the body does not have", "devices { loco: lazer; }"),
    "undefined-report": Code("a binding reports what no `on report` rule reads", "report THERE(drive.Pose.x);"),
    "undefined-domain": Code("a planner or problem names no domain", "domain: modle1;"),
    "undefined-problem": Code("an ftplan mission names no problem", "p1: M1_modle1;"),
    "undefined-planner": Code("an ftplan block names no planner of that name", "planners: p1, p3;"),
    "undefined-task": Code("a rule or binding names a task no planner's domain has", "DROOP(?p) => request ...;"),
    "undefined-attribute": Code("an attribute the domain or FTplan's state does not have", "AT_PLACE()"),
    "undefined-constant": Code("a constant no block defines", "?x in PLACEZ;"),
    "undefined-fragment": Code("an include names no fragment", "include model1_goals_M9;"),
    "undefined-macro": Code("a macro call names no macro", "MOVE_TME(?d);"),
    "macro-cycle": Code("a macro that calls itself, directly or through other macros (it would be written "
                        "out without end)", "macro twice(?a) { twice(?a); }"),
    "undefined-function": Code("a function no domain defines", "?d = dist(?a, ?b);"),
    "undefined-name": Code("a name in a planning block that is not a timepoint, a macro parameter or a declared "
                           "symbolic value", "t_midle - t_start in [1, 2];"),
    "undefined-loop-variable": Code("a rule uses a foreach index it does not declare", "r7[i]: speed > 3 ==> ..."),
    "unused-timepoint": Code("a timepoint declared in a task or a problem that no statement uses",
                             "timepoint t1, t2;  // t2 appears nowhere else"),
    "unused-fragment": Code("a fragment no block includes", "fragment spare { ... }"),
    # ---------------------------------------------------------------- modules
    "missing-property": Code("a block lacks a property it needs", "request Nothing { doc: \"no type\"; }"),
    "duplicate-module-number": Code("two modules share a number", "module m2 { number: 10; }"),
    "missing-exec-task": Code("an exec request without a task", "request Stop { type: exec; codel exec: stop; }"),
    "missing-codel": Code("an exec request without an exec codel", "request Empty { type: exec; task: Main; }"),
    "bad-codel-state": Code("a codel on a state requests do not have", "codel begin: nope;"),
    "codel-on-control-request": Code("a control request with codels: control requests run no codel",
                                     "request Set { type: control; codel exec: set; }"),
    "not-a-control-request": Code("a SET-PARAM parameter sets through an exec request", "set: loco.Track;"),
    "recursive-type": Code("a struct that contains itself", "struct Node { next: Node; }"),
    "bad-python-module": Code("a Python module name that is not dotted identifiers", 'codels: "cart-codels";'),
    "missing-python-module": Code("the Python module a spec names is not next to it", 'codels: "cart_codles";'),
    "python-syntax-error": Code("a codel module has a syntax error", "cart_codels.py with `def go(sdi:`"),
    # ---------------------------------------------------------------- executive
    "control-conflict": Code("a conflicts entry naming a service that runs a control request (it is never in EXEC)",
                             "DOCK { conflicts { SET-SPEED: interrupt; } }  // SET-SPEED: type control"),
    "rules-large": Code("a rule base whose decision graph, under the work limit, still makes megabytes of Python",
                        "8 numeric inputs x 50 threshold rules"),
    "intermediate-never-read": Code("an undeclared attribute rules deduce and no rule tests (a misspelt output?)",
                                    'outputs o; ... r: x > 1 ==> restrict oo == "a";'),
    "comparison-never-holds": Code("a rule compares a numeric attribute with a number outside its declared range",
                                   "inputs x: [0, 10]; ... r: x > 20 ==> ..."),
    "comparison-always-holds": Code("a rule compares a numeric attribute with a threshold every value passes",
                                    "inputs x: [0, 10]; ... r: x < 20 ==> ..."),
    "rule-never-fires": Code("a rule testing attributes that only rules needing them first can set (warning)",
                             'c1: mood == "a" ==> restrict state == "b"; c2: state == "b" ==> restrict mood == "a";'),
    "rule-never-applies": Code("an executive's hand-written rule a declared or sends-derived wait always overrides",
                               'START MOVE, @MotionState == "REACH" ==> ... (MOVE waits for REACH)'),
    "reflex-loop": Code("reflexes that restart a service on every reply it gives, directly or through others",
                        "reflex again on interm DOCK => start DOCK;"),
    "reflex-needs-input": Code("a reflex sends a request that takes inputs it cannot give",
                               "reflex on reply loco.Track => request loco.GoTo;"),
    "reflex-never-fires": Code("a reflex compares a reply with a value the request never replies (warning)",
                               "reflex on reply us.watch == OBSTACEL => request loco.Stop;"),
    "controller-attribute": Code("a hand-written controller rule uses an attribute the controller does not have",
                                 "r: @Xstate == \"A\" ==> ..."),
    "unknown-group-state": Code("a controller rule names a group state no group has", "@Bstate == \"NOPE\""),
    # ---------------------------------------------------------------- rule bases (Kheops)
    "type-mismatch": Code("a comparison between a symbol and a number", "event < 3 ==> ..."),
    "value-outside-domain": Code("a value outside the attribute's declared domain", 'event == "STOP" ==> ...'),
    "restrict-input": Code("a rule restricts an input", 'restrict event == "START"'),
    "missing-init": Code("a rule reads the previous cycle (@x) of an attribute with no init", '@status == "OK"'),
    "init-undeclared": Code("an init for an attribute the base does not declare (warning)", "init @nope = 1;"),
    "output-never-set": Code("an output no rule deduces", "outputs status, never;"),
    "empty-rule-base": Code("a rule base with no rules: it decides nothing (warning)", "rules speed { }"),
    "input-never-read": Code("an input no rule tests: it changes no decision (warning)", "inputs battery: [0, 100];"),
    "empty-domain": Code("a domain holding no value", "inputs load: [1, 0];"),
    "rules-too-large": Code("a rule base or resource controller whose decision graph is too large to build",
                            "8 numeric inputs tested against 50 thresholds each"),
    "not-propositional": Code("a rule base outside the propositional subset Kheops compiles (an attribute compared "
                              "with another, a constant that is not a literal...)", "r: speed > load ==> ..."),
    "rules-unsettled": Code("input configurations the rules do not settle (warning at compile)",
                            "specc rules examples/generic lists them"),
    # ---------------------------------------------------------------- procedures (PRS)
    "missing-invocation": Code("a KA without an invocation", "ka Go { body { ... } }"),
    "empty-ka-body": Code("a loop (while) with an empty body", "while ?(BUSY) { }"),
    "conflicting-ka-kinds": Code("a KA that mixes what only some kinds of KA may have (a body and an action, a meta "
                                 "property on a goal KA...)", "ka Go { invocation: !(GO); body {...} action: (GO); }"),
    "condition-not-test": Code("an if or while condition that is not a test goal", "if !(X) { ... }"),
    "unreachable-statement": Code("a statement after `fail;`", "fail; !(GO 1 2);"),
    "bad-binding": Code("an action or predicate bound to what is not a Python module.function (or a service)",
                        'action LOG(t: string) = "log";'),
    "unbound-variable": Code("a variable with no value where one is needed", "goal: !(GO $X 2);"),
    "array-too-large": Code("an array type of more than ten million elements", "hist: double[1000000000];"),
    "assigned-output": Code("a rule's `do` assigns a declared output: outputs are what rules restrict",
                            "outputs speed: [0, 2]; r: far ==> do {speed = 1.5};"),
    "always-true-test": Code("a test ?(= $V x) of a variable named nowhere else in the KA: it binds it and always "
                             "holds (a misspelt variable)", "^(REPLY $ID $R); ?(= $RR OK);"),
    "bad-argument": Code("a goal's argument outside the domain its predicate declares, or of another kind than "
                         "the input of the action it reaches (a symbol where a number goes)",
                         "goal: !(CARRY 7 BOX);"),
    "bypasses-executive": Code("a binding sends a request straight to a module the executive's services use: the "
                               "executive's conflicts do not apply to it, and `specc verify` does not cover it",
                               "PICK(?o) => request arm.Pick(?o);"),
    "bad-argument-type": Code("a value given to a service's or request's input does not fit its type: a planning "
                              "task's binding, or a procedure action's parameter (`action MOVE(bed: string)` for a "
                              "service whose input is an int)", "=> service GOTO(A, B);"),
    # ---------------------------------------------------------------- planning (IxTeT) and FTplan
    "include-cycle": Code("fragments that include each other", "fragment a { include b; } fragment b { include a; }"),
    "undeclared-variable": Code("a task uses a ?variable it does not declare", "?y in PLACES;   (no ?y)"),
    "undeclared-timepoint": Code("a timepoint the task does not declare", "event(AT(): (A, B), t_middle);"),
    "empty-interval": Code("an interval whose low bound is above its high", "(t_end - t_start) in [10, 5];"),
    "contradictory-constraints": Code("a problem's temporal constraints that cannot all hold (with what the planner "
                                      "requires of every problem: each timepoint between t_start and t_end)",
                                      "(t_o - t_start) in [10, 20];  (t_c - t_start) in [50, 60];  t_c < t_o;"),
    "event-without-transition": Code("an event that does not change the value", "event(AT(): (A, A), t);"),
    "hold-transition": Code("a hold given a transition", "hold(AT(): (A, B), (t1, t2));"),
    "bad-goal": Code("a problem goal's priority or weight is not a finite number",
                     "hold(AT(): DOCK, (t1, t_end)) goal(2, NaN);"),
    "statement-outside-problem": Code("a fragment a domain includes holds a statement (a constraint, an "
                                      "assertion): a domain declares, a problem states",
                                      "fragment rel { ?x in [0, 1]; }  domain d { include rel; }"),
    "goal-outside-problem": Code("a goal in a task: goals belong to a problem (or a fragment it includes)",
                                 "hold(AT(): DOCK, (t1, t2)) goal(1, 0);   (inside a task)"),
    "no-goals": Code("a problem with no goal", "problem quiet for d { ... }"),
    "unsupported-resource-use": Code("a resource use the planner cannot model (it borrows over an interval only)",
                                     "use(BASE(): 1, t1);"),
    "domain-mismatch": Code("an ftplan mission's problem for a domain its planner does not plan in",
                            "p1: M1_model2;"),
    "mission-ends-differ": Code("an ftplan mission's problems let it end at different times, and FTplan counts "
                                "the goals met by its own problem's", "careful: rounds_slow;   (rounds ends by 30 s, "
                                "rounds_slow by 900 s)"),
    "planners-share-domain": Code("an ftplan mission makes planners declared with different domains plan in one "
                                  "(a problem for another planner's domain): they are no longer diverse",
                                  "careful: rounds;   (rounds is for fast's domain)"),
    "bad-rule-argument": Code("an FTplan rule or requirement given what it cannot hold (an expression, a transition "
                              "where one value is meant, a task's parameter none of whose values the attribute "
                              "holds there)", "requires PTU(): ?o * 2;"),
    "unknown-heuristic": Code("a planner heuristic that does not exist", "heuristic: fastest;"),
    "unusable-correspondence": Code("a view correspondence that can neither read FTplan's state nor be written by a "
                                    "report", "PTU(): ?p <=> PTU_POS(): ?q;"),
    "over-capacity": Code("a task uses more of a resource than its capacity (the upper bound of its ?value)",
                          "resource ARM() { ?value in [0, 1]; } ... use(ARM(): 2, (t_start, t_end));"),
    "negative-amount": Code("a resource amount or a contingent duration below zero",
                            "contingent (t_end - t_start) in [-5, 80];"),
    "bad-duration": Code("a duration that is zero where it must not be, or too long to be a number of seconds",
                         "period: 0 ms;"),
    # ---------------------------------------------------------------- systems
    "bad-world": Code("a world file the simulator cannot use", 'shop: "worlds/broken.toml";'),
    "missing-world": Code("a world file that does not exist", 'nowhere: "worlds/nowhere.toml";'),
    "goal-without-supervisor": Code("a mission or binding posts a goal, but the system has no supervisor",
                                    "goal: !(GO 1 2);   (no supervisor:)"),
    "bad-mission-goal": Code("a mission's goal that is not !(...), ?(...) or a fact =>(...)", "goal: ^(GO 1 2);"),
    "missing-binding": Code("a task of the planners' domains without a binding", "bindings { }   (DROP unbound)"),
    "arity-mismatch": Code("a call with more or fewer arguments than what it calls takes", "goal: !(GO 1);"),
    # ---------------------------------------------------------------- procedures as Petri nets (specc verify --goal)
    "bad-executive-ka": Code("an executive KA not invoked by a goal naming the service first and its result last",
                             "invocation: !(EXEC-REQUEST $RESULT $REQUEST);"),
    "choose-first-arc": Code("a branch of a choose that does not start with a goal (its arc, seed 000 §4.4.7)",
                             "choose { branch { =>(DONE); } }"),
    "event-test": Code("a test on an event predicate (events are waited for, not tested)", "?(REPLY $ID OK);"),
    "no-executive": Code("procedures that request services verified without an executive", "specc verify --goal ..."),
    "no-applicable-ka": Code("a request no executive KA's invocation matches (a KA per service, none for this one)",
                             "!(EXEC LOOK $R);   (KAs for !(EXEC STOW $R) only)"),
    "shared-variable": Code("parallel branches sharing a variable the net cannot follow", "parallel { ... }"),
    "unbounded-variable": Code("a KA variable over an unbounded domain (int, string): no finite net",
                               "predicate event REPLY(id: int, ...)"),
    "answer-without-ok": Code("a service's answer is received in a domain without OK, the word it answers when "
                              "it works: the net would have no answer for it", "type RESULTS = {TIMEOUT, ERROR};"),
    "unsupported-goal": Code("a goal kind the net translation does not represent", "#(X)"),
    "unsupported-meta": Code("a meta KA (choosing among KAs): a Petri net cannot represent it (seed 000 §4.4.10)",
                             "ka Pick { property: meta; ... }"),
}

# How to fix what each code says (`specc explain`): tests/test_codes.py keeps one for every code.
FIXES: dict[str, str] = {
    "no-spec-files": (
        "Point the command at a folder or file that holds `.spec` files, or give your spec files the `.spec` "
        "suffix."),
    "empty-file": (
        "Write a block (module, executive, rules...) in the file, or delete the file; fine to leave if it "
        "only holds notes."),
    "missing-file": (
        "Correct the path on the command line (relative to where you run specc), or create the file it names."),
    "unreadable-file": (
        "Give the spec file or codel module read permission, and make sure a path ending in `.spec` is a "
        "file, not a folder."),
    "unreadable-folder": (
        "Give the folder read and execute (list) permission, or leave it out of the paths you pass to specc."),
    "bad-encoding": (
        "Re-save the spec file as UTF-8 (convert it, e.g. with `iconv -f latin1 -t utf-8`), or fix the byte "
        "at the reported position."),
    "unwritable-output": (
        "Pass `-o` a folder you can write to, or fix the permissions or free space of the output folder."),
    "skeleton-failed": (
        "Make the codel module's folder and file writable and fix any Python syntax error in the existing "
        "module, then rerun `specc skeleton`."),
    "unwritable-file": (
        "Give yourself write permission on the file (and its folder), or run the command on a writable copy."),
    "unexpected-token": (
        "Write one of the tokens the message lists at that point; usually a missing `:`, `;`, `,` or brace "
        "just before it, e.g. `type: control;`."),
    "unexpected-character": (
        "Delete the stray character (or invisible byte such as a BOM), or put the text inside a string or a "
        "`//` comment."),
    "unexpected-end": (
        "Close the block opened at the pointed `{` with its `}`, or finish the statement the file ends in."),
    "unterminated-string": "Close the string with `\"` on the same line it opens; strings cannot span lines.",
    "unterminated-comment": "Close the `/*` comment with `*/`, or use `//` comments for single lines.",
    "too-deeply-nested": (
        "Split the expression or goal into smaller pieces (intermediate sub-goals, variables or shorter "
        "expressions) so nothing nests more than 150 levels."),
    "number-too-large": (
        "Write a number below about 1.8e308; for an unbounded interval use `oo` (`-oo`, `+oo`) instead of a "
        "huge number."),
    "unknown-unit": "Give the duration one of the units `us`, `ms`, `s` or `min`, e.g. `period: 50 ms;`.",
    "missing-semicolon": "End the statement on the reported line with `;`.",
    "bad-operator": (
        "Write the plain operator (`=`/`==`, `+`, `-`, `*`, `/`) instead of IxTeT's dotted one (`=.`, `+.`, "
        "`*.`) where the message says."),
    "bad-conflict-policy": "Write each `conflicts` entry as `SERVICE: wait;` or `SERVICE: interrupt;`.",
    "duplicate-property": "Keep one of the two properties (or merge the two sections) and delete the other.",
    "unknown-property": (
        "Rename the property to one the block has (take the did-you-mean suggestion or pick from the known "
        "list), or remove it."),
    "bad-property-value": (
        "Give the property a value of the kind the message says it expects (a number, a duration with unit, a "
        "quoted path, one value), e.g. `number: 10;`."),
    "duplicate-definition": (
        "Rename or remove one of the two definitions (or merge them), so each name is defined once and no two "
        "blocks write the same generated file."),
    "reserved-name": (
        "Rename it to a name that is not a Python keyword, dunder, standard-library module or "
        "generated-client method (e.g. `abort` -> `AbortMove`)."),
    "bad-reference": (
        "Write the reference in the shape the message asks: `module.request` or `module.Poster.field`; a "
        "service's `output:` is an executive function, and a module cannot send to itself."),
    "undefined-module": (
        "Correct the module name (see did-you-mean) or define that `module`; if a service runs its request, "
        "add the module to the system's `modules:`."),
    "undefined-request": (
        "Correct the request name or declare the request in that module; `incompatible_with` names only the "
        "module's own requests (use executive `conflicts` across modules)."),
    "undefined-poster": (
        "Correct the poster name or declare a `poster` of that name in the module, so specs and codels read "
        "an existing `module.Poster`."),
    "undefined-field": (
        "Name a field the poster's `data:` exports, or for a poster's `data:` a field of the module's "
        "`internal_data`; otherwise add the field."),
    "undefined-type": (
        "Correct the type name, use a built-in type (`double`, `int`, `string`...), or declare the "
        "`struct`/`enum` (or procedures `type NAME = {...}`)."),
    "undefined-exec-task": "Set `task:` to an `exec_task` the module declares, or declare an `exec_task` of that name.",
    "undefined-activity": "Set the poster's `activity:` to a request or a permanent codel of the same module.",
    "undefined-codel": (
        "Define the function in the named Python module (run `specc skeleton` for a stub), or correct the "
        "function name in the spec."),
    "bad-codel-signature": (
        "Give the function exactly the parameters the runtime passes, as the message shows: `f(sdi, request)` "
        "for request codels, `f(sdi)` for an exec task's codels."),
    "incomplete-reply-domain": (
        "Add the missing results the message lists (the requests' `fail:` codes, `FINAL_ERROR`) to the result "
        "type of the procedures' `REPLY` predicate."),
    "computed-send": (
        "Send a literal request name, `sdi.send_request(\"module.Request\")`, and list it in the request's "
        "`sends:`; leave it only if unverified sends are acceptable."),
    "undeclared-send": (
        "Add `sends: module.Request;` to the request whose codel sends it, so the incompatibility graph and "
        "`specc verify` account for the send."),
    "undeclared-result": (
        "Return one of the states or `fail:` messages the request allows, or declare the new failure with "
        "`fail: NAME;` in the request."),
    "undefined-codel-state": (
        "Lead the codel only to states with a codel of their own, standard ones (`end`, `ether`...), or add a "
        "`codel STATE: f;` for that state."),
    "undefined-service": (
        "Correct the service name (see did-you-mean) or declare `service NAME {...}` in the executive; if the "
        "system has none, give it `executive: NAME;`."),
    "undefined-input": (
        "Name only inputs the service's request declares in `args` and `takes:`, or add the input to the "
        "request's `input:`."),
    "undefined-rules": "Make the executive's `rules:` name an existing `rules` block, or define that rule base.",
    "undefined-executive": (
        "Make the system's `executive:` name an existing `executive` block, or define one with that name."),
    "undefined-procedures": (
        "Make the system's `supervisor:` name an existing `procedures` block, or define one with that name."),
    "undefined-ftplan": "Make the system's `planning:` name an existing `ftplan` block, or define one with that name.",
    "undefined-predicate": (
        "Declare it with `predicate NAME(...);` in the procedures or write a KA invoked by it; call an action "
        "through a primitive KA, not as a goal."),
    "undefined-action": (
        "Declare it with `action NAME(...) = \"python.module.function\";` (or `= service NAME;`) in the "
        "procedures, or correct the name."),
    "undefined-goal": (
        "Write a KA whose `invocation:` is that goal (`!(NAME ...)`), or correct the goal's name to one a KA "
        "is invoked by."),
    "undefined-world": (
        "Name a world the system's `worlds { }` section declares, or add `NAME: \"worlds/file.toml\";` there."),
    "undefined-mission": (
        "Make `plan:` name a `mission` of the system's ftplan block, or add that mission to the ftplan block."),
    "undefined-device": (
        "Grant only devices the simulated body has, and give the body the key that provides it (e.g. "
        "`laser_beams: N;`)."),
    "undefined-report": (
        "Add an `on report NAME(...) => ...;` rule to the ftplan block's `state`, or correct the report's "
        "name to one a rule reads."),
    "undefined-domain": (
        "Make `domain:` (or the problem's `for`) name an existing `domain` block, or define that domain."),
    "undefined-problem": "Name an existing `problem` for that planner in the mission, or define the problem.",
    "undefined-planner": "Name a `planner` block the ftplan declares, or declare that planner.",
    "undefined-task": (
        "Name a task the planners' domains define (correct the spelling), or add that `task` to the domain."),
    "undefined-attribute": (
        "Correct the name to an attribute or resource the domain declares (in rules: an input, an initialised "
        "or rule-set attribute), or declare it."),
    "undefined-constant": (
        "Define the constant set with `constant NAME = {...};` in the domain or an included fragment, or "
        "correct its name."),
    "undefined-fragment": (
        "Include only a `fragment` that exists (correct the name or define it); move what a domain and "
        "problem share into a fragment."),
    "undefined-macro": "Define the `macro` in the domain or an included fragment, or correct the call's name.",
    "macro-cycle": (
        "Break the recursion: write the statements out instead of the call, so no macro calls itself directly "
        "or through other macros."),
    "undefined-function": (
        "Use only the functions the planner knows (`min`, `max`, `abs`), or compute the value with "
        "constraints instead."),
    "undefined-name": (
        "Declare it as a `timepoint`, a macro parameter or a symbolic value of a `constant`, or correct its "
        "spelling."),
    "undefined-loop-variable": (
        "Wrap the rule in `foreach i in [...] { ... }` declaring that index, or use the index its `foreach` "
        "declares."),
    "unused-timepoint": (
        "Remove the timepoint from the declaration, or date something with it in an assertion or constraint."),
    "unused-fragment": (
        "Include the fragment from a domain, problem or fragment (`include NAME;`), or delete it; fine to "
        "leave if kept as a spare."),
    "missing-property": (
        "Add the property the message names to the block, e.g. `type: exec;`, `update: auto;`, `codels: "
        "\"pkg.mod\";`, `modules: ...;` or `world: NAME;`."),
    "duplicate-module-number": "Give each module a distinct `number:`.",
    "missing-exec-task": "Add `task: <exec_task>;` to the exec request, naming an `exec_task` of its module.",
    "missing-codel": (
        "Give the exec request at least `codel exec: f;`, or make it `type: control;` if it runs no activity."),
    "bad-codel-state": "Give an `exec_task` only `codel init:` and `codel permanent:`; put other codels in a request.",
    "codel-on-control-request": (
        "Replace the codels with a `validate:` function and drop `task:`, or make the request `type: exec;` "
        "if it must run an activity."),
    "not-a-control-request": (
        "Make the SET-PARAM parameter's `set:` name a control request, or make that request `type: control;`."),
    "recursive-type": (
        "Break the cycle: remove the field that leads back to the struct, e.g. store an index or identifier "
        "instead of the struct itself."),
    "bad-python-module": (
        "Write the codel module as dotted Python identifiers, e.g. `codels: \"cart_codels.drive\";` "
        "(underscores, not dashes)."),
    "missing-python-module": (
        "Create the Python file next to the spec (`specc skeleton` writes it), or correct the dotted module "
        "name in `codels:`."),
    "python-syntax-error": "Fix the Python syntax error at the reported line of the codel module.",
    "control-conflict": (
        "Remove the `conflicts` entry naming the control-request service, or give the conflict to the exec "
        "service that actually runs."),
    "rules-large": (
        "Split the rule base into bases that decide from fewer inputs, or compare numeric inputs with fewer "
        "thresholds; fine to leave if slow imports are acceptable."),
    "intermediate-never-read": (
        "Correct the misspelt output name in the `restrict`, or test the attribute in a rule, or remove the "
        "rule that deduces it."),
    "comparison-never-holds": (
        "Change the threshold to lie within the attribute's declared range, or widen that range if values "
        "beyond it can occur."),
    "comparison-always-holds": (
        "Change the threshold to lie within the attribute's declared range (likely a typo), or drop the "
        "comparison since it tests nothing."),
    "rule-never-fires": (
        "Start the chain from an input: let some rule set the tested attribute without needing it first, or "
        "test an input instead."),
    "rule-never-applies": (
        "Drop the hand-written rule, or declare that conflict as `interrupt` instead of `wait` so the rule "
        "can take effect."),
    "reflex-loop": (
        "Give the reflex a condition on the reply (e.g. `== FAILED`), or have it start a different service, "
        "so a service is not restarted on every reply."),
    "reflex-needs-input": (
        "Have the reflex `start` a service that supplies the inputs via `args { }`, instead of a request with "
        "inputs or a service that `takes:` them."),
    "reflex-never-fires": (
        "Compare with a value the request reports: declare it in the request's `fail:` list, or correct the "
        "value's name."),
    "controller-attribute": (
        "Declare only what the executive supplies: inputs `service` and `event`, output `status`, group-state "
        "outputs, each with values among those the message lists."),
    "unknown-group-state": (
        "Give the output exactly one group's services plus `\"IDLE\"` as its values, and name each group the "
        "same in every rule base."),
    "type-mismatch": (
        "Compare symbolic attributes with `==`, `!=`, `oneof`, `noneof`; numeric ones with numbers; test a "
        "bool as `x` or `!x`."),
    "value-outside-domain": (
        "Use one of the values the attribute's or predicate's declared domain lists (see did-you-mean), or "
        "widen the domain to hold it."),
    "restrict-input": (
        "Restrict an output or intermediate attribute instead; inputs may only be tested, so remove the "
        "`restrict` of the input."),
    "missing-init": "Add `init @x = VALUE;` for the attribute whose previous-cycle value `@x` the rule reads.",
    "init-undeclared": (
        "Declare the attribute among `inputs`, `outputs` or `intermediate`, or correct the name in `init @x`; "
        "remove the init if unused."),
    "output-never-set": (
        "Add a rule that restricts the output (`... ==> restrict out == \"v\";`), or remove it from `outputs`."),
    "empty-rule-base": (
        "Add rules to the base (e.g. `slow: load > 100 ==> restrict speed == \"slow\";`) or remove it; fine to "
        "leave as a placeholder."),
    "input-never-read": (
        "Test the input in a rule, or remove it from `inputs`; fine to leave if it is kept for rules to come."),
    "empty-domain": "Write the lower bound first: `[0, 1]` in rules, `0..5` in procedures.",
    "rules-too-large": (
        "Split the base into bases deciding from fewer inputs, use fewer thresholds (or fewer conflicts per "
        "service), or raise `SPECC_RULES_WORK_LIMIT=N`."),
    "not-propositional": (
        "Compare each attribute with a literal constant only: compute the other side with `do {x = ...}` "
        "first, order only numbers, never restrict `@x`."),
    "rules-unsettled": (
        "Run `specc rules` to list the cases, then add rules (or an `else restrict ...` rule) or make "
        "conflicting rules exclusive; fine if those inputs cannot occur."),
    "missing-invocation": "Give the KA `invocation: !(GOAL ...);` or a fact it is invoked by.",
    "empty-ka-body": (
        "Put at least one statement in the body or loop, give the KA an `action:` instead, or remove the "
        "empty loop."),
    "conflicting-ka-kinds": (
        "Keep either the `body` or the primitive `action:` of the KA; split it into two KAs if both are "
        "needed."),
    "condition-not-test": (
        "Write the `if`/`while` condition as a test goal `?(...)`; achieve other goals as statements before "
        "it."),
    "unreachable-statement": "Remove the statements after `fail;`, or move them before it.",
    "bad-binding": "Bind the action or predicate to `\"python.module.function\"` (or an action to `service NAME`).",
    "unbound-variable": (
        "Bind the variable before it is used (a test `?(...)`, an invocation or a goal's result), or write a "
        "constant value in its place."),
    "array-too-large": (
        "Shrink the array to at most ten million elements; keep large data (maps, images) in the codels' own "
        "objects, outside the SDI."),
    "assigned-output": (
        "Set the output with `restrict out == ...` instead of `do {out = ...}`; use `do` only for "
        "intermediate attributes rules test."),
    "always-true-test": (
        "Correct the misspelt variable so `?(= $V x)` compares a variable bound earlier (a reply's result, "
        "the invocation's), or compare a value."),
    "bad-argument": (
        "Pass a value the predicate's domain holds and of the kind the KAs pass on: a number (whole where an "
        "`int` waits), not a symbol."),
    "bypasses-executive": (
        "Bind the task to an executive service (`=> service NAME(...)`) instead of a raw request; fine to "
        "leave if that module needs no conflict protection."),
    "bad-argument-type": (
        "Pass values the input's type holds (a number for `double`, a whole number for `int`, an enum's own "
        "values), or change the action's parameter domain."),
    "include-cycle": (
        "Break the cycle: stop one fragment including the other, moving what both need into a third fragment."),
    "undeclared-variable": "Declare it in the task with `variable ?x;`, or correct its spelling.",
    "undeclared-timepoint": (
        "Declare it with `timepoint t;` (or in the task's timepoint list), or use `t_start`/`t_end`."),
    "empty-interval": "Swap the bounds so the low one comes first, e.g. `[5, 10]`.",
    "contradictory-constraints": (
        "Loosen or remove one of the listed temporal constraints so all can hold, keeping every timepoint "
        "between `t_start` and `t_end`."),
    "event-without-transition": (
        "Give the event two different values, `event(A(): (before, after), t)`, or use `hold(A(): v, (t1, "
        "t2))` for a value that persists."),
    "hold-transition": (
        "Give the hold one value, `hold(A(): v, (t1, t2))`, or use `event(A(): (v1, v2), t)` for a change."),
    "bad-goal": "Give `goal(priority, weight)` two finite numbers, e.g. `goal(2, 0)`.",
    "statement-outside-problem": (
        "Move the constraint or assertion into a problem, or into a fragment only problems include; keep the "
        "domain's fragments to declarations."),
    "goal-outside-problem": (
        "Move the `goal(...)` statement out of the task into a problem (or a fragment the problem includes)."),
    "no-goals": (
        "Add a `goal(priority, weight)` to at least one of the problem's statements; fine to leave if the "
        "problem is a deliberate no-op."),
    "unsupported-resource-use": (
        "Write resource use as `use(R(): amount, (t1, t2))` over two distinct timepoints, instead of "
        "`consume`/`produce` or a single instant."),
    "domain-mismatch": "Give the planner a problem written for its own domain (or a domain with the same tasks).",
    "mission-ends-differ": (
        "Give the mission's problems one latest end, e.g. the same `(t_end - t_start) in [0, N];` in each."),
    "planners-share-domain": (
        "Give each planner a problem for its own domain; leave it only if that planner need not be diverse in "
        "this mission."),
    "bad-rule-argument": (
        "Pass a ?variable, symbol or number (not an expression); a requirement names one value `ATTR(args): "
        "VALUE`; intervals belong right of `<=>`."),
    "unknown-heuristic": (
        "Use a heuristic the planner knows (`most-room-first`, `least-room-first`) or flaw order "
        "(`newest-task-first`, `oldest-task-first`), or remove the property."),
    "unusable-correspondence": (
        "Bind the ?variables on both sides of `<=>`: each left ?variable appears on the right, and each right "
        "?variable or interval is bound by the left."),
    "over-capacity": "Lower the amount the task uses, or raise the upper bound of the resource's `?value` domain.",
    "negative-amount": "Make the resource amount 0 or more, and the contingent duration's lower bound 0 or more.",
    "bad-duration": (
        "Make the period, timeout, watchdog or horizon longer than zero, the delay non-negative and shorter "
        "than the period, and every duration a number a double holds."),
    "bad-world": (
        "Fix the world file as the message says (valid TOML, known keys and values, a start pose clear of "
        "obstacles for the body's footprint)."),
    "missing-world": "Correct the world file's path (relative to the spec) in `worlds { }`, or create the file.",
    "goal-without-supervisor": (
        "Add `supervisor: NAME;` to the system, naming its procedures, or carry the task out as a service or "
        "request instead."),
    "bad-mission-goal": "Write the mission goal as an achieve `!(...)`, a test `?(...)`, or a fact `=>(...)`.",
    "missing-binding": (
        "Add `TASK(...) => goal G(...);` (or `service`/`request`) to the system's `bindings`; bind an "
        "evaluable predicate to `\"python.module.function\"`."),
    "arity-mismatch": (
        "Pass exactly as many arguments as the called goal, predicate, action, service, macro or task "
        "declares."),
    "bad-executive-ka": (
        "Invoke the executive KA by a goal naming the service first and the result last, e.g. `!(EXEC-REQUEST "
        "$REQUEST $RESULT)`."),
    "choose-first-arc": (
        "Start each `choose` branch with a goal (`^(...)`, `!(...)`, `?(...)`), moving conclusions like "
        "`=>(...)` after it."),
    "event-test": "Wait for the event with `^(...)` (or a fact invocation) instead of testing it with `?(...)`.",
    "no-executive": "Connect the procedures to an executive: give a system both `supervisor:` and `executive:`.",
    "no-applicable-ka": (
        "Write an executive KA invoked by `!(HEAD SERVICE ...)` for that service, or correct the service "
        "name."),
    "shared-variable": "Bind the variable before the `parallel`, or pass the value between branches through a fact.",
    "unbounded-variable": (
        "Give the predicate argument the variable stands for a finite domain (e.g. `0..5` or `{A, B}`); wait "
        "for request ids in the `property: executive` KA."),
    "answer-without-ok": "Add `OK` to the domain of the result the service's answer is received in.",
    "unsupported-goal": (
        "Replace the `#` (preserve) or `%` (maintain) goal with a fact-invoked KA that reacts when the "
        "condition changes, or verify without it."),
    "unsupported-meta": "Verify without the meta KA, or drop its `property: meta`.",
}
