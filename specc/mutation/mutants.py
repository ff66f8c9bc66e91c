"""Mutants of a planning domain: enumerated on the model, printed back as spec text, filtered by
the checks `specc check` runs, sampled, and lowered to the planner's domain for a campaign."""

from __future__ import annotations

import difflib
import functools
import multiprocessing
import os
import random
import time
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field, fields, is_dataclass, replace
from functools import cached_property
from pathlib import Path
from typing import Any, Literal, Union

from specc.analysis.planning import PlanningError, domain_model
from specc.check import check_program
from specc.diagnostics import Diagnostic
from specc.model import nodes as m
from specc.model.span import Span
from specc.mutation.edits import CLASSES, Edit, MutationClass, domain_edits
from specc.mutation.tree import node_at, replace_at
from specc.pipeline import Loaded, load
from specc.runtime.planner import model as pm
from specc.syntax.parsed import Comment
from specc.syntax.parser import parse_text
from specc.syntax.printer import domain_value, format_source, ixexpr, print_source, tstmt

Robot = Union[Path, Sequence[Path], Loaded, m.Program]
Reason = Literal["identical", "duplicate", "invalid", "equivalent"]
# Not fork: the command line's progress display runs a thread, and a fork copies its locks.
START_METHOD = "forkserver"


class MutationError(ValueError):
    """The robot or the domain cannot be mutated (unknown domain, specs with errors), or a name
    given is unknown; the message is one line for the user."""


@dataclass(frozen=True, eq=False)
class MutationTarget:
    """The domain under mutation and the robot around it: the other spec files are re-checked
    with each mutant, as `specc check` would check the robot with the mutated file in it."""

    program: m.Program
    domain: m.Domain
    file_index: int  # the file holding the domain, in program.files
    item_index: int  # the domain, in that file's items
    base_dirs: dict[str, Path] = field(repr=False)
    # The file as written and its comments, so that a mutant keeps them (`specc fmt`'s printing);
    # without them (a Program whose file cannot be read again), files are printed without comments.
    written: str = field(default="", repr=False)
    comments: tuple[Comment, ...] = field(default=(), repr=False)

    @property
    def source(self) -> m.SourceFile:
        return self.program.files[self.file_index]

    def print(self, source: m.SourceFile) -> str:
        if not self.written:
            return print_source(source)
        return format_source(source, self.written, list(self.comments))

    @cached_property
    def line_starts(self) -> list[int]:
        """Where each line of the file as written starts (and one past its end): a mutant's span in it."""
        starts = [0]
        for line in self.written.split("\n"):
            starts.append(starts[-1] + len(line) + 1)
        return starts

    @cached_property
    def original_text(self) -> str:
        """The domain's file printed (the file itself when `specc fmt` leaves it as it is)."""
        return self.print(self.source)

    @cached_property
    def original_planning(self) -> pm.PlanningDomain:
        return without_lines(domain_model(self.program, self.domain))

    def with_file(self, source: m.SourceFile) -> m.Program:
        files = list(self.program.files)
        files[self.file_index] = source
        return m.Program(files=tuple(files), span=self.program.span)


@dataclass(frozen=True)
class Mutant:
    """One mutant of the domain: the whole mutated file as the printer writes it (comments are not
    part of the model), and its unified diff against the original file printed the same way."""

    id: str  # "<domain>-0042": its rank in the enumeration, the same at every run
    kind: MutationClass
    description: str  # "model1.spec:34:12: numeric 2 -> 10 in MOVE" (where the original node is)
    path: str  # the mutated file, as spans name it
    text: str
    diff: str
    span: Span = field(compare=False)
    target: MutationTarget = field(compare=False, repr=False)


@dataclass(frozen=True)
class Rejection:
    mutant: Mutant
    reason: Reason
    detail: str  # the first error, the mutant it duplicates, ...


