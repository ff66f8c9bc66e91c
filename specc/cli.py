"""The `specc` command line."""

from __future__ import annotations

import gc
import math
import os
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Optional

import typer
from rich.console import Console

from specc.check.symbols import symbols_of
from specc.diagnostics import did_you_mean, error, render
from specc.files import write_text_atomically
from specc.model import nodes as m
from specc.model.span import Span
from specc.pipeline import Loaded, load

if TYPE_CHECKING:
    from specc.analysis.prs_net import Translation
    from specc.campaign.report import CampaignReport

app = typer.Typer(
    name="specc",
    help="Compile robot control-architecture specs (modules, executive, rules, procedures, "
         "planning) into a Python package.\n\nExample: specc check examples/tug",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)
# A command that judges something other than the specs (verify, graph, plan, export, run, table,
# campaign...) exits 2 when it cannot do what is asked (a bad option, specs with errors, an unknown
# name, a file it cannot write), so that a script tells that apart from its negative verdict (1: a
# property refuted, no plan, a mission failed). check, fmt, compile, rules and skeleton judge the
# specs: their errors are that verdict (1). docs/reference.md, "Exit codes".
BAD_INPUT = 2
MOST_WORKERS = 256  # processes: more than any machine runs usefully (a larger count overflows a semaphore)
MOST_PARTIAL_PLANS = 10_000_000  # a search budget past which a planning takes hours, not an answer
CANNOT_VERIFY = BAD_INPUT
err = Console(stderr=True, highlight=False, soft_wrap=True, emoji=False)  # `:100:` is a line number
out = Console(highlight=False, soft_wrap=True, emoji=False)

# readable=False: an unreadable spec is reported gcc-style by the pipeline, not by click's usage error.
PathsArg = Annotated[list[Path], typer.Argument(help="Spec files, or folders searched for *.spec files.",
                                                show_default=False, readable=False)]


def finite(value: float | None) -> float | None:
    """A float option's check: `nan` passes a `min=` and `inf` reads as a number; neither is one."""
    if value is not None and not math.isfinite(value):
        raise typer.BadParameter(f"{value} is not a finite number of seconds")
    return value


def a_folder(value: Path | None) -> Path | None:
    """A folder option's check: '-' is the standard output elsewhere, and no folder here."""
    if value is not None and str(value) == "-":
        raise typer.BadParameter("'-' names no folder (the standard output is not one): give a folder, e.g. build/out")
    return value


def runs_folder(value: Path) -> Path:
    """`--runs` of `run` and `table` is a folder: a bare number that names none yet is a count
    meant for another option (`specc campaign --runs 3`), which would make a folder '3'."""
    value = a_folder(value) or value
    if str(value).isdigit() and not value.exists():
        raise typer.BadParameter(f"'{value}' would be a new folder named {value}: --runs is where the run folders "
                                 f"go (for {value} seeds of every combination: `specc table --seeds {value}`; a "
                                 "folder named by digits: give its absolute path)")
    return value


def refuse_unwritable(path: Path | None, what: str, option: str, example: str, picture: bool = False) -> None:
    """Exit at once, before any planning or drawing, when the file `path` cannot be written
    (`specc.run.writable_file`; '-' is the standard output)."""
    if path is None:
        return
    if str(path) == "-":
        if picture:
            err.print(f"error: {option} -: a picture cannot go to the standard output; give a file name, e.g. "
                      f"{option} {example}", markup=False)
            raise typer.Exit(BAD_INPUT)
        return
    from specc.run import RunError, writable_file

    try:
        writable_file(path, option, "a file name", f"the folder of {what}", example, picture)
    except RunError as error:
        err.print(f"error: {error}", markup=False)
        raise typer.Exit(BAD_INPUT) from None


# Errors of the command line's paths, not of the specs: the command could not do its work (exit 2).
INPUT_CODES = frozenset({"missing-file", "no-spec-files", "unreadable-file", "unreadable-folder"})


def report(loaded: Loaded) -> int:
    """Print every diagnostic; the exit code: 2 when a path given is missing or holds no spec, 1
    when any diagnostic is an error, else 0."""
    for diagnostic in loaded.diagnostics:
        err.print(render(diagnostic, loaded.sources), markup=False)
    errors = len(loaded.errors)
    warnings = len(loaded.diagnostics) - errors
    if errors or warnings:
        err.print(f"{errors} error(s), {warnings} warning(s)", markup=False)
    return exit_code(loaded)


def exit_code(loaded: Loaded) -> int:
    return 2 if any(d.code in INPUT_CODES for d in loaded.errors) else 1 if loaded.errors else 0


@app.command()
def explain(code: Annotated[Optional[str], typer.Argument(help="A diagnostic's code, as it ends a message "
                                                               "([unknown-unit]); none: every code.",
                                                          show_default=False)] = None) -> None:
    """Say what a diagnostic code means, with an example of a spec line that gets it.

    Example: specc explain missing-semicolon
    """
    from specc.codes import CODES, FIXES

    shown = code.strip("[]") if code is not None else None
    if shown is not None and shown not in CODES:
        err.print(f"error: no diagnostic code '{shown}'{did_you_mean(shown, CODES)}; `specc explain` lists them all",
                  markup=False)
        raise typer.Exit(2)
    for name in [shown] if shown is not None else sorted(CODES):
        entry = CODES[name]
        out.print(f"{name}: {entry.summary}\n    e.g. {entry.example}\n    fix: {FIXES[name]}", markup=False)


@app.command()
def check(paths: PathsArg,
          quiet: Annotated[bool, typer.Option("--quiet", "-q", help="Print nothing when all is well.")] = False,
          strict: Annotated[bool, typer.Option(help="Exit 1 on warnings too (for CI).")] = False,
          json_output: Annotated[bool, typer.Option("--json", help="Print the diagnostics as one JSON document "
                                                    "on the standard output (format: docs/reference.md).")] = False,
          ) -> None:
    """Parse and check specs; report every problem at once. Exit 1 when there is an error (with
    --strict, any diagnostic).

    Example: specc check examples/tug examples/generic/diagnosis.spec
    """
    started = time.perf_counter()
    loaded = load(paths)
    if json_output:
        import json

        errors = len(loaded.errors)
        document = {"format": "specc-diagnostics/1", "files": sorted(loaded.sources), "errors": errors,
                    "warnings": len(loaded.diagnostics) - errors,
                    "diagnostics": [d.as_data() for d in loaded.diagnostics]}
        sys.stdout.write(json.dumps(document, indent=2) + "\n")
        raise typer.Exit(exit_code(loaded) or (1 if strict and loaded.diagnostics else 0))
    code = report(loaded)
    if strict and loaded.diagnostics:
        raise typer.Exit(code or 1)
    if code == 0 and not quiet:
        count = len(loaded.sources)
        items = len(loaded.program.items) if loaded.program else 0
        out.print(f"ok: {count} file(s), {items} block(s) checked in "
                  f"{(time.perf_counter() - started) * 1000:.0f} ms", markup=False)
    raise typer.Exit(code)


@app.command()
def compile(paths: PathsArg,
            output: Annotated[Path, typer.Option("--output", "-o", callback=a_folder,
                                                 help="Folder receiving the robot package.")]
            = Path("generated"),
            robot: Annotated[Optional[str], typer.Option(help="Package name (default: the system block's name).")]
            = None) -> None:
    """Check specs, then write the robot's Python package into OUTPUT/<robot>/.

    Example: specc compile examples/tug -o generated
    """
    from specc.analysis.kheops import KheopsError
    from specc.backends import generate_all, package  # jinja2 and the back ends load only when compiling

    loaded = load(paths)
    code = report(loaded)
    if code or loaded.program is None:
        raise typer.Exit(code or 1)
    try:
        name = package.package_name(loaded.program, paths[0], robot)
    except ValueError as exc:
        err.print(f"error: {exc}", markup=False)
        raise typer.Exit(1) from None
    try:
        result = generate_all(loaded.program, name)
    except KheopsError as exc:
        err.print(exc.headline(), markup=False)
        raise typer.Exit(1) from None
    folder = output / name
    try:
        written = result.write(folder)
    except OSError as exc:
        problem = error("unwritable-output", f"cannot write the package into '{folder}': {exc.strerror}"
                        + (f" ('{exc.filename}')" if exc.filename else ""), Span.unknown(str(folder)))
        err.print(render(problem, {}), markup=False)
        raise typer.Exit(1) from None
    for warning in result.warnings:
        err.print(render(warning, loaded.sources), markup=False)
    if len(paths) == 1 and robot is None:  # what `specc run` would compile: it need not do it again
        from specc.run.package import remember_compilation

        remember_compilation(paths[0], output, name, result.files,
                             [d.headline() for d in [*loaded.diagnostics, *result.warnings] if d.severity == "warning"])
    out.print(f"wrote {len(written)} file(s) to {folder}", markup=False)


