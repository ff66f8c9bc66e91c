"""GenoM modules (seed 000 §2.4): requests, exec tasks, posters, types and codel states."""

from __future__ import annotations

import keyword
from collections.abc import Mapping

from specc.check.context import Context
from specc.model import nodes as m
from specc.pysource import camel, python_name_problem

BUILTIN_TYPES = frozenset({"double", "float", "int", "long", "bool", "string", "char"})
STANDARD_STATES = ("start", "exec", "end", "inter")
TERMINAL_YIELDS = frozenset({"ether", "zombie"})
EXEC_TASK_CODELS = ("init", "permanent")


def check(ctx: Context) -> None:
    numbers: dict[int | float, m.Module] = {}
    for module in ctx.items(m.Module):
        if module.number is not None:
            other = numbers.setdefault(module.number.value, module)
            # A module defined twice under one name is reported as such, not as a number clash.
            if other is not module and other.name != module.name:
                ctx.report("duplicate-module-number",
                           f"modules '{other.name}' and '{module.name}' both use number {module.number.value}",
                           module.number.span, (other.span, f"'{other.name}' declared here"))
        check_module(ctx, module)


# The generated client already has these methods, and Python reserves its keywords.
RESERVED = frozenset({"send", "reply", "interm", "final", "abort", "call", "poster", "module", "kernel", "create",
                      "client"}) | frozenset(keyword.kwlist)
# The parameters the generated client's request methods have besides the request's inputs.
CLIENT_PARAMETERS = frozenset({"self", "interm_timeout", "final_timeout"})
# What a codel's `request` already carries at run time (specc.runtime.functional.Activity):
# an input or output with one of these names would be hidden behind it.
ACTIVITY_ATTRIBUTES = frozenset({"id", "spec", "module", "input", "output", "state", "codel_state", "sink", "parent",
                                 "children", "started", "cause", "waiting_for", "pending_final", "pending_state",
                                 "fail_report", "task", "live_children"})


# Elements of one array type (`double[N]`): a list of ten million is 80 MB of references, built
# when the module starts and copied at each poster update (a 1024 x 1024 grid is a tenth of it); a
# typo's extra zeros would exhaust the memory.
MOST_ARRAY_ELEMENTS = 10_000_000
# What a codel reaches through its SDI besides the module's data (`sdi.hardware`, `sdi.read_poster`):
# an internal data field of one of these names would hide it. The public names of
# specc.runtime.functional.InternalData (tests/test_cases.py holds them equal; not imported here:
# every `specc check` would load the runtime's modules).
SDI_ATTRIBUTES = frozenset({"hardware", "read_poster", "write_poster", "send_request"})
# What the generated module imports or defines at top level beside the spec's types.
MODULE_NAMES = frozenset({"annotations", "enum", "dataclass", "field", "Any", "rt", "SPEC", "create", "client"})
# Names an Enum refuses, or keeps out of its members: `mro`, and the _sunder_ and __dunder__ ones.
ENUM_REFUSED = frozenset({"mro"})