@dataclass(frozen=True)
class ClassCounts:
    generated: int = 0
    identical: int = 0
    duplicate: int = 0
    invalid: int = 0
    equivalent: int = 0
    kept: int = 0

    def __add__(self, other: ClassCounts) -> ClassCounts:
        return ClassCounts(*(getattr(self, f.name) + getattr(other, f.name) for f in fields(self)))


@dataclass(frozen=True)
class MutantSet:
    """Mutants sorted into the kept and the rejected, each rejection with its reason."""

    mutants: tuple[Mutant, ...]  # every one enumerated, in order
    kept: tuple[Mutant, ...]
    rejected: tuple[Rejection, ...]
    seconds: float  # time spent re-parsing, checking and lowering

    def counts(self) -> dict[MutationClass, ClassCounts]:
        """Per class, in CLASSES' order (a class with no mutant is left out)."""
        tally: dict[MutationClass, dict[str, int]] = {}
        for mutant in self.mutants:
            tally.setdefault(mutant.kind, {}).setdefault("generated", 0)
            tally[mutant.kind]["generated"] += 1
        for mutant in self.kept:
            tally[mutant.kind]["kept"] = tally[mutant.kind].get("kept", 0) + 1
        for rejection in self.rejected:
            row = tally[rejection.mutant.kind]
            row[rejection.reason] = row.get(rejection.reason, 0) + 1
        return {kind: ClassCounts(**tally[kind]) for kind in CLASSES if kind in tally}

    def total(self) -> ClassCounts:
        return sum(self.counts().values(), ClassCounts())

    def find(self, mutant_id: str) -> Mutant | None:
        return next((x for x in self.mutants if x.id == mutant_id), None)

    def rejection(self, mutant_id: str) -> Rejection | None:
        return next((r for r in self.rejected if r.mutant.id == mutant_id), None)

    def sample(self, n: int, seed: int = 0, *, stratified: bool = True) -> tuple[Mutant, ...]:
        """`n` kept mutants (all of them when fewer), drawn with `seed`, in id order.

        Stratified (the default): the classes share `n` as evenly as they can, a class with too
        few kept mutants giving its remainder to the others, so that the numerous numeric and
        variable mutants do not crowd out the few operator and deletion ones; each class's share
        is drawn uniformly within it. Not stratified: a uniform draw among all kept mutants."""
        if n >= len(self.kept):
            return self.kept
        if stratified:
            kept = {x.id for x in self.kept}
            return draw_kept(self.mutants, n, seed, lambda x: x.id in kept)
        chosen = random.Random(seed).sample(self.kept, n)
        order = {x.id: i for i, x in enumerate(self.kept)}
        return tuple(sorted(chosen, key=lambda x: order[x.id]))


def draw_kept(mutants: Sequence[Mutant], n: int, seed: int = 0,
              is_kept: Callable[[Mutant], bool] | None = None) -> tuple[Mutant, ...]:
    """`n` mutants that keep_valid would keep, drawn with `seed` and stratified by class, in id order.

    Each class's mutants are shuffled with the seed; the draw goes one mutant at a time to the
    class with the fewest drawn so far (the first in CLASSES' order on a tie), which gives its next
    kept mutant; a class with no kept mutant left drops out. `is_kept` judges a mutant (by default,
    keep_valid's filters on that mutant alone), so only the mutants drawn and those passed over on
    the way are checked: a sample of a few dozen costs seconds, not the minute of the whole set.
    MutantSet.sample draws the same mutants from a set already judged."""
    if is_kept is None:
        first_with_text: dict[str, str] = {}
        for x in mutants:
            first_with_text.setdefault(x.text, x.id)

        def is_kept(x: Mutant) -> bool:
            return (x.text != x.target.original_text and first_with_text[x.text] == x.id
                    and verdict(x.target, x.text) is None)

    draw = random.Random(seed)
    queues: dict[MutationClass, list[Mutant]] = {}
    for kind in CLASSES:
        group = [x for x in mutants if x.kind == kind]
        draw.shuffle(group)
        if group:
            queues[kind] = group[::-1]  # popped from the end
    drawn: dict[MutationClass, list[Mutant]] = {kind: [] for kind in queues}
    while sum(len(group) for group in drawn.values()) < n and queues:
        kind = min(queues, key=lambda k: (len(drawn[k]), CLASSES.index(k)))
        queue = queues[kind]
        while queue:
            candidate = queue.pop()
            if is_kept(candidate):
                drawn[kind].append(candidate)
                break
        if not queue:
            del queues[kind]
    order = {x.id: i for i, x in enumerate(mutants)}
    return tuple(sorted((x for group in drawn.values() for x in group), key=lambda x: order[x.id]))