@app.command()
def fmt(paths: PathsArg,
        check_only: Annotated[bool, typer.Option(
            "--check", help="Change nothing; name each file that would change and exit 1 (--diff shows the changes).")]
        = False,
        diff: Annotated[bool, typer.Option("--diff", help="Show what would change, and change nothing.")]
        = False) -> None:
    """Rewrite specs in canonical form, keeping comments.

    Example: specc fmt --check examples/
    """
    import difflib

    write = not (check_only or diff)

    from specc.syntax.printer import format_source

    loaded = load(paths, check=False)
    code = report(loaded)
    if code or loaded.program is None:
        raise typer.Exit(code or 1)
    changed = []
    unwritable = []
    for source in loaded.program.files:
        text = loaded.sources[source.path]
        formatted = format_source(source, text, loaded.comments[source.path])
        if formatted == text:
            continue
        changed.append(source.path)
        if diff:  # --check alone names the files: --diff shows the changes
            sys.stdout.writelines(difflib.unified_diff(
                text.splitlines(keepends=True), formatted.splitlines(keepends=True),
                f"{source.path} (now)", f"{source.path} (formatted)"))
        if write:
            try:
                write_text_atomically(loaded.paths[source.path], formatted)  # never a half-written spec
            except OSError as exc:
                changed.pop()
                unwritable.append(error("unwritable-file", f"cannot rewrite '{source.path}': {exc.strerror}",
                                        Span.unknown(source.path)))
    verb = "reformatted" if write else "would reformat"
    for path in changed:  # after a --diff, on stderr: the standard output is then the patch alone
        (err if diff else out).print(f"{verb} {path}", markup=False)
    for problem in unwritable:
        err.print(render(problem, {}), markup=False)
    if not changed and not unwritable:
        out.print(f"{len(loaded.program.files)} file(s) already formatted", markup=False)
    raise typer.Exit(1 if unwritable or (check_only and changed) else 0)


@app.command()
def graph(paths: PathsArg,
          incompat: Annotated[bool, typer.Option("--incompat", help="Draw the executive's service "
                                                 "incompatibility graph and its groups.")] = False,
          net: Annotated[bool, typer.Option("--net", help="Draw the coloured Petri net the procedures a --goal "
                                            "reaches translate into (seed 000 §4.4).")] = False,
          output: Annotated[Optional[Path], typer.Option("--output", "-o", help="Picture file (PNG, SVG, PDF); "
                                                         "incompat.png or net.png by default.")] = None,
          executive: Annotated[Optional[str], typer.Option(help="Which executive, when there are several.")]
          = None,
          goal: Annotated[Optional[list[str]], typer.Option(help="With --net: the goal posted (repeatable).")]
          = None,
          ka: Annotated[Optional[str], typer.Option(help="With --net: draw only this KA's places.")] = None,
          procedures: Annotated[Optional[str], typer.Option(help="Which procedures, when there are several.")]
          = None) -> None:
    """Draw a picture of the spec: the service incompatibility graph (and print the service
    groups and the controller's state count), or the Petri net of the procedures.

    Example: specc graph --incompat examples/tug -o tug-incompat.png

    Example: specc graph --net <robot folder> --goal '!(<GOAL> <args>)' --ka <KA> -o net.png (the
    procedures' variables need finite domains, as for specc verify --goal; docs/language.md has one to
    run as it is)
    """
    from specc.analysis.incompat import build_graph, service_groups, state_count
    from specc.pictures import draw_incompatibility_graph

    if incompat == net:
        err.print("error: say what to draw: --incompat or --net", markup=False)
        raise typer.Exit(CANNOT_VERIFY)
    refuse_unwritable(output, "the picture", "-o", "net.png" if net else "incompat.png", picture=True)
    loaded = load(paths)
    if report(loaded) or loaded.program is None:
        raise typer.Exit(CANNOT_VERIFY)
    if net:
        draw_procedures_net(loaded, procedures, goal or [], ka, output or Path("net.png"))
        return
    output = output or Path("incompat.png")
    chosen = choose_executive(loaded.program, executive)
    incompatibility = build_graph(loaded.program, chosen)
    groups = service_groups(incompatibility)
    for group in groups:
        out.print(f"group {group.name}: {' | '.join(group.states)}", markup=False)
    out.print(f"{len(groups)} group(s), {state_count(groups)} resource-controller states", markup=False)
    try:
        picture = draw_incompatibility_graph(incompatibility, output, f"executive {chosen.name}")
    except (OSError, ValueError) as exc:
        err.print(f"error: cannot write '{output}': {exc}", markup=False)
        raise typer.Exit(CANNOT_VERIFY) from None
    out.print(f"wrote {picture}", markup=False)




def choose_executive(program: m.Program, name: str | None) -> m.Executive:
    """The executive the user means: the only one, or the one named by --executive."""
    executives: Mapping[str, m.Executive] = symbols_of(program).blocks[m.Executive]
    if not executives:
        err.print("error: no executive block in these specs", markup=False)
        raise typer.Exit(CANNOT_VERIFY)
    if name is None and len(executives) > 1:
        err.print(f"error: several executives ({', '.join(sorted(executives))}); pick one with --executive",
                  markup=False)
        raise typer.Exit(CANNOT_VERIFY)
    chosen = executives.get(name) if name else next(iter(executives.values()))
    if chosen is None:
        err.print(f"error: no executive '{name}' (there are: {', '.join(sorted(executives))})", markup=False)
        raise typer.Exit(CANNOT_VERIFY)
    return chosen


@app.command()
def verify(paths: PathsArg,
           executive: Annotated[Optional[str], typer.Option(help="Which executive, when there are several.")]
           = None,
           requests: Annotated[int, typer.Option(min=1, help="Requests the task level may have outstanding "
                                                 "at once (the bound of the exploration).")] = 2,
           max_states: Annotated[int, typer.Option(min=1, help="Stop after this many states (the executive's "
                                                   "properties then hold only in the states explored: exit 1).")]
           = 500_000,
           goal: Annotated[Optional[list[str]], typer.Option(
               help="Verify the procedures instead: the goal posted, e.g. '!(COLLECT-OBJECTS 2)' (repeatable).")]
           = None,
           fact: Annotated[Optional[list[str]], typer.Option(help="A fact the database starts with (repeatable).")]
           = None,
           fail: Annotated[Optional[list[str]], typer.Option(
               help="A service whose answer may be a failure (repeatable; 'all' for every one); by default "
                    "services succeed (§4.5: first the intrinsic correctness).")] = None,
           reach: Annotated[Optional[list[str]], typer.Option(
               help="Can these hold together? 'KA:LINE [?(condition)]; KA:LINE ...' (repeatable).")] = None,
           procedures: Annotated[Optional[str], typer.Option(help="Which procedures, when there are several.")]
           = None,
           pnml: Annotated[Optional[Path], typer.Option(help="Also write the net explored (reduced: its state count "
                                                            "is the one printed) as ISO 15909 PNML.")] = None,
           pnml_full: Annotated[Optional[Path], typer.Option(help="Also write the full unfolded net as PNML (more "
                                                                 "states than the reduced one).")] = None,
           strict: Annotated[bool, typer.Option(help="Exit 1 when there is any finding.")] = False,
           steps: Annotated[int, typer.Option(min=1, help="Trace steps shown per finding (the last ones).")] = 12,
           ) -> None:
    """Explore every state the executive can reach and prove or refute, with a shortest
    counterexample: exclusion of incompatible services, exactly one final reply per request,
    no starvation in WAIT without a start timeout, no general ERROR state.

    With --goal, verify the procedures instead (seed 000 §4.4-4.5): the KAs the goal reaches are
    translated into a coloured Petri net whose whole state space is explored; deadlocks,
    unbounded places, statements that never run or never succeed, endless cycles and --reach
    queries are reported with the firing sequence that shows them, in KA lines.

    Exit status for the executive: 0 when every property holds in every state, 1 when one is
    refuted or --max-states stopped the exploration; for the procedures: 0, or 1 with --strict
    when there is a finding; 2 when nothing could be verified (a bad option, specs with errors,
    procedures no net can stand for).

    Example: specc verify examples/generic --executive generic

    Example: specc verify examples/tug --requests 2
    """
    if goal:
        verify_procedures(paths, goal, fact or [], fail or [], reach or [], procedures, max_states, pnml, pnml_full,
                          strict, steps)
        return
    only_with_goal = [name for name, given in (("--fact", fact), ("--fail", fail), ("--reach", reach),
                                               ("--procedures", procedures), ("--pnml", pnml),
                                               ("--pnml-full", pnml_full)) if given]
    if only_with_goal:
        err.print(f"error: {', '.join(only_with_goal)}: for verifying procedures only; add --goal '!(GOAL ...)' "
                  "(the goal posted), or leave out what verifies procedures to verify the executive", markup=False)
        raise typer.Exit(CANNOT_VERIFY)
    from rich.status import Status

    from specc.analysis import kheops
    from specc.analysis.verify import describe
    from specc.analysis.verify import verify as explore

    loaded = load(paths)
    if report(loaded) or loaded.program is None:
        raise typer.Exit(CANNOT_VERIFY)
    chosen = choose_executive(loaded.program, executive)
    started = time.perf_counter()
    heartbeat = Heartbeat()  # in a log, where the status line does not show

    def progress(states: int) -> None:
        status.update(f"exploring: {states} states")
        if not err.is_terminal:
            heartbeat(f"exploring: {states:,} states")

    with Status("compiling the controller", console=err) as status:
        try:
            result = explore(loaded.program, chosen, requests, max_states, progress)
        except kheops.KheopsError as exc:
            err.print(exc.headline(), markup=False)
            raise typer.Exit(CANNOT_VERIFY) from None
    for line in describe(result):
        out.print(line, markup=False)
    unfollowed = sorted({d.code for d in loaded.diagnostics if d.code in ("undeclared-send", "computed-send")})
    if unfollowed:
        # What holds was proved of the codels as `sends:` declares them: the warnings above say
        # that some send what it does not declare (or a name computed at run time).
        out.print(f"assumed: the codels send only what their requests' `sends:` declare, which the warnings above "
                  f"({', '.join(unfollowed)}) say they do not: what holds is proved of the declared sends only; "
                  "declare every request a codel sends", markup=False)
    out.print(f"{result.states} states, {result.transitions} transitions, at most {requests} outstanding "
              f"request(s), in {time.perf_counter() - started:.1f} s", markup=False)
    if result.limited:
        err.print(f"warning: stopped at {max_states} states; raise --max-states to explore them all", markup=False)
    raise typer.Exit(0 if result.ok else 1)


