"""The executive (seed 000 ch. 3): services run existing module requests, conflicts name
existing services, reflexes and parameters point at real requests and posters."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from specc.check.codels import check_call, check_poster_reads, python_functions
from specc.check.context import Context
from specc.diagnostics import did_you_mean
from specc.model import nodes as m


def resolve_member(ctx: Context, ref: m.Ref, collection: str, word: str, code: str, shape: str) -> Any:
    """`module.member...` -> the module's member named by the second part, or a diagnostic."""
    if len(ref.parts) < 2:
        ctx.report("bad-reference", f"'{ref.text}' should be written {shape}", ref.span)
        return None
    module = ctx.lookup(m.Module, ref.parts[0], ref.span, "undefined-module")
    if module is None:
        return None
    members = getattr(ctx.symbols, collection)[module.name]
    member = members.get(ref.parts[1])
    if member is None:
        ctx.unknown(code, word, ref.parts[1], members, ref.span, f" in module '{module.name}'")
    return member


def resolve_request(ctx: Context, ref: m.Ref) -> m.Request | None:
    if len(ref.parts) > 2:
        ctx.report("bad-reference", f"'{ref.text}' should be written module.request", ref.span)
        return None
    request: m.Request | None = resolve_member(ctx, ref, "requests", "request", "undefined-request",
                                               "module.request")
    return request


def resolve_poster(ctx: Context, ref: m.Ref) -> m.Poster | None:
    """`module.Poster[.field]` -> the poster, or a diagnostic."""
    poster: m.Poster | None = resolve_member(ctx, ref, "posters", "poster", "undefined-poster",
                                             "module.Poster or module.Poster.field")
    if poster is not None and len(ref.parts) > 2:
        exported = {d.parts[0] for d in poster.data}
        if ref.parts[2] not in exported:
            ctx.unknown("undefined-field", "poster field", ref.parts[2], exported, ref.span,
                        f" in poster '{ref.parts[0]}.{poster.name}'")
    return poster


def check(ctx: Context) -> None:
    for executive in ctx.items(m.Executive):
        check_executive(ctx, executive)
    # Activity trees (seed 000 §1.6.4, §2.6): what a request's codels send to other modules.
    for module in ctx.items(m.Module):
        for request in module.requests:
            for ref in request.sends:
                target = resolve_request(ctx, ref)
                if target is not None and ref.parts[0] == module.name:
                    ctx.report("bad-reference", f"'{request.name}' sends to its own module; a module's "
                               "activities share its internal data instead", ref.span)


# How the executive calls its input and output functions (§3.3.1).
INPUT_FUNCTION = ("ctx",)
OUTPUT_FUNCTION = ("ctx", "output")


