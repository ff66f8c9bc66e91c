"""The front end in one call: find the spec files, parse them all, then run every check."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from specc.check import check_program
from specc.diagnostics import Diagnostic, display_path, error, sort_key, warning
from specc.model import nodes as m
from specc.model.span import Span
from specc.syntax.parsed import Comment
from specc.syntax.parser import parse_text, read_source, spec_files


@dataclass
class Loaded:
    """A robot's specs loaded: the program, every diagnostic, and the files' texts."""

    program: m.Program | None
    diagnostics: list[Diagnostic]
    sources: dict[str, str] = field(default_factory=dict)  # file as shown in spans -> its text
    comments: dict[str, list[Comment]] = field(default_factory=dict)
    paths: dict[str, Path] = field(default_factory=dict)  # file as shown in spans -> its path

    @property
    def errors(self) -> list[Diagnostic]:
        return [d for d in self.diagnostics if d.severity == "error"]


def load(paths: list[Path], *, check: bool = True) -> Loaded:
    files, diagnostics = spec_files(paths)
    loaded = Loaded(None, diagnostics)
    sources: list[m.SourceFile] = []
    for path in files:
        shown = display_path(path)
        text, problem = read_source(path)
        if problem is not None:
            loaded.diagnostics.append(problem)
            continue
        assert text is not None
        loaded.sources[shown] = text
        loaded.paths[shown] = path
        result = parse_text(text, shown)
        loaded.diagnostics.extend(result.diagnostics)
        loaded.comments[shown] = result.comments
        if result.source is not None:
            sources.append(result.source)
            if not result.source.items:  # a file emptied, or one of comments only: nothing of it is read
                loaded.diagnostics.append(warning("empty-file", f"'{shown}' holds no block (module, executive, "
                                                  "rules...): nothing in it is checked or compiled; write one or "
                                                  "remove the file", Span(shown, 1, 1, 1, 1)))
    parsed_all = len(sources) == len(files)
    if sources:
        loaded.program = m.Program(files=tuple(sources))
    if check and parsed_all and loaded.program is not None:
        base_dirs = {shown: path.resolve().parent for shown, path in loaded.paths.items()}
        found = check_program(loaded.program, base_dirs)
        found += _controller_naming_diagnostics(loaded.program, [d for d in found if d.severity == "error"])
        if not any(d.severity == "error" for d in found):
            found += _rule_base_diagnostics(loaded.program)
            found += _mission_end_diagnostics(loaded.program)
        loaded.diagnostics.extend(d for d in found if not _already_reported(d, loaded.diagnostics))
    loaded.diagnostics.sort(key=sort_key)
    return loaded


def _controller_naming_diagnostics(program: m.Program, errors: list[Diagnostic]) -> list[Diagnostic]:
    """How each executive's own rule bases name its service groups (seed 000 Fig 5.6 calls the
    pilo group ExecTrajState): what they get wrong, from the incompatibility graph (an analysis,
    so reported here, after the check passes, and before anything is compiled). Not for an
    executive whose services or modules have errors (`errors`): a misspelt request changes the
    groups, and the rules would be blamed for it."""
    from specc.analysis.controller import naming, rules_waits_override, unread_deductions

    modules = [item.span for item in program.items if isinstance(item, m.Module)]
    found = []
    for executive in (e for e in program.items if isinstance(e, m.Executive)):
        if any(_inside(d.span, block) for d in errors for block in (executive.span, *modules)):
            continue
        named = naming(program, executive)
        found += [error(p.code, p.message, p.node.span) for p in named.problems]
        found += [warning(p.code, p.message, p.node.span) for p in rules_waits_override(executive, named)]
        found += [warning(p.code, p.message, p.node.span) for p in unread_deductions(named)]
    return found


def _inside(span: Span, block: Span) -> bool:
    return span.file == block.file and (block.line, block.column) <= (span.line, span.column) <= (
        block.end_line, block.end_column)


def _rule_base_diagnostics(program: m.Program) -> list[Diagnostic]:
    """What `specc compile` says of the rule bases, said by `specc check` too: a rule outside the
    propositional subset Kheops compiles, a base past the compilation's work limit, and the inputs
    it leaves unsettled; for each executive, the same of its resource controller (its generated
    rules joined by its own bases, compiled one decision per service: milliseconds for 21 services)."""
    from specc.analysis.controller import executive_controller
    from specc.analysis.kheops import KheopsError, compile_base, compiled_warnings, normalise

    joined = {ref.text for e in program.items if isinstance(e, m.Executive) for ref in e.rules}
    found = []
    for base in (item for item in program.items if isinstance(item, m.RuleBase)):
        try:
            normal = normalise(base)
            if base.name not in joined:
                found += compiled_warnings(compile_base(normal), f"rule base '{base.name}'", base)
        except KheopsError as exc:
            found.append(exc.diagnostic())
    if any(d.severity == "error" for d in found):
        return found
    for executive in (item for item in program.items if isinstance(item, m.Executive)):
        try:
            controller = executive_controller(program, executive)
            if controller.problems:
                continue  # the executive's check reported them
            found += compiled_warnings(controller.compile(), f"the resource controller of executive "
                                       f"'{executive.name}'", executive)
        except KheopsError as exc:
            found.append(exc.diagnostic())
    return found


def _mission_end_diagnostics(program: m.Program) -> list[Diagnostic]:
    """FTplan counts a planned mission's goals met or missed by its own statement of the mission
    (the problem of its first planner without a view): a planner whose problem lets the mission
    end at another time plans for a deadline FTplan does not count by (a plan ending past
    FTplan's misses goals it met, one ending sooner leaves time unused)."""
    from specc.analysis.ftplan import state_planner
    from specc.analysis.planning import problem_model
    from specc.runtime.planner.model import latest_end

    problems = {p.name: p for p in program.items if isinstance(p, m.Problem)}
    found = []
    for block in (b for b in program.items if isinstance(b, m.FtPlan)):
        judge = state_planner(block)
        for mission in block.missions:
            named = {e.planner.text: e for e in mission.problems if e.problem.text in problems}
            if judge is None or judge.name not in named or len({e.problem.text for e in named.values()}) < 2:
                continue
            own = named[judge.name].problem.text
            ends = {name: latest_end(problem_model(program, problems[name]))
                    for name in {e.problem.text for e in named.values()}}
            for planner, entry in named.items():
                there = ends[entry.problem.text]
                if there != ends[own]:
                    said = {math.inf: "has no latest end"}
                    found.append(warning(
                        "mission-ends-differ",
                        f"mission '{mission.name}': planner '{planner}''s problem '{entry.problem.text}' "
                        f"{said.get(there, f'ends by {there:g} s at the latest')}, and FTplan counts the goals met "
                        f"by planner '{judge.name}''s problem '{own}' (its first planner without a view), which "
                        f"{said.get(ends[own], f'ends by {ends[own]:g} s')}: give both one latest end "
                        "(`(t_end - t_start) in [0, N];`)", entry.problem.span))
    return found


def _already_reported(diagnostic: Diagnostic, earlier: list[Diagnostic]) -> bool:
    """A property the builder rejected as malformed is not reported missing again, and a number
    too large to hold (kept as infinity) is not reported again as a value out of place."""
    s = diagnostic.span
    if any(d.code == "number-too-large" and d.span.file == s.file and (d.span.line, d.span.column)
           == (s.line, s.column) for d in earlier):
        return True
    if diagnostic.code != "missing-property":
        return False
    return any(d.code == "bad-property-value" and d.span.file == s.file
               and (s.line, s.column) <= (d.span.line, d.span.column) <= (s.end_line, s.end_column)
               for d in earlier)