def draw_procedures_net(loaded: Loaded, name: str | None, goals: list[str], ka: str | None, output: Path) -> None:
    from specc.pictures import draw_net

    if not goals:
        err.print("error: say which goal is posted: --goal '!(GOAL ...)' (the net holds the KAs it reaches)",
                  markup=False)
        raise typer.Exit(CANNOT_VERIFY)
    translation = translate_procedures(loaded, name, goals, [], [])
    if ka is not None and ka not in translation.kas:
        err.print(f"error: KA '{ka}' is not among the KAs the goal reaches: {', '.join(translation.kas)}",
                  markup=False)
        raise typer.Exit(CANNOT_VERIFY)
    only = None if ka is None else (lambda place: place.startswith(f"{ka}."))
    title = f"procedures {translation.net.name}" + (f": KA {ka}" if ka else "")
    try:
        picture = draw_net(translation.net, output, title, translation.where, only=only)
    except (OSError, ValueError) as exc:
        err.print(f"error: cannot draw '{output}': {exc}", markup=False)
        raise typer.Exit(CANNOT_VERIFY) from None
    out.print(f"wrote {picture}", markup=False)


def translate_procedures(loaded: Loaded, name: str | None, goals: list[str], facts: list[str],
                         failing: list[str]) -> Translation:
    """The Petri net of the procedures the user means, for the goals posted; errors end the command."""
    from specc.analysis.prs_net import TranslationError
    from specc.analysis.prs_verify import translate
    from specc.runtime import procedures as rp

    assert loaded.program is not None
    blocks: Mapping[str, m.Procedures] = symbols_of(loaded.program).blocks[m.Procedures]
    try:
        posted = [rp.parse_goal(g) for g in goals]
        initial = [rp.parse_fact(f) for f in facts]
    except ValueError as exc:
        err.print(f"error: {exc}", markup=False)
        raise typer.Exit(CANNOT_VERIFY) from None
    candidates = list(blocks.values())
    if name is None and len(candidates) > 1:  # the blocks whose KAs achieve every goal posted
        heads = {g.expr.head for g in posted}
        candidates = [b for b in candidates
                      if heads <= {ka.invocation.body.head for ka in b.kas if isinstance(ka.invocation, m.Goal)}]
    chosen = blocks.get(name) if name else candidates[0] if len(candidates) == 1 else None
    if chosen is None:
        what = f"no procedures '{name}'{did_you_mean(name, blocks)}" if name else \
            "no procedures block" if not blocks else \
            f"several procedures ({', '.join(sorted(blocks))}) achieve the goal, or none does; pick one with " \
            "--procedures"
        err.print(f"error: {what}", markup=False)
        raise typer.Exit(CANNOT_VERIFY)
    try:
        return translate(loaded.program, chosen, posted, initial, ["*" if f == "all" else f for f in failing])
    except ValueError as exc:
        err.print(f"error: {exc}", markup=False)
        raise typer.Exit(CANNOT_VERIFY) from None
    except TranslationError as exc:
        for diagnostic in exc.diagnostics:
            err.print(render(diagnostic, loaded.sources), markup=False)
        raise typer.Exit(CANNOT_VERIFY) from None


def verify_procedures(paths: list[Path], goals: list[str], facts: list[str], failing: list[str], reach: list[str],
                      name: str | None, max_states: int, pnml: Path | None, pnml_full: Path | None, strict: bool,
                      steps: int) -> None:
    from rich.status import Status

    from specc.analysis import petri
    from specc.analysis.prs_verify import analyse, parse_query

    loaded = load(paths)
    if report(loaded) or loaded.program is None:
        raise typer.Exit(CANNOT_VERIFY)
    try:
        queries = [parse_query(q) for q in reach]
    except ValueError as exc:
        err.print(f"error: {exc}", markup=False)
        raise typer.Exit(CANNOT_VERIFY) from None
    started = time.perf_counter()
    translation = translate_procedures(loaded, name, goals, facts, failing)
    net = translation.net
    full = net.unfold()
    out.print(f"net of {', '.join(translation.kas)}: {len(net.places)} places, {len(net.transitions)} transitions "
              f"(unfolded: {len(full.slots)} places, {len(full.steps)} transitions)", markup=False)
    with Status("exploring", console=err) as status:
        try:
            result = analyse(translation, queries, max_states, lambda n: status.update(f"exploring: {n} states"))
        except ValueError as exc:
            err.print(f"error: {exc}", markup=False)
            raise typer.Exit(CANNOT_VERIFY) from None
    explored = result.space.unfolded
    out.print(f"explored: the unfolded net reduced to {len(explored.slots)} of its {len(full.slots)} places and "
              f"{len(explored.steps)} of its {len(full.steps)} transitions (places no firing marks dropped, "
              "single-consumer places merged: the same deadlocks, ends and cycles)", markup=False)
    for path, chosen, what in ((pnml, explored, "the reduced net explored"), (pnml_full, full, "the full net")):
        if path is None:
            continue
        try:
            path.write_text(petri.to_pnml(chosen), encoding="utf-8")
        except OSError as exc:
            err.print(f"error: cannot write '{path}': {exc}", markup=False)
            raise typer.Exit(CANNOT_VERIFY) from None
        out.print(f"wrote {path} ({what})", markup=False)
    for finding in result.findings:
        out.print(f"{finding.kind}: {finding.message}", markup=False)
        print_trace(finding.trace, finding.where, steps)
    for answer in result.answers:
        out.print(f"reach {answer.query.text}: {'yes' if answer.reached else 'never'}", markup=False)
        print_trace(answer.trace, answer.where, steps)
    elapsed = time.perf_counter() - started
    if not result.space.complete:
        # Only a growing place is a finding before every marking is known.
        out.print(f"{result.states} states of the reduced net in {elapsed:.1f} s, and more not explored", markup=False)
        if result.space.limit_reached:
            err.print(f"warning: stopped at {result.states} states: deadlocks, cycles and dead statements are not "
                      "established; raise --max-states (or post a smaller goal) to explore them all", markup=False)
        else:  # only the growing branches were cut: more states would not end them
            err.print("warning: the net grows without bound (the 'unbounded' finding above): deadlocks, cycles and "
                      "dead statements are not established; bound what grows (a recursion, a goal posted in a "
                      "loop) and verify again: raising --max-states cannot help", markup=False)
        raise typer.Exit(1 if strict else 0)
    if not result.findings:
        out.print("no finding: no deadlock, no unbounded place, no statement that never runs or never succeeds, "
                  "no endless cycle", markup=False)
    out.print(f"{result.states} states of the reduced net in {elapsed:.1f} s; ends: {result.succeeded} with the goal "
              f"achieved, "
              f"{result.failed} with it failed; {result.bound_summary()}; {'a' if result.home else 'no'} home marking",
              markup=False)
    raise typer.Exit(1 if strict and result.findings else 0)


def print_trace(trace: list[str], where: list[str], steps: int) -> None:
    if trace:
        hidden = len(trace) - steps
        if hidden > 0:
            out.print(f"    ... {hidden} earlier step(s)", markup=False)
        for line in trace[-steps:]:
            out.print(f"    {line}", markup=False)
    if where:
        out.print("  then:", markup=False)
        for line in where:
            out.print(f"    {line}", markup=False)


class Controllability(StrEnum):
    strong = "strong"
    pseudo = "pseudo"