# ---------------------------------------------------------------- enumeration


def mutation_target(robot: Robot, domain: str | None = None, base_dirs: dict[str, Path] | None = None
                    ) -> MutationTarget:
    """The domain `domain` of the robot (default: the one its FTplan block's first planner plans
    in, else its only domain): spec files or folders (loaded and checked), a `Loaded`, or a
    `Program` (its files found again from the paths its spans name, for the codel checks, unless
    `base_dirs` says where each file is)."""
    sources: dict[str, str] = {}
    comments: dict[str, list[Comment]] = {}
    if isinstance(robot, m.Program):
        program = robot
        dirs = base_dirs if base_dirs is not None else {
            f.path: Path(f.path).resolve().parent for f in program.files if Path(f.path).exists()}
        errors = [d for d in check_program(program, dirs) if d.severity == "error"]
    else:
        loaded = robot if isinstance(robot, Loaded) else load([robot] if isinstance(robot, Path) else list(robot))
        errors = loaded.errors
        if loaded.program is None:
            raise MutationError(_first_error(errors) if errors else "no spec files")
        program = loaded.program
        dirs = {shown: path.resolve().parent for shown, path in loaded.paths.items()}
        sources, comments = loaded.sources, loaded.comments
    if errors:
        raise MutationError(f"{_first_error(errors)}; the specs must check clean to be mutated")
    domain = domain if domain is not None else default_domain(program)
    for file_index, source in enumerate(program.files):
        for item_index, item in enumerate(source.items):
            if isinstance(item, m.Domain) and item.name == domain:
                if source.path not in sources:
                    sources, comments = _written(source)
                return MutationTarget(program, item, file_index, item_index, dirs, sources.get(source.path, ""),
                                      tuple(comments.get(source.path, ())))
    known = sorted(i.name for i in program.items if isinstance(i, m.Domain))
    raise MutationError(f"no domain '{domain}' in these specs (domains: {', '.join(known) or 'none'})")


def default_domain(program: m.Program) -> str:
    """The domain the first planner of the robot's FTplan block plans in, else its only domain."""
    planners = [p for item in program.items if isinstance(item, m.FtPlan) for p in item.planners
                if p.domain is not None]
    if planners:
        return planners[0].domain.text  # type: ignore[union-attr]
    domains = sorted(i.name for i in program.items if isinstance(i, m.Domain))
    if not domains:
        raise MutationError("these specs have no planning domain: mutants are made of an IxTeT domain (seed 004 "
                            "§4.1.3's mutation of the planner's model), so there is nothing to mutate")
    if len(domains) != 1:
        raise MutationError(f"name the domain to mutate with --domain (domains: {', '.join(domains)})")
    return domains[0]


def _written(source: m.SourceFile) -> tuple[dict[str, str], dict[str, list[Comment]]]:
    """The text and comments of a Program's file, read again from the path its spans name when
    that file still holds the same model (so mutants keep their comments whichever way the robot
    was given); nothing otherwise."""
    try:
        text = Path(source.path).read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError):
        return {}, {}
    parsed = parse_text(text, source.path)
    if parsed.source != source:
        return {}, {}
    return {source.path: text}, {source.path: parsed.comments}