def check_names(ctx: Context, module: m.Module) -> None:
    """Requests, fields, types and enum values become Python names in the generated module."""
    named: list[tuple[str, m.Span, str]] = [(r.name, r.span, "request") for r in module.requests]
    named += [(f.name, f.span, "field") for s in module.structs for f in s.fields]
    named += [(f.name, f.span, "internal data field") for f in module.internal_data]
    named += [(t.name, t.span, "input or output") for r in module.requests for t in r.inputs + r.outputs]
    named += [(t.name, t.span, "type") for t in module.structs]
    named += [(t.name, t.span, "type") for t in module.enums]
    accessors = {f"poster_{p.name}" for p in module.posters}
    generated = MODULE_NAMES | {f"{camel(module.name)}Data", f"{camel(module.name)}Client"} | {
        f"{camel(r.name)}{part}" for r in module.requests for part in ("Input", "Output")} | {
        f"{camel(p.name)}Poster" for p in module.posters}
    for name, span, what in named:
        problem = python_name_problem(name)
        if problem is not None:
            ctx.report("reserved-name", f"{what} '{name}' cannot be a name of the generated code: {problem}; "
                       "rename it", span)
        elif what == "request" and name in RESERVED:
            ctx.report("reserved-name", f"request '{name}' would clash with a method of the generated client; "
                       "rename it", span)
        elif what == "input or output" and name in CLIENT_PARAMETERS:
            ctx.report("reserved-name", f"{what} '{name}' would clash with the parameter '{name}' of the generated "
                       "client's method; rename it", span)
        elif what == "input or output" and name in ACTIVITY_ATTRIBUTES:
            ctx.report("reserved-name", f"{what} '{name}' would be hidden by the activity's own '{name}' "
                       "when a codel reads request.{name}; rename it", span)
        elif what == "internal data field" and name in SDI_ATTRIBUTES:
            ctx.report("reserved-name", f"{what} '{name}' would hide the SDI's own '{name}' (codels reach "
                       f"sdi.{name}: {', '.join(sorted(SDI_ATTRIBUTES))} are specc's); rename it", span)
        elif what == "request" and name in accessors:
            ctx.report("reserved-name", f"request '{name}' would be hidden by the client's accessor of poster "
                       f"'{name.removeprefix('poster_')}'; rename it", span)
        elif what == "type" and name in generated:
            ctx.report("reserved-name", f"type '{name}' would replace a name the generated module defines or "
                       "imports; rename it", span)
    for decl in module.enums:
        seen: set[str] = set()
        for value in decl.values:
            problem = python_name_problem(value)
            if problem is None and (value in ENUM_REFUSED or value.startswith("_")):
                problem = f"'{value}' is a name an enum keeps for itself"
            if problem is not None:
                ctx.report("reserved-name", f"enum value '{value}' of '{decl.name}' cannot be a member of the "
                           f"generated Enum: {problem}; rename it", decl.span)
            elif value in seen:
                ctx.report("duplicate-definition", f"enum '{decl.name}' lists '{value}' twice", decl.span)
            seen.add(value)


def check_recursion(ctx: Context, module: m.Module) -> None:
    """A struct may not contain itself, directly or through others: its default value would be
    built for ever (and its class would be used before it exists)."""
    structs = {s.name: s for s in module.structs}
    done: set[str] = set()

    def visit(name: str, path: tuple[str, ...]) -> None:
        if name in path:
            cycle = " -> ".join((*path[path.index(name):], name))
            ctx.report("recursive-type", f"struct '{name}' contains itself ({cycle}): a record holds a value, "
                       "not a reference; break the cycle", structs[name].span)
            return
        if name in done:
            return
        for f in structs[name].fields:
            if f.type.name in structs:
                visit(f.type.name, (*path, name))
        done.add(name)

    for struct in module.structs:
        visit(struct.name, ())


def check_module(ctx: Context, module: m.Module) -> None:
    check_names(ctx, module)
    check_recursion(ctx, module)
    ctx.duplicates(module.structs + module.enums, "type")  # type: ignore[operator]
    ctx.duplicates(module.internal_data, "internal data field")
    ctx.duplicates(module.requests, "request")
    ctx.duplicates(module.exec_tasks, "exec task")
    ctx.duplicates(module.posters, "poster")
    types = BUILTIN_TYPES | {t.name for t in module.structs} | {e.name for e in module.enums}

    def check_type(t: m.TypeRef) -> None:
        if t.name not in types:
            ctx.unknown("undefined-type", "type", t.name, types, t.span, f" in module '{module.name}'")
        if t.size is not None and t.size > MOST_ARRAY_ELEMENTS:
            ctx.report("array-too-large", f"{t.name}[{t.size:,}]: an array holds at most {MOST_ARRAY_ELEMENTS:,} "
                       "elements (specc builds it as a Python list when the module starts, and again for every "
                       "request or poster copy); keep large data (maps, images) outside the SDI, in the codels' "
                       "own objects", t.span)

    for struct in module.structs:
        ctx.duplicates(struct.fields, "field")
        for f in struct.fields:
            check_type(f.type)
    for f in module.internal_data:
        check_type(f.type)
    requests = ctx.symbols.requests_of(module)
    tasks = {t.name: t for t in module.exec_tasks}
    for request in module.requests:
        check_request(ctx, module, request, requests, tasks, check_type)
    for task in module.exec_tasks:
        check_exec_task(ctx, task)
    # GenoM names a poster's activity by request or by codel (`activity: odoAndAsserv::exec`).
    activities = (set(requests) | {c.function for t in module.exec_tasks for c in t.codels}
                  | {c.function for r in module.requests for c in r.codels})
    fields = {f.name for f in module.internal_data}
    for poster in module.posters:
        for data in poster.data:
            if data.parts[0] not in fields:
                ctx.unknown("undefined-field", "internal data field", data.parts[0], fields, data.span,
                            f" in poster '{poster.name}'")
        if poster.activity is not None and poster.activity.text not in activities:
            ctx.unknown("undefined-activity", "activity", poster.activity.text, activities, poster.activity.span,
                        " (a request or a permanent codel of this module)")
        if poster.update is None:
            ctx.report("missing-property", f"poster '{poster.name}' needs 'update: auto;' or 'update: manual;'",
                       poster.span)