@app.command()
def plan(paths: PathsArg,
         problem: Annotated[str, typer.Option(help="The problem (mission) to plan: its name, or a prefix such "
                                                   "as M1 when --domain says which model.")],
         domain: Annotated[Optional[str], typer.Option(help="Keep the problems of this domain (or domains whose "
                                                             "name starts so: model2 takes model2_M1).")] = None,
         horizon: Annotated[Optional[float], typer.Option(help="End the mission by this many seconds.")] = None,
         now: Annotated[float, typer.Option(help="Mission time of a replanning: nothing starts before it.")] = 0.0,
         fact: Annotated[Optional[list[str]], typer.Option(
             help="A replanning: the current value of an attribute, e.g. 'AT_ROBOT_X() = 2' (repeatable).")] = None,
         goal: Annotated[Optional[list[int]], typer.Option(
             help="A replanning: the source line of a goal still to meet (repeatable; default: all).")] = None,
         picture: Annotated[Optional[Path], typer.Option("--picture", "-o", help="Draw the plan's timeline "
                                                         "(PNG, SVG, PDF).")] = None,
         json_path: Annotated[Optional[Path], typer.Option("--json", help="Write the plan, its schedule, "
                                                           "partial order and goals as JSON (format: "
                                                           "docs/planning.md); '-' prints it.")] = None,
         nodes: Annotated[int, typer.Option(max=MOST_PARTIAL_PLANS, min=1, help=(
             "Partial plans each search may expand (one for every goal at once, then one per goal added)."))] = 300,
         exact: Annotated[bool, typer.Option(help="Exact durations by CasADi (else the interval "
                                                  "enclosures the search computed).")] = True,
         controllability: Annotated[Controllability, typer.Option(
             help="strong: the plan holds whatever nature does; pseudo (IxTeT's): the problem's contingent "
                  "instants one at a time, each anywhere in its bounds.")] = Controllability.strong,
         improve: Annotated[int, typer.Option(max=MOST_PARTIAL_PLANS, min=0, help=(
             "Partial plans spent improving the first plan (goals it dropped, then its worst-case makespan); 0: "
             "the first plan."))] = 300,
         planner: Annotated[Optional[str], typer.Option(help=(
             "Plan as this planner of the ftplan block does in a run: its heuristics, controllability, "
             "improvement and node limit (--nodes, --improve and --controllability are then its own)."))] = None,
         ) -> None:
    """Plan a problem: the partially ordered plan, its schedule, the goals kept or dropped (and why),
    checked by the independent validator.

    Example: specc plan examples/tug --problem shuttle -o build/shuttle.png --json build/shuttle.json"""
    from specc.plan_report import print_result, solve

    refuse_unwritable(picture, "the picture", "-o", "plan.png", picture=True)
    refuse_unwritable(json_path, "the JSON file", "--json", "plan.json")
    loaded = load(paths)
    if report(loaded):
        raise typer.Exit(BAD_INPUT)
    assert loaded.program is not None
    try:
        outcome = solve(loaded.program, problem, domain, horizon, now, fact or [], goal, nodes, exact,
                        controllability.value, improve, planner)
    except ValueError as exc:
        err.print(f"error: {exc}", markup=False)
        raise typer.Exit(BAD_INPUT) from None
    if json_path is not None:
        import json

        from specc.plan_report import plan_document

        text = json.dumps(plan_document(outcome), indent=2, allow_nan=False) + "\n"
        if str(json_path) == "-":
            sys.stdout.write(text)
        else:
            try:
                json_path.parent.mkdir(parents=True, exist_ok=True)  # as -o does for the picture
                json_path.write_text(text, encoding="utf-8")
            except OSError as exc:
                err.print(f"error: cannot write '{json_path}': {exc} [unwritable-file]", markup=False)
                raise typer.Exit(BAD_INPUT) from None
    if str(json_path) != "-":
        # A file or pipe gets the whole tables, not ones squeezed into 80 columns.
        print_result(outcome, table_out())
        if json_path is not None:
            out.print(f"wrote {json_path}", markup=False)
    if picture is not None and outcome.useful:
        from specc.pictures import draw_timeline

        try:
            written = draw_timeline(outcome.result.plan, outcome.problem, picture)
        except (OSError, ValueError) as exc:
            err.print(f"error: cannot draw '{picture}': {exc}", markup=False)
            raise typer.Exit(BAD_INPUT) from None
        (err if str(json_path) == "-" else out).print(f"wrote {written}", markup=False)  # stdout: the JSON alone
    if not outcome.useful or outcome.violations:
        raise typer.Exit(1)


@app.command(name="export")
def export_problem(paths: PathsArg,
                   problem: Annotated[str, typer.Option(help="The problem to export: its name, or a prefix with "
                                                             "--domain.")],
                   output: Annotated[Path, typer.Option("--output", "-o", callback=a_folder,
                                                        help="Folder receiving domain.pddl and problem.pddl.")],
                   domain: Annotated[Optional[str], typer.Option(help="Keep the problems of this domain.")] = None,
                   keep_markers: Annotated[bool, typer.Option(
                       help="Keep the values that only mark a task in progress (MOVE's AT_ROBOT_X = 1000), which "
                            "the compact encoding leaves out.")] = False,
                   allow_partial: Annotated[bool, typer.Option(
                       help="Write the files even when a task of the domain cannot be exported (each one is said "
                            "as a warning): a planner reading them misses what that task does.")] = False,
                   ) -> None:
    """Export a planning domain and problem through unified-planning to PDDL 2.1, saying what could not
    be expressed. A task the export must leave out is an error, and nothing is written, unless
    --allow-partial.

    Example: specc export examples/tug --problem shuttle -o build/pddl"""
    from specc.analysis.planning import domain_block, domain_model, problem_model
    from specc.analysis.planning_export import constant_set_names, export, write_pddl
    from specc.plan_report import choose_problem

    loaded = load(paths)
    if report(loaded):
        raise typer.Exit(BAD_INPUT)
    assert loaded.program is not None
    try:
        chosen = choose_problem(loaded.program, problem, domain)
    except ValueError as exc:
        err.print(f"error: {exc}", markup=False)
        raise typer.Exit(BAD_INPUT) from None
    block = domain_block(loaded.program, chosen)
    exported = export(domain_model(loaded.program, block), problem_model(loaded.program, chosen),
                      constant_set_names(loaded.program, block), compact=not keep_markers)
    # A task left out takes away what specc's planner could use: the files would be another,
    # harder problem, often one with no plan at all, which a planner reports as unsolvable.
    partial = bool(exported.left_out) and not allow_partial
    if not partial:
        try:
            written = write_pddl(exported, output)
        except OSError as exc:
            err.print(f"error: cannot write into '{output}': {exc}", markup=False)
            raise typer.Exit(BAD_INPUT) from None
        for path in written:
            out.print(f"wrote {path}", markup=False)
    for note in exported.unsupported:
        out.print(f"not expressed: {note}", markup=False)
    for task, why in exported.left_out.items():
        severity = "error" if partial else "warning"
        err.print(f"{severity}: task {task} of domain '{block.name}' is left out of the export: {why}.", markup=False)
    if partial:
        err.print(f"error: {len(exported.left_out)} task(s) of domain '{block.name}' cannot be exported (above): the "
                  "PDDL files would lack them, and a planner reading them would not find the plans that need them; "
                  "nothing written (--allow-partial writes them anyway)", markup=False)
        raise typer.Exit(1)
    if not exported.problem.actions:  # files a planner can only answer "unsolvable": say so, and fail
        err.print(f"error: no task of domain '{block.name}' could be exported (each one's reason is above): the "
                  "PDDL files have no action", markup=False)
        raise typer.Exit(1)


@app.command(name="rules")
def rules_report(paths: PathsArg,
                 limit: Annotated[int, typer.Option(help="Findings shown per rule base (0: all).")] = 20,
                 strict: Annotated[bool, typer.Option(help="Exit 1 when a rule base or controller leaves some "
                                                           "input configuration unsettled.")] = False) -> None:
    """Compile every Kheops rule base and every executive's resource controller: domains,
    decision-graph depth, and the input configurations that leave an attribute without value
    (inconsistent) or an output undetermined (incomplete). Exit 0 (with --strict: 1 when some
    configuration is unsettled), 1 when the specs have errors.

    Example: specc rules examples/generic

    Example: specc rules examples/tug --strict   # for CI: fails on an unsettled case
    """
    from specc.analysis import kheops
    from specc.analysis.kheops import describe, tally, worst_first

    loaded = load(paths)
    code = report(loaded)
    if code or loaded.program is None:
        raise typer.Exit(code or 1)
    from specc.analysis.controller import executive_controller

    items = [i for i in loaded.program.items if isinstance(i, (m.RuleBase, m.Executive))]
    if not items:
        out.print("no rules or executive block in these specs", markup=False)
    # A base an executive joins to its controller decides only where it applies: the controller
    # completes it, and is what is judged (as `specc check` does).
    joined = {ref.text: e.name for e in loaded.program.items if isinstance(e, m.Executive) for ref in e.rules}
    unsettled = False
    for item in items:
        if isinstance(item, m.RuleBase) and item.name in joined:
            out.print(f"rules {item.name}: joined to the resource controller of executive '{joined[item.name]}' "
                      "(below), judged with it", markup=False)
            continue
        try:
            if isinstance(item, m.RuleBase):
                title, normal = f"rules {item.name}", kheops.normalise(item)
                compiled = kheops.compile_base(normal)
            else:
                title = f"executive {item.name}: resource controller"
                controller = executive_controller(loaded.program, item)
                normal, compiled = controller.base, controller.compile()
        except kheops.KheopsError as exc:
            err.print(exc.headline(), markup=False)
            raise typer.Exit(1) from None
        out.print(f"{title}: {len(normal.rules)} rules, decision graph of depth {compiled.depth} "
                  f"({compiled.tree_nodes} tree nodes -> {compiled.dag_nodes} shared)", markup=False)
        depths = compiled.part_depths()
        if depths:
            shown_depths = ", ".join(f"{service} {depth}" for service, depth in depths.items())
            out.print(f"  one decision per service, tests after the one on the service: {shown_depths}", markup=False)
        for attribute in normal.attributes.values():
            values = ", ".join(str(v) for v in attribute.values)
            out.print(f"  {attribute.role:12} {attribute.name}: {attribute.kind} {{{values}}}", markup=False)
        findings = worst_first(compiled.findings)
        shown = findings if limit <= 0 else findings[:limit]
        for finding in shown:
            out.print(f"  {describe(finding)}", markup=False)
        if len(shown) < len(findings):
            out.print(f"  ... {len(findings) - len(shown)} more (--limit 0 shows all)", markup=False)
        if findings:
            unsettled = True
            out.print(f"  {compiled.findings_count()} case(s) of inputs unsettled: {tally(findings)}"
                      + (" (the listing stops there)" if compiled.findings_cut else ""), markup=False)
        else:
            out.print("  complete and consistent for every input", markup=False)
    if strict and unsettled:
        raise typer.Exit(1)