def _first_error(errors: list[Diagnostic]) -> str:
    """The first error on one line, without its severity (a MutationError is one already)."""
    first = errors[0]
    more = f" (and {len(errors) - 1} more: run specc check)" if len(errors) > 1 else ""
    return f"{first.span}: {first.message} [{first.code}]{more}"


def enumerate_mutants(robot: Robot | MutationTarget, domain: str | None = None, *,
                      classes: Iterable[str] | None = None, random_values: int = 3,
                      seed: int = 0) -> list[Mutant]:
    """Every mutant of the domain, in a deterministic order (class by class, then in source
    order), each with a stable id `<domain>-NNNN`. Ids are given over all five classes before
    `classes` keeps some, so a mutant has the same id whichever classes are asked for;
    `random_values` and `seed` choose the drawn values of the numeric class (and so the ids)."""
    target = robot if isinstance(robot, MutationTarget) else mutation_target(robot, domain)
    wanted = set(CLASSES if classes is None else classes)
    unknown = wanted - set(CLASSES)
    if unknown:
        raise MutationError(f"unknown mutation class(es) {', '.join(sorted(unknown))} "
                            f"(classes: {', '.join(CLASSES)})")
    edits = domain_edits(target.program, target.file_index, target.item_index, random_values=random_values,
                         seed=seed)
    if not edits:
        included = [member.name for member in target.domain.members if isinstance(member, m.Include)]
        where = (f": its members are in the fragments it includes ({', '.join(included)}), which are never "
                 "mutated since the problems include them too; write the tasks in the domain block itself to "
                 "mutate them") if included else ""
        raise MutationError(f"domain '{target.domain.name}' has nothing of its own to mutate{where}")
    width = max(4, len(str(len(edits))))
    return [mutant(target, edit, f"{target.domain.name}-{rank:0{width}d}")
            for rank, edit in enumerate(edits, start=1) if edit.kind in wanted]


def mutant(target: MutationTarget, edit: Edit, mutant_id: str) -> Mutant:
    source = replace_at(target.source, edit.path, edit.new)
    text = target.print(source)
    path = target.source.path
    # The diff against the file as its author wrote it (its own lines and layout, a patch that
    # applies to it), when the edit can be written into it in place; else against the file as
    # `specc fmt` prints it, said so.
    written = _written_in_place(target, edit)
    before, after, label = ((target.written, written, "original") if written is not None
                            else (target.original_text, text, "original, as specc fmt prints it"))
    diff = "".join(difflib.unified_diff(before.splitlines(keepends=True), after.splitlines(keepends=True),
                                        f"{path} ({label})", f"{path} ({mutant_id})"))
    return Mutant(mutant_id, edit.kind, edit.describe(), path, text, diff, edit.span, target)


def _node_text(node: m.Node) -> str | None:
    """How the printer writes a mutated node alone (None for one it writes only within its block)."""
    try:
        if isinstance(node, m.Interval):
            return domain_value(node)
        if isinstance(node, (m.Number, m.Infinity, m.IxVar, m.IxName, m.IxCall, m.IxUnary, m.IxBinary)):
            return ixexpr(node)
        return tstmt(node)
    except TypeError:
        return None


def _written_in_place(target: MutationTarget, edit: Edit) -> str | None:
    """The file as written with the edit made where its node is written: the new node's text in
    place of the old one's, or the old one's lines removed. None when the text there is not the
    old node's as the printer writes it, spaces aside (a comment inside it), or the node is one
    the printer writes only within its block."""
    written, span = target.written, edit.span
    if not written or span.file != target.source.path:
        return None
    old = _node_text(node_at(target.source, edit.path))
    new = _node_text(edit.new) if edit.new is not None else ""
    if old is None or new is None:
        return None
    starts = target.line_starts
    if span.end_line >= len(starts):
        return None
    start, end = starts[span.line - 1] + span.column - 1, starts[span.end_line - 1] + span.end_column - 1
    there = written[start:end]
    if "".join(there.split()).rstrip(";") != "".join(old.split()).rstrip(";"):
        return None
    if edit.new is None:  # the statement's lines go when it is all they hold
        line_start, line_end = written.rfind("\n", 0, start) + 1, written.find("\n", end)
        line_end = len(written) if line_end < 0 else line_end
        rest = written[end:line_end].strip()
        after = rest.removeprefix(";").strip()
        # Alone on its line, with or without a comment of its own after it: the line goes.
        if not written[line_start:start].strip() and (not after or after.startswith("//")):
            return written[:line_start] + written[line_end + 1:]
        return written[:start] + written[end + (1 if rest.startswith(";") else 0):]
    return written[:start] + (new if there.endswith(";") else new.rstrip(";")) + written[end:]