def check_request(ctx: Context, module: m.Module, request: m.Request, requests: Mapping[str, m.Request],
                  tasks: dict[str, m.ExecTask], check_type: object) -> None:
    assert callable(check_type)
    ctx.duplicates(request.inputs, "input")
    ctx.duplicates(request.outputs, "output")
    ctx.duplicates(request.codels, "codel for state", key="state")
    for typed in request.inputs + request.outputs:
        check_type(typed.type)
    if request.kind is None:
        ctx.report("missing-property", f"request '{request.name}' needs 'type: control;' or 'type: exec;'",
                   request.span)
    for other in request.incompatible_with:
        if len(other.parts) > 1 and other.parts[0] == module.name:
            ctx.report("undefined-request", f"incompatible_with names requests of module '{module.name}' by their "
                       f"own names: write '{'.'.join(other.parts[1:])}', not '{other.text}'", other.span)
        elif len(other.parts) > 1:
            # A module only knows its own requests; two modules' requests kept apart is the
            # executive's business.
            ctx.report("undefined-request", f"incompatible_with names requests of module '{module.name}' only, not "
                       f"'{other.text}': to keep two modules' requests from running together, give the executive "
                       "services that run them a conflict (`conflicts { SERVICE: interrupt; }`, or wait)", other.span)
        elif other.text != "all" and other.text not in requests:
            ctx.unknown("undefined-request", "request", other.text, requests, other.span,
                        f" in module '{module.name}'")
    if request.kind == "control":
        for codel in request.codels:
            ctx.report("codel-on-control-request",
                       f"control request '{request.name}' runs no activity, so it takes no "
                       f"'codel {codel.state}'; use 'validate:' or make it 'type: exec;'", codel.span)
        if request.task is not None:
            ctx.report("codel-on-control-request",
                       f"control request '{request.name}' runs in the module's control task; remove 'task:'",
                       request.task.span)
    if request.kind == "exec":
        if request.task is None:
            ctx.report("missing-exec-task",
                       f"exec request '{request.name}' needs 'task: <exec_task>;' to run its activity",
                       request.span)
        elif request.task.text not in tasks:
            ctx.unknown("undefined-exec-task", "exec task", request.task.text, tasks, request.task.span,
                        f" in module '{module.name}'")
        if not request.codels:
            ctx.report("missing-codel", f"exec request '{request.name}' has no codel; give at least 'codel exec: f;'",
                       request.span)
    states = {c.state for c in request.codels}
    reachable = states | set(STANDARD_STATES) | TERMINAL_YIELDS
    for codel in request.codels:
        for state in codel.yields:
            if state not in reachable:
                ctx.unknown("undefined-codel-state", "codel state", state, reachable, codel.span,
                            f" (request '{request.name}' declares codels for: {', '.join(sorted(states))})")


def check_exec_task(ctx: Context, task: m.ExecTask) -> None:
    ctx.duplicates(task.codels, "codel for state", key="state")
    for codel in task.codels:
        if codel.state not in EXEC_TASK_CODELS:
            ctx.report("bad-codel-state",
                       f"an exec task runs only 'codel init' and 'codel permanent', not 'codel {codel.state}'",
                       codel.span)
    if task.period is None:
        ctx.report("missing-property", f"exec task '{task.name}' needs a 'period:'", task.span)
    for duration in (task.period, task.delay):
        if duration is not None and duration.seconds <= 0 and duration is task.period:
            ctx.report("bad-duration", "a period must be longer than zero", duration.span)
        if duration is not None and duration.seconds < 0:
            ctx.report("bad-duration", "a delay cannot be negative", duration.span)
    if task.period is not None and task.delay is not None and task.delay.seconds >= task.period.seconds > 0:
        ctx.report("bad-duration", "the delay must be shorter than the period", task.delay.span)