def check_executive(ctx: Context, executive: m.Executive) -> None:
    ctx.duplicates(executive.services, "service")
    ctx.duplicates(executive.parameters, "parameter")
    services = ctx.symbols.services_of(executive)
    functions = python_functions(ctx, executive.codel_module) if executive.codel_module else None
    posters = {module.name: {p.name for p in module.posters} for module in ctx.items(m.Module)}
    for ref in executive.rules:
        ctx.lookup(m.RuleBase, ref, ref.span, "undefined-rules")
    for service in executive.services:
        ctx.duplicates(service.args, "argument")
        if service.request is None:
            ctx.report("missing-property", f"service '{service.name}' needs 'request: module.request;'",
                       service.span)
        else:
            request = resolve_request(ctx, service.request)
            inputs = {i.name for i in request.inputs} if request is not None else set()
            for arg in service.args if request is not None else ():
                if arg.name not in inputs:
                    ctx.unknown("undefined-input", "input", arg.name, inputs, arg.span,
                                f" of request '{service.request.text}'")
            typed_inputs = {i.name: i for i in request.inputs} if request is not None else {}
            for arg in service.args:
                if arg.name in typed_inputs:
                    check_constant_input(ctx, arg, typed_inputs[arg.name], service.request)
            constants = {a.name for a in service.args}
            for taken in service.takes if request is not None else ():
                if taken.text not in inputs:
                    ctx.unknown("undefined-input", "input", taken.text, inputs, taken.span,
                                f" of request '{service.request.text}' (a service takes its request's inputs)")
                elif taken.text in constants:
                    ctx.report("duplicate-definition", f"input '{taken.text}' is both a constant of 'args' and "
                               "taken from the task level; keep one", taken.span)
            ctx.duplicates(service.takes, "taken input", key="text")
        if service.output is not None and len(service.output.parts) >= 2:
            ctx.report("bad-reference", f"'{service.output.text}': a service's output is a function of the "
                       "executive's codels (it prepares the result for the task level); only modules write posters",
                       service.output.span)
        for io in (service.input, service.output):
            if io is None or (io is service.output and len(io.parts) >= 2):  # reported just above
                continue
            if len(io.parts) >= 2:
                resolve_poster(ctx, io)
            elif functions is None:
                if executive.codel_module is None:  # else the module is missing or unreadable: said once, there
                    ctx.report("missing-property",
                               f"'{io.text}' is a function: give the executive 'codels: \"python.module\";'", io.span)
            elif io.text not in functions:
                ctx.report("undefined-codel", f"function '{io.text}' is not defined in "
                           f"{executive.codel_module.value if executive.codel_module else ''}"
                           f"{did_you_mean(io.text, functions)}; `specc skeleton` can write a stub for it", io.span)
            elif executive.codel_module is not None:
                check_call(ctx, io.text, functions[io.text], INPUT_FUNCTION if io is service.input else OUTPUT_FUNCTION,
                           executive.codel_module.value, io.span)
                check_poster_reads(ctx, io.text, functions[io.text], posters, executive.codel_module.value, io.span)
        timeout = service.timeout
        if timeout is not None:
            for value in (timeout.start, timeout.interm, timeout.final):
                if value is not None and value.seconds <= 0:
                    ctx.report("bad-duration", "a timeout must be longer than zero", value.span)
        ctx.duplicates(service.conflicts, "conflict with service", key="service")
        for conflict in service.conflicts:
            if conflict.service not in services:
                ctx.unknown("undefined-service", "service", conflict.service, services, conflict.span,
                            elsewhere(ctx, conflict.service, executive, "its conflicts name its own services"))
                continue
            target = ctx.symbols.service_request(services[conflict.service])
            if target is not None and target.kind == "control":  # the incompatibility graph leaves it out
                ctx.warn("control-conflict", f"'{conflict.service}' runs a control request, which ends as it "
                         f"starts and is never in EXEC: nothing to {conflict.policy}, so this entry changes "
                         "nothing; remove it, or give the conflict to the service that runs", conflict.span)
    for parameter in executive.parameters:
        if parameter.get is None and parameter.set is None:
            ctx.report("missing-property", f"parameter '{parameter.name}' needs 'get:' and/or 'set:'",
                       parameter.span)
        if parameter.get is not None:
            resolve_poster(ctx, parameter.get)
        if parameter.set is not None:
            request = resolve_request(ctx, parameter.set)
            # A request without a type is reported missing-property by the modules pass.
            if request is not None and request.kind is not None and request.kind != "control":
                ctx.report("not-a-control-request",
                           f"SET-PARAM writes through a control request; '{parameter.set.text}' is '{request.kind}'",
                           parameter.set.span)
    for reflex in executive.reflexes:
        check_reflex(ctx, reflex, services)
    check_reflex_loops(ctx, executive.reflexes, services)
    # How its own rule bases name its service groups is checked from the incompatibility graph,
    # an analysis: `specc.pipeline` reports it after these passes.