# ---------------------------------------------------------------- filtering


def keep_valid(mutants: Sequence[Mutant], *, workers: int = 1,
               progress: Callable[[int, int], None] | None = None) -> MutantSet:
    """Sort mutants (all of one target) into the kept and the rejected:

    - identical: printed exactly as the original file;
    - duplicate: printed as an earlier mutant (an interval opened to +oo and the bound replaced
      by +oo are one mutant);
    - invalid: the printed text, with the robot's other spec files, does not parse or does not
      pass `specc check` (warnings allowed);
    - equivalent: the planner's domain it lowers to is the original's (source lines aside).

    `workers` > 1 checks in that many processes (the check dominates: ~50 ms per mutant of
    Modele1, with the rover's 19 files); `progress(done, total)` is called as checks finish."""
    started = time.perf_counter()
    rejected: dict[str, Rejection] = {}
    first_with_text: dict[str, str] = {}
    to_check: list[Mutant] = []
    for x in mutants:
        if x.text == x.target.original_text:
            rejected[x.id] = Rejection(x, "identical", "prints as the original")
        elif x.text in first_with_text:
            rejected[x.id] = Rejection(x, "duplicate", f"same text as {first_with_text[x.text]}")
        else:
            first_with_text[x.text] = x.id
            to_check.append(x)
    verdicts = _check_all(to_check, workers, progress)
    for x, verdict in zip(to_check, verdicts, strict=True):
        if verdict is not None:
            rejected[x.id] = Rejection(x, verdict[0], verdict[1])
    kept = tuple(x for x in mutants if x.id not in rejected)
    ordered = tuple(rejected[x.id] for x in mutants if x.id in rejected)
    return MutantSet(tuple(mutants), kept, ordered, time.perf_counter() - started)