@app.command()
def skeleton(paths: PathsArg) -> None:
    """Write stubs for the Python functions the specs name but their modules lack (module codels,
    executive input/output functions, PRS actions and evaluable predicates); never rewrites code.
    A function is added to the Python module the spec names (`codels: "cart_codels.drive"`), in the
    robot's folder where `specc run` imports it from (the folder holding the system block, else the
    folder given), created with its package when missing.

    Example: specc skeleton examples/tug
    """
    from specc.backends import skeleton as stubs

    loaded = load(paths, check=False)
    code = report(loaded)
    if code or loaded.program is None:
        raise typer.Exit(code or 1)
    # New codel modules go to the robot's folder, where `specc run` imports them from: the nearest
    # folder above a spec (or its own) holding the system block; with no system block yet (step 1
    # of docs/your-robot.md), the folder the command was given; beside the spec otherwise.
    robots = {loaded.paths[f.path].resolve().parent for f in loaded.program.files
              if any(isinstance(item, m.System) for item in f.items)} or {
        path.resolve() for path in paths if path.is_dir()}
    wrote = 0
    for source in loaded.program.files:
        spec_dir = loaded.paths[source.path].resolve().parent
        robot_dir = next((folder for folder in (spec_dir, *spec_dir.parents) if folder in robots), None)
        for owner, wanted in ((item, needs) for item in source.items for needs in stubs.needs(item)):
            try:
                change = stubs.write_stubs(wanted, spec_dir, robot_dir)
            except (OSError, SyntaxError) as exc:
                err.print(f"{owner.span}: error: {wanted.owner}: {exc} [skeleton-failed]", markup=False)
                raise typer.Exit(1) from None
            if change is None or not change.functions:
                continue
            wrote += len(change.functions)
            verb = "created" if change.created else "added to"
            out.print(f"{verb} {change.path}: {', '.join(change.functions)}", markup=False)
    if not wrote:
        out.print("every function named by the specs already exists", markup=False)


TABLE_WIDTH = 140  # columns of a table printed to a file or a pipe
MISSION_COLUMNS = 7  # mission, world, configuration, seeds, succeeded, success rate, time: what `table` prints


def table_out() -> Console:
    """Where a table goes: the terminal as it is, or a file or pipe whole (not squeezed into 80
    columns, which cuts its cells)."""
    return out if out.is_terminal else Console(highlight=False, soft_wrap=True, width=TABLE_WIDTH, emoji=False)


def _run_error(error: Exception, code: int = 1) -> typer.Exit:
    """One clear line (or a spec's diagnostics) for a run that cannot go on; a message that starts
    with a spec's position says it gcc-style (`file:line:col: error: ...`)."""
    import re

    text = str(error)
    located = re.match(r"(\S+:\d+:\d+): (.*)", text, re.DOTALL)
    if "error:" in text:
        err.print(text, markup=False)
    elif located is not None:
        err.print(f"{located.group(1)}: error: {located.group(2)}", markup=False)
    else:
        err.print(f"error: {text}", markup=False)
    return typer.Exit(code)