# The report codes a module's final reply may carry beside OK and the request's declared fail
# messages (specc.runtime.functional): its own failures, and an interruption's cause.
RUNTIME_CODES = frozenset({"ABORT", "INTERRUPTED", "BAD_INPUT", "CODEL_ERROR", "NO_EXEC_TASK", "UNDECLARED_STATE",
                           "UNKNOWN_ACTIVITY", "UNKNOWN_ID", "UNKNOWN_MODULE", "UNKNOWN_REQUEST", "ZOMBIE",
                           "MODULE_FROZEN"})
# ... and those of a request whose codels send requests: a child's error, a child not started.
CHILD_CODES = frozenset({"CHILD_ERROR", "CHILD_NOT_ACTIVATED"})


def check_reflex_loops(ctx: Context, reflexes: tuple[m.Reflex, ...], services: Mapping[str, m.Service]) -> None:
    """A warning for reflexes that, on any intermediate or final reply of a service or of a
    module request (no condition on its report), start that service or request it again,
    directly or through others: each brings the reply that brings the next, for as long as the
    executive runs (at one instant when the module refuses at once, frozen by a ZOMBIE). A
    service's replies are its request's too, which a reflex on `module.request` hears."""
    def replies_of(verb: str, target: str) -> list[str]:
        """What an action makes reply: a service started, and its module request; a request."""
        if verb == "start" and target in services:
            ran = services[target].request
            return [target] + ([ran.text] if ran is not None else [])
        return [target] if verb == "request" else []

    starts: dict[str, list[tuple[str, m.Reflex]]] = {}
    for reflex in reflexes:
        if reflex.comparison is None and reflex.trigger in ("interm", "reply"):
            for action in reflex.actions:
                for target in replies_of(action.verb, action.target.text):
                    starts.setdefault(reflex.source.text, []).append((target, reflex))
    warned: set[int] = set()
    for first in sorted(starts):
        path: list[tuple[str, m.Reflex]] = []

        def follow(source: str, seen: frozenset[str]) -> list[tuple[str, m.Reflex]] | None:
            for target, reflex in starts.get(source, ()):
                path.append((target, reflex))
                if target == first:
                    return list(path)
                if target not in seen:
                    found = follow(target, seen | {target})
                    if found is not None:
                        return found
                path.pop()
            return None

        loop = follow(first, frozenset({first}))
        if loop is None or any(id(reflex) in warned for _, reflex in loop):
            continue
        warned.update(id(reflex) for _, reflex in loop)
        chain = " -> ".join([first] + [target for target, _ in loop])
        ctx.warn("reflex-loop", f"these reflexes ask for {first} again on every reply it gives ({chain}): once "
                 "started, it never stops being restarted (at one instant when its module refuses at once); give "
                 "the reflex a condition on the reply (`== FAILED`) or start another service", loop[0][1].span)


def elsewhere(ctx: Context, service: str, executive: m.Executive, rule: str) -> str:
    """' in executive 'e' (it is executive 'other''s: ...)' for a service another executive has."""
    owners = [e.name for e in ctx.items(m.Executive) if e is not executive and any(s.name == service
                                                                                 for s in e.services)]
    return f" in executive '{executive.name}' (it is a service of executive '{owners[0]}': {rule})" if owners else ""