def _check_all(mutants: list[Mutant], workers: int, progress: Callable[[int, int], None] | None
               ) -> list[tuple[Reason, str] | None]:
    if not mutants:
        return []
    targets = {id(x.target) for x in mutants}
    if len(targets) > 1:
        raise ValueError("keep_valid takes the mutants of one domain at a time")
    target = mutants[0].target
    verdicts: list[tuple[Reason, str] | None] = []
    if workers <= 1:
        for done, x in enumerate(mutants, start=1):
            verdicts.append(verdict(target, x.text))
            if progress is not None:
                progress(done, len(mutants))
        return verdicts
    # Each process receives the target once (the robot's model, pickled), then only texts.
    with ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context(START_METHOD),
                             initializer=_adopt, initargs=(target,)) as pool:
        chunk = max(1, min(32, len(mutants) // (4 * workers)))
        for done, answer in enumerate(pool.map(_verdict_here, [x.text for x in mutants], chunksize=chunk),
                                      start=1):
            verdicts.append(answer)
            if progress is not None:
                progress(done, len(mutants))
    return verdicts


_WORKER_TARGET: MutationTarget | None = None


def _adopt(target: MutationTarget) -> None:
    global _WORKER_TARGET
    _WORKER_TARGET = target


def _verdict_here(text: str) -> tuple[Reason, str] | None:
    assert _WORKER_TARGET is not None
    return verdict(_WORKER_TARGET, text)


def verdict(target: MutationTarget, text: str) -> tuple[Reason, str] | None:
    """Why the mutated file `text` is rejected (invalid or equivalent), or None to keep it."""
    try:
        lowered = lowered_domain(target, text)
    except MutationError as error:
        return "invalid", str(error)
    if without_lines(lowered) == target.original_planning:
        return "equivalent", "lowers to the original planning domain"
    return None


@functools.lru_cache(maxsize=1024)
def lowered_domain(target: MutationTarget, text: str) -> pm.PlanningDomain:
    """The planner's domain of the robot with `text` in place of the domain's file, lowered as
    `specc compile` lowers it; MutationError (the first error `specc check` finds, or why the
    planner cannot take it) otherwise. Cached: a campaign lowers the mutants its draw judged."""
    program, errors = mutated_program(target, text)
    if errors or program is None:
        raise MutationError(_first_error(errors))
    try:
        return domain_model(program, _domain_of(program, target))
    except PlanningError as exc:  # checked specs the planner cannot take: a bug the mutant found
        raise MutationError(f"checked, but the planner's domain cannot be built: {exc}") from None


def mutated_program(target: MutationTarget, text: str) -> tuple[m.Program | None, list[Diagnostic]]:
    """The robot with `text` in place of the domain's file, and the errors `specc check` finds."""
    parsed = parse_text(text, target.source.path)
    if parsed.source is None or any(d.severity == "error" for d in parsed.diagnostics):
        return None, [d for d in parsed.diagnostics if d.severity == "error"]
    program = target.with_file(parsed.source)
    return program, [d for d in check_program(program, target.base_dirs) if d.severity == "error"]


def _domain_of(program: m.Program, target: MutationTarget) -> m.Domain:
    item = program.files[target.file_index].items[target.item_index]
    assert isinstance(item, m.Domain) and item.name == target.domain.name
    return item


def without_lines(value: Any) -> Any:
    """`value` with every `line` field of the planner's records set to 0 and the source cleared:
    a deletion moves the lines after it, which says nothing about what the domain means."""
    if isinstance(value, tuple):
        return tuple(without_lines(v) for v in value)
    if not is_dataclass(value) or isinstance(value, type):
        return value
    changes = {f.name: without_lines(getattr(value, f.name)) for f in fields(value)}
    if "line" in changes:
        changes["line"] = 0
    if isinstance(value, pm.PlanningDomain):
        changes["source"] = ""
    return replace(value, **changes)


# ---------------------------------------------------------------- campaigns


def find_mutant(robot: Robot, mutant_id: str) -> tuple[Mutant, Rejection | None]:
    """The mutant `mutant_id` (`<domain>-NNNN`, as `specc mutants` and a campaign name it) of the
    robot, and why keep_valid sets it aside if it does (identical, a duplicate, equivalent: it
    runs as the original or another mutant); MutationError when there is none, or it does not
    pass `specc check` (a campaign never runs those)."""
    domain = mutant_id.rpartition("-")[0]
    mutants = enumerate_mutants(robot, domain)
    found = next((x for x in mutants if x.id == mutant_id), None)
    if found is None:
        raise MutationError(f"no such mutant (the mutants of '{domain}' are {mutants[0].id} to "
                            f"{mutants[-1].id}: `specc mutants` lists them)")
    rejected = keep_valid([found]).rejected
    if rejected and rejected[0].reason == "invalid":
        raise MutationError(f"mutant {mutant_id} does not pass specc check ({rejected[0].detail}): a campaign "
                            "never runs it")
    return found, rejected[0] if rejected else None


def mutant_domain(mutant: Mutant) -> pm.PlanningDomain:
    """The planner's domain (what `specc compile` generates as `<robot>.planner.<domain>.DOMAIN`)
    of a mutant: plan with `Planner(mutant_domain(x)).plan(problem)`, the problems unchanged."""
    try:
        return lowered_domain(mutant.target, mutant.text)
    except MutationError as error:
        raise MutationError(f"mutant {mutant.id}: {error}") from None


def default_workers() -> int:
    return max(1, min(8, os.cpu_count() or 1))