@app.command()
def run(specs: Annotated[Path, typer.Argument(metavar="ROBOT", help="The robot's folder (its specs, codels and "
                                                   "worlds), e.g. examples/tug.", show_default=False)],
        mission: Annotated[Optional[str], typer.Option(help="One of the system block's missions (default: its only "
                                                            "one).")] = None,
        world: Annotated[Optional[str], typer.Option(help="One of the system's worlds or a world file (default: "
                                                          "the mission's; with --goal, the system's first).")] = None,
        config: Annotated[Optional[str], typer.Option(help="FTplan's configuration for a planned mission: Robot1, "
                                                           "Robot2 (one planner; or that planner's name), Robot1/2 "
                                                           "(successive), Robot1/2c (concurrent), any with -repair, "
                                                           "-norepair or -noanalyzer; default: the ftplan block's "
                                                           "own.")] = None,
        seed: Annotated[int, typer.Option(min=0, help="Draws the run's randomness: one seed, one event log.")] = 0,
        generated: Annotated[Path, typer.Option("--generated", "-g", help="Where the specs compile to (compiled "
                                                "first when stale).")] = Path("generated"),
        runs: Annotated[Path, typer.Option(callback=runs_folder, help="Where run folders go.")] = Path("runs"),
        folder: Annotated[Optional[Path], typer.Option("--folder", "-o", callback=a_folder,
                                                       help="The run folder (default: "
                                                       "RUNS/<robot>-<mission>-<world>[-<config>]-s<seed>; with "
                                                       "--goal, 'goal' for the mission and the goals and a digest "
                                                       "of them after the seed).")] = None,
        timing: Annotated[str, typer.Option(help="FTplan's planning time: model (deterministic) or wall "
                                                 "(measured).")] = "model",
        horizon: Annotated[Optional[float], typer.Option(help="Simulated seconds before the run stops (default: "
                                                              "the mission's).")] = None,
        goal: Annotated[Optional[list[str]], typer.Option(help="Post this PRS goal instead of a mission's, e.g. "
                                                               "'!(GO 3 4)' (repeatable: posted together).")] = None,
        wall_limit: Annotated[float, typer.Option(help="Wall-clock seconds before the run is stopped (a codel "
                                                       "stuck in a loop): its report says so.")] = 3600.0,
        pictures: Annotated[bool, typer.Option(help="Draw the map and timeline now (else: specc replay "
                                                    "RUN).")] = True,
        mutant: Annotated[Optional[str], typer.Option(help="Plan with this mutant of a planning model in its "
                                                           "place, e.g. model1-0131 (`specc mutants` lists them; "
                                                           "a campaign's report names them).")] = None,
        quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress display.")] = False) -> None:
    """Run a mission end to end (modules on the simulated robot, executive, supervisor, FTplan and its
    planners) and write a run folder: events.jsonl, report.json, summary.txt, map.png, timeline.png.
    Exits 0 when the mission succeeded, 1 when it failed (the report says why), 2 on bad input.

    Example: specc run examples/tug --mission deliver

    Example: specc run examples/tug --goal '!(FETCH B C)' --seed 3

    Example: specc run examples/tug --mission shuttle --world crowded --config Robot2

    Example: specc run examples/tug --mission shuttle --config Robot1 --mutant warehouse-0042
    """
    from specc.run import RunError
    from specc.run.session import InjectedModel, RunCrashed, RunRequest, run_in_folder

    injected = None
    if mutant is not None:
        from specc.mutation import MutationError, find_mutant, mutant_domain

        try:
            found, aside = find_mutant(specs, mutant)
            injected = InjectedModel(found.id, found.description, mutant_domain(found))
        except MutationError as error:
            raise _run_error(RunError(f"--mutant {mutant}: {error}"), 2) from None
        if aside is not None:  # a campaign sets it aside before running it: say why this run is no news
            err.print(f"note: mutant {mutant} is set aside by a campaign ({aside.reason}: {aside.detail})",
                      markup=False)
    request = RunRequest(specs, mission=mission, world=world, configuration=config, seed=seed, generated=generated,
                         runs=runs, folder=folder, timing=timing, horizon=horizon,
                         goals=tuple(goal or ()), pictures=pictures, wall_limit=wall_limit, mutant=injected)
    try:
        with ProgressDisplay(quiet) as progress:
            outcome = run_in_folder(request, progress, compiled_note=lambda text: err.print(text, markup=False))
    except RunCrashed as crash:
        if os.environ.get("SPECC_DEBUG") and crash.__cause__ is not None:
            raise crash.__cause__ from crash  # the traceback the one-line message offers
        raise _run_error(crash, crash.exit_code) from None
    except RunError as error:
        raise _run_error(error, 2) from None
    out.print(outcome.summary, markup=False)
    out.print(f"run folder: {outcome.folder}", markup=False)
    if not outcome.succeeded:
        raise typer.Exit(1)


HEARTBEAT = 60.0  # s between two progress lines when stderr is a log, not a terminal


class Heartbeat:
    """Progress for a log (CI, a pipe): a live line cannot be redrawn there, so a line is printed
    at most every HEARTBEAT seconds, for work long enough that a reader wonders whether it hangs."""

    def __init__(self) -> None:
        self.last = time.monotonic()

    def due(self) -> bool:
        """Is a line due? (Asked first, so that a run's frequent progress builds no text for nothing.)"""
        now = time.monotonic()
        if now - self.last < HEARTBEAT:
            return False
        self.last = now
        return True

    def __call__(self, text: str) -> None:
        if self.due():
            err.print(f"... {text}", markup=False)


class ProgressDisplay:
    """A live line on stderr: how far (mission time, or runs done; against the total when there
    is one) and the latest step; when stderr is not a terminal, a line every HEARTBEAT seconds
    (`Heartbeat`; `heartbeat=False`: nothing, the caller says each step itself); nothing when quiet."""

    def __init__(self, quiet: bool, clock: Callable[[float], str] = lambda now: f"t = {now:7.1f} s",
                 heartbeat: bool = True) -> None:
        from rich.progress import BarColumn, Progress, TextColumn

        self.live = not quiet and err.is_terminal
        self.heartbeat = Heartbeat() if heartbeat and not quiet and not err.is_terminal else None
        self.clock = clock
        self.progress = Progress(TextColumn("[bold]{task.fields[clock]}"), BarColumn(),
                                 TextColumn("{task.description}"), console=err, transient=True)
        self.task = self.progress.add_task("starting", total=None, clock=clock(0.0))

    def __enter__(self) -> Callable[[float, float | None, str], None] | None:
        if self.heartbeat is not None:
            beat = self.heartbeat

            def say(now: float, total: float | None, what: str) -> None:
                if beat.due():
                    err.print(f"... {self.clock(now)}{f' of {total:g}' if total else ''}: {what}", markup=False)

            return say
        if not self.live:
            return None
        self.progress.start()
        return self.update

    def __exit__(self, *exc: object) -> None:
        if self.live:
            self.progress.stop()

    def update(self, now: float, horizon: float | None, what: str) -> None:
        self.progress.update(self.task, completed=now, total=horizon, description=what, clock=self.clock(now))


@app.command()
def replay(run_path: Annotated[Path, typer.Argument(metavar="RUN", help="A run folder (or its events.jsonl).",
                                                    show_default=False)],
           kind: Annotated[Optional[list[str]], typer.Option(help="Show only events of this kind (repeatable; "
                                                                  "pose samples only when named).")] = None,
           start: Annotated[Optional[float], typer.Option("--from", help="From this mission time (s).")] = None,
           end: Annotated[Optional[float], typer.Option("--to", help="Up to this mission time (s).")] = None,
           speed: Annotated[float, typer.Option(min=0.0, callback=finite, help=(
               "Play back at this many simulated seconds per second (0: at once)."))] = 0.0,
           render: Annotated[bool, typer.Option(help="Draw the pictures again from the log.")] = True,
           output: Annotated[Optional[Path], typer.Option("--output", "-o", callback=a_folder,
                                                          help="Where the pictures go (default: the run folder).")]
           = None) -> None:
    """Play a run's event log back, then draw its pictures again from the log alone.

    Example: specc replay runs/tug-shuttle-crowded-Robot1-2-s0 --kind action --kind ftplan --to 60"""
    from specc.run import RunError
    from specc.run.replay import check_kinds, describe, load_run, select

    try:
        for option, value in (("--from", start), ("--to", end)):
            if value is not None and not math.isfinite(value):
                raise RunError(f"{option} {value}: give a mission time in seconds")
        if start is not None and end is not None and start > end:
            raise RunError(f"--from {start:g} is after --to {end:g}: nothing between them")
        cut: list[str] = []
        folder, events = load_run(run_path, cut)
        note = check_kinds(events, kind or ())
    except RunError as error:
        raise _run_error(error, 2) from None
    previous: float | None = None
    for event in select(events, kind or (), start, end):
        if speed > 0 and previous is not None and event["t"] > previous:
            time.sleep((event["t"] - previous) / speed)
        previous = event["t"]
        out.print(describe(event), markup=False)
    # What the listing lacks is said under it, where a long listing leaves the reader. The note
    # goes to stderr: the listing is flushed first, whole lines, so that where both streams share
    # a screen or a file the note starts a line of its own.
    out.file.flush()
    for said in cut:
        err.print(f"warning: {said}", markup=False)
    if note is not None:
        err.print(f"note: {note}", markup=False)
    if not render:
        return
    from specc.run.render import render_run

    try:
        written = render_run(events, output or folder)
    except RunError as error:
        raise _run_error(error, 1) from None
    for path in written:
        out.print(f"picture: {path}", markup=False)


@app.command()
def table(specs: Annotated[Path, typer.Argument(metavar="ROBOT", help="The robot's folder, e.g. examples/tug.",
                                                show_default=False)],
          mission: Annotated[Optional[list[str]], typer.Option(help="A mission (repeatable; default: every mission "
                                                                    "of the system).")] = None,
          world: Annotated[Optional[list[str]], typer.Option(help="A world (repeatable; default: each mission's "
                                                                  "own).")] = None,
          config: Annotated[Optional[list[str]], typer.Option(help="FTplan's configuration of the planned missions "
                                                                   "(repeatable; without --mission, only the "
                                                                   "planned missions run; default: the ftplan "
                                                                   "block's own).")] = None,
          seeds: Annotated[int, typer.Option(min=1, help="Seeds 0..N-1 for every combination.")] = 1,
          generated: Annotated[Path, typer.Option("--generated", "-g", help="Where the specs compile to.")]
          = Path("generated"),
          runs: Annotated[Path, typer.Option(callback=runs_folder, help="Where the run folders go.")]
          = Path("runs"),
          output: Annotated[Optional[Path], typer.Option("--output", "-o", help="The table (Markdown; JSON "
                                                         "beside it). Default: RUNS/<robot>-table.md")] = None,
          pictures: Annotated[bool, typer.Option(help="Draw every run's pictures.")] = False,
          quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress display.")] = False) -> None:
    """Run every mission x world (x configuration) x seed, one run folder each, and print the table of
    their measures: per mission and world, the success rate and the means of the runs' figures (the
    means of seed 004 §4.1.4 when the robot's extension measures them, as the rover's does).

    Example: specc table examples/tug --seeds 10

    Example: specc table examples/tug --mission shuttle --config Robot1 --config Robot1/2
    """
    from specc.run import RunError, writable_file
    from specc.run.measures import rich_table
    from specc.run.mission import brief_why
    from specc.run.session import RunCrashed, RunRequest, compile_robot
    from specc.run.sweep import sweep, write_table

    try:
        if output is not None:
            writable_file(output, "--output", "the table's file", "the table's folder", "table.md")
        robot = compile_robot(specs, generated, lambda text: err.print(text, markup=False))
        base = RunRequest(specs, generated=generated, runs=runs, pictures=pictures)
        with ProgressDisplay(quiet, clock=lambda done: f"{done:.0f} run(s) done", heartbeat=False) as progress:
            def step(done: int, total: int, label: str) -> None:
                if progress is not None:
                    progress(done, total, label)
                elif not quiet and label:
                    err.print(f"[{done + 1}/{total}] {label}", markup=False)

            # An option given twice runs once: each run has one folder, counted once in the table.
            result = sweep(robot, base, missions=tuple(dict.fromkeys(mission or ())),
                           worlds=tuple(dict.fromkeys(world or ())), configurations=tuple(dict.fromkeys(config or ())),
                           seeds=range(seeds), step=step)
        table_path = output or runs / f"{robot}-table.md"
        if result.interrupted:  # beside the table of a whole sweep, which it must not replace
            table_path = table_path.with_name(f"{table_path.stem}-interrupted{table_path.suffix}")
        written = write_table(result, table_path)
    except RunCrashed as crash:  # stopped by a signal: the runs so far keep their folders
        raise _run_error(crash, crash.exit_code) from None
    except RunError as error:
        raise _run_error(error, 2) from None
    if result.rows:
        # A file or pipe gets the whole table, not one squeezed into 80 columns.
        table_out().print(rich_table(result.rows))
    else:
        from rich.table import Table

        headings, cells = result.mission_cells()
        table = Table(show_edge=False)
        shown = MISSION_COLUMNS  # the figures' means, as many as the runs measured, are in the files written
        for k, heading in enumerate(headings[:shown]):
            table.add_column(heading, justify="left" if k < 3 else "right")
        for row in cells:
            table.add_row(*row[:shown])
        table_out().print(table)
    for failure in result.failures:  # each reason cut short: the run's report.json has it whole
        out.print(f"{failure.outcome}: {failure.name}: {brief_why(failure.why)}", markup=False)
    for path in written:
        out.print(f"wrote {path}", markup=False)
    if result.interrupted:
        err.print(f"interrupted after {len(result.outcomes)} of {result.planned} run(s): the table is of those "
                  "(the run stopped has its folder too)", markup=False)
        raise typer.Exit(130)


@app.command(name="mutants")
def mutants_command(
        specs: Annotated[Path, typer.Argument(metavar="ROBOT", help="The robot's spec folder (or files), e.g. "
                                                                   "examples/tug.", show_default=False)],
        domain: Annotated[Optional[str], typer.Option(help="The planning domain to mutate (default: the one "
                                                            "the FTplan block's first planner plans in).")] = None,
        kinds: Annotated[Optional[list[str]], typer.Option(
            "--class", help="Keep this mutation class: numeric, variable, value, operator, deletion (repeatable; "
                            "default: all).")] = None,
        sample: Annotated[Optional[int], typer.Option(min=1, help="List (and write) only N kept mutants, drawn "
                                                                 "with --seed, stratified by class.")] = None,
        seed: Annotated[int, typer.Option(help="Draws the --sample.")] = 0,
        show: Annotated[Optional[str], typer.Option(help="Print this mutant's description, verdict and diff "
                                                         "(its id, as the listing gives it: "
                                                         "<domain>-NNNN, e.g. warehouse-0020).")] = None,
        output: Annotated[Optional[Path], typer.Option("--output", "-o", callback=a_folder, help=(
            "Write each kept (or sampled) mutant's spec file and diff into this folder."))] = None,
        workers: Annotated[Optional[int], typer.Option(min=1, max=MOST_WORKERS, help=(
            "Processes checking mutants (default: one per CPU, at most 8)."))] = None,
        quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress display.")] = False) -> None:
    """Mutate a planning domain on its model (seed 004 §4.1.3), print each mutant back as spec text and
    keep those that pass specc check: a table of counts per class, then the kept mutants.

    Example: specc mutants examples/tug --domain warehouse --sample 28 --seed 1 -o mutants/
    """
    from rich.table import Table

    from specc.mutation import (
        ClassCounts,
        MutationError,
        default_workers,
        enumerate_mutants,
        keep_valid,
        mutation_target,
    )
    from specc.mutation.mutants import verdict

    if not specs.exists():
        raise _run_error(ValueError(f"no such file or folder: '{specs}'"), 2)
    robot_folder = specs.resolve() if specs.is_dir() else specs.resolve().parent
    if output is not None and output.resolve().is_relative_to(robot_folder):
        raise _run_error(ValueError(f"--output {output} is inside the robot's folder {specs}: every mutant written "
                                    "there would be read as one of its specs (`specc check` would find each "
                                    "planning domain twice); give a folder outside it, e.g. -o build/mutants"), 2)
    started = time.perf_counter()
    if show is not None and domain is None and "-" in show:
        domain = show.rsplit("-", 1)[0]  # an id names its domain: warehouse_slow-0001
    try:
        target = mutation_target(specs, domain)
        # --show finds a mutant by id whatever --class says: ids are given over every class.
        wanted = enumerate_mutants(target, classes=None if show else kinds)
    except MutationError as exc:
        raise _run_error(exc, 2) from None
    enumerated = time.perf_counter() - started
    if show is not None:
        chosen = next((x for x in wanted if x.id == show), None)
        if chosen is None:
            span = f"{wanted[0].id} .. {wanted[-1].id}" if wanted else "none"
            raise _run_error(ValueError(f"no mutant '{show}' of {target.domain.name} (its mutants: {span})"), 2)
        found = verdict(target, chosen.text) if chosen.text != target.original_text else (
            "identical", "prints as the original")
        out.print(f"{chosen.id} [{chosen.kind}] {chosen.description}", markup=False)
        out.print("passes the checks and changes the planning domain" if found is None
                  else f"rejected ({found[0]}): {found[1]}", markup=False)
        sys.stdout.write(chosen.diff)
        return
    count = workers or default_workers()
    with ProgressDisplay(quiet, clock=lambda done: f"{done:.0f} checked") as progress:
        def step(done: int, total: int) -> None:
            if progress is not None:
                progress(done, total, f"checking {target.domain.name}'s mutants")

        result = keep_valid(wanted, workers=count, progress=step)
    table = Table(title=f"mutants of {target.domain.name} ({target.source.path})")
    for k, column in enumerate(("class", "generated", "identical", "duplicate", "failed check", "equivalent",
                                "kept")):
        table.add_column(column, justify="left" if k == 0 else "right")

    def cells(c: ClassCounts) -> list[str]:
        return [str(n) for n in (c.generated, c.identical, c.duplicate, c.invalid, c.equivalent, c.kept)]

    for kind, counts in result.counts().items():
        table.add_row(kind, *cells(counts))
    table.add_row("total", *cells(result.total()), style="bold")
    # A file or pipe gets the whole table, not one squeezed into 80 columns.
    table_out().print(table)
    out.print(f"enumerated in {enumerated:.1f} s, re-parsed and checked in {result.seconds:.1f} s "
              f"({count} process(es))", markup=False)
    listed = result.sample(sample, seed) if sample is not None else result.kept
    if sample is not None:
        out.print(f"sample of {len(listed)} kept mutant(s), seed {seed}, stratified by class:", markup=False)
    for x in listed:
        out.print(f"{x.id}  {x.kind:9} {x.description}", markup=False)
    if output is not None:
        try:
            output.mkdir(parents=True, exist_ok=True)
            suffix = Path(target.source.path).suffix or ".spec"
            for x in listed:
                (output / f"{x.id}{suffix}").write_text(x.text, encoding="utf-8")
                (output / f"{x.id}.diff").write_text(x.diff, encoding="utf-8")
            (output / "index.tsv").write_text("".join(f"{x.id}\t{x.kind}\t{x.description}\n" for x in listed),
                                              encoding="utf-8")
        except OSError as exc:
            raise _run_error(ValueError(f"cannot write into '{output}': {exc.strerror}"), 1) from None
        out.print(f"wrote {len(listed)} mutant(s) (spec file and diff each) and index.tsv to {output}",
                  markup=False)


def _names(text: str) -> tuple[str, ...]:
    return tuple(name.strip() for name in text.split(",") if name.strip())


@app.command()
def campaign(
        specs: Annotated[Path, typer.Argument(metavar="ROBOT", help="The robot's spec folder, e.g. examples/tug.",
                                              show_default=False)],
        mutants: Annotated[str, typer.Option(help="How many mutants to draw among those that pass specc check "
                                                  "(stratified by class), or 'all'.")] = "40",
        missions: Annotated[Optional[str], typer.Option(help="Comma-separated missions (default: every planned "
                                                             "mission of the system).")] = None,
        worlds: Annotated[Optional[str], typer.Option(help="Comma-separated worlds (default: every world of the "
                                                           "system).")] = None,
        set_apart: Annotated[str, typer.Option(help="Comma-separated worlds the means are also given without "
                                                    "(seed 004 set W4 apart).")] = "",
        runs: Annotated[int, typer.Option(min=1, help="Runs (seeds 0..N-1) of every activity.")] = 3,
        configs: Annotated[Optional[str], typer.Option(help="Comma-separated configurations; the first one judges "
                                                            "the mutants (add -noanalyzer to one for it without the "
                                                            "plan analyzer, -repair or -norepair for every planner "
                                                            "repairing its plans or none). Default: Robot1 (the "
                                                            "first planner alone), then every planner "
                                                            "(Robot1/2...).")] = None,
        domain: Annotated[Optional[str], typer.Option(help="The planning model faults are injected into (default: "
                                                           "the first planner's).")] = None,
        seed: Annotated[int, typer.Option(help="Draws the mutants.")] = 0,
        workers: Annotated[Optional[int], typer.Option(min=1, max=MOST_WORKERS, help=(
            "Experiments at once (default: one per CPU)."))] = None,
        scheduler: Annotated[Optional[str], typer.Option(help="Run on Dask distributed: a scheduler's address "
                                                              "(tcp://host:8786), or 'local' for a local "
                                                              "cluster.")] = None,
        timeout: Annotated[float, typer.Option(min=1.0, callback=finite, help=(
            "Hard timeout of one experiment (s): past it, its process is killed."))] = 120.0,
        store: Annotated[Optional[Path], typer.Option(help="The results store (SQLite); an interrupted campaign "
                                                           "resumes from it. Default: campaigns/<robot>-<domain>"
                                                           "-<mutants>.sqlite")] = None,
        output: Annotated[Optional[Path], typer.Option("--output", "-o", help="Where the report goes (default: "
                                                       "beside the store).")] = None,
        generated: Annotated[Path, typer.Option("--generated", "-g", help="Where the specs compile to.")]
        = Path("generated"),
        report_only: Annotated[bool, typer.Option("--report-only", help="Run nothing: write the report of the "
                                                                        "store as it is (a campaign stopped "
                                                                        "half-way says so).")] = False,
        quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress display.")] = False) -> None:
    """Inject faults into a planning model by mutation and run every configuration x mutant x mission x
    world x run (seed 004 ch. 4) of a robot with an ftplan block; then the report: the measures over sets
    of activities (with and without the worlds set apart), per mutant, the mutants set aside, the bar
    charts of Fig 4.14 and the headline.

    Example: specc campaign examples/tug --mutants 5 --runs 1

    Example: specc campaign examples/tug --mutants 40 --runs 3 --configs Robot1,Robot1/2 --set-apart crowded
    """
    from specc.campaign.campaign import Campaign, CampaignPlan, campaign_defaults, check_names, select_mutants
    from specc.campaign.engines import DaskEngine, LocalEngine
    from specc.campaign.experiments import ORIGINAL, Setting
    from specc.campaign.report import build_report
    from specc.campaign.store import ResultStore
    from specc.mutation import default_workers
    from specc.run import RunError, writable_folder
    from specc.run.session import compile_robot

    try:
        if mutants != "all" and not (mutants.isdigit() and int(mutants) > 0):
            raise RunError(f"--mutants {mutants}: give a number of mutants, or 'all'")
        if output is not None:
            writable_folder(output, "the report's folder")
        def robot_name() -> str:
            return compile_robot(specs, generated, lambda text: err.print(text, markup=False))

        robot = robot_name()
        defaults = campaign_defaults(generated, specs, robot)
        domain = domain or defaults.domain
        if report_only:  # the store is all a report needs
            _campaign_report(store or Path("campaigns") / f"{robot}-{domain}-{mutants}.sqlite", output,
                             _names(configs) if configs is not None else None)
            return
        setting = Setting(generated.resolve(), specs.resolve(), robot)
        plan = CampaignPlan(specs, setting, domain, None if mutants == "all" else int(mutants), seed,
                            _names(missions) if missions is not None else defaults.missions,
                            _names(worlds) if worlds is not None else defaults.worlds, runs,
                            _names(configs) if configs is not None else defaults.configurations, _names(set_apart))
        for note in check_names(plan):
            err.print(f"note: {note}", markup=False)
        count = workers or default_workers()
        engine = (LocalEngine(setting, count, timeout) if scheduler is None
                  else DaskEngine(setting, scheduler, count, timeout))
        with ProgressDisplay(quiet, clock=lambda done: f"{done:.0f} checked") as progress:
            def checking(done: int, total: int) -> None:
                if progress is not None:
                    progress(done, total, f"checking {domain}'s mutants")

            selection = select_mutants(plan, count, checking)
        err.print(f"{selection.generated} mutants of {domain}; {len(selection.domains)} passing specc check "
                  f"{'in all' if mutants == 'all' else f'drawn (seed {seed})'}", markup=False)
        path = store or Path("campaigns") / f"{robot}-{domain}-{mutants}.sqlite"
        with ResultStore(path) as results:
            job = Campaign(plan, results, engine, selection.domains, selection.records)
            for note in job.start():
                err.print(f"note: {note}", markup=False)
            err.print(f"results in {path} ({results.count()} already there); on {engine.describe()}", markup=False)
            try:
                with CampaignProgress(quiet) as step:
                    verdicts = job.run(step)
            except KeyboardInterrupt:
                err.print(f"interrupted: {results.count()} results kept in {path}; the same command resumes the "
                          "campaign", markup=False)
                raise typer.Exit(130) from None
            report = build_report(results)
        kept = sum(1 for v in verdicts.values() if v.verdict == "kept")
        out.print(f"{len(report.outcomes)} experiments; {kept} of {len(verdicts)} mutants kept", markup=False)
        _print_report(report, output or path.parent, path.stem)
        # This command's experiments that timed out (a wall-clock limit): a script must not take the
        # campaign for finished. Those of configurations or mutants a later command added are theirs.
        timed_out = sum(1 for o in report.outcomes if o.status == "timeout"
                        and o.experiment.configuration in plan.configurations
                        and (o.experiment.mutant == ORIGINAL or o.experiment.mutant in selection.domains))
        if timed_out:
            err.print(f"the campaign is not finished: {timed_out} experiment(s) timed out (--timeout {timeout:g} s); "
                      "the same command runs them again (with a larger --timeout if they keep timing out)",
                      markup=False)
            raise typer.Exit(1)
    except RunError as error:
        raise _run_error(error, 2) from None


def _campaign_report(path: Path, output: Path | None, configurations: Sequence[str] | None = None) -> None:
    """`specc campaign --report-only`: the report of the store at `path`, nothing run. Asked for
    `configurations`, RunError naming those the store has no experiment of."""
    from specc.campaign.report import build_report
    from specc.campaign.store import ResultStore
    from specc.run import RunError

    if not path.is_file():
        raise RunError(f"no results store '{path}': give the campaign's --store, or its --mutants")
    with ResultStore(path) as results:
        description = results.description()
        if not description:
            raise RunError(f"'{path}' holds no campaign: give the campaign's --store")
        stored = list(description.get("configurations", []))
        missing = [c for c in configurations or () if c not in stored]
        if missing:
            raise RunError(f"'{path}' has no experiment of {', '.join(missing)} (its configurations: "
                           f"{', '.join(stored)}): run the campaign with them first, or leave --configs out")
        report = build_report(results)
    out.print(f"{len(report.outcomes)} experiments in {path}", markup=False)
    _print_report(report, output or path.parent, path.stem)


def _print_report(report: CampaignReport, folder: Path, stem: str) -> None:
    """Write the campaign's report and say what it found: what is not finished, the headlines."""
    from specc.campaign.report import write_report

    for covered in report.coverage:
        if not covered.complete:
            out.print(f"{covered.configuration}: {covered.done:,} of {covered.expected:,} experiments: not finished",
                      markup=False)
    for headline in report.headlines:
        out.print(headline.text(), markup=False)
    for written_path in write_report(report, folder, stem):
        out.print(f"wrote {written_path}", markup=False)


class CampaignProgress:
    """done / total, experiments per hour and the time left, on stderr when it is a terminal;
    a line every 5 % otherwise (a campaign may run for an hour in a log file)."""

    def __init__(self, quiet: bool) -> None:
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

        self.quiet, self.live = quiet, not quiet and err.is_terminal
        self.started = time.perf_counter()
        self.first: int | None = None  # done when this session started (a resumed campaign)
        self.said = -1
        self.progress = Progress(TextColumn("experiments"), BarColumn(), MofNCompleteColumn(),
                                 TextColumn("{task.fields[rate]}"), TimeRemainingColumn(),
                                 TextColumn("{task.description}"), console=err, transient=True)
        self.task = self.progress.add_task("", total=None, rate="")

    def __enter__(self) -> Callable[[int, int, Any], None]:
        if self.live:
            self.progress.start()
        return self.update

    def __exit__(self, *exc: object) -> None:
        if self.live:
            self.progress.stop()

    def update(self, done: int, total: int, outcome: Any) -> None:
        if self.first is None:
            self.first = done
            self.progress.reset(self.task, completed=done, total=total)  # the rate counts this session only
        elapsed = time.perf_counter() - self.started
        rate = (done - self.first) / elapsed * 3600 if elapsed > 0 and done > self.first else 0.0
        what = "" if outcome is None else f"{outcome.experiment.key}: {outcome.status}"
        if self.live:
            self.progress.update(self.task, completed=done, total=total, rate=f"{rate:,.0f}/h", description=what)
        elif not self.quiet and total and (done * 20 // total) != self.said:
            self.said = done * 20 // total
            err.print(f"{done}/{total} experiments, {rate:,.0f}/h", markup=False)


# A command's start allocates its long-lived objects in bursts (the modules imported, the model read
# back): the collector, traversing them every 700 allocations, was 0.02 s of a cold `specc plan`. A
# larger first threshold still collects cycles, 70x less often; a simulation's run is as fast.
GC_THRESHOLDS = (50_000, 20, 20)


class ReaderGone:
    """Standard output that outlives its reader: once the pipe is closed (`specc run ... | head`),
    what is written is dropped instead of raising, so that the command ends as it would have (a
    campaign finishes its runs, the exit status still says how the mission went) rather than with
    click's silent status 1 for a broken pipe."""

    def __init__(self, stream: Any) -> None:
        self._stream = stream
        self._gone = False

    def write(self, text: str) -> int:
        if not self._gone:
            try:
                return int(self._stream.write(text))
            except BrokenPipeError:
                self._gone = True
        return len(text)

    def flush(self) -> None:
        if not self._gone:
            try:
                self._stream.flush()
            except BrokenPipeError:
                self._gone = True

    def __getattr__(self, name: str) -> Any:  # isatty, encoding, fileno...: the stream's own
        return getattr(self._stream, name)


def main() -> None:
    """The `specc` command: runs one subcommand, then ends the process at once."""
    gc.set_threshold(*GC_THRESHOLDS)
    sys.stdout = ReaderGone(sys.stdout)  # type: ignore[assignment]
    try:
        app()
    except KeyboardInterrupt:
        err.print("interrupted", markup=False)
        exit_now(130)
    except SystemExit as exit_:
        exit_now(exit_.code)
    except Exception as exc:  # a bug in specc itself: one line for the user, the trace on request
        if os.environ.get("SPECC_DEBUG"):
            raise
        err.print(f"internal error: {type(exc).__name__}: {exc} -- this is a bug in specc; "
                  "rerun with SPECC_DEBUG=1 to see where, and report it", markup=False)
        exit_now(2)
    exit_now(0)


def exit_now(code: object) -> None:
    """End the process with `code` (as `sys.exit` reads it) without the interpreter's teardown.

    Tearing down the modules and collecting the objects a plan or a check leaves took 0.1 s, a
    fifth of a cold `specc plan`. What libraries registered for the exit (logging's flush,
    temporary folders, worker pools) still runs, and the output is flushed first."""
    import atexit

    if code is None:
        status = 0
    elif isinstance(code, int):
        status = code
    else:  # sys.exit("message"): the message on stderr, status 1
        print(code, file=sys.stderr)
        status = 1
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe (specc plan ... | head): nothing left to say
            pass
    os._exit(status)


if __name__ == "__main__":
    main()