def check_reflex(ctx: Context, reflex: m.Reflex, services: Mapping[str, m.Service]) -> None:
    source = reflex.source
    request: m.Request | None = None
    if len(source.parts) == 1:
        if source.text not in services:
            ctx.unknown("undefined-service", "service", source.text, services, source.span)
        else:
            ran = services[source.text].request
            request = resolve_request(ctx, ran) if ran is not None else None
    else:
        request = resolve_request(ctx, source)
    comparison = reflex.comparison
    if reflex.trigger == "reply" and comparison is not None and comparison.op == "==" and request is not None:
        value = comparison.value.text if isinstance(comparison.value, m.Ref) else None
        module = ctx.symbols.module_of(request)
        replies = {"OK"} | {f.text for f in request.fail} | RUNTIME_CODES | set(
            ctx.symbols.requests_of(module) if module is not None else ()) | (CHILD_CODES if request.sends else set())
        if value is not None and value not in replies:
            # A reflex reads the module's report (OK, a fail message, the runtime's codes, the request
            # that interrupted it), not the result the executive gives the task level (INT, TIMEOUT...).
            ctx.warn("reflex-never-fires", f"'{source.text}''s module never reports '{value}' (a reflex compares "
                     f"the module's report: OK, its fail messages ({', '.join(f.text for f in request.fail) or 'none'}"
                     f"), the runtime's codes or the request that interrupted it, not the result the executive "
                     "answers the task level): this reflex cannot fire; declare the fail message or fix the name",
                     comparison.span)
    for action in reflex.actions:
        target = action.target
        if action.verb == "request":
            request = resolve_request(ctx, target)
            if request is not None and request.inputs:
                ctx.report("reflex-needs-input", f"a reflex sends '{target.text}' without input, but it takes "
                           f"{', '.join(i.name for i in request.inputs)}: start a service that provides them instead",
                           target.span)
        elif target.text not in services:
            ctx.unknown("undefined-service", "service", target.text, services, target.span,
                        f" (reflexes '{action.verb}' executive services)")
        elif action.verb == "start" and services[target.text].takes:
            taken = ", ".join(t.text for t in services[target.text].takes)
            ctx.report("reflex-needs-input", f"a reflex starts '{target.text}' without input, but it takes {taken} "
                       "from the task level: it would always end BAD-INPUT; give the service `args { }` instead "
                       "of `takes:`, or let the task level ask for it", target.span)


NUMERIC_INPUTS = frozenset({"double", "float"})
WHOLE_INPUTS = frozenset({"int", "long", "char"})
TEXT_INPUTS = frozenset({"string"})


def module_enums(ctx: Context, module_name: str) -> dict[str, set[str]]:
    """The enums of a module, by name, with their values: a request's input names its own
    module's (two modules may each have an enum of one name)."""
    return {e.name: set(e.values) for module in ctx.items(m.Module) if module.name == module_name
            for e in module.enums}


def refused_values(kind: str, values: list[str | float], enums: Mapping[str, set[str]]) -> list[str | float]:
    """The values (numbers, or words: symbols) an input of type `kind` refuses at run time: a word
    for a number, a fraction for a whole number, a word no member of its enum. Text and
    structures refuse nothing here: the runtime reads what it is given."""
    if kind in NUMERIC_INPUTS:
        return [v for v in values if isinstance(v, str)]
    if kind in WHOLE_INPUTS:
        return [v for v in values if isinstance(v, str) or not float(v).is_integer()]
    if kind in enums:
        return [v for v in values if v not in enums[kind]]
    return []


def check_constant_input(ctx: Context, arg: m.Argument, typed: m.TypedName, request: m.Ref) -> None:
    """A service's constant input (`args { rate: 0.5; }`) of the type its request declares: the
    request would refuse it at every call (BAD_INPUT), which the task level sees as an ERROR."""
    value = arg.value
    if typed.type.size is not None or not isinstance(value, (m.Number, m.Ref)) or (
            isinstance(value, m.Ref) and len(value.parts) > 1):
        return
    shown: str | float = value.value if isinstance(value, m.Number) else value.text
    enums = module_enums(ctx, request.parts[0])
    if refused_values(typed.type.name, [shown], enums):
        allowed = f" ({', '.join(sorted(enums[typed.type.name]))})" if typed.type.name in enums else ""
        ctx.report("bad-argument-type", f"{shown} cannot be input '{typed.name}' of {request.text}, of type "
                   f"{typed.type.name}{allowed}{did_you_mean(str(shown), enums.get(typed.type.name, ()))}: the "
                   "request would refuse it at every call", value.span)
