"""Verifying procedures (seed 000 §4.5): translate the KAs a posted goal reaches into a coloured
Petri net, explore its whole state space, and report in the procedures' own terms.

Findings:
- deadlock: a marking where nothing can fire and a posted goal has no answer yet (a marking
  where every posted goal has succeeded or failed is the expected end, §4.5);
- unbounded: a place that grows without bound (unbounded recursion, §4.5);
- out-of-domain: a value leaves its finite domain (the net would need more colours);
- zombie-unanswered: with `--fail`, a service may go ZOMBIE, and the request protocol never waits
  for its (WARNING ...): no REPLY comes until the procedures interrupt it, so its caller waits
  for ever;
- never-succeeds: a statement is reached but its arc can never be crossed (a dead transition);
- changes-nothing: a retraction that only ever runs with an unbound argument (it retracts nothing);
- unreachable: statements of an invoked KA that can never run; never-invoked: a KA never started;
- no-way-out: intentions cycle forever and nothing can take them out (a terminal strongly
  connected component other than the expected end);
- endless-cycle: intentions may cycle forever while the world keeps answering the same way: every
  way out of the cycle is a choice of the world (a service's answer, an evaluable predicate), never
  a step some procedure is ready to take (those must happen eventually: strong fairness).
Each finding carries the shortest firing sequence to it, one line per step, naming the KA line.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from specc.analysis import petri
from specc.analysis.controller import executive_controller
from specc.analysis.prs_net import ExecutiveModel, Reading, Service, Translation, Translator
from specc.analysis.service_list import executive_spec
from specc.check.symbols import symbols_of
from specc.model import nodes as m
from specc.runtime import procedures as rp


@dataclass
class Finding:
    kind: str
    message: str
    trace: list[str] = field(default_factory=list)
    where: list[str] = field(default_factory=list)  # where each intention stands at the end of the trace


@dataclass(frozen=True)
class Clause:
    """An intention standing at a statement (KA:LINE), where an optional condition holds (a
    test over the database and that KA's variables)."""

    ka: str
    line: int
    condition: rp.Goal | None = None


@dataclass(frozen=True)
class Query:
    """Can these clauses hold together? Written `KA:LINE [?(condition)]; KA:LINE ...`."""

    text: str
    clauses: tuple[Clause, ...]


@dataclass
class Answer:
    query: Query
    reached: bool
    trace: list[str] = field(default_factory=list)
    where: list[str] = field(default_factory=list)


def parse_query(text: str) -> Query:
    clauses = []
    for part in text.split(";"):
        head, _, condition = part.strip().partition(" ")
        ka, _, line = head.partition(":")
        if not ka or not line.isdigit():
            raise ValueError(f"'{part.strip()}': write KA:LINE, optionally followed by a test ?(...)")
        goal = rp.parse_goal(condition) if condition.strip() else None
        if goal is not None and goal.op != "?":
            raise ValueError(f"'{condition.strip()}': a query's condition is a test ?(...)")
        clauses.append(Clause(ka, int(line), goal))
    return Query(text, tuple(clauses))


@dataclass
class Report:
    translation: Translation
    space: petri.StateSpace
    findings: list[Finding]
    succeeded: int  # end markings where the posted goals succeeded
    failed: int  # ... where one failed
    answers: list[Answer] = field(default_factory=list)
    bounds: dict[str, int] = field(default_factory=dict)  # KA position -> most tokens it ever holds
    home: bool = False  # one marking (or cycle) every marking can reach

    def bound_summary(self) -> str:
        if not self.bounds:
            return "no KA place is ever marked"
        most = max(self.bounds.values())
        crowded = sorted(p for p, n in self.bounds.items() if n == most)
        shown = ", ".join(crowded[:4]) + (f" and {len(crowded) - 4} more" if len(crowded) > 4 else "")
        return f"every KA place holds at most {most} token(s)" + (f" (that many: {shown})" if most > 1 else "")

    @property
    def states(self) -> int:
        return self.space.states

    def kinds(self) -> list[str]:
        return [f.kind for f in self.findings]


def executive_model(program: m.Program, procedures: m.Procedures, failing: Sequence[str] = ()) -> ExecutiveModel | None:
    """The services and groups of the executive a system puts under these procedures."""
    systems = [i for i in program.items if isinstance(i, m.System)
               and i.supervisor is not None and i.supervisor.text == procedures.name and i.executive is not None]
    if not systems:
        return None
    assert systems[0].executive is not None
    name = systems[0].executive.text
    symbols = symbols_of(program)
    executive: m.Executive | None = symbols.blocks[m.Executive].get(name)
    if executive is None:
        return None
    spec = executive_spec(program, executive_controller(program, executive))
    group_of = {service: group for group, services in spec.groups.items() for service in services}
    requests = {s.name: symbols.service_request(s) for s in executive.services}
    services = {}
    for service in spec.services.values():
        excluded = tuple(sorted((group_of[c], c) for c in service.conflicts if c in group_of))
        request = requests.get(service.name)
        reports = frozenset(r.text for r in request.fail) if request is not None else frozenset()
        services[service.name] = Service(service.name, group_of.get(service.name), excluded, service.output, reports)
    unknown = sorted(set(failing) - set(services) - {"*"})
    if unknown:
        raise ValueError(f"executive '{name}' offers no service {', '.join(unknown)} (it offers "
                         f"{', '.join(sorted(services))})")
    return ExecutiveModel(services, {g: tuple(s) for g, s in spec.groups.items()}, frozenset(failing))


def translate(program: m.Program, procedures: m.Procedures, goals: Sequence[rp.Goal],
              facts: Sequence[rp.Compound] = (), failing: Sequence[str] = ()) -> Translation:
    """The Petri net of the KAs the goals reach (ValueError for a goal, fact or service the
    procedures do not know; TranslationError for what a net cannot represent)."""
    executive = executive_model(program, procedures, failing)
    if failing and executive is None:
        raise ValueError("--fail names services, but no system connects these procedures to an executive")
    return Translator(procedures, executive).translate(goals, facts)


def verify(program: m.Program, procedures: m.Procedures, goals: Sequence[rp.Goal], facts: Sequence[rp.Compound] = (),
           failing: Sequence[str] = (), queries: Sequence[Query] = (), limit: int = 2_000_000,
           progress: Callable[[int], None] | None = None) -> Report:
    translation = translate(program, procedures, goals, facts, failing)
    return analyse(translation, queries, limit, progress)


def query_places(translation: Translation, query: Query) -> dict[Clause, list[str]]:
    places = {}
    for clause in query.clauses:
        found = [p for (ka, line, _), ps in translation.statements.items() if (ka, line) == (clause.ka, clause.line)
                 for p in ps]
        if not found:
            lines = sorted({line for ka, line, _ in translation.statements if ka == clause.ka})
            known = f"its statements are on lines {', '.join(map(str, lines))}" if lines else \
                f"KA '{clause.ka}' is not among the KAs the goal reaches ({', '.join(translation.kas)})"
            raise ValueError(f"no statement at {clause.ka}:{clause.line}: {known}")
        if clause.condition is not None and translation.solver is not None:
            problems = translation.solver.problems(clause.condition.expr)
            if problems:
                raise ValueError(f"'{clause.condition}' in --reach '{query.text}': {'; '.join(problems)}")
        places[clause] = found
    return places


def analyse(translation: Translation, queries: Sequence[Query] = (), limit: int = 2_000_000,
            progress: Callable[[int], None] | None = None) -> Report:
    asked = [query_places(translation, q) for q in queries]
    watched = {p for places in asked for found in places.values() for p in found}
    tops = {f"{goal}.{outcome}" for goal, _ in translation.top for outcome in ("SUCC", "FAIL")}
    unfolded = translation.net.unfold().reduced(
        lambda place: place in translation.errors or place in tops or place in watched)
    space = petri.explore(unfolded, limit, progress)
    reader = Reader(translation, unfolded)
    findings: list[Finding] = []
    for finding in space.unbounded:
        grown = [reader.place(p) for p in finding.places]
        loop = " ; ".join(reader.trace(finding.loop))
        findings.append(Finding("unbounded", f"{', '.join(grown)}: tokens pile up without bound (unbounded "
                                f"recursion?); this sequence can repeat forever, adding tokens each time: {loop}",
                                reader.trace(finding.trace)))
    succeeded = failed = 0
    # Every place some firing marks (the reduction hides the places its fused steps pass by).
    original = unfolded.original_slots or unfolded.slots
    marked_places = {unfolded.slots[m.start()][0] for m in petri.NONZERO.finditer(unfolded.initial)}
    for i in space.fired():
        for part in unfolded.steps[i].elementary:
            marked_places.update(original[s][0] for s, _ in part.post)
    for error, (kind, meaning) in translation.errors.items():
        if error in marked_places:
            state = next(i for i, mk in enumerate(space.markings) if reader.tokens(mk, error))
            findings.append(Finding(kind, meaning, reader.trace(space.trace(state)),
                                    reader.where(space.markings[state])))
    if space.complete:
        deadlock = None
        for state in space.deadlocks():
            marking = space.markings[state]

            def tokens(place: str, marking: bytes = marking) -> int:
                return reader.tokens(marking, place)

            if translation.answered(tokens):
                if any(reader.tokens(marking, f"{goal}.FAIL") for goal, _ in translation.top):
                    failed += 1
                else:
                    succeeded += 1
            elif deadlock is None and not any(reader.tokens(marking, e) for e in translation.errors):
                deadlock = state
        if deadlock is not None:
            findings.append(Finding("deadlock", "nothing can happen any more and the posted goal has no answer",
                                    reader.trace(space.trace(deadlock)), reader.where(space.markings[deadlock])))
        findings.extend(_statements(translation, space, reader, marked_places))
        findings.extend(_cycles(translation, space, reader))
    answers = [_answer(query, places, space, reader) for query, places in zip(queries, asked, strict=True)]
    bounds: dict[str, int] = {}
    if space.complete:
        for place, most in space.bounds().items():
            if place in translation.where and most:
                shown = reader.place(place)
                bounds[shown] = max(bounds.get(shown, 0), most)
    home = space.complete and bool(space.home_markings())
    return Report(translation, space, findings, succeeded, failed, answers, bounds, home)


def _answer(query: Query, places: dict[Clause, list[str]], space: petri.StateSpace, reader: Reader) -> Answer:
    for state, marking in enumerate(space.markings):  # breadth-first: the first is the nearest
        if all(reader.holds(marking, clause, found) for clause, found in places.items()):
            return Answer(query, True, reader.trace(space.trace(state)), reader.where(marking))
    return Answer(query, False)


class Reader:
    """Markings and steps told in the procedures' terms."""

    def __init__(self, translation: Translation, unfolded: petri.Unfolded):
        self.translation = translation
        self.unfolded = unfolded
        self.slots_of: dict[str, list[int]] = {}
        self.index: dict[tuple[str, Any], int] = {}
        for slot, (place, colour) in enumerate(unfolded.slots):
            self.slots_of.setdefault(place, []).append(slot)
            self.index[(place, colour)] = slot

    def tokens(self, marking: bytes, place: str) -> int:
        return sum(marking[s] for s in self.slots_of.get(place, ()))

    def place(self, place: str) -> str:
        where = self.translation.where.get(place)
        return f"{where.ka}:{where.line} {where.what}" if where is not None else place

    def holds(self, marking: bytes, clause: Clause, places: Sequence[str]) -> bool:
        """Some token at the clause's statement satisfies its condition."""
        for place in places:
            where = self.translation.where.get(place)
            for slot in self.slots_of.get(place, ()):
                if not marking[slot]:
                    continue
                if clause.condition is None:
                    return True
                env = where.values(self.unfolded.slots[slot][1]) if where else {}
                if self._test(marking, clause.condition.expr, env):
                    return True
        return False

    def _test(self, marking: bytes, expr: rp.Compound, env: dict[str, Any]) -> bool:
        solver = self.translation.solver
        assert solver is not None
        states = {}
        for key in dict.fromkeys(solver.atoms(expr, env)):
            for state in solver.db.states(*key):
                if state.takes and all(self._present(marking, place, colour) for place, colour in state.takes):
                    states[key] = state
                    break
        return bool(solver.solve(expr, env, Reading(states)))

    def _present(self, marking: bytes, place: str, colour: Any) -> bool:
        slot = self.index.get((place, petri.BLACK if colour == () else colour))
        return slot is not None and marking[slot] > 0

    def firing(self, step: petri.Step) -> str:
        return self.translation.firings.get(step.transition, step.transition)

    def step(self, step: petri.Step) -> str:
        """One elementary step (the slots it counts are the unreduced net's)."""
        name = self.firing(step)
        shown = []
        for slot, _ in step.post:
            place, colour = (self.unfolded.original_slots or self.unfolded.slots)[slot]
            where = self.translation.where.get(place)
            if where is not None and where.vars and isinstance(colour, tuple):
                values = where.values(colour)
                if values:
                    shown.append(" ".join(f"{v}={c}" for v, c in values.items()))
            elif place.endswith(".SUCC") and isinstance(colour, tuple):
                shown.append(f"answer ({place[:-5]} {' '.join(map(str, colour))})")
        return name + (f"  [{'; '.join(dict.fromkeys(shown))}]" if shown else "")

    def trace(self, steps: Sequence[petri.Step]) -> list[str]:
        return [self.step(part) for s in steps for part in s.elementary]

    def where(self, marking: bytes) -> list[str]:
        found = []
        for match in petri.NONZERO.finditer(marking):
            place, colour = self.unfolded.slots[match.start()]
            where = self.translation.where.get(place)
            if where is None:
                continue
            values = " ".join(f"{v}={c}" for v, c in where.values(colour).items())
            found.append(f"{where.ka}:{where.line} {where.what}" + (f" ({values})" if values else ""))
        return found


def _statements(translation: Translation, space: petri.StateSpace, reader: Reader,
                marked: set[str]) -> list[Finding]:
    fired_names = {reader.firing(part) for i in space.fired() for part in space.unfolded.steps[i].elementary}
    findings = []
    for ka in translation.kas:
        if f"{ka}.INIT" not in marked and f"{ka}.INIT" in translation.net.places:
            findings.append(Finding("never-invoked", f"KA '{ka}' is never invoked"))
            continue
        unreachable = []
        for (owner, line, n), places in sorted(translation.statements.items()):
            if owner != ka:
                continue
            text = translation.text.get((owner, line, n), "")
            if not any(p in marked for p in places):
                unreachable.append(f"{line} {text}")
                continue
            crossed = translation.successes.get((owner, line, n))
            if crossed and not any(name in fired_names for name in crossed):
                trace = _first_marking(space, reader, set(places))
                findings.append(Finding("never-succeeds", f"{ka}:{line} {text} is reached but can never succeed "
                                        "(its success transition is dead): what follows it never runs", trace))
                continue
            idle = translation.idle_successes.get((owner, line, n), [])
            if idle and all(name in idle for name in crossed or () if name in fired_names):
                trace = _first_marking(space, reader, set(places))
                findings.append(Finding("changes-nothing", f"{ka}:{line} {text} only ever runs with an unbound "
                                        "argument: it retracts nothing (§4.4.2, Fig 4.12); bind the argument "
                                        "first, or retract by a value", trace))
        if unreachable:
            findings.append(Finding("unreachable", f"KA '{ka}': these statements can never run: "
                                    + "; ".join(unreachable)))
    return findings


def _first_marking(space: petri.StateSpace, reader: Reader, places: set[str]) -> list[str]:
    """The shortest firing sequence that puts a token in one of `places` (which the reduction
    may have merged into the steps passing by them)."""
    original = space.unfolded.original_slots or space.unfolded.slots
    for state, out in enumerate(space.edges):  # breadth-first order: the first found is the nearest
        for step_index, _ in out:
            parts = space.unfolded.steps[step_index].elementary
            for n, part in enumerate(parts):
                if any(original[s][0] in places for s, _ in part.post):
                    return reader.trace(space.trace(state)) + [reader.step(p) for p in parts[:n + 1]]
    return []


def _cycles(translation: Translation, space: petri.StateSpace, reader: Reader) -> list[Finding]:
    steps = space.unfolded.steps
    environment = translation.environment

    def name(step_index: int) -> str:
        return reader.firing(steps[step_index])

    def is_environment(step_index: int) -> bool:
        return any(part.origin in environment or reader.firing(part) in environment
                   for part in steps[step_index].elementary)

    found: dict[tuple[frozenset[str], bool], Finding] = {}
    work = [set(c) for c in space.components() if _cyclic(space, c)]
    while work:
        states = work.pop()
        # A state where some procedure is ready to leave: strong fairness makes it leave.
        forced = set()
        for state in states:
            for step, target in space.edges[state]:
                if target in states:
                    continue
                # Another answer of the same statement keeps the cycle going (the world may give it).
                sibling_stays = any(t in states and steps[s].origin == steps[step].origin
                                    for s, t in space.edges[state])
                if not (is_environment(step) and sibling_stays):
                    forced.add(state)
                    break
        if forced:
            rest = states - forced
            work.extend(set(c) for c in petri.strongly_connected(rest, lambda x: [t for _, t in space.edges[x]])
                        if _cyclic(space, c, rest))
            continue
        exits = sorted({" ; ".join(reader.trace([steps[s]])) for x in states for s, t in space.edges[x]
                        if t not in states})
        looping = frozenset(name(s) for x in states for s, t in space.edges[x] if t in states)
        key = (frozenset(_ka_of(n) for n in looping), bool(exits))
        entry = min(states)
        if key in found and len(reader.trace(space.trace(entry))) >= len(found[key].trace):
            continue
        kas = sorted({_ka_of(n) for n in looping} - {""})
        if exits:
            message = (f"{', '.join(kas)} may cycle forever ({len(states)} markings) while the world keeps answering "
                       f"the same way; the only ways out: {'; '.join(exits)}")
            kind = "endless-cycle"
        else:
            message = f"{', '.join(kas)} cycle forever ({len(states)} markings) and nothing can stop them"
            kind = "no-way-out"
        found[key] = Finding(kind, message, reader.trace(space.trace(entry)), reader.where(space.markings[entry]))
    return sorted(found.values(), key=lambda f: (f.kind, len(f.trace)))


def _cyclic(space: petri.StateSpace, component: Sequence[int] | set[int], within: set[int] | None = None) -> bool:
    members = set(component) if within is None else set(component) & within
    if len(members) > 1:
        return True
    (only,) = members
    return any(t == only for _, t in space.edges[only])


def _ka_of(transition: str) -> str:
    head = transition.split(" ", 1)[0]
    return head.split(":", 1)[0] if ":" in head else ""


